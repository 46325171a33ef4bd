//! Through the real binary: never lose a file (outputs naming inputs, all or nothing
//! across outputs, a closed or full stdout), never exhaust memory (hostile inputs under a memory
//! limit, the report streamed instead of held as text).

use assert_cmd::Command;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bin() -> Command {
    let mut c = Command::cargo_bin("meshclash").unwrap();
    c.timeout(Duration::from_secs(120)); // a hang fails the test instead of stalling it
    c
}

fn exe() -> &'static str {
    env!("CARGO_BIN_EXE_meshclash")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A directory with copies of two shipped meshes (`a.obj`, `b.obj`) and the shipped GLB.
fn tree() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    std::fs::copy(root().join("meshes/fcl_env.obj"), d.path().join("a.obj")).unwrap();
    std::fs::copy(root().join("meshes/fcl_rob.obj"), d.path().join("b.obj")).unwrap();
    std::fs::copy(root().join("meshes/pins.glb"), d.path().join("box.glb")).unwrap();
    std::fs::write(d.path().join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    d
}

/// The run fails with exit 2 and one stderr line containing every `expect`.
fn refused(cmd: &mut Command, expect: &[&str]) -> String {
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    for e in expect {
        assert!(err.contains(e), "expected {e:?} in {err}");
    }
    err
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
    v.sort();
    v
}

// ------------------------------------------------------------------ 1. outputs naming inputs

/// `-o A.obj`, `--junit A.obj`, `--export-glb A.obj`, `scene box.glb -o box.glb`, through a
/// symlink and a hard link: refused with exit 2, the input untouched. B is a broken mesh, so the
/// refusal must come before any input is loaded ("before any work").
#[test]
fn output_naming_an_input_is_refused_before_any_work() {
    let d = tree();
    let p = |n: &str| d.path().join(n);
    std::os::unix::fs::symlink(p("a.obj"), p("link.json")).unwrap();
    std::fs::hard_link(p("a.obj"), p("hard.json")).unwrap();
    let original = std::fs::read(p("a.obj")).unwrap();
    let glb = std::fs::read(p("box.glb")).unwrap();
    for (flag, out) in [
        ("-o", "a.obj"),
        ("--junit", "a.obj"),
        ("--export-glb", "a.obj"),
        ("-o", "link.json"),
        ("--junit", "hard.json"),
        ("-o", "./a.obj"),
    ] {
        refused(
            bin().current_dir(d.path()).args(["a.obj", "bad.obj", flag, out]),
            &[out, flag, "names the input a.obj"],
        );
        assert_eq!(std::fs::read(p("a.obj")).unwrap(), original, "{flag} {out} changed the input");
    }
    refused(bin().current_dir(d.path()).args(["scene", "box.glb", "-o", "box.glb"]), &["names the input"]);
    assert_eq!(std::fs::read(p("box.glb")).unwrap(), glb);
    // The same rule for `self` and `clash-set` (its file and every check's meshes are inputs).
    refused(
        bin().current_dir(d.path()).args(["self", "a.obj", "--junit", "hard.json"]),
        &["names the input"],
    );
    std::fs::write(p("set.json"), r#"{"version": 1, "checks": [{"name": "x", "a": "a.obj", "b": "b.obj"}]}"#)
        .unwrap();
    refused(
        bin().current_dir(d.path()).args(["clash-set", "set.json", "-o", "b.obj"]),
        &["names the input b.obj"],
    );
    refused(
        bin().current_dir(d.path()).args(["clash-set", "set.json", "--junit", "set.json"]),
        &["names the input"],
    );
    assert_eq!(std::fs::read(p("a.obj")).unwrap(), original);
    // Two outputs naming one file.
    std::fs::write(p("r.json"), "old").unwrap();
    refused(
        bin().current_dir(d.path()).args(["a.obj", "b.obj", "-o", "r.json", "--junit", "r.json"]),
        &["--junit names the same file as -o"],
    );
}

/// Updating a baseline in place stays allowed: the baseline is read whole before any output is
/// written (it is not a mesh input).
#[test]
fn baseline_may_be_updated_in_place() {
    let d = tree();
    let r = d.path().join("r.json");
    bin().current_dir(d.path()).args(["a.obj", "b.obj", "-o", "r.json", "--no-timings"]).assert().code(1);
    bin()
        .current_dir(d.path())
        .args(["a.obj", "b.obj", "--baseline", "r.json", "-o", "r.json", "--no-timings"])
        .assert()
        .code(1);
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&r).unwrap()).unwrap();
    assert_eq!(v["baseline"]["new"], 0, "{}", v["baseline"]);
}

// ---------------------------------------------------------------- 3. all or nothing

/// `--junit j.xml -o missing/r.json`: refused before the run (B is broken and is not what the
/// error names), and `j.xml` is not written.
#[test]
fn missing_output_directory_is_found_before_the_run_and_nothing_is_written() {
    let d = tree();
    refused(
        bin().current_dir(d.path()).args(["a.obj", "bad.obj", "--junit", "j.xml", "-o", "missing/r.json"]),
        &["missing/r.json", "directory missing"],
    );
    assert!(!d.path().join("j.xml").exists());
    refused(
        bin().current_dir(d.path()).args(["self", "a.obj", "--junit", "j.xml", "-o", "missing/r.json"]),
        &["missing"],
    );
    assert!(!d.path().join("j.xml").exists());
}

/// A run that fails while writing its outputs (`-o /dev/full`: written directly, fails with
/// "no space") leaves the other outputs unwritten: before the fix `j.xml` and the GLB stayed.
#[test]
fn failed_write_of_one_output_leaves_no_other_output() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let d = tree();
    let before = names(d.path());
    refused(
        bin().current_dir(d.path()).args([
            "a.obj",
            "b.obj",
            "--junit",
            "j.xml",
            "--export-glb",
            "v.glb",
            "-o",
            "/dev/full",
        ]),
        &["/dev/full"],
    );
    assert_eq!(names(d.path()), before, "outputs or temporaries left behind");
    // And a run that fails on its input leaves nothing either.
    refused(
        bin().current_dir(d.path()).args(["a.obj", "bad.obj", "--junit", "j.xml", "-o", "r.json"]),
        &["bad.obj"],
    );
    assert_eq!(names(d.path()), before);
}

/// All outputs of a good run are written, and `-o /dev/null` stays a device.
#[test]
fn good_run_writes_every_output() {
    let d = tree();
    bin()
        .current_dir(d.path())
        .args(["a.obj", "b.obj", "--junit", "j.xml", "--export-glb", "v.glb", "-o", "r.json"])
        .assert()
        .code(1);
    for f in ["j.xml", "v.glb", "r.json"] {
        assert!(std::fs::metadata(d.path().join(f)).unwrap().len() > 0, "{f}");
    }
    bin().current_dir(d.path()).args(["a.obj", "b.obj", "-o", "/dev/null"]).assert().code(1);
}

// ---------------------------------------------------------------- 4. closed or full stdout

/// Runs `meshclash ARGS` under `sh` with stdout redirected by `redir` (`>&-`, `>/dev/full`).
fn with_stdout(redir: &str, args: &[&str], dir: &Path) -> (Option<i32>, String) {
    let script = format!(r#"exec "$0" "$@" {redir}"#);
    let out = std::process::Command::new("/bin/sh")
        .current_dir(dir)
        .arg("-c")
        .arg(script)
        .arg(exe())
        .args(args)
        .output()
        .unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A closed (`>&-`) or full (`>/dev/full`) stdout loses the report or the generated text: exit
/// 2 with a message, never the verdict's code or 0.
#[test]
fn closed_or_full_stdout_is_exit_2_with_a_message() {
    let d = tree();
    let full = Path::new("/dev/full").exists();
    let cases: &[&[&str]] = &[
        &["a.obj", "b.obj"],
        &["a.obj", "b.obj", "--fail-on", "never"],
        &["a.obj", "b.obj", "--format", "text"],
        &["schema"],
        &["man"],
        &["completions", "bash"],
        &["self", "b.obj"],
    ];
    for args in cases {
        for redir in [">&-", ">/dev/full"] {
            if redir == ">/dev/full" && !full {
                continue;
            }
            let (code, err) = with_stdout(redir, args, d.path());
            assert_eq!(code, Some(2), "{args:?} {redir}: {err}");
            assert!(err.contains("cannot write to stdout"), "{args:?} {redir}: {err}");
        }
    }
    // `>/dev/null` is a choice, not a loss.
    let (code, err) = with_stdout(">/dev/null", &["a.obj", "b.obj", "-q"], d.path());
    assert_eq!((code, err.as_str()), (Some(1), ""));
}

/// A reader that goes away (a broken pipe) stays quiet: the verdict's exit code, no message.
/// (The report of a mesh against itself is megabytes, far more than a pipe holds.)
#[test]
fn broken_pipe_stays_quiet() {
    if !Path::new("/bin/bash").exists() {
        return;
    }
    let d = tree();
    let script =
        r#""$0" a.obj a.obj -q --fail-on never | head -c 1 >/dev/null; echo "code ${PIPESTATUS[0]}""#;
    let out = std::process::Command::new("/bin/bash")
        .current_dir(d.path())
        .arg("-c")
        .arg(script)
        .arg(exe())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.trim(), "code 0", "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
}

// ---------------------------------------------------------------- memory

/// Runs `sh -c 'ulimit -v KIB; exec meshclash ARGS'` (`--threads 1`: one allocator arena);
/// returns (exit code, stderr).
fn under_memory_limit(kib: u64, args: &[&str]) -> (Option<i32>, String) {
    let script = format!(r#"ulimit -v {kib} && exec "$0" "$@" --threads 1"#);
    let out =
        std::process::Command::new("/bin/sh").arg("-c").arg(script).arg(exe()).args(args).output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Hostile inputs under a 1 GiB address-space limit: each is refused with exit 2 and a message
/// naming the file, never an abort ("memory allocation of N bytes failed", exit 134).
#[test]
fn hostile_inputs_under_a_memory_limit_exit_2_not_abort() {
    if !cfg!(target_os = "linux") {
        return;
    }
    let d = tree();
    // one face line of 24 MB (12 million indices).
    let mut face = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf".to_vec();
    for _ in 0..12_000_000 {
        face.extend_from_slice(b" 1");
    }
    face.push(b'\n');
    let huge_face = d.path().join("huge_face.obj");
    std::fs::write(&huge_face, &face).unwrap();
    // /dev/zero behind a mesh name is refused up front.
    let zero = d.path().join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let good = root().join("meshes/fcl_rob.obj");
    for (file, expect) in
        [(&huge_face, "line 4: face has more than 65536 vertices"), (&zero, "not a regular file")]
    {
        for args in [[s(&good), s(file)], [s(file), s(&good)]] {
            let (code, err) = under_memory_limit(1 << 20, &args);
            assert!(!err.contains("memory allocation"), "{}: aborted: {err}", file.display());
            assert_eq!(code, Some(2), "{}: {err}", file.display());
            assert!(err.contains(s(file)) && err.contains(expect), "{err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        }
    }
}

/// A report listing 90 000 pairs (25 MB of JSON) is streamed to stdout and to `-o`: listing it
/// costs less than its own size in peak memory over `--max-pairs 0` (the same check, nothing
/// listed). Before the fix the text was built whole and, for stdout, copied once more: 95 MB
/// against 26 MB, a 69 MB difference; after it, 46 MB (the report's structure).
#[test]
fn report_is_streamed_not_held_as_text() {
    if !Path::new("/usr/bin/time").exists() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    // A 60×60 grid of unit squares checked against a copy of itself: every triangle touches
    // itself and its neighbours.
    let k = 60;
    let mut obj = String::new();
    for j in 0..=k {
        for i in 0..=k {
            obj += &format!("v {i} {j} 0\n");
        }
    }
    let v = |i: usize, j: usize| j * (k + 1) + i + 1;
    for j in 0..k {
        for i in 0..k {
            obj += &format!(
                "f {} {} {}\nf {} {} {}\n",
                v(i, j),
                v(i + 1, j),
                v(i + 1, j + 1),
                v(i, j),
                v(i + 1, j + 1),
                v(i, j + 1)
            );
        }
    }
    std::fs::write(d.path().join("g.obj"), &obj).unwrap();
    std::fs::write(d.path().join("h.obj"), &obj).unwrap();
    let peak = |extra: &str| -> u64 {
        let script = format!(
            r#"exec /usr/bin/time -f "MAXRSS_KIB %M" "$0" g.obj h.obj --threads 1 --no-timings {extra} > out.txt"#
        );
        let out = std::process::Command::new("/bin/sh")
            .current_dir(d.path())
            .arg("-c")
            .arg(script)
            .arg(exe())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        err.lines()
            .find_map(|l| l.strip_prefix("MAXRSS_KIB "))
            .unwrap_or_else(|| panic!("{err}"))
            .trim()
            .parse()
            .unwrap()
    };
    let listed_nothing = peak("--max-pairs 0");
    let json = peak("--max-pairs 100000000");
    let json_len = std::fs::metadata(d.path().join("out.txt")).unwrap().len() / 1024;
    let file = peak("--max-pairs 100000000 -o r.json");
    assert!(json_len > 20_000, "the report is only {json_len} KiB");
    assert_eq!(std::fs::metadata(d.path().join("r.json")).unwrap().len() / 1024, json_len);
    for (what, kib) in [("stdout", json), ("-o", file)] {
        assert!(
            kib < listed_nothing + json_len,
            "{what}: peak {kib} KiB vs {listed_nothing} KiB listing nothing; the report is {json_len} KiB"
        );
    }
}

/// a scene of thousands of one-triangle parts stacked in one place made every
/// pair of them a candidate, collected into one vector first (2^20 such nodes needed 4 GiB and
/// aborted). Beyond `MAX_CANDIDATE_PART_PAIRS` the scene is refused with exit 2 naming the file,
/// before any pair is collected; under the cap the same construction runs.
#[test]
fn stacked_parts_beyond_the_candidate_pair_cap_are_refused_not_collected() {
    use base64::Engine;
    // One triangle (f32 positions, u16 indices), placed by `n` nodes at the same spot.
    let stacked = |n: usize| -> Vec<u8> {
        let mut buf: Vec<u8> = [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        buf.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
        let data = base64::engine::general_purpose::STANDARD.encode(&buf);
        let nodes: Vec<String> = (0..n).map(|i| format!(r#"{{"name":"p{i}","mesh":0}}"#)).collect();
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{:?}}}],"nodes":[{}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":44,"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
            (0..n).collect::<Vec<_>>(),
            nodes.join(",")
        )
        .into_bytes()
    };
    let cap = meshclash::check::assembly::MAX_CANDIDATE_PART_PAIRS;
    let d = tree();
    // 4,200 parts: 8,817,900 pairs, just over the cap (2^23 = 8,388,608).
    let over = d.path().join("stacked.gltf");
    std::fs::write(&over, stacked(4_200)).unwrap();
    assert!(4_200 * 4_199 / 2 > cap);
    let (code, err) = under_memory_limit(1 << 20, &["scene", s(&over), "--no-timings", "-o", "/dev/null"]);
    assert!(!err.contains("memory allocation"), "aborted: {err}");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(s(&over)) && err.contains("candidate part pairs"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    // Under the cap: the same stack of 300 parts is checked (every pair touches: exit 0).
    let under = d.path().join("small_stack.gltf");
    std::fs::write(&under, stacked(300)).unwrap();
    let out = bin().args(["scene", s(&under), "--no-timings", "--max-pairs", "0"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
}

/// a small glTF placing one mesh on many nodes asked for more memory than the
/// machine has (one 1M-triangle mesh on 250 nodes: 249.9M triangles, within the triangle cap)
/// and aborted. The loader now estimates what the check of the scene needs after instancing
/// (`load::CHECK_BYTES_PER_TRIANGLE`) against the memory this process may use and refuses
/// with exit 2 before expanding anything; a scene that fits loads as before.
#[test]
fn instanced_scene_beyond_available_memory_is_refused_before_expanding() {
    use base64::Engine;
    // A strip of 20,000 triangles, placed by `n` nodes 0.5 apart in z.
    let placed = |n: usize| -> Vec<u8> {
        let quads = 10_000u32;
        let mut buf: Vec<u8> = Vec::new();
        for i in 0..=quads {
            for y in [0f32, 1.0] {
                buf.extend([i as f32, y, 0.0].iter().flat_map(|x| x.to_le_bytes()));
            }
        }
        let pos_len = buf.len();
        for i in 0..quads {
            let v = 2 * i;
            buf.extend([v, v + 2, v + 1, v + 1, v + 2, v + 3].iter().flat_map(|x| x.to_le_bytes()));
        }
        let idx_len = buf.len() - pos_len;
        let data = base64::engine::general_purpose::STANDARD.encode(&buf);
        let nodes: Vec<String> = (0..n)
            .map(|i| format!(r#"{{"name":"p{i}","mesh":0,"translation":[0,0,{}]}}"#, i as f64 * 0.5))
            .collect();
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{:?}}}],"nodes":[{}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{pos_len}}},{{"buffer":0,"byteOffset":{pos_len},"byteLength":{idx_len}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":[0,0,0],"max":[{quads},1,0]}},
{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
            (0..n).collect::<Vec<_>>(),
            nodes.join(","),
            buf.len(),
            2 * (quads + 1),
            6 * quads
        )
        .into_bytes()
    };
    let d = tree();
    // 13,000 placements: 260M triangles (under the 2^28 cap), ~26 GB to check.
    let big = d.path().join("many_placements.gltf");
    std::fs::write(&big, placed(13_000)).unwrap();
    let good = root().join("meshes/fcl_rob.obj");
    // A plain `scene` keeps the instances as (mesh, matrix): within the memory there is, it is
    // admitted (a test of its own says so); beyond it, it is refused like the others.
    let plain = vec!["scene", s(&big)];
    for args in [plain.clone(), vec!["scene", s(&big), "--split-bodies"], vec![s(&good), s(&big)]] {
        for limited in [false, true] {
            if args == plain && !limited {
                continue;
            }
            let (code, err) = if limited {
                under_memory_limit(1 << 20, &args)
            } else {
                let out = bin().args(&args).output().unwrap();
                (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
            };
            assert!(!err.contains("memory allocation"), "aborted: {err}");
            assert_eq!(code, Some(2), "{args:?}: {err}");
            assert!(err.contains(s(&big)) && err.contains("260000000 triangles after instancing"), "{err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        }
    }
    // Two placements (40,000 triangles) load and check under the same 1 GiB limit.
    let small = d.path().join("two_placements.gltf");
    std::fs::write(&small, placed(2)).unwrap();
    let (code, err) = under_memory_limit(1 << 20, &["scene", s(&small), "--no-timings", "-o", "/dev/null"]);
    assert_eq!(code, Some(0), "{err}");
}
