//! Part-pair results through the real binary on constructed assemblies: verdict, counts,
//! minimum distance with witness points, and each pair's triangle pairs capped with a flag.

use crate::common::boxes_obj_text as boxes_obj;
use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn run(args: &[&str]) -> (i32, Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_meshclash")).args(args).arg("--no-timings").output().unwrap();
    let code = out.status.code().unwrap();
    assert!(code < 2, "{}", String::from_utf8_lossy(&out.stderr));
    (code, serde_json::from_slice(&out.stdout).unwrap())
}

fn pair<'a>(r: &'a Value, a: &str, b: &str) -> &'a Value {
    r["part_pairs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["a_name"] == a && p["b_name"] == b)
        .unwrap_or_else(|| panic!("no part pair {a} / {b} in {}", r["part_pairs"]))
}

const A: (&str, [f64; 3], [f64; 3]) = ("A", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
const B: (&str, [f64; 3], [f64; 3]) = ("B", [0.5, 0.25, 0.25], [1.5, 0.75, 0.75]); // pokes through A's face x = 1
const C: (&str, [f64; 3], [f64; 3]) = ("C", [3.0, 0.0, 0.0], [4.0, 1.0, 1.0]); // 1.5 beyond B, 2 beyond A

#[test]
fn scene_part_pairs_carry_witnesses_and_capped_pairs() {
    let dir = std::env::temp_dir().join(format!("meshclash-pp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("abc.obj");
    std::fs::write(&f, boxes_obj(&[A, B, C])).unwrap();
    let p = f.to_str().unwrap();
    let (code, r) = run(&["scene", p, "--clearance", "2.5", "--max-pairs", "3"]);
    assert_eq!(code, 1);
    assert_eq!(r["part_pairs"].as_array().unwrap().len(), 3);
    // A and B cross; the witness is a shared point, on both parts' boxes.
    let ab = pair(&r, "A", "B");
    assert_eq!(ab["verdict"], "clash");
    assert_eq!(ab["min_distance"], 0.0);
    assert_eq!(ab["closest"]["a"]["point"], ab["closest"]["b"]["point"]);
    let listed = ab["pairs"].as_array().unwrap();
    let total = ab["crossing_pairs"].as_u64().unwrap() + ab["touching_pairs"].as_u64().unwrap();
    assert!(total > 3, "B's four side faces each cross A's face x = 1");
    assert_eq!((listed.len(), ab["pairs_truncated"].as_bool().unwrap()), (3, true));
    // Listed pairs: sorted, A's triangles 0..12 against B's 12..24 (file order).
    let idx: Vec<(u64, u64)> =
        listed.iter().map(|x| (x[0].as_u64().unwrap(), x[1].as_u64().unwrap())).collect();
    assert!(idx.windows(2).all(|w| w[0] < w[1]));
    assert!(idx.iter().all(|&(a, b)| a < 12 && (12..24).contains(&b)), "{idx:?}");
    // B and C: clearance, exactly 1.5 (B's face x = 1.5 against C's face x = 3).
    let bc = pair(&r, "B", "C");
    assert_eq!(bc["verdict"], "clearance");
    assert_eq!(bc["min_distance"], 1.5);
    assert_eq!(bc["closest"]["distance"], 1.5);
    assert_eq!(bc["closest"]["a"]["point"][0], 1.5);
    assert_eq!(bc["closest"]["b"]["point"][0], 3.0);
    assert_eq!(bc["closest"]["a"]["object"], 1);
    assert_eq!(bc["closest"]["b"]["object"], 2);
    let n = bc["clearance_pairs"].as_u64().unwrap() as usize;
    assert_eq!(bc["pairs"].as_array().unwrap().len(), n.min(3));
    assert_eq!(bc["pairs_truncated"], n > 3);
    // A and C: 2 apart.
    assert_eq!(pair(&r, "A", "C")["min_distance"], 2.0);
    // Uncapped, every part pair lists all its pairs.
    let (_, full) = run(&["scene", p, "--clearance", "2.5"]);
    for pp in full["part_pairs"].as_array().unwrap() {
        let n = ["crossing_pairs", "touching_pairs", "clearance_pairs"]
            .map(|k| pp[k].as_u64().unwrap())
            .iter()
            .sum::<u64>();
        assert_eq!(pp["pairs"].as_array().unwrap().len() as u64, n);
        assert_eq!(pp["pairs_truncated"], false);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn file_mode_part_pairs_have_witnesses_from_their_pairs() {
    let dir = std::env::temp_dir().join(format!("meshclash-ppf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (fa, fb) = (dir.join("ac.obj"), dir.join("b.obj"));
    std::fs::write(&fa, boxes_obj(&[A, C])).unwrap();
    std::fs::write(&fb, boxes_obj(&[B])).unwrap();
    let (code, r) = run(&[fa.to_str().unwrap(), fb.to_str().unwrap(), "--clearance", "2.5"]);
    assert_eq!(code, 1);
    assert_eq!(r["assembly"]["mode"], "files");
    let cb = pair(&r, "C", "B");
    assert_eq!(cb["verdict"], "clearance");
    assert_eq!(cb["min_distance"], 1.5);
    assert_eq!(cb["closest"]["a"]["point"][0], 3.0);
    assert_eq!(cb["closest"]["b"]["point"][0], 1.5);
    assert!(Path::new(&fa).exists());
    let ab = pair(&r, "A", "B");
    assert_eq!((ab["verdict"].as_str(), ab["min_distance"].as_f64()), (Some("clash"), Some(0.0)));
    std::fs::remove_dir_all(&dir).ok();
}

/// The report with every triangle-pair list and every region removed (what `--detail parts`
/// keeps), plus the settings block without `detail`.
fn without_lists(mut r: Value) -> Value {
    r["pairs"] = Value::Array(vec![]);
    r["pairs_truncated"] = Value::Null;
    r["regions"] = Value::Array(vec![]);
    r.as_object_mut().unwrap().remove("unlisted");
    r["settings"].as_object_mut().unwrap().remove("detail");
    for p in r["part_pairs"].as_array_mut().unwrap() {
        p["pairs"] = Value::Array(vec![]);
        p["pairs_truncated"] = Value::Null;
    }
    r
}

#[test]
fn detail_parts_keeps_every_verdict_count_and_witness_and_drops_only_the_lists() {
    let Some(engine) = crate::common::corpus("2CylinderEngine.glb") else { return };
    let dir = std::env::temp_dir().join(format!("meshclash-detail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let boxes = dir.join("boxes.obj");
    std::fs::write(&boxes, boxes_obj(&[A, B, C])).unwrap();
    let (e, b) = (engine.to_str().unwrap(), boxes.to_str().unwrap());
    for case in
        [vec!["scene", e], vec!["scene", b], vec![b, b, "--split-bodies"], vec!["scene", e, "--threads", "1"]]
    {
        let (code_full, full) = run(&case);
        let parts_args: Vec<&str> = case.iter().copied().chain(["--detail", "parts"]).collect();
        let (code_parts, parts) = run(&parts_args);
        assert_eq!(code_full, code_parts, "{case:?}");
        assert_eq!(parts["settings"]["detail"], "parts");
        assert!(full["settings"].get("detail").is_none(), "the default report has no detail field");
        assert_eq!(parts["pairs"].as_array().unwrap().len(), 0);
        assert_eq!(parts["regions"].as_array().unwrap().len(), 0);
        let found = full["summary"]["crossing_pairs"].as_u64().unwrap()
            + full["summary"]["touching_pairs"].as_u64().unwrap()
            + full["summary"]["clearance_pairs"].as_u64().unwrap();
        assert_eq!(parts["pairs_truncated"], found > 0, "{case:?}");
        for p in parts["part_pairs"].as_array().unwrap() {
            assert!(p["pairs"].as_array().unwrap().is_empty());
            let n = p["crossing_pairs"].as_u64().unwrap() + p["touching_pairs"].as_u64().unwrap();
            assert_eq!(p["pairs_truncated"], n > 0 || p["clearance_pairs"].as_u64().unwrap() > 0);
        }
        assert!(!full["part_pairs"].as_array().unwrap().is_empty() || case[1] == b, "{case:?}");
        assert_eq!(without_lists(full), without_lists(parts), "{case:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn detail_parts_refuses_the_outputs_that_need_triangle_pairs() {
    let dir = std::env::temp_dir().join(format!("meshclash-detail-refuse-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let boxes = dir.join("boxes.obj");
    std::fs::write(&boxes, boxes_obj(&[A, B])).unwrap();
    let out_html = dir.join("r.html");
    for (flag, value) in
        [("--html", out_html.to_str().unwrap()), ("--export-glb", "r.glb"), ("--bcf", "r.bcfzip")]
    {
        let out = Command::new(env!("CARGO_BIN_EXE_meshclash"))
            .args(["scene", boxes.to_str().unwrap(), "--detail", "parts", flag, value])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{flag}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flag) && err.contains("--detail parts"), "{flag}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    assert!(!out_html.exists(), "nothing is written on a usage error");
    // Part-pair BCF topics need no triangle pairs.
    let bcf = dir.join("r.bcfzip");
    let out = Command::new(env!("CARGO_BIN_EXE_meshclash"))
        .args(["scene", boxes.to_str().unwrap(), "--detail", "parts", "--bcf-topics", "part-pairs", "--bcf"])
        .arg(&bcf)
        .args(["-o", dir.join("r.json").to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(bcf.exists());
    std::fs::remove_dir_all(&dir).ok();
}
