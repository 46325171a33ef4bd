//! Regressions from issue 10 (trust): each test is named after what it caught.

use assert_cmd::Command;
use std::path::PathBuf;

fn shared(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes").join(name)
}

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
