//! CI-facing outputs built from a finished [`Report`]: the human summary ([`text`]), JUnit XML
//! ([`junit`]), the baseline diff with stable finding ids ([`baseline`]), a visual GLB scene
//! ([`glb`]), the HTML and BCF exports, the JSON Schema of the report, and the staged writer
//! ([`write`]).
//!
//! Everything here returns strings or bytes, or writes the files it was asked to write; the
//! library never prints. The binary decides what goes to stdout and stderr.

pub mod bcf;
pub mod glb;
pub mod html;
pub mod junit;
pub mod text;
pub mod write;

use crate::check::query::ClashResult;
use crate::error::Result;
use crate::report::baseline;
use crate::report::Report;
use crate::scene::mesh::Mesh;
use std::path::PathBuf;

/// `--format`: what goes to stdout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The JSON report (`meshclash.report/2`).
    Json,
    /// The human summary (the one shown on stderr on a terminal).
    Text,
    /// JUnit XML, one test case per checked pair of inputs.
    Junit,
}

/// The validated output options (what the command line's output flags ask for).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OutputOptions {
    /// `--format`, or None for the default (JSON, or nothing when the report goes to a file).
    pub format: Option<Format>,
    /// `--junit FILE`.
    pub junit: Option<PathBuf>,
    /// `--baseline REPORT`.
    pub baseline: Option<PathBuf>,
    /// `--export-glb FILE`.
    pub export_glb: Option<PathBuf>,
    /// `--html FILE`.
    pub html: Option<PathBuf>,
    /// `--bcf FILE` and `--bcf-topics`.
    pub bcf: Option<(PathBuf, bcf::Topics)>,
    /// `--bcf-version`.
    pub bcf_version: bcf::Version,
    /// `--up`.
    pub up: glb::Up,
    /// `--fail-on new`: fail only on new crossings and new containment (needs a baseline).
    pub fail_on_new: bool,
}

/// The JSON Schema of [`Report`], pretty-printed with a trailing newline.
pub fn schema_json() -> String {
    let schema = schemars::schema_for!(Report);
    let mut s = serde_json::to_string_pretty(&schema).expect("schema serialises");
    s.push('\n');
    s
}

/// Complete the report after [`crate::report::build`] and write the side files: finding ids (always),
/// the baseline comparison and `--fail-on new` (with `--baseline`), the JUnit file and the GLB.
/// Sets `rep.failed` for `--fail-on new`. `meshes` are the two placed inputs the result was
/// computed on.
pub fn finish(
    opts: &OutputOptions,
    rep: &mut Report,
    result: &ClashResult,
    meshes: [&Mesh; 2],
    staged: &mut write::Staged,
) -> Result<()> {
    // Every pair's id for a baseline comparison; without one, only the listed pairs show theirs.
    let listed = if opts.baseline.is_some() { result.pairs.len() } else { rep.pairs.len() };
    let findings = baseline::findings(&result.pairs[..listed], meshes[0], meshes[1]);
    baseline::assign_ids(rep, &findings);
    if let Some(path) = &opts.baseline {
        let base = baseline::read(path)?;
        baseline::compare(rep, &findings, &base);
    }
    if opts.fail_on_new {
        rep.settings.fail_on = "new".into();
        // `--fail-on new` replaces the verdict's condition; a failing `self` block (scene --self,
        // its own --self-fail-on) still fails the run.
        rep.failed = rep.baseline.as_ref().is_some_and(baseline::fails_on_new)
            || rep.self_check.as_ref().is_some_and(|s| s.failed);
    }
    if let Some(path) = &opts.junit {
        staged.stage(path, junit::from_report(rep).as_bytes())?;
    }
    if let Some(path) = &opts.export_glb {
        let z_up = opts.up.z_up(&rep.inputs.a.format);
        staged.stage(path, &glb::export(rep, result, meshes[0], meshes[1], z_up))?;
    }
    if let Some(path) = &opts.html {
        let z_up = opts.up.z_up(&rep.inputs.a.format);
        staged.stage(path, html::export(rep, result, meshes[0], meshes[1], z_up).as_bytes())?;
    }
    if let Some((path, topics)) = &opts.bcf {
        staged.stage(path, &bcf::export(rep, result, meshes[0], meshes[1], *topics, opts.bcf_version))?;
    }
    Ok(())
}

/// What goes to stdout for `opts.format`, given the finished report: (text, whether the JSON
/// report goes to stdout). The JSON is not rendered here: the binary streams it with
/// [`write_report_json`]. With no `--format` and the report written to a file
/// (`report_to_file`), nothing. Text is uncoloured (the binary re-renders it in colour on a
/// terminal).
pub fn stdout_for(opts: &OutputOptions, rep: &Report, report_to_file: bool) -> (Option<String>, bool) {
    match opts.format {
        None if report_to_file => (None, false),
        None | Some(Format::Json) => (None, true),
        Some(Format::Text) => (Some(text::render(rep, false)), false),
        Some(Format::Junit) => (Some(junit::from_report(rep)), false),
    }
}

/// The report as pretty JSON with a trailing newline, streamed to `w` (the same bytes as
/// [`crate::report::to_json`], never the whole text in memory).
pub fn write_report_json(w: &mut dyn std::io::Write, rep: &Report) -> std::io::Result<()> {
    serde_json::to_writer_pretty(&mut *w, rep).map_err(std::io::Error::from)?;
    w.write_all(b"\n")
}
