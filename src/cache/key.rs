//! The keys of the result cache: [`PartKey`] (a part's exact world-space triangles and its
//! name), [`Fingerprint`] (the settings that change an answer) and [`PairKey`] (two parts, the
//! settings and the tool version). Every key is a SHA-256 over a byte layout written out in the
//! doc comment of its constructor and pinned by a test vector.

use glam::DVec3;

use crate::check::assembly::Part;
use crate::scene::mesh::Mesh;
use crate::shard::sha256::Sha256;

/// The entry layout number: part of every [`PairKey`] and of every entry's header. Bump it when
/// the key layouts, the entry header or the meaning of a stored value change, so that entries
/// written before the change are never found.
pub const FORMAT: u32 = 5;

/// The tool version that goes into every [`PairKey`] and entry header: a cache written by
/// another version of meshclash is never read.
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");

const PART_TAG: &[u8] = b"meshclash.cache.part\0";
const SETTINGS_TAG: &[u8] = b"meshclash.cache.settings\0";
const PAIR_TAG: &[u8] = b"meshclash.cache.pair\0";
const MESH_TAG: &[u8] = b"meshclash.cache.mesh\0";
const SHAPE_TAG: &[u8] = b"meshclash.cache.part-shape\0";
const VERTICES_TAG: &[u8] = b"meshclash.cache.part-vertices\0";

/// A SHA-256 digest, the 32 bytes of every key.
pub type Digest = [u8; 32];

/// The digest of everything fed to `sha`, as bytes.
pub(crate) fn finish(sha: Sha256) -> Digest {
    sha.digest()
}

/// SHA-256 of `data`, as bytes.
pub(crate) fn digest(data: &[u8]) -> Digest {
    let mut sha = Sha256::default();
    sha.update(data);
    finish(sha)
}

/// `d` as 64 lowercase hex digits.
pub(crate) fn to_hex(d: &Digest) -> String {
    d.iter().map(|b| format!("{b:02x}")).collect()
}

/// The name of a model's index of earlier runs: `objects:` and the SHA-256 of its inputs'
/// object names (per input its object count, then each name's length and bytes). Content, not
/// file names: a model saved under another name or moved elsewhere finds its earlier runs, and
/// a moved or reshaped part keeps its model's index.
pub fn lineage(inputs: &[&Mesh]) -> String {
    lineage_of_names(inputs.iter().map(|m| m.objects.iter().map(|o| o.name.as_str()).collect()))
}

/// [`lineage`] of one instanced glTF scene: the same name its expanded mesh gives (its
/// objects are the scene's parts, in order).
pub fn lineage_of_scene(scene: &crate::load::InstancedScene) -> String {
    lineage_of_names(std::iter::once(scene.parts.iter().map(|p| p.name.as_str()).collect()))
}

fn lineage_of_names<'a>(inputs: impl Iterator<Item = Vec<&'a str>>) -> String {
    let mut sha = Sha256::default();
    for names in inputs {
        put_len(&mut sha, names.len());
        for name in names {
            put_len(&mut sha, name.len());
            sha.update(name.as_bytes());
        }
    }
    format!("objects:{}", to_hex(&finish(sha)))
}

fn put_len(sha: &mut Sha256, n: usize) {
    sha.update(&(n as u64).to_le_bytes());
}

/// The key of one part: its exact world-space triangles and its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PartKey(Digest);

impl PartKey {
    /// The key of part `name` whose world-space triangles (after placement and units) are
    /// `triangles`, in triangle order. The same as feeding them one by one to a [`PartHasher`].
    pub fn of(name: &str, triangles: impl IntoIterator<Item = [DVec3; 3]>) -> PartKey {
        let mut h = PartHasher::new(name);
        for t in triangles {
            h.triangle(t);
        }
        h.finish()
    }

    /// The key of the part of `mesh` made of triangles `triangles` (indices into
    /// `mesh.triangles`, in the part's order), named `name`. `mesh` must already be in world
    /// space (placed, in the run's units).
    pub fn of_mesh_part(name: &str, mesh: &Mesh, triangles: &[u32]) -> PartKey {
        PartKey::of(name, triangles.iter().map(|&t| crate::bvh::triangle(mesh, t)))
    }

    /// The keys of `parts` of `mesh` (world space), each named by its [`Part::name`], in the
    /// order of `parts`; computed in parallel (the keys do not depend on the thread count).
    pub fn of_parts(mesh: &Mesh, parts: &[Part]) -> Vec<PartKey> {
        use rayon::prelude::*;
        parts.par_iter().map(|p| PartKey::of_mesh_part(&p.name, mesh, &p.triangles)).collect()
    }

    /// The key of a whole input mesh in world space (placed, in the run's units): everything
    /// it holds, so everything a check of it can depend on — its triangle numbering (findings
    /// name triangles by index), its vertex sharing (closedness), its objects with their names,
    /// glTF meshes and world matrices (parts and instance sharing), and every vertex.
    ///
    /// The SHA-256 input, every integer little-endian, every f64 as `to_bits`: the tag
    /// `meshclash.cache.mesh` and a zero byte; the vertex count (u64) and each vertex's x, y,
    /// z; the triangle count (u64) and each triangle's three vertex indices (u32) and object
    /// index (u32); the object count (u64) and for each object its name's length (u64), the
    /// name, a byte `0`/`1` for its glTF mesh then that index (u32), a byte `0`/`1` for its
    /// world matrix then its 16 entries in column-major order.
    pub fn of_mesh(mesh: &Mesh) -> PartKey {
        let mut sha = Sha256::default();
        sha.update(MESH_TAG);
        let mut buf: Vec<u8> = Vec::with_capacity(1 << 16);
        let flush = |sha: &mut Sha256, buf: &mut Vec<u8>, force: bool| {
            if force || buf.len() >= 1 << 16 {
                sha.update(buf);
                buf.clear();
            }
        };
        put_len(&mut sha, mesh.positions.len());
        for p in &mesh.positions {
            for c in p.to_array() {
                buf.extend(c.to_bits().to_le_bytes());
            }
            flush(&mut sha, &mut buf, false);
        }
        flush(&mut sha, &mut buf, true);
        put_len(&mut sha, mesh.triangles.len());
        for (t, o) in mesh.triangles.iter().zip(&mesh.tri_object) {
            for v in t.iter().chain(std::iter::once(o)) {
                buf.extend(v.to_le_bytes());
            }
            flush(&mut sha, &mut buf, false);
        }
        flush(&mut sha, &mut buf, true);
        put_len(&mut sha, mesh.objects.len());
        for o in &mesh.objects {
            put_len(&mut sha, o.name.len());
            sha.update(o.name.as_bytes());
            match o.gltf_mesh {
                Some(m) => {
                    sha.update(&[1]);
                    sha.update(&m.to_le_bytes());
                }
                None => sha.update(&[0]),
            }
            match o.world {
                Some(w) => {
                    sha.update(&[1]);
                    for c in w.to_cols_array() {
                        sha.update(&c.to_bits().to_le_bytes());
                    }
                }
                None => sha.update(&[0]),
            }
        }
        PartKey(finish(sha))
    }

    /// The key of a part as a part-pair check sees it: its name, how its triangles share its
    /// vertices (closedness, winding and containment read the sharing) and its world-space
    /// vertices, independent of where its vertices sit in the file's vertex list, so a part
    /// keeps its key when other parts change.
    ///
    /// The part's vertices are numbered in order of first use by its triangles (as the check
    /// numbers them). Its *shape* digest is the SHA-256 of the tag
    /// `meshclash.cache.part-shape` and a zero byte, the triangle count (u64), then each
    /// triangle's three part-local vertex numbers (u32); the key is the SHA-256 of the tag
    /// `meshclash.cache.part-vertices` and a zero byte, the name's length (u64) and the name,
    /// the shape digest's 32 bytes, the vertex count (u64), then each vertex's x, y, z in that
    /// numbering. Every integer little-endian, every f64 as `to_bits`. `mesh` must be in world
    /// space (placed, in the run's units).
    ///
    /// The instances of one glTF mesh share their shape (their triangles index the mesh's
    /// vertices alike, one offset apart): [`PartKey::of_part_layouts`] hashes it once for all of
    /// them, and then only each instance's vertices.
    pub fn of_part_layout(name: &str, mesh: &Mesh, triangles: &[u32]) -> PartKey {
        let shape = Shape::of(mesh, triangles);
        shape.key(name, &mesh.positions, 0)
    }

    /// The keys of `parts` (see [`PartKey::of_part_layout`]), computed in parallel, in the
    /// order of `parts`; `meshes[p.input]` holds part `p`. The parts that instance one glTF mesh
    /// alike (the same triangles, their vertex numbers one offset apart) share one shape,
    /// numbered and hashed once; the keys are those [`PartKey::of_part_layout`] gives.
    pub fn of_part_layouts(meshes: [&Mesh; 2], parts: &[&Part]) -> Vec<PartKey> {
        use rayon::prelude::*;
        use std::collections::HashMap;
        let mut leader_of: HashMap<(u8, u32), usize> = HashMap::new();
        let leader: Vec<Option<usize>> = parts
            .iter()
            .enumerate()
            .map(|(j, p)| p.gltf_mesh.map(|m| *leader_of.entry((p.input, m)).or_insert(j)))
            .collect();
        // Each part's shape: its leader's, one vertex offset apart, when its triangles read
        // like the leader's; else its own.
        let shift: Vec<Option<(usize, i64)>> = (0..parts.len())
            .into_par_iter()
            .map(|j| {
                let l = leader[j].filter(|&l| l != j)?;
                let mesh = meshes[parts[j].input as usize];
                crate::check::assembly::shift_of(mesh, parts[l], parts[j]).map(|s| (l, s))
            })
            .collect();
        let own: Vec<usize> = (0..parts.len()).filter(|&j| shift[j].is_none()).collect();
        let shapes: HashMap<usize, Shape> = own
            .par_iter()
            .map(|&j| (j, Shape::of(meshes[parts[j].input as usize], &parts[j].triangles)))
            .collect();
        (0..parts.len())
            .into_par_iter()
            .map(|j| {
                let (l, s) = shift[j].unwrap_or((j, 0));
                shapes[&l].key(&parts[j].name, &meshes[parts[j].input as usize].positions, s)
            })
            .collect()
    }

    /// The keys of `parts` of an instanced glTF scene (each part's [`Part::object`] is its
    /// place in `scene.parts`), in the order of `parts`, computed in parallel: the keys
    /// [`PartKey::of_part_layout`] gives for the same parts of the scene's expanded mesh, so an
    /// instanced run and an expanded one find each other's results.
    ///
    /// They are the same function of the same bytes: a part placed
    /// ([`crate::load::InstancedScene::place`]) holds exactly the world vertices and
    /// triangles the expanded mesh holds for it, by the same arithmetic, its triangles' vertex
    /// numbers less the offset of its first vertex. Numbering vertices in order of first use
    /// does not see that offset, so the shape digest and the vertex order are the expanded
    /// part's. The instances of one glTF mesh index their vertices alike (the loader places
    /// their triangles unchanged, whatever the matrix), so the shape is hashed once per mesh
    /// and each instance then costs its placed vertices alone.
    pub fn of_placed_parts(scene: &crate::load::InstancedScene, parts: &[&Part]) -> Vec<PartKey> {
        use rayon::prelude::*;
        use std::collections::HashMap;
        let mesh_of = |p: &Part| scene.parts[p.object as usize].mesh;
        let mut leader_of: HashMap<u32, usize> = HashMap::new();
        for (j, p) in parts.iter().enumerate() {
            leader_of.entry(mesh_of(p)).or_insert(j);
        }
        let leaders: Vec<(u32, usize)> = leader_of.into_iter().collect();
        let shapes: HashMap<u32, Shape> = leaders
            .par_iter()
            .map(|&(m, j)| {
                // Placed alone (an empty part, if placing ever failed, would give a key no
                // expanded part has: a miss, never a hit).
                let (one, all) = crate::check::assembly::Source::Placed(scene).part_mesh(parts[j]);
                (m, Shape::of(&one, &all))
            })
            .collect();
        parts
            .par_iter()
            .map(|p| {
                let positions = scene.place_positions(p.object as usize);
                shapes[&mesh_of(p)].key(&p.name, &positions, 0)
            })
            .collect()
    }

    /// The 32 digest bytes.
    pub fn as_bytes(&self) -> &Digest {
        &self.0
    }

    /// The digest as 64 lowercase hex digits.
    pub fn hex(&self) -> String {
        to_hex(&self.0)
    }
}

/// Builds a [`PartKey`] triangle by triangle (for parts whose triangles are not in one slice).
///
/// The SHA-256 input is, in order, with every integer little-endian:
///
/// | bytes | content |
/// |---|---|
/// | 21 | the tag `meshclash.cache.part` and a zero byte |
/// | 8 | the name's length in bytes, u64 |
/// | n | the name, UTF-8 |
/// | 72 per triangle | the triangle's three vertices, x, y, z each: `f64::to_bits` as u64 |
/// | 8 | the number of triangles, u64 |
///
/// Bit patterns, not values: `-0.0` and `0.0` give different keys (a miss, never a wrong hit).
#[derive(Debug, Clone)]
pub struct PartHasher {
    sha: Sha256,
    triangles: u64,
}

impl PartHasher {
    /// Start the key of part `name`.
    pub fn new(name: &str) -> PartHasher {
        let mut sha = Sha256::default();
        sha.update(PART_TAG);
        put_len(&mut sha, name.len());
        sha.update(name.as_bytes());
        PartHasher { sha, triangles: 0 }
    }

    /// Add the next triangle (world space).
    pub fn triangle(&mut self, t: [DVec3; 3]) {
        let mut bytes = [0u8; 72];
        let coords = t.iter().flat_map(|v| [v.x, v.y, v.z]);
        for (chunk, c) in bytes.chunks_exact_mut(8).zip(coords) {
            chunk.copy_from_slice(&c.to_bits().to_le_bytes());
        }
        self.sha.update(&bytes);
        self.triangles += 1;
    }

    /// The key.
    pub fn finish(mut self) -> PartKey {
        self.sha.update(&self.triangles.to_le_bytes());
        PartKey(finish(self.sha))
    }
}

/// One setting's value, as the settings [`Fingerprint`] encodes it. Each kind has its own tag,
/// so `3_u64` and `3.0_f64` are different settings.
#[derive(Debug, Clone, PartialEq)]
pub enum Setting {
    /// Absent (an unset optional setting).
    None,
    /// A flag.
    Bool(bool),
    /// A whole number.
    U64(u64),
    /// A signed whole number.
    I64(i64),
    /// A number, by its bit pattern (`-0.0` and `0.0` differ).
    F64(f64),
    /// A text (a mode, a detail level, a list rendered canonically by the caller).
    Str(String),
}

impl Setting {
    /// Append this value's bytes: a tag byte then the value, integers little-endian.
    fn encode(&self, out: &mut Vec<u8>) {
        match self {
            Setting::None => out.push(0),
            Setting::Bool(b) => out.extend([1, u8::from(*b)]),
            Setting::U64(v) => {
                out.push(2);
                out.extend(v.to_le_bytes());
            }
            Setting::I64(v) => {
                out.push(3);
                out.extend(v.to_le_bytes());
            }
            Setting::F64(v) => {
                out.push(4);
                out.extend(v.to_bits().to_le_bytes());
            }
            Setting::Str(s) => {
                out.push(5);
                out.extend((s.len() as u64).to_le_bytes());
                out.extend(s.as_bytes());
            }
        }
    }
}

impl From<bool> for Setting {
    fn from(v: bool) -> Self {
        Setting::Bool(v)
    }
}
impl From<u64> for Setting {
    fn from(v: u64) -> Self {
        Setting::U64(v)
    }
}
impl From<u32> for Setting {
    fn from(v: u32) -> Self {
        Setting::U64(v.into())
    }
}
impl From<usize> for Setting {
    fn from(v: usize) -> Self {
        Setting::U64(v as u64)
    }
}
impl From<i64> for Setting {
    fn from(v: i64) -> Self {
        Setting::I64(v)
    }
}
impl From<f64> for Setting {
    fn from(v: f64) -> Self {
        Setting::F64(v)
    }
}
impl From<&str> for Setting {
    fn from(v: &str) -> Self {
        Setting::Str(v.to_string())
    }
}
impl From<String> for Setting {
    fn from(v: String) -> Self {
        Setting::Str(v)
    }
}
impl<T: Into<Setting>> From<Option<T>> for Setting {
    fn from(v: Option<T>) -> Self {
        v.map_or(Setting::None, Into::into)
    }
}

/// The fingerprint of the settings that change a part pair's answer (tolerances, mode, detail,
/// pair limits, penetration, …): whatever is not in it must not change a stored value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fingerprint(Digest);

impl Fingerprint {
    /// The fingerprint of `(name, value)` pairs, in any order: it is a function of the set of
    /// pairs, so callers cannot get the order wrong.
    ///
    /// Each pair is encoded as a record: the name's length (u64, little-endian), the name
    /// (UTF-8), then the value ([`Setting`]: a tag byte `0` none, `1` bool, `2` u64, `3` i64,
    /// `4` f64 bits, `5` text, followed by the value: one byte for a bool, 8 bytes
    /// little-endian for numbers, length u64 then UTF-8 for text). The records are sorted
    /// bytewise; the SHA-256 input is the tag `meshclash.cache.settings` and a zero byte, the
    /// record count (u64), then the sorted records.
    pub fn of<'a>(settings: impl IntoIterator<Item = (&'a str, Setting)>) -> Fingerprint {
        let mut records: Vec<Vec<u8>> = settings
            .into_iter()
            .map(|(name, value)| {
                let mut r = (name.len() as u64).to_le_bytes().to_vec();
                r.extend(name.as_bytes());
                value.encode(&mut r);
                r
            })
            .collect();
        records.sort_unstable();
        let mut sha = Sha256::default();
        sha.update(SETTINGS_TAG);
        put_len(&mut sha, records.len());
        for r in &records {
            sha.update(r);
        }
        Fingerprint(finish(sha))
    }

    /// The 32 digest bytes.
    pub fn as_bytes(&self) -> &Digest {
        &self.0
    }

    /// The digest as 64 lowercase hex digits.
    pub fn hex(&self) -> String {
        to_hex(&self.0)
    }
}

/// The key of one part pair's result: the A-side part, the B-side part (in that order: the
/// pair (x, y) and the pair (y, x) are different keys), the settings and the tool version.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PairKey(Digest);

impl PairKey {
    /// The key of the result of part `a` (A side) against part `b` (B side) under `settings`,
    /// for this build ([`TOOL_VERSION`], [`FORMAT`]).
    ///
    /// The SHA-256 input: the tag `meshclash.cache.pair` and a zero byte, the 32 bytes of `a`,
    /// the 32 bytes of `b`, the 32 bytes of `settings`, [`FORMAT`] (u32, little-endian), the
    /// tool version's length (u64, little-endian) and the version (UTF-8).
    pub fn new(a: &PartKey, b: &PartKey, settings: &Fingerprint) -> PairKey {
        PairKey::for_version(a, b, settings, TOOL_VERSION, FORMAT)
    }

    /// A key made of a digest computed elsewhere (the result cache's run indexes and packs,
    /// whose layouts [`super::pairs`] describes).
    pub(crate) fn from_digest(d: Digest) -> PairKey {
        PairKey(d)
    }

    pub(crate) fn for_version(
        a: &PartKey,
        b: &PartKey,
        settings: &Fingerprint,
        version: &str,
        format: u32,
    ) -> PairKey {
        let mut sha = Sha256::default();
        sha.update(PAIR_TAG);
        sha.update(&a.0);
        sha.update(&b.0);
        sha.update(&settings.0);
        sha.update(&format.to_le_bytes());
        put_len(&mut sha, version.len());
        sha.update(version.as_bytes());
        PairKey(finish(sha))
    }

    /// The 32 digest bytes.
    pub fn as_bytes(&self) -> &Digest {
        &self.0
    }

    /// The digest as 64 lowercase hex digits.
    pub fn hex(&self) -> String {
        to_hex(&self.0)
    }
}

/// A part's triangles as the check reads them: its vertices numbered in order of first use
/// (`vmap[v]`, the mesh vertex of part-local vertex `v`) and the digest of its triangles in
/// that numbering (see [`PartKey::of_part_layout`]).
struct Shape {
    vmap: Vec<u32>,
    digest: Digest,
}

impl Shape {
    fn of(mesh: &Mesh, triangles: &[u32]) -> Shape {
        let mut sha = Sha256::default();
        sha.update(SHAPE_TAG);
        put_len(&mut sha, triangles.len());
        let corners = || triangles.iter().flat_map(|&t| mesh.triangles[t as usize]);
        let (lo, hi) = corners().fold((u32::MAX, 0u32), |(lo, hi), v| (lo.min(v), hi.max(v)));
        // Local numbers by a dense table over the part's index range (parts are nearly always
        // one run of the file's vertices); a map when the range is sparse.
        let span = if triangles.is_empty() { 0 } else { (hi - lo) as usize + 1 };
        let dense = span <= 3 * triangles.len() + 64;
        let mut table: Vec<u32> = if dense { vec![u32::MAX; span] } else { Vec::new() };
        let mut map: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
        let mut vmap: Vec<u32> = Vec::new();
        let mut buf: Vec<u8> = Vec::with_capacity(1 << 16);
        for v in corners() {
            let slot = if dense { &mut table[(v - lo) as usize] } else { map.entry(v).or_insert(u32::MAX) };
            if *slot == u32::MAX {
                *slot = vmap.len() as u32;
                vmap.push(v);
            }
            buf.extend(slot.to_le_bytes());
            if buf.len() >= 1 << 16 {
                sha.update(&buf);
                buf.clear();
            }
        }
        sha.update(&buf);
        Shape { vmap, digest: finish(sha) }
    }

    /// The key of the part named `name` of this shape whose vertex `v` is mesh vertex
    /// `positions[vmap[v] + shift]`.
    fn key(&self, name: &str, positions: &[DVec3], shift: i64) -> PartKey {
        let mut sha = Sha256::default();
        sha.update(VERTICES_TAG);
        put_len(&mut sha, name.len());
        sha.update(name.as_bytes());
        sha.update(&self.digest);
        put_len(&mut sha, self.vmap.len());
        let mut buf: Vec<u8> = Vec::with_capacity(1 << 16);
        for &v in &self.vmap {
            let p = positions[(v as i64 + shift) as usize];
            for c in [p.x, p.y, p.z] {
                buf.extend(c.to_bits().to_le_bytes());
            }
            if buf.len() >= 1 << 16 {
                sha.update(&buf);
                buf.clear();
            }
        }
        sha.update(&buf);
        PartKey(finish(sha))
    }
}
