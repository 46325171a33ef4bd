//! `meshclash scene FILE --self` through the real binary: the `self` block agrees with
//! `meshclash self` part by part (instances included), is byte-identical across thread counts,
//! sets the exit code by `--fail-on` and `--self-fail-on`, adds a JUnit case per part with a
//! problem and summary lines, and is absent without `--self`.

use assert_cmd::Command;
use meshclash::report::self_report::SelfReport;
use meshclash::report::Report;
use std::path::{Path, PathBuf};

use crate::common::corpus;

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// `meshclash scene FILE ARGS --no-timings -q`: (stdout, exit code).
fn scene(file: &Path, args: &[&str]) -> (Vec<u8>, i32) {
    let out = bin().arg("scene").arg(file).args(args).args(["--no-timings", "-q"]).output().unwrap();
    assert!(out.stderr.is_empty(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    (out.stdout, out.status.code().unwrap())
}

/// Parse a scene report, validated against the checked-in schema, unknown fields denied.
fn parse(stdout: &[u8]) -> (Report, serde_json::Value) {
    let v: serde_json::Value = serde_json::from_slice(stdout).expect("stdout is JSON");
    let schema: serde_json::Value = serde_json::from_str(&meshclash::output::schema_json()).unwrap();
    assert!(jsonschema::is_valid(&schema, &v), "report does not match its schema");
    (serde_json::from_value(v.clone()).expect("report matches the wire types"), v)
}

/// Two objects far apart: `strip`, folded back through itself (2 crossing, 2 touching pairs, open),
/// and `cube`, a clean closed unit cube.
fn strip_and_cube(dir: &Path) -> PathBuf {
    let strip = [
        [0., 0., 0.],
        [0., 1., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [1., 0., 1.],
        [1., 1., 1.],
        [1., 0., -1.],
        [1., 1., -1.],
    ];
    let strip_f = [[0, 2, 3], [0, 3, 1], [2, 4, 5], [2, 5, 3], [4, 5, 7], [4, 7, 6]];
    let mut s = String::from("o strip\n");
    for p in strip {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in strip_f {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s += "o cube\n";
    for i in 0..8 {
        let (x, y, z) = ((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        s += &format!("v {} {} {}\n", x + 10.0, y, z);
    }
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            s += &format!("f {} {} {}\n", t[0] + 9, t[1] + 9, t[2] + 9);
        }
    }
    let path = dir.join("strip_and_cube.obj");
    std::fs::write(&path, s).unwrap();
    path
}

#[test]
fn without_self_there_is_no_self_block_and_a_self_crossing_part_alone_does_not_fail() {
    let dir = tempfile::tempdir().unwrap();
    let file = strip_and_cube(dir.path());
    let (out, code) = scene(&file, &[]);
    let (r, v) = parse(&out);
    assert_eq!((r.verdict.name(), code), ("clear", 0));
    assert!(v.get("self").is_none() && r.self_check.is_none());
}

#[test]
fn a_self_crossing_part_fails_the_scene_under_fail_on_clash() {
    let dir = tempfile::tempdir().unwrap();
    let file = strip_and_cube(dir.path());
    let (out, code) = scene(&file, &["--self"]);
    let (r, _) = parse(&out);
    let s = r.self_check.as_ref().expect("self block");
    // Part against part nothing changes; the self block fails the run.
    assert_eq!((r.verdict.name(), r.failed, code), ("clear", true, 1));
    assert_eq!((s.verdict.name(), s.failed), ("clash", true));
    assert_eq!(
        (s.fail_on.clone(), s.failed_on.clone()),
        (vec!["self-clash".to_string()], vec!["self-clash".to_string()])
    );
    assert_eq!((s.summary.parts, s.summary.crossing_pairs, s.summary.touching_pairs), (2, 2, 2));
    assert_eq!((s.summary.parts_with_self_clash, s.summary.open_parts, s.checks), (1, 1, 2));
    let names: Vec<(&str, usize, u64, bool)> =
        s.parts.iter().map(|p| (p.name.as_str(), p.part, p.crossing_pairs, p.health.closed)).collect();
    assert_eq!(names, [("strip", 0, 2, false), ("cube", 1, 0, true)]);
    assert_eq!(r.parts[s.parts[1].part].name, "cube");
    assert!(s.pairs.iter().all(|p| p.a < p.b && p.a_object == 0 && p.b_object == 0));
    assert_eq!(s.pairs.len(), 4);
    // The cube is fine: selecting it alone passes; --fail-on never passes; touching fails.
    assert_eq!(scene(&file, &["--self", "--select-a", "cube"]).1, 0);
    assert_eq!(scene(&file, &["--self", "--fail-on", "never"]).1, 0);
    let (out, code) = scene(&file, &["--self", "--fail-on", "touching"]);
    assert_eq!((parse(&out).0.self_check.unwrap().failed_on, code), (vec!["touching".to_string()], 1));
}

#[test]
fn self_fail_on_selects_health_findings() {
    let dir = tempfile::tempdir().unwrap();
    let file = strip_and_cube(dir.path());
    let (out, code) = scene(&file, &["--self", "--fail-on", "never", "--self-fail-on", "open,duplicates"]);
    let s = parse(&out).0.self_check.unwrap();
    assert_eq!(code, 1);
    assert_eq!(s.fail_on, ["open", "duplicates"]);
    assert_eq!(s.failed_on, ["open"]);
    // Without --self it is a usage error (exit 2, one line), as is --self without scene.
    let out = bin().arg("scene").arg(&file).args(["--self-fail-on", "open"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let out = bin().arg(&file).arg(&file).arg("--self").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("meshclash: error: ") && err.contains("--self works with scene"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn junit_has_a_case_per_part_with_a_problem_and_text_has_self_lines() {
    let dir = tempfile::tempdir().unwrap();
    let file = strip_and_cube(dir.path());
    let junit = dir.path().join("j.xml");
    let (out, code) = scene(&file, &["--self", "--format", "text", "--junit", junit.to_str().unwrap()]);
    assert_eq!(code, 1);
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("  self: clash — 2 crossing, 2 touching self-clash pairs in 1 of 2 part(s) — FAILED on self-clash"), "{text}");
    assert!(text.contains("    strip: 2 crossing pairs, 2 touching pairs, "), "{text}");
    assert!(!text.contains("    cube:"), "{text}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let cases: Vec<(String, bool)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .map(|n| (n.attribute("name").unwrap().to_string(), n.children().any(|c| c.has_tag_name("failure"))))
        .collect();
    let strip = cases.iter().find(|c| c.0 == "strip (self)").expect("a case for the strip");
    assert!(strip.1, "the strip's case fails");
    assert!(!cases.iter().any(|c| c.0 == "cube (self)"), "no case for the clean cube: {cases:?}");
    // Whole-run case fails too (the run failed).
    assert!(cases[0].1);
}

/// The engine (67 parts, instanced meshes, zero-area triangles): the self block says exactly what
/// `meshclash self` says part by part, and does not depend on the thread count.
#[test]
fn engine_self_block_matches_meshclash_self_and_threads() {
    let Some(engine) = corpus("2CylinderEngine.glb") else { return };
    let (one, code1) = scene(&engine, &["--self", "--threads", "1", "--max-pairs", "100000"]);
    let (two, code2) = scene(&engine, &["--self", "--threads", "2", "--max-pairs", "100000"]);
    assert!(one == two, "reports differ between 1 and 2 threads");
    assert_eq!((code1, code2), (1, 1));
    let s = parse(&one).0.self_check.unwrap();
    let out = bin()
        .arg("self")
        .arg(&engine)
        .args(["--no-timings", "-q", "--fail-on", "never", "--max-pairs", "100000"])
        .output()
        .unwrap();
    let alone: SelfReport = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(s.summary, alone.summary);
    assert_eq!(s.pairs, alone.pairs);
    assert!(!s.pairs_truncated && !alone.pairs_truncated);
    assert_eq!(s.parts.len(), alone.parts.len());
    for (x, y) in s.parts.iter().zip(&alone.parts) {
        assert_eq!((&x.name, Some(x.object), x.triangles), (&y.name, y.object, y.triangles));
        assert_eq!((x.crossing_pairs, x.touching_pairs), (y.crossing_pairs, y.touching_pairs), "{}", x.name);
        assert_eq!(x.health, y.health, "{}", x.name);
    }
    // Known: zero-area triangles (SOURCES.md); some instances are exact translates of another
    // and were not walked again, and their results still match the separate checks above.
    assert!(s.summary.zero_area_triangles > 0);
    assert!(s.checks < s.parts.len(), "no instance was reused");
    for p in s.parts.iter().filter(|p| p.same_as.is_some()) {
        assert!(p.same_as.unwrap() < p.part);
    }
}

/// `--fail-on new` replaced the run's failure with the baseline comparison alone, so a
/// `--self-fail-on` condition of `scene --self` no longer failed the run.
#[test]
fn fail_on_new_keeps_a_failing_self_block_failing() {
    let Some(engine) = corpus("2CylinderEngine.glb") else { return };
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("base.json");
    let run = |extra: &[&str]| {
        assert_cmd::Command::cargo_bin("meshclash")
            .unwrap()
            .arg("scene")
            .arg(&engine)
            .args(["--self", "--self-fail-on", "degenerate", "--no-timings", "-q"])
            .args(extra)
            .output()
            .unwrap()
    };
    // The baseline is the same run: nothing new, but the engine has zero-area triangles.
    let first = run(&["--fail-on", "never", "-o", base.to_str().unwrap()]);
    assert_eq!(first.status.code(), Some(1), "zero-area triangles fail under --self-fail-on degenerate");
    let again = run(&["--baseline", base.to_str().unwrap(), "--fail-on", "new"]);
    assert_eq!(again.status.code(), Some(1), "{}", String::from_utf8_lossy(&again.stderr));
}
