//! `meshclash clash-set FILE`: several named checks in one run, through the real binary.

use assert_cmd::Command;
use meshclash::report::clash_set::ClashSetReport;
use meshclash::report::{self, Report};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// A temporary tree: `meshes/` with copies of the shipped meshes, and `sets/` for the clash-set
/// files, which refer to the meshes as `../meshes/...` (relative to the set file).
fn tree() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("meshes")).unwrap();
    std::fs::create_dir(dir.path().join("sets")).unwrap();
    for m in ["fcl_env.obj", "fcl_rob.obj", "pins.glb", "multibody.stl"] {
        std::fs::copy(root().join("meshes").join(m), dir.path().join("meshes").join(m)).unwrap();
    }
    dir
}

const THREE: &str = r#"{
  "version": 1,
  "checks": [
    {"name": "env vs rob", "a": "../meshes/fcl_env.obj", "b": "../meshes/fcl_rob.obj", "max_pairs": 20},
    {"name": "dowels", "scene": "../meshes/pins.glb", "exclude": ["*sides*"], "clearance": "0.01"},
    {"name": "multibody apart", "a": "../meshes/multibody.stl", "b": "../meshes/multibody.stl",
     "translate_b": [0, 0, 1000], "clearance": 2000, "fail_on": "never"}
  ]
}"#;

/// The command lines the three checks stand for (paths as the set resolves them: the set file's
/// directory joined with the relative path).
fn equivalents(set_dir: &str) -> Vec<Vec<String>> {
    let m = |f: &str| format!("{set_dir}/../meshes/{f}");
    vec![
        vec![m("fcl_env.obj"), m("fcl_rob.obj"), "--max-pairs".into(), "20".into()],
        vec![
            "scene".into(),
            m("pins.glb"),
            "--exclude".into(),
            "*sides*".into(),
            "--clearance".into(),
            "0.01".into(),
        ],
        vec![
            m("multibody.stl"),
            m("multibody.stl"),
            "--translate-b".into(),
            "0,0,1000".into(),
            "--clearance".into(),
            "2000".into(),
            "--fail-on".into(),
            "never".into(),
        ],
    ]
}

fn write_set(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join("sets").join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn parse_doc(bytes: &[u8]) -> ClashSetReport {
    serde_json::from_slice(bytes).expect("a clash-set document with every field known")
}

#[test]
fn each_check_reports_exactly_what_its_command_line_reports() {
    let dir = tree();
    write_set(dir.path(), "three.json", THREE);
    // Run from the tree's root with a relative set path: the checks' paths are relative to the
    // set file, not to the working directory.
    let out = bin()
        .current_dir(dir.path())
        .args(["clash-set", "sets/three.json", "--no-timings", "--threads", "2", "-q"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty());
    let doc = parse_doc(&out.stdout);
    assert_eq!(doc.schema, "meshclash.clash-set/1");
    assert_eq!(doc.file, "sets/three.json");
    assert!(doc.failed);
    let names: Vec<&str> = doc.checks.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["env vs rob", "dowels", "multibody apart"]);
    for (check, line) in doc.checks.iter().zip(equivalents("sets")) {
        let single = bin().current_dir(dir.path()).args(&line).arg("--no-timings").output().unwrap();
        assert!(matches!(single.status.code(), Some(0 | 1)), "{line:?}");
        // Byte for byte: the check's report, printed the way the single command prints it.
        let from_set = report::to_json(&check.report);
        assert_eq!(from_set, String::from_utf8(single.stdout).unwrap(), "check {}", check.name);
    }
    // And the verdicts are the expected ones, reasoned independently: FCL's environment and
    // robot clash; the six dowels of pins.glb stand apart; multibody's two blocks are 0.507
    // apart, so copies 1000 up are far beyond contact but within a 2000 clearance.
    let [env, dowels, multi] = [&doc.checks[0].report, &doc.checks[1].report, &doc.checks[2].report];
    assert_eq!((env.verdict.name(), env.failed, env.pairs.len()), ("clash", true, 20));
    assert!(env.pairs_truncated);
    assert_eq!((dowels.verdict.name(), dowels.failed), ("clear", false));
    assert_eq!(dowels.assembly.mode, "parts");
    assert_eq!((multi.verdict.name(), multi.failed), ("clearance", false));
}

#[test]
fn exit_codes_outputs_and_formats() {
    let dir = tree();
    let set = write_set(dir.path(), "three.json", THREE);
    // Without the failing check: exit 0.
    let passing = THREE.replace(r#""max_pairs": 20}"#, r#""max_pairs": 20, "fail_on": "never"}"#);
    let pass = write_set(dir.path(), "pass.json", &passing);
    let out = bin().args(["clash-set", pass.to_str().unwrap(), "-q"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(!parse_doc(&out.stdout).failed);
    // -o and --junit: written atomically, nothing on stdout; exit 1 for the failing set.
    let (report_path, junit_path) = (dir.path().join("out.json"), dir.path().join("junit.xml"));
    let out = bin()
        .args(["clash-set", set.to_str().unwrap(), "-q", "--no-timings", "-o"])
        .arg(&report_path)
        .arg("--junit")
        .arg(&junit_path)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let doc = parse_doc(&std::fs::read(&report_path).unwrap());
    assert_eq!(doc.checks.len(), 3);
    let xml = std::fs::read_to_string(&junit_path).unwrap();
    let tree = roxmltree::Document::parse(&xml).unwrap();
    let suites: Vec<&str> = tree
        .descendants()
        .filter(|n| n.has_tag_name("testsuite"))
        .map(|n| n.attribute("name").unwrap())
        .collect();
    assert_eq!(suites, ["env vs rob", "dowels", "multibody apart"]);
    let root_el = tree.root_element();
    assert_eq!(root_el.tag_name().name(), "testsuites");
    let failures: usize = root_el.attribute("failures").unwrap().parse().unwrap();
    assert_eq!(failures, xml.matches("<failure").count());
    assert!(failures >= 1);
    // --format text: one line per check, then the total.
    let out = bin().args(["clash-set", set.to_str().unwrap(), "-q", "--format", "text"]).output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    assert!(lines[0].starts_with("env vs rob: CLASH FAILED (--fail-on clash)"), "{text}");
    assert!(lines[1].starts_with("dowels: CLEAR passed"), "{text}");
    assert!(lines[2].starts_with("multibody apart: CLEARANCE passed (--fail-on never)"), "{text}");
    assert!(lines[3].ends_with("3 checks, 1 failed"), "{text}");
    // --format junit on stdout is the same document as --junit FILE (deterministic run).
    let out = bin()
        .args(["clash-set", set.to_str().unwrap(), "-q", "--no-timings", "--format", "junit"])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8(out.stdout).unwrap(), xml);
}

#[test]
fn bad_input_in_any_check_exits_2_and_writes_nothing() {
    let dir = tree();
    let report_path = dir.path().join("out.json");
    let junit_path = dir.path().join("junit.xml");
    let cases = [
        // The last check's file is missing: the first two ran, yet nothing is written.
        (
            THREE.replace("../meshes/multibody.stl\", \"b", "../meshes/nope.stl\", \"b"),
            "check 'multibody apart'",
            "nope.stl",
        ),
        (THREE.replace("\"dowels\"", "\"env vs rob\""), "check 'env vs rob'", "twice"),
        (
            THREE.replace("\"max_pairs\": 20", "\"max_pair\": 20"),
            "check 'env vs rob'",
            "unknown field `max_pair`",
        ),
        (THREE.replace("\"clearance\": \"0.01\"", "\"clearance\": \"-1\""), "check 'dowels'", "--clearance"),
        (
            THREE.replace("\"fail_on\": \"never\"", "\"fail_on\": \"new\""),
            "check 'multibody apart'",
            "--baseline",
        ),
        (THREE.replace("\"version\": 1", "\"version\": 1, \"units\": \"parsec\""), "bad.json", "parsec"),
        ("{\"version\": 1, \"checks\": [".to_string(), "bad.json", "EOF"),
    ];
    for (text, who, what) in cases {
        let set = write_set(dir.path(), "bad.json", &text);
        let out = bin()
            .args(["clash-set", set.to_str().unwrap(), "-o"])
            .arg(&report_path)
            .arg("--junit")
            .arg(&junit_path)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{who} {what}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("bad.json") && err.contains(who) && err.contains(what), "{err}");
        assert!(out.stdout.is_empty());
        assert!(!report_path.exists() && !junit_path.exists(), "{err}");
    }
    // The set file itself missing.
    let out = bin().args(["clash-set", "no/such/set.json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8(out.stderr).unwrap().contains("no/such/set.json"));
    // Flags of the run do not belong in the file.
    let set = write_set(dir.path(), "bad.json", &THREE.replace("\"max_pairs\": 20", "\"threads\": 2"));
    let out = bin().args(["clash-set", set.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn units_and_defaults_apply_to_every_check() {
    let dir = tree();
    let set = write_set(
        dir.path(),
        "units.json",
        r#"{"version": 1, "units": "mm", "defaults": {"fail_on": "never", "units_a": "m"},
            "checks": [
              {"name": "pins", "scene": "../meshes/pins.glb"},
              {"name": "robot", "a": "../meshes/fcl_rob.obj", "b": "../meshes/pins.glb", "units_a": "in"}
            ]}"#,
    );
    let out = bin().args(["clash-set", set.to_str().unwrap(), "--no-timings"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = parse_doc(&out.stdout);
    let (pins, robot): (&Report, &Report) = (&doc.checks[0].report, &doc.checks[1].report);
    assert!(doc
        .checks
        .iter()
        .all(|c| c.report.settings.units == "mm" && c.report.settings.fail_on == "never"));
    let u = pins.inputs.a.units.as_ref().unwrap();
    assert_eq!((u.units.as_deref(), u.source.as_deref(), u.factor), (Some("m"), Some("given"), 1000.0));
    let (ua, ub) = (robot.inputs.a.units.as_ref().unwrap(), robot.inputs.b.units.as_ref().unwrap());
    assert_eq!((ua.units.as_deref(), ua.factor), (Some("in"), 25.4));
    assert_eq!((ub.units.as_deref(), ub.source.as_deref(), ub.factor), (Some("m"), Some("gltf"), 1000.0));
    // The same as the command line.
    let m = |f: &str| dir.path().join("sets/../meshes").join(f).display().to_string();
    let single = bin()
        .args([&m("fcl_rob.obj"), &m("pins.glb"), "--units", "mm", "--units-a", "in", "--fail-on", "never"])
        .arg("--no-timings")
        .output()
        .unwrap();
    assert_eq!(report::to_json(robot), String::from_utf8(single.stdout).unwrap());
}

#[test]
fn schemas_describe_the_file_and_the_output() {
    let dir = tree();
    let set = write_set(dir.path(), "three.json", THREE);
    for (kind, instance) in [
        ("file", std::fs::read_to_string(&set).unwrap()),
        (
            "output",
            String::from_utf8(
                bin().args(["clash-set", set.to_str().unwrap(), "-q"]).output().unwrap().stdout,
            )
            .unwrap(),
        ),
    ] {
        let out = bin().args(["clash-set", "--schema", kind]).output().unwrap();
        assert_eq!(out.status.code(), Some(0));
        let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let validator = jsonschema::validator_for(&schema).expect("a valid JSON Schema");
        let v: serde_json::Value = serde_json::from_str(&instance).unwrap();
        let errors: Vec<String> = validator.iter_errors(&v).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{kind}: {errors:?}");
        assert_eq!(schema["additionalProperties"], false);
    }
    // The file schema rejects what the parser rejects.
    let out = bin().args(["clash-set", "--schema", "file"]).output().unwrap();
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let bad: serde_json::Value =
        serde_json::from_str(r#"{"version": 1, "checks": [{"name": "x", "a": "a", "b": "b", "colour": 1}]}"#)
            .unwrap();
    assert!(!validator.is_valid(&bad));
}

#[test]
fn a_baseline_is_found_relative_to_the_set_file() {
    // The accepted state: FCL's pair clashes. With its own report as the baseline and
    // --fail-on new, nothing is new, so the set passes; without the baseline it fails.
    let dir = tree();
    let base = bin()
        .args([dir.path().join("meshes/fcl_env.obj"), dir.path().join("meshes/fcl_rob.obj")])
        .args(["-q", "--no-timings", "-o"])
        .arg(dir.path().join("sets/base.json"))
        .output()
        .unwrap();
    assert_eq!(base.status.code(), Some(1));
    let set = write_set(
        dir.path(),
        "gate.json",
        r#"{"version": 1, "checks": [{"name": "gate", "a": "../meshes/fcl_env.obj", "b": "../meshes/fcl_rob.obj",
            "baseline": "base.json", "fail_on": "new"}]}"#,
    );
    let out = bin().args(["clash-set", set.to_str().unwrap(), "-q"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = parse_doc(&out.stdout);
    let b = doc.checks[0].report.baseline.as_ref().expect("baseline block");
    assert_eq!((b.new, b.resolved), (0, 0));
    assert!(b.persistent > 0);
    assert_eq!(doc.checks[0].report.settings.fail_on, "new");
}
