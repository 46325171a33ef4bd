//! Command line: clap definitions, and their conversion into a validated [`Config`] (the core
//! never sees clap). [`run`] does the whole job and hands back what to print and the exit code;
//! the binary prints it.

use crate::bvh::{BuildOptions, Strategy};
use crate::check::query::{self, DistanceError, FailOn, InputSpec, Mode, Settings};
use crate::error::{Error, Result};
use crate::geom::predicates::Tolerances;
use crate::output::progress::Phase;
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
    /// Pairs that do not touch but are within this distance count as touching: in the report
    /// units (--units, else the files' own), or relative to the model size with a `rel` suffix (`1e-6rel` = 1e-6 × the diagonal of the
    /// box around both inputs).
    #[arg(long, value_name = "E", default_value = "0", allow_hyphen_values = true)]
    pub touch_tolerance: String,
    /// Also report every pair closer than D that does not touch (report units, or `rel` suffix).
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
    /// Split every part into its connected bodies (triangles joined through edges used by
    /// exactly two triangles), named `part/body1`, `part/body2`, …: e.g. two cubes in one STL
    /// solid that touch along an edge become two parts.
    #[arg(long)]
    pub split_bodies: bool,
    /// Estimate each clash region's penetration depth: the deepest vertex of one part inside
    /// the other closed part, measured to its surface (a lower bound; costs a tree per part
    /// with a region and point queries, at most about 2048 per region and side).
    #[arg(long)]
    pub penetration: bool,
    /// Allowed relative error of the minimum distance (reported d <= (1+R)·true + A).
    #[arg(long, value_name = "R", default_value_t = 0.0)]
    pub distance_rel_err: f64,
    /// Allowed absolute error of the minimum distance (report units).
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
    /// Units of the report: every input is converted into U (multiplied in f64 after loading,
    /// before --transform/--translate, which are therefore in U), and all coordinates,
    /// distances and tolerances are in U. Inputs of unknown units (OBJ, STL, without
    /// --units-a/-b) are taken to be in U, with a warning. Verdicts are exact for the converted
    /// coordinates (a factor that is not a power of two rounds each coordinate once). Default:
    /// --units-a, else --units-b, else none: no conversion, lengths in the files' own units.
    #[arg(long, value_enum, value_name = "U")]
    pub units: Option<Unit>,
    /// Units of A's coordinates [default: m for glTF/GLB (the glTF specification), unknown for
    /// OBJ/STL]. In scene mode, the units of the file.
    #[arg(long, value_enum, value_name = "U")]
    pub units_a: Option<Unit>,
    /// Units of B's coordinates, as --units-a.
    #[arg(long, value_enum, value_name = "U")]
    pub units_b: Option<Unit>,
    /// Multiply A's coordinates by F (finite, > 0) with the unit conversion, before
    /// --transform-a/--translate-a: the coordinates are multiplied once by the f64 product of
    /// the conversion factor and F. In scene mode, applies to the file.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub scale_a: Option<f64>,
    /// Multiply B's coordinates by F, as --scale-a.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub scale_b: Option<f64>,
    /// Scene mode: also check every selected part against itself (self-clashing triangle pairs
    /// and mesh health, as `meshclash self`), in a `self` block of the report. A crossing
    /// self-clash pair fails the run under --fail-on clash (any self-clash pair under touching
    /// or clearance); health findings fail it when named in --self-fail-on.
    #[arg(long = "self")]
    pub self_check: bool,
    /// With --self: also fail on these (comma-separated): open, non-manifold, duplicates,
    /// degenerate, winding, touching, self-clash.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "WHAT", requires = "self_check")]
    pub self_fail_on: Vec<crate::report::self_report::SelfFailOn>,
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
    /// Moved to the `meshclash-bench` binary (workspace member `bench/`): runs it with these
    /// arguments when it sits next to `meshclash`, else says how to run it.
    #[command(disable_help_flag = true)]
    Bench(BenchForward),
    /// Run the named checks of a clash-set file (JSON) in one go: one JSON document with every
    /// check's report, exit 1 if any check fails its --fail-on, 2 on bad input in any check.
    ClashSet(crate::clash_set::ClashSetArgs),
    /// Check one mesh against itself: self-clashing triangle pairs and mesh health per part.
    #[command(name = "self")]
    SelfCheck(crate::self_cmd::SelfArgs),
}

/// `meshclash bench ARGS..`: forwarded to `meshclash-bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchForward {
    /// Arguments for `meshclash-bench` (see `cargo run --release -p meshclash-bench -- --help`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
    pub args: Vec<std::ffi::OsString>,
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
    pub selection: crate::check::assembly::Selection,
    /// Output format, JUnit and GLB files, baseline.
    pub outputs: crate::output::OutputOptions,
    /// Units and scales (`--units`, `--units-a/-b`, `--scale-a/-b`).
    pub units: UnitsConfig,
    /// `--split-bodies`.
    pub split_bodies: bool,
    /// `--penetration`.
    pub penetration: bool,
    /// `--self` (scene mode): the conditions that fail the run on self-clash and health.
    pub self_check: Option<Vec<crate::report::self_report::SelfFailOn>>,
}

/// A unit of length (`--units`, `--units-a`, `--units-b`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, ValueEnum, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
pub enum Unit {
    /// Micrometre.
    #[value(name = "um")]
    #[serde(rename = "um")]
    Um,
    /// Millimetre.
    #[value(name = "mm")]
    #[serde(rename = "mm")]
    Mm,
    /// Centimetre.
    #[value(name = "cm")]
    #[serde(rename = "cm")]
    Cm,
    /// Metre (glTF's unit by specification).
    #[value(name = "m")]
    #[serde(rename = "m")]
    M,
    /// Inch (25.4 mm exactly).
    #[value(name = "in")]
    #[serde(rename = "in")]
    In,
    /// Foot (12 in).
    #[value(name = "ft")]
    #[serde(rename = "ft")]
    Ft,
    /// Yard (3 ft).
    #[value(name = "yd")]
    #[serde(rename = "yd")]
    Yd,
}

impl Unit {
    /// Its name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Um => "um",
            Unit::Mm => "mm",
            Unit::Cm => "cm",
            Unit::M => "m",
            Unit::In => "in",
            Unit::Ft => "ft",
            Unit::Yd => "yd",
        }
    }

    /// Its length in micrometres: an exact integer for every unit (the inch is 25.4 mm by
    /// definition).
    pub fn micrometres(self) -> u32 {
        match self {
            Unit::Um => 1,
            Unit::Mm => 1_000,
            Unit::Cm => 10_000,
            Unit::M => 1_000_000,
            Unit::In => 25_400,
            Unit::Ft => 304_800,
            Unit::Yd => 914_400,
        }
    }

    /// The factor that converts coordinates in `self` to `to`: the exact ratio of two integers,
    /// rounded once to f64 (one IEEE division of exactly representable operands).
    pub fn factor_to(self, to: Unit) -> f64 {
        f64::from(self.micrometres()) / f64::from(to.micrometres())
    }
}

/// Units and raw scales, validated. Indices follow [`Config::inputs`] (in scene mode the file is
/// input 1, and `--units-a`/`--scale-a` are stored there).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UnitsConfig {
    /// `--units`, or the default (`--units-a`, else `--units-b`); None: no conversion.
    pub report: Option<Unit>,
    /// Declared units of each input.
    pub inputs: [Option<Unit>; 2],
    /// Raw multipliers (None = 1).
    pub scale: [Option<f64>; 2],
}

impl UnitsConfig {
    /// True if any units or scale flag was given (otherwise inputs load exactly as before, and
    /// the report has no `inputs.*.units` blocks).
    pub fn active(&self) -> bool {
        self.report.is_some()
            || self.inputs.iter().any(Option::is_some)
            || self.scale.iter().any(Option::is_some)
    }

    /// The report's `settings.units`: the report unit, or `model`.
    pub fn report_name(&self) -> &'static str {
        self.report.map_or("model", Unit::name)
    }

    /// Resolve input `i` of format `format`: the multiplier, the report block and a warning when
    /// the units were assumed. `flag` names the units flag for the warning.
    pub fn resolve(
        &self,
        i: usize,
        format: crate::load::Format,
        flag: &str,
    ) -> (f64, report::InputUnitsReport, Option<String>) {
        let scale = self.scale[i].unwrap_or(1.0);
        let gltf = matches!(format, crate::load::Format::Gltf | crate::load::Format::Glb);
        let (units, source, warning) = match (self.report, self.inputs[i]) {
            (None, _) => (None, None, None),
            (Some(_), Some(u)) => (Some(u), Some("given"), None),
            (Some(_), None) if gltf => (Some(Unit::M), Some("gltf"), None),
            (Some(r), None) => (
                Some(r),
                Some("assumed"),
                Some(format!(
                    "units unknown ({} files carry none): taken to be {}, the report units; give {flag} to declare them",
                    format.name().to_uppercase(),
                    r.name()
                )),
            ),
        };
        let factor = match (units, self.report) {
            (Some(u), Some(r)) => u.factor_to(r),
            _ => 1.0,
        };
        let multiplier = factor * scale;
        let block = report::InputUnitsReport {
            units: units.map(|u| u.name().to_string()),
            source: source.map(str::to_string),
            factor,
            scale,
            multiplier,
        };
        (multiplier, block, warning)
    }
}

fn positive_scale(flag: &str, v: Option<f64>) -> Result<Option<f64>> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => {
            Err(Error::Usage(format!("--{flag} must be a finite number > 0, got {x}")))
        }
        _ => Ok(v),
    }
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
        if self.self_check && !scene_mode {
            return Err(Error::Usage(
                "--self works with scene (meshclash scene FILE --self); for one mesh use meshclash self FILE"
                    .into(),
            ));
        }
        if scene_mode && self.cross_check.is_some() {
            return Err(Error::Usage("--cross-check works on two files, not with scene".into()));
        }
        let touch = parse_tolerance("touch-tolerance", &self.touch_tolerance)?;
        let clearance = parse_tolerance("clearance", &self.clearance)?;
        let scale = [positive_scale("scale-a", self.scale_a)?, positive_scale("scale-b", self.scale_b)?];
        let units = if scene_mode {
            if self.units_b.is_some() || self.scale_b.is_some() {
                return Err(Error::Usage(
                    "scene has one file: give its units and scale with --units-a and --scale-a".into(),
                ));
            }
            UnitsConfig {
                report: self.units.or(self.units_a),
                inputs: [None, self.units_a],
                scale: [None, scale[0]],
            }
        } else {
            UnitsConfig {
                report: self.units.or(self.units_a).or(self.units_b),
                inputs: [self.units_a, self.units_b],
                scale,
            }
        };
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
            self_check: self.self_check.then(|| {
                let base = match self.fail_on {
                    FailOnArg::Clash => FailOn::Clash,
                    FailOnArg::Touching => FailOn::Touching,
                    FailOnArg::Clearance => FailOn::Clearance,
                    FailOnArg::Never | FailOnArg::New => FailOn::Never,
                };
                crate::report::self_report::scene_fail_on(base, &self.self_fail_on)
            }),
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
            selection: crate::check::assembly::Selection {
                scene: scene_mode,
                select_a: self.select_a.clone(),
                select_b: self.select_b.clone(),
                exclude: self.exclude.clone(),
            },
            outputs: self.outputs.into_options(self.fail_on == FailOnArg::New)?,
            units,
            split_bodies: self.split_bodies,
            penetration: self.penetration,
        })
    }
}

/// What the binary should do after a successful run.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// What goes to stdout: the report in `--format` (default JSON; None when the report is
    /// written to `--output` and no `--format` is given, or when the JSON report goes there:
    /// see `json_stdout`).
    pub stdout: Option<String>,
    /// The JSON report goes to stdout: the binary streams `report` there
    /// ([`crate::output::write_report_json`]) instead of holding its text in memory.
    pub json_stdout: bool,
    /// Lines for stderr (warnings).
    pub warnings: Vec<String>,
    /// [`crate::error::ExitCode::Ok`] or [`crate::error::ExitCode::Findings`].
    pub exit_code: crate::error::ExitCode,
    /// The finished report (for the human summary on a terminal).
    pub report: Box<report::Report>,
}

/// Do the whole job for a validated config.
pub fn run(cfg: &Config) -> Result<Outcome> {
    run_with_progress(cfg, &|_| {})
}

/// [`run`], calling `progress` as each phase starts (the binary drives a spinner with it).
pub fn run_with_progress(cfg: &Config, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    crate::output::check_outputs(cfg)?;
    in_pool(cfg.threads, |threads| run_in_pool(cfg, threads, progress))
}

/// Run `f` in a pool of `threads` workers (`--threads`; 0 = one per core), giving it the pool's
/// size (the single command and the clash-set runner share this).
pub fn in_pool<T: Send>(threads: usize, f: impl FnOnce(usize) -> Result<T> + Send) -> Result<T> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Usage(format!("--threads: {e}")))?;
    pool.install(|| f(pool.current_num_threads()))
}

fn run_in_pool(cfg: &Config, threads: usize, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    let mut staged = crate::output::write::Staged::new();
    let rep = check_staged(cfg, threads, progress, &mut staged)?;
    let warnings = rep.warnings.clone();
    if let Some(path) = &cfg.output {
        staged.stage_with(path, |w| crate::output::write_report_json(w, &rep))?;
    }
    staged.commit()?;
    let (stdout, json_stdout) = crate::output::stdout_for(&cfg.outputs, &rep, cfg.output.is_some());
    let exit_code = crate::error::ExitCode::from_failed(rep.failed);
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
        let (loaded, format) = crate::load::load_path(&spec.path)?;
        let (multiplier, block, warning) = cfg.units.resolve(i, format, flag);
        (query::prepare_input(spec, loaded, format, multiplier, warning)?, Some(block))
    };
    if cfg.split_bodies {
        crate::scene::bodies::split_bodies(&mut input.mesh);
    }
    Ok((input, units))
}

/// Check one configuration and return the finished report (with finding ids, the baseline
/// comparison, and the JUnit and GLB files of `cfg.outputs` written), without writing the report
/// itself: the single command and every check of a clash set go through here.
pub fn check_in_pool(
    cfg: &Config,
    threads: usize,
    progress: &(dyn Fn(Phase) + Sync),
) -> Result<report::Report> {
    let mut staged = crate::output::write::Staged::new();
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
    staged: &mut crate::output::write::Staged,
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
    let outcome = crate::check::assembly::run(&a.mesh, &b.mesh, &cfg.selection, &settings)
        .map_err(|e| Error::input(&cfg.inputs[1].path, e))?;
    let assembly = report::assembly_view(&outcome, cfg.max_pairs);
    let result = outcome.result;
    let failed = cfg.fail_on.fails(result.verdict);
    let cross_check = if cfg.cross_check {
        progress(Phase::CrossCheck);
        let p = crate::check::cross_check::parry_f64(&a.mesh, &b.mesh, true)
            .map_err(|e| Error::Usage(format!("--cross-check parry: {e}")))?;
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
    crate::output::finish(&cfg.outputs, &mut rep, &result, [&a.mesh, &b.mesh], staged)?;
    Ok(rep)
}
