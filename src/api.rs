//! Entry points for embedding meshclash in another program (the Python package in `python/`
//! uses nothing else): the JSON report for two inputs that are files or in-memory meshes, and
//! the *prepared* meshes of [`crate::prepared`] (re-exported here) — a mesh whose tree is built
//! once, then placed under any number of affine transforms for the yes/no and distance queries a
//! collision manager makes.
//!
//! [`report`] goes the same way as the command line (load, place, [`crate::check::assembly::run`],
//! [`crate::report::build`], finding ids), so the same inputs and settings give the same document
//! (the Python tests compare them, parsed, with the binary's `--no-timings` output).

use crate::bvh::BuildOptions;
use crate::check::assembly::{self, Selection};
use crate::check::query::{self, Detail, DistanceError, Input, InputSpec, Mode, Settings};
use crate::error::{Error, InputProblem, Location, NonFinite, Result, UsageProblem};
use crate::geom::predicates::Tolerances;
use crate::geom::{Aabb, DVec3};
use crate::load::Format;
use crate::report::{self, Report, SettingsReport};
use crate::scene::mesh::{Loaded, Mesh, Object};
use glam::DMat4;
use std::path::Path;
use std::time::Instant;

pub use crate::prepared::{collide, distance, meeting_pairs, Collision, Placed, PlacedMesh, Prepared};

/// The `format` an in-memory input has in the report.
pub const ARRAY_FORMAT: &str = "array";

/// A tolerance as given: absolute, or relative to the diagonal of the box around both inputs
/// (the command line's `1e-6rel`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// Model units.
    Abs(f64),
    /// Times the diagonal of the box around both inputs.
    Rel(f64),
}

impl Tolerance {
    /// Parse `0.5` or `1e-6rel` (finite, >= 0); the error names `flag` as the command line does.
    pub fn parse(flag: &str, s: &str) -> Result<Tolerance> {
        let t = s.trim();
        let (num, rel) = match t.strip_suffix("rel") {
            Some(n) => (n, true),
            None => (t, false),
        };
        match num.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(if rel { Tolerance::Rel(v) } else { Tolerance::Abs(v) }),
            _ => Err(Error::bad_flag(flag, UsageProblem::BadTolerance { text: s.to_string() })),
        }
    }

    fn resolve(self, size: f64) -> f64 {
        match self {
            Tolerance::Abs(v) => v,
            Tolerance::Rel(r) => r * size,
        }
    }

    fn spec(self) -> String {
        match self {
            Tolerance::Abs(v) => format!("{v}"),
            Tolerance::Rel(r) => format!("{r}rel"),
        }
    }
}

/// What to check and how: the command line's flags that shape the report.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// `--touch-tolerance`.
    pub touch: Tolerance,
    /// `--clearance`.
    pub clearance: Tolerance,
    /// `--max-pairs`.
    pub max_pairs: usize,
    /// `--mode`.
    pub mode: Mode,
    /// `--first-hit`.
    pub first_hit: bool,
    /// `--detail`.
    pub detail: Detail,
    /// `--bvh`, `--leaf-size`.
    pub bvh: BuildOptions,
    /// `--distance-rel-err`, `--distance-abs-err`.
    pub distance_error: DistanceError,
    /// `--no-timings`: no timings and no thread count in the report.
    pub deterministic: bool,
    /// `--penetration`.
    pub penetration: bool,
    /// Scene mode and part selections (`scene`, `--select-a/-b`, `--exclude`).
    pub selection: Selection,
    /// `--split-bodies`.
    pub split_bodies: bool,
    /// `--threads` (0 = the current pool, or one per core).
    pub threads: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            touch: Tolerance::Abs(0.0),
            clearance: Tolerance::Abs(0.0),
            max_pairs: 1000,
            mode: Mode::Exact,
            first_hit: false,
            detail: Detail::Pairs,
            bvh: BuildOptions::default(),
            distance_error: DistanceError::default(),
            deterministic: false,
            penetration: false,
            selection: Selection::default(),
            split_bodies: false,
            threads: 0,
        }
    }
}

impl Options {
    /// Reject what the command line rejects (leaf size, distance allowances).
    pub fn validate(&self) -> Result<()> {
        if !(1..=64).contains(&self.bvh.leaf_size) {
            let problem = UsageProblem::OutOfRange { value: self.bvh.leaf_size.into(), min: 1, max: 64 };
            return Err(Error::bad_flag("leaf-size", problem));
        }
        for (flag, v) in
            [("distance-rel-err", self.distance_error.rel), ("distance-abs-err", self.distance_error.abs)]
        {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::bad_flag(flag, UsageProblem::NotNonNegative { value: v }));
            }
        }
        Ok(())
    }
}

/// One input of a report: a loaded file, or a mesh handed over in memory (reported with
/// [`ARRAY_FORMAT`] and its label as the path).
#[derive(Debug, Clone)]
pub struct Source {
    /// The placed input.
    pub input: Input,
    /// The transform applied.
    pub transform: DMat4,
    /// True for an in-memory mesh.
    pub array: bool,
}

/// Load a file and place it, as the command line does for `A`/`B` (with `--split-bodies` when
/// `split_bodies`).
pub fn file_source(path: &Path, transform: DMat4, split_bodies: bool) -> Result<Source> {
    let mut input = query::load_input(&InputSpec { path: path.to_path_buf(), transform })?;
    if split_bodies {
        crate::scene::bodies::split_bodies(&mut input.mesh);
    }
    Ok(Source { input, transform, array: false })
}

/// Place an in-memory mesh (from [`mesh_from_arrays`]); `label` stands for its path in the report
/// and in error messages.
pub fn array_source(label: &Path, mesh: Mesh, transform: DMat4, split_bodies: bool) -> Result<Source> {
    let spec = InputSpec { path: label.to_path_buf(), transform };
    let mut input =
        query::prepare_input(&spec, Loaded { mesh, warnings: Vec::new() }, Format::Obj, 1.0, None)?;
    if split_bodies {
        crate::scene::bodies::split_bodies(&mut input.mesh);
    }
    Ok(Source { input, transform, array: true })
}

/// Triangle indices from a flat list of any integer type (three per triangle), with the
/// loaders' message for an index out of range (`label` names the input).
pub fn triangles_from<I>(label: &Path, flat: &[I], vertices: usize) -> Result<Vec<[u32; 3]>>
where
    I: Copy + TryInto<u32> + TryInto<i128>,
{
    let bad = |t: usize, v: I| {
        // Every primitive integer fits in i128.
        let index = TryInto::<i128>::try_into(v).unwrap_or(i128::MAX);
        Error::at(label, Location::Triangle(t), InputProblem::IndexOutOfRange { index, len: vertices })
    };
    flat.chunks_exact(3)
        .enumerate()
        .map(|(t, c)| {
            let mut out = [0u32; 3];
            for k in 0..3 {
                let v: u32 = c[k].try_into().map_err(|_| bad(t, c[k]))?;
                if v as usize >= vertices {
                    return Err(bad(t, c[k]));
                }
                out[k] = v;
            }
            Ok(out)
        })
        .collect()
}

/// A mesh of one object named `name` from vertex positions and triangles, validated as the
/// loaders validate a file: at least one triangle, indices in range, finite coordinates.
pub fn mesh_from_arrays(
    label: &Path,
    name: &str,
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
) -> Result<Mesh> {
    if triangles.is_empty() {
        return Err(Error::in_file(label, InputProblem::NoTriangles));
    }
    let n = positions.len();
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= n) {
            let problem = InputProblem::IndexOutOfRange { index: v.into(), len: n };
            return Err(Error::at(label, Location::Triangle(t), problem));
        }
    }
    for (i, p) in positions.iter().enumerate() {
        if let Some(value) = NonFinite::first(p.to_array()) {
            return Err(Error::at(label, Location::Vertex(i), InputProblem::NonFinite { value }));
        }
    }
    let name = if name.is_empty() { "object0" } else { name };
    Ok(Mesh {
        positions,
        tri_object: vec![0; triangles.len()],
        triangles,
        objects: vec![Object { name: name.to_string(), ..Object::default() }],
    })
}

/// Run `f` in a pool of `threads` workers (0 = the current pool), giving it the pool's size.
pub fn in_pool<T: Send>(threads: usize, f: impl FnOnce(usize) -> Result<T> + Send) -> Result<T> {
    if threads == 0 {
        return f(rayon::current_num_threads());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::bad_flag("threads", UsageProblem::Invalid(e.to_string())))?;
    pool.install(|| f(pool.current_num_threads()))
}

/// The report for `a` against `b` (`b` = None: scene mode, `a`'s parts against each other; set
/// `opts.selection.scene`), as the command line writes it for the same inputs and flags.
pub fn report(a: &Source, b: Option<&Source>, opts: &Options) -> Result<Report> {
    opts.validate()?;
    in_pool(opts.threads, |threads| {
        let t0 = Instant::now();
        let bs = b.unwrap_or(a);
        let outcome_of = |settings: &Settings| {
            assembly::run(&a.input.mesh, &bs.input.mesh, &opts.selection, settings)
                .map_err(|e| Error::in_file(&bs.input.path, InputProblem::Selection(e)))
        };
        finish_report(a, bs, opts, threads, t0, outcome_of)
    })
}

/// The settings with the tolerances resolved for two inputs.
fn resolved_settings(a: &Mesh, b: &Mesh, opts: &Options) -> Result<(Settings, f64)> {
    let size = Aabb::of_points(&a.positions).union(Aabb::of_points(&b.positions)).extent().length();
    let tolerances = Tolerances { touch: opts.touch.resolve(size), clearance: opts.clearance.resolve(size) };
    if !tolerances.touch.is_finite() || !tolerances.clearance.is_finite() {
        return Err(Error::usage(UsageProblem::ToleranceOverflow));
    }
    let settings = Settings {
        tolerances,
        bvh: opts.bvh,
        mode: opts.mode,
        first_hit: opts.first_hit,
        distance_error: opts.distance_error,
        detail: opts.detail,
    };
    Ok((settings, size))
}

fn finish_report(
    a: &Source,
    b: &Source,
    opts: &Options,
    threads: usize,
    t0: Instant,
    outcome_of: impl FnOnce(&Settings) -> Result<assembly::Outcome>,
) -> Result<Report> {
    let (settings, size) = resolved_settings(&a.input.mesh, &b.input.mesh, opts)?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let outcome = outcome_of(&settings)?;
    let assembly_view = report::assembly_view(&outcome, opts.max_pairs);
    let result = outcome.result;
    let ctx = report::Context {
        inputs: [&a.input, &b.input],
        transforms: [a.transform, b.transform],
        settings: SettingsReport {
            touch_tolerance: settings.tolerances.touch,
            clearance: settings.tolerances.clearance,
            touch_tolerance_given: opts.touch.spec(),
            clearance_given: opts.clearance.spec(),
            model_size: size,
            units: "model".into(),
            fail_on: query::FailOn::Clash.name().into(),
            bvh: opts.bvh.strategy.name().into(),
            mode: opts.mode.name().into(),
            first_hit: opts.first_hit,
            penetration: opts.penetration,
            distance_rel_err: opts.distance_error.rel,
            distance_abs_err: opts.distance_error.abs,
            leaf_size: opts.bvh.leaf_size,
            max_pairs: opts.max_pairs,
            threads: (!opts.deterministic).then_some(threads),
            detail: (opts.detail != Detail::Pairs).then(|| opts.detail.name().into()),
        },
        failed: query::FailOn::Clash.fails(result.verdict),
        times: (!opts.deterministic).then(|| (load_ms, t0.elapsed().as_secs_f64() * 1e3)),
        cross_check: None,
        assembly: assembly_view,
    };
    let mut rep = report::build(&ctx, &result);
    let listed = &result.pairs[..rep.pairs.len()];
    let findings = report::baseline::findings(listed, &a.input.mesh, &b.input.mesh);
    report::baseline::assign_ids(&mut rep, &findings);
    if a.array {
        rep.inputs.a.format = ARRAY_FORMAT.into();
    }
    if b.array {
        rep.inputs.b.format = ARRAY_FORMAT.into();
    }
    Ok(rep)
}

/// The report for two placed meshes, as [`report`] gives for the same world coordinates
/// (files mode), except that `bvh` describes the prepared trees and `timings_ms.build` is 0.
pub fn report_placed(a: &Placed, b: &Placed, opts: &Options) -> Result<Report> {
    opts.validate()?;
    if opts.selection.by_parts() || opts.split_bodies {
        return Err(Error::usage(UsageProblem::Conflict(
            "prepared meshes are checked whole: selections, scene mode and --split-bodies need arrays or files".into(),
        )));
    }
    in_pool(opts.threads, |threads| {
        let t0 = Instant::now();
        let (sa, sb) = (placed_source(a), placed_source(b));
        let outcome_of = |settings: &Settings| {
            let r = query::check_built(&a.mesh(), &a.tree(), &b.mesh(), &b.tree(), settings);
            let mut parts = assembly::parts_of(&sa.input.mesh, 0);
            parts.extend(assembly::parts_of(&sb.input.mesh, 1));
            let part_pairs = assembly::group_by_part(&parts, &sa.input.mesh, &sb.input.mesh, &r);
            let info = assembly::AssemblyInfo {
                mode: "files",
                selected: [1, 1],
                candidate_part_pairs: part_pairs.len(),
                built_parts: None,
                sah_builds: None,
                sharing: None,
            };
            Ok(assembly::Outcome { result: r, parts, part_pairs, info })
        };
        finish_report(&sa, &sb, opts, threads, t0, outcome_of)
    })
}

/// A placed mesh copied as a report input, with its label as the path.
fn placed_source(p: &Placed) -> Source {
    let mut mesh = p.prepared.mesh.clone();
    mesh.positions = p.positions().to_vec();
    let input = Input { path: p.prepared.label.clone(), format: Format::Obj, mesh, warnings: Vec::new() };
    Source { input, transform: p.transform, array: true }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_errors_are_the_loaders_lines() {
        let l = Path::new("<array a>");
        let e = mesh_from_arrays(l, "a", vec![DVec3::ZERO; 3], vec![[0, 1, 3]]).unwrap_err();
        assert_eq!(e.to_string(), "<array a>: triangle 0 refers to vertex 3 but there are 3 vertices");
        let e =
            mesh_from_arrays(l, "a", vec![DVec3::ZERO, DVec3::NAN, DVec3::ONE], vec![[0, 1, 2]]).unwrap_err();
        assert_eq!(e.to_string(), "<array a>: vertex 1 has a non-finite coordinate (NaN)");
        let e = mesh_from_arrays(l, "a", vec![DVec3::ZERO; 3], vec![]).unwrap_err();
        assert_eq!(e.to_string(), "<array a>: no triangles");
        let e = triangles_from(l, &[0i64, 1, -1], 3).unwrap_err();
        assert_eq!(e.to_string(), "<array a>: triangle 0 refers to vertex -1 but there are 3 vertices");
        let e = Tolerance::parse("clearance", "x").unwrap_err();
        assert!(e.to_string().starts_with("usage: --clearance must be"), "{e}");
    }
}
