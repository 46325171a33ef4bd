//! `meshclash bench --sizes 2k --trade` through the real binary: the tables have the expected
//! rows, and every approximate-distance error is within its guaranteed bound.

use assert_cmd::Command;

#[test]
fn bench_small_with_trade() {
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .args(["bench", "--sizes", "2k", "--trade", "--json"])
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> =
        v["inputs"].as_array().unwrap().iter().map(|i| i["name"].as_str().unwrap()).collect();
    for want in ["coplanar grids at 1e8", "torus vs 1-ulp shift", "tori crossing 2k", "tori apart 2k"] {
        assert!(names.iter().any(|n| n.starts_with(want)), "missing input {want}: {names:?}");
    }
    for i in v["inputs"].as_array().unwrap() {
        let name = i["name"].as_str().unwrap();
        assert!(i["meshclash"]["build_ms"].as_f64().unwrap() >= 0.0);
        assert!(i["parry_f64"]["pairs_ms"].as_f64().is_some(), "{name}");
        assert!(i["parry_f32"]["pairs_ms"].as_f64().is_some(), "{name}");
        assert!(i["layouts"]["agree"].as_bool().unwrap(), "{name}: stack and stackless walks disagree");
        assert_eq!(i["scaling"].as_array().unwrap().len(), 2);
        if name.starts_with("tori crossing") {
            assert_eq!(i["verdict"], "clash");
            assert!(i["crossing"].as_u64().unwrap() > 0);
            // Clear-cut crossings of unit-size triangles: parry f64 agrees exactly.
            assert_eq!(i["parry_f64"]["false_pairs"], 0);
            assert_eq!(i["parry_f64"]["missed_pairs"], 0);
        }
        if name.starts_with("tori apart") {
            assert_eq!(i["verdict"], "clear");
            let d = i["meshclash"]["distance"].as_f64().unwrap();
            assert!((d - 0.3).abs() < 0.01, "{d}");
        }
    }
    let trade = v["trade"].as_array().unwrap();
    assert_eq!(trade.len(), names.len());
    let mut distance_rows = 0;
    for t in trade {
        let modes: Vec<&str> =
            t["rows"].as_array().unwrap().iter().map(|r| r["mode"].as_str().unwrap()).collect();
        for want in [
            "exact (default)",
            "--mode fast",
            "--first-hit",
            "--bvh sah --leaf-size 4",
            "--bvh median --leaf-size 16",
            "--bvh equal --leaf-size 1",
        ] {
            assert!(modes.contains(&want), "{}: no row {want}: {modes:?}", t["input"]);
        }
        for r in t["rows"].as_array().unwrap() {
            let mode = r["mode"].as_str().unwrap();
            if mode.starts_with("--bvh") {
                // Tree shape never changes the answer.
                assert_eq!(r["false_pairs"], 0, "{mode}");
                assert_eq!(r["missed_pairs"], 0, "{mode}");
                assert_eq!(r["kind_changes"], 0, "{mode}");
            }
            if mode.starts_with("distance") {
                distance_rows += 1;
                let (e, b) = (r["distance_error"].as_f64().unwrap(), r["bound"].as_f64().unwrap());
                assert!(
                    r["within_bound"].as_bool().unwrap(),
                    "{}: {mode}: error {e} > bound {b}",
                    t["input"]
                );
                assert!(e >= 0.0 && e <= b * (1.0 + 1e-12) + 1e-12, "{mode}: {e} vs {b}");
            }
        }
    }
    assert!(distance_rows >= 5, "the apart input must have approximate-distance rows");
}

#[test]
fn bench_table_output_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("trade.svg");
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .args(["bench", "--sizes", "1k", "--threads", "2", "--plot"])
        .arg(&plot)
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    for want in [
        "### Time per phase",
        "### Answers",
        "### Memory",
        "### Node layouts",
        "### Parallel scaling",
        "### Speed/accuracy trade: tori apart 1k",
        "| --mode fast",
        "| distance rel=0.1",
    ] {
        assert!(text.contains(want), "missing {want:?} in\n{text}");
    }
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("--mode fast"));
}

#[test]
fn bench_rejects_bad_sizes() {
    Command::cargo_bin("meshclash").unwrap().args(["bench", "--sizes", "lots"]).assert().code(2);
}
