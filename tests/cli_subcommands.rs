//! Through the real binary: every subcommand is listed in `--help` and the man
//! page, flags given before a subcommand apply to it (or are refused by name), help wraps to
//! 100 columns when stdout is not a terminal, and `--format json` names the report schema.

use assert_cmd::Command;
use std::path::PathBuf;

fn shipped(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("meshes").join(name).display().to_string()
}

fn bin() -> Command {
    let mut c = Command::cargo_bin("meshclash").unwrap();
    // The width off a terminal is ours to choose (100), not the caller's COLUMNS.
    c.env_remove("COLUMNS");
    c
}

fn stdout_of(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

const SUBCOMMANDS: [&str; 10] =
    ["scene", "clash-set", "self", "plan", "run", "merge", "bench", "schema", "completions", "man"];

#[test]
fn every_subcommand_is_listed_in_help_and_man_page() {
    for help in [stdout_of(&["-h"]), stdout_of(&["--help"])] {
        let commands: Vec<&str> = help
            .lines()
            .skip_while(|l| *l != "Commands:")
            .skip(1)
            .take_while(|l| !l.is_empty())
            .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
            .map(|l| l.split_whitespace().next().unwrap())
            .collect();
        for s in SUBCOMMANDS {
            assert!(commands.contains(&s), "`{s}` missing from the Commands of --help: {commands:?}");
        }
    }
    let man = stdout_of(&["man"]);
    for s in SUBCOMMANDS {
        let entry = format!("meshclash\\-{}(1)", s.replace('-', "\\-"));
        assert!(man.contains(&entry), "`{entry}` missing from the man page");
    }
    // `scene` is a real subcommand with its own help naming the file argument.
    let scene = stdout_of(&["scene", "--help"]);
    assert!(scene.contains("Usage: meshclash scene [OPTIONS] <FILE>"), "{scene}");
}

#[test]
fn flags_before_a_subcommand_apply_to_it() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("set.json");
    let set_text = format!(
        r#"{{"version": 1, "checks": [{{"name": "env", "a": {:?}, "b": {:?}, "fail_on": "never"}}]}}"#,
        shipped("fcl_env.obj"),
        shipped("fcl_rob.obj")
    );
    std::fs::write(&set, set_text).unwrap();
    let set = set.to_str().unwrap();
    // Today's meaning of `meshclash --threads 1 clash-set x.json` was "clash-set is mesh A".
    let before = bin().args(["--threads", "1", "--no-timings", "clash-set", set]).output().unwrap();
    let after = bin().args(["clash-set", set, "--threads", "1", "--no-timings"]).output().unwrap();
    assert_eq!(before.status.code(), Some(0), "{}", String::from_utf8_lossy(&before.stderr));
    assert!(before.stdout.starts_with(b"{") && !before.stdout.is_empty());
    assert_eq!(before.stdout, after.stdout);
    // `self` and `scene` likewise.
    let s = bin().args(["--no-timings", "-q", "self", &shipped("multibody.stl")]).output().unwrap();
    assert!(matches!(s.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&s.stderr));
    assert!(String::from_utf8_lossy(&s.stdout).contains("\"meshclash.self/1\""));
    let a = bin().args(["--no-timings", "scene", &shipped("pins.glb")]).output().unwrap();
    let b = bin().args(["scene", &shipped("pins.glb"), "--no-timings"]).output().unwrap();
    assert!(matches!(a.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&a.stderr));
    assert!(String::from_utf8_lossy(&a.stdout).contains("\"mode\": \"parts\""));
    assert_eq!(a.stdout, b.stdout);
    // A flag the subcommand does not take is refused by name, exit 2.
    let bad = bin().args(["--clearance", "1", "clash-set", set]).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.starts_with("meshclash: error: unexpected argument '--clearance'"), "{err}");
    assert!(err.contains("Usage: meshclash clash-set"), "{err}");
    // A flag's value that happens to be a subcommand's name stays a value: `-o self`.
    let o =
        bin().current_dir(dir.path()).args(["-o", "self", "scene", &shipped("pins.glb")]).output().unwrap();
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.path().join("self").is_file());
}

#[test]
fn help_wraps_to_100_columns_off_a_terminal() {
    for args in
        [&["-h"][..], &["--help"], &["scene", "--help"], &["self", "--help"], &["clash-set", "--help"]]
    {
        let help = stdout_of(args);
        let widest = help.lines().map(|l| l.chars().count()).max().unwrap();
        assert!(widest <= 100, "{args:?}: a line of {widest} columns");
        // Wrapped, not cut: the end of the longest flag description is still there.
        if args == ["--help"] {
            assert!(widest > 80, "--help does not use the width");
            assert!(help.contains("diagonal of the box around both inputs)"), "{help}");
        }
    }
}

#[test]
fn format_json_help_names_the_report_schema() {
    let help = stdout_of(&["--help"]);
    let line = format!("The JSON report (`{}`)", meshclash::report::SCHEMA);
    assert!(help.contains(&line), "--help does not say `{line}`");
    assert!(!help.contains("meshclash.report/1"));
}
