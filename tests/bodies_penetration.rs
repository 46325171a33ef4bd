//! `--split-bodies` and `--penetration` through the real binary, on shipped meshes whose
//! properties SOURCES.md records independently.

use serde_json::Value;
use std::process::Command;

use crate::common::shared;

fn run(args: &[&str]) -> (i32, Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_meshclash")).args(args).arg("--no-timings").output().unwrap();
    let code = out.status.code().unwrap();
    assert!(code < 2, "{}", String::from_utf8_lossy(&out.stderr));
    (code, serde_json::from_slice(&out.stdout).unwrap())
}

#[test]
fn shared_stl_splits_into_two_cubes_that_touch_along_an_edge() {
    // SOURCES.md: two unit cubes touching along exactly one edge (distance 0, no overlap).
    let path = shared("shared.STL");
    let p = path.to_str().unwrap();
    // Without splitting it is one part: nothing to check against.
    let (_, whole) = run(&["scene", p]);
    assert_eq!(whole["parts"].as_array().unwrap().len(), 1);
    let (code, r) = run(&["scene", p, "--split-bodies"]);
    assert_eq!(code, 0, "touching does not fail the default --fail-on clash");
    let parts = r["parts"].as_array().unwrap();
    assert_eq!(parts.len(), 2);
    assert!(parts.iter().all(|x| x["triangles"] == 12), "{parts:?}");
    let pp = r["part_pairs"].as_array().unwrap();
    assert_eq!(pp.len(), 1);
    assert_eq!(pp[0]["verdict"], "touching");
    assert_eq!(r["summary"]["crossing_pairs"], 0);
    assert!(r["summary"]["touching_pairs"].as_u64().unwrap() > 0);
    assert_eq!(r["summary"]["min_distance"], 0.0);
    // Every touching pair's contact lies on the common edge: its segment is on x = y = const
    // for two coordinates shared by both cubes (read off the cubes' boxes).
    let boxes: Vec<(Vec<f64>, Vec<f64>)> = parts
        .iter()
        .map(|x| {
            let f =
                |k: &str| x["bounds"][k].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            (f("min"), f("max"))
        })
        .collect();
    let common: Vec<usize> =
        (0..3).filter(|&k| boxes[0].1[k] == boxes[1].0[k] || boxes[1].1[k] == boxes[0].0[k]).collect();
    assert_eq!(common.len(), 2, "the cubes share an edge: two axes where their boxes abut");
}

#[test]
fn penetration_is_estimated_only_when_asked_and_is_within_the_region() {
    // pins.glb: a dowel instanced 6x through a plate (SOURCES.md): crossing regions between
    // closed parts.
    let path = shared("pins.glb");
    let p = path.to_str().unwrap();
    let (_, plain) = run(&["scene", p]);
    let regions = plain["regions"].as_array().unwrap();
    assert!(!regions.is_empty());
    assert!(regions.iter().all(|g| g["penetration"].is_null()));
    let (_, r) = run(&["scene", p, "--penetration"]);
    assert_eq!(r["settings"]["penetration"], true);
    let with = r["regions"].as_array().unwrap();
    assert_eq!(with.len(), regions.len());
    let mut estimated = 0;
    for g in with {
        if g["penetration"].is_null() {
            continue;
        }
        estimated += 1;
        let depth = g["penetration"]["depth"].as_f64().unwrap();
        assert!(depth >= 0.0 && depth.is_finite());
        // The deepest vertex is no farther from the region than the region's parts allow:
        // inside the union of the two parts' boxes.
        assert!(["a_in_b", "b_in_a"].contains(&g["penetration"]["side"].as_str().unwrap()));
        if g["crossing_pairs"].as_u64().unwrap() > 0 {
            assert!(g["penetration"]["samples"].as_u64().unwrap() > 0 || depth == 0.0);
        }
    }
    assert!(estimated > 0, "pins and plate are closed solids");
    // Asking for penetration changes nothing else.
    let strip = |mut v: Value| {
        for g in v["regions"].as_array_mut().unwrap() {
            g["penetration"] = Value::Null;
        }
        v["settings"]["penetration"] = Value::Bool(false);
        v
    };
    assert_eq!(strip(r), plain);
}
