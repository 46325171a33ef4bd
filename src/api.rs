//! Entry points for embedding meshclash in another program (the Python package in `python/`
//! uses nothing else): the report for two inputs that are files or in-memory meshes, and the
//! *prepared* meshes of [`crate::prepared`] (re-exported here) — a mesh whose tree is built
//! once, then placed under any number of affine transforms for the yes/no and distance queries a
//! collision manager makes.
//!
//! A report goes through the one pipeline ([`crate::pipeline::run`], then
//! [`crate::pipeline::report::build`]), exactly as the command line does, so the same inputs and settings
//! give the same document (the Python tests compare them with the binary's `--no-timings`
//! output). This module only turns an embedder's options into a [`Request`].

use crate::bvh::BuildOptions;
use crate::cache::CacheConfig;
use crate::check::assembly::Selection;
use crate::check::query::FailOn;
use crate::check::query::{Detail, DistanceError, Mode, Settings};
use crate::error::{Error, InputProblem, Location, NonFinite, Result, UsageProblem};
use crate::geom::DVec3;
use crate::pipeline::{Gate, InputRequest, Request, Unit, Units};
use crate::report::self_report::{self, SelfFailOn};
use crate::report::Report;
use crate::scene::mesh::{Mesh, Object};
use glam::DMat4;
use std::path::{Path, PathBuf};

pub use crate::pipeline::Tolerance;
pub use crate::prepared::{collide, distance, meeting_pairs, Collision, Placed, PlacedMesh, Prepared};
pub use crate::report::ARRAY_FORMAT;

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
    /// `--units`: the report's unit (None: `units_a`, else `units_b`, else no conversion).
    pub units: Option<Unit>,
    /// `--units-a` (in scene mode: the file's units).
    pub units_a: Option<Unit>,
    /// `--units-b`.
    pub units_b: Option<Unit>,
    /// `--scale-a` (in scene mode: the file's scale).
    pub scale_a: Option<f64>,
    /// `--scale-b`.
    pub scale_b: Option<f64>,
    /// `--fail-on`.
    pub gate: Gate,
    /// `--baseline REPORT`.
    pub baseline: Option<PathBuf>,
    /// `scene --self` with the extra `--self-fail-on` conditions (None: no self check).
    pub self_check: Option<Vec<SelfFailOn>>,
    /// `--cache DIR` and `--cache-max-bytes`.
    pub cache: Option<CacheConfig>,
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
            units: None,
            units_a: None,
            units_b: None,
            scale_a: None,
            scale_b: None,
            gate: Gate::default(),
            baseline: None,
            self_check: None,
            cache: None,
        }
    }
}

/// The verdict `--fail-on` gates on (`new` gates on the baseline, and on no verdict).
fn verdict_gate(g: Gate) -> FailOn {
    match g {
        Gate::Verdict(f) => f,
        Gate::New => FailOn::Never,
    }
}

impl Options {
    /// The pipeline's request for these inputs (one input: scene mode).
    pub fn request(&self, inputs: Vec<InputRequest>) -> Request {
        let mut selection = self.selection.clone();
        selection.scene = inputs.len() == 1;
        // As the command line: in scene mode the one file's units and scale are A's.
        let units = if selection.scene {
            Units {
                report: self.units.or(self.units_a),
                inputs: [self.units_a, None],
                scale: [self.scale_a, None],
            }
        } else {
            Units {
                report: self.units.or(self.units_a).or(self.units_b),
                inputs: [self.units_a, self.units_b],
                scale: [self.scale_a, self.scale_b],
            }
        };
        let self_check =
            self.self_check.as_ref().map(|extra| self_report::scene_fail_on(verdict_gate(self.gate), extra));
        Request {
            units,
            gate: self.gate,
            baseline: self.baseline.clone(),
            self_check,
            cache: self.cache.clone(),
            inputs,
            touch: self.touch,
            clearance: self.clearance,
            settings: Settings {
                tolerances: Default::default(),
                bvh: self.bvh,
                mode: self.mode,
                first_hit: self.first_hit,
                distance_error: self.distance_error,
                detail: self.detail,
            },
            max_pairs: self.max_pairs,
            deterministic: self.deterministic,
            penetration: self.penetration,
            selection,
            split_bodies: self.split_bodies,
            ..Request::defaults()
        }
    }

    /// Reject what the command line rejects (leaf size, distance allowances, scales; the
    /// pipeline's [`Request::validate`] refuses the conflicts).
    pub fn validate(&self) -> Result<()> {
        for (flag, v) in [("scale-a", self.scale_a), ("scale-b", self.scale_b)] {
            if let Some(x) = v.filter(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(Error::bad_flag(flag, UsageProblem::NotPositive { value: x }));
            }
        }
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

/// One input of a report: a file, or a mesh handed over in memory (reported with
/// [`ARRAY_FORMAT`] and its label as the path), with its placement.
#[derive(Debug, Clone)]
pub struct Source(pub InputRequest);

/// A file placed by `transform`, as the command line takes `A`/`B` (read when the report is
/// made). `split_bodies` is [`Options::split_bodies`]'s, kept for callers that set it here.
pub fn file_source(path: &Path, transform: DMat4, _split_bodies: bool) -> Result<Source> {
    Ok(Source(InputRequest { source: crate::pipeline::Source::File(path.to_path_buf()), transform }))
}

/// An in-memory mesh (from [`mesh_from_arrays`]) placed by `transform`; `label` stands for its
/// path in the report and in error messages.
pub fn array_source(label: &Path, mesh: Mesh, transform: DMat4, _split_bodies: bool) -> Result<Source> {
    let source = crate::pipeline::Source::Mesh { label: label.to_path_buf(), mesh };
    Ok(Source(InputRequest { source, transform }))
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

/// The report for `a` against `b` (`b` = None: scene mode, `a`'s parts against each other), as
/// the command line writes it for the same inputs and flags.
pub fn report(a: &Source, b: Option<&Source>, opts: &Options) -> Result<Report> {
    opts.validate()?;
    let inputs = std::iter::once(a).chain(b).map(|s| s.0.clone()).collect();
    let req = opts.request(inputs);
    in_pool(opts.threads, |_| Ok(crate::pipeline::report::build(&crate::pipeline::run(&req, &|_| {})?)))
}

/// The report for two placed meshes: the report of their prepared meshes under their
/// placements, as [`report`] gives for the same arrays and transforms.
pub fn report_placed(a: &Placed, b: &Placed, opts: &Options) -> Result<Report> {
    if opts.selection.by_parts() || opts.split_bodies {
        return Err(Error::usage(UsageProblem::Conflict(
            "prepared meshes are checked whole: selections, scene mode and --split-bodies need arrays or files".into(),
        )));
    }
    let source = |p: &Placed| {
        let mesh = p.prepared.mesh.clone();
        array_source(&p.prepared.label, mesh, p.transform, false)
    };
    report(&source(a)?, Some(&source(b)?), opts)
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
