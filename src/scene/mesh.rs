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

impl Mesh {
    /// Multiply every coordinate by `factor` in f64, each product rounded once (a unit
    /// conversion or `--scale`). A power-of-two factor is exact (unless a product over- or
    /// underflows); any other factor rounds each coordinate to the nearest f64 of the exact
    /// product. `objects[*].world` keeps the loader's matrix (the scale is applied after it).
    /// The caller checks the result's range (an overflow gives infinite coordinates).
    pub fn scale(&mut self, factor: f64) {
        if factor == 1.0 {
            return;
        }
        for p in &mut self.positions {
            *p *= factor;
        }
    }

    /// The given triangles (in that order) re-indexed to the vertices they use, numbered in
    /// order of first use, and for each new index the vertex it stands for.
    pub fn reindex(&self, tris: &[u32]) -> (Vec<[u32; 3]>, Vec<u32>) {
        // A table over the span of vertices the triangles use when they may use a good share
        // of it (one array lookup each): a part of a glTF scene uses one contiguous run of
        // the scene's vertices, however large the scene. A hash map for a few triangles
        // scattered over a large mesh (the table would cost more to fill than it saves). The
        // numbering is the same either way.
        let (lo, hi) = self.span(tris);
        self.reindex_by(tris, tris.len().saturating_mul(24) >= (hi - lo) as usize, lo, hi)
    }

    /// The least and one past the greatest vertex index the given triangles use (`(0, 0)` for
    /// none).
    fn span(&self, tris: &[u32]) -> (u32, u32) {
        let (lo, hi) = tris.iter().fold((u32::MAX, 0u32), |(lo, hi), &t| {
            let [a, b, c] = self.triangles[t as usize];
            (lo.min(a).min(b).min(c), hi.max(a).max(b).max(c))
        });
        if lo > hi {
            (0, 0)
        } else {
            (lo, hi + 1)
        }
    }

    /// [`Mesh::reindex`] with a table over vertices `lo..hi` (`table`; every vertex the
    /// triangles use lies there) or a hash map.
    fn reindex_by(&self, tris: &[u32], table: bool, lo: u32, hi: u32) -> (Vec<[u32; 3]>, Vec<u32>) {
        let mut remap = if table {
            Remap::Table(lo, vec![u32::MAX; (hi - lo) as usize])
        } else {
            Remap::Map(std::collections::HashMap::new())
        };
        let mut vmap = Vec::new();
        let triangles = tris
            .iter()
            .map(|&t| {
                self.triangles[t as usize].map(|v| {
                    remap.get_or_insert(v, || {
                        vmap.push(v);
                        (vmap.len() - 1) as u32
                    })
                })
            })
            .collect();
        (triangles, vmap)
    }

    /// The sub-mesh of the given triangles (in that order), re-indexed: only the vertices they
    /// use, in order of first use; every triangle assigned to object 0, a copy of the object of
    /// the first triangle (`objects` is empty when `tris` is).
    pub fn sub_mesh(&self, tris: &[u32]) -> Mesh {
        let (triangles, vmap) = self.reindex(tris);
        let positions = vmap.iter().map(|&v| self.positions[v as usize]).collect();
        let objects = tris.first().map(|&t| self.objects[self.tri_object[t as usize] as usize].clone());
        Mesh {
            positions,
            tri_object: vec![0; triangles.len()],
            triangles,
            objects: objects.into_iter().collect(),
        }
    }
}

/// Read access to a triangle mesh in world coordinates: a whole [`Mesh`], or a view of one part
/// of one (`crate::check::assembly`) that borrows the loaded coordinates instead of copying them.
/// Vertices are numbered `0..vertex_count()` and triangles `0..triangle_count()`.
pub trait TriMesh: Sync {
    /// Number of vertices.
    fn vertex_count(&self) -> usize;
    /// Vertex `v`.
    fn vertex(&self, v: u32) -> DVec3;
    /// Number of triangles.
    fn triangle_count(&self) -> usize;
    /// The vertex indices of triangle `t`.
    fn indices(&self, t: u32) -> [u32; 3];
    /// Triangle `t` as three points.
    #[inline]
    fn triangle(&self, t: u32) -> [DVec3; 3] {
        self.indices(t).map(|v| self.vertex(v))
    }
    /// All vertices in order (borrowed when they are stored contiguously).
    fn positions(&self) -> std::borrow::Cow<'_, [DVec3]> {
        (0..self.vertex_count() as u32).map(|v| self.vertex(v)).collect::<Vec<_>>().into()
    }
}

/// Where a triangle's world corners and its object come from, by the triangle's index in the
/// world mesh: the loaded [`Mesh`] itself, or an instanced scene
/// ([`crate::load::InstancedScene`]) that places a triangle's corners when they are read, by
/// the arithmetic that expands it (so both give the same coordinates, bit for bit). What reads
/// only the triangles it needs (finding ids, regions) reads them through this, never through
/// the whole world mesh.
pub trait WorldTriangles: Sync {
    /// The world corners of triangle `t`.
    fn corners(&self, t: u32) -> [DVec3; 3];
    /// The object (index into the mesh's objects) triangle `t` belongs to.
    fn object_of(&self, t: u32) -> u32;
    /// The name of object `o` (empty for an index past the objects).
    fn object_name(&self, o: u32) -> &str;
}

impl WorldTriangles for Mesh {
    #[inline]
    fn corners(&self, t: u32) -> [DVec3; 3] {
        self.triangles[t as usize].map(|i| self.positions[i as usize])
    }
    #[inline]
    fn object_of(&self, t: u32) -> u32 {
        self.tri_object[t as usize]
    }
    fn object_name(&self, o: u32) -> &str {
        self.objects.get(o as usize).map_or("", |o| &o.name)
    }
}

impl TriMesh for Mesh {
    #[inline]
    fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    #[inline]
    fn vertex(&self, v: u32) -> DVec3 {
        self.positions[v as usize]
    }
    #[inline]
    fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
    #[inline]
    fn indices(&self, t: u32) -> [u32; 3] {
        self.triangles[t as usize]
    }
    fn positions(&self) -> std::borrow::Cow<'_, [DVec3]> {
        std::borrow::Cow::Borrowed(&self.positions)
    }
}

/// Old vertex index -> new, for [`Mesh::reindex`].
enum Remap {
    /// Indexed by the old vertex less the first one of the span; `u32::MAX` where not yet
    /// numbered.
    Table(u32, Vec<u32>),
    Map(std::collections::HashMap<u32, u32>),
}

impl Remap {
    fn get_or_insert(&mut self, v: u32, new: impl FnOnce() -> u32) -> u32 {
        match self {
            Remap::Table(lo, t) => {
                let slot = &mut t[(v - *lo) as usize];
                if *slot == u32::MAX {
                    *slot = new();
                }
                *slot
            }
            Remap::Map(m) => *m.entry(v).or_insert_with(new),
        }
    }
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
    /// glTF only: the world matrix (column-major, as glam stores it) that was applied: the
    /// node's, or for an `EXT_mesh_gpu_instancing` instance the node's times the instance's.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Mesh {
        Mesh {
            positions: vec![
                DVec3::new(1.0, -2.0, 0.1),
                DVec3::new(3.0, 0.0, -0.0),
                DVec3::new(0.3, 5.0, 7.0),
            ],
            triangles: vec![[0, 1, 2]],
            tri_object: vec![0],
            objects: vec![Object { name: "o".into(), ..Object::default() }],
        }
    }

    /// Both ways of [`Mesh::reindex`] number the vertices alike, on a random subset and order
    /// of the triangles of a mesh with unused vertices.
    #[test]
    fn reindex_by_table_and_by_map_agree() {
        let mut next = crate::load::test_rng(3);
        let n = 400;
        let m = Mesh {
            positions: (0..n).map(|i| DVec3::splat(i as f64)).collect(),
            triangles: (0..600).map(|_| [next(n), next(n), next(n)].map(|v| v as u32)).collect(),
            tri_object: vec![0; 600],
            objects: vec![Object { name: "o".into(), ..Object::default() }],
        };
        for k in [0usize, 1, 7, 150, 600] {
            let tris: Vec<u32> = (0..k).map(|_| next(600) as u32).collect();
            let (lo, hi) = m.span(&tris);
            let used = tris.iter().flat_map(|&t| m.triangles[t as usize]);
            assert!(used.clone().all(|v| (lo..hi).contains(&v)), "{k}");
            assert_eq!(used.clone().min(), (k > 0).then_some(lo));
            assert_eq!(used.max(), (k > 0).then(|| hi - 1));
            let (table, map) = (m.reindex_by(&tris, true, lo, hi), m.reindex_by(&tris, false, lo, hi));
            assert_eq!(table, m.reindex_by(&tris, true, 0, n as u32), "{k}");
            assert_eq!(table, map, "{k}");
            assert_eq!(m.reindex(&tris), map);
            for (t, r) in tris.iter().zip(&table.0) {
                assert_eq!(m.triangles[*t as usize], r.map(|v| table.1[v as usize]));
            }
        }
    }

    #[test]
    fn scale_multiplies_each_coordinate_once() {
        let mut m = tri();
        m.scale(0.25);
        assert_eq!(m.positions[0], DVec3::new(0.25, -0.5, 0.025));
        assert_eq!(m.positions[2], DVec3::new(0.075, 1.25, 1.75));
        // Not a power of two: each coordinate is the rounded product, nothing else changes.
        let mut m = tri();
        m.scale(25.4);
        assert_eq!(m.positions[0].z, 0.1 * 25.4);
        assert_eq!(m.positions[2].x, 0.3 * 25.4);
        assert_eq!((m.triangles.clone(), m.tri_object.clone()), (tri().triangles, tri().tri_object));
        let mut m = tri();
        m.scale(1.0);
        assert_eq!(m, tri());
        assert!(m.positions[1].z.is_sign_negative());
    }
}
