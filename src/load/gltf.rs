//! glTF 2.0 loader (`.gltf` JSON and `.glb` binary), without the `gltf` crate's `import`.
//!
//! - **Buffers**: the GLB binary chunk, base64 `data:` URIs, or files given by a relative
//!   path that stays inside the glTF's directory (percent-decoded, then checked: a scheme such
//!   as `file:` or `https:`, an absolute path, a drive letter or UNC prefix, or a `..` that
//!   climbs above the directory is refused with an error naming the URI). Each must hold its
//!   `byteLength`; every bufferView and accessor range is checked before reading (see
//!   `gltf_data`).
//! - **Extensions**: a file may *require* `KHR_mesh_quantization`, `EXT_mesh_gpu_instancing`
//!   (both decoded) and extensions that only add appearance or metadata (`KHR_materials_*`,
//!   `KHR_texture_transform`, `EXT_mesh_features`, …). Any other required extension is an
//!   error naming it (Draco and meshopt compression cannot be decoded). Extensions that are
//!   only *used* never fail a file: geometry is read from the core data, and an accessor with
//!   no data at all (neither bufferView nor sparse, i.e. supplied by an extension) is an error
//!   naming the extensions used.
//! - **Scene**: the default scene, else the first scene, else every root node (a node that is
//!   nobody's child). The hierarchy is walked iteratively; a node with two parents, a cycle,
//!   or more than [`MAX_DEPTH`] levels is an error. World = parent × local, computed in f64
//!   (the node `matrix`, or translation × rotation (normalised quaternion) × scale). Every node
//!   `matrix`/`translation`/`rotation`/`scale` number is read from the JSON as f64 (the decimal
//!   correctly rounded once to f64; the `gltf` crate's own copy is f32, which would move a part
//!   by up to half an f32 ulp of its placement). Binary accessor data (`KHR_mesh_quantization`
//!   positions, `EXT_mesh_gpu_instancing` attributes) is used as stored.
//! - **Primitives**: modes TRIANGLES, TRIANGLE_STRIP (triangle `i` is `(i, i+1, i+2)`, with the
//!   last two swapped for odd `i` to keep the winding) and TRIANGLE_FAN (`(0, i+1, i+2)`),
//!   indexed (u8/u16/u32) or not. POINTS/LINES/LINE_LOOP/LINE_STRIP are skipped with a warning.
//!   Skins and morph targets are ignored (with a warning); application-specific attributes
//!   (`_BATCHID`, `_FEATURE_ID_0`, …) are ignored.
//! - **Positions** (VEC3; sparse substitution applied for every component type), in f64:
//!   `FLOAT` widened exactly; with `KHR_mesh_quantization`, `BYTE`/`UNSIGNED_BYTE`/`SHORT`/
//!   `UNSIGNED_SHORT` unnormalized are the integer itself (exact), normalized are the correctly
//!   rounded f64 quotient `c / 127`, `c / 255`, `c / 32767`, `c / 65535`, clamped below at -1
//!   for the signed types (so -128 and -127 both give -1). The node transform then
//!   dequantizes, like any node transform.
//! - **World coordinates**: each vertex is `W · v` with `W` the f64 world matrix of its part,
//!   evaluated as glam's `transform_point3`: `((W₀·x + W₁·y) + W₂·z) + W₃` per row, plain f64
//!   multiplies and adds, no FMA, so the result is the same on every platform. Verdicts are
//!   exact for these coordinates.
//! - **`EXT_mesh_gpu_instancing`** (honoured on any node with a mesh that carries it, declared
//!   or not): attributes `TRANSLATION` (VEC3 FLOAT), `ROTATION` (VEC4 FLOAT, or normalized
//!   BYTE/SHORT decoded as above) and `SCALE` (VEC3 FLOAT), each optional; every attribute,
//!   application-specific ones included, must have the same count, the number of instances.
//!   Instance `k` gets `W = node world · (T · R · S)`, the product in f64, `R` from the
//!   quaternion divided by its f64 length (zero length, or a non-finite value, is an error).
//!   The node's own, non-instanced draw is not emitted; its children are ordinary nodes.
//! - **Limits**: a scene expanding to more than [`MAX_SCENE_VERTICES`] vertices,
//!   [`MAX_SCENE_TRIANGLES`] triangles or [`MAX_SCENE_PARTS`] parts (node instances plus GPU
//!   instances) is refused from the declared counts, before any instance is read or anything
//!   is allocated for it. Loaded without expansion ([`load_instanced`]), where memory grows
//!   with the parts and not with the world coordinates, the limits are
//!   [`MAX_INSTANCED_TRIANGLES`] triangles and the same parts, with no vertex limit; expanding
//!   it later ([`InstancedScene::expand`]) applies the expanded limits.
//! - **Vertices**: every primitive instance contributes its own vertices, transformed to world
//!   space in f64 (no merging across primitives or instances).
//! - **Triangle order**: scene traversal order (depth-first pre-order over the scene's root
//!   nodes in the order listed, children in listed order); within a node, its GPU instances in
//!   order, within those its mesh's primitives in order; within a primitive, index order.
//! - **Objects**: one per node that draws a mesh (node × mesh), named by the node path from the
//!   scene root joined with `/` (each node by its `name`, or `node<index>`); a node with
//!   `EXT_mesh_gpu_instancing` gives one object per instance instead, named `<node path>#<k>`
//!   (`k` from 0 in accessor order). Every object has `gltf_mesh = Some(mesh index)` (so
//!   instances share one BVH build in assemblies) and `world = Some(the matrix applied)`.
//!   Instances that yield no triangles get no object. Winding is kept as stored, also under
//!   mirroring transforms (containment decides orientation from the geometry).
//! - **Without expansion** ([`load_instanced`]): the same walk, checks and errors, but each mesh
//!   is kept once in its own coordinates and every part as (mesh, world matrix); a part's world
//!   coordinates are computed when asked ([`InstancedScene::place`]) by the arithmetic above,
//!   so they are the expanded load's, bit for bit.

use std::borrow::Cow;
use std::path::Path;

use ::gltf::mesh::Mode;
use ::gltf::scene::Transform;
use ::gltf::{Accessor, Document};
use glam::{DMat4, DQuat, DVec3};

use super::gltf_data::{
    load_buffers, parse_document, parse_extensions, split_glb, Extensions, GpuInstancing, NodeTransform,
    Reader,
};
use crate::error::{
    AccessorUser, Error, GltfProblem, InputProblem, InstancingProblem, Location, Quantity, Result,
};
use crate::scene::mesh::{Loaded, Mesh, Object, WorldTriangles};

/// The deepest node hierarchy accepted.
pub(crate) const MAX_DEPTH: usize = 1024;

/// The most vertices a scene may expand to through instancing (2^28, 6 GiB of f64
/// positions): a small file instancing a big mesh many times must fail, not exhaust memory.
pub(crate) const MAX_SCENE_VERTICES: usize = 1 << 28;

/// The most triangles a scene may expand to through instancing (2^28, 4 GiB of triangles and
/// object ids): many instances of a mesh with few vertices but many indices must fail too.
pub(crate) const MAX_SCENE_TRIANGLES: usize = 1 << 28;

/// The most parts (objects) a scene may expand to (2^24, some 4 GiB of names, matrices and
/// part records): `EXT_mesh_gpu_instancing` makes one part per instance from as little as
/// 12 bytes of file, so a tiny mesh instanced many times must fail too.
pub(crate) const MAX_SCENE_PARTS: usize = 1 << 24;

/// The most triangles a scene loaded without expanding its instances ([`load_instanced`]) may
/// have after instancing: the expanded scene's triangles are numbered in u32.
pub(crate) const MAX_INSTANCED_TRIANGLES: usize = u32::MAX as usize;

/// Loads `.gltf` or `.glb` `bytes` (the GLB magic decides); see the module doc.
pub(crate) fn load(path: &Path, bytes: &[u8]) -> Result<Loaded> {
    let mut mesh = Mesh::default();
    let (_, warnings) = walk(path, bytes, &mut mesh)?;
    Ok(Loaded { mesh, warnings })
}

/// Loads `.gltf` or `.glb` `bytes` without expanding the instances: each mesh decoded once, in
/// its own coordinates, and every part as (mesh, world matrix). Every check and error of
/// [`load`] is made, in the same order (each part is placed once, in a scratch buffer, to find a
/// non-finite world coordinate); [`InstancedScene::expand`] gives what [`load`] gives.
pub(crate) fn load_instanced(path: &Path, bytes: &[u8]) -> Result<InstancedScene> {
    let mut sink = PartSink { parts: Vec::new(), scratch: Mesh::default() };
    let (meshes, warnings) = walk(path, bytes, &mut sink)?;
    // Where each mesh's primitives, and each part, start in triangle order.
    let prim_starts: Vec<Vec<u32>> = meshes
        .iter()
        .map(|m| {
            let mut at = 0u32;
            let start = |p: &Prim| {
                let s = at;
                at += p.triangles.len() as u32;
                s
            };
            m.as_deref().unwrap_or(&[]).iter().map(start).collect()
        })
        .collect();
    let mut tri_starts = Vec::with_capacity(sink.parts.len() + 1);
    let mut at = 0u32;
    tri_starts.push(at);
    for p in &sink.parts {
        let prims = meshes.get(p.mesh as usize).and_then(Option::as_deref).unwrap_or(&[]);
        // The limits keep the expanded scene's triangle numbers within u32.
        at = at.saturating_add(counts(prims).1 as u32);
        tri_starts.push(at);
    }
    Ok(InstancedScene {
        path: path.to_path_buf(),
        meshes,
        prim_starts,
        tri_starts,
        parts: sink.parts,
        warnings,
    })
}

/// What [`walk`] hands the scene's parts to, in object order.
trait Sink {
    /// Whether the parts are placed into one world mesh ([`load`]) rather than kept as (mesh,
    /// matrix) ([`load_instanced`]): the limits and the memory estimate depend on it.
    fn expands(&self) -> bool;
    /// Called once, before any part, with the expanded scene's vertex, triangle and part counts.
    fn reserve(&mut self, vertices: usize, triangles: usize, parts: usize);
    /// One part: `prims` placed by `world` (see [`add_instance`]).
    fn part(&mut self, path: &Path, at: Placement, prims: &[Prim], name: String, world: DMat4) -> Result<()>;
    /// One part whose mesh no other part uses, on a sink that [`Self::expands`]: the same as
    /// [`Self::part`], given the primitives to keep or drop.
    fn sole_part(
        &mut self,
        path: &Path,
        at: Placement,
        prims: Vec<Prim>,
        name: String,
        world: DMat4,
    ) -> Result<()> {
        self.part(path, at, &prims, name, world)
    }
}

impl Sink for Mesh {
    fn expands(&self) -> bool {
        true
    }
    fn reserve(&mut self, vertices: usize, triangles: usize, parts: usize) {
        self.positions.reserve_exact(vertices);
        self.triangles.reserve_exact(triangles);
        self.tri_object.reserve_exact(triangles);
        self.objects.reserve_exact(parts);
    }
    fn part(&mut self, path: &Path, at: Placement, prims: &[Prim], name: String, world: DMat4) -> Result<()> {
        add_instance(self, path, at, prims, name, world)
    }
    fn sole_part(
        &mut self,
        path: &Path,
        at: Placement,
        mut prims: Vec<Prim>,
        name: String,
        world: DMat4,
    ) -> Result<()> {
        // The first part, of one primitive: its vectors become the mesh's (the positions placed
        // where they are), which is what `add_instance` makes of them (its vertices start at
        // 0, so its triangles are unchanged), without a copy of either.
        if !(self.positions.is_empty() && self.triangles.is_empty() && prims.len() == 1) {
            return add_instance(self, path, at, &prims, name, world);
        }
        let Prim { mut positions, triangles, .. } = prims.pop().expect("one primitive");
        let object = self.objects.len() as u32;
        self.objects.push(Object { name, gltf_mesh: Some(at.mesh as u32), world: Some(world) });
        positions.iter_mut().for_each(|v| *v = world.transform_point3(*v));
        check_placed(path, at, &positions)?;
        self.positions = positions;
        self.tri_object.resize(triangles.len(), object);
        self.triangles = triangles;
        Ok(())
    }
}

/// Collects the parts of an [`InstancedScene`], placing each in `scratch` (cleared after) only
/// to find a non-finite coordinate as [`load`] does.
struct PartSink {
    parts: Vec<ScenePart>,
    scratch: Mesh,
}

impl Sink for PartSink {
    fn expands(&self) -> bool {
        false
    }
    fn reserve(&mut self, _: usize, _: usize, parts: usize) {
        self.parts.reserve_exact(parts);
    }
    fn part(&mut self, path: &Path, at: Placement, prims: &[Prim], name: String, world: DMat4) -> Result<()> {
        let m = &mut self.scratch;
        m.positions.clear();
        m.triangles.clear();
        m.tri_object.clear();
        m.objects.clear();
        add_instance(m, path, at, prims, String::new(), world)?;
        self.parts.push(ScenePart { name, mesh: at.mesh as u32, world, at });
        Ok(())
    }
}

/// Where a part comes from, for error messages: its glTF mesh, node and GPU instance.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Placement {
    mesh: usize,
    node: usize,
    instance: Option<usize>,
}

/// A glTF scene before its instances are expanded: each glTF mesh decoded once in its own
/// coordinates, and every part (node × mesh, or GPU instance) as the mesh and the world matrix
/// that places it. Its memory grows with the distinct meshes, not with the instances.
#[derive(Clone)]
pub struct InstancedScene {
    path: std::path::PathBuf,
    meshes: Decoded,
    /// For each glTF mesh, the first triangle of each of its primitives (in the mesh's
    /// triangle order).
    prim_starts: Vec<Vec<u32>>,
    /// The first triangle of each part in the expanded mesh, and the triangle count last.
    tri_starts: Vec<u32>,
    /// The parts, in object order (the expanded mesh's `objects`).
    pub parts: Vec<ScenePart>,
    /// The loader's warnings, as [`load`] gives them.
    pub warnings: Vec<String>,
}

/// Decoded primitives by glTF mesh index (`None` for a mesh no node draws).
type Decoded = Vec<Option<Vec<Prim>>>;

/// One part of an [`InstancedScene`].
#[derive(Debug, Clone, PartialEq)]
pub struct ScenePart {
    /// Object name, as in the expanded mesh.
    pub name: String,
    /// The glTF mesh it draws.
    pub mesh: u32,
    /// The world matrix that places it (node world, times the GPU instance's own for one).
    pub world: DMat4,
    at: Placement,
}

impl InstancedScene {
    /// Part `k` placed: its world positions and its triangles (indexing them), exactly the
    /// positions and triangles (less the offset of its first vertex) the expanded mesh holds for
    /// object `k`, computed by the same arithmetic.
    pub fn place(&self, k: usize) -> Result<(Vec<DVec3>, Vec<[u32; 3]>)> {
        let p = &self.parts[k];
        let mut one = Mesh::default();
        add_instance(&mut one, &self.path, p.at, self.prims(p), String::new(), p.world)?;
        Ok((one.positions, one.triangles))
    }

    /// Part `k`'s world positions alone: those [`Self::place`] gives, by the same arithmetic,
    /// without its triangles or the check for non-finite coordinates (the load made it).
    pub fn place_positions(&self, k: usize) -> Vec<DVec3> {
        let p = &self.parts[k];
        let prims = self.prims(p);
        let mut positions = Vec::with_capacity(counts(prims).0);
        // Nothing to check, so this cannot fail.
        let _ = place_vertices(&mut positions, prims, p.world, |_| Ok(()));
        positions
    }

    /// The expanded mesh's objects (one per part, in order), without placing anything.
    pub fn objects(&self) -> Vec<Object> {
        let object =
            |p: &ScenePart| Object { name: p.name.clone(), gltf_mesh: Some(p.mesh), world: Some(p.world) };
        self.parts.iter().map(object).collect()
    }

    /// The vertices and triangles part `k` expands to, without placing it.
    pub fn part_counts(&self, k: usize) -> (usize, usize) {
        counts(self.prims(&self.parts[k]))
    }

    /// The whole scene expanded into one mesh in world coordinates and validated: what
    /// [`crate::load::load_bytes`] gives for the file.
    pub fn expand(&self) -> Result<Loaded> {
        let mut mesh = Mesh::default();
        let (mut v, mut t) = (0usize, 0usize);
        for k in 0..self.parts.len() {
            let (pv, pt) = self.part_counts(k);
            (v, t) = (v.saturating_add(pv), t.saturating_add(pt));
        }
        // The instanced load admits scenes the expanded one refuses: refuse those here, as
        // the expanded load would, before anything is allocated.
        check_scene_size(&self.path, (v, t, self.parts.len()), true)?;
        mesh.reserve(v, t, self.parts.len());
        for p in &self.parts {
            add_instance(&mut mesh, &self.path, p.at, self.prims(p), p.name.clone(), p.world)?;
        }
        let loaded = Loaded { mesh, warnings: self.warnings.clone() };
        super::validate(&self.path, &loaded)?;
        Ok(loaded)
    }

    fn prims(&self, p: &ScenePart) -> &[Prim] {
        self.meshes.get(p.mesh as usize).and_then(Option::as_deref).unwrap_or(&[])
    }

    /// The part holding triangle `t` of the expanded mesh, and `t`'s index within the part.
    fn locate(&self, t: u32) -> (usize, u32) {
        let k = self.tri_starts.partition_point(|&s| s <= t).saturating_sub(1).min(self.parts.len() - 1);
        (k, t - self.tri_starts[k])
    }
}

/// The expanded mesh's triangles read one at a time: a triangle's corners are its part's
/// vertices placed by the part's matrix with [`place_vertices`]' arithmetic (each vertex on its
/// own), so they are the expanded mesh's coordinates, bit for bit, without placing the part.
impl WorldTriangles for InstancedScene {
    fn corners(&self, t: u32) -> [DVec3; 3] {
        let (k, local) = self.locate(t);
        let p = &self.parts[k];
        let prims = self.prims(p);
        let starts = &self.prim_starts[p.mesh as usize];
        // The primitive holding the triangle: the last one starting at or before it that has
        // triangles (one without triangles starts where the next one does).
        let j = starts.partition_point(|&s| s <= local) - 1;
        let prim = &prims[j];
        let positions = &prims[prim.shares.unwrap_or(j)].positions;
        prim.triangles[(local - starts[j]) as usize].map(|i| p.world.transform_point3(positions[i as usize]))
    }

    fn object_of(&self, t: u32) -> u32 {
        self.locate(t).0 as u32
    }

    fn object_name(&self, o: u32) -> &str {
        self.parts.get(o as usize).map_or("", |p| &p.name)
    }
}

/// Refuses a scene of `(vertices, triangles, parts)` after instancing beyond what the load can
/// hold: when it `expands` the scene, [`MAX_SCENE_VERTICES`], [`MAX_SCENE_TRIANGLES`],
/// [`MAX_SCENE_PARTS`] and [`super::scene_estimate`] against the memory this process may use;
/// when it keeps the instances ([`load_instanced`]), whose memory grows with the parts and
/// not with the world coordinates, no vertex limit, triangles numbered in u32
/// ([`MAX_INSTANCED_TRIANGLES`]), the same parts limit, and
/// [`super::instanced_scene_estimate`].
fn check_scene_size(path: &Path, (v, t, parts): (usize, usize, usize), expands: bool) -> Result<()> {
    let limits = if expands {
        [
            (v, MAX_SCENE_VERTICES, Quantity::SceneVertices),
            (t, MAX_SCENE_TRIANGLES, Quantity::SceneTriangles),
            (parts, MAX_SCENE_PARTS, Quantity::SceneParts),
        ]
    } else {
        [
            (v, usize::MAX, Quantity::SceneVertices),
            (t, MAX_INSTANCED_TRIANGLES, Quantity::SceneTriangles),
            (parts, MAX_SCENE_PARTS, Quantity::SceneParts),
        ]
    };
    for (total, limit, quantity) in limits {
        if total > limit {
            let problem = InputProblem::TooLarge { quantity, count: total as u64, limit: limit as u64 };
            return Err(Error::in_file(path, problem));
        }
    }
    // Instancing multiplies what a small file asks for: refuse up front, before anything is
    // expanded, a scene whose check cannot fit in the memory this process may use.
    let need = if expands {
        super::scene_estimate(v as u64, t as u64, parts as u64)
    } else {
        super::instanced_scene_estimate(t as u64, parts as u64)
    };
    if let Some(available) = super::available_memory().filter(|&a| need > a) {
        let problem = InputProblem::NeedsMemory {
            triangles: t as u64,
            need,
            available,
            // The whole estimate per triangle (parts included), so the message adds up.
            per_triangle: need / (t as u64).max(1),
        };
        return Err(Error::in_file(path, problem));
    }
    Ok(())
}

/// The vertices (a shared accessor once) and triangles one instance of `prims` places.
fn counts(prims: &[Prim]) -> (usize, usize) {
    let (mut v, mut t) = (0usize, 0usize);
    for p in prims.iter().filter(|p| !p.triangles.is_empty()) {
        v = v.saturating_add(p.positions.len());
        t = t.saturating_add(p.triangles.len());
    }
    (v, t)
}

/// Parses, decodes and checks the scene, then hands `sink` every part in object order; returns
/// the decoded meshes (by glTF mesh index) and the warnings.
fn walk(path: &Path, bytes: &[u8], sink: &mut dyn Sink) -> Result<(Decoded, Vec<String>)> {
    let (json, bin) = if bytes.starts_with(b"glTF") { split_glb(path, bytes)? } else { (bytes, None) };
    let mut warnings = Vec::new();
    let doc = parse_document(path, json)?;
    let ext = parse_extensions(path, json, doc.accessors().len())?;
    let buffers = load_buffers(path, &doc, bin)?;
    let input_bytes = buffers.iter().map(|b| b.len()).fold(bytes.len(), usize::saturating_add);
    let reader = Reader { path, buffers: &buffers, input_bytes };
    let accessors: Vec<Accessor> = doc.accessors().collect();
    let instances = traverse(path, &doc, &ext, &reader, &accessors, &mut warnings)?;

    // Decode each mesh once, whatever its number of instances; check the expanded scene
    // against the limits from declared counts, before any instance is read or allocated.
    let mut decoded: Decoded = vec![None; doc.meshes().len()];
    let (mut total_v, mut total_t, mut total_parts) = (0usize, 0usize, 0usize);
    for inst in &instances {
        if decoded[inst.mesh].is_none() {
            decoded[inst.mesh] = Some(decode_mesh(&reader, &doc, inst.mesh, &mut warnings)?);
        }
        let copies = inst.gpu.as_ref().map_or(1, |g| g.count);
        let (v, t) = counts(decoded[inst.mesh].as_deref().unwrap_or(&[]));
        if t > 0 {
            total_v = total_v.saturating_add(v.saturating_mul(copies));
            total_t = total_t.saturating_add(t.saturating_mul(copies));
            total_parts = total_parts.saturating_add(copies);
        }
    }
    check_scene_size(path, (total_v, total_t, total_parts), sink.expands())?;

    sink.reserve(total_v, total_t, total_parts);
    let names = node_names(&doc);
    // The parts of each mesh: a mesh placed once is handed over to an expanding sink.
    let mut uses = vec![0usize; decoded.len()];
    for inst in &instances {
        uses[inst.mesh] = uses[inst.mesh].saturating_add(inst.gpu.as_ref().map_or(1, |g| g.count));
    }
    for inst in &instances {
        let prims = decoded[inst.mesh].as_deref().unwrap_or(&[]);
        if prims.iter().all(|p| p.triangles.is_empty()) {
            continue;
        }
        let name = node_path(&inst.path, &names);
        let at = |instance| Placement { mesh: inst.mesh, node: inst.node, instance };
        let Some(gpu) = &inst.gpu else {
            if sink.expands() && uses[inst.mesh] == 1 {
                let prims = decoded[inst.mesh].take().unwrap_or_default();
                sink.sole_part(path, at(None), prims, name, inst.world)?;
            } else {
                sink.part(path, at(None), prims, name, inst.world)?;
            }
            continue;
        };
        let trs = InstanceTransforms::read(&reader, &accessors, inst.node, gpu)?;
        for k in 0..gpu.count {
            let world = inst.world * trs.matrix(k)?;
            if !world.is_finite() {
                let at = Location::Instance { node: inst.node, instance: k };
                return Err(Error::at(path, at, GltfProblem::WorldOverflow));
            }
            sink.part(path, at(Some(k)), prims, format!("{name}#{k}"), world)?;
        }
    }
    Ok((decoded, warnings))
}

/// Appends one part: `prims` transformed by `world`, as object `name` (`at` says where it
/// comes from, for an error).
fn add_instance(
    mesh: &mut Mesh,
    path: &Path,
    at: Placement,
    prims: &[Prim],
    name: String,
    world: DMat4,
) -> Result<()> {
    let object = mesh.objects.len() as u32;
    mesh.objects.push(Object { name, gltf_mesh: Some(at.mesh as u32), world: Some(world) });
    let bases = place_vertices(&mut mesh.positions, prims, world, |placed| check_placed(path, at, placed))?;
    for (p, base) in prims.iter().zip(bases) {
        let Some(base) = base else { continue };
        mesh.triangles.extend(p.triangles.iter().map(|t| t.map(|i| base + i)));
        mesh.tri_object.resize(mesh.tri_object.len() + p.triangles.len(), object);
    }
    Ok(())
}

/// The first non-finite coordinate of a run of placed vertices, as an error (one tight loop).
fn check_placed(path: &Path, at: Placement, placed: &[DVec3]) -> Result<()> {
    match placed.iter().enumerate().find_map(|(i, w)| Some((i, super::non_finite(w.to_array())?))) {
        Some((i, value)) => {
            let at = Location::Placed { mesh: at.mesh, position: i, node: at.node, instance: at.instance };
            Err(Error::at(path, at, InputProblem::NonFiniteAfterTransform { value: Some(value) }))
        }
        None => Ok(()),
    }
}

/// Appends the vertices of `prims` placed by `world` to `positions` and returns where each
/// primitive's vertices start (a primitive sharing an earlier one's accessor uses that one's,
/// placed once; `None` for a primitive that places nothing). `check` sees each run of vertices
/// as it is appended, and its error stops the placement.
fn place_vertices(
    positions: &mut Vec<DVec3>,
    prims: &[Prim],
    world: DMat4,
    mut check: impl FnMut(&[DVec3]) -> Result<()>,
) -> Result<Vec<Option<u32>>> {
    let mut bases: Vec<Option<u32>> = vec![None; prims.len()];
    for (k, p) in prims.iter().enumerate() {
        if p.triangles.is_empty() && p.shares.is_none() {
            continue;
        }
        let owner = p.shares.unwrap_or(k);
        if let Some(base) = bases[owner] {
            bases[k] = Some(base);
            continue;
        }
        let base = positions.len() as u32;
        bases[k] = Some(base);
        // Transform all, then check the run.
        positions.extend(prims[owner].positions.iter().map(|&v| world.transform_point3(v)));
        check(&positions[base as usize..])?;
    }
    Ok(bases)
}

/// The decoded attributes of one `EXT_mesh_gpu_instancing` node (components decoded by
/// [`super::gltf_data::component`]); missing ones are the identity (zero translation,
/// identity rotation, unit scale). Matrices are made one at a time by [`Self::matrix`].
struct InstanceTransforms<'a> {
    path: &'a Path,
    node: usize,
    t: Option<Vec<[f64; 3]>>,
    r: Option<Vec<[f64; 4]>>,
    s: Option<Vec<[f64; 3]>>,
}

impl<'a> InstanceTransforms<'a> {
    fn read(r: &Reader<'a, '_>, accessors: &[Accessor], node: usize, gpu: &Gpu) -> Result<Self> {
        let user = AccessorUser::Instancing { node };
        let get = |a: Option<usize>| a.and_then(|a| accessors.get(a));
        Ok(InstanceTransforms {
            path: r.path,
            node,
            t: get(gpu.attrs.translation).map(|a| r.vectors(a, user)).transpose()?,
            r: get(gpu.attrs.rotation).map(|a| r.vectors(a, user)).transpose()?,
            s: get(gpu.attrs.scale).map(|a| r.vectors(a, user)).transpose()?,
        })
    }

    /// `T * R * S` of instance `k`: the rotation divided by its f64 length (a zero or
    /// non-finite value is an error), the matrix built from the f64 values as a node's TRS is
    /// ([`DMat4::from_scale_rotation_translation`]).
    fn matrix(&self, k: usize) -> Result<DMat4> {
        let t = self.t.as_ref().and_then(|v| v.get(k)).copied().unwrap_or([0.0; 3]);
        let q = self.r.as_ref().and_then(|v| v.get(k)).copied().unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let s = self.s.as_ref().and_then(|v| v.get(k)).copied().unwrap_or([1.0; 3]);
        let bad =
            |p: GltfProblem| Error::at(self.path, Location::Instance { node: self.node, instance: k }, p);
        for (attribute, bad_value) in [
            ("TRANSLATION", super::non_finite(t)),
            ("ROTATION", super::non_finite(q)),
            ("SCALE", super::non_finite(s)),
        ] {
            if let Some(value) = bad_value {
                return Err(bad(GltfProblem::InstanceNotFinite { attribute, value }));
            }
        }
        let q = DQuat::from_array(q);
        let len = q.length();
        if len == 0.0 || !len.is_finite() {
            return Err(bad(GltfProblem::ZeroQuaternion));
        }
        Ok(DMat4::from_scale_rotation_translation(DVec3::from_array(s), q / len, DVec3::from_array(t)))
    }
}

/// One node drawing a mesh, in traversal order.
struct Instance {
    node: usize,
    mesh: usize,
    world: DMat4,
    /// Node indices from the scene root down to `node`.
    path: Vec<usize>,
    /// The node's `EXT_mesh_gpu_instancing`, checked (types, equal counts), not yet read.
    gpu: Option<Gpu>,
}

/// A checked `EXT_mesh_gpu_instancing`: its attributes and the common count.
struct Gpu {
    attrs: GpuInstancing,
    count: usize,
}

/// One decoded primitive in mesh-local space (triangles index `positions`).
#[derive(Clone)]
struct Prim {
    /// Its positions; empty when it shares an earlier primitive's (`shares`).
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// The earlier primitive of the same mesh whose POSITION accessor this one uses too: its
    /// vertices are placed once and both index them (`inputs.*.vertices` counts them once).
    shares: Option<usize>,
}

fn node_names(doc: &Document) -> Vec<Cow<'_, str>> {
    doc.nodes()
        .map(|n| match n.name() {
            Some(s) if !s.is_empty() => Cow::Borrowed(s),
            _ => Cow::Owned(format!("node{}", n.index())),
        })
        .collect()
}

fn node_path(path: &[usize], names: &[Cow<'_, str>]) -> String {
    let parts: Vec<&str> = path.iter().map(|&i| names.get(i).map_or("?", |s| s.as_ref())).collect();
    parts.join("/")
}

/// Checks a node's `EXT_mesh_gpu_instancing` without reading it: accessor types, and one
/// count shared by every attribute (the number of instances).
fn check_gpu(r: &Reader, accessors: &[Accessor], node: usize, attrs: &GpuInstancing) -> Result<Gpu> {
    let mut count: Option<(usize, &str)> = None;
    for (name, a) in &attrs.all {
        let Some(acc) = accessors.get(*a) else {
            return Err(Error::at(
                r.path,
                Location::Node(node),
                InstancingProblem::NoSuchAccessor { accessor: *a },
            ));
        };
        r.check_instance_attribute(acc, name, node)?;
        match count {
            None => count = Some((acc.count(), name)),
            Some((first_count, first)) if first_count != acc.count() => {
                let problem = InstancingProblem::CountMismatch {
                    first: first.to_string(),
                    first_count,
                    attribute: super::clip(name, 40),
                    count: acc.count(),
                };
                return Err(Error::at(r.path, Location::Node(node), problem));
            }
            Some(_) => {}
        }
    }
    Ok(Gpu { attrs: attrs.clone(), count: count.map_or(0, |c| c.0) })
}

/// Checks the node graph (single parents, no cycles, bounded depth) and lists the mesh
/// instances of the chosen scene in depth-first pre-order.
fn traverse(
    path: &Path,
    doc: &Document,
    ext: &Extensions,
    r: &Reader,
    accessors: &[Accessor],
    warnings: &mut Vec<String>,
) -> Result<Vec<Instance>> {
    let err = |node: usize, p: GltfProblem| Error::at(path, Location::Node(node), p);
    let n = doc.nodes().len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for node in doc.nodes() {
        for child in node.children() {
            let c = child.index();
            if let Some(p) = parent[c] {
                if p == node.index() {
                    return Err(err(p, GltfProblem::ChildTwice { child: c }));
                }
                return Err(err(c, GltfProblem::TwoParents { first: p, second: node.index() }));
            }
            parent[c] = Some(node.index());
        }
    }
    if let Some(c) = find_cycle(&parent) {
        return Err(err(c, GltfProblem::Cycle));
    }

    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let roots: Vec<usize> = match &scene {
        Some(s) => s.nodes().map(|r| r.index()).collect(),
        None => (0..n).filter(|&i| parent[i].is_none()).collect(),
    };
    let mut listed = vec![false; n];
    for &r in &roots {
        if let Some(p) = parent[r] {
            return Err(err(r, GltfProblem::RootIsChild { parent: p }));
        }
        if std::mem::replace(&mut listed[r], true) {
            return Err(err(r, GltfProblem::RootListedTwice));
        }
    }

    let nodes: Vec<::gltf::Node> = doc.nodes().collect();
    let mut visited = vec![false; n];
    let mut instances = Vec::new();
    let mut skinned = false;
    // (node, parent world, depth); `chain` holds the current root-to-node path.
    let mut stack: Vec<(usize, DMat4, usize)> =
        roots.iter().rev().map(|&r| (r, DMat4::IDENTITY, 1)).collect();
    let mut chain: Vec<usize> = Vec::new();
    while let Some((i, parent_world, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(err(i, GltfProblem::TooDeep { limit: MAX_DEPTH }));
        }
        if std::mem::replace(&mut visited[i], true) {
            return Err(err(i, GltfProblem::Cycle));
        }
        chain.truncate(depth - 1);
        chain.push(i);
        let node = &nodes[i];
        let exact = ext.transforms.get(i).and_then(Option::as_ref);
        let world = parent_world * local_matrix(path, node, exact)?;
        if !world.is_finite() {
            return Err(err(i, GltfProblem::WorldOverflow));
        }
        let gpu = ext.instancing.get(i).and_then(Option::as_ref);
        if let Some(mesh) = node.mesh() {
            skinned |= node.skin().is_some();
            let gpu = gpu.map(|g| check_gpu(r, accessors, i, g)).transpose()?;
            instances.push(Instance { node: i, mesh: mesh.index(), world, path: chain.clone(), gpu });
        } else if gpu.is_some() {
            warnings.push(format!("glTF node {i} has EXT_mesh_gpu_instancing but no mesh: ignored"));
        }
        let children: Vec<usize> = node.children().map(|c| c.index()).collect();
        for &c in children.iter().rev() {
            stack.push((c, world, depth + 1));
        }
    }
    if skinned {
        warnings.push("skins are ignored: skinned meshes are loaded in their bind pose".into());
    }
    Ok(instances)
}

/// A node on a cycle of the parent function, if any (iterative, O(n)).
fn find_cycle(parent: &[Option<usize>]) -> Option<usize> {
    // 0 = unseen, 1 = on the current walk, 2 = finished
    let mut state = vec![0u8; parent.len()];
    let mut walk = Vec::new();
    for start in 0..parent.len() {
        walk.clear();
        let mut cur = Some(start);
        while let Some(c) = cur {
            match state[c] {
                0 => {
                    state[c] = 1;
                    walk.push(c);
                    cur = parent[c];
                }
                1 => return Some(c),
                _ => break,
            }
        }
        for &w in &walk {
            state[w] = 2;
        }
    }
    None
}

/// The node's local matrix in f64, from the numbers of the JSON read as f64 (`exact`, from
/// [`Extensions::transforms`]); the `gltf` crate's f32 copy only when that is missing.
fn local_matrix(path: &Path, node: &::gltf::Node, exact: Option<&NodeTransform>) -> Result<DMat4> {
    let bad = |p: GltfProblem| Error::at(path, Location::Node(node.index()), p);
    let widened;
    let transform = match exact {
        Some(t) => t,
        None => {
            widened = match node.transform() {
                Transform::Matrix { matrix } => {
                    let cols = matrix.map(|c| c.map(f64::from));
                    NodeTransform::Matrix(std::array::from_fn(|k| cols[k / 4][k % 4]))
                }
                Transform::Decomposed { translation: t, rotation: r, scale: s } => {
                    NodeTransform::Trs { t: t.map(f64::from), r: r.map(f64::from), s: s.map(f64::from) }
                }
            };
            &widened
        }
    };
    match transform {
        NodeTransform::Matrix(m) => {
            if m.iter().any(|x| !x.is_finite()) {
                return Err(bad(GltfProblem::NonFiniteTransform { matrix: true }));
            }
            Ok(DMat4::from_cols_array(m))
        }
        NodeTransform::Trs { t, r, s } => {
            if t.iter().chain(r).chain(s).any(|x| !x.is_finite()) {
                return Err(bad(GltfProblem::NonFiniteTransform { matrix: false }));
            }
            let q = DQuat::from_array(*r);
            let len = q.length();
            if len == 0.0 || !len.is_finite() {
                return Err(bad(GltfProblem::ZeroQuaternion));
            }
            Ok(DMat4::from_scale_rotation_translation(DVec3::from_array(*s), q / len, DVec3::from_array(*t)))
        }
    }
}

/// Decodes every triangle primitive of mesh `m`; other modes are skipped with a warning.
fn decode_mesh(r: &Reader, doc: &Document, m: usize, warnings: &mut Vec<String>) -> Result<Vec<Prim>> {
    let Some(mesh) = doc.meshes().nth(m) else {
        return Ok(Vec::new());
    };
    let mut out: Vec<Prim> = Vec::new();
    let mut by_accessor: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for prim in mesh.primitives() {
        let what = format!("mesh {m} primitive {}", prim.index());
        let mode = prim.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            warnings.push(format!("{what}: skipped {mode:?} primitive (only triangles are loaded)"));
            continue;
        }
        let Some(acc) = prim.get(&::gltf::Semantic::Positions) else {
            warnings.push(format!("{what}: skipped primitive without POSITION"));
            continue;
        };
        if prim.morph_targets().len() > 0 {
            warnings.push(format!("{what}: morph targets ignored (base positions used)"));
        }
        let positions = r.positions(&acc, m, prim.index())?;
        let nv = positions.len();
        let out_of_range = |k: usize, v: u32| {
            let at = Location::Index { mesh: m, primitive: prim.index(), index: k };
            Error::at(r.path, at, InputProblem::IndexOutOfRange { index: v.into(), len: nv })
        };
        let (triangles, leftover) = match (mode, prim.indices()) {
            // A triangle list read straight into its triangles.
            (Mode::Triangles, Some(ia)) => {
                let (triangles, rest) = r.triangle_indices(&ia, m, prim.index())?;
                let all = triangles.iter().flatten().chain(&rest);
                if let Some((k, &v)) = all.enumerate().find(|(_, &v)| v as usize >= nv) {
                    return Err(out_of_range(k, v));
                }
                (triangles, rest.len())
            }
            (_, ia) => {
                let indices: Cow<[u32]> = match ia {
                    Some(ia) => Cow::Owned(r.indices(&ia, m, prim.index())?),
                    None => Cow::Owned((0..nv as u32).collect()),
                };
                if let Some((k, &v)) = indices.iter().enumerate().find(|(_, &v)| v as usize >= nv) {
                    return Err(out_of_range(k, v));
                }
                let leftover = match mode {
                    Mode::Triangles => indices.len() % 3,
                    _ if indices.len() < 3 => indices.len(),
                    _ => 0,
                };
                (triangulate(mode, &indices), leftover)
            }
        };
        if leftover > 0 {
            warnings
                .push(format!("{what}: {leftover} trailing indices do not form a triangle and were ignored"));
        }
        // A POSITION accessor used by an earlier primitive (with triangles) is read once.
        let shares = (!triangles.is_empty()).then(|| by_accessor.get(&acc.index()).copied()).flatten();
        if !triangles.is_empty() && shares.is_none() {
            by_accessor.insert(acc.index(), out.len());
        }
        let positions = if shares.is_some() {
            Vec::new()
        } else {
            positions.into_iter().map(DVec3::from_array).collect()
        };
        out.push(Prim { positions, triangles, shares });
    }
    Ok(out)
}

/// Triangles of a TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN index list.
fn triangulate(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => {
            (0..idx.len().saturating_sub(2))
                .map(|i| {
                    if i % 2 == 0 {
                        [idx[i], idx[i + 1], idx[i + 2]]
                    } else {
                        [idx[i], idx[i + 2], idx[i + 1]]
                    }
                })
                .collect()
        }
        Mode::TriangleFan => {
            (0..idx.len().saturating_sub(2)).map(|i| [idx[0], idx[i + 1], idx[i + 2]]).collect()
        }
        _ => Vec::new(),
    }
}

#[cfg(test)]
#[path = "gltf_tests.rs"]
mod tests;
