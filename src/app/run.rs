//! Running a validated [`Config`]: the library's pipeline ([`meshclash::pipeline::run`]), the
//! report as its projection ([`meshclash::pipeline::report::build`]), and the outputs the command line
//! names, staged so that all of them, stdout included, are written or none is.

use super::config::Config;
use meshclash::error::{Error, Result, UsageProblem};
use meshclash::output::write::Staged;
use meshclash::pipeline::Phase;
use meshclash::report;

/// What the binary should do after a successful run.
#[derive(Debug)]
pub struct Outcome {
    /// What goes to stdout: the report in `--format` (default JSON; None when the report is
    /// written to `--output` and no `--format` is given, or when the JSON report goes there:
    /// see `json_stdout`).
    pub stdout: Option<String>,
    /// The JSON report goes to stdout: the binary streams `report` there
    /// ([`meshclash::output::write_report_json`]) instead of holding its text in memory.
    pub json_stdout: bool,
    /// Lines for stderr (warnings).
    pub warnings: Vec<String>,
    /// [`meshclash::error::ExitCode::Ok`] or [`meshclash::error::ExitCode::Findings`].
    pub exit_code: meshclash::error::ExitCode,
    /// The finished report (for the human summary on a terminal).
    pub report: Box<report::Report>,
    /// The files to write (the report's `-o`, JUnit, GLB, HTML, BCF): committed by the binary
    /// once stdout is written, so a failing stdout writes no file.
    pub staged: Staged,
}

impl Outcome {
    /// Write what goes to stdout: the text, or the JSON report streamed
    /// ([`meshclash::output::write::to_stdout`]: `Ok(false)` when the reader went away).
    pub fn write_stdout(&self) -> std::io::Result<bool> {
        use meshclash::output::write;
        match (&self.stdout, self.json_stdout) {
            (Some(text), _) => write::to_stdout(|w| w.write_all(text.as_bytes())),
            (None, true) => write::to_stdout(|w| meshclash::output::write_report_json(w, &self.report)),
            (None, false) => Ok(true),
        }
    }
}

/// Do the whole job for a validated config (without progress).
#[cfg(test)]
pub fn run(cfg: &Config) -> Result<Outcome> {
    run_with_progress(cfg, &|_| {})
}

/// [`run`], calling `progress` as each phase starts (the binary drives a spinner with it).
pub fn run_with_progress(cfg: &Config, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    check_outputs(cfg)?;
    in_pool(cfg.threads, |_| {
        let (rep, mut staged) = check(cfg, progress)?;
        if let Some(path) = &cfg.output {
            staged.stage_with(path, |w| meshclash::output::write_report_json(w, &rep))?;
        }
        let (stdout, json_stdout) = meshclash::output::stdout_for(&cfg.outputs, &rep, cfg.output.is_some());
        let exit_code = meshclash::error::ExitCode::from_failed(rep.failed);
        Ok(Outcome {
            stdout,
            json_stdout,
            warnings: rep.warnings.clone(),
            exit_code,
            report: Box::new(rep),
            staged,
        })
    })
}

/// Run `f` in a pool of `threads` workers (`--threads`; 0 = one per core), giving it the pool's
/// size (the single command and the clash-set runner share this).
pub fn in_pool<T: Send>(threads: usize, f: impl FnOnce(usize) -> Result<T> + Send) -> Result<T> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::bad_flag("threads", UsageProblem::Invalid(e.to_string())))?;
    pool.install(|| f(pool.current_num_threads()))
}

/// The check of one configuration in the current pool: the pipeline's outcome projected into
/// the report, with the side files of `cfg.outputs` staged (not yet written). The single
/// command, every check of a clash set and the steps of a sharded run go through here.
pub fn check(cfg: &Config, progress: &(dyn Fn(Phase) + Sync)) -> Result<(report::Report, Staged)> {
    let outcome = meshclash::pipeline::run(&cfg.request, progress)?;
    let rep = meshclash::pipeline::report::build(&outcome);
    let mut staged = Staged::new();
    meshclash::output::stage_files(&cfg.outputs, &rep, &outcome, &mut staged)?;
    // A cache problem (a damaged entry, an unwritable directory) never fails a run and never
    // changes the report: it is said on stderr.
    for w in &outcome.cache_warnings {
        eprintln!("meshclash: warning: {w}");
    }
    Ok((rep, staged))
}

/// Every output of the two-file or scene command, checked against its inputs and each other
/// before the run ([`meshclash::output::write::check_outputs`]). The baseline is not an input
/// here: it is read whole before any output is written, so `--baseline r.json -o r.json`
/// updates a baseline in place.
pub fn check_outputs(cfg: &Config) -> Result<()> {
    let mut outputs: Vec<meshclash::output::write::Named> = Vec::new();
    if let Some(p) = &cfg.output {
        outputs.push(("-o", p));
    }
    outputs.extend(cfg.outputs.files());
    meshclash::output::write::check_outputs(&outputs, &cfg.input_paths())
}

#[cfg(test)]
mod tests {
    use crate::app::args::Args;

    #[test]
    fn streamed_json_is_byte_identical() {
        use clap::Parser;
        let m = |f: &str| format!("{}/meshes/{f}", env!("CARGO_MANIFEST_DIR"));
        let args = Args::try_parse_from([
            "meshclash".to_string(),
            m("fcl_env.obj"),
            m("fcl_rob.obj"),
            "--no-timings".into(),
        ])
        .unwrap();
        let out = super::run(&args.into_config().unwrap()).unwrap();
        assert!(out.json_stdout && out.stdout.is_none());
        let mut streamed = Vec::new();
        meshclash::output::write_report_json(&mut streamed, &out.report).unwrap();
        assert_eq!(String::from_utf8(streamed).unwrap(), meshclash::report::to_json(&out.report));
    }
}
