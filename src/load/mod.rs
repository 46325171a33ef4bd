//! File loaders: OBJ, STL (ASCII and binary), glTF 2.0 (`.gltf` and `.glb`).
//!
//! [`load_path`] reads a file, detects its format ([`detect_format`]: by extension, confirmed
//! by content), parses it and validates the result. Every loader guarantees, or fails with a
//! one-line [`Error::Input`] naming the file:
//!
//! - at least one triangle;
//! - every triangle index in range;
//! - every coordinate finite (NaN and ±infinity are reported);
//! - `tri_object.len() == triangles.len()`, every `tri_object` entry indexes `objects`, and
//!   every object has a non-empty name. Objects that end up without triangles are dropped.
//!
//! Degenerate triangles (zero area, repeated index) are kept: callers count them.
//!
//! Hostile input: no loader panics, and no loader allocates from a count declared in the file
//! (STL triangle count, GLB chunk length, glTF buffer length, accessor count) before checking
//! the data holding it is present.

use std::path::Path;

use crate::error::{Error, FileKind, InputProblem, Location, NonFinite, Reading, Result};
use crate::scene::mesh::Loaded;

/// The most triangles one input may make (2^28, 4 GiB of triangles and part ids): a glTF scene
/// after instancing, an OBJ file after fan triangulation. Checked before the triangles are
/// allocated (glTF) or as they are made (OBJ).
pub const MAX_TRIANGLES: usize = 1 << 28;

pub use obj::MAX_FACE_VERTICES;

/// What a check needs per triangle of a glTF scene after instancing, beyond the 24 bytes per
/// vertex of its world positions: the triangle and its part id (16 bytes) plus trees, topology
/// and pair lists (measured: ~90–100 bytes per triangle in all at peak on generated 1M-triangle
/// tori and on 2CylinderEngine instanced 100 times). An estimate, used only to refuse up front a
/// scene that cannot fit.
pub const CHECK_BYTES_PER_TRIANGLE: u64 = 100;

/// What a check needs per part of a glTF scene after instancing (a node instance or a GPU
/// instance), whatever its triangles: its object (name, world matrix: ~190 bytes), the
/// loader's instance record, and the check's per-part records, trees and lists. Measured as
/// the growth of peak memory with the part count of one-triangle parts: `scene` on 250,000
/// and 500,000 GPU instances of one triangle (`--threads 1`) peaked at 262 MiB and 556 MiB,
/// 1,232 bytes per part, of which ~170 are its triangle and three vertices. An estimate,
/// used only to refuse up front.
pub const CHECK_BYTES_PER_PART: u64 = 1_100;

/// The memory a glTF scene's check is estimated to need: 24 bytes per vertex (its world
/// positions), [`CHECK_BYTES_PER_TRIANGLE`] per triangle and [`CHECK_BYTES_PER_PART`] per part.
pub fn scene_estimate(vertices: u64, triangles: u64, parts: u64) -> u64 {
    vertices
        .saturating_mul(24)
        .saturating_add(triangles.saturating_mul(CHECK_BYTES_PER_TRIANGLE))
        .saturating_add(parts.saturating_mul(CHECK_BYTES_PER_PART))
}

/// What a check of a glTF scene kept instanced needs per triangle after instancing: the world
/// coordinates are placed a part at a time, so what stays is each part's list of its
/// triangles' numbers (4 bytes) and the check's share (measured: `scene --detail parts` on
/// 2CylinderEngine instanced 100 times, 12.1 million triangles, peaked at 140 MiB, 12 bytes
/// per triangle, the meshes decoded once included). An estimate, used only to refuse up front.
pub const INSTANCED_BYTES_PER_TRIANGLE: u64 = 12;

/// The memory a glTF scene's check is estimated to need when its instances are kept, not
/// expanded: [`INSTANCED_BYTES_PER_TRIANGLE`] per triangle and [`CHECK_BYTES_PER_PART`] per
/// part (what is kept per part is the same on both paths).
pub fn instanced_scene_estimate(triangles: u64, parts: u64) -> u64 {
    triangles
        .saturating_mul(INSTANCED_BYTES_PER_TRIANGLE)
        .saturating_add(parts.saturating_mul(CHECK_BYTES_PER_PART))
}

/// The memory this process may still use, in bytes: the least of the machine's available
/// memory (`MemAvailable`), the cgroup's limit less its usage, and the address-space limit
/// (`ulimit -v`) less what is mapped. `None` where none of them can be read.
pub fn available_memory() -> Option<u64> {
    fn read(p: &str) -> Option<String> {
        std::fs::read_to_string(p).ok()
    }
    fn field_kib(text: &str, key: &str) -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line[key.len()..].split_whitespace().next()?.parse::<u64>().ok().map(|k| k * 1024)
    }
    let mut best: Option<u64> = None;
    let mut take = |v: Option<u64>| {
        if let Some(v) = v {
            best = Some(best.map_or(v, |b| b.min(v)));
        }
    };
    take(read("/proc/meminfo").and_then(|t| field_kib(&t, "MemAvailable:")));
    let cg = |f: &str| read(&format!("/sys/fs/cgroup/{f}")).and_then(|t| t.trim().parse::<u64>().ok());
    if let (Some(max), Some(cur)) = (cg("memory.max"), cg("memory.current")) {
        take(Some(max.saturating_sub(cur)));
    }
    let limit = read("/proc/self/limits").and_then(|t| {
        let l = t.lines().find(|l| l.starts_with("Max address space"))?.to_string();
        l["Max address space".len()..].split_whitespace().next()?.parse::<u64>().ok()
    });
    if let Some(limit) = limit {
        let mapped = read("/proc/self/status").and_then(|t| field_kib(&t, "VmSize:")).unwrap_or(0);
        take(Some(limit.saturating_sub(mapped)));
    }
    best
}

mod gltf;
mod gltf_data;
pub use gltf::{InstancedScene, ScenePart};
mod obj;
mod stl;

/// A supported input file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// glTF 2.0 JSON (`.gltf`), buffers embedded as data URIs or in external files.
    Gltf,
    /// glTF 2.0 binary container (`.glb`).
    Glb,
}

impl Format {
    /// The short lowercase name: `"obj"`, `"stl"`, `"gltf"` or `"glb"`.
    pub fn name(&self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Stl => "stl",
            Format::Gltf => "gltf",
            Format::Glb => "glb",
        }
    }
}

/// Reads `path`, detects its format, loads and validates it.
///
/// A missing or unreadable file is an [`Error::Input`] naming the path. A path that is not a
/// regular file (a FIFO, a device such as `/dev/zero`, a socket, a directory) is refused before
/// it is opened, so a FIFO cannot block the run and a device cannot stream without end
///. Symlinks are followed: the link's target must be a regular file.
pub fn load_path(path: &Path) -> Result<(Loaded, Format)> {
    let obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if obj {
        if let Some(loaded) = load_obj_streamed(path)? {
            return Ok((loaded, Format::Obj));
        }
    }
    let bytes = read_regular_file(path, Reading::File, u64::MAX)?;
    let format = detect_format(path, &bytes)?;
    let loaded = load_bytes(path, &bytes, format)?;
    Ok((loaded, format))
}

/// An OBJ file parsed as it is read, a chunk at a time ([`obj::load_file`]), with the checks
/// and errors of [`load_path`]: its head is checked as [`detect_format`] checks it, the mesh
/// validated. `None` when the fast path declines or the file cannot be read so: [`load_path`]
/// then reads it whole, and reports what it finds.
fn load_obj_streamed(path: &Path) -> Result<Option<Loaded>> {
    use std::os::unix::fs::FileExt;
    let (f, size) = open_regular(path, Reading::File)?;
    let mut head = vec![0u8; size.min(4096) as usize];
    if f.read_exact_at(&mut head, 0).is_err() {
        return Ok(None);
    }
    detect_format(path, &head)?;
    let Some(loaded) = obj::load_file(&f, size) else { return Ok(None) };
    validate(path, &loaded)?;
    Ok(Some(loaded))
}

/// The most bytes a plan, shard report, baseline or clash-set file may have (1 GiB): read
/// whole into memory and parsed, so bounded.
pub const MAX_SMALL_FILE_BYTES: u64 = 1 << 30;

/// Reads a file meshclash reads whole besides the meshes (a plan, shard report, baseline or
/// clash-set file), `reading` saying which: [`read_regular_file`] with at most `limit` bytes.
pub fn read_small_file(path: &Path, reading: Reading, limit: u64) -> Result<Vec<u8>> {
    read_regular_file(path, reading, limit)
}

/// Opens `path` for reading and checks it is a regular file, without blocking: the file is
/// opened with `O_NONBLOCK` (so a FIFO without a writer does not block the open) and the
/// *opened* file is checked (`fstat`), so a path swapped between a check and the open cannot
/// slip a FIFO or device through. Symlinks are followed. Returns the file and its size.
pub fn open_regular(path: &Path, reading: Reading) -> Result<(std::fs::File, u64)> {
    use std::os::unix::fs::OpenOptionsExt;
    let cannot = |e: std::io::Error| Error::in_file(path, unreadable(reading.clone(), &e));
    let nonblock = rustix::fs::OFlags::NONBLOCK.bits() as i32;
    let f = std::fs::OpenOptions::new().read(true).custom_flags(nonblock).open(path).map_err(cannot)?;
    let meta = f.metadata().map_err(cannot)?;
    if !meta.is_file() {
        return Err(Error::in_file(path, InputProblem::NotARegularFile { kind: file_kind(&meta) }));
    }
    Ok((f, meta.len()))
}

/// Reads the regular file `path` whole ([`open_regular`]): at most `limit` bytes, else a
/// one-line error naming the file, its size and the limit (checked on the size before
/// reading, and again while reading, in case the file grows).
pub fn read_regular_file(path: &Path, reading: Reading, limit: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let (f, size) = open_regular(path, reading.clone())?;
    let too_large = |size: u64| {
        let msg = format!("the file has {size} bytes, more than the {limit} bytes supported");
        Error::in_file(path, InputProblem::Invalid(msg))
    };
    if size > limit {
        return Err(too_large(size));
    }
    let mut bytes = Vec::with_capacity(size as usize);
    f.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| Error::in_file(path, unreadable(reading, &e)))?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Every file reading `path` as an input reads: `path` itself and, for a glTF (`.gltf` or
/// `.glb`), the external files its buffers and images name (resolved next to it, as the loader
/// resolves buffers; `data:` URIs and references the loader refuses are not files it reads).
/// An output naming any of them would overwrite the model ([`crate::output::write`]).
/// Best effort and never an error: a file that cannot be read or parsed here yields just
/// `path`, and loading it reports the problem.
pub fn files_read(path: &Path) -> Vec<std::path::PathBuf> {
    let mut out = vec![path.to_path_buf()];
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("gltf" | "glb")) {
        return out;
    }
    let Ok(json) = gltf_json_of(path) else { return out };
    out.extend(gltf_data::external_files(path, &json));
    out
}

/// The JSON of the glTF `path`: the whole file, or a GLB's JSON chunk (only it is read).
fn gltf_json_of(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let (mut f, size) = open_regular(path, Reading::File)?;
    let mut head = [0u8; 20];
    let n = f.read(&mut head).map_err(|e| Error::in_file(path, unreadable(Reading::File, &e)))?;
    if n >= 4 && &head[..4] == b"glTF" {
        // Header (12 bytes), then the first chunk's length and type: JSON.
        f.read_exact(&mut head[n.min(20)..])
            .map_err(|e| Error::in_file(path, unreadable(Reading::File, &e)))?;
        let len = u32::from_le_bytes([head[12], head[13], head[14], head[15]]) as u64;
        if &head[16..20] != b"JSON" || len > size {
            return Err(Error::in_file(path, InputProblem::Invalid("no JSON chunk".into())));
        }
        let mut json = Vec::with_capacity(len as usize);
        f.take(len)
            .read_to_end(&mut json)
            .map_err(|e| Error::in_file(path, unreadable(Reading::File, &e)))?;
        return Ok(json);
    }
    let mut json = head[..n].to_vec();
    f.read_to_end(&mut json).map_err(|e| Error::in_file(path, unreadable(Reading::File, &e)))?;
    Ok(json)
}

/// The kind of a non-regular file.
fn file_kind(meta: &std::fs::Metadata) -> FileKind {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        FileKind::Directory
    } else if t.is_fifo() {
        FileKind::Fifo
    } else if t.is_char_device() {
        FileKind::CharDevice
    } else if t.is_block_device() {
        FileKind::BlockDevice
    } else if t.is_socket() {
        FileKind::Socket
    } else {
        FileKind::Other
    }
}

/// Loads `bytes` as `format` and validates the result.
///
/// `path` is used in error messages and, for glTF, to resolve external buffers relative to
/// the file's directory.
pub fn load_bytes(path: &Path, bytes: &[u8], format: Format) -> Result<Loaded> {
    if bytes.is_empty() {
        return Err(Error::in_file(path, InputProblem::Empty));
    }
    let loaded = match format {
        Format::Obj => obj::load(path, bytes)?,
        Format::Stl => stl::load(path, bytes)?,
        Format::Gltf | Format::Glb => gltf::load(path, bytes)?,
    };
    validate(path, &loaded)?;
    Ok(loaded)
}

/// Loads glTF or GLB `bytes` without expanding its instances: each mesh once in its own
/// coordinates and every part as (mesh, world matrix), with every check and error of
/// [`load_bytes`] made in the same order; [`InstancedScene::expand`] then gives what
/// [`load_bytes`] gives, and [`InstancedScene::place`] one part of it.
pub fn load_gltf_instanced(path: &Path, bytes: &[u8]) -> Result<InstancedScene> {
    if bytes.is_empty() {
        return Err(Error::in_file(path, InputProblem::Empty));
    }
    let scene = gltf::load_instanced(path, bytes)?;
    if scene.parts.is_empty() {
        return Err(Error::in_file(path, InputProblem::NoTriangles));
    }
    Ok(scene)
}

/// Detects the format from the extension of `path` (case-insensitive `.obj`, `.stl`, `.gltf`,
/// `.glb`) and confirms it from the content.
///
/// For `.stl` this also decides ASCII versus binary viability: a file that is neither an
/// exactly-sized binary STL nor ASCII STL is reported as truncated here. For `.gltf`/`.glb`
/// the content decides between [`Format::Gltf`] (JSON) and [`Format::Glb`] (binary magic).
pub fn detect_format(path: &Path, bytes: &[u8]) -> Result<Format> {
    let ext = match path.extension() {
        Some(e) => e.to_string_lossy().to_ascii_lowercase(),
        None => return Err(Error::in_file(path, InputProblem::NoExtension)),
    };
    let format = match ext.as_str() {
        "obj" => Format::Obj,
        "stl" => Format::Stl,
        "gltf" => Format::Gltf,
        "glb" => Format::Glb,
        _ => return Err(Error::in_file(path, InputProblem::UnknownExtension(ext))),
    };
    if bytes.is_empty() {
        return Err(Error::in_file(path, InputProblem::Empty));
    }
    match format {
        Format::Obj => {
            let head = &bytes[..bytes.len().min(4096)];
            if let Some(pos) = head.iter().position(|&b| b == 0) {
                return Err(Error::at(path, Location::Byte(pos as u64), InputProblem::NotText));
            }
            Ok(Format::Obj)
        }
        Format::Stl => {
            stl::check_viable(path, bytes)?;
            Ok(Format::Stl)
        }
        Format::Gltf | Format::Glb => {
            if bytes.starts_with(b"glTF") {
                Ok(Format::Glb)
            } else if bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{')
                || bytes.starts_with(&[0xEF, 0xBB, 0xBF, b'{'])
            {
                Ok(Format::Gltf)
            } else {
                let start = bytes[..bytes.len().min(8)].to_vec();
                Err(Error::in_file(path, InputProblem::NotGltf { start }))
            }
        }
    }
}

/// Checks the guarantees listed in the module doc.
fn validate(path: &Path, loaded: &Loaded) -> Result<()> {
    let mesh = &loaded.mesh;
    if mesh.triangles.is_empty() {
        return Err(Error::in_file(path, InputProblem::NoTriangles));
    }
    if mesh.tri_object.len() != mesh.triangles.len() {
        let msg = format!("{} triangles but {} object entries", mesh.triangles.len(), mesh.tri_object.len());
        return Err(Error::in_file(path, InputProblem::Internal(msg)));
    }
    let n = mesh.positions.len();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            if v as usize >= n {
                let problem = InputProblem::IndexOutOfRange { index: v.into(), len: n };
                return Err(Error::at(path, Location::Triangle(t), problem));
            }
        }
    }
    for (i, p) in mesh.positions.iter().enumerate() {
        if let Some(value) = non_finite([p.x, p.y, p.z]) {
            return Err(Error::at(path, Location::Vertex(i), InputProblem::NonFinite { value }));
        }
    }
    for (t, &o) in mesh.tri_object.iter().enumerate() {
        if o as usize >= mesh.objects.len() {
            let msg =
                format!("triangle {t} belongs to object {o} but there are {} objects", mesh.objects.len());
            return Err(Error::in_file(path, InputProblem::Internal(msg)));
        }
    }
    if let Some(i) = mesh.objects.iter().position(|o| o.name.is_empty()) {
        return Err(Error::in_file(path, InputProblem::Internal(format!("object {i} has no name"))));
    }
    Ok(())
}

/// The first non-finite value (NaN, inf or -inf; displayed so), else `None`.
pub(crate) fn non_finite<const N: usize>(v: [f64; N]) -> Option<NonFinite> {
    NonFinite::first(v)
}

/// An unreadable file: the error's kind and its text without the trailing ` (os error N)`.
pub(crate) fn unreadable(reading: Reading, e: &std::io::Error) -> InputProblem {
    InputProblem::Unreadable { reading, kind: e.kind(), reason: io_message(e) }
}

/// An I/O error as text without the trailing ` (os error N)`.
pub(crate) fn io_message(e: &std::io::Error) -> String {
    let s = e.to_string();
    match s.find(" (os error ") {
        Some(i) if s.ends_with(')') => s[..i].to_string(),
        _ => s,
    }
}

pub(crate) use crate::error::clip;

/// Drops objects without triangles and renumbers `tri_object`, keeping first-appearance order.
pub(crate) fn drop_empty_objects(mesh: &mut crate::scene::mesh::Mesh) {
    let mut used = vec![false; mesh.objects.len()];
    for &o in &mesh.tri_object {
        if let Some(u) = used.get_mut(o as usize) {
            *u = true;
        }
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut remap = vec![u32::MAX; used.len()];
    let mut kept = Vec::new();
    for (i, obj) in std::mem::take(&mut mesh.objects).into_iter().enumerate() {
        if used[i] {
            remap[i] = kept.len() as u32;
            kept.push(obj);
        }
    }
    mesh.objects = kept;
    for o in &mut mesh.tri_object {
        if let Some(&r) = remap.get(*o as usize) {
            *o = r;
        }
    }
}

/// Locates a test mesh: the repository's own copies (`meshes/`, `tests/data/meshes/`) first, then
/// the corpus in `$MESHCLASH_SHARED_MESHES` or `../shared/meshes` next to the crate; `None` (the
/// test skips, saying so) when it is nowhere. With `CI` set and the corpus present, a missing
/// file is a failure, not a skip.
#[cfg(test)]
pub(crate) fn shared(name: &str) -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let corpus = std::env::var_os("MESHCLASH_SHARED_MESHES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/meshes"));
    let candidates = [root.join("meshes"), root.join("tests/data/meshes"), corpus.clone()];
    for dir in candidates {
        let p = dir.join(name);
        if p.is_file() {
            return Some(p);
        }
    }
    assert!(
        !(std::env::var_os("CI").is_some() && corpus.is_dir()),
        "{name} is missing from the corpus at {}",
        corpus.display()
    );
    eprintln!("skipping: test mesh {name} not found (set MESHCLASH_SHARED_MESHES to the corpus)");
    None
}

/// A fixed-seed xorshift generator for the loaders' mutation tests: `rnd(n)` is in `0..n`.
#[cfg(test)]
pub(crate) fn test_rng(mut seed: u64) -> impl FnMut(usize) -> usize {
    move |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n.max(1) as u64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn p(s: &str) -> PathBuf {
        PathBuf::from(s)
    }

    #[test]
    fn format_names() {
        assert_eq!(Format::Obj.name(), "obj");
        assert_eq!(Format::Stl.name(), "stl");
        assert_eq!(Format::Gltf.name(), "gltf");
        assert_eq!(Format::Glb.name(), "glb");
    }

    #[test]
    fn detect_by_extension_case_insensitive() {
        assert_eq!(detect_format(&p("a.OBJ"), b"v 0 0 0\n").unwrap(), Format::Obj);
        assert_eq!(detect_format(&p("a.Gltf"), b" {}").unwrap(), Format::Gltf);
        assert_eq!(detect_format(&p("a.GLB"), b"glTF....").unwrap(), Format::Glb);
        let stl = b"solid x\nfacet normal 0 0 1\nendfacet\nendsolid x\n";
        assert_eq!(detect_format(&p("a.StL"), stl).unwrap(), Format::Stl);
    }

    #[test]
    fn detect_errors() {
        let e = detect_format(&p("mesh.ply"), b"ply").unwrap_err().to_string();
        assert!(e.contains("unknown extension '.ply' (expected .obj, .stl, .gltf or .glb)"), "{e}");
        assert!(e.starts_with("mesh.ply: "), "{e}");
        let e = detect_format(&p("mesh"), b"x").unwrap_err().to_string();
        assert!(e.contains("no file extension"), "{e}");
        let e = detect_format(&p("a.obj"), b"").unwrap_err().to_string();
        assert!(e.contains("file is empty"), "{e}");
        let e = detect_format(&p("a.glb"), b"PK\x03\x04zip").unwrap_err().to_string();
        assert!(e.contains("not a glTF file"), "{e}");
        let e = detect_format(&p("a.obj"), b"v 1 2\0 3").unwrap_err().to_string();
        assert!(e.contains("NUL byte at byte 5"), "{e}");
    }

    #[test]
    fn load_path_missing_file_names_path() {
        let e = load_path(Path::new("/nonexistent/dir/x.stl")).unwrap_err().to_string();
        assert!(e.starts_with("/nonexistent/dir/x.stl: cannot read file:"), "{e}");
        assert!(e.contains("No such file"), "{e}");
    }

    #[test]
    fn fifo_input_is_refused_without_hanging() {
        // Before the non-blocking open, this opened the FIFO and blocked forever with no writer.
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("f.obj");
        let status = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(status.success());
        let e = load_path(&fifo).unwrap_err().to_string();
        assert!(e.contains("f.obj: not a regular file (a FIFO)"), "{e}");
    }

    #[test]
    fn small_file_reader_refuses_fifo_directory_device_large_and_missing() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("plan.json");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        // A FIFO without a writer: refused at once (a blocking open would never return).
        let e = read_small_file(&fifo, Reading::Plan, 1 << 20).unwrap_err().to_string();
        assert!(e.contains("plan.json: not a regular file (a FIFO)"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        let e = read_small_file(dir.path(), Reading::Baseline, 1 << 20).unwrap_err().to_string();
        assert!(e.contains("not a regular file (a directory)"), "{e}");
        let e =
            read_small_file(Path::new("/dev/zero"), Reading::ShardReport, 1 << 20).unwrap_err().to_string();
        assert!(e.contains("/dev/zero: not a regular file (a character device)"), "{e}");
        let big = dir.path().join("big.json");
        std::fs::write(&big, vec![b' '; 1001]).unwrap();
        let e = read_small_file(&big, Reading::ClashSet, 1000).unwrap_err().to_string();
        assert!(e.contains("big.json") && e.contains("1001 bytes") && e.contains("1000 bytes"), "{e}");
        assert_eq!(read_small_file(&big, Reading::ClashSet, 1001).unwrap().len(), 1001);
        let e = read_small_file(&dir.path().join("gone.json"), Reading::Baseline, 10).unwrap_err();
        let e = e.to_string();
        assert!(e.contains("gone.json") && e.contains("No such file"), "{e}");
    }

    #[test]
    fn files_read_lists_external_buffers_and_images() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let json = r#"{"asset":{"version":"2.0"},
            "buffers":[{"uri":"geo%20a.bin","byteLength":4},{"uri":"data:application/octet-stream;base64,AAAA","byteLength":3},
                       {"uri":"../up.bin","byteLength":1},{"byteLength":2}],
            "images":[{"uri":"tex.png"},{"bufferView":0}]}"#;
        std::fs::write(d.join("m.gltf"), json).unwrap();
        let got = files_read(&d.join("m.gltf"));
        assert_eq!(got, [d.join("m.gltf"), d.join("geo a.bin"), d.join("tex.png")]);
        // A GLB: only its JSON chunk is read.
        let mut chunk =
            br#"{"asset":{"version":"2.0"},"buffers":[{"uri":"ext.bin","byteLength":4}]}"#.to_vec();
        while !chunk.len().is_multiple_of(4) {
            chunk.push(b' ');
        }
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend((20 + chunk.len() as u32).to_le_bytes());
        glb.extend((chunk.len() as u32).to_le_bytes());
        glb.extend(b"JSON");
        glb.extend(&chunk);
        std::fs::write(d.join("m.glb"), &glb).unwrap();
        assert_eq!(files_read(&d.join("m.glb")), [d.join("m.glb"), d.join("ext.bin")]);
        // Anything else, or a glTF that does not parse: the file alone.
        assert_eq!(files_read(&d.join("a.obj")), [d.join("a.obj")]);
        std::fs::write(d.join("bad.gltf"), "{").unwrap();
        assert_eq!(files_read(&d.join("bad.gltf")), [d.join("bad.gltf")]);
    }

    #[test]
    fn dev_zero_input_is_refused_up_front() {
        // Before the fix /dev/zero was read until memory ran out.
        let e = load_path(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.starts_with("/dev/zero: not a regular file (a character device)"), "{e}");
        let e = load_path(Path::new("/tmp")).unwrap_err().to_string();
        assert!(e.contains("not a regular file (a directory)"), "{e}");
    }

    #[test]
    fn empty_file_for_every_format() {
        for (name, f) in
            [("e.obj", Format::Obj), ("e.stl", Format::Stl), ("e.gltf", Format::Gltf), ("e.glb", Format::Glb)]
        {
            let e = load_bytes(&p(name), b"", f).unwrap_err().to_string();
            assert!(e.contains("file is empty"), "{e}");
        }
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("empty.stl");
        std::fs::write(&f, b"").unwrap();
        let e = load_path(&f).unwrap_err().to_string();
        assert!(e.contains("file is empty"), "{e}");
    }

    #[test]
    fn load_path_every_shared_format() {
        for (name, fmt, tris) in [
            ("joined_tetrahedra.obj", Format::Obj, 8),
            ("shared.STL", Format::Stl, 24),
            ("SimpleMeshes.gltf", Format::Gltf, 2),
            ("Box.glb", Format::Glb, 12),
        ] {
            let Some(path) = shared(name) else { return };
            let (loaded, f) = load_path(&path).unwrap();
            assert_eq!(f, fmt, "{name}");
            assert_eq!(loaded.mesh.triangles.len(), tris, "{name}");
        }
    }

    #[test]
    fn validate_catches_bad_meshes() {
        use crate::scene::mesh::{Mesh, Object};
        use glam::DVec3;
        let obj = || Object { name: "a".into(), ..Default::default() };
        let mut m = Loaded {
            mesh: Mesh {
                positions: vec![DVec3::ZERO; 3],
                triangles: vec![[0, 1, 5]],
                tri_object: vec![0],
                objects: vec![obj()],
            },
            warnings: vec![],
        };
        let e = validate(&p("x"), &m).unwrap_err().to_string();
        assert!(e.contains("triangle 0 refers to vertex 5 but there are 3 vertices"), "{e}");
        m.mesh.triangles[0] = [0, 1, 2];
        m.mesh.positions[1].y = f64::NEG_INFINITY;
        let e = validate(&p("x"), &m).unwrap_err().to_string();
        assert!(e.contains("vertex 1 has a non-finite coordinate (-inf)"), "{e}");
        m.mesh.positions[1].y = 0.0;
        assert!(validate(&p("x"), &m).is_ok());
        m.mesh.tri_object[0] = 1;
        assert!(validate(&p("x"), &m).is_err());
        m.mesh.tri_object.clear();
        assert!(validate(&p("x"), &m).is_err());
        m.mesh.triangles.clear();
        let e = validate(&p("x"), &m).unwrap_err().to_string();
        assert!(e.contains("no triangles"), "{e}");
    }

    /// Random mutations of real files (byte flips, digit changes, hostile u32s, truncation)
    /// must give `Ok` or a one-line `Err`, never a panic.
    #[test]
    fn mutated_files_never_panic() {
        let mut rnd = test_rng(0x9E37_79B9_7F4A_7C15);
        let files = [
            ("Box.glb", Format::Glb),
            ("SimpleMeshes.gltf", Format::Gltf),
            ("shared.STL", Format::Stl),
            ("multibody.stl", Format::Stl),
            ("joined_tetrahedra.obj", Format::Obj),
        ];
        for (name, format) in files {
            let Some(path) = shared(name) else { return };
            let orig = std::fs::read(&path).unwrap();
            for _ in 0..3000 {
                let mut b = orig.clone();
                for _ in 0..1 + rnd(3) {
                    let at = rnd(b.len());
                    match rnd(5) {
                        0 => b[at] = rnd(256) as u8,
                        1 if b[at].is_ascii_digit() => b[at] = b'0' + rnd(10) as u8,
                        1 => {
                            if let Some(d) = b.iter().skip(at).position(|c| c.is_ascii_digit()) {
                                b[at + d] = b"09"[rnd(2)];
                            }
                        }
                        2 if at + 4 <= b.len() => {
                            let v = [0u32, 1, 0x7FFF_FFFF, u32::MAX, 84, 12][rnd(6)];
                            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
                        }
                        3 => b.truncate(at),
                        _ => b.insert(at, b"-9e0 /\n"[rnd(7)]),
                    }
                    if b.is_empty() {
                        break;
                    }
                }
                match load_bytes(&path, &b, format) {
                    Ok(l) => assert!(!l.mesh.triangles.is_empty()),
                    Err(e) => assert!(!e.to_string().contains('\n')),
                }
                let _ = detect_format(&path, &b);
            }
        }
    }

    #[test]
    fn drop_empty_objects_renumbers() {
        use crate::scene::mesh::{Mesh, Object};
        let o = |n: &str| Object { name: n.into(), ..Default::default() };
        let mut m = Mesh {
            positions: vec![],
            triangles: vec![[0, 0, 0]; 3],
            tri_object: vec![1, 3, 1],
            objects: vec![o("a"), o("b"), o("c"), o("d")],
        };
        drop_empty_objects(&mut m);
        assert_eq!(m.tri_object, vec![0, 1, 0]);
        let names: Vec<_> = m.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["b", "d"]);
    }
}
