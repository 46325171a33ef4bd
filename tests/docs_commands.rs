//! Every command in the documentation runs as written.
//!
//! The fenced blocks tagged `sh` in README.md, CONTRIBUTING.md and docs/*.md are run, command by
//! command, through `bash` in a scratch directory laid out like the repository root (copies of
//! `meshes/` and `tests/data/meshes/`), with the built `meshclash` first on `PATH`. Each command
//! must exit 0, or the code its line declares with a trailing `# exit N`. Commands of one file
//! share the directory, in document order (a baseline written by one command is read by the
//! next). Block tags after `sh`:
//!
//! * `no-run`: installs software or runs the test suites (`cargo install`, `bash .ci/test`); shown,
//!   never run;
//! * `corpus`: needs the non-redistributable meshes under `../shared/meshes` (found as the tests
//!   find them, `tests/common.rs`); skipped with one line when they are absent.
//!
//! A block tagged `text output` right after a runnable block is what the first command of that
//! block prints on stdout: the lines up to a line `...` must match exactly.

use crate::common;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// One command of a `sh` block.
#[derive(Debug, PartialEq)]
struct Cmd {
    line: usize,
    text: String,
    exit: i32,
}

/// What a documentation file asks to be run, in order.
#[derive(Debug, PartialEq)]
enum Item {
    Block { line: usize, corpus: bool, cmds: Vec<Cmd> },
    Output { line: usize, lines: Vec<String> },
}

/// The expected exit code of a command line: a trailing `# exit N`, else 0.
fn declared_exit(line: &str) -> Result<i32, String> {
    match line.rfind("# exit ") {
        None => Ok(0),
        Some(i) => line[i + 7..].trim().parse().map_err(|_| format!("bad exit declaration in `{line}`")),
    }
}

/// The runnable blocks and expected outputs of one Markdown text.
fn parse(md: &str) -> Result<Vec<Item>, String> {
    let lines: Vec<&str> = md.lines().collect();
    let mut items = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let fence = lines[i].trim_start();
        let Some(info) = fence.strip_prefix("```") else {
            i += 1;
            continue;
        };
        let start = i + 1;
        let mut end = start;
        while end < lines.len() && !lines[end].trim_start().starts_with("```") {
            end += 1;
        }
        if end == lines.len() {
            return Err(format!("line {}: unclosed code block", i + 1));
        }
        let words: Vec<&str> =
            info.split(|c: char| c.is_whitespace() || c == ',').filter(|w| !w.is_empty()).collect();
        let body = &lines[start..end];
        match words.as_slice() {
            ["sh", tags @ ..] => {
                if let Some(t) = tags.iter().find(|t| !matches!(**t, "no-run" | "corpus")) {
                    return Err(format!("line {}: unknown sh block tag `{t}`", i + 1));
                }
                if !tags.contains(&"no-run") {
                    items.push(Item::Block {
                        line: i + 1,
                        corpus: tags.contains(&"corpus"),
                        cmds: commands(body, start)?,
                    });
                }
            }
            ["text", "output"] => {
                let lines = body.iter().take_while(|l| l.trim() != "...").map(|l| l.to_string()).collect();
                items.push(Item::Output { line: i + 1, lines });
            }
            _ => {}
        }
        i = end + 1;
    }
    Ok(items)
}

/// The commands of a block body whose first line is line `first` (0-based) of the file:
/// comments and blank lines dropped, `\` continuations joined.
fn commands(body: &[&str], first: usize) -> Result<Vec<Cmd>, String> {
    let mut cmds = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (k, raw) in body.iter().enumerate() {
        let (line, mut text) = pending.take().unwrap_or((first + k + 1, String::new()));
        if text.is_empty() && (raw.trim().is_empty() || raw.trim_start().starts_with('#')) {
            continue;
        }
        if let Some(head) = raw.strip_suffix('\\') {
            text.push_str(head);
            pending = Some((line, text));
            continue;
        }
        text.push_str(raw);
        let exit = declared_exit(&text).map_err(|e| format!("line {line}: {e}"))?;
        cmds.push(Cmd { line, text, exit });
    }
    if let Some((line, _)) = pending {
        return Err(format!("line {line}: continuation at the end of the block"));
    }
    Ok(cmds)
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
        }
    }
}

/// The documentation files whose commands are run.
fn doc_files() -> Vec<PathBuf> {
    let root = common::root();
    let mut files = vec![root.join("README.md"), root.join("CONTRIBUTING.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

/// Runs every command of one file; returns the failures (one line each) and the count run.
fn run_file(doc: &Path, corpus: Option<&Path>) -> (Vec<String>, usize) {
    let name = doc.strip_prefix(common::root()).unwrap().display().to_string();
    let items = parse(&std::fs::read_to_string(doc).unwrap()).unwrap_or_else(|e| panic!("{name}: {e}"));
    let scratch = tempfile::tempdir().unwrap();
    let work = scratch.path().join("work");
    copy_dir(&common::root().join("meshes"), &work.join("meshes"));
    copy_dir(&common::root().join("tests/data/meshes"), &work.join("tests/data/meshes"));
    if let Some(dir) = corpus {
        std::fs::create_dir_all(scratch.path().join("shared")).unwrap();
        std::os::unix::fs::symlink(dir, scratch.path().join("shared/meshes")).unwrap();
    }
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_meshclash")).parent().unwrap().to_path_buf();
    let path = std::env::join_paths(
        std::iter::once(bin_dir).chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .unwrap();
    let (mut failures, mut ran) = (Vec::new(), 0);
    let mut last_first_stdout: Option<String> = None;
    for item in items {
        match item {
            Item::Block { line, corpus: needs, cmds } => {
                last_first_stdout = None;
                if needs && corpus.is_none() {
                    common::say(&format!(
                        "skipped {name}:{line}: needs the corpus meshes in ../shared/meshes or ${}",
                        common::CORPUS_VAR
                    ));
                    continue;
                }
                for (k, c) in cmds.iter().enumerate() {
                    let mut cmd = Command::new("bash");
                    cmd.args(["-o", "pipefail", "-c", &c.text]).current_dir(&work).env("PATH", &path);
                    cmd.env("NO_COLOR", "1").stdin(Stdio::null());
                    for v in [
                        "JOB_COMPLETION_INDEX",
                        "AWS_BATCH_JOB_ARRAY_INDEX",
                        "CLOUD_RUN_TASK_INDEX",
                        "SLURM_ARRAY_TASK_ID",
                    ] {
                        cmd.env_remove(v);
                    }
                    let out = cmd.output().unwrap();
                    ran += 1;
                    let code = out.status.code().unwrap_or(-1);
                    if code != c.exit {
                        let err = String::from_utf8_lossy(&out.stderr);
                        let last = err.lines().last().unwrap_or("").to_owned();
                        failures.push(format!(
                            "{name}:{}: exit {code}, declared {}: {} [{last}]",
                            c.line, c.exit, c.text
                        ));
                    }
                    if k == 0 {
                        last_first_stdout = Some(String::from_utf8_lossy(&out.stdout).into_owned());
                    }
                }
            }
            Item::Output { line, lines } => {
                let Some(stdout) = last_first_stdout.take() else {
                    if !failures.iter().any(|f| f.starts_with(&name)) {
                        common::say(&format!("skipped {name}:{line}: output of a block that did not run"));
                    }
                    continue;
                };
                let got: Vec<&str> = stdout.lines().take(lines.len()).collect();
                if got != lines.iter().map(String::as_str).collect::<Vec<_>>() {
                    failures.push(format!(
                        "{name}:{line}: the shown output differs from the real one:\n{stdout}"
                    ));
                }
            }
        }
    }
    (failures, ran)
}

#[test]
fn every_documented_command_runs_as_written() {
    let corpus = common::corpus_dir();
    let (mut failures, mut ran) = (Vec::new(), 0);
    for doc in doc_files() {
        let (f, n) = run_file(&doc, corpus.as_deref());
        failures.extend(f);
        ran += n;
    }
    assert!(
        failures.is_empty(),
        "{} of {ran} documented commands failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(ran >= 30, "only {ran} documented commands ran");
}

#[test]
fn readme_is_short_and_starts_with_the_install_and_test_commands() {
    let readme = std::fs::read_to_string(common::root().join("README.md")).unwrap();
    assert!(readme.len() <= 20 * 1024, "README.md is {} bytes, more than 20 KB", readme.len());
    let first_screen: Vec<&str> = readme.lines().take(30).collect();
    for want in ["cargo install --locked --path .", "pip install ./python", "bash .ci/test"] {
        assert!(
            first_screen.iter().any(|l| l.starts_with(want)),
            "`{want}` is not on the README's first screen"
        );
    }
}

#[test]
fn documentation_speaks_of_the_product_only() {
    let root = common::root();
    let mut files = doc_files();
    files.extend(["CHANGELOG.md", "meshes/README.md", "tests/data/meshes/README.md"].map(|f| root.join(f)));
    // Spelled in pieces so that a search of the sources for these phrases finds only real uses.
    let banned = ["issue ", "issue-", concat!("this", " round"), concat!("previous", " round"), "session"];
    let mut found = Vec::new();
    for f in files {
        for (n, line) in std::fs::read_to_string(&f).unwrap().lines().enumerate() {
            let lower = line.to_lowercase();
            for b in banned {
                let hit = lower.match_indices(b).any(|(i, _)| {
                    // "issue N" / "issue-N": process references; "issue" alone is a plain word.
                    !b.starts_with("issue") || lower[i + b.len()..].starts_with(|c: char| c.is_ascii_digit())
                });
                if hit {
                    found.push(format!("{}:{}: {line}", f.strip_prefix(&root).unwrap().display(), n + 1));
                }
            }
        }
    }
    assert!(found.is_empty(), "process vocabulary in the documentation:\n{}", found.join("\n"));
}

#[test]
fn blocks_commands_exit_codes_and_outputs_are_parsed() {
    let md = "x\n```sh\n# a comment\nmeshclash a b  # exit 1\nmeshclash c \\\n  d\n\n```\n\
              ```text output\nline one\n...\nmore\n```\n```sh no-run\ncargo install\n```\n\
              ```sh corpus\nmeshclash e   # exit 2\n```\n```json\n{}\n```\n";
    let items = parse(md).unwrap();
    assert_eq!(
        items,
        vec![
            Item::Block {
                line: 2,
                corpus: false,
                cmds: vec![
                    Cmd { line: 4, text: "meshclash a b  # exit 1".into(), exit: 1 },
                    Cmd { line: 5, text: "meshclash c   d".into(), exit: 0 },
                ],
            },
            Item::Output { line: 9, lines: vec!["line one".into()] },
            Item::Block {
                line: 17,
                corpus: true,
                cmds: vec![Cmd { line: 18, text: "meshclash e   # exit 2".into(), exit: 2 }]
            },
        ]
    );
    assert!(parse("```sh runn\nx\n```\n").unwrap_err().contains("unknown sh block tag `runn`"));
    assert!(parse("```sh\nx\n").unwrap_err().contains("unclosed"));
    assert!(parse("```sh\nx # exit one\n```\n").unwrap_err().contains("bad exit declaration"));
    assert!(parse("```sh\nx \\\n```\n").unwrap_err().contains("continuation at the end"));
}
