//! Inputs that used to abort or run without end, through the real binary: instanced glTF
//! scenes within the documented caps under a 1 GiB address-space limit (refused up front with
//! exit 2 and one line naming the file), and `self` on 100,000-triangle constructions around
//! one vertex or edge (copies of one face, point triangles at one point, a flat disc fan,
//! pages on one edge), which must
//! finish (a child process bounded by a generous time limit: a hang fails, no speed is
//! asserted).

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

fn exe() -> &'static str {
    env!("CARGO_BIN_EXE_meshclash")
}

/// Runs `sh -c 'ulimit -v KIB; exec meshclash ARGS --threads 1'`: (exit code, stderr).
fn under_limit(kib: u64, args: &[&str]) -> (Option<i32>, String) {
    let script = format!(r#"ulimit -v {kib} && exec "$0" "$@" --threads 1"#);
    let out =
        std::process::Command::new("/bin/sh").arg("-c").arg(script).arg(exe()).args(args).output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// One triangle's positions as a base64 data URI buffer prefix (36 bytes).
fn triangle_bytes() -> Vec<u8> {
    [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// `n` nodes, each placing a one-triangle mesh 2 apart along x.
fn many_nodes(path: &Path, n: usize) {
    use base64::Engine;
    let data = base64::engine::general_purpose::STANDARD.encode(triangle_bytes());
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    write!(f, r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":["#).unwrap();
    for i in 0..n {
        write!(f, "{}{i}", if i == 0 { "" } else { "," }).unwrap();
    }
    write!(f, r#"]}}],"nodes":["#).unwrap();
    for i in 0..n {
        write!(f, r#"{}{{"mesh":0,"translation":[{},0,0]}}"#, if i == 0 { "" } else { "," }, 2 * i).unwrap();
    }
    write!(
        f,
        r#"],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}]}}"#
    )
    .unwrap();
}

/// One node with `n` EXT_mesh_gpu_instancing instances (translations 2 apart along x) of a
/// one-triangle mesh; the buffer is an external file next to it.
fn gpu_instances(path: &Path, n: usize) {
    let mut bin = triangle_bytes();
    for i in 0..n {
        bin.extend([2.0 * i as f32, 0.0, 0.0].iter().flat_map(|x| x.to_le_bytes()));
    }
    std::fs::write(path.with_extension("bin"), &bin).unwrap();
    let name = path.with_extension("bin").file_name().unwrap().to_string_lossy().into_owned();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["EXT_mesh_gpu_instancing"],"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":1}}}}}}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"buffers":[{{"byteLength":{},"uri":"{name}"}}],
"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":{}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5126,"count":{n},"type":"VEC3"}}]}}"#,
        bin.len(),
        12 * n
    );
    std::fs::write(path, json).unwrap();
}

#[test]
fn instanced_scenes_within_the_caps_are_refused_under_1_gib_not_aborted() {
    if !cfg!(target_os = "linux") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let nodes = d.path().join("nodes.gltf");
    many_nodes(&nodes, 1_000_000);
    let gpu = d.path().join("gpu.gltf");
    gpu_instances(&gpu, 4_000_000);
    let good = concat!(env!("CARGO_MANIFEST_DIR"), "/meshes/fcl_rob.obj");
    for file in [&nodes, &gpu] {
        let f = file.to_str().unwrap();
        for args in [vec!["scene", f, "-o", "/dev/null"], vec![good, f, "-o", "/dev/null"]] {
            let (code, err) = under_limit(1 << 20, &args);
            assert_eq!(code, Some(2), "{args:?} under ulimit -v 1 GiB: {err}");
            assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
            assert!(err.contains(f) && err.contains("GiB") && err.contains("may use"), "{err}");
        }
    }
}

/// Runs `meshclash self FILE -o /dev/null` in a child, killed after `limit`: the exit code,
/// or `None` when it had to be killed.
fn self_within(file: &Path, limit: Duration) -> Option<i32> {
    let mut child = std::process::Command::new(exe())
        .args(["self", file.to_str().unwrap(), "-q", "--no-timings", "-o", "/dev/null"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status.code();
        }
        if start.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            return None;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn self_on_100k_triangles_around_one_vertex_or_edge_finishes() {
    let n = 100_000usize;
    let d = tempfile::tempdir().unwrap();
    let write = |name: &str, text: String| {
        let p = d.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let copies = write("copies.obj", format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{}", "f 1 2 3\n".repeat(n)));
    let mut pts = "v 0.5 0.5 0\n".repeat(3 * n);
    for i in 0..n {
        pts.push_str(&format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3));
    }
    let points = write("points.obj", pts);
    let mut disc = String::from("v 0 0 0\n");
    for i in 0..n {
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        disc.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    for i in 0..n {
        disc.push_str(&format!("f 1 {} {}\n", 2 + i, 2 + (i + 1) % n));
    }
    let fan = write("fan.obj", disc);
    let mut pages = String::from("v 0 0 0\nv 0 0 1\n");
    for i in 0..n {
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        pages.push_str(&format!("v {} {} 0.5\n", a.cos(), a.sin()));
    }
    for i in 0..n {
        pages.push_str(&format!("f 1 2 {}\n", 3 + i));
    }
    let book = write("book.obj", pages);
    // Generous: a hang or the old quadratic walk (hours) fails; the figures are in benchmarks.
    for f in [&copies, &points, &fan, &book] {
        assert_eq!(self_within(f, Duration::from_secs(120)), Some(0), "{}", f.display());
    }
}

/// A flat fan of `n` triangles around the origin as OBJ object `name`, its vertices numbered
/// from `base` (1-based).
fn fan_obj(name: &str, n: usize, base: usize) -> String {
    let mut s = format!("o {name}\nv 0 0 0\n");
    for i in 0..=n {
        let t = i as f64 / n as f64 * 3.0;
        s.push_str(&format!("v {} {} 0\n", t.cos(), t.sin()));
    }
    for i in 0..n {
        s.push_str(&format!("f {} {} {}\n", base, base + 1 + i, base + 2 + i));
    }
    s
}

#[test]
fn detail_parts_on_coincident_fans_runs_in_memory_that_does_not_grow_with_their_pairs() {
    if !cfg!(target_os = "linux") {
        return;
    }
    // Two coincident fans of 1,500 triangles: every one of the 2,250,000 triangle pairs touches
    // (all share the apex). Collecting them took about 220 MB; a tally per part pair needs a
    // few MB, so 120 MB of address space is plenty, files mode and scene mode alike.
    let n = 1500usize;
    let d = tempfile::tempdir().unwrap();
    let one = d.path().join("fan.obj");
    std::fs::write(&one, fan_obj("fan", n, 1)).unwrap();
    let two = d.path().join("fans.obj");
    std::fs::write(&two, fan_obj("a", n, 1) + &fan_obj("b", n, n + 3)).unwrap();
    let out = d.path().join("r.json");
    let (f1, f2, o) = (one.to_str().unwrap(), two.to_str().unwrap(), out.to_str().unwrap());
    for args in [vec![f1, f1], vec!["scene", f2]] {
        let args: Vec<&str> =
            args.into_iter().chain(["--detail", "parts", "--max-pairs", "0", "-o", o]).collect();
        let (code, err) = under_limit(120_000, &args);
        assert_eq!(code, Some(0), "{args:?} under ulimit -v 120 MB: {err}");
        let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
        assert_eq!(r["summary"]["touching_pairs"], (n * n) as u64, "{args:?}");
        assert_eq!(r["part_pairs"][0]["touching_pairs"], (n * n) as u64, "{args:?}");
        assert_eq!(r["verdict"], "touching");
        std::fs::remove_file(&out).unwrap();
    }
}

/// `n` zero-area triangles on the line through the origin along (1, 2, 3), each with its own
/// three vertices: triangle `i` spans `[3i, 3i + 2 + 3h]` along the line, so `i < j` meet
/// (touch along a segment) iff `j - i <= h`.
fn collinear_obj(n: usize, h: usize) -> String {
    let mut s = String::with_capacity(n * 90);
    for i in 0..n {
        let t0 = 3 * i;
        for t in [t0 + 1, t0 + 2 + 3 * h, t0] {
            s.push_str(&format!("v {t} {} {}\n", 2 * t, 3 * t));
        }
    }
    for i in 0..n {
        s.push_str(&format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3));
    }
    s
}

/// The same construction as a mesh, for the brute force.
fn collinear_mesh(n: usize, h: usize) -> meshclash::scene::mesh::Mesh {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for i in 0..n {
        let t0 = 3 * i;
        for t in [t0 + 1, t0 + 2 + 3 * h, t0] {
            let t = t as f64;
            positions.push(meshclash::geom::DVec3::new(t, 2.0 * t, 3.0 * t));
        }
        let b = 3 * i as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    meshclash::scene::mesh::Mesh {
        positions,
        tri_object: vec![0; triangles.len()],
        triangles,
        objects: vec![meshclash::scene::mesh::Object { name: "line".into(), ..Default::default() }],
    }
}

#[test]
fn self_on_100k_collinear_overlapping_triangles_counts_every_pair_under_1_gb() {
    if !cfg!(target_os = "linux") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("r.json");
    let o = out.to_str().unwrap();
    let report = |file: &Path, extra: &[&str], kib: u64| -> (Option<i32>, serde_json::Value) {
        let f = file.to_str().unwrap();
        let args: Vec<&str> =
            ["self", f, "--no-timings", "-q", "-o", o].iter().chain(extra).copied().collect();
        let (code, err) = under_limit(kib, &args);
        assert!(err.is_empty(), "{args:?}: {err}");
        (code, serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap())
    };
    // A small instance: every pair, listed and counted, is the brute force's.
    let (n, h) = (300usize, 40usize);
    let small = d.path().join("small.obj");
    std::fs::write(&small, collinear_obj(n, h)).unwrap();
    let m = collinear_mesh(n, h);
    let (merged, _) = meshclash::scene::bodies::merge_vertices(&m.positions);
    let all: Vec<u32> = (0..n as u32).collect();
    let want = meshclash::check::self_clash::self_pairs_brute_force(&m, &merged, &all);
    assert_eq!(want.len(), (0..n).map(|i| h.min(n - 1 - i)).sum::<usize>(), "the construction");
    assert!(want.iter().all(|p| !p.hit.crossing));
    let (code, r) = report(&small, &["--max-pairs", "100000"], 1_000_000);
    assert_eq!(code, Some(0), "touching only: clear for --fail-on self-clash");
    assert_eq!(r["verdict"], "touching");
    assert_eq!(r["summary"]["touching_pairs"], want.len() as u64);
    assert_eq!(r["summary"]["crossing_pairs"], 0);
    let listed: Vec<(u64, u64)> = r["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["a"].as_u64().unwrap(), p["b"].as_u64().unwrap()))
        .collect();
    assert_eq!(listed, want.iter().map(|p| (p.a as u64, p.b as u64)).collect::<Vec<_>>());
    assert_eq!(r["pairs_truncated"], false);
    // 100,000 triangles: 3,749,975,000 pairs, counted in under 1 GB, the first 1,000 listed.
    let (n, h) = (100_000usize, 50_000usize);
    let big = d.path().join("big.obj");
    std::fs::write(&big, collinear_obj(n, h)).unwrap();
    let (code, r) = report(&big, &["--fail-on", "touching"], 1_000_000);
    assert_eq!(code, Some(1), "touching pairs fail --fail-on touching");
    assert_eq!(r["verdict"], "touching");
    assert_eq!(r["summary"]["touching_pairs"], (0..n).map(|i| h.min(n - 1 - i) as u64).sum::<u64>());
    assert_eq!(r["summary"]["crossing_pairs"], 0);
    assert_eq!(r["pairs_truncated"], true);
    let pairs = r["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), 1000);
    // The first pairs in (a, b) order: triangle 0 with 1, 2, ..., 1000.
    assert!(pairs.iter().enumerate().all(|(k, p)| p["a"] == 0 && p["b"] == k as u64 + 1));
}

/// One node with `n` EXT_mesh_gpu_instancing instances (translations 2 apart along x) of a mesh
/// of `vertices` vertices (a sparse accessor over zeros: the first three make its one triangle),
/// all in a data URI: a few bytes per instance, `n * vertices` vertices after instancing.
fn instances_of_many_vertices(path: &Path, n: usize, vertices: usize) {
    use base64::Engine;
    let mut bin: Vec<u8> = [0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()).collect(); // indices, sparse indices
    bin.extend(triangle_bytes()); // sparse values, at 8
    for i in 0..n {
        bin.extend([2.0 * i as f32, 0.0, 0.0].iter().flat_map(|x| x.to_le_bytes()));
        // at 44
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["EXT_mesh_gpu_instancing"],"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":2}}}}}}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteLength":6}},{{"buffer":0,"byteLength":6}},{{"buffer":0,"byteOffset":8,"byteLength":36}},
{{"buffer":0,"byteOffset":44,"byteLength":{t}}}],
"accessors":[{{"componentType":5126,"count":{vertices},"type":"VEC3","min":[0,0,0],"max":[1,1,0],
  "sparse":{{"count":3,"indices":{{"bufferView":1,"componentType":5123}},"values":{{"bufferView":2}}}}}},
{{"bufferView":0,"componentType":5123,"count":3,"type":"SCALAR"}},
{{"bufferView":3,"componentType":5126,"count":{n},"type":"VEC3"}}]}}"#,
        len = bin.len(),
        t = 12 * n,
    );
    std::fs::write(path, json).unwrap();
}

/// The scene check keeps a glTF scene's instances as (mesh, matrix) and places a part when it
/// reads it, so a scene past the expanded load's vertex limit loads there (and in far less
/// memory than its expansion); a request that expands the scene refuses it as before, with
/// exit 2 and the one-line message, before anything is allocated.
#[test]
fn instances_past_the_expanded_vertex_limit_load_instanced_and_are_refused_expanded() {
    let d = tempfile::tempdir().unwrap();
    let file = d.path().join("wide.gltf");
    // 4097 instances of 65,536 vertices: 2^28 + 2^16 vertices after instancing, 4097 triangles.
    instances_of_many_vertices(&file, 4097, 1 << 16);
    assert!(std::fs::metadata(&file).unwrap().len() < 100_000);
    let f = file.to_str().unwrap();
    let expanded_is_refused = |args: &[&str]| {
        let out = std::process::Command::new(exe()).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
        let message = "glTF scene has 268500992 vertices after instancing, more than the 268435456 supported";
        assert!(err.contains(f) && err.contains(message), "{args:?}: {err}");
    };
    // Splitting bodies reads the whole world mesh; two files are expanded as they load.
    expanded_is_refused(&["scene", f, "--split-bodies", "-o", "/dev/null"]);
    expanded_is_refused(&[f, concat!(env!("CARGO_MANIFEST_DIR"), "/meshes/fcl_rob.obj"), "-o", "/dev/null"]);
    // An output that draws the geometry expands the scene: refused the same way, nothing written.
    let glb = d.path().join("drawn.glb");
    expanded_is_refused(&["scene", f, "--export-glb", glb.to_str().unwrap(), "-o", "/dev/null"]);
    assert!(!glb.exists(), "a refused run wrote its drawing");
    // Instanced, it is checked (the instances are 2 apart: clear), its 6 GiB of expanded world
    // coordinates never made: it fits under 1 GiB of address space where that can be set.
    let report = d.path().join("r.json");
    let args = ["scene", f, "--no-timings", "-o", report.to_str().unwrap()];
    let (code, err) = if cfg!(target_os = "linux") {
        under_limit(1 << 20, &args)
    } else {
        let out = std::process::Command::new(exe()).args(args).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    assert_eq!(code, Some(0), "{err}");
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(r["inputs"]["a"]["vertices"], 4097u64 << 16, "{}", r["inputs"]["a"]);
    assert_eq!(r["inputs"]["a"]["triangles"], 4097, "{}", r["inputs"]["a"]);
    assert_eq!(r["verdict"], "clear");
}
