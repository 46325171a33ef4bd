//! Running a validated [`Config`]: load, check, build the report, write the outputs.

use super::config::Config;
use super::progress::Phase;
use meshclash::check::query;
use meshclash::error::{Error, InputProblem, Result, UsageProblem};
use meshclash::geom::predicates::Tolerances;
use meshclash::report::{self, SettingsReport};
use std::time::Instant;

/// What the binary should do after a successful run.
#[derive(Debug, Clone, PartialEq)]
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
}

/// Do the whole job for a validated config (without progress).
#[cfg(test)]
pub fn run(cfg: &Config) -> Result<Outcome> {
    run_with_progress(cfg, &|_| {})
}

/// [`run`], calling `progress` as each phase starts (the binary drives a spinner with it).
pub fn run_with_progress(cfg: &Config, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    check_outputs(cfg)?;
    in_pool(cfg.threads, |threads| run_in_pool(cfg, threads, progress))
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

fn run_in_pool(cfg: &Config, threads: usize, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    let mut staged = meshclash::output::write::Staged::new();
    let rep = check_staged(cfg, threads, progress, &mut staged)?;
    let warnings = rep.warnings.clone();
    if let Some(path) = &cfg.output {
        staged.stage_with(path, |w| meshclash::output::write_report_json(w, &rep))?;
    }
    staged.commit()?;
    let (stdout, json_stdout) = meshclash::output::stdout_for(&cfg.outputs, &rep, cfg.output.is_some());
    let exit_code = meshclash::error::ExitCode::from_failed(rep.failed);
    Ok(Outcome { stdout, json_stdout, warnings, exit_code, report: Box::new(rep) })
}

/// Load one input: exactly [`query::load_input`] when no units or scale flag was given; else
/// [`query::prepare_input`] with the input's multiplier. `i` indexes `cfg.inputs`; `flag` is the
/// units flag that declares this input's units.
fn load_with_units(
    cfg: &Config,
    i: usize,
    flag: &str,
) -> Result<(query::Input, Option<report::InputUnitsReport>)> {
    let spec = &cfg.inputs[i];
    let (mut input, units) = if !cfg.units.active() {
        (query::load_input(spec)?, None)
    } else {
        let (loaded, format) = meshclash::load::load_path(&spec.path)?;
        let (multiplier, block, warning) = cfg.units.resolve(i, format, flag);
        (query::prepare_input(spec, loaded, format, multiplier, warning)?, Some(block))
    };
    if cfg.split_bodies {
        meshclash::scene::bodies::split_bodies(&mut input.mesh);
    }
    Ok((input, units))
}

/// The input whose file a selection error names: A's when A's selection (`--select-a`,
/// `--exclude`) leaves no part (the side checked first), else B's; in scene mode the one file.
fn problem_side(cfg: &Config, a: &meshclash::scene::mesh::Mesh) -> usize {
    use meshclash::check::assembly::{glob_match, parts_of};
    let sel = &cfg.selection;
    let kept = |name: &str| {
        (sel.select_a.is_empty() || sel.select_a.iter().any(|g| glob_match(g, name)))
            && !sel.exclude.iter().any(|g| glob_match(g, name))
    };
    let a_empty = !parts_of(a, 0).iter().any(|p| kept(&p.name));
    if !sel.scene && a_empty {
        0
    } else {
        1
    }
}

/// Check one configuration and return the finished report (with finding ids, the baseline
/// comparison, and the JUnit and GLB files of `cfg.outputs` written), without writing the report
/// itself: the single command and every check of a clash set go through here.
pub fn check_in_pool(
    cfg: &Config,
    threads: usize,
    progress: &(dyn Fn(Phase) + Sync),
) -> Result<report::Report> {
    let mut staged = meshclash::output::write::Staged::new();
    let rep = check_staged(cfg, threads, progress, &mut staged)?;
    staged.commit()?;
    Ok(rep)
}

/// [`check_in_pool`], with the JUnit and GLB files staged in `staged` (committed by the caller
/// with its other outputs: all or nothing).
pub fn check_staged(
    cfg: &Config,
    threads: usize,
    progress: &(dyn Fn(Phase) + Sync),
    staged: &mut meshclash::output::write::Staged,
) -> Result<report::Report> {
    progress(Phase::Load);
    let t0 = Instant::now();
    let (first, second, units) = if cfg.selection.scene {
        // `meshclash scene FILE`: one file, its parts against each other (A and B are the same
        // input, loaded once).
        let (a, u) = load_with_units(cfg, 1, "--units-a")?;
        (a, None, [u.clone(), u])
    } else {
        let (a, b) =
            rayon::join(|| load_with_units(cfg, 0, "--units-a"), || load_with_units(cfg, 1, "--units-b"));
        let ((a, ua), (b, ub)) = (a?, b?);
        (a, Some(b), [ua, ub])
    };
    let (a, b) = (&first, second.as_ref().unwrap_or(&first));
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let size = meshclash::geom::Aabb::of_points(&a.mesh.positions)
        .union(meshclash::geom::Aabb::of_points(&b.mesh.positions))
        .extent()
        .length();
    let mut settings = cfg.settings;
    settings.tolerances =
        Tolerances { touch: cfg.touch.resolve(size), clearance: cfg.clearance.resolve(size) };
    if !settings.tolerances.touch.is_finite() || !settings.tolerances.clearance.is_finite() {
        return Err(Error::usage(UsageProblem::ToleranceOverflow));
    }
    progress(Phase::Check);
    let outcome =
        meshclash::check::assembly::run(&a.mesh, &b.mesh, &cfg.selection, &settings).map_err(|e| {
            Error::in_file(&cfg.inputs[problem_side(cfg, &a.mesh)].path, InputProblem::Selection(e))
        })?;
    let assembly = report::assembly_view(&outcome, cfg.max_pairs);
    let result = outcome.result;
    let failed = cfg.fail_on.fails(result.verdict);
    let cross_check = if cfg.cross_check {
        progress(Phase::CrossCheck);
        let p = meshclash::check::cross_check::parry_f64(&a.mesh, &b.mesh, true)
            .map_err(|e| Error::bad_flag("cross-check", UsageProblem::CrossCheck(e.to_string())))?;
        Some(report::cross_check_report(&result, &p, cfg.max_pairs, cfg.deterministic))
    } else {
        None
    };
    let ctx = report::Context {
        inputs: [a, b],
        transforms: [cfg.inputs[0].transform, cfg.inputs[1].transform],
        settings: SettingsReport {
            touch_tolerance: settings.tolerances.touch,
            clearance: settings.tolerances.clearance,
            touch_tolerance_given: cfg.touch.spec(),
            clearance_given: cfg.clearance.spec(),
            model_size: size,
            units: cfg.units.report_name().into(),
            fail_on: cfg.fail_on.name().into(),
            bvh: cfg.settings.bvh.strategy.name().into(),
            mode: cfg.settings.mode.name().into(),
            first_hit: cfg.settings.first_hit,
            penetration: cfg.penetration,
            distance_rel_err: cfg.settings.distance_error.rel,
            distance_abs_err: cfg.settings.distance_error.abs,
            leaf_size: cfg.settings.bvh.leaf_size,
            max_pairs: cfg.max_pairs,
            threads: (!cfg.deterministic).then_some(threads),
            detail: (cfg.settings.detail != query::Detail::Pairs).then(|| cfg.settings.detail.name().into()),
        },
        failed,
        times: (!cfg.deterministic).then(|| (load_ms, t0.elapsed().as_secs_f64() * 1e3)),
        cross_check,
        assembly,
    };
    let mut rep = report::build(&ctx, &result);
    if let Some(fail_on) = &cfg.self_check {
        let (sel, bvh) = (&cfg.selection, cfg.settings.bvh);
        report::self_report::attach_scene_self(
            &mut rep,
            &a.mesh,
            sel,
            bvh,
            fail_on,
            cfg.max_pairs,
            cfg.deterministic,
        );
    }
    let [ua, ub] = units;
    rep.inputs.a.units = ua;
    rep.inputs.b.units = ub;
    progress(Phase::Write);
    meshclash::output::finish(&cfg.outputs, &mut rep, &result, [&a.mesh, &b.mesh], staged)?;
    Ok(rep)
}

/// Every output of the two-file or scene command, checked against its inputs before the run
/// ([`meshclash::output::write::check_outputs`]). The baseline is not an input here: it is read whole before any
/// output is written, so `--baseline r.json -o r.json` updates a baseline in place.
pub fn check_outputs(cfg: &Config) -> Result<()> {
    let mut outputs: Vec<meshclash::output::write::Named> = Vec::new();
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
    meshclash::output::write::check_outputs(&outputs, &input_paths(cfg))
}

/// The mesh files a configuration reads (in scene mode, the one file).
pub fn input_paths(cfg: &Config) -> Vec<&std::path::Path> {
    let skip = usize::from(cfg.selection.scene);
    cfg.inputs[skip..].iter().map(|i| i.path.as_path()).collect()
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
