//! The CI-facing outputs through the real binary: JSON Schema (generated, checked in, validated
//! against real reports), JUnit XML, baseline diff with stable ids and `--fail-on new`, the GLB
//! scene, text summary, completions and man page, and a quiet stderr when it is not a terminal.

use crate::common::boxes_obj;
use assert_cmd::Command;
use meshclash::report::Report;
use std::collections::BTreeSet;
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

fn report(stdout: &[u8]) -> Report {
    serde_json::from_slice(stdout).expect("stdout is a report")
}

const SLAB: (&str, [f64; 3], [f64; 3]) = ("slab", [0.0, 0.0, 0.0], [10.0, 10.0, 1.0]);

// ---------------------------------------------------------------- JSON Schema

#[test]
fn schema_subcommand_matches_the_checked_in_copy() {
    let out = bin().arg("schema").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let generated = String::from_utf8(out.stdout).unwrap();
    let copy = root().join("tests/data/report.schema.json");
    if std::env::var_os("MESHCLASH_UPDATE_SCHEMA").is_some() {
        std::fs::write(&copy, &generated).unwrap();
    }
    let checked_in = std::fs::read_to_string(&copy).unwrap_or_default();
    assert!(
        generated == checked_in,
        "tests/data/report.schema.json is out of date: run `cargo run -- schema > tests/data/report.schema.json` \
         (or this test with MESHCLASH_UPDATE_SCHEMA=1)"
    );
    let v: serde_json::Value = serde_json::from_str(&generated).unwrap();
    assert_eq!(v["title"], "Report");
    assert_eq!(v["additionalProperties"], false, "unknown fields are not allowed");
}

#[test]
fn real_reports_validate_against_the_schema() {
    let schema: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("tests/data/report.schema.json")).unwrap())
            .unwrap();
    let validator = jsonschema::validator_for(&schema).expect("the schema is a valid JSON Schema");
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("base.json");
    let (env, rob) = (shipped("fcl_env.obj"), shipped("fcl_rob.obj"));
    let runs: Vec<Vec<String>> = vec![
        vec![env.clone(), rob.clone()],
        vec![env.clone(), rob.clone(), "--no-timings".into(), "-o".into(), base.display().to_string()],
        vec![env.clone(), rob.clone(), "--baseline".into(), base.display().to_string()],
        vec![
            env.clone(),
            rob.clone(),
            "--translate-b".into(),
            "0,0,300".into(),
            "--clearance".into(),
            "500".into(),
        ],
        vec![
            env.clone(),
            rob.clone(),
            "--cross-check".into(),
            "parry".into(),
            "--max-pairs".into(),
            "3".into(),
        ],
        vec![shipped("SimpleMeshes.gltf"), shipped("pins.glb"), "--touch-tolerance".into(), "1e-3rel".into()],
    ];
    let mut saw_baseline = false;
    for args in runs {
        let out = bin().args(&args).arg("-q").output().unwrap();
        assert!(
            matches!(out.status.code(), Some(0 | 1)),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = if out.stdout.is_empty() { std::fs::read(&base).unwrap() } else { out.stdout };
        let v: serde_json::Value = serde_json::from_slice(&stdout).unwrap();
        let errors: Vec<String> = validator.iter_errors(&v).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{args:?}: {errors:?}");
        saw_baseline |= v.get("baseline").is_some();
    }
    assert!(saw_baseline, "a report with a baseline block was validated");

    // The validation can fail: a wrong type, an unknown field, a missing field.
    let out = bin().args([&env, &rob, "-q"]).output().unwrap();
    let good: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut bad = good.clone();
    bad["verdict"] = serde_json::json!(3);
    assert!(!validator.is_valid(&bad));
    let mut bad = good.clone();
    bad["pairs"][0]["colour"] = serde_json::json!("red");
    assert!(!validator.is_valid(&bad));
    let mut bad = good;
    bad.as_object_mut().unwrap().remove("summary");
    assert!(!validator.is_valid(&bad));
}

// ---------------------------------------------------------------- JUnit

fn attr<'a>(n: roxmltree::Node<'a, '_>, name: &str) -> &'a str {
    n.attribute(name).unwrap_or_else(|| panic!("<{}> has no {name}", n.tag_name().name()))
}

#[test]
fn junit_file_has_one_failing_case_with_counts_and_first_findings() {
    let dir = tempfile::tempdir().unwrap();
    let xml_path = dir.path().join("junit.xml");
    let (env, rob) = (shipped("fcl_env.obj"), shipped("fcl_rob.obj"));
    let out = bin().args([&env, &rob, "-q", "--no-timings", "--junit"]).arg(&xml_path).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = report(&out.stdout); // the JSON still goes to stdout
    let xml = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
    let top = doc.root_element();
    assert_eq!(top.tag_name().name(), "testsuites");
    let suites: Vec<_> = top.children().filter(|n| n.has_tag_name("testsuite")).collect();
    assert_eq!(suites.len(), 1);
    assert_eq!((attr(suites[0], "tests"), attr(suites[0], "failures")), ("1", "1"));
    let cases: Vec<_> = suites[0].children().filter(|n| n.has_tag_name("testcase")).collect();
    assert_eq!(cases.len(), 1);
    assert_eq!(attr(cases[0], "name"), format!("{env} vs {rob}"));
    let failure = cases[0].children().find(|n| n.has_tag_name("failure")).expect("a failure");
    assert_eq!(attr(failure, "type"), "clash");
    let msg = attr(failure, "message");
    assert!(msg.starts_with("clash: 192 crossing, 0 touching, 0 clearance pairs"), "{msg}");
    let body = failure.text().unwrap();
    let lines: Vec<&str> = body.lines().collect();
    assert_eq!(lines.len(), 11, "{body}");
    assert_eq!(lines[10], format!("... and {} more", 192 - 10));
    let first = &r.pairs[0];
    assert!(lines[0].starts_with(&format!("crossing A#{} (object0) x B#{} (object0)", first.a, first.b)));

    // --format junit puts the same XML on stdout.
    let out = bin().args([&env, &rob, "-q", "--no-timings", "--format", "junit"]).output().unwrap();
    assert_eq!(String::from_utf8(out.stdout).unwrap(), xml);

    // A passing run: no failure element.
    let out = bin().args([&env, &rob, "-q", "--fail-on", "never", "--format", "junit"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let xml = String::from_utf8(out.stdout).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    assert_eq!(attr(doc.root_element(), "failures"), "0");
    assert!(doc.descendants().all(|n| !n.has_tag_name("failure")));
}

#[test]
fn junit_escapes_names() {
    let dir = tempfile::tempdir().unwrap();
    let nasty = "p<1>&\"q'";
    let a = boxes_obj(dir.path(), "a&b.obj", &[(nasty, [0.0; 3], [2.0; 3])]);
    let b = boxes_obj(dir.path(), "b.obj", &[("pin", [1.0; 3], [3.0; 3])]);
    let out = bin().args([&a, &b, "-q", "--format", "junit"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let xml = String::from_utf8(out.stdout).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("escaped properly");
    let case = doc.descendants().find(|n| n.has_tag_name("testcase")).unwrap();
    assert!(attr(case, "name").contains("a&b.obj"));
    let failure = case.children().find(|n| n.has_tag_name("failure")).unwrap();
    assert!(failure.text().unwrap().contains(&format!("({nasty})")));
}

// ---------------------------------------------------------------- baseline

fn pairs_of<'a>(r: &'a Report, b_object: &str) -> Vec<&'a meshclash::report::PairReport> {
    let i = r.inputs.b.objects.iter().position(|o| o.name == b_object).unwrap() as u32;
    r.pairs.iter().filter(|p| p.b_object == i).collect()
}

fn ids(pairs: &[&meshclash::report::PairReport]) -> BTreeSet<String> {
    pairs.iter().map(|p| p.id.clone().expect("every pair has an id")).collect()
}

#[test]
fn baseline_marks_new_persistent_and_resolved_by_stable_ids() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = boxes_obj(d, "fixture.obj", &[SLAB]);
    let through = |lo: f64| ([lo, lo, -1.0], [lo + 1.0, lo + 1.0, 2.0]);
    let above = |lo: f64| ([lo, lo, 3.0], [lo + 1.0, lo + 1.0, 5.0]);
    // Before: pin1 and pin2 go through the slab, pin3 is above it.
    let (p1, p2, p3) = (through(1.0), through(5.0), above(8.0));
    let before =
        boxes_obj(d, "before.obj", &[("pin1", p1.0, p1.1), ("pin2", p2.0, p2.1), ("pin3", p3.0, p3.1)]);
    // After: pin2 lifted clear, pin3 pushed through, pin1 unchanged but written last (so its
    // triangle indices change).
    let (q2, q3) = (above(5.0), through(8.0));
    let after =
        boxes_obj(d, "after.obj", &[("pin3", q3.0, q3.1), ("pin2", q2.0, q2.1), ("pin1", p1.0, p1.1)]);

    let base_path = d.join("before.json");
    let out = bin().args([&a, &before, "-q", "-o"]).arg(&base_path).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let old: Report = serde_json::from_slice(&std::fs::read(&base_path).unwrap()).unwrap();
    assert!(old.baseline.is_none() && old.pairs.iter().all(|p| p.status.is_none()));

    let out = bin().args([&a, &after, "-q", "--baseline"]).arg(&base_path).output().unwrap();
    assert_eq!(out.status.code(), Some(1), "default --fail-on clash still fails");
    let new = report(&out.stdout);

    let (old1, old2, old3) = (pairs_of(&old, "pin1"), pairs_of(&old, "pin2"), pairs_of(&old, "pin3"));
    let (new1, new2, new3) = (pairs_of(&new, "pin1"), pairs_of(&new, "pin2"), pairs_of(&new, "pin3"));
    assert!(!old1.is_empty() && !old2.is_empty() && old3.is_empty());
    assert!(!new1.is_empty() && new2.is_empty() && !new3.is_empty());
    let crossing =
        |v: &[&meshclash::report::PairReport]| v.iter().filter(|p| p.kind == "crossing").count() as u64;
    assert!(crossing(&new3) > 0 && crossing(&old1) > 0);
    // pin1's findings: other triangle indices, same ids.
    assert_ne!(old1.iter().map(|p| p.b).collect::<Vec<_>>(), new1.iter().map(|p| p.b).collect::<Vec<_>>());
    assert_eq!(ids(&old1), ids(&new1));
    assert!(new1.iter().all(|p| p.status.as_deref() == Some("persistent")));
    assert!(new3.iter().all(|p| p.status.as_deref() == Some("new")));

    let b = new.baseline.as_ref().expect("a baseline block");
    assert_eq!(b.path, base_path.display().to_string());
    assert_eq!(b.new, new3.len() as u64);
    assert_eq!(b.new_crossing, crossing(&new3));
    assert_eq!(b.persistent, new1.len() as u64);
    assert_eq!(b.resolved, old2.len() as u64);
    assert_eq!(b.resolved_ids, ids(&old2).into_iter().collect::<Vec<_>>());
    assert!(!b.new_containment && b.complete);
    assert!(ids(&new3).is_disjoint(&ids(&old1).union(&ids(&old2)).cloned().collect()));

    // --fail-on new: fails on the new crossing; a run against itself passes although it clashes.
    let out =
        bin().args([&a, &after, "-q", "--fail-on", "new", "--baseline"]).arg(&base_path).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = report(&out.stdout);
    assert!(r.failed);
    assert_eq!(r.settings.fail_on, "new");
    let same = d.join("after.json");
    bin().args([&a, &after, "-q", "-o"]).arg(&same).output().unwrap();
    let out = bin().args([&a, &after, "-q", "--fail-on", "new", "--baseline"]).arg(&same).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let r = report(&out.stdout);
    assert_eq!(r.verdict, "clash");
    assert!(!r.failed);
    let b = r.baseline.unwrap();
    assert_eq!((b.new, b.resolved, b.persistent), (0, 0, r.pairs.len() as u64));
}

#[test]
fn fail_on_new_counts_new_containment_and_needs_a_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = boxes_obj(d, "case.obj", &[("case", [0.0; 3], [10.0; 3])]);
    let outside = boxes_obj(d, "out.obj", &[("part", [20.0; 3], [21.0; 3])]);
    let inside = boxes_obj(d, "in.obj", &[("part", [4.0; 3], [5.0; 3])]);
    let base = d.join("base.json");
    let out = bin().args([&a, &outside, "-q", "-o"]).arg(&base).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let out = bin().args([&a, &inside, "-q", "--fail-on", "new", "--baseline"]).arg(&base).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r = report(&out.stdout);
    assert_eq!(r.summary.contained.map(|c| c.name()), Some("b_in_a"));
    let b = r.baseline.unwrap();
    assert!(b.new_containment);
    assert_eq!(b.new_crossing, 0);

    let out = bin().args([&a, &inside, "--fail-on", "new"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--baseline"));
    // A baseline from an older version (no ids) is bad input.
    let mut old: serde_json::Value = serde_json::from_slice(
        &bin().args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q"]).output().unwrap().stdout,
    )
    .unwrap();
    for p in old["pairs"].as_array_mut().unwrap() {
        p.as_object_mut().unwrap().remove("id");
    }
    std::fs::write(&base, old.to_string()).unwrap();
    let out = bin().args([&a, &inside, "--baseline"]).arg(&base).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("no id"), "{err}");
}

// GLB: tests/glb.rs.

// ---------------------------------------------------------------- text, stderr, completions

#[test]
fn format_text_prints_the_summary_and_o_still_writes_json() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q", "--format", "text", "-o"])
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("meshclash: CLASH  FAILED (--fail-on clash)\n"), "{text}");
    assert!(text.contains("192 crossing, 0 touching (0 within tolerance), 0 clearance pairs"));
    assert!(text.contains("closest: 0 between A#"));
    assert!(text.contains("worst findings (5 of 192):"));
    assert!(!text.contains('\x1b'), "no colour when stdout is not a terminal");
    let r: Report = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(r.summary.crossing_pairs, 192);
}

#[test]
fn stderr_that_is_not_a_terminal_gets_no_summary_and_no_progress() {
    // No warnings for these inputs: stderr must be empty (assert_cmd's stderr is a pipe).
    let out = bin().args([&shipped("joined_tetrahedra.obj"), &shipped("multibody.stl")]).output().unwrap();
    assert!(matches!(out.status.code(), Some(0 | 1)));
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
    // With warnings: exactly the warning lines.
    let out = bin().args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj")]).output().unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 2, "{err}");
    assert!(err.lines().all(|l| l.starts_with("meshclash: warning: ")), "{err}");
}

/// Run under a pseudo-terminal with util-linux `script`, if there is one.
fn on_a_terminal(args: &[String], env: &[(&str, &str)]) -> Option<String> {
    let exe = assert_cmd::cargo::cargo_bin("meshclash");
    let cmd = std::iter::once(exe.display().to_string())
        .chain(args.iter().cloned())
        .map(|a| format!("'{}'", a.replace('\'', "'\\''")))
        .collect::<Vec<_>>()
        .join(" ");
    let mut c = std::process::Command::new("script");
    c.args(["-qec", &cmd, "/dev/null"]).env_remove("NO_COLOR").stdin(std::process::Stdio::null());
    for (k, v) in env {
        c.env(k, v);
    }
    let out = c.output().ok()?;
    let s = String::from_utf8_lossy(&out.stdout).into_owned();
    (out.status.code() == Some(1) && s.contains("meshclash")).then_some(s)
}

#[test]
fn a_terminal_gets_the_summary_in_colour_unless_no_color() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json").display().to_string();
    let args = vec![shipped("fcl_env.obj"), shipped("fcl_rob.obj"), "-o".to_string(), json];
    let Some(tty) = on_a_terminal(&args, &[]) else {
        crate::common::say("skipped a_terminal_gets_the_summary_in_colour_unless_no_color: no usable `script` (util-linux) for a pseudo-terminal");
        return;
    };
    assert!(tty.contains("192"), "{tty}");
    assert!(tty.contains("\x1b[1;31mCLASH\x1b[0m"), "{tty:?}");
    let plain = on_a_terminal(&args, &[("NO_COLOR", "1")]).unwrap();
    let line = plain.lines().find(|l| l.contains("CLASH")).expect("summary");
    assert!(line.contains("meshclash: CLASH  FAILED"), "{line:?}");
    assert!(!line.contains("\x1b[1;31m"), "{line:?}");
    let mut quiet = args.clone();
    quiet.push("-q".into());
    assert!(!on_a_terminal(&quiet, &[]).unwrap_or_default().contains("CLASH"));
}

#[test]
fn completions_and_man_page_mention_the_flags() {
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        let out = bin().args(["completions", shell]).output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{shell}");
        let s = String::from_utf8(out.stdout).unwrap();
        let flag = if shell == "fish" { "-l clearance" } else { "--clearance" };
        assert!(s.contains(flag), "{shell}: {s}");
        assert!(s.contains("export-glb"), "{shell}");
    }
    let out = bin().arg("man").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let man = String::from_utf8(out.stdout).unwrap();
    assert!(man.starts_with(".ie") || man.contains(".TH meshclash"), "{man}");
    assert!(man.contains("\\-\\-clearance"));
    assert!(bin().args(["completions", "tcsh"]).output().unwrap().status.code() == Some(2));
}

#[test]
fn subcommand_names_are_files_once_a_mesh_is_given() {
    // `meshclash A schema` checks A against a file called `schema`.
    let out = bin().args([&shipped("fcl_env.obj"), "schema", "-q"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("meshclash: error: schema: "));
}

/// Two crossing triangles in a glTF whose two nodes (and meshes) are named `na` and `nb`.
fn named_gltf(na: &str, nb: &str) -> String {
    use base64::Engine;
    let positions: [f32; 18] =
        [0., 0., 0., 2., 0., 0., 0., 2., 0., 0.5, 0.5, -1., 0.5, 0.5, 1., 1.5, 0.5, 1.];
    let bytes: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
    serde_json::json!({
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
    })
    .to_string()
}

#[test]
fn every_output_is_written_and_well_formed_for_names_with_every_control_character() {
    use std::io::Read;
    let dir = tempfile::tempdir().unwrap();
    let controls: String =
        (0u32..32).chain([0x7f, 0x85, 0x2028, 0xfffe]).filter_map(char::from_u32).collect();
    let cases = [("a\0b", "c"), ("\0", "\u{1}\u{1f}"), (controls.as_str(), "<&>\"'\u{7f}]]>")];
    for (k, (na, nb)) in cases.into_iter().enumerate() {
        let input = dir.path().join(format!("names{k}.gltf"));
        std::fs::write(&input, named_gltf(na, nb)).unwrap();
        let out = |ext: &str| dir.path().join(format!("w{k}.{ext}"));
        for version in ["2.1", "3.0"] {
            let run = bin()
                .arg("scene")
                .arg(&input)
                .args(["--no-timings", "--threads", "1", "--bcf-version", version, "-o"])
                .arg(out("json"))
                .arg("--junit")
                .arg(out("xml"))
                .arg("--bcf")
                .arg(out("bcfzip"))
                .arg("--html")
                .arg(out("html"))
                .arg("--export-glb")
                .arg(out("glb"))
                .output()
                .unwrap();
            assert_eq!(run.status.code(), Some(1), "{na:?}: {}", String::from_utf8_lossy(&run.stderr));
            let json: serde_json::Value =
                serde_json::from_slice(&std::fs::read(out("json")).unwrap()).unwrap();
            let names: Vec<&str> =
                json["parts"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
            assert_eq!(names, [na, nb], "names round-trip through the JSON report");
            let junit = std::fs::read_to_string(out("xml")).unwrap();
            roxmltree::Document::parse(&junit).unwrap_or_else(|e| panic!("{na:?}: JUnit: {e}"));
            let mut z = zip::ZipArchive::new(std::fs::File::open(out("bcfzip")).unwrap()).unwrap();
            assert!(z.len() > 1, "a BCF with its topic");
            for i in 0..z.len() {
                let mut f = z.by_index(i).unwrap();
                let mut s = String::new();
                f.read_to_string(&mut s).unwrap();
                roxmltree::Document::parse(&s).unwrap_or_else(|e| panic!("{na:?}: BCF member {i}: {e}"));
            }
            let html = std::fs::read_to_string(out("html")).unwrap();
            assert!(!html.contains('\0'), "no raw NUL in the HTML");
            assert_eq!(&std::fs::read(out("glb")).unwrap()[..4], b"glTF");
            for ext in ["json", "xml", "bcfzip", "html", "glb"] {
                std::fs::remove_file(out(ext)).unwrap();
            }
        }
    }
}
