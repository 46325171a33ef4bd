//! through the real binary: a selection problem names the file of the side
//! that has it.

use assert_cmd::Command;
use std::path::PathBuf;

fn shipped(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("meshes").join(name).display().to_string()
}

fn error_of(args: &[&str]) -> String {
    let out = Command::cargo_bin("meshclash").unwrap().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn a_selection_error_names_the_file_of_its_side() {
    let (a, b) = (shipped("fcl_env.obj"), shipped("pins.glb"));
    let side_a = error_of(&[&a, &b, "--select-a", "nomatch*"]);
    assert_eq!(side_a, format!("meshclash: error: {a}: --select-a nomatch* matches no part\n"));
    let excluded = error_of(&[&a, &b, "--exclude", "*"]);
    assert_eq!(excluded, format!("meshclash: error: {a}: no part left to check on side a after --exclude\n"));
    // B's problem names B's file.
    let side_b = error_of(&[&a, &b, "--select-b", "nomatch*"]);
    assert_eq!(side_b, format!("meshclash: error: {b}: --select-b nomatch* matches no part\n"));
    // Scene mode: one file, named for either side.
    let scene = error_of(&["scene", &b, "--select-a", "nomatch*"]);
    assert_eq!(scene, format!("meshclash: error: {b}: --select-a nomatch* matches no part\n"));
}
