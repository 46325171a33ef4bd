//! The contract of the gate: every path that can answer a check — two files, `scene`,
//! `--detail parts`, `--first-hit`, `--max-pairs 1`, a baseline against itself, a clash set,
//! `plan`/`run`/`merge` at 1 and 3 shards — gives the exit code and verdict of the full exact
//! run, or refuses (exit 2) where it cannot. A matrix of real cases: generated overlaps,
//! containment, touching only, clearance, clear, and shipped meshes.

use crate::gate::{cube, floor, lying, obj, piercing};
use assert_cmd::Command;
use serde_json::Value;
use std::path::{Path, PathBuf};

type Tris = Vec<[[f64; 3]; 3]>;

/// A case: A and B (single parts, also written as one two-part scene file), or two files.
struct Case {
    name: &'static str,
    a: PathBuf,
    b: PathBuf,
    /// The one file holding both as parts, when the case has one.
    scene: Option<PathBuf>,
    flags: Vec<&'static str>,
}

fn generated(dir: &Path, name: &'static str, a: Tris, b: Tris, flags: Vec<&'static str>) -> Case {
    let sub = dir.join(name);
    std::fs::create_dir_all(&sub).unwrap();
    std::fs::write(sub.join("a.obj"), obj(&[("A", a.clone())])).unwrap();
    std::fs::write(sub.join("b.obj"), obj(&[("B", b.clone())])).unwrap();
    std::fs::write(sub.join("scene.obj"), obj(&[("A", a), ("B", b)])).unwrap();
    Case { name, a: sub.join("a.obj"), b: sub.join("b.obj"), scene: Some(sub.join("scene.obj")), flags }
}

fn cases(dir: &Path) -> Vec<Case> {
    let mut crossing = lying(0..20);
    crossing.extend(piercing(20..40));
    let shipped = |f: &str| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("meshes").join(f);
    vec![
        generated(dir, "overlap", crossing, floor(40), vec![]),
        generated(dir, "contained", cube([0.0; 3], [4.0; 3]), cube([1.0; 3], [2.0; 3]), vec![]),
        generated(dir, "touching", cube([0.0; 3], [1.0; 3]), cube([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]), vec![]),
        generated(
            dir,
            "clearance",
            cube([0.0; 3], [1.0; 3]),
            cube([1.25, 0.0, 0.0], [2.25, 1.0, 1.0]),
            vec!["--clearance", "0.5", "--fail-on", "clearance"],
        ),
        generated(dir, "clear", cube([0.0; 3], [1.0; 3]), cube([3.0, 0.0, 0.0], [4.0, 1.0, 1.0]), vec![]),
        Case {
            name: "shipped fcl",
            a: shipped("fcl_env.obj"),
            b: shipped("fcl_rob.obj"),
            scene: None,
            flags: vec![],
        },
        Case {
            name: "shipped multibody",
            a: shipped("multibody.stl"),
            b: shipped("joined_tetrahedra.obj"),
            scene: None,
            flags: vec!["--clearance", "1"],
        },
    ]
}

/// (exit code, verdict) of a run whose JSON report is on stdout or in `report`.
fn answer(dir: &Path, args: &[&str], report: Option<&str>) -> (i32, String) {
    let o = Command::cargo_bin("meshclash").unwrap().current_dir(dir).args(args).output().unwrap();
    let code = o.status.code().unwrap();
    assert!(code != 2, "{args:?} failed: {}", String::from_utf8_lossy(&o.stderr));
    let bytes = match report {
        Some(f) => std::fs::read(dir.join(f)).unwrap(),
        None => o.stdout,
    };
    let v: Value = serde_json::from_slice(&bytes).unwrap();
    let verdict = v.get("verdict").or_else(|| v.pointer("/checks/0/report/verdict")).unwrap();
    (code, verdict.as_str().unwrap().to_string())
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_path_gives_the_full_runs_exit_code_and_verdict() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    for case in cases(dir) {
        let with = |extra: &[&'static str], files: &[&str]| -> Vec<String> {
            let mut v: Vec<String> = extra.iter().map(|x| x.to_string()).collect();
            v.extend(files.iter().map(|x| x.to_string()));
            v.extend(case.flags.iter().map(|x| x.to_string()));
            v.push("--no-timings".into());
            v
        };
        let files = [s(&case.a), s(&case.b)];
        let full = answer(dir, &to_refs(&with(&[], &files)), None);
        let name = case.name;
        let mut paths: Vec<(String, (i32, String))> = Vec::new();
        for extra in
            [&["--detail", "parts"][..], &["--first-hit"], &["--max-pairs", "1"], &["--max-pairs", "0"]]
        {
            let mut args = with(&[], &files);
            args.extend(extra.iter().map(|x| x.to_string()));
            paths.push((format!("{extra:?}"), answer(dir, &to_refs(&args), None)));
        }
        if let Some(scene) = &case.scene {
            paths.push(("scene".into(), answer(dir, &to_refs(&with(&["scene"], &[s(scene)])), None)));
            let mut args = with(&["scene"], &[s(scene)]);
            args.extend(["--detail".into(), "parts".into()]);
            paths.push(("scene --detail parts".into(), answer(dir, &to_refs(&args), None)));
        }
        // A baseline against itself: the same gate, and `--fail-on new` passes.
        let mut args = with(&[], &files);
        args.extend(["-o".into(), "base.json".into()]);
        paths.push(("writing a baseline".into(), answer(dir, &to_refs(&args), Some("base.json"))));
        let mut args = with(&[], &files);
        args.extend(["--baseline".into(), "base.json".into()]);
        paths.push(("--baseline itself".into(), answer(dir, &to_refs(&args), None)));
        // (The case's own --fail-on gives way to `new`.)
        let mut args: Vec<String> = Vec::new();
        let mut it = with(&[], &files).into_iter();
        while let Some(x) = it.next() {
            if x == "--fail-on" {
                it.next();
            } else {
                args.push(x);
            }
        }
        args.extend(["--baseline", "base.json", "--max-pairs", "1", "--fail-on", "new"].map(String::from));
        let (code, verdict) = answer(dir, &to_refs(&args), None);
        assert_eq!((code, &verdict), (0, &full.1), "{name}: --fail-on new against itself");
        // A clash set of the one check.
        let mut check = serde_json::json!({"name": "c", "a": s(&case.a), "b": s(&case.b)});
        let mut flags = case.flags.iter();
        while let Some(f) = flags.next() {
            let key = f.trim_start_matches("--").replace('-', "_");
            check[key] = Value::String(flags.next().unwrap().to_string());
        }
        let set = serde_json::json!({"version": 1, "checks": [check]});
        std::fs::write(dir.join("set.json"), set.to_string()).unwrap();
        paths.push(("clash-set".into(), answer(dir, &["clash-set", "set.json", "--no-timings"], None)));
        // plan / run / merge at 1 and 3 shards.
        for n in [1, 3] {
            let mut args = with(&["plan"], &files);
            args.extend(["-o".into(), "plan.json".into()]);
            let o = Command::cargo_bin("meshclash").unwrap().current_dir(dir).args(&args).output().unwrap();
            assert_eq!(o.status.code(), Some(0), "{name}: plan: {}", String::from_utf8_lossy(&o.stderr));
            let mut merge = vec!["merge".to_string(), "-o".into(), "merged.json".into()];
            for i in 1..=n {
                let out = format!("shard-{i}.json");
                let shard = format!("{i}/{n}");
                let o = Command::cargo_bin("meshclash")
                    .unwrap()
                    .current_dir(dir)
                    .args(["run", "--plan", "plan.json", "--shard", &shard, "-o", &out])
                    .output()
                    .unwrap();
                assert_eq!(o.status.code(), Some(0), "{name}: shard {shard}");
                merge.push(out);
            }
            paths.push((format!("merge of {n}"), answer(dir, &to_refs(&merge), Some("merged.json"))));
        }
        for (path, got) in &paths {
            assert_eq!(got, &full, "{name}: {path} differs from the full run");
        }
        // The gate follows the verdict.
        assert_eq!(
            full.0 == 1,
            full.1 == "clash" || (full.1 == "clearance" && case.flags.contains(&"clearance"))
        );
    }
}

fn to_refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}
