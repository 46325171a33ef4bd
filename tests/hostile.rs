//! Hostile input files through the real binary.
//!
//! Every case is built in a temporary directory and given to `meshclash` beside a good mesh
//! (`meshes/fcl_rob.obj`). Each must give exit code 2, nothing on stdout, exactly one line on
//! stderr naming the file and the problem, no panic, and — with `-o` — no report and no
//! temporary file left behind. Inputs that declare hostile sizes must also finish quickly and
//! with a small peak RSS: those sizes are never allocated.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use assert_cmd::Command;
use tempfile::TempDir;

/// Upper bound for one run on a hostile input (they are all tiny files).
const MAX_SECONDS: u64 = 5;

/// Peak RSS allowed for hostile-size inputs, in KiB (a 4 GiB allocation would show).
const MAX_RSS_KIB: u64 = 256 * 1024;

fn good() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes").join("fcl_rob.obj")
}

fn meshclash() -> Command {
    let mut c = Command::cargo_bin("meshclash").unwrap();
    // A hang must fail the test, not stall it.
    c.timeout(Duration::from_secs(60));
    c
}

fn write(dir: &TempDir, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Which argument slot the hostile file goes in.
#[derive(Clone, Copy, Debug)]
enum Side {
    A,
    B,
}

/// Runs `meshclash` with the hostile file on `side` and the good mesh on the other, checks the
/// error contract and returns the single stderr line. `expect` are substrings the line must
/// contain besides the file's path.
fn rejects_on(side: Side, file: &Path, expect: &[&str]) -> String {
    let good = good();
    let (a, b) = match side {
        Side::A => (file, good.as_path()),
        Side::B => (good.as_path(), file),
    };

    // Report to stdout.
    let start = Instant::now();
    let out = meshclash().args([s(a), s(b)]).output().unwrap();
    let took = start.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let what = format!("{side:?} = {}", file.display());
    assert!(!stderr.contains("panicked"), "{what}: panic: {stderr}");
    assert_eq!(out.status.code(), Some(2), "{what}: exit code; stderr: {stderr}");
    assert!(out.stdout.is_empty(), "{what}: stdout not empty: {}", String::from_utf8_lossy(&out.stdout));
    assert_eq!(stderr.lines().count(), 1, "{what}: stderr is not one line: {stderr:?}");
    assert!(stderr.ends_with('\n') && !stderr.trim_end().contains('\n'), "{what}: {stderr:?}");
    let line = stderr.trim_end().to_string();
    assert!(line.contains(&file.display().to_string()), "{what}: the error does not name the file: {line}");
    for e in expect {
        assert!(line.contains(e), "{what}: expected {e:?} in: {line}");
    }
    assert!(took < Duration::from_secs(MAX_SECONDS), "{what}: took {took:?}");

    // Report to a file: nothing may be left in its (otherwise empty) directory.
    let out_dir = tempfile::tempdir().unwrap();
    let report = out_dir.path().join("out.json");
    let out = meshclash().args([s(a), s(b), "-o", s(&report)]).output().unwrap();
    let stderr2 = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr2.contains("panicked"), "{what} -o: panic: {stderr2}");
    assert_eq!(out.status.code(), Some(2), "{what} -o: exit code; stderr: {stderr2}");
    assert!(out.stdout.is_empty(), "{what} -o: stdout not empty");
    assert_eq!(stderr2, stderr, "{what}: -o changed the error");
    let left: Vec<_> = std::fs::read_dir(out_dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "{what}: -o left files behind: {left:?}");
    line
}

/// [`rejects_on`] with the hostile file as input B.
fn rejects(file: &Path, expect: &[&str]) -> String {
    rejects_on(Side::B, file, expect)
}

/// [`rejects_on`] with the hostile file on both sides in turn.
fn rejects_both_sides(file: &Path, expect: &[&str]) {
    let a = rejects_on(Side::A, file, expect);
    let b = rejects_on(Side::B, file, expect);
    assert_eq!(a, b, "the error depends on the side");
}

/// Virtual memory allowed for hostile-size inputs, in KiB: allocating a declared size fails
/// under this limit instead of taking the machine's memory.
const MAX_VM_KIB: u64 = 4 * 1024 * 1024;

/// Runs `meshclash good file` under `ulimit -v` ([`MAX_VM_KIB`]) and, where GNU time is
/// installed, measures its peak RSS: returns (exit code, stderr without time's lines, peak RSS
/// in KiB). `None` where there is no `/bin/sh` with `ulimit` (not Linux).
fn bounded_run(file: &Path) -> Option<(Option<i32>, String, Option<u64>)> {
    if !cfg!(target_os = "linux") || !Path::new("/bin/sh").exists() {
        return None;
    }
    let time = Path::new("/usr/bin/time").exists();
    let script = if time {
        format!(r#"ulimit -v {MAX_VM_KIB} && exec /usr/bin/time -f "MAXRSS_KIB %M" "$0" "$@""#)
    } else {
        format!(r#"ulimit -v {MAX_VM_KIB} && exec "$0" "$@""#)
    };
    let out = std::process::Command::new("/bin/sh")
        .args(["-c", &script, env!("CARGO_BIN_EXE_meshclash"), s(&good()), s(file)])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    let rss = err.lines().find_map(|l| l.strip_prefix("MAXRSS_KIB ")).map(|r| r.trim().parse().unwrap());
    let own: Vec<&str> = err
        .lines()
        .filter(|l| !l.starts_with("MAXRSS_KIB ") && !l.starts_with("Command exited with non-zero status"))
        .collect();
    Some((out.status.code(), own.join("\n"), rss))
}

/// [`rejects`] plus bounded memory: a hostile declared size must never be allocated. The first
/// run is under a virtual-memory limit, so that a regression fails here instead of exhausting
/// the machine; its peak RSS must be small.
fn rejects_without_allocating(file: &Path, expect: &[&str]) {
    if let Some((code, stderr, rss)) = bounded_run(file) {
        let what = file.display();
        assert!(!stderr.contains("panicked") && !stderr.contains("memory allocation"), "{what}: {stderr}");
        assert_eq!(code, Some(2), "{what}: under ulimit -v {MAX_VM_KIB}: {stderr}");
        if let Some(kib) = rss {
            assert!(kib < MAX_RSS_KIB, "{what}: peak RSS {kib} KiB");
        }
    }
    rejects(file, expect);
}

// ---------------------------------------------------------------------------------------------
// Builders.

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Binary STL: an 80-byte header, the declared count, then the given facets.
fn binary_stl(declared: u32, tris: &[[f32; 9]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&declared.to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]); // normal
        b.extend_from_slice(&f32s(t));
        b.extend_from_slice(&[0u8; 2]); // attribute byte count
    }
    b
}

const TRI: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Binary data of one triangle: 3 f32 positions (36 bytes), then u16 indices (+ padding).
fn tri_bin(positions: [f32; 9], indices: [u16; 3]) -> Vec<u8> {
    let mut b = f32s(&positions);
    for i in indices.into_iter().chain([0]) {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// Views, accessors and the one-primitive mesh over [`tri_bin`]'s layout.
const TRI_LAYOUT: &str = r#""bufferViews":[{"buffer":0,"byteLength":36},
    {"buffer":0,"byteOffset":36,"byteLength":6}],
  "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
    {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],
  "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#;

/// A glTF JSON document: `buffer` is the whole buffer object; `rest` the other members.
fn gltf_doc(buffer: &str, rest: &str) -> String {
    format!(r#"{{"asset":{{"version":"2.0"}},"buffers":[{buffer}],{rest}}}"#)
}

/// A buffer object holding `bin` as a base64 data URI, declaring `declared` bytes.
fn data_uri_buffer(bin: &[u8], declared: u64) -> String {
    format!(r#"{{"byteLength":{declared},"uri":"data:application/octet-stream;base64,{}"}}"#, base64(bin))
}

/// The one-triangle document with `bin` embedded and the given nodes/scenes members.
fn tri_gltf(bin: &[u8], nodes: &str) -> String {
    gltf_doc(&data_uri_buffer(bin, bin.len() as u64), &format!("{TRI_LAYOUT},{nodes}"))
}

const ONE_NODE: &str = r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0"#;

/// A GLB container: JSON chunk (space-padded) and optional BIN chunk (zero-padded).
fn glb(json: &str, bin: Option<&[u8]>) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut body = Vec::new();
    body.extend_from_slice(&(j.len() as u32).to_le_bytes());
    body.extend_from_slice(b"JSON");
    body.extend_from_slice(&j);
    if let Some(bin) = bin {
        let mut b = bin.to_vec();
        while b.len() % 4 != 0 {
            b.push(0);
        }
        body.extend_from_slice(&(b.len() as u32).to_le_bytes());
        body.extend_from_slice(b"BIN\0");
        body.extend_from_slice(&b);
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(12 + body.len() as u32).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

/// A valid one-triangle GLB with its data in the BIN chunk; also returns where the JSON
/// chunk's data starts and where the BIN chunk's data starts.
fn tri_glb() -> (Vec<u8>, usize, usize) {
    let bin = tri_bin(TRI, [0, 1, 2]);
    let json = gltf_doc(&format!(r#"{{"byteLength":{}}}"#, bin.len()), &format!("{TRI_LAYOUT},{ONE_NODE}"));
    let bytes = glb(&json, Some(&bin));
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    (bytes, 20, 20 + json_len + 8)
}

// ---------------------------------------------------------------------------------------------
// Sanity: the builders make files the binary accepts, so each hostile case differs from a
// good file only by what it tests.

#[test]
fn builders_make_valid_files() {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        write(&dir, "ok.stl", binary_stl(1, &[TRI])),
        write(&dir, "ok.gltf", tri_gltf(&tri_bin(TRI, [0, 1, 2]), ONE_NODE)),
        write(&dir, "ok.glb", tri_glb().0),
    ];
    for f in files {
        let out = meshclash().args([s(&good()), s(&f), "-q"]).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(matches!(out.status.code(), Some(0 | 1)), "{}: {stderr}", f.display());
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a JSON report");
        assert_eq!(v["inputs"]["b"]["triangles"], 1, "{}", f.display());
    }
}

// ---------------------------------------------------------------------------------------------
// Files that cannot be read, or are not meshes at all.

#[test]
fn missing_and_unreadable_files() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.obj");
    rejects_both_sides(&missing, &["cannot read file", "No such file or directory"]);

    let as_dir = dir.path().join("a_directory.stl");
    std::fs::create_dir(&as_dir).unwrap();
    rejects_both_sides(&as_dir, &["not a regular file (a directory)"]);

    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let locked = write(&dir, "locked.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o000)).unwrap();
        // As root (or with CAP_DAC_OVERRIDE) mode 000 does not stop reading; then this variant
        // cannot be tested and is skipped.
        if std::fs::read(&locked).is_err() {
            rejects(&locked, &["cannot read file", "Permission denied"]);
        } else {
            eprintln!("skipping the chmod 000 case: this user can read a mode-000 file (root)");
        }
    }
}

#[test]
fn unknown_extension_and_empty_files() {
    let dir = tempfile::tempdir().unwrap();
    let ply = write(&dir, "mesh.ply", "ply\nformat ascii 1.0\nend_header\n");
    rejects_both_sides(&ply, &["unknown extension '.ply'", "expected .obj, .stl, .gltf or .glb"]);
    for ext in ["obj", "stl", "gltf", "glb"] {
        let empty = write(&dir, &format!("empty.{ext}"), b"");
        rejects(&empty, &["file is empty"]);
    }
}

#[test]
fn files_without_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(&dir, "only_vertices.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    rejects(&obj, &["no triangles"]);

    let stl = write(&dir, "empty_solid.stl", "solid nothing\nendsolid nothing\n");
    rejects(&stl, &["no triangles"]);

    let bin = tri_bin(TRI, [0, 1, 2]);
    let points = gltf_doc(
        &data_uri_buffer(&bin, bin.len() as u64),
        &format!(
            r#""bufferViews":[{{"buffer":0,"byteLength":36}}],
  "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":0}}]}}],{ONE_NODE}"#
        ),
    );
    let gltf = write(&dir, "points_only.gltf", points);
    rejects(&gltf, &["no triangles"]);
}

// ---------------------------------------------------------------------------------------------
// Bad numbers and bad indices.

#[test]
fn nan_and_inf_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let nan = write(&dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    rejects_both_sides(&nan, &["line 2", "vertex 2 has a non-finite coordinate (NaN)"]);

    let overflow = write(&dir, "overflow.obj", "v 1e400 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    rejects(&overflow, &["line 1", "vertex 1 has a non-finite coordinate (inf)"]);

    let mut t = TRI;
    t[4] = f32::NAN;
    let stl = write(&dir, "nan.stl", binary_stl(2, &[TRI, t]));
    rejects_both_sides(&stl, &["triangle 1 vertex 1 has a non-finite coordinate (NaN)"]);

    let mut p = TRI;
    p[6] = f32::INFINITY;
    let inf = write(&dir, "inf.gltf", tri_gltf(&tri_bin(p, [0, 1, 2]), ONE_NODE));
    rejects(&inf, &["position 2", "mesh 0 primitive 0", "non-finite coordinate (inf)"]);
}

#[test]
fn out_of_range_zero_and_negative_indices() {
    let dir = tempfile::tempdir().unwrap();
    let three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let beyond = write(&dir, "beyond.obj", format!("{three}f 1 2 99\n"));
    rejects_both_sides(&beyond, &["line 4", "face refers to vertex 99 but there are 3 vertices"]);

    let zero = write(&dir, "zero.obj", format!("{three}f 0 1 2\n"));
    rejects(&zero, &["line 4", "vertex 0 (OBJ indices start at 1)"]);

    let negative = write(&dir, "negative.obj", format!("{three}f -1 -2 -9\n"));
    rejects(&negative, &["line 4", "face refers to vertex -9 but only 3 vertices are defined before it"]);

    let gltf = write(&dir, "index.gltf", tri_gltf(&tri_bin(TRI, [0, 1, 7]), ONE_NODE));
    rejects(&gltf, &["mesh 0 primitive 0", "index 2 refers to vertex 7 but there are 3 vertices"]);
}

// ---------------------------------------------------------------------------------------------
// Sizes declared beyond the file: reported, never allocated.

#[test]
fn truncated_binary_stl_is_reported_without_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let three = binary_stl(10, &[TRI, TRI, TRI]);
    assert_eq!(three.len(), 84 + 3 * 50);
    let short = write(&dir, "ten_declared_three_present.stl", three);
    rejects_both_sides(
        &short,
        &["truncated binary STL", "header declares 10 triangles (needs 584 bytes)", "file has 234 bytes"],
    );

    let huge = write(&dir, "u32max_triangles.stl", binary_stl(u32::MAX, &[]));
    rejects_without_allocating(&huge, &["truncated binary STL", "4294967295 triangles", "file has 84 bytes"]);
}

#[test]
fn truncated_glb_is_reported_without_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let (full, json_at, bin_at) = tri_glb();

    // Cut in the JSON chunk, and in the BIN chunk: the header's total length is then wrong.
    let mid_json = json_at + 10;
    let cut = write(&dir, "cut_in_json.glb", &full[..mid_json]);
    rejects_both_sides(
        &cut,
        &[
            "truncated GLB",
            &format!("header declares {} bytes but the file has {mid_json} bytes", full.len()),
        ],
    );
    let mid_bin = bin_at + 10;
    let cut = write(&dir, "cut_in_bin.glb", &full[..mid_bin]);
    rejects(&cut, &["truncated GLB", &format!("header declares {} bytes", full.len())]);

    // The same cuts with the header's total length fixed up: the chunk lengths are then wrong.
    let fixed = |n: usize| {
        let mut b = full[..n].to_vec();
        b[8..12].copy_from_slice(&(n as u32).to_le_bytes());
        b
    };
    let json_len = bin_at - 8 - json_at;
    let cut = write(&dir, "cut_in_json_chunk.glb", fixed(mid_json));
    rejects(
        &cut,
        &["truncated GLB", &format!("chunk 0 ('JSON') declares {json_len} bytes but only 10 remain")],
    );
    let cut = write(&dir, "cut_in_bin_chunk.glb", fixed(mid_bin));
    rejects(&cut, &["truncated GLB", "chunk 1 ('BIN') declares 44 bytes but only 10 remain"]);

    // A header declaring 4 GiB in a file of a few hundred bytes.
    let mut huge = full.clone();
    huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    let huge = write(&dir, "4gb_header.glb", huge);
    rejects_without_allocating(
        &huge,
        &[
            "truncated GLB",
            &format!("header declares 4294967295 bytes but the file has {} bytes", full.len()),
        ],
    );

    // A JSON chunk declaring 4 GiB.
    let mut chunk = full.clone();
    chunk[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    let chunk = write(&dir, "4gb_json_chunk.glb", chunk);
    rejects_without_allocating(&chunk, &["truncated GLB", "chunk 0 ('JSON') declares 4294967295 bytes"]);
}

#[test]
fn gltf_buffer_declaring_4gb_is_reported_without_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let bin = tri_bin(TRI, [0, 1, 2]);
    let rest = format!("{TRI_LAYOUT},{ONE_NODE}");

    let uri = write(&dir, "4gb_data_uri.gltf", gltf_doc(&data_uri_buffer(&bin, u32::MAX as u64), &rest));
    rejects_without_allocating(
        &uri,
        &["glTF buffer 0 declares 4294967295 bytes but its data URI has 44 bytes"],
    );

    write(&dir, "small.bin", &bin);
    let external =
        write(&dir, "4gb_external.gltf", gltf_doc(r#"{"byteLength":4294967295,"uri":"small.bin"}"#, &rest));
    rejects_without_allocating(
        &external,
        &["glTF external buffer 'small.bin' has 44 bytes but buffer 0 declares 4294967295"],
    );

    let json = gltf_doc(r#"{"byteLength":4294967295}"#, &rest);
    let in_glb = write(&dir, "4gb_bin_buffer.glb", glb(&json, Some(&bin)));
    rejects_without_allocating(
        &in_glb,
        &["glTF buffer 0 declares 4294967295 bytes but the GLB binary chunk has 44 bytes"],
    );
}

// ---------------------------------------------------------------------------------------------
// glTF structure.

#[test]
fn gltf_external_buffer_missing() {
    let dir = tempfile::tempdir().unwrap();
    let bin = tri_bin(TRI, [0, 1, 2]);
    let doc = gltf_doc(r#"{"byteLength":44,"uri":"missing.bin"}"#, &format!("{TRI_LAYOUT},{ONE_NODE}"));
    let f = write(&dir, "external.gltf", doc);
    rejects_both_sides(
        &f,
        &["glTF external buffer 'missing.bin' cannot be read", "No such file or directory"],
    );
    // With the buffer present the same document loads.
    write(&dir, "missing.bin", &bin);
    let out = meshclash().args([s(&good()), s(&f), "-q"]).output().unwrap();
    assert!(matches!(out.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn gltf_node_cycle_and_deep_chain() {
    let dir = tempfile::tempdir().unwrap();
    let bin = tri_bin(TRI, [0, 1, 2]);
    let cycle = r#""nodes":[{"mesh":0,"children":[1]},{"children":[0]}],"scenes":[{"nodes":[0]}],"scene":0"#;
    let f = write(&dir, "cycle.gltf", tri_gltf(&bin, cycle));
    rejects_both_sides(&f, &["glTF node graph has a cycle"]);

    // Node i has child i + 1; the mesh hangs at the bottom, 5000 levels down.
    let n = 5000;
    let mut nodes: Vec<String> = (0..n - 1).map(|i| format!(r#"{{"children":[{}]}}"#, i + 1)).collect();
    nodes.push(r#"{"mesh":0}"#.to_string());
    let chain = format!(r#""nodes":[{}],"scenes":[{{"nodes":[0]}}],"scene":0"#, nodes.join(","));
    let f = write(&dir, "deep_chain.gltf", tri_gltf(&bin, &chain));
    rejects(&f, &["glTF node hierarchy deeper than 1024 levels"]);
}

#[test]
fn gltf_requiring_draco_names_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let bin = tri_bin(TRI, [0, 1, 2]);
    let rest = format!(
        r#"{TRI_LAYOUT},{ONE_NODE},"extensionsUsed":["KHR_draco_mesh_compression"],
  "extensionsRequired":["KHR_draco_mesh_compression"]"#
    );
    let f = write(&dir, "draco.gltf", gltf_doc(&data_uri_buffer(&bin, bin.len() as u64), &rest));
    rejects_both_sides(&f, &["KHR_draco_mesh_compression", "not supported"]);
}

// ---------------------------------------------------------------------------------------------
// Bytes that are not UTF-8.

#[test]
fn obj_non_utf8_number_is_an_error_and_non_utf8_name_loads() {
    let dir = tempfile::tempdir().unwrap();
    let number = write(&dir, "bad_number.obj", b"v 1\xff 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    rejects_both_sides(&number, &["line 1", "not UTF-8 at byte 3"]);

    let name = write(&dir, "latin1_name.obj", b"o caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let out = meshclash().args([s(&good()), s(&name)]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(matches!(out.status.code(), Some(0 | 1)), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a JSON report");
    assert_eq!(v["inputs"]["b"]["triangles"], 1);
    assert_eq!(v["inputs"]["b"]["objects"][0]["name"], "caf\u{FFFD}");
}

// ---------------------------------------------------------------------------------------------
// Regressions: bugs found by fuzzing or review, with the inputs that showed them.

/// Found in review: the instancing limit counted vertices only. A 160 KB glTF whose one mesh
/// has 3 vertices and 150 000 zero indices (a sparse accessor with no bufferView, so the
/// indices cost no bytes), instanced by 10 000 nodes, expands to 5·10^8 triangles; the loader
/// reserved 6 GB for them (24 GB, an allocation failure abort, with more nodes).
#[test]
fn regression_gltf_instanced_triangle_count_is_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = f32s(&TRI);
    bin.extend_from_slice(&0u32.to_le_bytes()); // sparse index
    bin.extend_from_slice(&1u32.to_le_bytes()); // sparse value
    let (instances, indices) = (10_000, 150_000);
    let nodes = vec![r#"{"mesh":0}"#; instances].join(",");
    let roots: Vec<String> = (0..instances).map(|i| i.to_string()).collect();
    let rest = format!(
        r#""bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":4}},
    {{"buffer":0,"byteOffset":40,"byteLength":4}}],
  "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
    {{"componentType":5125,"count":{indices},"type":"SCALAR","sparse":{{"count":1,
      "indices":{{"bufferView":1,"componentType":5125}},"values":{{"bufferView":2}}}}}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
  "nodes":[{nodes}],"scenes":[{{"nodes":[{}]}}],"scene":0"#,
        roots.join(",")
    );
    let f = write(&dir, "instancing_bomb.gltf", gltf_doc(&data_uri_buffer(&bin, bin.len() as u64), &rest));
    rejects_without_allocating(
        &f,
        &["glTF scene has 500000000 triangles after instancing, more than the 268435456 supported"],
    );
}

/// a one-line face of 24 MB (12 million indices) reached gigabytes and
/// aborted with no file name; it is refused at the polygon cap, naming the file and line.
#[test]
fn regression_obj_huge_face_line_is_refused_naming_file_and_line() {
    let dir = TempDir::new().unwrap();
    let mut face = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf".to_vec();
    for _ in 0..12_000_000 {
        face.extend_from_slice(b" 1");
    }
    face.push(b'\n');
    let file = write(&dir, "huge_face.obj", &face);
    rejects_without_allocating(&file, &["line 4: face has more than 65536 vertices"]);
}

/// A FIFO given as the plan of `run`, a shard report of `merge`, a `--baseline` or a
/// `clash-set` file is refused at once (exit 2, one line naming it), never opened for reading
/// (which blocks until a writer comes, forever). Each run is a child killed after a generous
/// limit: a hang fails.
#[test]
fn fifo_as_plan_shard_report_baseline_or_clash_set_is_refused_without_blocking() {
    if !cfg!(unix) || !Path::new("/usr/bin/mkfifo").exists() && !Path::new("/bin/mkfifo").exists() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let fifo = d.path().join("f.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let f = s(&fifo);
    let out = d.path().join("out.json");
    let o = s(&out);
    let g = good();
    let cases: [Vec<&str>; 4] = [
        vec!["run", "--plan", f, "--shard", "1/1", "-o", o],
        vec!["merge", f, "-o", o],
        vec![s(&g), s(&g), "--baseline", f, "-o", o],
        vec!["clash-set", f],
    ];
    for args in cases {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_meshclash"))
            .args(&args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let start = Instant::now();
        let status = loop {
            if let Some(st) = child.try_wait().unwrap() {
                break Some(st);
            }
            if start.elapsed() > Duration::from_secs(60) {
                child.kill().unwrap();
                child.wait().unwrap();
                break None;
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let status = status.unwrap_or_else(|| panic!("{args:?} blocked on the FIFO"));
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(f) && err.contains("FIFO"), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote an output");
    }
}
