//! The real binary: exit codes, report file, one-line errors, determinism, schema.

use assert_cmd::Command;
use meshclash::report::Report;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn shipped(name: &str) -> String {
    root().join("meshes").join(name).display().to_string()
}

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// Parse with unknown fields denied (the report types say `deny_unknown_fields`), and check the
/// top-level keys against the documented list independently of those types.
fn parse(stdout: &[u8]) -> Report {
    let v: serde_json::Value = serde_json::from_slice(stdout).expect("stdout is JSON");
    // Blocks present only when they apply: `unlisted` (a cut list), `baseline`, `self`,
    // `complete` and `missing_shards` (a partial merge).
    let optional = ["unlisted", "baseline", "self", "complete", "missing_shards"];
    let keys: Vec<&str> =
        v.as_object().unwrap().keys().map(String::as_str).filter(|k| !optional.contains(k)).collect();
    let documented = [
        "schema",
        "tool",
        "inputs",
        "settings",
        "verdict",
        "failed",
        "summary",
        "closest",
        "pairs",
        "pairs_truncated",
        "bvh",
        "cross_check",
        "assembly",
        "parts",
        "part_pairs",
        "regions",
        "warnings",
        "timings_ms",
    ];
    let mut k = keys.clone();
    k.sort();
    let mut d = documented.to_vec();
    d.sort();
    assert_eq!(k, d);
    serde_json::from_value(v).expect("report matches the documented schema")
}

#[test]
fn main_job_on_shipped_meshes_reports_the_clash_and_exits_1() {
    let out = bin().args([shipped("fcl_env.obj"), shipped("fcl_rob.obj")]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = parse(&out.stdout);
    assert_eq!(r.schema, "meshclash.report/2");
    assert_eq!(r.verdict, "clash");
    assert!(r.failed);
    assert_eq!(r.summary.min_distance, Some(0.0));
    assert_eq!(r.inputs.a.triangles, 2180);
    assert_eq!(r.pairs.len() as u64, r.summary.crossing_pairs + r.summary.touching_pairs);
    // Sorted by (a, b), every listed pair a crossing with its segment.
    assert!(r.pairs.windows(2).all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b)));
    assert!(r.pairs.iter().all(|p| p.kind == "crossing" && p.segment.is_some()));
    // The count line of the FCL file is reported as a warning on stderr, once per file.
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().filter(|l| l.contains("warning")).count(), 2, "{err}");
    assert_eq!(r.warnings.len(), 2);
}

#[test]
fn fail_on_never_and_far_apart_exit_0() {
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "--fail-on", "never", "-q"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty(), "--quiet silences warnings");
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "--translate-b", "0,0,10000"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let r = parse(&out.stdout);
    assert_eq!(r.verdict, "clear");
    let c = r.closest.unwrap();
    let d: f64 = (0..3).map(|k| (c.a.point[k] - c.b.point[k]).powi(2)).sum::<f64>().sqrt();
    assert!((d - c.distance).abs() <= 1e-9 * c.distance);
    assert!(c.distance > 0.0 && r.pairs.is_empty());
}

#[test]
fn clearance_and_fail_on_clearance() {
    // multibody: two bodies 0.507 apart in one file; compare the file with itself moved far
    // enough that only the clearance band catches it.
    let f = shipped("multibody.stl");
    let base = bin().args([&f, &f, "--translate-b", "0,0,100", "-q"]).output().unwrap();
    let d = parse(&base.stdout).summary.min_distance.unwrap();
    let clearance = format!("{}", d * 1.01);
    let out = bin()
        .args([&f, &f, "--translate-b", "0,0,100", "--clearance", &clearance, "--fail-on", "clearance"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = parse(&out.stdout);
    assert_eq!(r.verdict, "clearance");
    assert!(r.summary.clearance_pairs > 0);
    assert!(r.pairs.iter().all(|p| p.kind == "clearance" && p.distance < d * 1.01 && p.distance >= d));
}

#[test]
fn output_file_is_written_and_stdout_stays_empty() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("report.json");
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q", "-o", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let r = parse(&std::fs::read(&path).unwrap());
    assert_eq!(r.verdict, "clash");
    // Nothing but the report is left behind (the temporary file was renamed).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn max_pairs_truncates_the_list_not_the_counts() {
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q", "--max-pairs", "5"])
        .output()
        .unwrap();
    let r = parse(&out.stdout);
    assert_eq!(r.pairs.len(), 5);
    assert!(r.pairs_truncated);
    assert!(r.summary.crossing_pairs > 5);
}

fn error_line(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "args {args:?}");
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr).unwrap();
    // One error, under the one prefix; a usage error found by clap keeps clap's whole message
    // (allowed values, tips) on the lines after it.
    assert!(err.starts_with("meshclash: error: "), "{err}");
    assert_eq!(err.matches("error:").count(), 1, "one error: {err}");
    err
}

#[test]
fn bad_input_is_one_line_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let ok = shipped("fcl_rob.obj");
    let missing = dir.path().join("nope.obj");
    let err = error_line(&[missing.to_str().unwrap(), &ok]);
    assert!(err.contains("nope.obj"), "{err}");
    let ply = dir.path().join("x.ply");
    std::fs::write(&ply, "ply\n").unwrap();
    assert!(error_line(&[&ok, ply.to_str().unwrap()]).contains("x.ply"));
    let empty = dir.path().join("empty.stl");
    std::fs::write(&empty, "").unwrap();
    assert!(error_line(&[&ok, empty.to_str().unwrap()]).contains("empty.stl"));
    let nan = dir.path().join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert!(error_line(&[&ok, nan.to_str().unwrap()]).contains("nan.obj"));
    let idx = dir.path().join("idx.obj");
    std::fs::write(&idx, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    assert!(error_line(&[&ok, idx.to_str().unwrap()]).contains("idx.obj"));
}

#[test]
fn bad_arguments_exit_2() {
    let ok = shipped("fcl_rob.obj");
    assert!(error_line(&[&ok, &ok, "--transform-a", "1,0,0"]).contains("transform-a"));
    assert!(error_line(&[&ok, &ok, "--transform-b", "1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,1"]).contains("last row"));
    assert!(error_line(&[&ok, &ok, "--translate-a", "1,2"]).contains("translate-a"));
    assert!(error_line(&[&ok, &ok, "--clearance", "-1"]).contains("clearance"));
    assert!(error_line(&[&ok, &ok, "--leaf-size", "0"]).contains("leaf-size"));
    let out = bin().args([&ok]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn transform_and_translate_agree() {
    let a = shipped("fcl_env.obj");
    let b = shipped("fcl_rob.obj");
    let t = bin().args([&a, &b, "-q", "--no-timings", "--translate-a", "10,-20,30"]).output().unwrap();
    let m = bin()
        .args([&a, &b, "-q", "--no-timings", "--transform-a", "1,0,0,10,0,1,0,-20,0,0,1,30"])
        .output()
        .unwrap();
    let (t, m) = (parse(&t.stdout), parse(&m.stdout));
    assert_eq!(t.summary, m.summary);
    assert_eq!(t.pairs, m.pairs);
}

#[test]
fn byte_identical_across_thread_counts_on_the_bunny() {
    let Some(bunny) = crate::common::corpus("stanford-bunny.obj") else { return };
    let b = bunny.to_str().unwrap();
    // A moved, rotated copy that cuts through the original.
    let m = "0.8,-0.6,0,0.01,0.6,0.8,0,0.005,0,0,1,0.002";
    let run = |threads: &str| {
        let out = bin()
            .args([b, b, "--transform-b", m, "--no-timings", "--threads", threads, "--clearance", "0.0005"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        out.stdout
    };
    let one = run("1");
    let r = parse(&one);
    assert!(r.summary.crossing_pairs > 0 && r.summary.clearance_pairs > 0);
    assert!(r.timings_ms.is_none() && r.settings.threads.is_none());
    assert_eq!(run("2"), one);
    assert_eq!(run("4"), one);
}

#[test]
fn cross_check_with_parry_lists_disagreements() {
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q", "--cross-check", "parry"])
        .output()
        .unwrap();
    let r = parse(&out.stdout);
    let cc = r.cross_check.expect("cross_check block");
    assert!(cc.intersects && cc.verdict_agrees);
    assert_eq!(cc.distance, 0.0);
    // Every pair parry reports and we do not must be one we can show is apart; and vice versa.
    assert_eq!(cc.only_meshclash_count, cc.only_meshclash.len());
    assert_eq!(
        cc.intersecting_pairs as i64 - cc.only_parry_count as i64 + cc.only_meshclash_count as i64,
        (r.summary.crossing_pairs + r.summary.touching_pairs) as i64
    );
    let none = bin().args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q"]).output().unwrap();
    assert!(parse(&none.stdout).cross_check.is_none());
}

/// An axis-aligned box as an OBJ file (12 triangles, closed).
fn cube_obj(dir: &std::path::Path, name: &str, min: [f64; 3], max: [f64; 3]) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let c = |k: usize| if i >> k & 1 == 0 { min[k] } else { max[k] };
        s += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    for q in [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, 3], [2, 4, 8, 6]] {
        s += &format!("f {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    let path = dir.join(name);
    std::fs::write(&path, s).unwrap();
    path.display().to_string()
}

#[test]
fn a_part_hidden_inside_another_is_a_clash() {
    let dir = tempfile::tempdir().unwrap();
    let outer = cube_obj(dir.path(), "outer.obj", [0.0; 3], [10.0; 3]);
    let inner = cube_obj(dir.path(), "inner.obj", [4.0; 3], [5.0; 3]);
    let out = bin().args([&inner, &outer]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = parse(&out.stdout);
    assert_eq!(r.verdict, "clash");
    assert_eq!(r.summary.contained.map(|c| c.name()), Some("a_in_b"));
    // Containment needed both sides' topology, so closedness was computed and reported.
    assert_eq!((r.inputs.a.closed, r.inputs.b.closed), (Some(true), Some(true)));
    assert!(r.pairs.is_empty());
    assert_eq!(r.summary.min_distance, Some(4.0));
    let out = bin().args([&outer, &inner]).output().unwrap();
    assert_eq!(parse(&out.stdout).summary.contained.map(|c| c.name()), Some("b_in_a"));
    // Touching the container's wall from inside: the faces coincide with the same outward
    // normal, so the solids share volume: a clash, though no pair crosses.
    let touching = cube_obj(dir.path(), "touch.obj", [0.0, 4.0, 4.0], [1.0, 5.0, 5.0]);
    let r = parse(&bin().args([&touching, &outer]).output().unwrap().stdout);
    assert_eq!((r.verdict.name(), r.summary.crossing_pairs), ("clash", 0));
    assert_eq!(r.summary.contained.map(|c| c.name()), Some("volumes_overlap"));
    // Stacked on the outside: opposite normals, plain contact.
    let stacked = cube_obj(dir.path(), "stack.obj", [10.0, 4.0, 4.0], [11.0, 5.0, 5.0]);
    let r = parse(&bin().args([&stacked, &outer]).output().unwrap().stdout);
    assert_eq!((r.verdict.name(), r.summary.contained.map(|c| c.name())), ("touching", None));
    // Outside: clear.
    let apart = cube_obj(dir.path(), "apart.obj", [20.0; 3], [21.0; 3]);
    let r = parse(&bin().args([&apart, &outer]).output().unwrap().stdout);
    assert_eq!((r.verdict.name(), r.summary.contained.map(|c| c.name())), ("clear", None));
    // Boxes that cannot nest and faces that do not touch: no verdict needs an inside, so
    // closedness is not computed (null in the report), not guessed.
    assert_eq!((r.inputs.a.closed, r.inputs.b.closed), (None, None));
}

#[test]
fn open_container_makes_containment_undecided() {
    let dir = tempfile::tempdir().unwrap();
    let inner = cube_obj(dir.path(), "inner.obj", [4.0; 3], [5.0; 3]);
    let outer = cube_obj(dir.path(), "outer.obj", [0.0; 3], [10.0; 3]);
    let text = std::fs::read_to_string(&outer).unwrap();
    let open: String = text.lines().filter(|l| *l != "f 5 6 8 7").map(|l| format!("{l}\n")).collect();
    std::fs::write(&outer, open).unwrap();
    let r = parse(&bin().args([&inner, &outer]).output().unwrap().stdout);
    assert_eq!(r.inputs.b.closed, Some(false));
    assert_eq!(r.summary.contained.map(|c| c.name()), Some("undecided"));
    assert!(r.summary.contained_reason.unwrap().contains("not closed"));
    assert_eq!(r.verdict, "clear");
}

#[test]
fn relative_tolerances_resolve_against_model_size() {
    let dir = tempfile::tempdir().unwrap();
    let a = cube_obj(dir.path(), "a.obj", [0.0; 3], [1.0; 3]);
    let b = cube_obj(dir.path(), "b.obj", [1.25, 0.0, 0.0], [2.0, 1.0, 1.0]);
    let out = bin().args([&a, &b, "--clearance", "0.1rel"]).output().unwrap();
    let r = parse(&out.stdout);
    let size = (4.0f64 + 1.0 + 1.0).sqrt(); // box (0,0,0)-(2,1,1)
    assert!((r.settings.model_size - size).abs() < 1e-12);
    assert_eq!(r.settings.clearance_given, "0.1rel");
    assert!((r.settings.clearance - 0.1 * size).abs() < 1e-12);
    // The gap is 0.25: 0.1 × 2.449 = 0.245 does not reach it, 0.2 × 2.449 = 0.49 does.
    assert_eq!(r.verdict, "clear");
    let r = parse(&bin().args([&a, &b, "--clearance", "0.2rel"]).output().unwrap().stdout);
    assert_eq!(r.verdict, "clearance");
    let r = parse(&bin().args([&a, &b, "--clearance", "0.3"]).output().unwrap().stdout);
    assert_eq!((r.verdict.name(), r.settings.clearance_given.as_str()), ("clearance", "0.3"));
}

#[test]
fn coordinates_outside_the_exact_range_are_rejected_or_flagged() {
    let dir = tempfile::tempdir().unwrap();
    let ok = shipped("fcl_rob.obj");
    let huge = dir.path().join("huge.obj");
    std::fs::write(&huge, "v 0 0 0\nv 1e120 0 0\nv 0 1e120 0\nf 1 2 3\n").unwrap();
    let err = error_line(&[&ok, huge.to_str().unwrap()]);
    assert!(err.contains("huge.obj") && err.contains("2^250"), "{err}");
    let tiny = dir.path().join("tiny.obj");
    std::fs::write(&tiny, "v 0 0 0\nv 1 0 1e-300\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = bin().args([&ok, tiny.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let r = parse(&out.stdout);
    assert!(r.warnings.iter().any(|w| w.contains("below 2^-250")), "{:?}", r.warnings);
}

#[test]
fn scene_checks_every_part_against_every_other() {
    let out = bin().args(["scene", &shipped("pins.glb"), "--no-timings"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = parse(&out.stdout);
    assert_eq!(r.schema, "meshclash.report/2");
    assert_eq!(r.assembly.mode, "parts");
    assert_eq!(r.parts.len(), 7);
    // The six dowels pass through the plate; no dowel meets another.
    assert_eq!(r.part_pairs.len(), 6);
    assert!(r.part_pairs.iter().all(|p| p.verdict == "clash" && p.a_name.contains("sides")));
    assert!(r.assembly.sah_builds.unwrap() <= 2, "one build per distinct mesh");
    let total: u64 = r.part_pairs.iter().map(|p| p.crossing_pairs).sum();
    assert_eq!(total, r.summary.crossing_pairs);
    // JUnit: the whole run plus one failing case per clashing part pair, named by the parts.
    let junit = bin().args(["scene", &shipped("pins.glb"), "--format", "junit"]).output().unwrap();
    let xml = String::from_utf8(junit.stdout).unwrap();
    assert_eq!(xml.matches("<testcase").count(), 7);
    assert_eq!(xml.matches("<failure").count(), 7);
    assert!(xml.contains(&r.part_pairs[0].b_name));
    // One interference region per dowel, covering every pair, with distinct stable ids.
    assert_eq!(r.regions.len(), 6);
    let in_regions: usize = r.regions.iter().map(|g| g.pairs).sum();
    assert_eq!(in_regions as u64, r.summary.crossing_pairs + r.summary.touching_pairs);
    let ids: std::collections::BTreeSet<&str> = r.regions.iter().map(|g| g.id.as_str()).collect();
    assert_eq!(ids.len(), 6);
    // A selection: one dowel against the plate.
    let dowel = &r.part_pairs[0].b_name;
    let out = bin()
        .args(["scene", &shipped("pins.glb"), "--select-a", "*sides*", "--select-b", dowel, "--no-timings"])
        .output()
        .unwrap();
    let s = parse(&out.stdout);
    assert_eq!(s.part_pairs.len(), 1);
    assert_eq!(s.part_pairs[0].crossing_pairs, r.part_pairs[0].crossing_pairs);
    // Excluding the plate leaves only dowels, which do not meet.
    let out = bin().args(["scene", &shipped("pins.glb"), "--exclude", "*sides*"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(parse(&out.stdout).verdict, "clear");
    // A selection matching nothing is an error naming it.
    assert!(error_line(&["scene", &shipped("pins.glb"), "--select-a", "nothing*"]).contains("nothing*"));
}

#[test]
fn two_files_report_part_pairs_by_object() {
    let out = bin().args([&shipped("multibody.stl"), &shipped("multibody.stl"), "-q"]).output().unwrap();
    let r = parse(&out.stdout);
    assert_eq!(r.assembly.mode, "files");
    assert_eq!(r.parts.len(), 4); // two solids in each input
                                  // Each solid coincides with its own copy and is 0.507 away from the other one.
    let mut pairs: Vec<(String, String)> =
        r.part_pairs.iter().map(|p| (p.a_name.clone(), p.b_name.clone())).collect();
    pairs.sort();
    assert_eq!(pairs.len(), 2);
    assert!(pairs.iter().all(|(a, b)| a == b));
}

// ---- Units and scale (`--units`, `--units-a/-b`, `--scale-a/-b`) ----

fn run_json(args: &[&str]) -> (Option<i32>, Report, String) {
    let out = bin().args(args).output().unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(matches!(out.status.code(), Some(0 | 1)), "{args:?}: {err}");
    (out.status.code(), parse(&out.stdout), err)
}

fn halved(p: [f64; 3]) -> [f64; 3] {
    p.map(|c| c * 0.5)
}

#[test]
fn a_power_of_two_scale_scales_every_length_exactly() {
    // Halving every coordinate (and the translation, which is in the scaled units) is exact in
    // binary floating point, and every operation of the check commutes with it: verdicts and
    // pair sets are identical, and every length is exactly half.
    let (a, b) = (shipped("fcl_env.obj"), shipped("fcl_rob.obj"));
    for (tb, tb_half) in [("0,0,0", "0,0,0"), ("0,0,300", "0,0,150")] {
        let (code, r, _) =
            run_json(&[&a, &b, "-q", "--no-timings", "--clearance", "40", "--translate-b", tb]);
        let (code2, h, _) = run_json(&[
            &a,
            &b,
            "-q",
            "--no-timings",
            "--clearance",
            "20",
            "--translate-b",
            tb_half,
            "--scale-a",
            "0.5",
            "--scale-b",
            "0.5",
        ]);
        assert_eq!(code, code2);
        assert_eq!(h.settings.units, "model");
        let u = h.inputs.a.units.as_ref().expect("scale recorded");
        assert_eq!(
            (u.units.as_deref(), u.source.as_deref(), u.factor, u.scale, u.multiplier),
            (None, None, 1.0, 0.5, 0.5)
        );
        assert_eq!(h.verdict, r.verdict);
        assert_eq!(h.summary.crossing_pairs, r.summary.crossing_pairs);
        assert_eq!(h.summary.clearance_pairs, r.summary.clearance_pairs);
        assert_eq!(h.summary.min_distance, r.summary.min_distance.map(|d| d * 0.5));
        assert_eq!(h.inputs.b.bounds.min, halved(r.inputs.b.bounds.min));
        assert_eq!(h.inputs.a.bounds.max, halved(r.inputs.a.bounds.max));
        let (c, ch) = (r.closest.unwrap(), h.closest.unwrap());
        assert_eq!(ch.a.point, halved(c.a.point));
        assert_eq!(ch.b.point, halved(c.b.point));
        assert_eq!(r.pairs.len(), h.pairs.len());
        assert!(!r.pairs.is_empty());
        for (p, q) in r.pairs.iter().zip(&h.pairs) {
            assert_eq!((p.a, p.b, &p.kind, &p.contact), (q.a, q.b, &q.kind, &q.contact));
            assert_eq!(q.distance, p.distance * 0.5);
            assert_eq!(q.segment, p.segment.map(|[s, t]| [halved(s), halved(t)]));
        }
    }
}

#[test]
fn metres_to_millimetres_on_a_known_pair() {
    // Two unit cubes (metres) 2 m apart along x: 2000 mm apart; integer coordinates times 1000
    // are exact, so the distance is exactly 2000. --translate-b is in report units (mm):
    // moving B by -1000 mm leaves 1000 mm, and moving by -1000 m would have crossed.
    let dir = tempfile::tempdir().unwrap();
    let a = cube_obj(dir.path(), "a.obj", [0.0; 3], [1.0; 3]);
    let b = cube_obj(dir.path(), "b.obj", [3.0, 0.0, 0.0], [4.0, 1.0, 1.0]);
    let (code, plain, _) = run_json(&[&a, &b, "--no-timings"]);
    assert_eq!(code, Some(0));
    assert_eq!(plain.summary.min_distance, Some(2.0));
    assert!(plain.inputs.a.units.is_none() && plain.inputs.b.units.is_none());
    assert_eq!(plain.settings.units, "model");
    let (_, mm, err) =
        run_json(&[&a, &b, "--no-timings", "--units", "mm", "--units-a", "m", "--units-b", "m"]);
    assert_eq!(mm.settings.units, "mm");
    assert_eq!(mm.summary.min_distance, Some(2000.0));
    assert_eq!(mm.inputs.b.bounds.max, [4000.0, 1000.0, 1000.0]);
    let u = mm.inputs.a.units.as_ref().unwrap();
    assert_eq!(
        (u.units.as_deref(), u.source.as_deref(), u.factor, u.scale, u.multiplier),
        (Some("m"), Some("given"), 1000.0, 1.0, 1000.0)
    );
    assert!(mm.warnings.is_empty(), "{:?}", mm.warnings);
    assert!(!err.contains("warning"), "{err}");
    let (_, moved, _) = run_json(&[
        &a,
        &b,
        "-q",
        "--no-timings",
        "--units",
        "mm",
        "--units-a",
        "m",
        "--units-b",
        "m",
        "--translate-b",
        "-1000,0,0",
    ]);
    assert_eq!(moved.summary.min_distance, Some(1000.0));
    // --units defaults to --units-a: the same run without --units.
    let (_, dflt, _) = run_json(&[&a, &b, "-q", "--no-timings", "--units-a", "m", "--units-b", "m"]);
    assert_eq!(dflt.settings.units, "m");
    assert_eq!(dflt.summary.min_distance, Some(2.0));
    // Inches to millimetres: 25.4 exactly per inch; a 2-inch gap is 50.8 mm (the nearest f64).
    let (_, inch, _) =
        run_json(&[&a, &b, "-q", "--no-timings", "--units", "mm", "--units-a", "in", "--units-b", "in"]);
    assert_eq!(inch.inputs.a.units.as_ref().unwrap().factor, 25.4);
    let d = inch.summary.min_distance.unwrap();
    assert!((d - 50.8).abs() <= 4.0 * f64::EPSILON * 101.6, "{d}");
}

#[test]
fn unknown_units_are_assumed_and_gltf_is_metres() {
    let (obj, glb) = (shipped("fcl_rob.obj"), shipped("pins.glb"));
    let (_, plain, _) = run_json(&[&obj, &glb, "-q", "--no-timings", "--fail-on", "never"]);
    let (_, mm, err) = run_json(&[&obj, &glb, "--no-timings", "--fail-on", "never", "--units", "mm"]);
    let (ua, ub) = (mm.inputs.a.units.as_ref().unwrap(), mm.inputs.b.units.as_ref().unwrap());
    assert_eq!(
        (ua.units.as_deref(), ua.source.as_deref(), ua.multiplier),
        (Some("mm"), Some("assumed"), 1.0)
    );
    assert_eq!((ub.units.as_deref(), ub.source.as_deref(), ub.multiplier), (Some("m"), Some("gltf"), 1000.0));
    // The assumption is a warning, in the report and on stderr, naming the file and the flag.
    let w: Vec<&String> = mm.warnings.iter().filter(|w| w.contains("units unknown")).collect();
    assert_eq!(w.len(), 1, "{:?}", mm.warnings);
    assert!(w[0].contains("fcl_rob.obj") && w[0].contains("--units-a") && w[0].contains("mm"), "{}", w[0]);
    assert!(err.contains("units unknown"), "{err}");
    // Unchanged A; B's coordinates each multiplied by 1000 and rounded once, so the bounds
    // (min/max, which rounding preserves) are the plain ones times 1000.
    assert_eq!(mm.inputs.a.bounds, plain.inputs.a.bounds);
    assert_eq!(mm.inputs.b.bounds.min, plain.inputs.b.bounds.min.map(|c| c * 1000.0));
    assert_eq!(mm.inputs.b.bounds.max, plain.inputs.b.bounds.max.map(|c| c * 1000.0));
    // Scene mode: --units-a is the file's.
    let (_, scene, _) = run_json(&["scene", &glb, "-q", "--no-timings", "--units", "mm", "--units-a", "cm"]);
    assert_eq!(scene.settings.units, "mm");
    for u in [&scene.inputs.a.units, &scene.inputs.b.units] {
        let u = u.as_ref().unwrap();
        assert_eq!((u.units.as_deref(), u.source.as_deref(), u.factor), (Some("cm"), Some("given"), 10.0));
    }
    assert_eq!(scene.inputs.a.bounds.min, plain.inputs.b.bounds.min.map(|c| c * 10.0));
}

#[test]
fn bad_units_and_scales_exit_2() {
    let ok = shipped("fcl_rob.obj");
    assert!(error_line(&[&ok, &ok, "--units", "furlong"]).contains("--units"));
    assert!(error_line(&[&ok, &ok, "--units-b", "MM"]).contains("--units-b"));
    for bad in ["0", "-2", "nan", "inf", "-0"] {
        assert!(
            error_line(&[&ok, &ok, "--scale-a", bad]).contains("--scale-a must be a finite number > 0"),
            "{bad}"
        );
    }
    assert!(error_line(&[&ok, &ok, "--scale-b", "1e400"]).contains("--scale-b"));
    let scene = error_line(&["scene", &shipped("pins.glb"), "--units-b", "mm"]);
    assert!(scene.contains("--units-a"), "{scene}");
    // A scale that overflows the coordinates is bad input naming the file.
    let big = error_line(&[&ok, &ok, "--scale-a", "1e300"]);
    assert!(big.contains("fcl_rob.obj") && big.contains("2^250"), "{big}");
}
