//! `meshclash-bench --sizes 2k --trade` through the real binary: the tables have the expected
//! rows, and every approximate-distance error is within its guaranteed bound.

use assert_cmd::Command;

#[test]
fn bench_small_with_trade() {
    let out = Command::cargo_bin("meshclash-bench")
        .unwrap()
        .args(["--sizes", "2k", "--trade", "--json"])
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
    let out = Command::cargo_bin("meshclash-bench")
        .unwrap()
        .args(["--sizes", "1k", "--threads", "2", "--plot"])
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
    Command::cargo_bin("meshclash-bench").unwrap().args(["--sizes", "lots"]).assert().code(2);
}

/// `gen` at small sizes writes every input, and `cases` runs them all in one process with parry
/// beside meshclash; the answers are the geometry's (crossing tori clash, apart tori are about
/// 0.1 apart, linked tori about 0.5 apart).
#[test]
fn gen_and_cases_small() {
    let dir = tempfile::tempdir().unwrap();
    let engine = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../meshes/pins.glb");
    let out = Command::cargo_bin("meshclash-bench")
        .unwrap()
        .args(["gen", "--sphere-subdivisions", "2", "--torus-segments", "24", "--engine"])
        .arg(&engine)
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    for f in [
        "spheres_a.obj",
        "spheres_b.obj",
        "torus_a.glb",
        "torus_b_crossing.glb",
        "torus_b_apart.glb",
        "torus_b_linked.glb",
        "engine.glb",
        "engine_grid100.glb",
    ] {
        assert!(dir.path().join(f).is_file(), "{f} not written");
    }
    let out = Command::cargo_bin("meshclash-bench")
        .unwrap()
        .args(["cases", "--json", "--parry-distance", "all"])
        .arg(dir.path())
        .timeout(std::time::Duration::from_secs(300))
        .output()
        .unwrap();
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let cases = v["cases"].as_array().unwrap();
    let by_name = |n: &str| cases.iter().find(|c| c["name"] == n).unwrap_or_else(|| panic!("no case {n}"));
    for n in ["spheres", "tori-crossing", "tori-apart", "tori-linked"] {
        let c = by_name(n);
        assert_eq!(c["triangles"][0], c["triangles"][1], "{n}");
        // What the CLI runs, timed through the library's pipeline (its verdict checked there).
        assert!(c["meshclash"]["pipeline_ms"].as_f64().is_some(), "{n}: {c}");
        for tool in ["meshclash", "parry_f64", "parry_f32"] {
            assert!(c[tool]["build_ms"].as_f64().is_some(), "{n} {tool}: {c}");
            assert!(c[tool]["pairs_ms"].as_f64().is_some(), "{n} {tool}: {c}");
            assert!(c[tool]["distance_ms"].as_f64().is_some(), "{n} {tool}: {c}");
        }
    }
    assert_eq!(by_name("spheres")["triangles"][0], 320);
    assert_eq!(by_name("tori-crossing")["triangles"][0], 2 * 24 * 24);
    for n in ["spheres", "tori-crossing"] {
        assert_eq!(by_name(n)["verdict"], "clash", "{n}");
        assert!(by_name(n)["meshclash"]["pairs"].as_u64().unwrap() > 0);
        assert_eq!(by_name(n)["meshclash"]["distance"], 0.0);
    }
    let d = |n: &str| by_name(n)["meshclash"]["distance"].as_f64().unwrap();
    // Coarse tessellation (24 segments): facets and chords of the major circle move the gaps by
    // up to a few percent, the f32 rounding of the positions by ~1e-8.
    assert!(d("tori-apart") > 0.0999 && d("tori-apart") < 0.12, "{}", d("tori-apart"));
    assert!(d("tori-linked") > 0.45 && d("tori-linked") < 0.55, "{}", d("tori-linked"));
    for n in ["tori-apart", "tori-linked"] {
        let p = by_name(n)["parry_f64"]["distance"].as_f64().unwrap();
        assert!((p - d(n)).abs() < 1e-6 * d(n), "{n}: parry {p} vs {}", d(n));
    }
    for n in ["engine", "engine-grid100"] {
        assert!(by_name(n)["meshclash"]["check_ms"].as_f64().is_some(), "{n}");
    }
    // The grid has 100 copies of the file's parts.
    let parts = |n: &str| -> u64 {
        let note = by_name(n)["meshclash"]["note"].as_str().unwrap().to_string();
        note.trim_start_matches("scene mode, ").trim_end_matches(" parts").parse().unwrap()
    };
    assert_eq!(parts("engine-grid100"), 100 * parts("engine"));

    let text = Command::cargo_bin("meshclash-bench")
        .unwrap()
        .args(["cases", "--only", "tori-apart", "--no-parry"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(text.status.success());
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("### tori-apart") && !text.contains("### spheres"), "{text}");
}

#[test]
fn cases_rejects_unknown_case_and_empty_dir() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = Command::cargo_bin("meshclash-bench").unwrap().args(args).arg(dir.path()).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (code, err) = run(&["cases", "--only", "bunnies"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("no case 'bunnies'"), "{err}");
    let (code, err) = run(&["cases"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("meshclash-bench gen"), "{err}");
}

/// `meshclash-bench self` through the real binary: the folded torus's phases are timed and its
/// answer is the fold's crossing pairs; the bunny (open, no self-clash) is clear.
#[test]
fn self_case_times_the_phases_and_gives_the_answer() {
    let bunny =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes/stanford-bunny.obj");
    let out = Command::cargo_bin("meshclash-bench")
        .unwrap()
        .args(["self", "--triangles", "20k", "--reps", "1", "--json", "--mesh"])
        .arg(&bunny)
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v.as_array().unwrap();
    assert_eq!(rows.len(), 2);
    let torus = &rows[0];
    assert!(torus["name"].as_str().unwrap().starts_with("folded torus"));
    assert!(torus["crossing"].as_u64().unwrap() > 0, "the fold crosses the tube");
    for key in ["merge_ms", "health_ms", "tree_ms", "walk_ms", "check_ms"] {
        assert!(torus[key].as_f64().unwrap() >= 0.0, "{key}");
    }
    assert!(torus["load_ms"].is_null());
    let b = &rows[1];
    assert_eq!(
        (b["triangles"].as_u64(), b["crossing"].as_u64(), b["touching"].as_u64()),
        (Some(69451), Some(0), Some(0))
    );
    assert!(b["load_ms"].as_f64().unwrap() >= 0.0);
}
