//! Where the integration tests find their meshes.
//!
//! Meshes whose licence allows it ship with the repository (`meshes/`, `tests/data/meshes/`), so
//! a fresh clone runs every test that needs only them. Two meshes of the team's corpus may not be
//! redistributed (2CylinderEngine.glb, the Stanford bunny): they are looked up in
//! `$MESHCLASH_SHARED_MESHES`, else in `../shared/meshes` beside the repository, and a test
//! that needs one and cannot find it skips with one printed line. With `CI` set and the corpus
//! present, a mesh that is still missing fails the test instead: CI runs every test.

use std::path::{Path, PathBuf};

/// The environment variable naming a directory of corpus meshes.
pub const CORPUS_VAR: &str = "MESHCLASH_SHARED_MESHES";

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Directories searched for a mesh, in order: the in-repository copies, then the corpus.
fn search_dirs() -> Vec<PathBuf> {
    let mut dirs = vec![root().join("meshes"), root().join("tests/data/meshes")];
    dirs.extend(corpus_dir());
    dirs
}

/// The corpus directory when it exists: `$MESHCLASH_SHARED_MESHES`, else `../shared/meshes`.
pub fn corpus_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os(CORPUS_VAR) {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => root().join("../shared/meshes"),
    };
    dir.is_dir().then_some(dir)
}

fn find(name: &str) -> Option<PathBuf> {
    search_dirs().into_iter().map(|d| d.join(name)).find(|p| p.is_file())
}

/// What the test that asks for a missing mesh does: skip (one line on stderr), or fail when
/// `CI` is set and the corpus is there (so CI never skips silently).
fn missing(name: &str) {
    let test = std::thread::current().name().unwrap_or("a test").to_owned();
    let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty());
    match corpus_dir() {
        Some(dir) if ci => panic!(
            "{test}: {name} is not in {} (CI is set and the corpus is present, so nothing may skip)",
            dir.display()
        ),
        Some(dir) => {
            say(&format!("skipped {test}: {name} is not in {} nor in the repository", dir.display()))
        }
        None => say(&format!(
            "skipped {test}: {name} is not redistributable and not shipped; point {CORPUS_VAR} at a \
             directory holding it, or put the corpus at ../shared/meshes"
        )),
    }
}

/// One line straight to the process's stderr: the test harness captures `eprintln!` of passing
/// tests, and a skip must show in a plain `cargo test`.
pub fn say(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// A mesh by file name, or `None` after printing why the calling test skips. For meshes that
/// only the corpus has: `let Some(p) = corpus("2CylinderEngine.glb") else { return };`.
pub fn corpus(name: &str) -> Option<PathBuf> {
    let found = find(name);
    if found.is_none() {
        missing(name);
    }
    found
}

/// A mesh that ships with the repository (or, for a corpus mesh, is known to be present). Panics
/// with the places searched when it is absent: a shipped mesh missing is a broken checkout.
pub fn shared(name: &str) -> PathBuf {
    find(name).unwrap_or_else(|| {
        let dirs: Vec<String> = search_dirs().iter().map(|d| d.display().to_string()).collect();
        panic!("{name} not found in {}", dirs.join(", "))
    })
}

/// `shared(name)` as a string, for command lines.
pub fn shared_str(name: &str) -> String {
    shared(name).display().to_string()
}

/// OBJ text with one `o` per named axis-aligned box (min corner, max corner): 8 vertices and 12
/// outward-facing triangles each, the boxes numbered on in file order.
pub fn boxes_obj_text(boxes: &[(&str, [f64; 3], [f64; 3])]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    for (k, (name, lo, hi)) in boxes.iter().enumerate() {
        writeln!(s, "o {name}").unwrap();
        for i in 0..8 {
            let c = |axis: usize| if i >> axis & 1 == 1 { hi[axis] } else { lo[axis] };
            writeln!(s, "v {} {} {}", c(0), c(1), c(2)).unwrap();
        }
        let o = 8 * k + 1;
        for q in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
            let [a, b, c, d] = q.map(|v| v + o);
            writeln!(s, "f {a} {b} {c}\nf {a} {c} {d}").unwrap();
        }
    }
    s
}

/// [`boxes_obj_text`] written to `dir/file`; returns the path as a string.
pub fn boxes_obj(dir: &Path, file: &str, boxes: &[(&str, [f64; 3], [f64; 3])]) -> String {
    let path = dir.join(file);
    std::fs::write(&path, boxes_obj_text(boxes)).unwrap();
    path.display().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_mesh_is_found_in_the_repository() {
        for name in ["fcl_env.obj", "fcl_rob.obj", "pins.glb", "shared.STL", "Box.glb", "counter.unitsmm.STL"]
        {
            let p = shared(name);
            assert!(
                p.starts_with(root().join("meshes")) || p.starts_with(root().join("tests/data/meshes")),
                "{p:?}"
            );
        }
    }

    #[test]
    fn a_name_found_nowhere_is_none() {
        let name = "no-such-mesh-anywhere.glb";
        // With CI set and the corpus present this would panic by design; test the lookup itself.
        assert_eq!(find(name), None);
        assert!(Path::new(&shared_str("pins.glb")).is_file());
    }
}
