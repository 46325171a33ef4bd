//! Validation of the parsed command line into a [`Config`] (the library never sees clap).

use super::args::{Args, BvhArg, CheckArgs, Command, DetailArg, FailOnArg, ModeArg, TopicsArg, Unit};
use glam::{DMat4, DVec3, DVec4};
use meshclash::bvh::{BuildOptions, Strategy};
use meshclash::check::query::{Detail, DistanceError, FailOn, InputSpec, Mode, Settings};
use meshclash::error::{Error, Result, UsageProblem};
use meshclash::geom::predicates::Tolerances;
use meshclash::report;
use std::path::PathBuf;

fn nonneg(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(Error::bad_flag(flag, UsageProblem::NotNonNegative { value: v }))
    }
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
    pub selection: meshclash::check::assembly::Selection,
    /// Output format, JUnit and GLB files, baseline.
    pub outputs: meshclash::output::OutputOptions,
    /// Units and scales (`--units`, `--units-a/-b`, `--scale-a/-b`).
    pub units: UnitsConfig,
    /// `--split-bodies`.
    pub split_bodies: bool,
    /// `--penetration`.
    pub penetration: bool,
    /// `--self` (scene mode): the conditions that fail the run on self-clash and health.
    pub self_check: Option<Vec<meshclash::report::self_report::SelfFailOn>>,
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
        format: meshclash::load::Format,
        flag: &str,
    ) -> (f64, report::InputUnitsReport, Option<String>) {
        let scale = self.scale[i].unwrap_or(1.0);
        let gltf = matches!(format, meshclash::load::Format::Gltf | meshclash::load::Format::Glb);
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
            Err(Error::bad_flag(flag, UsageProblem::NotPositive { value: x }))
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
                _ => Err(Error::bad_flag(flag, UsageProblem::NotANumber { text: t.to_string() })),
            }
        })
        .collect()
}

/// Parse a row-major 3×4 or 4×4 affine matrix.
pub fn parse_transform(flag: &str, s: &str) -> Result<DMat4> {
    let v = numbers(flag, s)?;
    if v.len() != 12 && v.len() != 16 {
        return Err(Error::bad_flag(flag, UsageProblem::MatrixLength { got: v.len() }));
    }
    if v.len() == 16 && v[12..] != [0.0, 0.0, 0.0, 1.0] {
        return Err(Error::bad_flag(flag, UsageProblem::NotAffine));
    }
    let row = |r: usize| DVec4::new(v[4 * r], v[4 * r + 1], v[4 * r + 2], v[4 * r + 3]);
    Ok(DMat4::from_cols(row(0), row(1), row(2), DVec4::W).transpose())
}

/// Parse `x,y,z`.
pub fn parse_translation(flag: &str, s: &str) -> Result<DVec3> {
    let v = numbers(flag, s)?;
    match v[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(Error::bad_flag(flag, UsageProblem::NotATriple { got: v.len() })),
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
        _ => Err(Error::bad_flag(flag, UsageProblem::BadTolerance { text: s.to_string() })),
    }
}

impl Args {
    /// Validate into a [`Config`] (a two-file check, or `scene FILE`).
    pub fn into_config(self) -> Result<Config> {
        match self.command {
            // Scene mode: input A is the word `scene`, input B the file (as the report has it).
            Some(Command::Scene(s)) => s.check.into_config(Some(PathBuf::from("scene")), Some(s.file), true),
            // The word `scene` in place of A is scene mode too (`meshclash -- scene FILE`, and
            // the clash-set runner's argv); `./scene` names a file so called.
            _ => {
                let scene = self.a.as_deref() == Some(std::path::Path::new("scene"));
                self.check.into_config(self.a, self.b, scene)
            }
        }
    }
}

impl CheckArgs {
    /// Validate the flags of a check of `a` against `b` (`scene_mode`: `b`'s parts against
    /// each other).
    pub fn into_config(self, a: Option<PathBuf>, b: Option<PathBuf>, scene_mode: bool) -> Result<Config> {
        if !(1..=64).contains(&self.leaf_size) {
            let problem = UsageProblem::OutOfRange { value: self.leaf_size.into(), min: 1, max: 64 };
            return Err(Error::bad_flag("leaf-size", problem));
        }
        if self.self_check && !scene_mode {
            return Err(Error::bad_flag(
                "self",
                UsageProblem::Conflict(
                    "--self works with scene (meshclash scene FILE --self); for one mesh use meshclash self FILE"
                        .into(),
                ),
            ));
        }
        if self.detail == DetailArg::Parts {
            let o = &self.outputs;
            let needs_regions = [
                (o.html.is_some(), "html", ""),
                (o.export_glb.is_some(), "export-glb", ""),
                (o.baseline.is_some(), "baseline", ""),
                (
                    o.bcf.is_some() && o.bcf_topics == TopicsArg::Regions,
                    "bcf",
                    " (region topics; use --bcf-topics part-pairs)",
                ),
                (self.cross_check.is_some(), "cross-check", ""),
            ];
            if let Some((_, flag, note)) = needs_regions.iter().find(|(given, ..)| *given) {
                let why = format!(
                    "--{flag}{note} needs the triangle pairs that --detail parts does not keep: drop one of them"
                );
                return Err(Error::bad_flag(flag, UsageProblem::Conflict(why)));
            }
        }
        if scene_mode && self.cross_check.is_some() {
            let why = "--cross-check works on two files, not with scene".to_string();
            return Err(Error::bad_flag("cross-check", UsageProblem::Conflict(why)));
        }
        let touch = parse_tolerance("touch-tolerance", &self.touch_tolerance)?;
        let clearance = parse_tolerance("clearance", &self.clearance)?;
        let scale = [positive_scale("scale-a", self.scale_a)?, positive_scale("scale-b", self.scale_b)?];
        let units = if scene_mode {
            if self.units_b.is_some() || self.scale_b.is_some() {
                let flag = if self.units_b.is_some() { "units-b" } else { "scale-b" };
                let why = "scene has one file: give its units and scale with --units-a and --scale-a";
                return Err(Error::bad_flag(flag, UsageProblem::Conflict(why.into())));
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
                    path: a.ok_or_else(|| Error::usage(UsageProblem::Missing("mesh A".into())))?,
                    transform: placement('a', &self.transform_a, &self.translate_a)?,
                },
                InputSpec {
                    path: b.ok_or_else(|| Error::usage(UsageProblem::Missing("mesh B".into())))?,
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
                detail: match self.detail {
                    DetailArg::Pairs => Detail::Pairs,
                    DetailArg::Parts => Detail::Parts,
                },
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
                let extra: Vec<meshclash::report::self_report::SelfFailOn> =
                    self.self_fail_on.iter().map(|&f| f.into()).collect();
                meshclash::report::self_report::scene_fail_on(base, &extra)
            }),
            fail_on: match self.fail_on {
                FailOnArg::Clash => FailOn::Clash,
                FailOnArg::Touching => FailOn::Touching,
                FailOnArg::Clearance => FailOn::Clearance,
                // `new` is decided after the baseline comparison (meshclash::output::finish).
                FailOnArg::Never | FailOnArg::New => FailOn::Never,
            },
            threads: self.threads,
            max_pairs: self.max_pairs,
            deterministic: self.no_timings,
            cross_check: self.cross_check.is_some(),
            selection: meshclash::check::assembly::Selection {
                scene: scene_mode,
                select_a: self.select_a.clone(),
                select_b: self.select_b.clone(),
                exclude: self.exclude.clone(),
                hook: None,
            },
            outputs: self.outputs.into_options(self.fail_on == FailOnArg::New)?,
            units,
            split_bodies: self.split_bodies,
            penetration: self.penetration,
        })
    }
}
