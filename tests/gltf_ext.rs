//! glTF as CAD/BIM exporters write it, through the real binary: `KHR_mesh_quantization`
//! positions, `EXT_mesh_gpu_instancing` instances as parts (`meshclash scene`), required
//! extensions that cannot be decoded, buffer URIs outside the glTF's directory, and instance
//! counts that would expand beyond the loader's limits.
//!
//! Every file is generated here. Expected part boxes and part pairs are derived by hand from
//! the construction (power-of-two coordinates, so every world coordinate is exact), not copied
//! from the program's output.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use assert_cmd::Command;
use serde_json::Value;
use tempfile::TempDir;

fn meshclash() -> Command {
    let mut c = Command::cargo_bin("meshclash").unwrap();
    c.timeout(Duration::from_secs(60));
    c
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Wraps JSON and a binary chunk into a GLB (chunks padded to 4 bytes).
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    j.resize(j.len().next_multiple_of(4), b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().next_multiple_of(4), 0);
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The unit cube `[0,1]^3`: vertex `i` is `(i & 1, i >> 1 & 1, i >> 2 & 1)`, stored as
/// UNSIGNED_BYTE (unnormalized) with a 4-byte stride; 12 triangles, outward winding.
fn cube_bytes() -> (Vec<u8>, Vec<u8>) {
    let mut pos = Vec::new();
    for i in 0u8..8 {
        pos.extend_from_slice(&[i & 1, i >> 1 & 1, i >> 2 & 1, 0]);
    }
    let tris: [[u16; 3]; 12] = [
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    let idx = tris.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    (pos, idx)
}

/// One instance: translation, rotation as normalized SHORT xyzw, scale.
type Inst = ([f32; 3], [i16; 4], [f32; 3]);

/// A GLB: the quantized cube drawn by node `site/bolts` (translated by (8,0,0)) with one
/// GPU instance per entry of `inst`; both extensions required.
fn instanced_cube_glb(inst: &[Inst]) -> Vec<u8> {
    let (pos, idx) = cube_bytes();
    let mut bin = pos; // 32 bytes at 0
    bin.extend_from_slice(&idx); // 72 bytes at 32
    let t_at = bin.len();
    for i in inst {
        bin.extend(f32s(&i.0));
    }
    let r_at = bin.len();
    for i in inst {
        bin.extend(i.1.iter().flat_map(|c| c.to_le_bytes()));
    }
    let s_at = bin.len();
    for i in inst {
        bin.extend(f32s(&i.2));
    }
    let n = inst.len();
    let json = format!(
        r#"{{"asset":{{"version":"2.0","generator":"meshclash tests"}},
  "extensionsUsed":["KHR_mesh_quantization","EXT_mesh_gpu_instancing","KHR_materials_unlit"],
  "extensionsRequired":["KHR_mesh_quantization","EXT_mesh_gpu_instancing"],
  "buffers":[{{"byteLength":{len}}}],
  "bufferViews":[{{"buffer":0,"byteLength":32,"byteStride":4}},{{"buffer":0,"byteOffset":32,"byteLength":72}},
    {{"buffer":0,"byteOffset":{t_at},"byteLength":{tl}}},{{"buffer":0,"byteOffset":{r_at},"byteLength":{rl}}},
    {{"buffer":0,"byteOffset":{s_at},"byteLength":{tl}}}],
  "accessors":[{{"bufferView":0,"componentType":5121,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
    {{"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}},
    {{"bufferView":2,"componentType":5126,"count":{n},"type":"VEC3"}},
    {{"bufferView":3,"componentType":5122,"normalized":true,"count":{n},"type":"VEC4"}},
    {{"bufferView":4,"componentType":5126,"count":{n},"type":"VEC3"}}],
  "meshes":[{{"name":"cube","primitives":[{{"attributes":{{"POSITION":0,"_BATCHID":1}},"indices":1}}]}}],
  "nodes":[{{"name":"site","children":[1]}},
    {{"name":"bolts","mesh":0,"translation":[8,0,0],
      "extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":2,"ROTATION":3,"SCALE":4}}}}}}}}],
  "scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        len = bin.len(),
        tl = 12 * n,
        rl = 8 * n,
    );
    glb(&json, &bin)
}

const ID: [i16; 4] = [0, 0, 0, 32767];
/// 180° about z: (x, y, z) -> (-x, -y, z), exactly.
const HALF_TURN_Z: [i16; 4] = [0, 0, 32767, 0];

/// A world box: (min, max).
type Box3 = ([f64; 3], [f64; 3]);

/// The five instances of the scene test and, beside each, its world box worked out by hand
/// (node translation (8,0,0) added).
fn scene_instances() -> (Vec<Inst>, Vec<Box3>) {
    let inst: Vec<Inst> = vec![
        // 0: the cube as is
        ([0.0, 0.0, 0.0], ID, [1.0, 1.0, 1.0]),
        // 1: shifted by 0.5 in x: overlaps 0 by half its width -> clash
        ([0.5, 0.0, 0.0], ID, [1.0, 1.0, 1.0]),
        // 2: mirrored in x: [-1,0] x [0,1] x [0,1], face to face with 0 at x = 0 -> touching
        ([0.0, 0.0, 0.0], ID, [-1.0, 1.0, 1.0]),
        // 3: non-uniform scale: [4,6] x [0,1/4] x [0,1/2]
        ([4.0, 0.0, 0.0], ID, [2.0, 0.25, 0.5]),
        // 4: half turn about z then +6 x: [5,6] x [-1,0] x [0,1], touching 3 on y = 0
        ([6.0, 0.0, 0.0], HALF_TURN_Z, [1.0, 1.0, 1.0]),
    ];
    let boxes = vec![
        ([8.0, 0.0, 0.0], [9.0, 1.0, 1.0]),
        ([8.5, 0.0, 0.0], [9.5, 1.0, 1.0]),
        ([7.0, 0.0, 0.0], [8.0, 1.0, 1.0]),
        ([12.0, 0.0, 0.0], [14.0, 0.25, 0.5]),
        ([13.0, -1.0, 0.0], [14.0, 0.0, 1.0]),
    ];
    (inst, boxes)
}

fn write(dir: &TempDir, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Runs `meshclash scene FILE --no-timings ARGS`; returns (exit code, report).
fn scene(file: &Path, args: &[&str]) -> (i32, Value) {
    let out = meshclash().args(["scene", s(file), "--no-timings", "-q"]).args(args).output().unwrap();
    let code = out.status.code().unwrap();
    assert!(code == 0 || code == 1, "exit {code}: {}", String::from_utf8_lossy(&out.stderr));
    (code, serde_json::from_slice(&out.stdout).unwrap())
}

/// Part pairs of a report as {(name a, name b): verdict}, names in sorted order.
fn part_pairs(r: &Value) -> BTreeMap<(String, String), String> {
    r["part_pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let (a, b) =
                (p["a_name"].as_str().unwrap().to_string(), p["b_name"].as_str().unwrap().to_string());
            let key = if a < b { (a, b) } else { (b, a) };
            (key, p["verdict"].as_str().unwrap().to_string())
        })
        .collect()
}

fn pair(a: usize, b: usize, verdict: &str) -> ((String, String), String) {
    ((format!("site/bolts#{a}"), format!("site/bolts#{b}")), verdict.to_string())
}

#[test]
fn scene_of_gpu_instances_of_a_quantized_mesh() {
    let dir = TempDir::new().unwrap();
    let (inst, boxes) = scene_instances();
    let f = write(&dir, "bolts.glb", instanced_cube_glb(&inst));
    let (code, r) = scene(&f, &[]);
    assert_eq!(code, 1, "a clash fails the run");
    assert_eq!(r["verdict"], "clash");

    // one part per instance, named <node path>#<k>, with the boxes worked out by hand
    let parts = r["parts"].as_array().unwrap();
    assert_eq!(parts.len(), 5);
    for (k, (p, (lo, hi))) in parts.iter().zip(&boxes).enumerate() {
        assert_eq!(p["name"], format!("site/bolts#{k}"));
        assert_eq!(p["triangles"], 12);
        let got = |m: &str| -> Vec<f64> {
            p["bounds"][m].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
        };
        assert_eq!(got("min"), lo.to_vec(), "part {k}");
        assert_eq!(got("max"), hi.to_vec(), "part {k}");
    }

    // exactly the pairs the construction makes meet
    let want: BTreeMap<_, _> = [pair(0, 1, "clash"), pair(0, 2, "touching"), pair(3, 4, "touching")].into();
    assert_eq!(part_pairs(&r), want);
    for p in r["part_pairs"].as_array().unwrap() {
        assert_eq!(p["min_distance"].as_f64(), Some(0.0), "{p}");
        if p["verdict"] == "touching" {
            assert_eq!(p["crossing_pairs"], 0, "{p}");
        }
    }
    // the instances share one mesh: one SAH build, the other parts refit it
    assert_eq!(r["assembly"]["sah_builds"], 1, "{}", r["assembly"]);
    assert_eq!(r["assembly"]["mode"], "parts");

    // without the overlapping instance: only the two face-to-face contacts are left
    let (code, r) = scene(&f, &["--exclude", "*#1"]);
    assert_eq!(code, 0);
    assert_eq!(r["verdict"], "touching");
    let want: BTreeMap<_, _> = [pair(0, 2, "touching"), pair(3, 4, "touching")].into();
    assert_eq!(part_pairs(&r), want);

    // pull instance 2 back by 1/4: a gap of exactly 1/4 between it and instance 0
    let mut moved = inst.clone();
    moved[2].0 = [-0.25, 0.0, 0.0];
    let f = write(&dir, "moved.glb", instanced_cube_glb(&moved));
    let (_, r) = scene(&f, &["--exclude", "*#1", "--clearance", "0.5"]);
    let pp = r["part_pairs"].as_array().unwrap();
    let p02 = pp.iter().find(|p| p["a_name"] == "site/bolts#0" || p["b_name"] == "site/bolts#0").unwrap();
    assert_eq!(p02["verdict"], "clearance", "{p02}");
    assert_eq!(p02["min_distance"].as_f64(), Some(0.25), "{p02}");
}

/// `scene --detail parts` checks the GPU instances (mirrored, turned, non-uniformly scaled)
/// placed one part at a time; the report is the expanded scene's, byte for byte, with and
/// without a clearance, and with a part left out.
#[test]
fn gpu_instances_checked_placed_give_the_expanded_report() {
    use meshclash::pipeline::{self, Request, Tolerance};
    let dir = TempDir::new().unwrap();
    let (mut inst, _) = scene_instances();
    let f = write(&dir, "bolts.glb", instanced_cube_glb(&inst));
    inst[2].0 = [-0.25, 0.0, 0.0];
    let moved = write(&dir, "moved.glb", instanced_cube_glb(&inst));
    let json = |o: &pipeline::Outcome| serde_json::to_string(&pipeline::report::build(o)).unwrap();
    for (file, clearance, exclude) in
        [(&f, 0.0, None), (&f, 0.5, Some("*#1")), (&moved, 0.5, Some("*#1")), (&moved, 0.0, None)]
    {
        let mut req = Request::scene(file);
        req.settings.detail = meshclash::check::query::Detail::Parts;
        req.deterministic = true;
        req.clearance = Tolerance::Abs(clearance);
        req.selection.exclude.extend(exclude.map(String::from));
        assert!(pipeline::instanced_path(&req));
        let placed = pipeline::run(&req, &|_| {}).unwrap();
        assert!(placed.inputs[0].instanced.is_some());
        let expanded = pipeline::run_expanded(&req, &|_| {}).unwrap();
        assert_eq!(json(&placed), json(&expanded), "{} {clearance} {exclude:?}", file.display());
    }
}

#[test]
fn two_files_with_instances_against_each_other() {
    // files mode: A = the instanced scene, B = a single instance placed inside instance 3's
    // box region so that it crosses instance 3 only
    let dir = TempDir::new().unwrap();
    let (inst, _) = scene_instances();
    let a = write(&dir, "a.glb", instanced_cube_glb(&inst));
    let b = write(&dir, "b.glb", instanced_cube_glb(&[([4.5, 0.125, 0.25], ID, [0.5, 0.5, 0.5])]));
    let out = meshclash().args([s(&a), s(&b), "--no-timings", "-q"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<(&str, &str)> = r["part_pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["a_name"].as_str().unwrap(), p["b_name"].as_str().unwrap()))
        .collect();
    assert_eq!(names, [("site/bolts#3", "site/bolts#0")]);
}

/// Runs `meshclash scene FILE` expecting exit 2 and one stderr line containing `expect`.
fn rejects(file: &Path, expect: &[&str]) -> String {
    let start = Instant::now();
    let out = meshclash().args(["scene", s(file)]).output().unwrap();
    assert!(start.elapsed() < Duration::from_secs(10), "{}", file.display());
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(out.stdout.is_empty());
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(s(file)), "{err}");
    for e in expect {
        assert!(err.contains(e), "expected {e:?} in {err}");
    }
    err
}

#[test]
fn huge_instance_counts_fail_before_allocating() {
    // 20 million instances declared by a 12-byte sparse TRANSLATION over implied zeros: the
    // file is tiny, the expanded scene (2e7 parts) is over the limit; refused from the declared
    // count, before the instances are read. Peak RSS checked where GNU time exists.
    let dir = TempDir::new().unwrap();
    let (pos, idx) = cube_bytes();
    let mut bin = pos;
    bin.extend_from_slice(&idx);
    bin.extend_from_slice(&[0; 4]); // sparse index 0 (u16) + pad, at 104
    bin.extend(f32s(&[1.0, 2.0, 3.0])); // sparse value, at 108
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["EXT_mesh_gpu_instancing","KHR_mesh_quantization"],
  "buffers":[{{"byteLength":{}}}],
  "bufferViews":[{{"buffer":0,"byteLength":32,"byteStride":4}},{{"buffer":0,"byteOffset":32,"byteLength":72}},
    {{"buffer":0,"byteOffset":104,"byteLength":2}},{{"buffer":0,"byteOffset":108,"byteLength":12}}],
  "accessors":[{{"bufferView":0,"componentType":5121,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
    {{"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}},
    {{"componentType":5126,"count":20000000,"type":"VEC3",
      "sparse":{{"count":1,"indices":{{"bufferView":2,"componentType":5123}},"values":{{"bufferView":3}}}}}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
  "nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":2}}}}}}}}]}}"#,
        bin.len()
    );
    let f = write(&dir, "instance_bomb.glb", glb(&json, &bin));
    assert!(std::fs::metadata(&f).unwrap().len() < 4096);
    // 2e7 instances x 8 vertices = 1.6e8 vertices (under 2^28), 2.4e8 triangles (under
    // 2^28): the parts limit is what refuses it
    rejects(&f, &["glTF scene has 20000000 parts after instancing, more than the 16777216 supported"]);
    if cfg!(target_os = "linux") && Path::new("/usr/bin/time").exists() {
        let out = std::process::Command::new("/usr/bin/time")
            .args(["-f", "MAXRSS_KIB %M", env!("CARGO_BIN_EXE_meshclash"), "scene", s(&f)])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let kib: u64 =
            err.lines().find_map(|l| l.strip_prefix("MAXRSS_KIB ")).unwrap().trim().parse().unwrap();
        assert!(kib < 64 * 1024, "peak RSS {kib} KiB");
    }
}

#[test]
fn undecodable_required_extensions_are_named() {
    let dir = TempDir::new().unwrap();
    let (inst, _) = scene_instances();
    for (ext, why) in [
        ("KHR_draco_mesh_compression", "Draco-compressed geometry cannot be decoded"),
        ("EXT_meshopt_compression", "meshopt-compressed buffers cannot be decoded"),
    ] {
        let bytes = instanced_cube_glb(&inst);
        // patch the required list in the JSON chunk and rebuild the GLB
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json = std::str::from_utf8(&bytes[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len + 8;
        let json = json.replace(
            r#""extensionsRequired":["KHR_mesh_quantization","EXT_mesh_gpu_instancing"]"#,
            &format!(r#""extensionsRequired":["KHR_mesh_quantization","{ext}"]"#),
        );
        let f = write(&dir, &format!("{ext}.glb"), glb(&json, &bytes[bin_at..]));
        rejects(&f, &[&format!("glTF requires extension '{ext}', which is not supported"), why]);
    }
}

#[test]
fn buffer_uris_outside_the_directory_are_refused() {
    let dir = TempDir::new().unwrap();
    std::fs::create_dir(dir.path().join("model")).unwrap();
    let (pos, idx) = cube_bytes();
    let mut bin = pos;
    bin.extend_from_slice(&idx);
    std::fs::write(dir.path().join("outside.bin"), &bin).unwrap();
    std::fs::write(dir.path().join("model/inside.bin"), &bin).unwrap();
    let doc = |uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":104,"uri":"{uri}"}}],
  "bufferViews":[{{"buffer":0,"byteLength":32,"byteStride":4}},{{"buffer":0,"byteOffset":32,"byteLength":72}}],
  "accessors":[{{"bufferView":0,"componentType":5121,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
    {{"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"nodes":[{{"mesh":0}}]}}"#
        )
    };
    let f = dir.path().join("model/m.gltf");
    std::fs::write(&f, doc("inside.bin")).unwrap();
    meshclash().args(["scene", s(&f), "-q"]).assert().code(0);
    let abs = dir.path().join("outside.bin").display().to_string();
    for (uri, why) in [
        ("../outside.bin", "'..' leaving the glTF's directory"),
        (abs.as_str(), "an absolute path"),
        (&format!("file://{abs}"), "a scheme or drive letter"),
    ] {
        std::fs::write(&f, doc(uri)).unwrap();
        rejects(&f, &[&format!("glTF buffer 0 URI '{uri}' is refused: {why}")]);
    }
    // a symlink inside the folder pointing outside it was read.
    std::os::unix::fs::symlink("../outside.bin", dir.path().join("model/link.bin")).unwrap();
    std::fs::write(&f, doc("link.bin")).unwrap();
    rejects(&f, &["glTF buffer 0 URI 'link.bin' is refused: it resolves (through a symlink) outside"]);
}
