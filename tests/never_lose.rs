//! Outputs that must never cost a file, through the real binary: a report written to
//! `/dev/stdout` while standard output is redirected to a file, an output naming a file a glTF
//! input reads (its external buffer or image), two outputs naming one new file, a plan or
//! shard report named as an output, and outputs written though stdout failed.

use assert_cmd::Command;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn exe() -> &'static str {
    env!("CARGO_BIN_EXE_meshclash")
}

fn bin() -> Command {
    let mut c = Command::cargo_bin("meshclash").unwrap();
    c.timeout(Duration::from_secs(120));
    c
}

fn two_meshes() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    std::fs::copy(root().join("meshes/fcl_env.obj"), d.path().join("a.obj")).unwrap();
    std::fs::copy(root().join("meshes/fcl_rob.obj"), d.path().join("b.obj")).unwrap();
    d
}

/// Runs a shell script in `dir` with `$M` the binary; returns (exit code, stderr).
fn sh(dir: &Path, script: &str) -> (Option<i32>, String) {
    let out = std::process::Command::new("/bin/sh")
        .arg("-c")
        .arg(script)
        .env("M", exe())
        .current_dir(dir)
        .output()
        .unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// `{ echo HEADER; meshclash a b -o /dev/stdout; } >> log`: the report is appended after what
/// the shell wrote; the log is neither truncated nor replaced (same inode).
#[test]
fn report_to_dev_stdout_appends_to_a_redirected_log() {
    let d = two_meshes();
    let log = d.path().join("ci.log");
    std::fs::write(&log, "EARLIER\n").unwrap();
    let ino = std::os::unix::fs::MetadataExt::ino(&std::fs::metadata(&log).unwrap());
    for out in ["/dev/stdout", "/proc/self/fd/1"] {
        let script = format!(r#"{{ echo HEADER; "$M" a.obj b.obj --no-timings -o {out}; }} >> ci.log"#);
        let (code, err) = sh(d.path(), &script);
        assert_eq!(code, Some(1), "{out}: {err}");
    }
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(text.starts_with("EARLIER\nHEADER\n{"), "{text}");
    assert_eq!(text.matches("HEADER\n").count(), 2, "{text}");
    let second = text.rfind("HEADER\n").unwrap();
    let report: serde_json::Value = serde_json::from_str(&text[second + 7..]).unwrap();
    assert!(report["pairs"].as_array().is_some_and(|p| !p.is_empty()), "{report}");
    assert_eq!(std::os::unix::fs::MetadataExt::ino(&std::fs::metadata(&log).unwrap()), ino);
}

/// `{ echo HEADER; meshclash … -o /dev/stdout; echo FOOTER; } > log`: written at the shell's
/// offset, so what comes after follows the report instead of overwriting it; `/dev/stderr`
/// redirected the same way.
#[test]
fn report_to_dev_stdout_or_stderr_keeps_what_the_shell_writes_around_it() {
    let d = two_meshes();
    let script = r#"{ echo HEADER; "$M" a.obj b.obj --no-timings -o /dev/stdout; echo FOOTER; } > out.log"#;
    let (code, err) = sh(d.path(), script);
    assert_eq!(code, Some(0), "{err}");
    let text = std::fs::read_to_string(d.path().join("out.log")).unwrap();
    assert!(text.starts_with("HEADER\n{") && text.ends_with("}\nFOOTER\n"), "{text}");
    let script = r#"{ echo HEADER >&2; "$M" a.obj b.obj --no-timings --junit /dev/stderr; } 2> err.log"#;
    let (code, _) = sh(d.path(), script);
    assert_eq!(code, Some(1));
    let text = std::fs::read_to_string(d.path().join("err.log")).unwrap();
    assert!(text.starts_with("HEADER\n<?xml"), "{text}");
}

/// A `.gltf` reading `geo.bin` and naming `tex.png`: `-o geo.bin`, `--junit tex.png` are
/// refused (exit 2, one line) and both files keep their bytes.
#[test]
fn output_naming_a_gltf_external_buffer_or_image_is_refused() {
    let d = two_meshes();
    let mut bin_data: Vec<u8> = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        bin_data.extend(p.iter().flat_map(|x| x.to_le_bytes()));
    }
    std::fs::write(d.path().join("geo.bin"), &bin_data).unwrap();
    std::fs::write(d.path().join("tex.png"), b"\x89PNG").unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"byteLength":36,"uri":"geo.bin"}],"images":[{"uri":"tex.png"}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]}"#;
    std::fs::write(d.path().join("m.gltf"), gltf).unwrap();
    for (flag, out) in [("-o", "geo.bin"), ("--junit", "tex.png"), ("--export-glb", "./geo.bin")] {
        let o = bin().current_dir(d.path()).args(["m.gltf", "a.obj", flag, out]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(flag) && err.contains("names the input"), "{err}");
    }
    assert_eq!(std::fs::read(d.path().join("geo.bin")).unwrap(), bin_data);
    assert_eq!(std::fs::read(d.path().join("tex.png")).unwrap(), b"\x89PNG");
    // The model itself still loads and checks.
    bin().current_dir(d.path()).args(["m.gltf", "a.obj", "-o", "/dev/null"]).assert().code(0);
}

/// `-o r.json --junit r.json` with no `r.json` yet (and through `./`): exit 2 naming both
/// flags, nothing written.
#[test]
fn two_outputs_naming_one_new_file_are_refused() {
    let d = two_meshes();
    for second in ["r.json", "./r.json"] {
        let o =
            bin().current_dir(d.path()).args(["a.obj", "b.obj", "-o", "r.json", "--junit", second]).output();
        let o = o.unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("--junit names the same file as -o"), "{err}");
        assert!(!d.path().join("r.json").exists());
    }
}

/// `meshclash merge s1.json -o s1.json`: a shard report is an input, refused (exit 2, one
/// line), and left as it was.
#[test]
fn merge_output_naming_a_shard_report_is_refused_and_the_report_kept() {
    let d = two_meshes();
    let (code, err) = sh(
        d.path(),
        r#""$M" plan a.obj b.obj -o p.json -q && "$M" run --plan p.json --shard 1/1 -o s1.json -q"#,
    );
    assert_eq!(code, Some(0), "{err}");
    let before = std::fs::read(d.path().join("s1.json")).unwrap();
    let (code, err) = sh(d.path(), r#""$M" merge s1.json -o s1.json -q"#);
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("s1.json") && err.contains("names the input"), "{err}");
    assert_eq!(std::fs::read(d.path().join("s1.json")).unwrap(), before, "the shard report was rewritten");
}

/// `meshclash run --plan p.json -o p.json` (or `-o a.obj`, a mesh the plan reads): the plan and
/// its meshes are inputs, refused (exit 2) before anything is written, and left as they were;
/// the report a failed shard leaves for the merge is not written over them either.
#[test]
fn run_output_naming_its_plan_or_a_mesh_is_refused_and_the_input_kept() {
    let d = two_meshes();
    let (code, err) = sh(d.path(), r#""$M" plan a.obj b.obj -o p.json -q"#);
    assert_eq!(code, Some(0), "{err}");
    for input in ["p.json", "a.obj"] {
        let before = std::fs::read(d.path().join(input)).unwrap();
        let (code, err) = sh(d.path(), &format!(r#""$M" run --plan p.json --shard 1/1 -o {input} -q"#));
        assert_eq!(code, Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(input) && err.contains("names the input"), "{err}");
        assert_eq!(std::fs::read(d.path().join(input)).unwrap(), before, "{input} was rewritten");
    }
}

/// `--format text -o t.json > /dev/full`: the summary is lost, so the run is exit 2 and writes
/// no report file either (all or nothing includes stdout); `--help` and `--version` to a full
/// or closed stdout are exit 2 with a message, not 0 in silence.
#[test]
fn a_full_stdout_writes_no_output_file_and_help_to_it_is_an_error() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let d = two_meshes();
    let (code, err) = sh(d.path(), r#""$M" a.obj b.obj --format text -o t.json > /dev/full"#);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("cannot write to stdout"), "{err}");
    assert!(!d.path().join("t.json").exists(), "t.json was written though stdout failed");
    for script in [r#""$M" --help > /dev/full"#, r#""$M" --version > /dev/full"#, r#""$M" --version >&-"#] {
        let (code, err) = sh(d.path(), script);
        assert_eq!(code, Some(2), "{script}: {err}");
        assert!(err.contains("cannot write to stdout"), "{script}: {err}");
    }
}
