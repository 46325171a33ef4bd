//! CI-facing outputs built from a finished [`Report`]: the human summary ([`text`]), JUnit XML
//! ([`junit`]), the baseline diff with stable finding ids ([`baseline`]), a visual GLB scene
//! ([`glb`]), progress phases ([`progress`]), and the artefacts generated from the command-line
//! definition (JSON Schema, shell completions, man page).
//!
//! Everything here returns strings or bytes, or writes the files it was asked to write; the
//! library never prints. The binary decides what goes to stdout and stderr.

pub mod bcf;
pub mod glb;
pub mod html;
pub mod junit;
pub mod progress;
pub mod text;
pub mod write;

use crate::check::query::ClashResult;
use crate::error::{Error, Result};
use crate::report::baseline;
use crate::report::Report;
use crate::scene::mesh::Mesh;
use clap::CommandFactory;
use std::path::PathBuf;

/// `--format`: what goes to stdout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// The JSON report (`meshclash.report/2`).
    Json,
    /// The human summary (the one shown on stderr on a terminal).
    Text,
    /// JUnit XML, one test case per checked pair of inputs.
    Junit,
}

/// The output flags, flattened into [`crate::cli::Args`].
#[derive(Debug, Clone, Default, clap::Args)]
pub struct OutputArgs {
    /// What to print on stdout: the JSON report, a human summary or JUnit XML [default: json,
    /// or nothing when -o is given].
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<Format>,
    /// Also write JUnit XML to FILE (atomically): one test case per checked pair of inputs,
    /// failed when the run fails.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Compare with an earlier report: every finding gets a status (new or persistent) and the
    /// report a `baseline` block with the resolved ones. Findings are matched by stable ids.
    #[arg(long, value_name = "REPORT")]
    pub baseline: Option<PathBuf>,
    /// Write a self-contained GLB scene to FILE for any glTF viewer: a node per part (A orange,
    /// B blue), a node per clash worst first (marker, contact lines, its triangles, a camera,
    /// counts in extras) and the closest points.
    #[arg(long, value_name = "FILE")]
    pub export_glb: Option<PathBuf>,
    /// Write a self-contained HTML report to FILE: the summary, a sortable list of clashes and
    /// a WebGL viewer of the parts involved (no network needed to open it).
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
    /// Write the clashes as BCF 2.1 topics to FILE (.bcfzip), for BIM tools: one topic per
    /// clash region or part pair (--bcf-topics), with a camera, the parts and the witness line.
    #[arg(long, value_name = "FILE")]
    pub bcf: Option<PathBuf>,
    /// What one BCF topic is.
    #[arg(long, value_enum, value_name = "WHAT", default_value = "regions")]
    pub bcf_topics: bcf::Topics,
    /// BCF version of --bcf: 2.1 (read by every BIM tool) or 3.0.
    #[arg(long, value_enum, value_name = "V", default_value = "2.1")]
    pub bcf_version: bcf::Version,
    /// Which axis points up in the inputs, for --export-glb and --html: `z` turns the GLB's
    /// root node -90° about X (CAD data shows upright in glTF viewers) and orbits the HTML
    /// viewer around Z; coordinates in the files stay those of the report [default: z for
    /// STL, else y].
    #[arg(long, value_enum, value_name = "AXIS", default_value = "auto", hide_default_value = true)]
    pub up: glb::Up,
}

/// The validated output options (part of [`crate::cli::Config`]).
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

impl OutputArgs {
    /// Validate. `fail_on_new` is whether `--fail-on new` was given: it needs `--baseline`.
    pub fn into_options(self, fail_on_new: bool) -> Result<OutputOptions> {
        if fail_on_new && self.baseline.is_none() {
            return Err(Error::Usage("--fail-on new needs --baseline REPORT".into()));
        }
        Ok(OutputOptions {
            format: self.format,
            junit: self.junit,
            baseline: self.baseline,
            export_glb: self.export_glb,
            html: self.html,
            bcf: self.bcf.map(|p| (p, self.bcf_topics)),
            bcf_version: self.bcf_version,
            up: self.up,
            fail_on_new,
        })
    }
}

/// The subcommands beside the main `meshclash A B` job. Each prints to stdout.
#[derive(Debug, Clone, PartialEq, Eq, clap::Subcommand)]
pub enum Command {
    /// Print the JSON Schema (draft 2020-12) of the report.
    Schema,
    /// Print a shell completion script.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff).
    Man,
}

impl Command {
    /// What the subcommand prints.
    pub fn render(&self) -> String {
        match self {
            Command::Schema => schema_json(),
            Command::Completions { shell } => completions(*shell),
            Command::Man => man_page(),
        }
    }
}

/// The JSON Schema of [`Report`], pretty-printed with a trailing newline.
pub fn schema_json() -> String {
    let schema = schemars::schema_for!(Report);
    let mut s = serde_json::to_string_pretty(&schema).expect("schema serialises");
    s.push('\n');
    s
}

/// A completion script for `shell`, generated from the clap definition.
pub fn completions(shell: clap_complete::Shell) -> String {
    let mut cmd = crate::cli::Args::command();
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut cmd, "meshclash", &mut out);
    String::from_utf8_lossy(&out).into_owned()
}

/// The man page (roff), generated from the clap definition.
pub fn man_page() -> String {
    let mut out = Vec::new();
    clap_mangen::Man::new(crate::cli::Args::command()).render(&mut out).expect("writing to a Vec");
    String::from_utf8_lossy(&out).into_owned()
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
    let findings = baseline::findings(&result.pairs, meshes[0], meshes[1]);
    baseline::assign_ids(rep, &findings);
    if let Some(path) = &opts.baseline {
        let base = baseline::read(path)?;
        baseline::compare(rep, &findings, &base);
    }
    if opts.fail_on_new {
        rep.settings.fail_on = "new".into();
        rep.failed = rep.baseline.as_ref().is_some_and(baseline::fails_on_new);
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

/// Every output of the two-file or scene command, checked against its inputs before the run
/// ([`write::check_outputs`]). The baseline is not an input here: it is read whole before any
/// output is written, so `--baseline r.json -o r.json` updates a baseline in place.
pub fn check_outputs(cfg: &crate::cli::Config) -> Result<()> {
    let mut outputs: Vec<write::Named> = Vec::new();
    if let Some(p) = &cfg.output {
        outputs.push(("-o", p));
    }
    if let Some(p) = &cfg.outputs.junit {
        outputs.push(("--junit", p));
    }
    if let Some(p) = &cfg.outputs.export_glb {
        outputs.push(("--export-glb", p));
    }
    if let Some(p) = &cfg.outputs.html {
        outputs.push(("--html", p));
    }
    if let Some((p, _)) = &cfg.outputs.bcf {
        outputs.push(("--bcf", p));
    }
    write::check_outputs(&outputs, &input_paths(cfg))
}

/// The mesh files a configuration reads (in scene mode, the one file).
pub fn input_paths(cfg: &crate::cli::Config) -> Vec<&std::path::Path> {
    let skip = usize::from(cfg.selection.scene);
    cfg.inputs[skip..].iter().map(|i| i.path.as_path()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streamed_json_is_byte_identical() {
        use clap::Parser;
        let m = |f: &str| format!("{}/meshes/{f}", env!("CARGO_MANIFEST_DIR"));
        let args = crate::cli::Args::try_parse_from([
            "meshclash".to_string(),
            m("fcl_env.obj"),
            m("fcl_rob.obj"),
            "--no-timings".into(),
        ])
        .unwrap();
        let out = crate::cli::run(&args.into_config().unwrap()).unwrap();
        assert!(out.json_stdout && out.stdout.is_none());
        let mut streamed = Vec::new();
        write_report_json(&mut streamed, &out.report).unwrap();
        assert_eq!(String::from_utf8(streamed).unwrap(), crate::report::to_json(&out.report));
    }
}
