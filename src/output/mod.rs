//! CI-facing outputs, each a projection of a finished [`Report`] (and, for the pictures, of the
//! geometry of the [`Outcome`] it was built from): the human summary ([`text`]), JUnit XML
//! ([`junit`]), a visual GLB scene ([`glb`]), the HTML and BCF exports, the JSON Schema of the
//! report, and the staged writer ([`write`]). No function here takes a `&mut Report`.
//!
//! Everything here returns strings or bytes, or writes the files it was asked to write; the
//! library never prints. The binary decides what goes to stdout and stderr.

pub mod bcf;
pub mod glb;
pub mod html;
pub mod junit;
pub mod text;
pub mod write;

use crate::error::Result;
use crate::pipeline::Outcome;
use crate::report::Report;
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
}

impl OutputOptions {
    /// The files these options write, each with the flag that names it.
    pub fn files(&self) -> Vec<write::Named<'_>> {
        let mut out: Vec<write::Named> = Vec::new();
        if let Some(p) = &self.junit {
            out.push(("--junit", p));
        }
        if let Some(p) = &self.export_glb {
            out.push(("--export-glb", p));
        }
        if let Some(p) = &self.html {
            out.push(("--html", p));
        }
        if let Some((p, _)) = &self.bcf {
            out.push(("--bcf", p));
        }
        out
    }
}

/// The JSON Schema of [`Report`], pretty-printed with a trailing newline.
pub fn schema_json() -> String {
    let schema = schemars::schema_for!(Report);
    let mut s = serde_json::to_string_pretty(&schema).expect("schema serialises");
    s.push('\n');
    s
}

/// Stage the side files of a run (JUnit, GLB, HTML, BCF): each a projection of the report and
/// of the geometry the outcome was computed on. Nothing here decides or changes the report.
pub fn stage_files(
    opts: &OutputOptions,
    rep: &Report,
    outcome: &Outcome,
    staged: &mut write::Staged,
) -> Result<()> {
    let result = &outcome.assembly.result;
    if let Some(path) = &opts.junit {
        staged.stage(path, junit::from_report(rep).as_bytes())?;
    }
    if opts.export_glb.is_none() && opts.html.is_none() && opts.bcf.is_none() {
        return Ok(());
    }
    // An instanced scene is expanded only for an output that draws it, and refused, like a
    // plain load of it, when it is too large to expand.
    let [a, b] = outcome.meshes();
    let (a, b) = (a.drawn_mesh()?, b.drawn_mesh()?);
    let (a, b) = (&*a, &*b);
    if let Some(path) = &opts.export_glb {
        let z_up = opts.up.z_up(&rep.inputs.a.format);
        staged.stage(path, &glb::export(rep, result, a, b, z_up))?;
    }
    if let Some(path) = &opts.html {
        let z_up = opts.up.z_up(&rep.inputs.a.format);
        staged.stage(path, html::export(rep, result, a, b, z_up).as_bytes())?;
    }
    if let Some((path, topics)) = &opts.bcf {
        staged.stage(path, &bcf::export(rep, result, a, b, *topics, opts.bcf_version))?;
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
    crate::report::pretty::write_pretty(&mut *w, rep)?;
    w.write_all(b"\n")
}
