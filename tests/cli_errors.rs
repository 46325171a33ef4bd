//! Typed errors: the one-line messages of the command line, byte for byte, through
//! the real binary. The errors became data (path, location, problem); what a user reads did not
//! change. Each case: exit code 2 and exactly `meshclash: error: {message}\n` on stderr.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn shipped(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("meshes").join(name).display().to_string()
}

fn error_of(args: &[&str]) -> String {
    let out = Command::cargo_bin("meshclash").unwrap().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    assert!(out.stdout.is_empty(), "{args:?}");
    String::from_utf8(out.stderr).unwrap()
}

fn line(msg: &str) -> String {
    format!("meshclash: error: {msg}\n")
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p.display().to_string()
}

/// A binary STL of `tris` triangles.
fn binary_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for v in t {
            for c in v {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

#[test]
fn input_file_messages_are_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = shipped("fcl_rob.obj");
    let check = |a: &str, expected: &str| {
        assert_eq!(error_of(&[a, &good]), line(expected), "{a}");
    };
    let missing = d.join("missing.stl").display().to_string();
    check(&missing, &format!("{missing}: cannot read file: No such file or directory"));
    let sub = d.join("sub.stl");
    std::fs::create_dir(&sub).unwrap();
    let sub = sub.display().to_string();
    check(&sub, &format!("{sub}: not a regular file (a directory); meshclash reads only regular files"));
    let ply = write(d, "x.ply", b"ply\n");
    check(&ply, &format!("{ply}: unknown extension '.ply' (expected .obj, .stl, .gltf or .glb)"));
    let noext = write(d, "noext", b"v 0 0 0\n");
    check(&noext, &format!("{noext}: no file extension (expected .obj, .stl, .gltf or .glb)"));
    let empty = write(d, "empty.stl", b"");
    check(&empty, &format!("{empty}: file is empty"));

    let mut cut = binary_stl(&[TRI, TRI]);
    cut.pop();
    let cut = write(d, "cut.stl", &cut);
    check(
        &cut,
        &format!(
            "{cut}: truncated binary STL: header declares 2 triangles (needs 184 bytes) but the file has 183 bytes"
        ),
    );
    let mut long = binary_stl(&[TRI]);
    long.extend_from_slice(&[0, 0, 0]);
    let long = write(d, "long.stl", &long);
    check(
        &long,
        &format!(
            "{long}: binary STL size mismatch: header declares 1 triangles (needs 134 bytes) but the file has \
             137 bytes (3 extra)"
        ),
    );
    let mut nan = [TRI, TRI];
    nan[1][2][1] = f32::NAN;
    let nan = write(d, "nan.stl", &binary_stl(&nan));
    check(&nan, &format!("{nan}: triangle 1 vertex 2 has a non-finite coordinate (NaN)"));
    let png = write(d, "png.stl", &[b"\x89PNG\r\n\x1a\n".as_slice(), &[7u8; 300]].concat());
    check(&png, &format!("{png}: not an STL file (looks like PNG)"));

    let ascii = "solid one\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   \
                 vertex 0 1 0\n  endloop\n endfacet\nendsolid one\n";
    let wobble = write(d, "wobble.stl", ascii.replace("endloop", "wobble").as_bytes());
    check(&wobble, &format!("{wobble}: line 7: unexpected 'wobble' in ASCII STL"));
    let inf = write(d, "inf.stl", ascii.replace("vertex 1 0 0", "vertex 1 -inf 0").as_bytes());
    check(&inf, &format!("{inf}: line 5: vertex has a non-finite coordinate (-inf)"));
    let short = write(d, "short.stl", ascii.replace("   vertex 0 1 0\n", "").as_bytes());
    check(&short, &format!("{short}: line 7: facet starting at line 2 has 2 vertices (needs 3)"));
    let eof = write(d, "eof.stl", ascii.replace(" endfacet\nendsolid one\n", "").as_bytes());
    check(&eof, &format!("{eof}: unexpected end of file inside the facet starting at line 2"));
    let outside =
        write(d, "outside.stl", ascii.replacen(" facet normal", " endfacet\n facet normal", 1).as_bytes());
    check(&outside, &format!("{outside}: line 2: 'endfacet' outside a facet"));
    let none = write(d, "none.stl", b"solid empty\nendsolid empty\n");
    check(&none, &format!("{none}: no triangles"));

    let text = write(d, "text.gltf", b"hello world");
    check(
        &text,
        &format!(
            "{text}: not a glTF file: expected JSON starting with '{{' or the GLB magic 'glTF', found 'hello wo'"
        ),
    );
    let glb = write(d, "cut.glb", b"glTF\x02\0\0");
    check(&glb, &format!("{glb}: truncated GLB: 7 bytes, the header alone needs 12"));
    let nul = write(d, "nul.obj", b"v 0 0 0\n\0");
    check(&nul, &format!("{nul}: not an OBJ text file: NUL byte at byte 8 (binary data)"));
}

/// A glTF with one triangle primitive whose positions and indices are in `tri.bin`.
fn gltf(dir: &Path, indices: [u16; 3], extra: &str) -> String {
    let mut bin = Vec::new();
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin.extend_from_slice(&[0, 0]);
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, {extra}
  "buffers": [{{"uri": "tri.bin", "byteLength": 44}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "nodes": [{{"mesh": 0}}],
  "scenes": [{{"nodes": [0]}}]
}}"#
    );
    write(dir, "tri.gltf", json.as_bytes())
}

#[test]
fn gltf_messages_are_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = shipped("fcl_rob.obj");
    let ok = gltf(d, [0, 1, 2], "");
    // The control: this file loads.
    let out = Command::cargo_bin("meshclash").unwrap().args([&ok, &good]).output().unwrap();
    assert_ne!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    let bad = gltf(d, [0, 1, 5], "");
    assert_eq!(
        error_of(&[&bad, &good]),
        line(&format!("{bad}: mesh 0 primitive 0: index 2 refers to vertex 5 but there are 3 vertices"))
    );
    let required = gltf(d, [0, 1, 2], r#""extensionsRequired": ["KHR_draco_mesh_compression"],"#);
    assert_eq!(
        error_of(&[&required, &good]),
        line(&format!(
            "{required}: glTF requires extension 'KHR_draco_mesh_compression', which is not supported \
             (Draco-compressed geometry cannot be decoded)"
        ))
    );
}

#[test]
fn usage_and_output_messages_are_unchanged() {
    let (a, b) = (shipped("fcl_env.obj"), shipped("fcl_rob.obj"));
    let usage = |flags: &[&str], expected: &str| {
        let args: Vec<&str> = [a.as_str(), b.as_str()].into_iter().chain(flags.iter().copied()).collect();
        assert_eq!(error_of(&args), line(&format!("usage: {expected}")), "{flags:?}");
    };
    usage(&["--leaf-size", "0"], "--leaf-size must be 1..=64, got 0");
    usage(
        &["--touch-tolerance", "abc"],
        "--touch-tolerance must be a finite number >= 0, optionally with a 'rel' suffix (e.g. 0.01 or \
         1e-6rel), got 'abc'",
    );
    usage(&["--transform-a", "1,2,3"], "--transform-a takes 12 or 16 numbers, got 3");
    usage(
        &["--transform-b", "1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,1"],
        "--transform-b: the last row must be 0,0,0,1 (affine only)",
    );
    usage(&["--translate-a", "1,x,3"], "--translate-a: 'x' is not a finite number");
    usage(&["--translate-b", "1,2"], "--translate-b takes x,y,z, got 2 numbers");
    usage(&["--scale-a", "0"], "--scale-a must be a finite number > 0, got 0");
    usage(&["--distance-rel-err=-1"], "--distance-rel-err must be a finite number >= 0, got -1");
    usage(&["--fail-on", "new"], "--fail-on new needs --baseline REPORT");
    usage(
        &["--detail", "parts", "--html", "x.html"],
        "--html needs the triangle pairs that --detail parts does not keep: drop one of them",
    );

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().display().to_string();
    assert_eq!(
        error_of(&[&a, &b, "-o", &out]),
        line(&format!("{out}: cannot write report: -o names a directory"))
    );
    let into_input = error_of(&[&a, &b, "-o", &b]);
    assert_eq!(
        into_input,
        line(&format!(
            "{b}: cannot write report: -o names the input {b} (the same file); refusing to overwrite an input"
        ))
    );
    let nowhere = dir.path().join("no/such/dir/r.json").display().to_string();
    let parent = dir.path().join("no/such/dir").display().to_string();
    assert_eq!(
        error_of(&[&a, &b, "-o", &nowhere]),
        line(&format!(
            "{nowhere}: cannot write report: directory {parent}: No such file or directory (os error 2)"
        ))
    );
    let baseline = dir.path().join("base.json").display().to_string();
    assert_eq!(
        error_of(&[&a, &b, "--baseline", &baseline]),
        line(&format!("{baseline}: cannot read baseline: No such file or directory"))
    );
}

#[test]
fn clash_set_messages_are_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (shipped("fcl_env.obj"), shipped("fcl_rob.obj"));
    let set = |text: &str| write(dir.path(), "set.json", text.as_bytes());
    let run = |path: &str| error_of(&["clash-set", path]);
    let f = set(&format!(
        r#"{{"version": 1, "checks": [{{"name": "c1", "a": "{a}", "b": "{b}", "leaf_size": 0}}]}}"#
    ));
    assert_eq!(run(&f), line(&format!("{f}: check 'c1': --leaf-size must be 1..=64, got 0")));
    let f = set(&format!(r#"{{"version": 1, "checks": [{{"a": "{a}", "b": "{b}"}}]}}"#));
    assert_eq!(run(&f), line(&format!("{f}: check #1: has no \"name\"")));
    let f = set(r#"{"version": 2, "checks": []}"#);
    assert_eq!(run(&f), line(&format!("{f}: version 2 is not supported (this meshclash reads version 1)")));
    let missing = dir.path().join("gone.stl").display().to_string();
    let f = set(&format!(r#"{{"version": 1, "checks": [{{"name": "c1", "a": "{missing}", "b": "{b}"}}]}}"#));
    assert_eq!(
        run(&f),
        line(&format!("{f}: check 'c1': {missing}: cannot read file: No such file or directory"))
    );
}
