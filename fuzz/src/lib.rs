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
