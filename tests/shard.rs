//! `meshclash plan` → `run --shard I/N` (separate processes) → `merge` writes the
//! report of the unsharded check byte for byte (`--no-timings`), with its JUnit file and exit
//! code; the engines' shard variables; every refusal (missing, duplicate, failed, foreign
//! shard; inputs changed since the plan); `--allow-partial` and the baseline that refuses it.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};

use crate::common::{corpus, shared};

fn bin(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_meshclash"));
    c.current_dir(dir);
    for v in [
        "JOB_COMPLETION_INDEX",
        "AWS_BATCH_JOB_ARRAY_INDEX",
        "AWS_BATCH_JOB_ARRAY_SIZE",
        "CLOUD_RUN_TASK_INDEX",
        "CLOUD_RUN_TASK_COUNT",
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_COUNT",
    ] {
        c.env_remove(v);
    }
    c
}

fn run(dir: &Path, args: &[&str]) -> Output {
    bin(dir).args(args).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A temporary directory holding copies of the named meshes; `None` (the test skips) when one
/// of them is not available.
fn workdir(meshes: &[&str]) -> Option<tempfile::TempDir> {
    let d = tempfile::tempdir().unwrap();
    for m in meshes {
        std::fs::copy(corpus(m)?, d.path().join(m)).unwrap();
    }
    Some(d)
}

/// The unsharded check: (report, JUnit, exit code).
fn single(dir: &Path, check: &[&str]) -> (Vec<u8>, Vec<u8>, i32) {
    let mut args: Vec<&str> = check.to_vec();
    args.extend(["--no-timings", "--junit", "single.xml", "-o", "single.json"]);
    let o = run(dir, &args);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    (
        std::fs::read(dir.join("single.json")).unwrap(),
        std::fs::read(dir.join("single.xml")).unwrap(),
        o.status.code().unwrap(),
    )
}

/// How each shard learns its index.
#[derive(Clone, Copy, Debug)]
enum Via {
    Flag,
    Kubernetes,
    AwsBatch,
    CloudRun,
    Slurm,
}

fn spawn_shard(dir: &Path, plan: &str, i: usize, n: usize, via: Via, threads: usize) -> Child {
    let mut c = bin(dir);
    c.args([
        "run",
        "--plan",
        plan,
        "-o",
        &format!("shard-{i}.json"),
        "--threads",
        &threads.to_string(),
        "-q",
    ]);
    match via {
        Via::Flag => {
            c.args(["--shard", &format!("{i}/{n}")]);
        }
        Via::Kubernetes => {
            c.env("JOB_COMPLETION_INDEX", (i - 1).to_string()).args(["--shards", &n.to_string()]);
        }
        Via::AwsBatch => {
            c.env("AWS_BATCH_JOB_ARRAY_INDEX", (i - 1).to_string())
                .env("AWS_BATCH_JOB_ARRAY_SIZE", n.to_string());
        }
        Via::CloudRun => {
            c.env("CLOUD_RUN_TASK_INDEX", (i - 1).to_string()).env("CLOUD_RUN_TASK_COUNT", n.to_string());
        }
        Via::Slurm => {
            // `sbatch --array=5-(4+N)`: the index is relative to SLURM_ARRAY_TASK_MIN.
            c.env("SLURM_ARRAY_TASK_ID", (i + 4).to_string())
                .env("SLURM_ARRAY_TASK_MIN", "5")
                .env("SLURM_ARRAY_TASK_COUNT", n.to_string());
        }
    }
    c.stderr(std::process::Stdio::piped()).spawn().unwrap()
}

/// plan → N shard processes at once → merge (shards listed in a scrambled order): (report,
/// JUnit, exit code).
fn sharded(dir: &Path, check: &[&str], n: usize, via: Via) -> (Vec<u8>, Vec<u8>, i32) {
    let mut args = vec!["plan"];
    args.extend(check);
    args.extend(["--no-timings", "-o", "plan.json"]);
    let o = run(dir, &args);
    assert_eq!(o.status.code(), Some(0), "plan: {}", stderr(&o));
    let children: Vec<Child> = (1..=n).map(|i| spawn_shard(dir, "plan.json", i, n, via, 1 + i % 2)).collect();
    for (i, c) in children.into_iter().enumerate() {
        let o = c.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(0), "shard {}/{n}: {}", i + 1, stderr(&o));
    }
    // Scrambled: every third first, then the rest backwards.
    let mut order: Vec<usize> = (1..=n).filter(|i| i % 3 == 0).collect();
    order.extend((1..=n).rev().filter(|i| i % 3 != 0));
    let names: Vec<String> = order.iter().map(|i| format!("shard-{i}.json")).collect();
    let mut args = vec!["merge", "--junit", "merged.xml", "-o", "merged.json"];
    args.extend(names.iter().map(String::as_str));
    let o = run(dir, &args);
    assert!(matches!(o.status.code(), Some(0 | 1)), "merge: {}", stderr(&o));
    (
        std::fs::read(dir.join("merged.json")).unwrap(),
        std::fs::read(dir.join("merged.xml")).unwrap(),
        o.status.code().unwrap(),
    )
}

/// The merged report, JUnit and exit code equal the single run's, for every N.
fn assert_identical(dir: &Path, check: &[&str], ns: &[usize], via: Via) {
    let (report, junit, code) = single(dir, check);
    let v: serde_json::Value = serde_json::from_slice(&report).unwrap();
    assert!(v["timings_ms"].is_null());
    for &n in ns {
        let (r, j, c) = sharded(dir, check, n, via);
        assert!(r == report, "{check:?} in {n} shards ({via:?}): the merged report differs");
        // The JUnit files differ only by the name they were written under (none) or not at all.
        assert!(j == junit, "{check:?} in {n} shards: the merged JUnit differs");
        assert_eq!(c, code, "{check:?} in {n} shards: exit code");
    }
}

#[test]
fn engine_scene_merges_byte_identically_for_1_2_3_7_shards() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    assert_identical(d.path(), &["scene", "2CylinderEngine.glb"], &[1, 2, 3, 7], Via::Flag);
}

#[test]
fn engine_scene_with_clearance_merges_byte_identically() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    assert_identical(
        d.path(),
        &["scene", "2CylinderEngine.glb", "--clearance", "2", "--fail-on", "clearance"],
        &[2, 7],
        Via::Flag,
    );
}

#[test]
fn the_engines_variables_give_the_shard() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    for (via, n) in [(Via::Kubernetes, 3), (Via::AwsBatch, 2), (Via::CloudRun, 3), (Via::Slurm, 2)] {
        assert_identical(d.path(), &["scene", "2CylinderEngine.glb"], &[n], via);
    }
}

#[test]
fn split_bodies_and_two_files_merge_byte_identically() {
    let Some(d) = workdir(&["shared.STL", "fcl_env.obj", "fcl_rob.obj", "2CylinderEngine.glb", "pins.glb"])
    else {
        return;
    };
    assert_identical(d.path(), &["scene", "shared.STL", "--split-bodies"], &[1, 2, 3, 7], Via::Flag);
    // Two files: one work unit (the whole-file check is one dual walk).
    assert_identical(
        d.path(),
        &["fcl_env.obj", "fcl_rob.obj", "--translate-b", "0,0,0"],
        &[1, 2, 3, 7],
        Via::Flag,
    );
    // Two files part by part (a selection), and containment/penetration settings.
    assert_identical(
        d.path(),
        &["2CylinderEngine.glb", "pins.glb", "--select-a", "*", "--penetration", "--units", "mm"],
        &[1, 3, 7],
        Via::Flag,
    );
}

#[test]
fn baseline_status_and_fail_on_new_merge_identically() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    let base = run(
        d.path(),
        &["scene", "2CylinderEngine.glb", "--clearance", "1", "--no-timings", "-o", "base.json"],
    );
    assert!(matches!(base.status.code(), Some(0 | 1)), "{}", stderr(&base));
    assert_identical(
        d.path(),
        &["scene", "2CylinderEngine.glb", "--clearance", "3", "--baseline", "base.json", "--fail-on", "new"],
        &[3],
        Via::Flag,
    );
}

/// glTF of the engine cloned `k` times in a 10-wide grid (700 × 300 apart: neighbours in x
/// overlap, so parts of different clones meet), each clone under a node `cNN`.
fn federation(dir: &Path, k: usize) {
    let d = std::fs::read(shared("2CylinderEngine.glb")).unwrap();
    let u32_at = |o: usize| u32::from_le_bytes(d[o..o + 4].try_into().unwrap()) as usize;
    let jl = u32_at(12);
    let mut j: serde_json::Value = serde_json::from_slice(&d[20..20 + jl]).unwrap();
    let bl = u32_at(20 + jl);
    let bin = &d[28 + jl..28 + jl + bl];
    let nodes = j["nodes"].as_array().unwrap().clone();
    let roots: Vec<u64> =
        j["scenes"][0]["nodes"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    let n = nodes.len() as u64;
    let mut all = Vec::new();
    for c in 0..k as u64 {
        for node in &nodes {
            let mut node = node.clone();
            if let Some(ch) = node.get_mut("children") {
                *ch = ch
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| serde_json::Value::from(x.as_u64().unwrap() + c * n))
                    .collect();
            }
            all.push(node);
        }
    }
    for c in 0..k as u64 {
        all.push(serde_json::json!({
            "name": format!("c{c:02}"),
            "translation": [700.0 * (c % 10) as f64, 300.0 * (c / 10) as f64, 0.0],
            "children": roots.iter().map(|r| r + c * n).collect::<Vec<_>>(),
        }));
    }
    j["nodes"] = all.into();
    j["scenes"] =
        serde_json::json!([{ "nodes": (0..k as u64).map(|c| k as u64 * n + c).collect::<Vec<_>>() }]);
    j["scene"] = 0.into();
    let mut js = serde_json::to_vec(&j).unwrap();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + js.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((js.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&js);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    std::fs::write(dir.join("fed.glb"), out).unwrap();
}

#[test]
fn federation_of_50_engines_merges_byte_identically() {
    let Some(_) = corpus("2CylinderEngine.glb") else { return };
    let d = tempfile::tempdir().unwrap();
    federation(d.path(), 50);
    // One clone against the rest of the site (all 3350 parts planned; the neighbours in the
    // grid meet it), and a clone against ten with overlapping selections (a part against
    // itself and mirrored pairs are not work, but count and need their trees).
    assert_identical(d.path(), &["scene", "fed.glb", "--select-a", "c00/*"], &[1, 2, 3, 7], Via::Flag);
    assert_identical(
        d.path(),
        &["scene", "fed.glb", "--select-a", "c00/*", "--select-b", "c0?/*"],
        &[3, 7],
        Via::Flag,
    );
}

/// plan + all N shards of `scene 2CylinderEngine.glb` in `dir` (shards written as shard-I.json).
fn planned(dir: &Path, n: usize, extra: &[&str]) {
    let mut args = vec!["plan", "scene", "2CylinderEngine.glb", "--no-timings", "-o", "plan.json"];
    args.extend(extra);
    assert_eq!(run(dir, &args).status.code(), Some(0));
    for i in 1..=n {
        let o = run(
            dir,
            &["run", "--plan", "plan.json", "--shard", &format!("{i}/{n}"), "-o", &format!("shard-{i}.json")],
        );
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
}

fn refused(dir: &Path, args: &[&str], says: &[&str]) {
    let o = run(dir, args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(e.starts_with("meshclash: error: ") && e.trim_end().lines().count() == 1, "{e}");
    for s in says {
        assert!(e.contains(s), "{args:?}: '{e}' does not say '{s}'");
    }
}

#[test]
fn missing_duplicate_foreign_and_failed_shards_are_refused_by_name() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    let p = d.path();
    planned(p, 3, &[]);
    assert!(!p.join("report.json").exists());
    refused(p, &["merge", "shard-1.json", "shard-3.json", "-o", "report.json"], &["missing shard 2/3"]);
    refused(
        p,
        &["merge", "shard-1.json", "shard-2.json", "shard-3.json", "shard-2.json"],
        &["duplicate shard 2/3", "shard-2.json"],
    );
    std::fs::copy(p.join("shard-1.json"), p.join("copy-1.json")).unwrap();
    refused(
        p,
        &["merge", "shard-1.json", "shard-2.json", "shard-3.json", "copy-1.json"],
        &["duplicate shard 1/3", "copy-1.json"],
    );
    // A shard of another plan (other settings, same inputs).
    std::fs::create_dir(p.join("other")).unwrap();
    std::fs::copy(p.join("2CylinderEngine.glb"), p.join("other/2CylinderEngine.glb")).unwrap();
    planned(&p.join("other"), 3, &["--clearance", "1"]);
    std::fs::copy(p.join("other/shard-2.json"), p.join("foreign-2.json")).unwrap();
    refused(
        p,
        &["merge", "shard-1.json", "foreign-2.json", "shard-3.json"],
        &["foreign-2.json", "another plan"],
    );
    // A shard count that is not the others'.
    let o = run(p, &["run", "--plan", "plan.json", "--shard", "2/4", "-o", "four-2.json"]);
    assert_eq!(o.status.code(), Some(0));
    refused(p, &["merge", "shard-1.json", "four-2.json", "shard-3.json"], &["four-2.json", "2/4"]);
    // Not a shard report at all.
    refused(p, &["merge", "shard-1.json", "plan.json", "shard-3.json"], &["plan.json", "meshclash.shard/1"]);
    // Bad shard numbers.
    refused(p, &["run", "--plan", "plan.json", "--shard", "4/3", "-o", "x.json"], &["4/3"]);
    refused(p, &["run", "--plan", "plan.json", "--shard", "0/3", "-o", "x.json"], &["0/3"]);
    refused(p, &["run", "--plan", "plan.json", "-o", "x.json"], &["--shard", "JOB_COMPLETION_INDEX"]);
    let o = bin(p)
        .args(["run", "--plan", "plan.json", "-o", "x.json"])
        .env("JOB_COMPLETION_INDEX", "1")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--shards N"), "{}", stderr(&o));
    // A failed shard (its input changed after the plan) writes a report saying so; the merge
    // names it.
    let mut bytes = std::fs::read(p.join("2CylinderEngine.glb")).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(p.join("2CylinderEngine.glb"), &bytes).unwrap();
    refused(
        p,
        &["run", "--plan", "plan.json", "--shard", "2/3", "-o", "shard-2.json"],
        &["2CylinderEngine.glb", "changed since the plan"],
    );
    refused(
        p,
        &["merge", "shard-1.json", "shard-2.json", "shard-3.json"],
        &["shard-2.json", "shard 2/3 failed", "changed since the plan"],
    );
    assert!(!p.join("report.json").exists(), "no refusal wrote a report");
}

#[test]
fn tampered_input_is_refused_at_merge() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    let p = d.path();
    planned(p, 2, &[]);
    let mut bytes = std::fs::read(p.join("2CylinderEngine.glb")).unwrap();
    bytes[100] ^= 0x10;
    std::fs::write(p.join("2CylinderEngine.glb"), &bytes).unwrap();
    refused(
        p,
        &["merge", "shard-1.json", "shard-2.json", "-o", "r.json"],
        &["2CylinderEngine.glb", "changed since the plan"],
    );
    assert!(!p.join("r.json").exists());
}

#[test]
fn partial_merge_is_marked_and_refused_as_a_baseline() {
    let Some(d) = workdir(&["2CylinderEngine.glb"]) else { return };
    let p = d.path();
    planned(p, 3, &[]);
    let o = run(p, &["merge", "shard-1.json", "shard-3.json", "--allow-partial", "-o", "partial.json"]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let text = std::fs::read_to_string(p.join("partial.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["complete"], serde_json::Value::Bool(false));
    // Fewer findings than the whole run.
    let whole = run(p, &["merge", "shard-1.json", "shard-2.json", "shard-3.json", "-o", "whole.json"]);
    assert_eq!(whole.status.code(), Some(1));
    let w: serde_json::Value = serde_json::from_slice(&std::fs::read(p.join("whole.json")).unwrap()).unwrap();
    assert!(w.get("complete").is_none());
    assert!(
        v["pairs"].as_array().unwrap().len() < w["pairs"].as_array().unwrap().len()
            || v["summary"]["crossing_pairs"].as_u64() < w["summary"]["crossing_pairs"].as_u64()
    );
    refused(
        p,
        &["scene", "2CylinderEngine.glb", "--baseline", "partial.json", "-o", "next.json"],
        &["partial.json", "partial merge"],
    );
    // A whole merge is a baseline like any report.
    let o = run(p, &["scene", "2CylinderEngine.glb", "--baseline", "whole.json", "-o", "next.json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
}

#[test]
fn plan_lists_stable_ids_costs_and_refuses_what_cannot_be_sharded() {
    let Some(d) = workdir(&["2CylinderEngine.glb", "fcl_env.obj", "fcl_rob.obj"]) else { return };
    let p = d.path();
    let o = run(p, &["plan", "scene", "2CylinderEngine.glb", "-o", "plan.json", "--clearance", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value =
        serde_json::from_slice(&std::fs::read(p.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["schema"], "meshclash.plan/1");
    assert_eq!(plan["args"], serde_json::json!(["scene", "2CylinderEngine.glb", "--clearance", "1"]));
    assert_eq!(plan["inputs"][0]["sha256"].as_str().unwrap().len(), 64);
    let pairs = plan["pairs"].as_array().unwrap();
    assert!(pairs.len() > 100);
    let ids: std::collections::HashSet<&str> = pairs.iter().map(|p| p["id"].as_str().unwrap()).collect();
    assert_eq!(ids.len(), pairs.len());
    assert!(pairs.iter().all(|p| p["cost"].as_u64().unwrap() >= 1));
    let keys: Vec<(u64, u64)> =
        pairs.iter().map(|p| (p["a"].as_u64().unwrap(), p["b"].as_u64().unwrap())).collect();
    assert!(keys.windows(2).all(|w| w[0] < w[1]), "sorted by (a, b)");
    // Planning again gives the same bytes; so does `--output=` spelled otherwise.
    let first = std::fs::read(p.join("plan.json")).unwrap();
    let o = run(p, &["plan", "--output=plan2.json", "scene", "2CylinderEngine.glb", "--clearance", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read(p.join("plan2.json")).unwrap(), first);
    // Two files without a selection: one work unit.
    let o = run(p, &["plan", "fcl_env.obj", "fcl_rob.obj", "-o", "files.json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let files: serde_json::Value =
        serde_json::from_slice(&std::fs::read(p.join("files.json")).unwrap()).unwrap();
    assert_eq!(files["mode"], "files");
    assert_eq!(files["pairs"].as_array().unwrap().len(), 1);
    refused(p, &["plan", "scene", "2CylinderEngine.glb"], &["-o PLAN.json"]);
    refused(
        p,
        &["plan", "fcl_env.obj", "fcl_rob.obj", "--cross-check", "parry", "-o", "x.json"],
        &["--cross-check"],
    );
    refused(p, &["plan", "scene", "2CylinderEngine.glb", "--first-hit", "-o", "x.json"], &["--first-hit"]);
    refused(
        p,
        &["plan", "scene", "2CylinderEngine.glb", "-o", "2CylinderEngine.glb"],
        &["2CylinderEngine.glb"],
    );
    refused(p, &["plan", "scene", "missing.glb", "-o", "x.json"], &["missing.glb"]);
    refused(p, &["run", "--plan", "fcl_env.obj", "--shard", "1/1", "-o", "x.json"], &["fcl_env.obj"]);
}

#[test]
fn deploy_local_sh_runs_plan_shards_and_merge() {
    let Some(d) = workdir(&["shared.STL"]) else { return };
    let p = d.path();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("deploy/local.sh");
    let o = Command::new("bash")
        .arg(&script)
        .args(["3", "out", "--", "scene", "shared.STL", "--split-bodies", "--no-timings"])
        .env("MESHCLASH", env!("CARGO_BIN_EXE_meshclash"))
        .current_dir(p)
        .output()
        .unwrap();
    let (report, junit, code) = single(p, &["scene", "shared.STL", "--split-bodies"]);
    assert_eq!(o.status.code(), Some(code), "{}", stderr(&o));
    assert!(std::fs::read(p.join("out/report.json")).unwrap() == report);
    assert!(std::fs::read(p.join("out/report.xml")).unwrap() == junit);
    assert!((1..=3).all(|i| p.join(format!("out/shard-{i}.json")).is_file()));
}
