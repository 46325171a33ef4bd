//! Shared body of the fuzz targets: load the bytes with one loader and, when that succeeds,
//! check every guarantee `meshclash::load` documents. An `Err` must be one line naming the file.

/// The binary's app layer (clap definitions, validation, the runners): `src/app/`, compiled
/// here too, as the fuzz targets drive it the way `meshclash` does.
#[allow(dead_code)]
#[path = "../../src/app/mod.rs"]
mod app;

use std::path::Path;

use meshclash::load::{detect_format, load_bytes, Format};

/// Runs the loader for `format` on `data` (as a file called `name`) and checks the result.
pub fn check(name: &str, data: &[u8], format: Format) {
    let path = Path::new(name);
    // Format detection sees the same bytes first, as in `load_path`; it must not panic either.
    let _ = detect_format(path, data);
    match load_bytes(path, data, format) {
        Ok(loaded) => {
            let m = &loaded.mesh;
            assert!(!m.triangles.is_empty(), "Ok with no triangles");
            assert_eq!(m.tri_object.len(), m.triangles.len(), "tri_object length");
            let n = m.positions.len();
            for t in &m.triangles {
                for &v in t {
                    assert!((v as usize) < n, "index {v} out of range ({n} vertices)");
                }
            }
            for p in &m.positions {
                assert!(p.is_finite(), "non-finite position {p:?}");
            }
            for &o in &m.tri_object {
                assert!((o as usize) < m.objects.len(), "object {o} out of range");
            }
            for o in &m.objects {
                assert!(!o.name.is_empty(), "object without a name");
            }
        }
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with(&format!("{name}: ")), "error does not name the file: {s}");
            assert!(!s.contains('\n'), "error spans lines: {s}");
        }
    }
}

/// A scratch directory for this fuzzing process (the whole-check targets go through files,
/// as the command line does).
fn scratch() -> &'static Path {
    static DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("meshclash-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("scratch directory");
        d
    })
}

/// An error of the whole command: one line.
fn one_line(e: &meshclash::error::Error) {
    let s = e.to_string();
    assert!(!s.is_empty() && !s.contains('\n'), "error is not one line: {s:?}");
}

/// Runs `meshclash ARGS…` through the binary's app layer (`app::run`) and checks the outcome: an exit code
/// of 0 or 1 and a report that round-trips through JSON, or a one-line error.
fn run_args(args: &[&std::ffi::OsStr]) -> Option<meshclash::report::Report> {
    use clap::Parser;
    let parsed = app::args::Args::try_parse_from(args).expect("the fuzz targets build valid argv");
    let cfg = match parsed.into_config() {
        Ok(c) => c,
        Err(e) => {
            one_line(&e);
            return None;
        }
    };
    match app::run::run_with_progress(&cfg, &|_| {}) {
        Ok(out) => {
            use meshclash::error::ExitCode;
            assert!(
                matches!(out.exit_code, ExitCode::Ok | ExitCode::Findings),
                "exit code {:?}",
                out.exit_code
            );
            let json = meshclash::report::to_json(&out.report);
            let back: meshclash::report::Report = serde_json::from_str(&json).expect("report round-trips");
            assert_eq!(back.verdict, out.report.verdict);
            // The staged output files are written only on commit, as the binary does after
            // stdout; a refusal here is one line, like any other error.
            if let Err(e) = out.staged.commit() {
                one_line(&e);
                return None;
            }
            Some(*out.report)
        }
        Err(e) => {
            one_line(&e);
            None
        }
    }
}

/// Small caps for the whole-check target: a fuzzed glTF may legitimately instance a mesh up to
/// the loader's documented limits (gigabytes); such inputs are valid but not what this target
/// is for.
const MAX_TRIANGLES: usize = 4096;
const MAX_VERTICES: usize = 1 << 14;
const MAX_PARTS: usize = 64;

const EXT: [&str; 4] = ["obj", "stl", "gltf", "glb"];
const FORMATS: [Format; 4] = [Format::Obj, Format::Stl, Format::Gltf, Format::Glb];

/// The `check` target: see `fuzz_targets/check.rs`.
pub fn whole(data: &[u8]) {
    if data.len() < 2 || data.len() > 64 * 1024 {
        return;
    }
    let (ctl, cut, rest) = (data[0], data[1] as usize, &data[2..]);
    let split = (rest.len() * (cut % 65)) / 64;
    let (fa, fb) = ((ctl & 3) as usize, ((ctl >> 2) & 3) as usize);
    let (scene, split_bodies, penetration, clearance) =
        (ctl & 16 != 0, ctl & 32 != 0, ctl & 64 != 0, ctl & 128 != 0);
    let parts = [(&rest[..split], fa), (&rest[split..], fb)];
    let dir = scratch();
    let mut paths = Vec::new();
    for (i, (bytes, f)) in parts.iter().enumerate() {
        if scene && i == 0 {
            continue;
        }
        let path = dir.join(format!("{}.{}", ["a", "b"][i], EXT[*f]));
        // Inputs over the small caps (or that do not load) are skipped here: loading errors are
        // the loader targets' business, and the check must see inputs it can finish quickly.
        match load_bytes(&path, bytes, FORMATS[*f]) {
            Ok(l) => {
                let m = &l.mesh;
                if m.triangles.len() > MAX_TRIANGLES
                    || m.positions.len() > MAX_VERTICES
                    || m.objects.len() > MAX_PARTS
                {
                    return;
                }
            }
            Err(_) => return,
        }
        std::fs::write(&path, bytes).expect("scratch write");
        paths.push(path);
    }
    let mut args: Vec<std::ffi::OsString> = vec!["meshclash".into()];
    if scene {
        args.push("scene".into());
    }
    args.extend(paths.iter().map(|p| p.clone().into_os_string()));
    args.extend(["--no-timings", "--threads", "1", "--max-pairs", "50"].map(Into::into));
    if split_bodies {
        args.push("--split-bodies".into());
    }
    if penetration {
        args.push("--penetration".into());
    }
    if clearance {
        args.push("--clearance=1e-3rel".into());
    }
    let argv: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    if let Some(rep) = run_args(&argv) {
        assert!(rep.pairs.len() <= 50, "max-pairs not honoured");
    }
}

/// The `clash_set` target: see `fuzz_targets/clash_set.rs`.
pub fn clash_set(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("fuzz-set.json");
    let run = app::clash_set::ClashSetArgs::default();
    match app::clash_set::parse(file, text, &run) {
        Ok(checks) => {
            assert!(!checks.is_empty(), "Ok with no checks");
            for c in &checks {
                assert!(!c.name.is_empty(), "a check without a name");
                assert!(c.argv.len() >= 3, "argv too short: {:?}", c.argv);
            }
        }
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("fuzz-set.json: "), "error does not name the file: {s}");
            assert!(!s.contains('\n'), "error spans lines: {s}");
        }
    }
}

/// Two small meshes that touch (the same tetrahedra twice), for the `baseline` target.
const TETRAHEDRA: &[u8] = include_bytes!("../../meshes/joined_tetrahedra.obj");

/// The `baseline` target: see `fuzz_targets/baseline.rs`.
pub fn baseline(data: &[u8]) {
    let parsed = meshclash::report::baseline::parse("fuzz-base.json", data);
    let base = match parsed {
        Ok(b) => b,
        Err(msg) => {
            assert!(!msg.contains('\n'), "error spans lines: {msg}");
            return;
        }
    };
    let dir = scratch();
    let (a, b, r) = (dir.join("base-a.obj"), dir.join("base-b.obj"), dir.join("base.json"));
    if !a.exists() {
        std::fs::write(&a, TETRAHEDRA).expect("scratch write");
        std::fs::write(&b, TETRAHEDRA).expect("scratch write");
    }
    std::fs::write(&r, data).expect("scratch write");
    let args: Vec<std::ffi::OsString> = vec![
        "meshclash".into(),
        a.into_os_string(),
        b.into_os_string(),
        "--no-timings".into(),
        "--threads".into(),
        "1".into(),
        "--fail-on".into(),
        "new".into(),
        "--baseline".into(),
        r.into_os_string(),
    ];
    let argv: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let rep = run_args(&argv).expect("a baseline that parses is accepted");
    let block = rep.baseline.as_ref().expect("baseline block");
    let _ = (block, base.ids.len());
}

/// The `self_fans` target: a small part built from the bytes with the shapes `self` used to be
/// quadratic on (fans around one vertex, copies of one face, point and segment triangles,
/// books of triangles on one edge), integer coordinates in [-4, 4]; `self_pairs` (every leaf
/// size) must equal the brute force over every pair.
pub fn self_fans(data: &[u8]) {
    use meshclash::check::self_clash::{self_pairs, self_pairs_brute_force};
    use meshclash::geom::DVec3;
    if data.len() < 4 || data.len() > 4096 {
        return;
    }
    let c = |b: u8| (b % 9) as f64 - 4.0;
    let mut positions = vec![DVec3::ZERO, DVec3::new(0.0, 0.0, 1.0)];
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for chunk in data.chunks_exact(4).take(300) {
        let p = DVec3::new(c(chunk[1]), c(chunk[2]), c(chunk[3]));
        positions.push(p);
        let last = positions.len() as u32 - 1;
        let prev = if last > 2 { last - 1 } else { last };
        let t = match chunk[0] % 6 {
            0 | 1 => [0, prev, last], // a fan around vertex 0
            2 => [1, 0, last],        // a book on the edge 0-1
            3 => triangles.last().copied().unwrap_or([0, 1, last]).map(|v| v.min(last)), // a copy
            4 => [last, last, last],  // a point
            _ => [0, last, last],     // a segment from vertex 0
        };
        triangles.push(if chunk[0] & 64 != 0 { [t[2], t[1], t[0]] } else { t });
    }
    let mesh = meshclash::scene::mesh::Mesh {
        tri_object: vec![0; triangles.len()],
        triangles,
        positions,
        objects: vec![meshclash::scene::mesh::Object { name: "fuzz".into(), ..Default::default() }],
    };
    let (merged, _) = meshclash::scene::bodies::merge_vertices(&mesh.positions);
    let all: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
    let want = self_pairs_brute_force(&mesh, &merged, &all);
    for leaf_size in [1, 4] {
        let opts = meshclash::bvh::BuildOptions { leaf_size, ..Default::default() };
        let got = self_pairs(&mesh, &merged, &all, opts);
        assert_eq!(got, want, "leaf size {leaf_size}");
    }
}

/// The `writers` target: two crossing triangles in a glTF whose node names are the fuzzed
/// bytes (any Unicode, control characters included), checked with every report writer
/// (`-o` JSON, `--junit`, `--bcf` 2.1 or 3.0, `--html`, `--export-glb`) and the text summary:
/// the JSON and every XML file must parse, and the text summary holds no control character
/// but newlines.
pub fn writers(data: &[u8]) {
    use std::io::Read;
    if data.is_empty() || data.len() > 512 {
        return;
    }
    let text = String::from_utf8_lossy(&data[1..]);
    let cut = text.char_indices().nth(text.chars().count() / 2).map_or(text.len(), |(i, _)| i);
    let (na, nb) = (&text[..cut], &text[cut..]);
    let positions: [f32; 18] =
        [0., 0., 0., 2., 0., 0., 0., 2., 0., 0.5, 0.5, -1., 0.5, 0.5, 1., 1.5, 0.5, 1.];
    let bytes: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    let b64 = {
        use std::fmt::Write;
        // Hex would not be a data URI: encode base64 by hand (no extra dependency).
        const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for ch in bytes.chunks(3) {
            let n = (ch[0] as u32) << 16
                | (*ch.get(1).unwrap_or(&0) as u32) << 8
                | *ch.get(2).unwrap_or(&0) as u32;
            for k in 0..4 {
                let _ = if k <= ch.len() {
                    s.write_char(A[(n >> (18 - 6 * k) & 63) as usize] as char)
                } else {
                    s.write_char('=')
                };
            }
        }
        s
    };
    let gltf = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": na, "mesh": 0}, {"name": nb, "mesh": 1}],
        "meshes": [{"name": na, "primitives": [{"attributes": {"POSITION": 0}}]},
                   {"name": nb, "primitives": [{"attributes": {"POSITION": 1}}]}],
        "buffers": [{"byteLength": 72, "uri": format!("data:application/octet-stream;base64,{b64}")}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 36}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [2, 2, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0.5, 0.5, -1], "max": [1.5, 0.5, 1]}
        ]
    });
    let dir = scratch();
    let input = dir.join("names.gltf");
    std::fs::write(&input, gltf.to_string()).expect("scratch write");
    let out = |n: &str| dir.join(n).into_os_string();
    // Nothing left over from the previous input can pass for this one's output.
    for n in ["w.json", "w.xml", "w.bcfzip", "w.html", "w.glb"] {
        let _ = std::fs::remove_file(dir.join(n));
    }
    let version = if data[0] & 1 == 0 { "2.1" } else { "3.0" };
    let args: Vec<std::ffi::OsString> = vec![
        "meshclash".into(),
        "scene".into(),
        input.into_os_string(),
        "--no-timings".into(),
        "--threads".into(),
        "1".into(),
        "-o".into(),
        out("w.json"),
        "--junit".into(),
        out("w.xml"),
        "--bcf".into(),
        out("w.bcfzip"),
        "--bcf-version".into(),
        version.into(),
        "--html".into(),
        out("w.html"),
        "--export-glb".into(),
        out("w.glb"),
    ];
    let argv: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let Some(rep) = run_args(&argv) else { return };
    let summary = meshclash::output::text::render(&rep, false);
    assert!(!summary.chars().any(|c| c.is_control() && c != '\n'), "control character in {summary:?}");
    let json = std::fs::read(dir.join("w.json")).expect("report written");
    serde_json::from_slice::<serde_json::Value>(&json).expect("report is JSON");
    let junit = std::fs::read_to_string(dir.join("w.xml")).expect("junit written");
    roxmltree::Document::parse(&junit).expect("junit is XML");
    let mut z =
        zip::ZipArchive::new(std::fs::File::open(dir.join("w.bcfzip")).expect("bcf written")).expect("zip");
    for i in 0..z.len() {
        let mut f = z.by_index(i).expect("member");
        let mut s = String::new();
        f.read_to_string(&mut s).expect("UTF-8 member");
        roxmltree::Document::parse(&s).unwrap_or_else(|e| panic!("BCF member {i}: {e}"));
    }
}

/// The `merge_inputs` target: the bytes as a shard plan (`Plan::parse`) and as a shard report
/// (its serde form, then each outcome read back against a small part count): `Ok`, or a one-line
/// error, never a panic.
pub fn merge_inputs(data: &[u8]) {
    if let Err(e) = meshclash::shard::plan::Plan::parse(data) {
        assert!(!e.contains('\n'), "plan error spans lines: {e}");
    }
    if let Ok(r) = serde_json::from_slice::<meshclash::shard::ShardReport>(data) {
        if let Some(o) = &r.outcome {
            if let Err(e) = o.outcome(8) {
                assert!(!e.contains('\n'), "outcome error spans lines: {e}");
            }
        }
    }
}

/// The `arrays` target (what the Python package hands over): the bytes as `f64` coordinates
/// and `i64` indices (byte 0 splits them), through `api::triangles_from` and
/// `api::mesh_from_arrays`: `Ok` with every index in range, or a one-line error naming the
/// label.
pub fn arrays(data: &[u8]) {
    use meshclash::geom::DVec3;
    if data.len() < 2 || data.len() > 1 << 16 {
        return;
    }
    let rest = &data[1..];
    let cut = (rest.len() * data[0] as usize / 256) / 24 * 24;
    let coords: Vec<f64> =
        rest[..cut].chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap())).collect();
    let idx: Vec<i64> =
        rest[cut..].chunks_exact(8).map(|b| i64::from_le_bytes(b.try_into().unwrap())).collect();
    let positions: Vec<DVec3> = coords.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
    let label = Path::new("<arrays>");
    let tris = match meshclash::api::triangles_from(label, &idx, positions.len()) {
        Ok(t) => t,
        Err(e) => {
            one_line(&e);
            assert!(e.to_string().starts_with("<arrays>"), "{e}");
            return;
        }
    };
    match meshclash::api::mesh_from_arrays(label, "fuzz", positions, tris) {
        Ok(m) => {
            let n = m.positions.len();
            assert!(m.triangles.iter().flatten().all(|&v| (v as usize) < n));
            assert!(m.positions.iter().all(|p| p.is_finite()));
        }
        Err(e) => one_line(&e),
    }
}
