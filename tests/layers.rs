//! The module graph of `src/`, read from `crate::` paths: the lower layers import
//! nothing above them, and no two top-level modules import each other, directly or through
//! others, except the cycles listed in [`KNOWN_CYCLES`] (which fail the test when they grow,
//! when a new one appears, or when one is gone and still listed). Run with
//! `cargo test --test suite layers -- --nocapture` to print the graph and its cycles.
//!
//! Two crates share `src/`: the library (`src/lib.rs` and every top-level module but `app`)
//! and the binary (`src/main.rs` and `src/app/`, the app layer: clap, the spinner). The binary
//! may use the library (`meshclash::`), never the reverse; inside `src/app/`, the submodules
//! name each other through `super::`, and their graph has no cycle either.
//!
//! Unit-test code (`#[cfg(test)]` blocks and `tests.rs` files) is not counted; the test support
//! of `src/testing/` is (it is a module like the others).

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
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let code = line.split("//").next().unwrap();
        if line.trim_start().starts_with("#[cfg(test)]") {
            // `#[cfg(test)] mod tests;` only declares a file (read as a test file); an inline
            // test block sits at the end of a file by convention.
            let next = lines[i + 1..].iter().map(|l| l.trim()).find(|l| !l.is_empty()).unwrap_or("");
            if next.starts_with("mod ") && next.ends_with(';') {
                continue;
            }
            break;
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
        if m == "lib" || m == "main" || m == APP {
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

/// The binary's own module tree under `src/` (with `src/main.rs`).
const APP: &str = "app";

/// The graph of the binary's app layer: `src/app/x.rs` -> the sibling modules it names through
/// `super::`.
fn app_graph() -> BTreeMap<String, BTreeSet<String>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(APP);
    let mut files = Vec::new();
    rust_files(&dir, &mut files);
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let m = top_module(&dir, &f);
        if m == "mod" {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        let refs = crate_refs(&text.replace("super::", "crate::"), false);
        g.entry(m.clone()).or_default().extend(refs.into_iter().filter(|r| *r != m && *r != "super"));
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

/// Import cycles between top-level modules that exist today, each as its sorted member list
/// (a strongly connected component of the graph); remove an entry here when its cycle is gone
/// (the test says so).
const KNOWN_CYCLES: &[&[&str]] = &[];

/// Strongly connected components that contain a cycle (the import cycles), each sorted, in
/// sorted order.
fn cycles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = Vec::new();
    let mut placed = BTreeSet::new();
    for m in g.keys() {
        if placed.contains(m) {
            continue;
        }
        let from_m = reachable(g, m);
        if !from_m.contains(m) {
            continue;
        }
        let scc: Vec<String> =
            from_m.iter().filter(|x| *x == m || reachable(g, x).contains(m)).cloned().collect();
        placed.extend(scc.iter().cloned());
        out.push(scc);
    }
    out.sort();
    out
}

#[test]
fn no_new_import_cycle_between_top_level_modules() {
    let g = graph();
    let found = cycles(&g);
    println!("import cycles between top-level modules: {}", found.len());
    for c in &found {
        // One concrete loop per cycle, to show where to cut: the direct edges inside it.
        let edges: Vec<String> = c
            .iter()
            .flat_map(|a| g[a].iter().filter(|b| c.contains(b)).map(move |b| format!("{a}->{b}")))
            .collect();
        println!("  {{{}}}: {}", c.join(", "), edges.join(" "));
    }
    let known: Vec<Vec<String>> =
        KNOWN_CYCLES.iter().map(|c| c.iter().map(|s| s.to_string()).collect()).collect();
    for c in &found {
        assert!(
            known.contains(c),
            "new or grown import cycle between top-level modules: {{{}}} (known: {known:?}); \
             cut one of its edges (see the printed graph: --nocapture)",
            c.join(", ")
        );
    }
    for k in &known {
        assert!(
            found.contains(k),
            "known cycle {{{}}} is gone or smaller: update KNOWN_CYCLES in tests/layers.rs",
            k.join(", ")
        );
    }
}

#[test]
fn the_library_never_uses_the_binary() {
    // The app layer is the binary's: the library does not declare it, and no library file
    // names it (it could not compile if one did, but a `pub mod app` in lib.rs would).
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    assert!(!lib
        .lines()
        .any(|l| l.trim_start().starts_with("pub mod app") || l.trim_start().starts_with("mod app")));
    let main = std::fs::read_to_string(src.join("main.rs")).unwrap();
    assert!(main.lines().any(|l| l.trim() == "mod app;"), "src/main.rs declares the app layer");
    let g = graph();
    assert!(!g.contains_key(APP));
    for (m, deps) in &g {
        assert!(!deps.contains(APP), "src/{m} names crate::{APP}, the binary's module tree");
    }
    // And the library keeps clap and indicatif out of its code (so out of its public API).
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    for f in files.iter().filter(|f| top_module(&src, f) != APP && top_module(&src, f) != "main") {
        let text = std::fs::read_to_string(f).unwrap();
        for dep in ["clap::", "clap_complete", "clap_mangen", "indicatif"] {
            assert!(!text.contains(dep), "{} uses {dep}: the app layer belongs in src/app/", f.display());
        }
    }
}

#[test]
fn the_report_is_a_projection_and_outputs_read_it() {
    // The wire format does not compute: it names neither the loaders, the trees nor the
    // narrow phase (the pipeline computes; `pipeline::report::build` projects).
    let g = graph();
    let report = reachable(&g, "report");
    for below in ["bvh", "load", "narrow", "pipeline", "output"] {
        assert!(!g["report"].contains(below), "src/report names crate::{below}");
    }
    assert!(!report.contains("pipeline"), "src/report reaches crate::pipeline");
    // Outputs are projections: nothing under src/output takes a report to change it.
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src.join("output"), &mut files);
    rust_files(&src.join("report"), &mut files);
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let code: String = text.lines().map(|l| l.split("//").next().unwrap()).collect::<Vec<_>>().join("\n");
        assert!(
            !code.contains("&mut Report") && !code.contains("&mut crate::report::Report"),
            "{} changes a report",
            f.display()
        );
    }
    // One pipeline: the binary and the embedding API reach the check through it.
    assert!(g["api"].contains("pipeline"), "src/api.rs goes through crate::pipeline");
    let app = std::fs::read_to_string(src.join("app/run.rs")).unwrap();
    assert!(app.contains("meshclash::pipeline::run("), "the app layer runs the pipeline");
    assert!(!app.contains("assembly::run("), "the app layer does not assemble a check itself");
}

#[test]
fn the_app_layer_has_no_import_cycle() {
    let g = app_graph();
    for (m, d) in &g {
        println!("app::{m} -> {}", d.iter().cloned().collect::<Vec<_>>().join(" "));
    }
    assert!(g.contains_key("args") && g.contains_key("run"), "src/app/ is gone: update this test");
    let found = cycles(&g);
    assert!(found.is_empty(), "import cycles inside src/app/: {found:?}");
}

#[test]
fn the_reader_sees_cycles() {
    // The checker itself: a made-up cyclic graph is caught.
    let mut g = BTreeMap::new();
    g.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    g.insert("b".to_string(), BTreeSet::from(["a".to_string()]));
    assert!(reachable(&g, "a").contains("a"));
    g.insert("c".to_string(), BTreeSet::from(["a".to_string()]));
    g.insert("d".to_string(), BTreeSet::from(["d".to_string(), "c".to_string()]));
    assert_eq!(cycles(&g), vec![vec!["a".to_string(), "b".to_string()], vec!["d".to_string()]]);
    assert_eq!(
        crate_refs("use crate::geom::Aabb; // crate::cli\n#[cfg(test)]\nuse crate::bench;", false),
        BTreeSet::from(["geom".to_string()])
    );
    assert_eq!(
        crate_refs(
            "#[cfg(test)]\nmod tests;\n\nfn f() { crate::bvh::x() }\n#[cfg(test)]\nmod t {\n crate::cli",
            false
        ),
        BTreeSet::from(["bvh".to_string()])
    );
}

/// `autotests = false` (one test binary): a `tests/*.rs` file that `tests/suite.rs`
/// does not declare would silently never run.
#[test]
fn every_test_file_is_in_the_suite() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let suite = std::fs::read_to_string(dir.join("suite.rs")).unwrap();
    let mut missing = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let (Some(stem), Some("rs")) =
            (p.file_stem().and_then(|s| s.to_str()), p.extension().and_then(|s| s.to_str()))
        else {
            continue;
        };
        if stem != "suite" && !suite.contains(&format!("#[path = \"{stem}.rs\"]\nmod {stem};")) {
            missing.push(format!("#[path = \"{stem}.rs\"]\nmod {stem};"));
        }
    }
    assert!(missing.is_empty(), "add to tests/suite.rs:\n{}", missing.join("\n"));
}
