//! The scene data every loader produces: positions in f64, triangles as u32 indices, and per
//! triangle the object (OBJ `o`/`g`, STL `solid`, glTF node × primitive) it came from.
//!
//! Only what a clash needs is modelled: no normals, UVs or materials.

use glam::DVec3;

/// A triangle mesh in f64 world coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles, 0-based indices into `positions`, in file order (see the loaders for the
    /// order of each format).
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the index into `objects` of the object it came from.
    pub tri_object: Vec<u32>,
    /// The objects triangles belong to, in order of first appearance.
    pub objects: Vec<Object>,
}

/// One object of a file: an OBJ `o`/`g` group, an STL `solid`, or a glTF mesh instance
/// (node × mesh).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Object {
    /// Display name: OBJ `o`/`g` name, STL solid name, or the glTF node path `Root/Child/Leaf`
    /// (a node without a name is called `node<i>`). Never empty: loaders invent `object<i>`.
    pub name: String,
    /// glTF only: the index of the glTF mesh this instance draws (instances of one mesh share it).
    pub gltf_mesh: Option<u32>,
    /// glTF only: the node's world matrix (column-major, as glam stores it) that was applied.
    pub world: Option<glam::DMat4>,
}

/// What a loader returns: the mesh and any warnings about harmless oddities it skipped
/// (the library never prints; the binary shows these on stderr).
#[derive(Debug, Clone, Default)]
pub struct Loaded {
    /// The mesh, in the file's own coordinates (glTF: with node transforms applied).
    pub mesh: Mesh,
    /// Human-readable warnings, one line each.
    pub warnings: Vec<String>,
}
