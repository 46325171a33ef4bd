//! `meshclash bench` after the harness moved to the `meshclash-bench` crate: the
//! subcommand forwards its arguments to a `meshclash-bench` next to the executable, and without
//! one says how to run it (exit 2). The harness's own tests are in `bench/tests/`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The `meshclash` binary alone in a fresh directory: a hard link (a copy would be open for
/// writing while parallel tests fork, and exec would fail with "text file busy").
fn lone_meshclash(dir: &Path) -> PathBuf {
    let exe = dir.join("meshclash");
    std::fs::hard_link(env!("CARGO_BIN_EXE_meshclash"), &exe).unwrap();
    exe
}

/// A directory on the target's file system (so the hard link works).
fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap()
}

#[test]
fn bench_without_the_harness_says_how_to_run_it() {
    let dir = tempdir();
    let out = Command::new(lone_meshclash(dir.path())).args(["bench", "--sizes", "1k"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(out.stdout.is_empty());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("cargo run --release -p meshclash-bench --"), "{err}");
}

#[cfg(unix)]
#[test]
fn bench_forwards_arguments_and_exit_code() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempdir();
    let exe = lone_meshclash(dir.path());
    // A stand-in harness that echoes its arguments and exits 3.
    let fake = dir.path().join("meshclash-bench");
    std::fs::write(&fake, "#!/bin/sh\nprintf '%s|' \"$@\"\nexit 3\n").unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    // The script was just written: a test forking in parallel can hold it open for an instant
    // ("text file busy"), so retry that one error.
    let busy = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).contains("busy");
    let out = (0..20)
        .map(|_| {
            let out = Command::new(&exe)
                .args(["bench", "cases", "dir with space", "--only", "spheres", "--help"])
                .output()
                .unwrap();
            if busy(&out) {
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            out
        })
        .find(|o| !busy(o))
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(String::from_utf8_lossy(&out.stdout), "cases|dir with space|--only|spheres|--help|");
}
