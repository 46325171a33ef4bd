//! The exit code is the one promise to a CI job: regressions of wrong gates, each through the
//! real binary on meshes generated here (no files from outside the repository).
//!
//! - a report whose pair list was cut is still a complete baseline, so an unchanged model passes
//!   `--fail-on new`, and an old-style cut baseline is refused;
//! - a cut list keeps the worst pairs (crossing before touching before clearance);
//! - `--first-hit` with a baseline is refused, on the command line and in a clash set;
//! - a partial merge never passes, and its JUnit file names the missing shards;
//! - `merge` writes only the outputs named on its own command line.

use assert_cmd::Command;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::Path;

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// Triangles as OBJ text under `o name` (vertex numbers continue from `base`).
pub fn obj_object(name: &str, tris: &[[[f64; 3]; 3]], base: &mut usize, out: &mut String) {
    let _ = writeln!(out, "o {name}");
    for t in tris {
        for v in t {
            let _ = writeln!(out, "v {} {} {}", v[0], v[1], v[2]);
        }
        let _ = writeln!(out, "f {} {} {}", *base + 1, *base + 2, *base + 3);
        *base += 3;
    }
}

/// One OBJ file of named objects.
pub fn obj(objects: &[(&str, Vec<[[f64; 3]; 3]>)]) -> String {
    let (mut s, mut base) = (String::new(), 0);
    for (name, tris) in objects {
        obj_object(name, tris, &mut base, &mut s);
    }
    s
}

/// A flat grid in z = 0 over [0, w] × [0, 1]: two triangles per unit square.
pub fn floor(w: usize) -> Vec<[[f64; 3]; 3]> {
    (0..w)
        .flat_map(|i| {
            let x = i as f64;
            [
                [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]],
                [[x + 1.0, 0.0, 0.0], [x + 1.0, 1.0, 0.0], [x, 1.0, 0.0]],
            ]
        })
        .collect()
}

/// Small triangles lying on the floor in squares `range` (each touches it face to face).
pub fn lying(range: std::ops::Range<usize>) -> Vec<[[f64; 3]; 3]> {
    range.map(|i| i as f64).map(|x| [[x + 0.1, 0.1, 0.0], [x + 0.4, 0.1, 0.0], [x + 0.1, 0.4, 0.0]]).collect()
}

/// Small triangles piercing the floor in squares `range` (each crosses it).
pub fn piercing(range: std::ops::Range<usize>) -> Vec<[[f64; 3]; 3]> {
    range
        .map(|i| i as f64)
        .map(|x| [[x + 0.2, 0.2, -0.5], [x + 0.3, 0.2, 0.5], [x + 0.2, 0.3, 0.5]])
        .collect()
}

/// A closed box as 12 triangles, outward facing.
pub fn cube(min: [f64; 3], max: [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    let p = |i: usize| {
        [
            if i & 1 == 0 { min[0] } else { max[0] },
            if i & 2 == 0 { min[1] } else { max[1] },
            if i & 4 == 0 { min[2] } else { max[2] },
        ]
    };
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    quads.iter().flat_map(|q| [[p(q[0]), p(q[1]), p(q[2])], [p(q[0]), p(q[2]), p(q[3])]]).collect()
}

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    bin().current_dir(dir).args(args).output().unwrap()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(bytes: &[u8]) -> Value {
    serde_json::from_slice(bytes).expect("a JSON report")
}

/// A on top of a floor B: 20 lying (touching) triangles first, then 20 piercing (crossing)
/// ones, so that the first pairs by triangle index are all touching.
fn touching_then_crossing(dir: &Path) {
    let mut a = lying(0..20);
    a.extend(piercing(20..40));
    write(dir, "a.obj", &obj(&[("a", a)]));
    write(dir, "b.obj", &obj(&[("floor", floor(40))]));
}

#[test]
fn a_cut_list_keeps_the_worst_pairs() {
    let d = tempfile::tempdir().unwrap();
    touching_then_crossing(d.path());
    let full = json(&run(d.path(), &["a.obj", "b.obj", "--no-timings"]).stdout);
    let crossing = full["summary"]["crossing_pairs"].as_u64().unwrap();
    assert!(crossing >= 20 && full["summary"]["touching_pairs"].as_u64().unwrap() >= 20);
    let o = run(d.path(), &["a.obj", "b.obj", "--no-timings", "--max-pairs", "10"]);
    assert_eq!(o.status.code(), Some(1));
    let cut = json(&o.stdout);
    assert_eq!(cut["pairs_truncated"], true);
    let pairs = cut["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), 10);
    assert!(pairs.iter().all(|p| p["kind"] == "crossing"), "a cut list shows crossings first: {pairs:?}");
    // Sorted by (a, b) within what is kept, and every kept pair is one of the full run's.
    let key = |p: &Value| (p["a"].as_u64().unwrap(), p["b"].as_u64().unwrap());
    assert!(pairs.windows(2).all(|w| key(&w[0]) < key(&w[1])));
    let all: Vec<(u64, u64)> = full["pairs"].as_array().unwrap().iter().map(key).collect();
    assert!(pairs.iter().all(|p| all.contains(&key(p))));
    // The ids of what is not listed are recorded (complete as a baseline).
    let unlisted = &cut["unlisted"];
    let n = |k: &str| unlisted[k].as_array().unwrap().len() as u64;
    assert_eq!(n("crossing_ids"), crossing - 10);
    // The text summary and the JUnit failure show crossings, not touching pairs.
    let text = run(d.path(), &["a.obj", "b.obj", "--max-pairs", "10", "--format", "text"]);
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("crossing") && !text.lines().any(|l| l.contains("coplanar")), "{text}");
    let junit = run(d.path(), &["a.obj", "b.obj", "--max-pairs", "10", "--format", "junit"]);
    let junit = String::from_utf8(junit.stdout).unwrap();
    let failure = junit.lines().find(|l| l.contains("<failure")).expect("a failure");
    assert!(failure.contains("first: ") && !failure.contains("coplanar"), "{failure}");
}

#[test]
fn a_cut_report_is_a_complete_baseline() {
    let d = tempfile::tempdir().unwrap();
    touching_then_crossing(d.path());
    let base = run(d.path(), &["a.obj", "b.obj", "--no-timings", "--max-pairs", "3", "-o", "base.json"]);
    assert_eq!(base.status.code(), Some(1), "{}", stderr(&base));
    // The same model again: nothing new, nothing resolved, exit 0.
    for max in ["3", "1000", "0"] {
        let o = run(
            d.path(),
            &[
                "a.obj",
                "b.obj",
                "--no-timings",
                "--max-pairs",
                max,
                "--baseline",
                "base.json",
                "--fail-on",
                "new",
            ],
        );
        assert_eq!(o.status.code(), Some(0), "--max-pairs {max}: {}", stderr(&o));
        let r = json(&o.stdout);
        assert_eq!(r["baseline"]["new"], 0, "--max-pairs {max}");
        assert_eq!(r["baseline"]["resolved"], 0, "--max-pairs {max}");
        assert_eq!(r["baseline"]["complete"], true);
    }
    // One more piercing triangle, at the end of A (never listed with --max-pairs 3): new, exit 1.
    let mut a = lying(0..20);
    a.extend(piercing(20..40));
    a.push([[25.6, 0.6, -0.5], [25.7, 0.6, 0.5], [25.6, 0.7, 0.5]]);
    write(d.path(), "a.obj", &obj(&[("a", a)]));
    let o =
        run(d.path(), &["a.obj", "b.obj", "--max-pairs", "3", "--baseline", "base.json", "--fail-on", "new"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(json(&o.stdout)["baseline"]["new_crossing"].as_u64().unwrap() >= 1);
    // A cut report without the unlisted ids (as older versions wrote) is refused, exit 2.
    let mut old = json(&std::fs::read(d.path().join("base.json")).unwrap());
    old.as_object_mut().unwrap().remove("unlisted");
    write(d.path(), "old.json", &old.to_string());
    let o = run(d.path(), &["a.obj", "b.obj", "--baseline", "old.json", "--fail-on", "new"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.starts_with("meshclash: error: old.json") && e.contains("--max-pairs") && e.lines().count() == 1,
        "{e}"
    );
}

#[test]
fn first_hit_with_a_baseline_is_refused_everywhere() {
    let d = tempfile::tempdir().unwrap();
    touching_then_crossing(d.path());
    let base = run(d.path(), &["a.obj", "b.obj", "-o", "base.json"]);
    assert_eq!(base.status.code(), Some(1));
    let o = run(d.path(), &["a.obj", "b.obj", "--first-hit", "--baseline", "base.json", "--fail-on", "new"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--first-hit"), "{}", stderr(&o));
    write(
        d.path(),
        "set.json",
        r#"{"version": 1, "checks": [{"name": "fh", "a": "a.obj", "b": "b.obj", "first_hit": true,
            "baseline": "base.json", "fail_on": "new"}]}"#,
    );
    let o = run(d.path(), &["clash-set", "set.json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--first-hit"), "{}", stderr(&o));
    // A first-hit report is no baseline either.
    let fh = run(d.path(), &["a.obj", "b.obj", "--first-hit", "-o", "fh.json"]);
    assert_eq!(fh.status.code(), Some(1));
    let o = run(d.path(), &["a.obj", "b.obj", "--baseline", "fh.json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// Six cubes in a row, each overlapping the next: a scene whose part pairs all clash.
fn row_of_cubes(dir: &Path) {
    let cubes: Vec<(String, Vec<[[f64; 3]; 3]>)> = (0..6)
        .map(|i| {
            let x = i as f64 * 0.9;
            (format!("c{i}"), cube([x, 0.0, 0.0], [x + 1.0, 1.0, 1.0]))
        })
        .collect();
    let named: Vec<(&str, Vec<[[f64; 3]; 3]>)> = cubes.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
    write(dir, "row.obj", &obj(&named));
}

#[test]
fn a_partial_merge_never_passes() {
    let d = tempfile::tempdir().unwrap();
    row_of_cubes(d.path());
    let p = run(d.path(), &["plan", "scene", "row.obj", "--no-timings", "-o", "plan.json"]);
    assert_eq!(p.status.code(), Some(0), "{}", stderr(&p));
    for i in 1..=3 {
        let o = run(
            d.path(),
            &["run", "--plan", "plan.json", "--shard", &format!("{i}/3"), "-o", &format!("s{i}.json")],
        );
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    // Whatever the shards present hold, a merge with shards missing fails, and says which.
    for present in [&["s1.json"][..], &["s2.json", "s3.json"]] {
        let mut args = vec!["merge", "--allow-partial", "--junit", "j.xml", "-o", "m.json"];
        args.extend(present);
        let o = run(d.path(), &args);
        assert_eq!(o.status.code(), Some(1), "{present:?}: {}", stderr(&o));
        let r = json(&std::fs::read(d.path().join("m.json")).unwrap());
        assert_eq!(r["complete"], false);
        assert_eq!(r["failed"], true);
        let missing: Vec<&str> =
            r["missing_shards"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
        assert!(!missing.is_empty());
        let junit = std::fs::read_to_string(d.path().join("j.xml")).unwrap();
        let doc = roxmltree::Document::parse(&junit).unwrap();
        let case = doc
            .descendants()
            .find(|n| n.has_tag_name("testcase") && n.attribute("name").is_some_and(|s| s.contains("shard")))
            .expect("a case for the missing shards");
        let failure = case.children().find(|n| n.has_tag_name("failure")).expect("it fails");
        for m in &missing {
            assert!(failure.attribute("message").unwrap().contains(m), "{junit}");
        }
    }
    // All shards: the merge equals the unsharded run, exit 1 (the cubes clash).
    let o = run(d.path(), &["merge", "s1.json", "s2.json", "s3.json", "-o", "all.json"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(json(&std::fs::read(d.path().join("all.json")).unwrap()).get("complete").is_none());
}

#[test]
fn merge_writes_only_the_outputs_on_its_own_command_line() {
    let d = tempfile::tempdir().unwrap();
    row_of_cubes(d.path());
    // A plan carries no outputs.
    let o = run(d.path(), &["plan", "scene", "row.obj", "--junit", "j.xml", "-o", "plan.json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("merge"), "{}", stderr(&o));
    assert!(!d.path().join("plan.json").exists());
    let p = run(d.path(), &["plan", "scene", "row.obj", "--no-timings", "-o", "plan.json"]);
    assert_eq!(p.status.code(), Some(0));
    let o = run(d.path(), &["run", "--plan", "plan.json", "--shard", "1/1", "-o", "s1.json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // A shard report edited to name an output: the merge refuses it and writes nothing.
    write(d.path(), "victim.txt", "keep me");
    let mut shard = json(&std::fs::read(d.path().join("s1.json")).unwrap());
    let args = shard["plan"]["args"].as_array_mut().unwrap();
    args.extend(["--junit".into(), "victim.txt".into()]);
    write(d.path(), "edited.json", &shard.to_string());
    let o = run(d.path(), &["merge", "edited.json", "-o", "m.json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(d.path().join("victim.txt")).unwrap(), "keep me");
    assert!(!d.path().join("m.json").exists());
    // Outputs named on merge's own command line are written; a shard report is never one.
    let o = run(d.path(), &["merge", "s1.json", "--junit", "j.xml", "-o", "m.json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(d.path().join("j.xml").exists() && d.path().join("m.json").exists());
    let o = run(d.path(), &["merge", "s1.json", "-o", "s1.json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = run(d.path(), &["run", "--plan", "plan.json", "--shard", "1/1", "-o", "plan.json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(json(&std::fs::read(d.path().join("plan.json")).unwrap()).get("pairs").is_some());
}
