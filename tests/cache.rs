//! The result cache (`--cache DIR`) through the real binary: a report with the cache is the
//! report without it, byte for byte, but for the added `cache` block; a moved part, a changed
//! setting, a corrupt entry, concurrent runs and a baseline comparison change nothing else.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_meshclash"));
    c.current_dir(dir).env_remove("MESHCLASH_CACHE");
    c
}

fn run(dir: &Path, args: &[&str]) -> Output {
    let o = bin(dir).args(args).output().unwrap();
    assert!(matches!(o.status.code(), Some(0 | 1)), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    o
}

fn text(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

/// An axis-aligned cube of edge `s` at `min`, as OBJ lines (vertices numbered from `base`).
fn cube(name: &str, min: [f64; 3], s: f64, base: usize) -> String {
    let mut out = format!("o {name}\n");
    for i in 0..8 {
        let [x, y, z] = [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(|b| b as f64 * s);
        out += &format!("v {} {} {}\n", min[0] + x, min[1] + y, min[2] + z);
    }
    // Outward-wound faces of the unit cube (corner i has bits x, y, z).
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for f in faces {
        let v = f.map(|i| i + base + 1);
        out += &format!("f {} {} {}\nf {} {} {}\n", v[0], v[1], v[2], v[0], v[2], v[3]);
    }
    out
}

/// A row of cubes in one OBJ, one `o` group each.
fn row(cubes: &[(&str, [f64; 3])]) -> String {
    cubes.iter().enumerate().map(|(i, (n, m))| cube(n, *m, 1.0, 8 * i)).collect()
}

/// Overlapping (a, b), close (b, c: 0.05 apart), far (d).
fn scene_cubes() -> Vec<(&'static str, [f64; 3])> {
    vec![("a", [0.0; 3]), ("b", [0.5, 0.0, 0.0]), ("c", [1.55, 0.0, 0.0]), ("d", [10.0, 0.0, 0.0])]
}

fn write(dir: &Path, name: &str, s: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

/// The report without its `cache` block (the last member), and the block's three values.
fn split(report: &str) -> (String, (u64, u64, String)) {
    let i = report.rfind(",\n  \"cache\": {").expect("a cache block");
    let end = i + report[i..].find("\n  }").unwrap() + 4;
    let v: serde_json::Value = serde_json::from_str(report).unwrap();
    let c = &v["cache"];
    let counts = (
        c["part_pairs_reused"].as_u64().unwrap(),
        c["part_pairs_checked"].as_u64().unwrap(),
        c["dir"].as_str().unwrap().to_string(),
    );
    (format!("{}{}", &report[..i], &report[end..]), counts)
}

fn candidates(report: &str) -> u64 {
    let v: serde_json::Value = serde_json::from_str(report).unwrap();
    v["assembly"]["candidate_part_pairs"].as_u64().expect("assembly.candidate_part_pairs")
}

const SCENE: [&str; 5] = ["scene", "row.obj", "--no-timings", "--clearance", "0.1"];

fn with(base: &[&str], more: &[&str]) -> Vec<String> {
    base.iter().chain(more).map(|s| s.to_string()).collect()
}

fn run_s(dir: &Path, args: &[String]) -> String {
    text(&run(dir, &args.iter().map(String::as_str).collect::<Vec<_>>()))
}

#[test]
fn warm_run_equals_cold_and_reuses_every_candidate_pair() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "row.obj", &row(&scene_cubes()));
    let cold = run_s(d.path(), &with(&SCENE, &[]));
    assert!(!cold.contains("\"cache\""), "no block without --cache");
    let n = candidates(&cold);
    assert!(n >= 2, "the scene has candidate pairs: {n}");
    let first = run_s(d.path(), &with(&SCENE, &["--cache", "c"]));
    let (body, counts) = split(&first);
    assert_eq!(body, cold);
    assert_eq!(counts, (0, n, "c".to_string()));
    let warm = run_s(d.path(), &with(&SCENE, &["--cache", "c"]));
    let (body, counts) = split(&warm);
    assert_eq!(body, cold);
    assert_eq!(counts, (n, 0, "c".to_string()));
}

#[test]
fn two_file_check_warm_equals_cold() {
    let d = tempfile::tempdir().unwrap();
    let cubes = scene_cubes();
    write(d.path(), "a.obj", &row(&cubes[..2]));
    write(d.path(), "b.obj", &row(&cubes[2..]));
    let args = ["a.obj", "b.obj", "--no-timings", "--clearance", "0.1"];
    let cold = run_s(d.path(), &with(&args, &[]));
    let first = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    let warm = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!(first.0, cold);
    assert_eq!(warm.0, cold);
    assert_eq!(warm.1 .1, 0, "nothing checked on a warm run");
    assert_eq!(warm.1 .0, first.1 .1, "what was checked is reused");
}

#[test]
fn environment_variable_names_the_cache() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "row.obj", &row(&scene_cubes()));
    let o = bin(d.path()).args(SCENE).env("MESHCLASH_CACHE", "envcache").output().unwrap();
    assert_eq!(split(&text(&o)).1 .2, "envcache");
    assert!(d.path().join("envcache/CACHEDIR.TAG").is_file());
    let o = bin(d.path()).args(SCENE).env("MESHCLASH_CACHE", "").output().unwrap();
    assert!(!text(&o).contains("\"cache\""), "an empty variable is no cache");
}

#[test]
fn moved_part_gives_the_cold_report_of_the_edited_file() {
    let d = tempfile::tempdir().unwrap();
    let mut cubes = scene_cubes();
    write(d.path(), "row.obj", &row(&cubes));
    run_s(d.path(), &with(&SCENE, &["--cache", "c"]));
    // Move c so that it touches b exactly.
    cubes[2].1 = [1.5, 0.0, 0.0];
    write(d.path(), "row.obj", &row(&cubes));
    let cold = run_s(d.path(), &with(&SCENE, &[]));
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&SCENE, &["--cache", "c"])));
    assert_eq!(body, cold);
    // c's only candidate pair is (b, c): it alone is checked, (a, b) is reused.
    let n = candidates(&cold);
    assert_eq!((reused, checked), (n - 1, 1), "only the moved part's pairs are new keys");
    assert!(cold.contains("\"touching\""), "the move changed the answer");
}

/// A chain of `n` cubes, each overlapping the next by a quarter of an edge (candidate pairs: the
/// neighbours; with the clearance, none farther).
fn chain(n: usize) -> Vec<(String, [f64; 3])> {
    (0..n).map(|i| (format!("p{i}"), [i as f64 * 0.75, 0.0, 0.0])).collect()
}

fn chain_obj(cubes: &[(String, [f64; 3])]) -> String {
    cubes.iter().enumerate().map(|(i, (n, m))| cube(n, *m, 1.0, 8 * i)).collect()
}

#[test]
fn one_moved_part_checks_only_its_pairs() {
    let d = tempfile::tempdir().unwrap();
    let mut cubes = chain(7);
    let args = ["scene", "chain.obj", "--no-timings", "--clearance", "0.01"];
    write(d.path(), "chain.obj", &chain_obj(&cubes));
    let cold = run_s(d.path(), &with(&args, &[]));
    let n = candidates(&cold);
    assert_eq!(n, 6, "neighbours only");
    let first = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!((first.0, first.1 .0, first.1 .1), (cold, 0, n));
    // The middle cube moves a little (it still overlaps both neighbours): its two pairs are
    // new keys; every other pair, whose parts did not move, is reused.
    for (k, dy) in [(3, 0.125), (0, 0.25), (6, -0.0625)] {
        cubes[k].1[1] += dy;
        write(d.path(), "chain.obj", &chain_obj(&cubes));
        let cold = run_s(d.path(), &with(&args, &[]));
        let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
        assert_eq!(body, cold, "cube {k} moved");
        let own = if k == 0 || k == 6 { 1 } else { 2 };
        assert_eq!((reused, checked), (n - own, own), "cube {k} moved");
        // And again: nothing left to check.
        let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
        assert_eq!((body, reused, checked), (cold, n, 0), "cube {k} moved, warm");
    }
}

#[test]
fn selection_and_max_pairs_use_the_stored_pairs() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "chain.obj", &chain_obj(&chain(7)));
    let base = ["scene", "chain.obj", "--no-timings", "--clearance", "0.01"];
    run_s(d.path(), &with(&base, &["--cache", "c"]));
    // The listed-pair cut is applied after the pairs are merged: reused pairs are cut as
    // checked ones are.
    let cut = with(&base, &["--max-pairs", "3"]);
    let cold = run_s(d.path(), &cut);
    let mut cached = cut.clone();
    cached.extend(["--cache".to_string(), "c".to_string()]);
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &cached));
    assert_eq!(body, cold);
    assert_eq!((reused, checked), (6, 0));
}

#[test]
fn changed_setting_reuses_nothing() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "row.obj", &row(&scene_cubes()));
    run_s(d.path(), &with(&SCENE, &["--cache", "c"]));
    for extra in [
        &["--touch-tolerance", "0.01"][..],
        &["--leaf-size", "2"],
        &["--mode", "fast"],
        &["--detail", "parts"],
        &["--exclude", "d"],
        &["--penetration"],
    ] {
        let args = with(&SCENE, extra);
        let cold = run_s(d.path(), &args);
        let mut cached = args.clone();
        cached.extend(["--cache".to_string(), "c".to_string()]);
        let (body, (reused, _, _)) = split(&run_s(d.path(), &cached));
        assert_eq!(body, cold, "{extra:?}");
        assert_eq!(reused, 0, "{extra:?} changes the key");
    }
}

#[test]
fn corrupt_entry_is_ignored_with_a_warning_and_recomputed() {
    let d = tempfile::tempdir().unwrap();
    let file = write(d.path(), "row.obj", &row(&scene_cubes()));
    let cold = run_s(d.path(), &with(&SCENE, &[]));
    run_s(d.path(), &with(&SCENE, &["--cache", "c"]));
    let entries = |dir: &Path| {
        let mut v = Vec::new();
        for sub in std::fs::read_dir(dir).unwrap() {
            let sub = sub.unwrap().path();
            if sub.is_dir() {
                v.extend(std::fs::read_dir(&sub).unwrap().map(|e| e.unwrap().path()));
            }
        }
        v.sort();
        v
    };
    let found = entries(&d.path().join("c"));
    assert_eq!(found.len(), 2, "one run writes an index and a pack: {found:?}");
    // Each entry in turn: flipped in the middle, cut short, or replaced by the other's bytes
    // (a foreign entry: right layout, wrong key).
    for (i, how) in
        [(0, "flip"), (1, "flip"), (0, "truncate"), (1, "truncate"), (0, "foreign"), (1, "foreign")]
    {
        let found = entries(&d.path().join("c"));
        assert_eq!(found.len(), 2, "{how} {i}: {found:?}");
        let (p, other) = (&found[i], &found[1 - i]);
        let saved = std::fs::read(p).unwrap();
        let bad = match how {
            "flip" => {
                let mut b = saved.clone();
                let mid = b.len() / 2;
                b[mid] ^= 0x20;
                b
            }
            "truncate" => saved[..saved.len() - 3].to_vec(),
            _ => std::fs::read(other).unwrap(),
        };
        std::fs::write(p, bad).unwrap();
        // Through the library, where the warning is handed over.
        let mut req = meshclash::pipeline::Request::scene(&file);
        req.deterministic = true;
        req.clearance = meshclash::pipeline::Tolerance::Abs(0.1);
        req.cache = Some(meshclash::cache::CacheConfig {
            dir: d.path().join("c"),
            max_bytes: meshclash::cache::DEFAULT_MAX_BYTES,
        });
        let o = meshclash::pipeline::run(&req, &|_| {}).unwrap();
        assert_eq!(o.cache_warnings.len(), 1, "{how} {i}: {:?}", o.cache_warnings);
        assert!(o.cache_warnings[0].contains("ignored entry"), "{:?}", o.cache_warnings);
        assert_eq!(o.cache.as_ref().unwrap().part_pairs_reused, 0, "{how} {i}");
        // Recomputed and stored again: the binary now reuses it and writes the cold report.
        let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&SCENE, &["--cache", "c"])));
        assert_eq!(body, cold, "{how} {i}");
        assert_eq!((reused, checked), (candidates(&cold), 0), "{how} {i}");
    }
}

#[test]
fn concurrent_runs_share_one_directory() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "row.obj", &row(&scene_cubes()));
    let cold = run_s(d.path(), &with(&SCENE, &[]));
    let args = with(&SCENE, &["--cache", "c"]);
    let children: Vec<_> = (0..4)
        .map(|_| bin(d.path()).args(&args).stdout(std::process::Stdio::piped()).spawn().unwrap())
        .collect();
    for c in children {
        let o = c.wait_with_output().unwrap();
        assert!(matches!(o.status.code(), Some(0 | 1)));
        assert_eq!(split(&text(&o)).0, cold);
    }
    let (body, (_, checked, _)) = split(&run_s(d.path(), &args));
    assert_eq!((body, checked), (cold, 0));
}

#[test]
fn baseline_comparison_on_a_warm_run_equals_the_cold_one() {
    let d = tempfile::tempdir().unwrap();
    let mut cubes = scene_cubes();
    write(d.path(), "row.obj", &row(&cubes));
    let base = run(d.path(), &["scene", "row.obj", "--no-timings", "--clearance", "0.1", "-o", "base.json"]);
    assert!(base.stdout.is_empty());
    // The overlap goes away, a touch appears.
    cubes[1].1 = [1.0, 0.0, 0.0];
    cubes[2].1 = [2.0, 0.0, 0.0];
    write(d.path(), "row.obj", &row(&cubes));
    let args = with(&SCENE, &["--baseline", "base.json", "--fail-on", "never"]);
    let cold = run_s(d.path(), &args);
    assert!(cold.contains("\"resolved\""), "the baseline block is there");
    let mut cached = args.clone();
    cached.extend(["--cache".to_string(), "c".to_string()]);
    let first = split(&run_s(d.path(), &cached));
    let warm = split(&run_s(d.path(), &cached));
    assert_eq!(first.0, cold);
    assert_eq!(warm.0, cold, "a reused result compares as a checked one");
    assert_eq!(warm.1 .1, 0);
}

/// The report's closest pair: the objects and the distance.
fn closest_parts(report: &str) -> (u64, u64, f64) {
    let v: serde_json::Value = serde_json::from_str(report).unwrap();
    let c = &v["closest"];
    (c["a"]["object"].as_u64().unwrap(), c["b"]["object"].as_u64().unwrap(), c["distance"].as_f64().unwrap())
}

#[test]
fn closest_clear_pair_changes_when_one_part_moves_away() {
    let d = tempfile::tempdir().unwrap();
    // All apart, within the clearance: c-d are the closest (0.2), a-b next (0.5).
    let mut cubes =
        vec![("a", [0.0, 0.0, 0.0]), ("b", [1.5, 0.0, 0.0]), ("c", [5.0, 0.0, 0.0]), ("d", [6.2, 0.0, 0.0])];
    let args = ["scene", "row.obj", "--no-timings", "--clearance", "1"];
    write(d.path(), "row.obj", &row(&cubes));
    let cold = run_s(d.path(), &with(&args, &[]));
    assert_eq!(split(&run_s(d.path(), &with(&args, &["--cache", "c"]))).0, cold);
    // d moves away: the closest pair is now a-b, which did not change.
    cubes[3].1 = [9.0, 0.0, 0.0];
    write(d.path(), "row.obj", &row(&cubes));
    let cold_moved = run_s(d.path(), &with(&args, &[]));
    let before = closest_parts(&cold);
    let after = closest_parts(&cold_moved);
    assert_eq!((before.0, before.1), (2, 3), "c-d first: {before:?}");
    assert_eq!((after.0, after.1), (0, 1), "then a-b: {after:?}");
    assert!(before.2 < after.2, "{before:?} {after:?}");
    let warm = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!(warm.0, cold_moved);
    assert_eq!(closest_parts(&warm.0), after);
}

#[test]
fn engine_scene_warm_equals_cold() {
    let Some(engine) = crate::common::corpus("2CylinderEngine.glb") else { return };
    let d = tempfile::tempdir().unwrap();
    std::fs::copy(&engine, d.path().join("engine.glb")).unwrap();
    let args = ["scene", "engine.glb", "--no-timings", "--detail", "parts"];
    let cold = run_s(d.path(), &with(&args, &[]));
    let first = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    let warm = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!(first.0, cold);
    assert_eq!(warm.0, cold);
    assert_eq!((warm.1 .0, warm.1 .1), (candidates(&cold), 0));
}

#[test]
fn clash_set_checks_share_one_cache() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "row.obj", &row(&scene_cubes()));
    write(d.path(), "chain.obj", &chain_obj(&chain(5)));
    write(
        d.path(),
        "set.json",
        r#"{"version": 1, "checks": [
            {"name": "row", "scene": "row.obj", "clearance": "0.1"},
            {"name": "chain", "scene": "chain.obj", "clearance": "0.01"}]}"#,
    );
    let set = |cache: Option<&str>| {
        let mut c = bin(d.path());
        c.args(["clash-set", "set.json", "--no-timings"]);
        if let Some(dir) = cache {
            c.env("MESHCLASH_CACHE", dir);
        }
        let o = c.output().unwrap();
        assert!(matches!(o.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let strip = |mut v: serde_json::Value| {
        let mut blocks = Vec::new();
        for c in v["checks"].as_array_mut().unwrap() {
            let b = c["report"].as_object_mut().unwrap().remove("cache").expect("a cache block");
            blocks
                .push((b["part_pairs_reused"].as_u64().unwrap(), b["part_pairs_checked"].as_u64().unwrap()));
        }
        (v, blocks)
    };
    let cold = set(None);
    let (first, b1) = strip(set(Some("c")));
    let (warm, b2) = strip(set(Some("c")));
    assert_eq!(first, cold);
    assert_eq!(warm, cold);
    let n: Vec<u64> = cold["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["report"]["assembly"]["candidate_part_pairs"].as_u64().unwrap())
        .collect();
    assert_eq!(b1, vec![(0, n[0]), (0, n[1])]);
    assert_eq!(b2, vec![(n[0], 0), (n[1], 0)], "each check found its own results");
}

#[test]
fn sharded_runs_reuse_their_pairs_and_merge_to_the_cold_report() {
    let d = tempfile::tempdir().unwrap();
    let mut cubes = chain(7);
    write(d.path(), "chain.obj", &chain_obj(&cubes));
    let check = ["scene", "chain.obj", "--no-timings", "--clearance", "0.01"];
    let sharded = |cache: bool| {
        let mut plan = vec!["plan"];
        plan.extend(check);
        plan.extend(["-o", "plan.json"]);
        run(d.path(), &plan);
        let mut blocks = Vec::new();
        for i in 1..=3 {
            let shard = format!("{i}/3");
            let out = format!("shard-{i}.json");
            let mut c = bin(d.path());
            c.args(["run", "--plan", "plan.json", "--shard", &shard, "-o", &out]);
            if cache {
                c.env("MESHCLASH_CACHE", "c");
            }
            let o = c.output().unwrap();
            assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
            blocks.push(o);
        }
        let o = bin(d.path())
            .args(["merge", "shard-1.json", "shard-2.json", "shard-3.json", "-o", "merged.json"])
            .output()
            .unwrap();
        assert!(matches!(o.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(d.path().join("merged.json")).unwrap()
    };
    let cold = run_s(d.path(), &with(&check, &[]));
    assert_eq!(sharded(false), cold, "sharding changes nothing");
    assert_eq!(sharded(true), cold, "cold shards with the cache");
    // Every pair was stored by some shard: a single-machine run of the same check reuses all.
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&check, &["--cache", "c"])));
    assert_eq!((reused, checked), (candidates(&cold), 0), "the shards stored every pair");
    assert_eq!(body, cold);
    // One part moves: warm shards reuse the rest and still merge to the cold report.
    cubes[2].1[2] += 0.125;
    write(d.path(), "chain.obj", &chain_obj(&cubes));
    let cold = run_s(d.path(), &with(&check, &[]));
    assert_eq!(sharded(true), cold, "warm shards after a move");
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&check, &["--cache", "c"])));
    let n = candidates(&cold);
    assert_eq!((body, reused, checked), (cold, n, 0));
}

#[test]
fn clash_set_cache_flags_name_the_directory_and_bound_it() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("sets")).unwrap();
    write(d.path(), "sets/row.obj", &row(&scene_cubes()));
    write(
        d.path(),
        "sets/set.json",
        r#"{"version": 1, "checks": [{"name": "row", "scene": "row.obj", "clearance": "0.1"}]}"#,
    );
    let set = |extra: &[&str], env: Option<&str>| {
        let mut c = bin(d.path());
        c.args(["clash-set", "sets/set.json", "--no-timings"]).args(extra);
        if let Some(dir) = env {
            c.env("MESHCLASH_CACHE", dir);
        }
        let o = c.output().unwrap();
        assert!(matches!(o.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&o.stderr));
        let mut v = serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap();
        let block = v["checks"][0]["report"].as_object_mut().unwrap().remove("cache");
        let block = block.map(|b| {
            (
                b["part_pairs_reused"].as_u64().unwrap(),
                b["part_pairs_checked"].as_u64().unwrap(),
                b["dir"].as_str().unwrap().to_string(),
            )
        });
        (v, block, String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (cold, none, _) = set(&[], None);
    assert_eq!(none, None, "no block without a cache");
    let n = cold["checks"][0]["report"]["assembly"]["candidate_part_pairs"].as_u64().unwrap();
    // The flag names a directory relative to the working directory (not to the set's file),
    // and wins over the environment variable.
    let (first, b1, _) = set(&["--cache", "c"], Some("env"));
    let (warm, b2, _) = set(&["--cache", "c"], Some("env"));
    assert_eq!((&first, &warm), (&cold, &cold));
    assert_eq!(b1, Some((0, n, "c".to_string())));
    assert_eq!(b2, Some((n, 0, "c".to_string())));
    assert!(d.path().join("c/CACHEDIR.TAG").is_file());
    assert!(!d.path().join("env").exists() && !d.path().join("sets/c").exists());
    // A bound below one entry: nothing is stored (one warning), so nothing is reused.
    let (tiny, b3, err) = set(&["--cache", "tiny", "--cache-max-bytes", "64"], None);
    let (again, b4, _) = set(&["--cache", "tiny", "--cache-max-bytes", "64"], None);
    assert_eq!((&tiny, &again), (&cold, &cold));
    assert_eq!((b3, b4), (Some((0, n, "tiny".to_string())), Some((0, n, "tiny".to_string()))));
    assert!(err.contains("entry limit"), "{err}");
    // A bad bound is a usage error naming the flag.
    let o = bin(d.path()).args(["clash-set", "sets/set.json", "--cache-max-bytes", "x"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--cache-max-bytes"));
}

/// A regular octahedron of radius `r` at `c`, as OBJ lines (vertices numbered from `base`):
/// its box reaches further than its faces, so two of them can be a candidate pair (their boxes
/// overlap) and still be clear.
fn octahedron(name: &str, c: [f64; 3], r: f64, base: usize) -> String {
    let mut out = format!("o {name}\n");
    let axes = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    for a in axes {
        out += &format!("v {} {} {}\n", c[0] + r * a[0], c[1] + r * a[1], c[2] + r * a[2]);
    }
    // +x 1, -x 2, +y 3, -y 4, +z 5, -z 6 (one-based, before `base`), wound outwards.
    let faces = [[1, 3, 5], [3, 2, 5], [2, 4, 5], [4, 1, 5], [3, 1, 6], [2, 3, 6], [4, 2, 6], [1, 4, 6]];
    for f in faces {
        out += &format!("f {} {} {}\n", f[0] + base, f[1] + base, f[2] + base);
    }
    out
}

/// Octahedra of radius 1 along the xy diagonal, each `gaps[i]` further than touching its
/// predecessor (touching: centres 1 apart along x and y).
fn diagonal(gaps: &[f64], order: &[usize]) -> String {
    let mut at = 0.0;
    let mut centres = vec![[0.0, 0.0, 0.0]];
    for g in gaps {
        at += 1.0 + g;
        centres.push([at, at, 0.0]);
    }
    order.iter().enumerate().map(|(k, &i)| octahedron(&format!("o{i}"), centres[i], 1.0, 6 * k)).collect()
}

#[test]
fn clear_scene_warm_run_searches_nothing_and_keeps_the_closest_pair() {
    let d = tempfile::tempdir().unwrap();
    let args = ["scene", "diag.obj", "--no-timings"];
    let step = |gaps: &[f64], order: &[usize]| {
        write(d.path(), "diag.obj", &diagonal(gaps, order));
        let cold = run_s(d.path(), &with(&args, &[]));
        let v: serde_json::Value = serde_json::from_str(&cold).unwrap();
        assert_eq!(v["verdict"], "clear", "{cold}");
        assert!(closest_parts(&cold).2 > 0.0);
        let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
        assert_eq!(body, cold, "gaps {gaps:?}, order {order:?}");
        // Nothing changed since: every pair is reused and none is searched again.
        let (again, counts) = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
        assert_eq!(again, cold, "warm, gaps {gaps:?}, order {order:?}");
        let n = candidates(&cold);
        assert_eq!((counts.0, counts.1), (n, 0), "warm, gaps {gaps:?}, order {order:?}");
        (reused, checked, n)
    };
    let order: Vec<usize> = (0..6).collect();
    let mut gaps = vec![0.5, 0.25, 0.75, 0.375, 0.625];
    let (_, checked, n) = step(&gaps, &order);
    assert_eq!(n, 5, "neighbours only: their boxes overlap, their faces do not meet");
    assert_eq!(checked, n, "cold");
    // The closest pair (o1-o2) moves apart: o3-o4 becomes the closest, a reused pair that must
    // be searched again or be proven by its stored bound.
    gaps[1] = 0.875;
    step(&gaps, &order);
    // One pair comes closer than every other.
    gaps[3] = 0.125;
    step(&gaps, &order);
    // Ties: every neighbour pair at one distance (the lowest triangle numbers win), then the
    // file's parts in another order (the triangle numbering changes, the parts do not).
    let even = vec![0.5; 5];
    step(&even, &order);
    let (reused, checked, n) = step(&even, &[5, 4, 3, 2, 1, 0]);
    assert_eq!(reused + checked, n);
    step(&even, &[2, 0, 4, 1, 5, 3]);
}

#[test]
fn reused_overlap_boxes_equal_the_cold_report_also_after_a_move() {
    let d = tempfile::tempdir().unwrap();
    let mut cubes = chain(5);
    let args = ["scene", "chain.obj", "--no-timings", "--clearance", "0.01"];
    write(d.path(), "chain.obj", &chain_obj(&cubes));
    let cold = run_s(d.path(), &with(&args, &[]));
    let boxes = |r: &str| {
        let v: serde_json::Value = serde_json::from_str(r).unwrap();
        v["part_pairs"].as_array().unwrap().iter().filter(|pp| pp["overlap"].is_object()).count()
    };
    let n = candidates(&cold);
    assert_eq!(boxes(&cold), n as usize, "every neighbour pair has its overlap box");
    run_s(d.path(), &with(&args, &["--cache", "c"]));
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!((body.as_str(), reused, checked), (cold.as_str(), n, 0));
    // The middle cube grows into its neighbours: its two boxes change, the others are reused.
    cubes[2].1[0] -= 0.125;
    write(d.path(), "chain.obj", &chain_obj(&cubes));
    let cold2 = run_s(d.path(), &with(&args, &[]));
    assert_ne!(cold2, cold);
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!((body.as_str(), reused, checked), (cold2.as_str(), n - 2, 2));
    assert_eq!(boxes(&body), n as usize);
}

#[test]
fn a_model_saved_under_another_name_reuses_its_pairs() {
    let d = tempfile::tempdir().unwrap();
    let args = |f: &str| with(&["scene", f, "--no-timings", "--clearance", "0.01"], &["--cache", "c"]);
    write(d.path(), "chain.obj", &chain_obj(&chain(5)));
    let first = split(&run_s(d.path(), &args("chain.obj")));
    let n = candidates(&first.0);
    assert_eq!((first.1 .0, first.1 .1), (0, n));
    std::fs::create_dir(d.path().join("elsewhere")).unwrap();
    std::fs::rename(d.path().join("chain.obj"), d.path().join("elsewhere/renamed.obj")).unwrap();
    let cold = run_s(
        d.path(),
        &with(&["scene", "elsewhere/renamed.obj", "--no-timings", "--clearance", "0.01"], &[]),
    );
    let (body, (reused, checked, _)) = split(&run_s(d.path(), &args("elsewhere/renamed.obj")));
    assert_eq!((body.as_str(), reused, checked), (cold.as_str(), n, 0), "the index is found by content");
}

/// `glb` with the JSON chunk edited by `edit` (the binary chunk kept as it is).
fn edit_glb(glb: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let u32_at = |i: usize| u32::from_le_bytes(glb[i..i + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let mut json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    edit(&mut json);
    let mut text = serde_json::to_vec(&json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let rest = &glb[20 + json_len..];
    let mut out = Vec::new();
    out.extend(&glb[..8]);
    out.extend(((20 + text.len() + rest.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(&glb[16..20]);
    out.extend(&text);
    out.extend(rest);
    out
}

#[test]
fn moved_instance_of_a_gltf_mesh_checks_its_pairs_and_gives_the_cold_report() {
    let Some(engine) = crate::common::corpus("2CylinderEngine.glb") else { return };
    let d = tempfile::tempdir().unwrap();
    let glb = std::fs::read(&engine).unwrap();
    std::fs::write(d.path().join("engine.glb"), &glb).unwrap();
    let args = ["scene", "engine.glb", "--no-timings", "--clearance", "0.5"];
    let cold = run_s(d.path(), &with(&args, &[]));
    let first = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!(first.0, cold);
    // Move one node that draws a mesh other nodes draw too: its instances share their shape,
    // the moved one has new coordinates.
    let moved = edit_glb(&glb, |json| {
        let nodes = json["nodes"].as_array_mut().unwrap();
        let mut drawn = std::collections::HashMap::new();
        for n in nodes.iter() {
            if let Some(m) = n["mesh"].as_u64() {
                *drawn.entry(m).or_insert(0) += 1;
            }
        }
        let node = nodes
            .iter_mut()
            .find(|n| n["mesh"].as_u64().is_some_and(|m| drawn[&m] > 1) && n["matrix"].is_array())
            .expect("an instanced node placed by a matrix");
        let y = node["matrix"][13].as_f64().unwrap();
        node["matrix"][13] = serde_json::json!(y + 0.25);
    });
    std::fs::write(d.path().join("engine.glb"), &moved).unwrap();
    let cold_moved = run_s(d.path(), &with(&args, &[]));
    assert_ne!(cold_moved, cold, "the move changed the report");
    let warm = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!(warm.0, cold_moved);
    let (reused, checked) = (warm.1 .0, warm.1 .1);
    assert_eq!(reused + checked, candidates(&cold_moved));
    assert!(
        checked > 0 && reused > checked,
        "only the moved part's pairs are checked: {reused} reused, {checked} checked"
    );
    let again = split(&run_s(d.path(), &with(&args, &["--cache", "c"])));
    assert_eq!((again.0, again.1 .1), (cold_moved, 0));
}

/// The deterministic report of `req` run instanced (`expanded` false: asserting that it takes
/// the instanced path) or expanded.
fn report_of(req: &meshclash::pipeline::Request, expanded: bool) -> String {
    use meshclash::pipeline;
    let name = req.inputs[0].path().display().to_string();
    let o = if expanded {
        pipeline::run_expanded(req, &|_| {}).unwrap()
    } else {
        assert!(pipeline::instanced_path(req), "{name}: takes the instanced path");
        pipeline::run(req, &|_| {}).unwrap()
    };
    assert_eq!(o.inputs[0].instanced.is_some(), !expanded, "{name}");
    serde_json::to_string_pretty(&pipeline::report::build(&o)).unwrap()
}

/// A scene run instanced with the cache, cold then warm, gives the report of an instanced run
/// without it, and shares its entries with an expanded run both ways.
fn instanced_and_expanded_share_the_cache(file: &Path, detail: meshclash::check::query::Detail) {
    use meshclash::cache::{CacheConfig, DEFAULT_MAX_BYTES};
    use meshclash::pipeline::{Request, Tolerance};
    let name = file.display().to_string();
    let d = tempfile::tempdir().unwrap();
    let request = |cache: Option<&str>| {
        let mut req = Request::scene(file);
        req.settings.detail = detail;
        req.clearance = Tolerance::Rel(0.002);
        req.deterministic = true;
        req.cache = cache.map(|c| CacheConfig { dir: d.path().join(c), max_bytes: DEFAULT_MAX_BYTES });
        req
    };
    let plain = report_of(&request(None), false);
    let n = candidates(&plain);
    let dir = |c: &str| d.path().join(c).display().to_string();
    // Instanced cold, instanced warm, then expanded warm on the same entries.
    for (expanded, counts) in [(false, (0, n)), (false, (n, 0)), (true, (n, 0))] {
        let (body, got) = split(&report_of(&request(Some("i")), expanded));
        assert_eq!(body, plain, "{name}: expanded {expanded}");
        assert_eq!(got, (counts.0, counts.1, dir("i")), "{name}: expanded {expanded}");
    }
    // Expanded cold, then instanced warm on its entries.
    for (expanded, counts) in [(true, (0, n)), (false, (n, 0))] {
        let (body, got) = split(&report_of(&request(Some("e")), expanded));
        assert_eq!(body, plain, "{name}: expanded {expanded}");
        assert_eq!(got, (counts.0, counts.1, dir("e")), "{name}: expanded {expanded}");
    }
}

#[test]
fn instanced_scene_with_the_cache_equals_the_run_without_and_shares_entries_with_expanded_runs() {
    use meshclash::check::query::Detail;
    let mut files: Vec<PathBuf> = ["Box.glb", "SimpleMeshes.gltf", "pins.glb", "simple_pole.glb"]
        .iter()
        .map(|n| crate::common::shared(n))
        .collect();
    files.extend(crate::common::corpus("2CylinderEngine.glb"));
    for file in &files {
        for detail in [Detail::Pairs, Detail::Parts] {
            instanced_and_expanded_share_the_cache(file, detail);
        }
    }
}
