//! The module graph of `src/`, read from `crate::` paths (issue 13): the lower layers import
//! nothing above them. Run with `cargo test --test layers -- --nocapture` to print the graph.
//!
//! Not yet enforced (still cyclic, see README "Layout"): `cli`, `clash_set`, `output`, `report`,
//! `check` and `bench`; unit-test code (`#[cfg(test)]` modules and `tests.rs` files) may use the
//! test fixtures in `bench::gen` until they move.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Top-level module of a file under `src/` (`src/check/query.rs` -> `check`).
fn top_module(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next().unwrap().as_os_str().to_string_lossy().into_owned();
    first.trim_end_matches(".rs").to_string()
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `crate::x` names used in non-comment, non-test lines of `text`.
fn crate_refs(text: &str, is_test_file: bool) -> BTreeSet<String> {
    let mut refs = BTreeSet::new();
    if is_test_file {
        return refs;
    }
    for line in text.lines() {
        let code = line.split("//").next().unwrap();
        if line.trim_start().starts_with("#[cfg(test)]") {
            break; // unit tests sit at the end of a file by convention
        }
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            rest = &rest[i + "crate::".len()..];
            let name: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                refs.insert(name);
            }
        }
    }
    refs
}

fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let m = top_module(&src, &f);
        if m == "lib" || m == "main" {
            continue;
        }
        let is_test =
            f.file_name().is_some_and(|n| n == "tests.rs" || n.to_string_lossy().ends_with("_tests.rs"));
        let refs = crate_refs(&std::fs::read_to_string(&f).unwrap(), is_test);
        let deps = g.entry(m.clone()).or_default();
        deps.extend(refs.into_iter().filter(|r| *r != m));
    }
    g
}

/// Modules reachable from `m`, `m` excluded unless there is a cycle through it.
fn reachable(g: &BTreeMap<String, BTreeSet<String>>, m: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut stack: Vec<String> = g.get(m).map(|d| d.iter().cloned().collect()).unwrap_or_default();
    while let Some(x) = stack.pop() {
        if seen.insert(x.clone()) {
            stack.extend(g.get(&x).into_iter().flatten().cloned());
        }
    }
    seen
}

#[test]
fn lower_layers_import_nothing_above_them() {
    let g = graph();
    for (m, d) in &g {
        println!("{m} -> {}", d.iter().cloned().collect::<Vec<_>>().join(" "));
    }
    // The one-way core, lowest first: each may use only the ones before it.
    let core = ["error", "geom", "scene", "load", "narrow", "bvh"];
    for (i, m) in core.iter().enumerate() {
        assert!(g.contains_key(*m), "src/{m} is gone: update this test and README's Layout");
        let below: BTreeSet<&str> = core[..i].iter().copied().collect();
        for dep in reachable(&g, m) {
            assert!(
                below.contains(dep.as_str()),
                "src/{m} reaches crate::{dep}, which is not below it in {core:?}"
            );
        }
    }
}

#[test]
fn the_reader_sees_cycles() {
    // The checker itself: a made-up cyclic graph is caught.
    let mut g = BTreeMap::new();
    g.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    g.insert("b".to_string(), BTreeSet::from(["a".to_string()]));
    assert!(reachable(&g, "a").contains("a"));
    assert_eq!(
        crate_refs("use crate::geom::Aabb; // crate::cli\n#[cfg(test)]\nuse crate::bench;", false),
        BTreeSet::from(["geom".to_string()])
    );
}
