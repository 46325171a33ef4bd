//! `--html FILE` through the real binary: the page is self-contained, its clash rows match the
//! report (regions, contained part pairs, the closest points of a clear run), baseline status
//! reaches the rows, and pages are byte-identical across thread counts. (The page in a real
//! browser: tests/browser/run.sh.)

use crate::common::boxes_obj;
use assert_cmd::Command;
use meshclash::report::Report;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn shipped(name: &str) -> String {
    root().join("meshes").join(name).display().to_string()
}

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// Run meshclash with `args` plus `--html` and `-o`; the page, its embedded data and the report.
fn run(dir: &Path, args: &[&str]) -> (String, Value, Report) {
    let html = dir.join("r.html");
    let json = dir.join("r.json");
    let out = bin()
        .args(args)
        .args(["-q", "--no-timings", "--html"])
        .arg(&html)
        .arg("-o")
        .arg(&json)
        .output()
        .unwrap();
    assert!(out.status.code().unwrap() < 2, "{}", String::from_utf8_lossy(&out.stderr));
    let page = std::fs::read_to_string(&html).unwrap();
    let rep: Report = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    (page.clone(), data(&page), rep)
}

fn data(page: &str) -> Value {
    let start = page.find("id=\"meshclash-data\">").expect("data block") + "id=\"meshclash-data\">".len();
    let end = start + page[start..].find("</script>").expect("end of data block");
    serde_json::from_str(&page[start..end]).expect("data is JSON")
}

#[test]
fn fcl_page_is_self_contained_and_matches_the_report() {
    let d = tempfile::tempdir().unwrap();
    let (page, v, rep) = run(d.path(), &[&shipped("fcl_env.obj"), &shipped("fcl_rob.obj")]);
    assert!(page.starts_with("<!DOCTYPE html>"));
    for banned in ["<script src", "<link", "@import", "url(", "http://", "https://", "<iframe", "<img"] {
        assert!(!page.contains(banned), "page contains {banned}");
    }
    assert!(page.contains("Content-Security-Policy\" content=\"default-src 'none'"));
    // The text summary is at the top.
    assert!(page.contains("meshclash: CLASH  FAILED (--fail-on clash)"));
    assert_eq!(v["verdict"], "clash");
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), rep.regions.len());
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    assert_eq!(r["id"], rep.regions[0].id.as_str());
    assert_eq!(r["kind"], "crossing");
    assert_eq!(r["pairs"], 192);
    assert_eq!(r["crossing"], 192);
    // Every crossing pair's segment is drawn (6 numbers each).
    assert_eq!(r["segments"].as_array().unwrap().len(), 192 * 6);
    assert_eq!(r["segments_left_off"], 0);
    let parts = v["parts"].as_array().unwrap();
    assert_eq!(parts.len(), 2);
    assert_eq!(parts[r["a"].as_u64().unwrap() as usize]["side"], "a");
    assert_eq!(parts[r["b"].as_u64().unwrap() as usize]["side"], "b");
    assert_eq!(parts[0]["shown"], 2180);
    assert_eq!(parts[1]["shown"], 216);
    assert_eq!(v["triangles_shown"], 2396);
    // The geometry decodes to the stated sizes.
    use base64::Engine;
    let idx =
        base64::engine::general_purpose::STANDARD.decode(parts[1]["indices"].as_str().unwrap()).unwrap();
    assert_eq!(idx.len(), 216 * 3 * 4);
}

#[test]
fn scene_rows_are_the_regions_worst_first_with_their_parts() {
    let d = tempfile::tempdir().unwrap();
    let (_, v, rep) = run(d.path(), &["scene", &shipped("pins.glb")]);
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), rep.regions.len());
    assert_eq!(rows.len(), 6);
    let parts = v["parts"].as_array().unwrap();
    let mut ids: Vec<&str> = rows.iter().map(|r| r["id"].as_str().unwrap()).collect();
    ids.sort();
    let mut want: Vec<&str> = rep.regions.iter().map(|g| g.id.as_str()).collect();
    want.sort();
    assert_eq!(ids, want);
    for r in rows {
        let (a, b) = (r["a"].as_u64().unwrap() as usize, r["b"].as_u64().unwrap() as usize);
        assert_ne!(a, b);
        assert_eq!(parts[a]["name"], r["a_name"]);
        assert_eq!(parts[b]["name"], r["b_name"]);
        assert_eq!(parts[a]["involved"], true);
        let g = rep.regions.iter().find(|g| g.id == r["id"].as_str().unwrap()).unwrap();
        assert_eq!(r["pairs"].as_u64().unwrap() as usize, g.pairs);
        assert_eq!(r["a_name"].as_str().unwrap(), g.a_name);
    }
    // Worst first: all crossing here, so by pair count, descending.
    let counts: Vec<u64> = rows.iter().map(|r| r["pairs"].as_u64().unwrap()).collect();
    assert!(counts.windows(2).all(|w| w[0] >= w[1]), "{counts:?}");
    // Every part of the file is carried (3408 triangles is far under the budget).
    assert_eq!(v["triangles_shown"], 3408);
    assert_eq!(v["up"], "y");
}

#[test]
fn pages_are_identical_across_thread_counts() {
    let d = tempfile::tempdir().unwrap();
    let mut pages = Vec::new();
    for t in ["1", "2", "4"] {
        let (page, _, _) = run(d.path(), &["scene", &shipped("pins.glb"), "--threads", t]);
        pages.push(page);
    }
    assert_eq!(pages[0], pages[1]);
    assert_eq!(pages[0], pages[2]);
}

#[test]
fn baseline_status_reaches_the_rows() {
    let d = tempfile::tempdir().unwrap();
    let base = d.path().join("base.json");
    // The accepted state: every dowel but #1:14 (its clash is new in the full run).
    bin()
        .args(["scene", &shipped("pins.glb"), "--exclude", "*dowel#1:14*", "--max-pairs", "5000", "-q", "-o"])
        .arg(&base)
        .assert()
        .code(1);
    let (_, v, _) = run(
        d.path(),
        &["scene", &shipped("pins.glb"), "--baseline", base.to_str().unwrap(), "--max-pairs", "5000"],
    );
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    for r in rows {
        let want = if r["b_name"].as_str().unwrap().contains("dowel#1:14") { "new" } else { "persistent" };
        assert_eq!(r["status"], want, "{}", r["b_name"]);
    }
}

#[test]
fn contained_part_gets_a_row_and_a_clear_run_the_closest_points() {
    let d = tempfile::tempdir().unwrap();
    let outer = boxes_obj(d.path(), "outer.obj", &[("outer", [0.0; 3], [10.0; 3])]);
    let inner = boxes_obj(d.path(), "inner.obj", &[("inner", [4.0; 3], [5.0; 3])]);
    let (_, v, rep) = run(d.path(), &[&outer, &inner]);
    assert_eq!(rep.summary.contained.map(|c| c.name()), Some("b_in_a"));
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0]["kind"], "contained");
    assert_eq!(rows[0]["a_name"], "outer");
    assert_eq!(rows[0]["b_name"], "inner");

    let far = boxes_obj(d.path(), "far.obj", &[("far", [20.0; 3], [21.0; 3])]);
    let (_, v, rep) = run(d.path(), &[&outer, &far]);
    assert_eq!(rep.verdict, "clear");
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0]["kind"], "closest");
    let dist = rows[0]["distance"].as_f64().unwrap();
    assert!((dist - (300.0f64).sqrt()).abs() < 1e-9, "{dist}");
    assert_eq!(rows[0]["witness"].as_array().unwrap().len(), 6);
}

#[test]
fn html_to_an_unwritable_place_is_exit_2_naming_it() {
    let out = bin()
        .args([&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "-q", "--html", "/nonexistent-dir/r.html"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent-dir/r.html"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn self_page_lists_self_clashes_and_health_problems_with_their_triangles() {
    let d = tempfile::tempdir().unwrap();
    let strip = crate::glb::folded_strip(d.path());
    let html = d.path().join("s.html");
    let out = bin().arg("self").arg(&strip).args(["--no-timings", "--html"]).arg(&html).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r: meshclash::report::self_report::SelfReport = serde_json::from_slice(&out.stdout).unwrap();
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(!page.contains("http://") && !page.contains("https://"));
    assert!(page.contains("self-clash"), "the summary is the self summary");
    let v = data(&page);
    let rows = v["rows"].as_array().unwrap();
    let kinds: Vec<&str> = rows.iter().map(|r| r["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["crossing", "winding", "open"]);
    let parts = v["parts"].as_array().unwrap();
    let part = |r: &Value, k: &str| &parts[r[k].as_u64().unwrap() as usize];
    // The self-clash: lower triangles (0, 1) as A, higher ones (4, 5) as B, the rest of the
    // strip faded; the contact segments of the listed pairs.
    let c = &rows[0];
    assert_eq!((c["pairs"].as_u64(), c["crossing"].as_u64()), (Some(4), Some(2)));
    assert_eq!((part(c, "a")["shown"].as_u64(), part(c, "b")["shown"].as_u64()), (Some(2), Some(2)));
    assert_eq!(part(c, "a")["name"], "strip (lower triangles)");
    let with_segment = r.pairs.iter().filter(|p| p.segment.is_some()).count();
    assert_eq!(c["segments"].as_array().unwrap().len(), 6 * with_segment);
    // The health problem: its listed triangles as B against the rest of the part.
    let o = &rows[2];
    let h = &r.parts[0].health;
    assert_eq!(o["pairs"].as_u64(), Some(h.boundary_edges.count));
    assert_eq!(part(o, "b")["shown"].as_u64(), Some(h.boundary_edges.triangles.len() as u64));
    assert_eq!(part(o, "b")["name"], "strip (open)");
    // A self-clash's triangles leave the strip (drawn once, in its two sides); a health
    // finding's are copies over the strip, which stays whole otherwise.
    let shown: u64 = parts.iter().map(|p| p["shown"].as_u64().unwrap()).sum();
    assert_eq!(part(o, "a")["name"], "strip");
    assert_eq!(part(o, "a")["shown"].as_u64(), Some(2));
    let copies = h.boundary_edges.triangles.len() + h.inconsistent_winding_edges.triangles.len();
    assert_eq!(shown as usize, 6 + copies);
}
