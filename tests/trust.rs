//! Regressions found by trying the tool as a user would: each test is named after what it caught.

use assert_cmd::Command;

use crate::common::shared;

/// The text summary printed `volumes_overlap` as "undecided" (in yellow).
#[test]
fn text_summary_names_volumes_overlap_instead_of_undecided() {
    let boxes = shared("Box.glb");
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .arg(&boxes)
        .arg(&boxes)
        .args(["--format", "text", "--no-timings"])
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("containment: the closed parts' volumes overlap"), "{text}");
    assert!(!text.contains("undecided"), "{text}");
}

/// glTF node translations were read as f32: a part placed at x = 0.1000000015 landed on the
/// f32 value of 0.1, exactly where the other part ends, and was reported touching. The JSON
/// number is now read as f64, so the report gives the exact f64 gap (~9.88e-12) and `clear`.
#[test]
fn gltf_node_translation_not_f32_exact_gives_the_f64_gap_not_touching() {
    use base64::Engine as _;
    let dir = tempfile::tempdir().unwrap();
    let mut bin: Vec<u8> =
        [0f32, 0., 0., 1., 0., 0., 0., 1., 0.].iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},
  "buffers":[{{"byteLength":44,"uri":"data:application/octet-stream;base64,{}"}}],
  "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
  "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
    {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
  "nodes":[{{"mesh":0,"translation":[0.1000000015,0,0]}}]}}"#,
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    let a = dir.path().join("a.gltf");
    std::fs::write(&a, gltf).unwrap();
    // B: a triangle in the plane x = f32(0.1), across A's edge x = 0.1000000015, y in [0, 1]
    let c = 0.1f32 as f64;
    let b = dir.path().join("b.obj");
    std::fs::write(&b, format!("v {c:?} -1 -1\nv {c:?} 3 -1\nv {c:?} 0.5 2\nf 1 2 3\n")).unwrap();
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .arg(&a)
        .arg(&b)
        .args(["--no-timings", "--fail-on", "touching"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["verdict"], "clear");
    let gap = 0.1000000015f64 - c;
    assert!((9.8e-12..9.9e-12).contains(&gap));
    assert_eq!(v["summary"]["min_distance"].as_f64(), Some(gap));
    assert_eq!(v["summary"]["touching_pairs"], 0);
}

fn usage_error(args: &[&str]) -> String {
    let out = Command::cargo_bin("meshclash").unwrap().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    assert!(out.stdout.is_empty());
    String::from_utf8(out.stderr).unwrap()
}

/// Usage errors kept only clap's first line: the allowed values of `--fail-on` and the "did you
/// mean" tip were cut off. Every error now starts with `meshclash: error:`.
#[test]
fn usage_errors_keep_allowed_values_and_did_you_mean_under_one_prefix() {
    let e = usage_error(&["a.obj", "b.obj", "--fail-on", "clashes"]);
    assert!(e.starts_with("meshclash: error: invalid value 'clashes' for '--fail-on"), "{e}");
    assert!(e.contains("clash, touching, clearance, never, new"), "{e}");
    let e = usage_error(&["a.obj", "b.obj", "--clearence", "1"]);
    assert!(e.starts_with("meshclash: error: "), "{e}");
    assert!(e.contains("--clearance"), "the did-you-mean tip is kept: {e}");
    let e = usage_error(&["a.obj"]);
    assert!(e.starts_with("meshclash: error: "), "{e}");
    assert!(e.contains("<B>"), "the missing argument is named: {e}");
    // a non-clap error has the same prefix
    let e = usage_error(&["a.obj", "b.obj", "--leaf-size", "0"]);
    assert!(e.starts_with("meshclash: error: "), "{e}");
}

fn text_of(args: &[&std::ffi::OsStr]) -> String {
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .args(args)
        .args(["--format", "text", "--no-timings"])
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    assert!(matches!(out.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// Scene-mode summaries said nothing about parts; a scene with no candidate part pairs said
/// "an input has no triangles"; `--first-hit` counts did not say they are lower bounds.
#[test]
fn text_summary_names_clashing_part_pairs_candidates_and_first_hit_lower_bounds() {
    let dir = tempfile::tempdir().unwrap();
    // three parts: `bolt` crosses `plate`; `far` is far from both
    let scene = dir.path().join("scene.obj");
    std::fs::write(
        &scene,
        "o plate\nv 0 0 0\nv 4 0 0\nv 0 4 0\nf 1 2 3\n\
         o bolt\nv 1 1 -1\nv 1.2 1 1\nv 1 1.2 1\nf 4 5 6\n\
         o far\nv 100 0 0\nv 101 0 0\nv 100 1 0\nf 7 8 9\n",
    )
    .unwrap();
    let t = text_of(&["scene".as_ref(), scene.as_os_str()]);
    assert!(t.contains("1 clashing part pair:\n    plate x bolt  (1 crossing)"), "{t}");
    // only `far` selected against nothing near it: no candidate part pairs
    let t = text_of(&["scene".as_ref(), scene.as_os_str(), "--select-a".as_ref(), "far".as_ref()]);
    assert!(!t.contains("an input has no triangles"), "{t}");
    assert!(t.contains("closest: none (no candidate part pairs"), "{t}");
    // --first-hit: lower bounds
    let t = text_of(&["scene".as_ref(), scene.as_os_str(), "--first-hit".as_ref()]);
    assert!(t.contains("at least 1 crossing") && t.contains("lower bounds"), "{t}");
}

/// Closedness, containment and volume overlap were decided per input: `Box.glb` is an exact
/// copy of one of the two cubes of `shared.STL`, and with `--split-bodies` the check said
/// `touching` (exit 0) where the same cube saved alone gives `clash` (`volumes_overlap`). They
/// are now decided per part pair in file mode too, and the pair is listed in `part_pairs`.
#[test]
fn duplicated_body_inside_a_multi_part_file_is_a_clash_per_part() {
    let run = |args: &[&std::ffi::OsStr]| {
        let out = Command::cargo_bin("meshclash").unwrap().args(args).arg("--no-timings").output().unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (out.status.code(), v)
    };
    let (boxes, shared_stl) = (shared("Box.glb"), shared("shared.STL"));
    let (code, r) = run(&[boxes.as_os_str(), shared_stl.as_os_str(), "--split-bodies".as_ref()]);
    assert_eq!(code, Some(1), "{r}");
    assert_eq!(r["verdict"], "clash");
    assert_eq!(r["summary"]["contained"], "volumes_overlap");
    assert_eq!(r["summary"]["crossing_pairs"], 0);
    let pp = r["part_pairs"].as_array().unwrap();
    let dup: Vec<_> = pp.iter().filter(|p| p["contained"] == "volumes_overlap").collect();
    assert_eq!(dup.len(), 1, "{pp:?}");
    assert_eq!(dup[0]["verdict"], "clash");
    // The other body only touches the box along shared faces with opposite normals.
    assert!(pp.iter().any(|p| p["verdict"] == "touching" && p["contained"].is_null()), "{pp:?}");
    // The same answer as the cube against itself, and as the scene check of the bodies.
    let (code_alone, alone) = run(&[boxes.as_os_str(), boxes.as_os_str()]);
    assert_eq!(
        (code_alone, &alone["summary"]["contained"]),
        (Some(1), &serde_json::json!("volumes_overlap"))
    );
}
