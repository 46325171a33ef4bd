//! Command line: clap definitions, and their conversion into a validated [`Config`] (the core
//! never sees clap). [`run`] does the whole job and hands back what to print and the exit code;
//! the binary prints it.

use crate::bvh::{BuildOptions, Strategy};
use crate::error::{Error, Result};
use crate::geom::predicates::Tolerances;
use crate::output::progress::Phase;
use crate::query::{self, DistanceError, FailOn, InputSpec, Mode, Settings};
use crate::report::{self, SettingsReport};
use clap::{Parser, ValueEnum};
use glam::{DMat4, DVec3, DVec4};
use std::path::PathBuf;
use std::time::Instant;

/// Do two meshes clash, where, and how close do they come? Reads OBJ, STL (ASCII or binary) and
/// glTF (.gltf/.glb); writes a JSON report. Exit code: 0 nothing at or above --fail-on,
/// 1 findings at or above it, 2 bad input, I/O or usage error.
#[derive(Debug, Parser)]
#[command(
    name = "meshclash",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    /// First mesh (A).
    #[arg(required = true)]
    pub a: Option<PathBuf>,
    /// Second mesh (B).
    #[arg(required = true)]
    pub b: Option<PathBuf>,
    /// `schema`, `completions <shell>` or `man` instead of a check.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Write the report to FILE (atomically) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Move A by x,y,z (after --transform-a).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub translate_a: Option<String>,
    /// Move B by x,y,z (after --transform-b).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub translate_b: Option<String>,
    /// Affine transform of A: 12 (3×4) or 16 (4×4, last row 0,0,0,1) comma-separated numbers, row-major.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub transform_a: Option<String>,
    /// Affine transform of B, as --transform-a.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub transform_b: Option<String>,
    /// Pairs that do not touch but are within this distance count as touching: model units, or
    /// relative to the model size with a `rel` suffix (`1e-6rel` = 1e-6 × the diagonal of the
    /// box around both inputs).
    #[arg(long, value_name = "E", default_value = "0", allow_hyphen_values = true)]
    pub touch_tolerance: String,
    /// Also report every pair closer than D that does not touch (model units, or `rel` suffix).
    #[arg(long, value_name = "D", default_value = "0", allow_hyphen_values = true)]
    pub clearance: String,
    /// Exit 1 when the verdict is at or above this.
    #[arg(long, value_enum, default_value_t = FailOnArg::Clash)]
    pub fail_on: FailOnArg,
    /// BVH split strategy.
    #[arg(long, value_enum, default_value_t = BvhArg::Sah)]
    pub bvh: BvhArg,
    /// Largest BVH leaf, in triangles (1..=64).
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub leaf_size: u32,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// List at most N pairs (the summary counts stay complete).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub max_pairs: usize,
    /// Also run parry3d-f64 on the same input and add a `cross_check` block listing every
    /// disagreement (slow on large overlapping meshes: parry's distance is not a dual walk).
    #[arg(long, value_enum, value_name = "TOOL")]
    pub cross_check: Option<CrossCheckArg>,
    /// Pair classification: `exact` predicates, or `fast` plain f64 determinants (gives up
    /// exactness on nearly touching or coplanar pairs; `meshclash bench --trade` measures it).
    #[arg(long, value_enum, default_value_t = ModeArg::Exact)]
    pub mode: ModeArg,
    /// Stop at the first crossing pair: a quick pass/fail gate. Counts become lower bounds,
    /// no distance or containment is computed, and which pair is listed depends on timing.
    #[arg(long)]
    pub first_hit: bool,
    /// Allowed relative error of the minimum distance (reported d <= (1+R)·true + A).
    #[arg(long, value_name = "R", default_value_t = 0.0)]
    pub distance_rel_err: f64,
    /// Allowed absolute error of the minimum distance (model units).
    #[arg(long, value_name = "A", default_value_t = 0.0)]
    pub distance_abs_err: f64,
    /// Check only parts of A whose name matches GLOB (`*`, `?`; repeatable). Part names are
    /// glTF node paths (`Engine/Piston_2`), OBJ `o`/`g` names, STL solid names.
    #[arg(long, value_name = "GLOB")]
    pub select_a: Vec<String>,
    /// Check only parts of B matching GLOB (in scene mode: the second set; without it, the
    /// selected parts are checked all-vs-all).
    #[arg(long, value_name = "GLOB")]
    pub select_b: Vec<String>,
    /// Leave out parts matching GLOB, on both sides (repeatable).
    #[arg(long, value_name = "GLOB")]
    pub exclude: Vec<String>,
    /// Deterministic report: no timings, no thread count (byte-identical across runs).
    #[arg(long)]
    pub no_timings: bool,
    /// Output flags: --format, --junit, --baseline, --export-glb.
    #[command(flatten)]
    pub outputs: crate::output::OutputArgs,
    /// Nothing on stderr but errors: no warnings, no summary, no progress.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Subcommands instead of a check: the generated-text ones of [`crate::output::Command`], and
/// `bench`.
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// `schema`, `completions <shell>`, `man`.
    #[command(flatten)]
    Output(crate::output::Command),
    /// Time meshclash against parry3d (f32 and f64) on generated and given meshes, compare their
    /// answers, and (--trade) tabulate every speed/accuracy option against the exact default.
    Bench(crate::bench::BenchArgs),
}

/// `--fail-on` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FailOnArg {
    /// Crossing pairs fail.
    Clash,
    /// Touching or crossing pairs fail.
    Touching,
    /// Anything within the clearance fails.
    Clearance,
    /// Never fail on findings.
    Never,
    /// With --baseline: fail only on crossing pairs that were not crossing in the baseline, or
    /// on containment the baseline did not report.
    New,
}

/// `--cross-check` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CrossCheckArg {
    /// parry3d-f64 0.31 (GJK triangle tests, f64).
    Parry,
}

/// `--mode` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Exact predicates (default).
    Exact,
    /// Plain f64 determinants, no exact fallback.
    Fast,
}

fn nonneg(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(Error::Usage(format!("--{flag} must be a finite number >= 0, got {v}")))
    }
}

/// `--bvh` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BvhArg {
    /// Binned surface-area heuristic.
    Sah,
    /// Spatial median of the centroid bounds.
    Median,
    /// Equal counts (object median).
    Equal,
}

/// A validated configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Inputs A and B with their placements.
    pub inputs: [InputSpec; 2],
    /// Where the report goes (None = stdout).
    pub output: Option<PathBuf>,
    /// Touch tolerance as given.
    pub touch: Tol,
    /// Clearance as given.
    pub clearance: Tol,
    /// Search settings (tolerances are resolved to absolute values once the inputs are loaded).
    pub settings: Settings,
    /// Failure threshold.
    pub fail_on: FailOn,
    /// Worker threads (0 = default).
    pub threads: usize,
    /// Cap on listed pairs.
    pub max_pairs: usize,
    /// Deterministic report.
    pub deterministic: bool,
    /// Run parry3d-f64 too.
    pub cross_check: bool,
    /// Scene mode and part selections.
    pub selection: crate::assembly::Selection,
    /// Output format, JUnit and GLB files, baseline.
    pub outputs: crate::output::OutputOptions,
}

fn numbers(flag: &str, s: &str) -> Result<Vec<f64>> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(Error::Usage(format!("--{flag}: '{t}' is not a finite number"))),
            }
        })
        .collect()
}

/// Parse a row-major 3×4 or 4×4 affine matrix.
pub fn parse_transform(flag: &str, s: &str) -> Result<DMat4> {
    let v = numbers(flag, s)?;
    if v.len() != 12 && v.len() != 16 {
        return Err(Error::Usage(format!("--{flag} takes 12 or 16 numbers, got {}", v.len())));
    }
    if v.len() == 16 && v[12..] != [0.0, 0.0, 0.0, 1.0] {
        return Err(Error::Usage(format!("--{flag}: the last row must be 0,0,0,1 (affine only)")));
    }
    let row = |r: usize| DVec4::new(v[4 * r], v[4 * r + 1], v[4 * r + 2], v[4 * r + 3]);
    Ok(DMat4::from_cols(row(0), row(1), row(2), DVec4::W).transpose())
}

/// Parse `x,y,z`.
pub fn parse_translation(flag: &str, s: &str) -> Result<DVec3> {
    let v = numbers(flag, s)?;
    match v[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(Error::Usage(format!("--{flag} takes x,y,z, got {} numbers", v.len()))),
    }
}

fn placement(name: char, transform: &Option<String>, translate: &Option<String>) -> Result<DMat4> {
    let mut m = DMat4::IDENTITY;
    if let Some(t) = transform {
        m = parse_transform(&format!("transform-{name}"), t)?;
    }
    if let Some(t) = translate {
        m = DMat4::from_translation(parse_translation(&format!("translate-{name}"), t)?) * m;
    }
    Ok(m)
}

/// A tolerance as given: absolute (model units) or relative to the model size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tol {
    /// Model units.
    Abs(f64),
    /// Times the diagonal of the box around both inputs.
    Rel(f64),
}

impl Tol {
    /// The absolute value for a model of size `size`.
    pub fn resolve(self, size: f64) -> f64 {
        match self {
            Tol::Abs(v) => v,
            Tol::Rel(r) => r * size,
        }
    }

    /// As written on the command line (canonical form).
    pub fn spec(self) -> String {
        match self {
            Tol::Abs(v) => format!("{v}"),
            Tol::Rel(r) => format!("{r}rel"),
        }
    }
}

/// Parse `1.5` or `1e-6rel`: finite, >= 0.
pub fn parse_tolerance(flag: &str, s: &str) -> Result<Tol> {
    let t = s.trim();
    let (num, rel) = match t.strip_suffix("rel") {
        Some(n) => (n, true),
        None => (t, false),
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(if rel { Tol::Rel(v) } else { Tol::Abs(v) }),
        _ => Err(Error::Usage(format!(
            "--{flag} must be a finite number >= 0, optionally with a 'rel' suffix (e.g. 0.01 or 1e-6rel), got '{s}'"
        ))),
    }
}

impl Args {
    /// Validate into a [`Config`].
    pub fn into_config(self) -> Result<Config> {
        if !(1..=64).contains(&self.leaf_size) {
            return Err(Error::Usage(format!("--leaf-size must be 1..=64, got {}", self.leaf_size)));
        }
        // `meshclash scene FILE`: the word `scene` in place of A (use `./scene` for a file so named).
        let scene_mode = self.a.as_deref() == Some(std::path::Path::new("scene"));
        if scene_mode && self.cross_check.is_some() {
            return Err(Error::Usage("--cross-check works on two files, not with scene".into()));
        }
        let touch = parse_tolerance("touch-tolerance", &self.touch_tolerance)?;
        let clearance = parse_tolerance("clearance", &self.clearance)?;
        Ok(Config {
            inputs: [
                InputSpec {
                    path: self.a.ok_or_else(|| Error::Usage("missing mesh A".into()))?,
                    transform: placement('a', &self.transform_a, &self.translate_a)?,
                },
                InputSpec {
                    path: self.b.ok_or_else(|| Error::Usage("missing mesh B".into()))?,
                    transform: placement('b', &self.transform_b, &self.translate_b)?,
                },
            ],
            output: self.output,
            touch,
            clearance,
            settings: Settings {
                tolerances: Tolerances::default(),
                bvh: BuildOptions {
                    strategy: match self.bvh {
                        BvhArg::Sah => Strategy::Sah,
                        BvhArg::Median => Strategy::Median,
                        BvhArg::Equal => Strategy::Equal,
                    },
                    leaf_size: self.leaf_size,
                },
                mode: match self.mode {
                    ModeArg::Exact => Mode::Exact,
                    ModeArg::Fast => Mode::Fast,
                },
                first_hit: self.first_hit,
                distance_error: DistanceError {
                    rel: nonneg("distance-rel-err", self.distance_rel_err)?,
                    abs: nonneg("distance-abs-err", self.distance_abs_err)?,
                },
            },
            fail_on: match self.fail_on {
                FailOnArg::Clash => FailOn::Clash,
                FailOnArg::Touching => FailOn::Touching,
                FailOnArg::Clearance => FailOn::Clearance,
                // `new` is decided after the baseline comparison (crate::output::finish).
                FailOnArg::Never | FailOnArg::New => FailOn::Never,
            },
            threads: self.threads,
            max_pairs: self.max_pairs,
            deterministic: self.no_timings,
            cross_check: self.cross_check.is_some(),
            selection: crate::assembly::Selection {
                scene: scene_mode,
                select_a: self.select_a.clone(),
                select_b: self.select_b.clone(),
                exclude: self.exclude.clone(),
            },
            outputs: self.outputs.into_options(self.fail_on == FailOnArg::New)?,
        })
    }
}

/// What the binary should do after a successful run.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// What goes to stdout: the report in `--format` (default JSON; None when the report is
    /// written to `--output` and no `--format` is given).
    pub stdout: Option<String>,
    /// Lines for stderr (warnings).
    pub warnings: Vec<String>,
    /// 0 or 1.
    pub exit_code: u8,
    /// The finished report (for the human summary on a terminal).
    pub report: Box<report::Report>,
}

/// Do the whole job for a validated config.
pub fn run(cfg: &Config) -> Result<Outcome> {
    run_with_progress(cfg, &|_| {})
}

/// [`run`], calling `progress` as each phase starts (the binary drives a spinner with it).
pub fn run_with_progress(cfg: &Config, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(cfg.threads)
        .build()
        .map_err(|e| Error::Usage(format!("--threads: {e}")))?;
    pool.install(|| run_in_pool(cfg, pool.current_num_threads(), progress))
}

fn run_in_pool(cfg: &Config, threads: usize, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    progress(Phase::Load);
    let t0 = Instant::now();
    let (a, b) = if cfg.selection.scene {
        // `meshclash scene FILE`: one file, its parts against each other.
        let a = query::load_input(&cfg.inputs[1])?;
        (a.clone(), a)
    } else {
        let (a, b) = rayon::join(|| query::load_input(&cfg.inputs[0]), || query::load_input(&cfg.inputs[1]));
        (a?, b?)
    };
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let size = crate::geom::Aabb::of_points(&a.mesh.positions)
        .union(crate::geom::Aabb::of_points(&b.mesh.positions))
        .extent()
        .length();
    let mut settings = cfg.settings;
    settings.tolerances =
        Tolerances { touch: cfg.touch.resolve(size), clearance: cfg.clearance.resolve(size) };
    if !settings.tolerances.touch.is_finite() || !settings.tolerances.clearance.is_finite() {
        return Err(Error::Usage("relative tolerance overflows for this model size".into()));
    }
    progress(Phase::Check);
    let outcome = crate::assembly::run(&a.mesh, &b.mesh, &cfg.selection, &settings)
        .map_err(|e| Error::input(&cfg.inputs[1].path, e))?;
    let assembly = report::assembly_view(&outcome);
    let result = outcome.result;
    let failed = cfg.fail_on.fails(result.verdict);
    let cross_check = if cfg.cross_check {
        progress(Phase::CrossCheck);
        let p = crate::cross_check::parry_f64(&a.mesh, &b.mesh, true)
            .map_err(|e| Error::Usage(format!("--cross-check parry: {e}")))?;
        Some(report::cross_check_report(&result, &p, cfg.max_pairs, cfg.deterministic))
    } else {
        None
    };
    let ctx = report::Context {
        inputs: [&a, &b],
        transforms: [cfg.inputs[0].transform, cfg.inputs[1].transform],
        settings: SettingsReport {
            touch_tolerance: settings.tolerances.touch,
            clearance: settings.tolerances.clearance,
            touch_tolerance_given: cfg.touch.spec(),
            clearance_given: cfg.clearance.spec(),
            model_size: size,
            units: "model".into(),
            fail_on: cfg.fail_on.name().into(),
            bvh: cfg.settings.bvh.strategy.name().into(),
            mode: cfg.settings.mode.name().into(),
            first_hit: cfg.settings.first_hit,
            distance_rel_err: cfg.settings.distance_error.rel,
            distance_abs_err: cfg.settings.distance_error.abs,
            leaf_size: cfg.settings.bvh.leaf_size,
            max_pairs: cfg.max_pairs,
            threads: (!cfg.deterministic).then_some(threads),
        },
        failed,
        times: (!cfg.deterministic).then(|| (load_ms, t0.elapsed().as_secs_f64() * 1e3)),
        cross_check,
        assembly,
    };
    let mut rep = report::build(&ctx, &result);
    progress(Phase::Write);
    crate::output::finish(&cfg.outputs, &mut rep, &result, [&a.mesh, &b.mesh])?;
    let json = report::to_json(&rep);
    let warnings = rep.warnings.clone();
    if let Some(path) = &cfg.output {
        report::write_atomic(path, json.as_bytes())?;
    }
    let stdout = crate::output::stdout_for(&cfg.outputs, &rep, &json, cfg.output.is_some());
    let exit_code = rep.failed as u8;
    Ok(Outcome { stdout, warnings, exit_code, report: Box::new(rep) })
}
