//! Shard counts, indices and shard reports are data: hostile values are one-line errors (exit
//! 2), never an abort, a panic or a wrapped index.

use crate::gate::{cube, obj};
use assert_cmd::Command;
use serde_json::Value;
use std::path::Path;

fn run(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    let mut c = Command::cargo_bin("meshclash").unwrap();
    c.current_dir(dir).args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.timeout(std::time::Duration::from_secs(120)).output().unwrap()
}

fn one_line_error(o: &std::process::Output, what: &str) {
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {e}");
    assert!(e.starts_with("meshclash: error: ") && e.lines().count() == 1, "{what}: {e}");
}

#[test]
fn hostile_shard_counts_indices_and_reports_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let parts: Vec<(String, Vec<[[f64; 3]; 3]>)> = (0..4)
        .map(|i| (format!("c{i}"), cube([i as f64 * 0.9, 0.0, 0.0], [i as f64 * 0.9 + 1.0, 1.0, 1.0])))
        .collect();
    let named: Vec<(&str, Vec<[[f64; 3]; 3]>)> = parts.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
    std::fs::write(p.join("row.obj"), obj(&named)).unwrap();
    let o = run(p, &["plan", "scene", "row.obj", "--no-timings", "-o", "plan.json"], &[]);
    assert_eq!(o.status.code(), Some(0));
    for shard in ["1/10000000000", "1/18446744073709551615", "0/3", "4/3", "1/0"] {
        let o = run(p, &["run", "--plan", "plan.json", "--shard", shard, "-o", "s.json"], &[]);
        one_line_error(&o, shard);
    }
    let o = run(
        p,
        &["run", "--plan", "plan.json", "--shards", "3", "-o", "s.json"],
        &[("JOB_COMPLETION_INDEX", "18446744073709551615")],
    );
    one_line_error(&o, "JOB_COMPLETION_INDEX at the top of usize");
    let o = run(
        p,
        &["run", "--plan", "plan.json", "-o", "s.json"],
        &[("CLOUD_RUN_TASK_INDEX", "0"), ("CLOUD_RUN_TASK_COUNT", "10000000000")],
    );
    one_line_error(&o, "CLOUD_RUN_TASK_COUNT of ten billion");
    // More shards than pairs is fine: the extra shards are empty.
    let o = run(p, &["run", "--plan", "plan.json", "--shard", "1/1000", "-o", "s1.json"], &[]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    // A plan naming a part that does not exist.
    let mut plan: Value = serde_json::from_slice(&std::fs::read(p.join("plan.json")).unwrap()).unwrap();
    plan["pairs"][0]["a"] = Value::from(1_000_000u64);
    std::fs::write(p.join("bad-plan.json"), plan.to_string()).unwrap();
    let o = run(p, &["run", "--plan", "bad-plan.json", "--shard", "1/1", "-o", "s.json"], &[]);
    one_line_error(&o, "plan part index out of range");
    // Shard reports: a huge shard count, a triangle index out of range.
    let o = run(p, &["run", "--plan", "plan.json", "--shard", "1/1", "-o", "whole.json"], &[]);
    assert_eq!(o.status.code(), Some(0));
    let whole: Value = serde_json::from_slice(&std::fs::read(p.join("whole.json")).unwrap()).unwrap();
    let mut huge = whole.clone();
    huge["shards"] = Value::from(1_000_000_000_000_000_000u64);
    std::fs::write(p.join("huge.json"), huge.to_string()).unwrap();
    one_line_error(&run(p, &["merge", "--allow-partial", "huge.json"], &[]), "shards: 1e18");
    let mut far = whole.clone();
    let pairs = far["outcome"]["pairs"].as_array_mut().unwrap();
    assert!(!pairs.is_empty(), "the cubes meet");
    pairs[0]["a"] = Value::from(4_000_000_000u64);
    std::fs::write(p.join("far.json"), far.to_string()).unwrap();
    one_line_error(&run(p, &["merge", "far.json"], &[]), "triangle index out of range");
}
