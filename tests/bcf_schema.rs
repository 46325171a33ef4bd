//! Every file of a `--bcf` archive, both versions, validated against buildingSMART's official
//! schemas (`tests/data/bcf-xsd`, shipped verbatim) with `xmllint --schema`; part names holding
//! control characters still make well-formed, valid XML, and the text summary prints them
//! escaped.

use assert_cmd::Command;
use std::io::Read;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn xmllint() -> bool {
    let ok =
        std::process::Command::new("xmllint").arg("--version").output().is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("skipping: xmllint not found (Debian package libxml2-utils)");
    }
    ok
}

/// Runs meshclash with `--bcf` in `dir`; the archive's files as (name, bytes).
fn archive(dir: &Path, args: &[&str]) -> Vec<(String, Vec<u8>)> {
    let bcf = dir.join("r.bcfzip");
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .current_dir(dir)
        .args(args)
        .args(["-q", "--no-timings", "-o", "/dev/null", "--bcf"])
        .arg(&bcf)
        .output()
        .unwrap();
    assert!(out.status.code().unwrap() < 2, "{}", String::from_utf8_lossy(&out.stderr));
    let mut z = zip::ZipArchive::new(std::fs::File::open(&bcf).unwrap()).unwrap();
    (0..z.len())
        .map(|i| {
            let mut f = z.by_index(i).unwrap();
            let mut b = Vec::new();
            f.read_to_end(&mut b).unwrap();
            (f.name().unwrap().to_string(), b)
        })
        .collect()
}

/// The schema of an archive member.
fn schema(name: &str) -> &'static str {
    match name.rsplit('/').next().unwrap() {
        "bcf.version" => "version.xsd",
        "markup.bcf" => "markup.xsd",
        "extensions.xml" => "extensions.xsd",
        n if n.ends_with(".bcfv") => "visinfo.xsd",
        n => panic!("unexpected archive member {n}"),
    }
}

/// Validates every member with xmllint; returns how many files were validated.
fn validate(files: &[(String, Vec<u8>)], version: &str) -> usize {
    let d = tempfile::tempdir().unwrap();
    let xsd = root().join("tests/data/bcf-xsd").join(version);
    for (k, (name, bytes)) in files.iter().enumerate() {
        let f = d.path().join(format!("{k}.xml"));
        std::fs::write(&f, bytes).unwrap();
        let out = std::process::Command::new("xmllint")
            .args(["--noout", "--schema"])
            .arg(xsd.join(schema(name)))
            .arg(&f)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "BCF {version} {name} fails {}: {}\n{}",
            schema(name),
            String::from_utf8_lossy(&out.stderr),
            String::from_utf8_lossy(bytes)
        );
    }
    files.len()
}

#[test]
fn both_versions_validate_against_the_official_schemas() {
    if !xmllint() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let pins = root().join("meshes/pins.glb");
    let mut inputs = vec![vec!["scene".to_string(), pins.display().to_string()]];
    let engine = root().join("../shared/meshes/2CylinderEngine.glb");
    if engine.is_file() {
        inputs.push(vec!["scene".into(), engine.display().to_string()]);
    } else {
        eprintln!("skipping the engine: ../shared/meshes/2CylinderEngine.glb not found");
    }
    for args in &inputs {
        for (version, extra) in [("2.1", 1), ("3.0", 2)] {
            let mut a: Vec<&str> = args.iter().map(String::as_str).collect();
            a.extend(["--bcf-version", version]);
            let files = archive(d.path(), &a);
            let viewpoints = files.iter().filter(|(n, _)| n.ends_with(".bcfv")).count();
            assert!(viewpoints > 0, "{args:?}: no topics");
            assert_eq!(validate(&files, version), extra + 2 * viewpoints);
        }
    }
}

/// Two overlapping boxes named with escape sequences and other control characters (OBJ `o`).
fn hostile_names(dir: &Path) -> (PathBuf, PathBuf) {
    let cube = |name: &str, at: f64| {
        let mut s = format!("o {name}\n");
        for k in 0..8 {
            let c = |b: usize| at + ((k >> b) & 1) as f64;
            s.push_str(&format!("v {} {} {}\n", c(0), c(1), c(2)));
        }
        for f in ["1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6"] {
            s.push_str(&format!("f {f}\n"));
        }
        s
    };
    let (a, b) = (dir.join("a.obj"), dir.join("b.obj"));
    std::fs::write(&a, cube("bolt\u{1b}[2K\u{1b}[1A\rmeshclash: CLEAR\u{7}", 0.0)).unwrap();
    std::fs::write(&b, cube("nut\u{1}\u{8}\u{b}\u{c}\u{1f}<&>\"", 0.5)).unwrap();
    (a, b)
}

#[test]
fn control_characters_in_part_names_make_valid_xml() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = hostile_names(d.path());
    let (a, b) = (a.display().to_string(), b.display().to_string());
    for version in ["2.1", "3.0"] {
        let files = archive(d.path(), &[&a, &b, "--bcf-version", version]);
        for (name, bytes) in &files {
            let text = std::str::from_utf8(bytes).unwrap();
            roxmltree::Document::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!bytes.iter().any(|&c| c < 0x20 && !b"\t\n\r".contains(&c)), "{name}: raw control");
        }
        let vp = files.iter().find(|(n, _)| n.ends_with(".bcfv")).unwrap();
        let vp = String::from_utf8(vp.1.clone()).unwrap();
        assert!(vp.contains("bolt\\u{1b}[2K"), "{vp}");
        if xmllint() {
            validate(&files, version);
        }
    }
}

#[test]
fn text_summary_escapes_control_characters_in_names() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = hostile_names(d.path());
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .args([&a, &b])
        .args(["--format", "text", "--no-timings"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(!text.chars().any(|c| c.is_control() && c != '\n'), "raw control character in:\n{text}");
    assert!(text.contains("bolt\\u{1b}[2K\\u{1b}[1A\\u{d}meshclash: CLEAR\\u{7}"), "{text}");
    assert!(text.starts_with("meshclash: CLASH"), "{text}");
}
