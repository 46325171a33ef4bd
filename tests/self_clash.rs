//! `meshclash self` through the real binary: constructions with exact answers, `--fail-on`
//! lists, outputs, errors, determinism, and the known properties of the shared real meshes
//! (../shared/meshes/SOURCES.md).

use assert_cmd::Command;
use meshclash::report::self_report::SelfReport;
use std::path::{Path, PathBuf};

use crate::common::{corpus, shared};

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// Parse with unknown fields denied, after validating against the generated schema.
fn parse(stdout: &[u8]) -> SelfReport {
    let v: serde_json::Value = serde_json::from_slice(stdout).expect("stdout is JSON");
    let schema: serde_json::Value =
        serde_json::from_str(&meshclash::report::self_report::schema_json()).unwrap();
    assert!(jsonschema::is_valid(&schema, &v), "report does not match its schema");
    serde_json::from_value(v).expect("report matches the wire types")
}

/// Run `self` on `file` with `args`, `--no-timings` and `-q`; (report, exit code).
fn run(file: &Path, args: &[&str]) -> (SelfReport, i32) {
    let out = bin().arg("self").arg(file).args(args).args(["--no-timings", "-q"]).output().unwrap();
    assert!(out.stderr.is_empty(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    (parse(&out.stdout), out.status.code().unwrap())
}

fn obj(dir: &Path, name: &str, v: &[[f64; 3]], f: &[[u32; 3]]) -> PathBuf {
    let mut s = String::new();
    for p in v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in f {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let path = dir.join(name);
    std::fs::write(&path, s).unwrap();
    path
}

const CUBE_V: [[f64; 3]; 8] = [
    [0., 0., 0.],
    [1., 0., 0.],
    [0., 1., 0.],
    [1., 1., 0.],
    [0., 0., 1.],
    [1., 0., 1.],
    [0., 1., 1.],
    [1., 1., 1.],
];

/// Outward-wound unit cube.
fn cube_faces() -> Vec<[u32; 3]> {
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect()
}

#[test]
fn a_clean_cube_is_clear_closed_and_positive() {
    let dir = tempfile::tempdir().unwrap();
    let (r, code) = run(&obj(dir.path(), "cube.obj", &CUBE_V, &cube_faces()), &[]);
    assert_eq!(code, 0);
    assert_eq!(r.schema, "meshclash.self/1");
    assert_eq!((r.verdict.name(), r.failed), ("clear", false));
    assert_eq!((r.summary.crossing_pairs, r.summary.touching_pairs, r.summary.open_parts), (0, 0, 0));
    let h = &r.parts[0].health;
    assert!(h.closed);
    assert_eq!(h.volume, Some(1.0));
    assert!(r.pairs.is_empty());
}

#[test]
fn a_folded_strip_fails_with_its_crossing_pairs_listed() {
    let dir = tempfile::tempdir().unwrap();
    let v = [
        [0., 0., 0.],
        [0., 1., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [1., 0., 1.],
        [1., 1., 1.],
        [1., 0., -1.],
        [1., 1., -1.],
    ];
    let f = [[0, 2, 3], [0, 3, 1], [2, 4, 5], [2, 5, 3], [4, 5, 7], [4, 7, 6]];
    let path = obj(dir.path(), "strip.obj", &v, &f);
    let (r, code) = run(&path, &[]);
    assert_eq!(code, 1);
    assert_eq!((r.verdict.name(), r.failed_on.clone()), ("clash", vec!["self-clash".to_string()]));
    assert_eq!((r.summary.crossing_pairs, r.summary.touching_pairs), (2, 2));
    let listed: Vec<(u32, u32, &str, &str)> =
        r.pairs.iter().map(|p| (p.a, p.b, p.kind.name(), p.contact.unwrap().name())).collect();
    assert_eq!(
        listed,
        [
            (0, 4, "touching", "point"),
            (0, 5, "crossing", "segment"),
            (1, 4, "crossing", "segment"),
            (1, 5, "touching", "point")
        ]
    );
    // The crossing segment of (0, 5) is exactly x = 1, z = 0, y from 0 to 1/2.
    let s = r.pairs[1].segment.unwrap();
    let mut ys = [s[0][1], s[1][1]];
    ys.sort_by(f64::total_cmp);
    assert_eq!(ys, [0.0, 0.5]);
    assert!(s.iter().all(|p| p[0] == 1.0 && p[2] == 0.0));
    // --max-pairs caps the list, not the counts; --fail-on never passes.
    let (r, code) = run(&path, &["--max-pairs", "1", "--fail-on", "never"]);
    assert_eq!((code, r.pairs.len(), r.pairs_truncated, r.summary.crossing_pairs), (0, 1, true, 2));
}

#[test]
fn fail_on_lists_select_health_findings() {
    let dir = tempfile::tempdir().unwrap();
    // The cube without its first triangle, plus a zero-area sliver and a duplicated face.
    let mut v = CUBE_V.to_vec();
    v.push([0.5, 0.0, 0.0]);
    let mut f = cube_faces()[1..].to_vec();
    f.push([0, 8, 1]);
    f.push(f[3]);
    let path = obj(dir.path(), "broken.obj", &v, &f);
    let (r, code) = run(&path, &[]);
    assert_eq!((code, r.failed), (0, false), "no self-crossing: the default passes");
    let h = &r.parts[0].health;
    assert!(!h.closed);
    assert_eq!(h.volume, None);
    assert_eq!((h.boundary_edges.count, h.boundary_loops), (3, 1));
    assert_eq!(h.zero_area_triangles.triangles, [11]);
    assert_eq!(h.duplicate_faces.triangles, [12]);
    assert_eq!(h.non_manifold_edges.count, 3);
    for (flag, want) in [
        ("open", vec!["open"]),
        ("degenerate,duplicates", vec!["duplicates", "degenerate"]),
        ("non-manifold,winding", vec!["non-manifold"]),
        ("clash,touching", vec![]),
    ] {
        let (r, code) = run(&path, &["--fail-on", flag]);
        assert_eq!(r.failed_on, want, "{flag}");
        assert_eq!(code, !want.is_empty() as i32, "{flag}");
    }
}

#[test]
fn text_output_and_report_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = obj(dir.path(), "cube.obj", &CUBE_V, &cube_faces());
    let out = bin().arg("self").arg(&path).args(["--format", "text"]).output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains(": clear (1 part, 12 triangles)"), "{text}");
    assert!(text.contains("self-clash: 0 crossing, 0 touching"), "{text}");
    let report = dir.path().join("r.json");
    let out = bin().arg("self").arg(&path).arg("-o").arg(&report).arg("--no-timings").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stdout.is_empty());
    let r = parse(&std::fs::read(&report).unwrap());
    assert!(r.parts[0].health.closed);
    // JUnit: one case per part, failed only for a part with something in --fail-on.
    let junit = dir.path().join("j.xml");
    let engine = shared("joined_tetrahedra.obj");
    let out = bin()
        .arg("self")
        .arg(&engine)
        .arg("--junit")
        .arg(&junit)
        .args(["-q", "--fail-on", "open"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert_eq!(xml.matches("<testcase").count(), 2, "{xml}");
    assert!(!xml.contains("<failure"), "{xml}");
    let out = bin()
        .arg("self")
        .arg(&engine)
        .arg("--junit")
        .arg(&junit)
        .args(["-q", "--whole-file", "--fail-on", "duplicates"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert_eq!((xml.matches("<testcase").count(), xml.matches("<failure").count()), (1, 1), "{xml}");
    assert!(xml.contains("1 duplicate faces, first triangles [7]"), "{xml}");
}

#[test]
fn bad_input_is_one_line_naming_the_file_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.stl");
    std::fs::write(&garbage, b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2\n").unwrap();
    let missing = dir.path().join("missing.obj");
    for path in [&garbage, &missing] {
        let out = bin().arg("self").arg(path).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(&*path.display().to_string()), "{err}");
        assert!(out.stdout.is_empty());
    }
    // A bad --fail-on value, and -o pointing at the input (which is left alone).
    let cube = obj(dir.path(), "cube.obj", &CUBE_V, &cube_faces());
    let before = std::fs::read(&cube).unwrap();
    for args in [vec!["--fail-on", "open,bogus"], vec!["-o", cube.to_str().unwrap()]] {
        let out = bin().arg("self").arg(&cube).args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        // one error under the one prefix (a clap usage error keeps its allowed values below it)
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.starts_with("meshclash: error: ") && err.matches("error:").count() == 1, "{err}");
    }
    assert_eq!(std::fs::read(&cube).unwrap(), before);
}

#[test]
fn one_and_two_threads_give_byte_identical_reports() {
    let Some(file) = corpus("2CylinderEngine.glb") else { return };
    let outs: Vec<Vec<u8>> = ["1", "2"]
        .iter()
        .map(|t| {
            let out = bin()
                .arg("self")
                .arg(&file)
                .args(["--threads", t, "--no-timings", "--fail-on", "never"])
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(0));
            out.stdout
        })
        .collect();
    assert_eq!(outs[0], outs[1]);
    let r = parse(&outs[0]);
    assert!(r.summary.crossing_pairs > 0 && r.summary.touching_pairs > 0);
    // Another tree (strategy, leaf size) gives the same answer.
    let (other, _) = run(&file, &["--bvh", "median", "--leaf-size", "1", "--fail-on", "never"]);
    assert_eq!((&other.pairs, &other.parts, &other.summary), (&r.pairs, &r.parts, &r.summary));
    assert_eq!(other.settings.bvh, "median");
    // Pairs sorted, a < b, both in the same part.
    assert!(r.pairs.windows(2).all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b)));
    assert!(r.pairs.iter().all(|p| p.a < p.b && p.a_object == p.b_object));
}

#[test]
fn shared_meshes_have_their_known_properties() {
    // Bunny: a real scan with holes, 223 boundary edges (SOURCES.md), and no self-clash.
    if let Some(bunny) = corpus("stanford-bunny.obj") {
        let (r, code) = run(&bunny, &[]);
        let h = &r.parts[0].health;
        assert_eq!((code, h.closed, h.boundary_edges.count), (0, false, 223));
        assert_eq!((r.summary.crossing_pairs, r.summary.touching_pairs), (0, 0));
    }
    // fcl_rob.obj: 96 boundary edges and 27 non-manifold edges after merging.
    let (r, _) = run(&shared("fcl_rob.obj"), &["--fail-on", "never"]);
    assert_eq!((r.summary.boundary_edges, r.summary.non_manifold_edges), (96, 27));
    assert!(r.warnings[0].contains("skipped unrecognised line '648 216'"), "{:?}", r.warnings);
    // soup.stl: 100 separate triangles: 300 boundary edges in 100 loops.
    let (r, _) = run(&shared("soup.stl"), &["--fail-on", "never"]);
    assert_eq!((r.summary.boundary_edges, r.summary.boundary_loops), (300, 100));
    // joined_tetrahedra.obj: two closed objects; as one file, the shared base face is a
    // duplicate and its 3 edges are non-manifold.
    let (r, _) = run(&shared("joined_tetrahedra.obj"), &[]);
    assert_eq!((r.summary.parts, r.summary.open_parts, r.summary.duplicate_faces), (2, 0, 0));
    let (r, code) = run(&shared("joined_tetrahedra.obj"), &["--whole-file", "--fail-on", "duplicates"]);
    assert_eq!((r.summary.duplicate_faces, r.summary.non_manifold_edges, code), (1, 3, 1));
    assert_eq!(r.parts[0].object, None);
    // shared.STL: two cubes along one edge: one non-manifold edge, and the cubes' contact is
    // connectivity, not a self-clash.
    let (r, _) = run(&shared("shared.STL"), &[]);
    assert_eq!((r.summary.non_manifold_edges, r.summary.crossing_pairs, r.summary.touching_pairs), (1, 0, 0));
    // featuretype.STL is watertight only under a tolerant merge: exactly, its seams have
    // vertices 2.7e-16 apart (576 boundary edges), touching each other but never crossing.
    let (r, code) = run(&shared("featuretype.STL"), &[]);
    assert_eq!((code, r.summary.boundary_edges, r.summary.crossing_pairs), (0, 576, 0));
    assert!(r.summary.touching_pairs > 0);
}

#[test]
fn counter_crossings_are_between_its_bodies() {
    // counter.unitsmm.STL: 6 watertight bodies in one solid. Checked as one part, its
    // self-crossings are exactly the crossings the two-mesh check finds between the bodies.
    let file = shared("counter.unitsmm.STL");
    let (whole, code) = run(&file, &[]);
    assert_eq!(code, 1);
    let (bodies, code) = run(&file, &["--split-bodies"]);
    assert_eq!(
        (code, bodies.summary.parts, bodies.summary.crossing_pairs, bodies.summary.open_parts),
        (0, 6, 0, 0)
    );
    let out = bin().arg("scene").arg(&file).args(["--split-bodies", "--no-timings", "-q"]).output().unwrap();
    let scene: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(scene["summary"]["crossing_pairs"], whole.summary.crossing_pairs);
    assert!(whole.summary.crossing_pairs > 0);
}

#[test]
fn engine_zero_area_triangles_match_the_check_and_selection_works() {
    // 2CylinderEngine has zero-area triangles (SOURCES.md: 10 419 of the stored ones); every
    // zero-area triangle of the scene is counted in exactly one part.
    let Some(file) = corpus("2CylinderEngine.glb") else { return };
    let (r, _) = run(&file, &["--fail-on", "never"]);
    let out =
        bin().arg("scene").arg(&file).args(["--no-timings", "-q", "--fail-on", "never"]).output().unwrap();
    let scene: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(scene["inputs"]["a"]["degenerate_triangles"], r.summary.zero_area_triangles);
    assert!(r.summary.zero_area_triangles > 10_000);
    // SOURCES.md: no geometry is watertight... under instancing; closed parts have a volume.
    assert!(r.summary.open_parts > 0);
    assert!(r.parts.iter().all(|p| p.health.closed == p.health.volume.is_some()));
    // --select keeps matching parts only, --exclude drops them.
    let name = r.parts[0].name.clone();
    let (one, _) = run(&file, &["--select", &name, "--fail-on", "never"]);
    assert_eq!((one.summary.parts, one.parts[0].name.as_str()), (1, name.as_str()));
    let (rest, _) = run(&file, &["--exclude", &name, "--fail-on", "never"]);
    assert_eq!(rest.summary.parts, r.summary.parts - 1);
}
