//! Validation of the parsed command line into a [`Config`] (the library never sees clap).

use super::args::{Args, BvhArg, CheckArgs, Command, DetailArg, FailOnArg, ModeArg, TopicsArg};
use glam::{DMat4, DVec3, DVec4};
use meshclash::bvh::{BuildOptions, Strategy};
use meshclash::check::query::{Detail, DistanceError, FailOn, Mode, Settings};
use meshclash::error::{Error, Result, UsageProblem};
use meshclash::geom::predicates::Tolerances;
use meshclash::pipeline::{Gate, InputRequest, Request, Source, Tolerance, Units};
use std::path::PathBuf;

fn nonneg(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(Error::bad_flag(flag, UsageProblem::NotNonNegative { value: v }))
    }
}

/// A validated configuration: the pipeline's request and what the command writes.
#[derive(Debug, Clone)]
pub struct Config {
    /// The check.
    pub request: Request,
    /// Where the report goes (None = stdout).
    pub output: Option<PathBuf>,
    /// Output format and side files (JUnit, GLB, HTML, BCF).
    pub outputs: meshclash::output::OutputOptions,
    /// Worker threads (0 = one per core).
    pub threads: usize,
}

impl Config {
    /// The mesh files the check reads (in scene mode, the one file).
    pub fn input_paths(&self) -> Vec<&std::path::Path> {
        self.request.inputs.iter().map(|i| i.path()).collect()
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
        let conflict = |flag: &str, why: &str| Error::bad_flag(flag, UsageProblem::Conflict(why.into()));
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
                return Err(conflict(flag, &why));
            }
        }
        let touch = Tolerance::parse("touch-tolerance", &self.touch_tolerance)?;
        let clearance = Tolerance::parse("clearance", &self.clearance)?;
        let scale = [positive_scale("scale-a", self.scale_a)?, positive_scale("scale-b", self.scale_b)?];
        let (inputs, units) = if scene_mode {
            let b_flag = [
                (self.units_b.is_some(), "units-b"),
                (self.scale_b.is_some(), "scale-b"),
                (self.transform_b.is_some(), "transform-b"),
                (self.translate_b.is_some(), "translate-b"),
            ];
            if let Some((_, flag)) = b_flag.iter().find(|(given, _)| *given) {
                let why =
                    "scene has one file: give its units, scale and placement with --units-a, --scale-a, \
                           --transform-a and --translate-a";
                return Err(conflict(flag, why));
            }
            let file = b.ok_or_else(|| Error::usage(UsageProblem::Missing("scene FILE".into())))?;
            let input = InputRequest {
                source: Source::File(file),
                transform: placement('a', &self.transform_a, &self.translate_a)?,
            };
            let units = Units {
                report: self.units.or(self.units_a),
                inputs: [self.units_a, None],
                scale: [scale[0], None],
            };
            (vec![input], units)
        } else {
            let side = |path: Option<PathBuf>, name: char, transform, translate| -> Result<InputRequest> {
                let what = format!("mesh {}", name.to_ascii_uppercase());
                Ok(InputRequest {
                    source: Source::File(path.ok_or_else(|| Error::usage(UsageProblem::Missing(what)))?),
                    transform: placement(name, transform, translate)?,
                })
            };
            let inputs = vec![
                side(a, 'a', &self.transform_a, &self.translate_a)?,
                side(b, 'b', &self.transform_b, &self.translate_b)?,
            ];
            let units = Units {
                report: self.units.or(self.units_a).or(self.units_b),
                inputs: [self.units_a, self.units_b],
                scale,
            };
            (inputs, units)
        };
        let verdict_gate = |f: FailOnArg| match f {
            FailOnArg::Clash => FailOn::Clash,
            FailOnArg::Touching => FailOn::Touching,
            FailOnArg::Clearance => FailOn::Clearance,
            FailOnArg::Never | FailOnArg::New => FailOn::Never,
        };
        let request = Request {
            inputs,
            units,
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
            gate: match self.fail_on {
                FailOnArg::New => Gate::New,
                f => Gate::Verdict(verdict_gate(f)),
            },
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
            split_bodies: self.split_bodies,
            penetration: self.penetration,
            self_check: self.self_check.then(|| {
                let extra: Vec<meshclash::report::self_report::SelfFailOn> =
                    self.self_fail_on.iter().map(|&f| f.into()).collect();
                meshclash::report::self_report::scene_fail_on(verdict_gate(self.fail_on), &extra)
            }),
            baseline: self.outputs.baseline.clone(),
            missing_shards: Vec::new(),
            cache: self
                .cache
                .clone()
                .or_else(|| std::env::var_os("MESHCLASH_CACHE").filter(|v| !v.is_empty()).map(PathBuf::from))
                .map(|dir| meshclash::cache::CacheConfig { dir, max_bytes: self.cache_max_bytes }),
        };
        request.validate()?;
        Ok(Config {
            request,
            output: self.output,
            outputs: self.outputs.into_options(),
            threads: self.threads,
        })
    }
}
