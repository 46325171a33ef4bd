//! `meshclash._meshclash`: the native half of the Python package. The public API (argument
//! checking, the trimesh-style return values) is in `python/meshclash/__init__.py`; this module
//! converts arrays, releases the GIL and calls `meshclash::api`.

use glam::{DMat4, DVec3, DVec4};
use meshclash::api::{self, Options, Placed, Prepared, Source, Tolerance};
use meshclash::bvh::{BuildOptions, Strategy};
use meshclash::cache::CacheConfig;
use meshclash::check::assembly::Selection;
use meshclash::check::query::FailOn;
use meshclash::check::query::{Detail, DistanceError, Mode};
use meshclash::geom::predicates;
use meshclash::geom::Aabb;
use meshclash::narrow::tri_tri;
use meshclash::pipeline::{Gate, Unit};
use meshclash::prepared;
use meshclash::prepared::broad::{self, ObjectTree};
use meshclash::report::self_report::SelfFailOn;
use meshclash::Error;
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A library error as the Python exception the API documents: OSError for files that cannot be
/// read, ValueError for everything else; the message is the command line's line.
fn py_err(e: Error) -> PyErr {
    let line = e.to_string();
    match &e {
        _ if e.is_unreadable_file() => PyOSError::new_err(line),
        Error::Output { .. } => PyOSError::new_err(line),
        _ => PyValueError::new_err(line),
    }
}

/// Vertex positions from an (n, 3) float64 or float32 array.
fn positions(label: &Path, v: &Bound<'_, PyAny>) -> PyResult<Vec<DVec3>> {
    fn rows<T: Copy + Into<f64> + numpy::Element>(a: PyReadonlyArray2<'_, T>) -> Vec<DVec3> {
        let view = a.as_array();
        view.rows().into_iter().map(|r| DVec3::new(r[0].into(), r[1].into(), r[2].into())).collect()
    }
    let shape_ok = |shape: &[usize]| shape.len() == 2 && shape[1] == 3;
    if let Ok(a) = v.extract::<PyReadonlyArray2<'_, f64>>() {
        if shape_ok(a.shape()) {
            return Ok(match a.as_slice() {
                // C-contiguous float64: read in place, one pass (as_slice also accepts
                // Fortran order, which is not row-major).
                Ok(s) if a.is_c_contiguous() => {
                    s.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect()
                }
                _ => rows(a),
            });
        }
    } else if let Ok(a) = v.extract::<PyReadonlyArray2<'_, f32>>() {
        if shape_ok(a.shape()) {
            return Ok(rows(a));
        }
    }
    Err(PyValueError::new_err(format!(
        "{}: vertices must be a float64 or float32 array of shape (n, 3)",
        label.display()
    )))
}

/// Triangles from an (m, 3) int32, int64 or uint32 array, every index checked.
fn triangles(label: &Path, f: &Bound<'_, PyAny>, vertices: usize) -> PyResult<Vec<[u32; 3]>> {
    fn flat<T: Copy + numpy::Element>(a: &PyReadonlyArray2<'_, T>) -> Vec<T> {
        match a.as_slice() {
            Ok(s) if a.is_c_contiguous() => s.to_vec(),
            // Logical (row-major) order whatever the memory layout.
            _ => a.as_array().iter().copied().collect(),
        }
    }
    let shape_ok = |shape: &[usize]| shape.len() == 2 && shape[1] == 3;
    let r = if let Ok(a) = f.extract::<PyReadonlyArray2<'_, i64>>() {
        shape_ok(a.shape()).then(|| api::triangles_from(label, &flat(&a), vertices))
    } else if let Ok(a) = f.extract::<PyReadonlyArray2<'_, i32>>() {
        shape_ok(a.shape()).then(|| api::triangles_from(label, &flat(&a), vertices))
    } else if let Ok(a) = f.extract::<PyReadonlyArray2<'_, u32>>() {
        shape_ok(a.shape()).then(|| api::triangles_from(label, &flat(&a), vertices))
    } else {
        None
    };
    match r {
        Some(r) => r.map_err(py_err),
        None => Err(PyValueError::new_err(format!(
            "{}: faces must be an int32, int64 or uint32 array of shape (m, 3)",
            label.display()
        ))),
    }
}

/// Peak bytes preparing a mesh takes per vertex and per triangle, measured with margin: the f64
/// positions, the vertex merge's table, the tree and its build, the face copies.
const BYTES_PER_VERTEX: u64 = 96;
const BYTES_PER_TRIANGLE: u64 = 192;

/// The memory this process may still allocate: the smaller of the address-space limit left
/// (`RLIMIT_AS` from /proc/self/limits, minus the current size) and the system's available
/// memory (/proc/meminfo). `None` where neither is known.
fn memory_available() -> Option<u64> {
    let field = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line[key.len()..].split_whitespace().next()?.parse().ok()
    };
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let system = meminfo.as_deref().and_then(|t| field(t, "MemAvailable:")).map(|kb| kb * 1024);
    let limits = std::fs::read_to_string("/proc/self/limits").ok();
    let status = std::fs::read_to_string("/proc/self/status").ok();
    let address_space = limits.as_deref().and_then(|t| field(t, "Max address space")).map(|limit| {
        let used = status.as_deref().and_then(|t| field(t, "VmSize:")).unwrap_or(0) * 1024;
        limit.saturating_sub(used)
    });
    match (system, address_space) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// MemoryError, before anything is allocated, when preparing `vertices` and `triangles` would
/// need more memory than the process may still allocate (an abort otherwise).
fn check_memory(label: &Path, vertices: usize, triangles: usize) -> PyResult<()> {
    let need = BYTES_PER_VERTEX
        .saturating_mul(vertices as u64)
        .saturating_add(BYTES_PER_TRIANGLE.saturating_mul(triangles as u64));
    match memory_available() {
        Some(free) if need > free => Err(PyMemoryError::new_err(format!(
            "{}: {vertices} vertices and {triangles} triangles need about {} MB to prepare, more than \
             the {} MB this process may still allocate",
            label.display(),
            need >> 20,
            free >> 20
        ))),
        _ => Ok(()),
    }
}

/// The number of rows of an (n, 3) array argument, if it is one (for the memory check).
fn rows(x: &Bound<'_, PyAny>) -> usize {
    x.getattr("shape")
        .and_then(|s| s.extract::<Vec<usize>>())
        .ok()
        .and_then(|s| s.first().copied())
        .unwrap_or(0)
}

fn mesh_from(
    label: &Path,
    name: &str,
    v: &Bound<'_, PyAny>,
    f: &Bound<'_, PyAny>,
) -> PyResult<meshclash::scene::mesh::Mesh> {
    check_memory(label, rows(v), rows(f))?;
    let p = positions(label, v)?;
    let t = triangles(label, f, p.len())?;
    api::mesh_from_arrays(label, name, p, t).map_err(py_err)
}

/// A 4×4 row-major affine transform (nested sequences), or None for the identity. `flag` names
/// it in errors, as the command line does.
fn transform(flag: &str, t: Option<Vec<Vec<f64>>>) -> PyResult<DMat4> {
    let Some(t) = t else { return Ok(DMat4::IDENTITY) };
    if t.len() != 4 || t.iter().any(|r| r.len() != 4) {
        return Err(PyValueError::new_err(format!("{flag} must be a 4x4 matrix")));
    }
    if t.iter().flatten().any(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!("{flag} must be finite")));
    }
    if t[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(PyValueError::new_err(format!(
            "usage: --{flag}: the last row must be 0,0,0,1 (affine only)"
        )));
    }
    let row = |r: usize| DVec4::new(t[r][0], t[r][1], t[r][2], t[r][3]);
    Ok(DMat4::from_cols(row(0), row(1), row(2), DVec4::W).transpose())
}

/// One input of `check`: a path, a (vertices, faces) pair, or a prepared Mesh.
enum In {
    Source(Box<Source>),
    Prepared(Arc<Prepared>),
}

fn input(side: char, obj: &Bound<'_, PyAny>, t: DMat4, split: bool) -> PyResult<(In, DMat4)> {
    if let Ok(m) = obj.extract::<PyRef<'_, Mesh>>() {
        return Ok((In::Prepared(m.inner.clone()), t));
    }
    if let Ok(path) = obj.extract::<PathBuf>() {
        return Ok((In::Source(Box::new(api::file_source(&path, t, split).map_err(py_err)?)), t));
    }
    if let Ok((v, f)) = obj.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>() {
        let label = PathBuf::from(format!("<array {side}>"));
        let mesh = mesh_from(&label, &side.to_string(), &v, &f)?;
        return Ok((In::Source(Box::new(api::array_source(&label, mesh, t, split).map_err(py_err)?)), t));
    }
    Err(PyValueError::new_err(format!(
        "{side} must be a file path, a (vertices, faces) pair of arrays or a meshclash.Mesh"
    )))
}

#[allow(clippy::too_many_arguments)]
fn options(
    touch_tolerance: &Bound<'_, PyAny>,
    clearance: &Bound<'_, PyAny>,
    max_pairs: usize,
    mode: &str,
    first_hit: bool,
    detail: &str,
    threads: usize,
    timings: bool,
    penetration: bool,
    split_bodies: bool,
    bvh: &str,
    leaf_size: u32,
    distance_rel_err: f64,
    distance_abs_err: f64,
    select_a: Vec<String>,
    select_b: Vec<String>,
    exclude: Vec<String>,
) -> PyResult<Options> {
    let tol = |flag: &str, v: &Bound<'_, PyAny>| -> PyResult<Tolerance> {
        let s = match v.extract::<f64>() {
            Ok(x) => format!("{x:e}"),
            Err(_) => v.extract::<String>().map_err(|_| {
                PyValueError::new_err(format!("{flag} must be a number or a string such as '1e-6rel'"))
            })?,
        };
        Tolerance::parse(flag, &s).map_err(py_err)
    };
    let mode = match mode {
        "exact" => Mode::Exact,
        "fast" => Mode::Fast,
        m => return Err(PyValueError::new_err(format!("mode must be 'exact' or 'fast', got '{m}'"))),
    };
    let detail = match detail {
        "pairs" => Detail::Pairs,
        "parts" => Detail::Parts,
        d => return Err(PyValueError::new_err(format!("detail must be 'pairs' or 'parts', got '{d}'"))),
    };
    let strategy = match bvh {
        "sah" => Strategy::Sah,
        "median" => Strategy::Median,
        "equal" => Strategy::Equal,
        b => return Err(PyValueError::new_err(format!("bvh must be 'sah', 'median' or 'equal', got '{b}'"))),
    };
    let o = Options {
        touch: tol("touch-tolerance", touch_tolerance)?,
        clearance: tol("clearance", clearance)?,
        max_pairs,
        mode,
        first_hit,
        detail,
        bvh: BuildOptions { strategy, leaf_size },
        distance_error: DistanceError { rel: distance_rel_err, abs: distance_abs_err },
        deterministic: !timings,
        penetration,
        selection: Selection { scene: false, select_a, select_b, exclude, hook: None },
        split_bodies,
        threads,
        ..Options::default()
    };
    o.validate().map_err(py_err)?;
    Ok(o)
}

/// The command line's units, gate, baseline, self-check and cache flags, onto `o`.
#[allow(clippy::too_many_arguments)]
fn flags(
    o: &mut Options,
    units: Option<&str>,
    units_a: Option<&str>,
    units_b: Option<&str>,
    scale_a: Option<f64>,
    scale_b: Option<f64>,
    fail_on: &str,
    baseline: Option<PathBuf>,
    cache: Option<PathBuf>,
    cache_max_bytes: u64,
    self_fail_on: Option<Vec<String>>,
) -> PyResult<()> {
    let unit = |flag: &str, u: Option<&str>| -> PyResult<Option<Unit>> {
        u.map(|name| {
            Unit::from_name(name).ok_or_else(|| {
                let all: Vec<&str> = Unit::ALL.iter().map(|u| u.name()).collect();
                PyValueError::new_err(format!("{flag} must be one of {}, got '{name}'", all.join(", ")))
            })
        })
        .transpose()
    };
    o.units = unit("units", units)?;
    o.units_a = unit("units_a", units_a)?;
    o.units_b = unit("units_b", units_b)?;
    o.scale_a = scale_a;
    o.scale_b = scale_b;
    o.gate = match fail_on {
        "clash" => Gate::Verdict(FailOn::Clash),
        "touching" => Gate::Verdict(FailOn::Touching),
        "clearance" => Gate::Verdict(FailOn::Clearance),
        "never" => Gate::Verdict(FailOn::Never),
        "new" => Gate::New,
        f => {
            return Err(PyValueError::new_err(format!(
                "fail_on must be 'clash', 'touching', 'clearance', 'never' or 'new', got '{f}'"
            )))
        }
    };
    o.baseline = baseline;
    o.cache = cache.map(|dir| CacheConfig { dir, max_bytes: cache_max_bytes });
    o.self_check = self_fail_on
        .map(|names| {
            names
                .iter()
                .map(|n| {
                    SelfFailOn::from_name(n).ok_or_else(|| {
                        PyValueError::new_err(format!(
                            "self_fail_on: unknown condition '{n}' (self-clash, touching, open, non-manifold, \
                             duplicates, degenerate, winding, never)"
                        ))
                    })
                })
                .collect::<PyResult<Vec<_>>>()
        })
        .transpose()?;
    o.validate().map_err(py_err)
}

/// The report of `a` against `b` as JSON text (see `meshclash.check`).
#[pyfunction]
#[pyo3(signature = (a, b, *, transform_a=None, transform_b=None, touch_tolerance=None, clearance=None,
    max_pairs=1000, mode="exact", first_hit=false, detail="pairs", threads=0, timings=true, penetration=false,
    split_bodies=false, bvh="sah", leaf_size=4, distance_rel_err=0.0, distance_abs_err=0.0,
    select_a=vec![], select_b=vec![], exclude=vec![], units=None, units_a=None, units_b=None,
    scale_a=None, scale_b=None, fail_on="clash", baseline=None, cache=None,
    cache_max_bytes=meshclash::cache::DEFAULT_MAX_BYTES))]
#[allow(clippy::too_many_arguments)]
fn check_json(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    transform_a: Option<Vec<Vec<f64>>>,
    transform_b: Option<Vec<Vec<f64>>>,
    touch_tolerance: Option<Bound<'_, PyAny>>,
    clearance: Option<Bound<'_, PyAny>>,
    max_pairs: usize,
    mode: &str,
    first_hit: bool,
    detail: &str,
    threads: usize,
    timings: bool,
    penetration: bool,
    split_bodies: bool,
    bvh: &str,
    leaf_size: u32,
    distance_rel_err: f64,
    distance_abs_err: f64,
    select_a: Vec<String>,
    select_b: Vec<String>,
    exclude: Vec<String>,
    units: Option<&str>,
    units_a: Option<&str>,
    units_b: Option<&str>,
    scale_a: Option<f64>,
    scale_b: Option<f64>,
    fail_on: &str,
    baseline: Option<PathBuf>,
    cache: Option<PathBuf>,
    cache_max_bytes: u64,
) -> PyResult<String> {
    let zero = 0.0f64.into_pyobject(py)?.into_any();
    let mut opts = options(
        touch_tolerance.as_ref().unwrap_or(&zero),
        clearance.as_ref().unwrap_or(&zero),
        max_pairs,
        mode,
        first_hit,
        detail,
        threads,
        timings,
        penetration,
        split_bodies,
        bvh,
        leaf_size,
        distance_rel_err,
        distance_abs_err,
        select_a,
        select_b,
        exclude,
    )?;
    flags(
        &mut opts,
        units,
        units_a,
        units_b,
        scale_a,
        scale_b,
        fail_on,
        baseline,
        cache,
        cache_max_bytes,
        None,
    )?;
    let ta = transform("transform-a", transform_a)?;
    let tb = transform("transform-b", transform_b)?;
    let (ia, ta) = input('a', a, ta, opts.split_bodies)?;
    let (ib, tb) = input('b', b, tb, opts.split_bodies)?;
    let rep = py.detach(move || -> meshclash::Result<String> {
        // A prepared mesh is its mesh under its placement: the same pipeline as arrays.
        let source = |i: &In, t: DMat4| -> meshclash::Result<api::Source> {
            match i {
                In::Prepared(p) => api::array_source(&p.label, p.mesh.clone(), t, false),
                In::Source(s) => Ok((**s).clone()),
            }
        };
        let rep = api::report(&source(&ia, ta)?, Some(&source(&ib, tb)?), &opts)?;
        Ok(meshclash::report::to_json(&rep))
    });
    rep.map_err(py_err)
}

/// The scene report of one file (see `meshclash.scene`).
#[pyfunction]
#[pyo3(signature = (path, *, touch_tolerance=None, clearance=None, max_pairs=1000, mode="exact",
    first_hit=false, detail="pairs", threads=0, timings=true, penetration=false, split_bodies=false, bvh="sah",
    leaf_size=4, distance_rel_err=0.0, distance_abs_err=0.0, select_a=vec![], select_b=vec![],
    exclude=vec![], units=None, file_units=None, scale=None, fail_on="clash", baseline=None,
    self_check=false, self_fail_on=vec![], cache=None,
    cache_max_bytes=meshclash::cache::DEFAULT_MAX_BYTES))]
#[allow(clippy::too_many_arguments)]
fn scene_json(
    py: Python<'_>,
    path: PathBuf,
    touch_tolerance: Option<Bound<'_, PyAny>>,
    clearance: Option<Bound<'_, PyAny>>,
    max_pairs: usize,
    mode: &str,
    first_hit: bool,
    detail: &str,
    threads: usize,
    timings: bool,
    penetration: bool,
    split_bodies: bool,
    bvh: &str,
    leaf_size: u32,
    distance_rel_err: f64,
    distance_abs_err: f64,
    select_a: Vec<String>,
    select_b: Vec<String>,
    exclude: Vec<String>,
    units: Option<&str>,
    file_units: Option<&str>,
    scale: Option<f64>,
    fail_on: &str,
    baseline: Option<PathBuf>,
    self_check: bool,
    self_fail_on: Vec<String>,
    cache: Option<PathBuf>,
    cache_max_bytes: u64,
) -> PyResult<String> {
    let zero = 0.0f64.into_pyobject(py)?.into_any();
    let mut opts = options(
        touch_tolerance.as_ref().unwrap_or(&zero),
        clearance.as_ref().unwrap_or(&zero),
        max_pairs,
        mode,
        first_hit,
        detail,
        threads,
        timings,
        penetration,
        split_bodies,
        bvh,
        leaf_size,
        distance_rel_err,
        distance_abs_err,
        select_a,
        select_b,
        exclude,
    )?;
    if !self_check && !self_fail_on.is_empty() {
        return Err(PyValueError::new_err(
            "self_fail_on needs self_check=True (--self-fail-on needs --self)",
        ));
    }
    flags(
        &mut opts,
        units,
        file_units,
        None,
        scale,
        None,
        fail_on,
        baseline,
        cache,
        cache_max_bytes,
        self_check.then_some(self_fail_on),
    )?;
    opts.selection.scene = true;
    py.detach(move || -> meshclash::Result<String> {
        let src = api::file_source(&path, DMat4::IDENTITY, opts.split_bodies)?;
        Ok(meshclash::report::to_json(&api::report(&src, None, &opts)?))
    })
    .map_err(py_err)
}

/// A prepared mesh: validated, its tree built once.
#[pyclass(module = "meshclash._meshclash", frozen)]
struct Mesh {
    inner: Arc<Prepared>,
}

#[pymethods]
impl Mesh {
    #[new]
    #[pyo3(signature = (vertices, faces, name=None))]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        name: Option<String>,
    ) -> PyResult<Self> {
        let name = name.unwrap_or_else(|| "mesh".to_string());
        let label = PathBuf::from(format!("<mesh {name}>"));
        let mesh = mesh_from(&label, &name, vertices, faces)?;
        let inner = py
            .detach(|| Prepared::new(&label, mesh, BuildOptions::default()).map(Arc::new))
            .map_err(py_err)?;
        Ok(Mesh { inner })
    }

    /// Number of vertices.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.inner.mesh.positions.len()
    }

    /// Number of triangles.
    #[getter]
    fn face_count(&self) -> usize {
        self.inner.mesh.triangles.len()
    }

    /// The name the report and errors use.
    #[getter]
    fn name(&self) -> String {
        self.inner.mesh.objects[0].name.clone()
    }

    /// `(min, max)` corners of the box around the vertices (own coordinates).
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let b = meshclash::geom::Aabb::of_points(&self.inner.mesh.positions);
        (b.min.to_array(), b.max.to_array())
    }

    /// Whether this mesh placed by `transform` and `other` placed by `other_transform`
    /// collide, exactly (see `meshclash.Mesh.collides` in the stub).
    #[pyo3(signature = (other, transform=None, other_transform=None))]
    fn collides(
        &self,
        py: Python<'_>,
        other: PyRef<'_, Mesh>,
        transform: Option<Vec<Vec<f64>>>,
        other_transform: Option<Vec<Vec<f64>>>,
    ) -> PyResult<bool> {
        let (ta, tb) = (transform_of(transform)?, transform_of(other_transform)?);
        let (a, b) = (self.inner.clone(), other.inner.clone());
        py.detach(move || -> meshclash::Result<bool> {
            Ok(api::collide(&a.place(ta)?, &b.place(tb)?, false).collides())
        })
        .map_err(py_err)
    }

    /// `(distance, point_on_self, point_on_other, face_self, face_other)`.
    #[pyo3(signature = (other, transform=None, other_transform=None))]
    fn distance(
        &self,
        py: Python<'_>,
        other: PyRef<'_, Mesh>,
        transform: Option<Vec<Vec<f64>>>,
        other_transform: Option<Vec<Vec<f64>>>,
    ) -> PyResult<Witness> {
        let (ta, tb) = (transform_of(transform)?, transform_of(other_transform)?);
        let (a, b) = (self.inner.clone(), other.inner.clone());
        py.detach(move || -> meshclash::Result<_> {
            let c = api::distance(&a.place(ta)?, &b.place(tb)?, f64::INFINITY).expect("non-empty meshes");
            Ok((c.distance, c.a.1.to_array(), c.b.1.to_array(), c.a.0, c.b.0))
        })
        .map_err(py_err)
    }
}

fn transform_of(t: Option<Vec<Vec<f64>>>) -> PyResult<DMat4> {
    transform("transform", t)
}

/// One contact: (face, face, point, unit normal, depth). Faces are -1 where none applies (a
/// contained part); for a convex pair the one contact of the exact penetration, else one per
/// meeting triangle pair (depth 0.0, the normal of the second triangle).
type Contact = (i64, i64, [f64; 3], [f64; 3], f64);

/// One colliding pair: (index in the first list, index in the second, contacts, containment
/// name or None).
type Hit = (usize, usize, Vec<Contact>, Option<&'static str>);

/// A colliding pair by name: (name, name, contacts, containment name or None).
type NamedHit = (String, String, Vec<Contact>, Option<&'static str>);

/// Mesh.distance's answer: (distance, point on self, point on other, face, face).
type Witness = (f64, [f64; 3], [f64; 3], u32, u32);

/// A colliding object of the manager against a single mesh: (name, contacts, containment).
type SingleHit = (String, Vec<Contact>, Option<&'static str>);

/// The closest object to a single mesh: (distance, name, face, face, point, point).
type SingleNear = (f64, String, i64, i64, [f64; 3], [f64; 3]);

/// A closest pair by name: (distance, name, name, face, face, point, point).
type NamedNear = (f64, String, String, i64, i64, [f64; 3], [f64; 3]);

/// The contacts of a colliding pair (`c` from `collide`): the exact penetration as one contact
/// when both are convex, else every meeting triangle pair found.
fn contacts(a: &Placed, b: &Placed, c: &api::Collision) -> Vec<Contact> {
    let first = c.contacts.first().map_or((-1, -1), |p| (p.a as i64, p.b as i64));
    if let Some(p) = prepared::penetration(a, b) {
        return vec![(first.0, first.1, p.point.to_array(), p.normal.to_array(), p.depth)];
    }
    let mb = b.positions();
    let tris = &b.prepared.mesh.triangles;
    c.contacts
        .iter()
        .map(|p| {
            let point = match p.segment {
                Some([s, t]) => (s + t) * 0.5,
                None => meshclash::check::query::pair_witness(&a.mesh(), &b.mesh(), p).a.1,
            };
            let [x, y, z] = tris[p.b as usize].map(|v| mb[v as usize]);
            let n = (y - x).cross(z - x).normalize_or_zero();
            (p.a as i64, p.b as i64, point.to_array(), n.to_array(), 0.0)
        })
        .collect()
}

/// What a pair's exact collision test said: does it collide, and the containment name when
/// no triangles meet.
#[derive(Debug, Clone, Copy)]
struct Verdict {
    collides: bool,
    containment: Option<&'static str>,
}

/// Answers about pairs of placements kept across queries, under the pair of placement ids
/// ([`Placed::id`]): a placed mesh never changes and moving an object places it anew, so an
/// entry stays true until one of the two objects moves (its entries are dropped then).
#[derive(Default)]
struct Memo {
    verdicts: HashMap<(u64, u64), Verdict>,
    signed: HashMap<(u64, u64), prepared::Signed>,
    /// Pairs known to have no meeting triangles (their containment not decided yet).
    no_meeting: std::collections::HashSet<(u64, u64)>,
    /// A triangle pair (of A, of B) that met the last time two objects collided, under any
    /// placements (keyed by [`HintKey`]): kept when objects move, yes/no questions about the
    /// pair try it first (one exact triangle test; any meeting pair settles that the pair
    /// collides, with no containment to decide). Only speed depends on it: a stale hint is a
    /// triangle pair that no longer meets, or out of range.
    hints: HashMap<HintKey, (u32, u32)>,
}

impl Memo {
    /// Forget every answer about placement `id`.
    fn forget(&mut self, id: u64) {
        self.verdicts.retain(|k, _| k.0 != id && k.1 != id);
        self.signed.retain(|k, _| k.0 != id && k.1 != id);
        self.no_meeting.retain(|k| k.0 != id && k.1 != id);
    }
}

/// Two objects (index in their list, and their prepared mesh's address: a hint stays with the
/// meshes it was found on even when indices shift after a removal).
type HintKey = ((usize, usize), (usize, usize));

/// Above this many entries a memo is emptied (a bound on memory; only speed depends on it).
const MEMO_MAX: usize = 1 << 20;

/// The memo a query reads and fills (`None`: a one-off query, e.g. against a single mesh).
struct Memory<'a>(Option<&'a Mutex<Memo>>);

impl Memory<'_> {
    fn verdict(&self, k: (u64, u64)) -> Option<Verdict> {
        self.0.and_then(|m| m.lock().unwrap().verdicts.get(&k).copied())
    }
    fn keep_verdict(&self, k: (u64, u64), v: Verdict) {
        if let Some(m) = self.0 {
            let mut m = m.lock().unwrap();
            if m.verdicts.len() >= MEMO_MAX {
                m.verdicts.clear();
            }
            m.verdicts.insert(k, v);
        }
    }
    fn no_meeting(&self, k: (u64, u64)) -> bool {
        self.0.is_some_and(|m| m.lock().unwrap().no_meeting.contains(&k))
    }
    fn keep_no_meeting(&self, k: (u64, u64)) {
        if let Some(m) = self.0 {
            let mut m = m.lock().unwrap();
            if m.no_meeting.len() >= MEMO_MAX {
                m.no_meeting.clear();
            }
            m.no_meeting.insert(k);
        }
    }
    fn hint(&self, k: HintKey) -> Option<(u32, u32)> {
        self.0.and_then(|m| m.lock().unwrap().hints.get(&k).copied())
    }
    fn keep_hint(&self, k: HintKey, v: (u32, u32)) {
        if let Some(m) = self.0 {
            let mut m = m.lock().unwrap();
            if m.hints.len() >= MEMO_MAX {
                m.hints.clear();
            }
            m.hints.insert(k, v);
        }
    }
    fn signed(&self, k: (u64, u64)) -> Option<prepared::Signed> {
        self.0.and_then(|m| m.lock().unwrap().signed.get(&k).cloned())
    }
    fn keep_signed(&self, k: (u64, u64), v: &prepared::Signed) {
        if let Some(m) = self.0 {
            let mut m = m.lock().unwrap();
            if m.signed.len() >= MEMO_MAX {
                m.signed.clear();
            }
            m.signed.insert(k, v.clone());
        }
    }
}

/// Run `f` on every item, in order; on the calling thread for short lists (waking the pool
/// costs more than a few exact checks; a speed threshold, no answer depends on it).
fn filter_map_all<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> Option<R> + Sync + Send) -> Vec<R> {
    if items.len() <= SEQUENTIAL_PAIRS {
        items.iter().filter_map(f).collect()
    } else {
        items.par_iter().filter_map(f).collect()
    }
}

/// Some item for which `f` answers (any: the caller needs only one). The first
/// [`SEQUENTIAL_PAIRS`] items are tried on the calling thread (an answer among them costs no
/// wake-up of the pool), the rest in parallel.
fn find_any<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> Option<R> + Sync + Send) -> Option<R> {
    let (head, rest) = items.split_at(items.len().min(SEQUENTIAL_PAIRS));
    head.iter().find_map(&f).or_else(|| rest.par_iter().find_map_any(&f))
}

/// The first item (in order) for which `f` answers: the first [`SEQUENTIAL_PAIRS`] items on the
/// calling thread, then the first of the rest, found in parallel.
fn find_first<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> Option<R> + Sync + Send) -> Option<R> {
    let (head, rest) = items.split_at(items.len().min(SEQUENTIAL_PAIRS));
    head.iter().find_map(&f).or_else(|| rest.par_iter().find_map_first(&f))
}

/// Exact collision of every candidate pair `(i, j)`, sorted by (i, j); pairs whose boxes or
/// bounding balls are apart are settled without a look at their triangles. With
/// `stop_at_first` (a yes/no question) the answer is one colliding pair, any: a pair known to
/// collide from an earlier query, else meeting triangles are looked for in every open pair
/// first (a crossing settles it), containment only when no pair has any.
fn collide_pairs(
    pairs: &[(usize, usize)],
    a: &[Arc<Placed>],
    b: &[Arc<Placed>],
    data: bool,
    stop_at_first: bool,
    memo: Memory<'_>,
) -> Vec<Hit> {
    let key = |&(i, j): &(usize, usize)| (a[i].id(), b[j].id());
    let apart = |&(i, j): &(usize, usize)| prepared::surely_clear(&a[i], &b[j]) || a[i].apart(&b[j]);
    let meets = Verdict { collides: true, containment: None };
    // The triangle pair that met last time, when it still meets (exact test): then the pair
    // collides with no containment, the verdict the full test gives.
    let hinted = |p: &(usize, usize)| hint_meets(&a[p.0], &b[p.1], memo.hint(hint_key(a, b, *p)));
    let decide = |p: &(usize, usize)| -> Verdict {
        if let Some(v) = memo.verdict(key(p)) {
            return v;
        }
        let v = if hinted(p) {
            meets
        } else if apart(p) {
            Verdict { collides: false, containment: None }
        } else {
            let c = api::collide(&a[p.0], &b[p.1], false);
            if let Some(f) = c.contacts.first() {
                memo.keep_hint(hint_key(a, b, *p), (f.a, f.b));
            }
            Verdict { collides: c.collides(), containment: c.containment.name() }
        };
        memo.keep_verdict(key(p), v);
        v
    };
    let hit = |&(i, j): &(usize, usize), v: Verdict| -> Hit {
        let cs = if data { contacts(&a[i], &b[j], &api::collide(&a[i], &b[j], true)) } else { Vec::new() };
        (i, j, cs, v.containment)
    };
    if stop_at_first {
        // Kept verdicts and the hints first: neither needs the pairs' bounding balls (a pair
        // known to collide, or with a meeting triangle pair, is not apart).
        let mut open = Vec::with_capacity(pairs.len());
        for p in pairs {
            match memo.verdict(key(p)) {
                Some(v) if v.collides => return vec![hit(p, v)],
                Some(_) => {}
                None => open.push(*p),
            }
        }
        let met = |p: &(usize, usize)| {
            memo.keep_verdict(key(p), meets);
            hit(p, meets)
        };
        if let Some(h) = open.iter().find(|p| hinted(p)).map(met) {
            return vec![h];
        }
        open.retain(|p| !apart(p));
        let meet = |p: &(usize, usize)| {
            let (x, y) = (&a[p.0], &b[p.1]);
            if prepared::no_meeting_triangles(x, y) {
                return None;
            }
            let m = api::meeting_pairs(&x.corners(), &x.tree(), &y.corners(), &y.tree(), true);
            let first = m.first()?;
            memo.keep_hint(hint_key(a, b, *p), (first.a, first.b));
            Some(met(p))
        };
        if let Some(h) = find_any(&open, meet) {
            return vec![h];
        }
        let contained = |p: &(usize, usize)| {
            let v = decide(p);
            v.collides.then(|| hit(p, v))
        };
        return find_any(&open, contained).into_iter().collect();
    }
    filter_map_all(pairs, |p| {
        let v = decide(p);
        v.collides.then(|| hit(p, v))
    })
}

/// The key of object pair `(i, j)` (of `a`, of `b`) in the memo's hints.
fn hint_key(a: &[Arc<Placed>], b: &[Arc<Placed>], (i, j): (usize, usize)) -> HintKey {
    ((i, Arc::as_ptr(&a[i].prepared) as usize), (j, Arc::as_ptr(&b[j].prepared) as usize))
}

/// Exact: does triangle pair `hint` (of `x`, of `y`; ignored when out of range) meet?
fn hint_meets(x: &Placed, y: &Placed, hint: Option<(u32, u32)>) -> bool {
    let Some((s, t)) = hint else { return false };
    // The two triangles' world corners alone (the meshes' world coordinates are not computed
    // for them).
    (s as usize) < x.prepared.mesh.triangles.len()
        && (t as usize) < y.prepared.mesh.triangles.len()
        && tri_tri::classify(&x.triangle(s), &y.triangle(t)).is_some()
}

/// Up to this many candidate object pairs, a query runs them on the calling thread (waking the
/// pool costs more than a few exact checks; a speed threshold, no answer depends on it).
const SEQUENTIAL_PAIRS: usize = 8;

/// The closest pair over candidate object pairs: (signed distance, i, j, face i, face j, point
/// i, point j). When some pair collides, a colliding pair with its signed distance (<= 0): the
/// first pair in (i, j) order whose triangles meet, else the first in (i, j) order with one
/// part inside the other; otherwise the smallest gap, ties broken by (i, j), pairs whose
/// lower bound (boxes, balls) is above the best gap so far skipped.
type Near = (f64, usize, usize, i64, i64, [f64; 3], [f64; 3]);

fn near(d: prepared::Signed, i: usize, j: usize) -> Near {
    (d.distance, i, j, d.a.0, d.b.0, d.a.1.to_array(), d.b.1.to_array())
}

/// Which object pairs a distance query is about.
#[derive(Debug, Clone, Copy)]
enum Among {
    /// Every pair `(i, j)`, `i < j`, of one list (`a` and `b` are the same list).
    Internal,
    /// `(k, j)` for every `j != k` of one list.
    Named(usize),
    /// Every pair of one object of `a` and one of `b`.
    Across,
}

/// `candidates`: the pairs whose boxes meet, sorted (only they can collide); `among`: every pair
/// the query is about, searched best-first (by [`Placed::gap`]) only when no candidate
/// collides; `tree`: the tree of `b`'s objects (all of them), when the caller keeps one (asked
/// for only when no candidate collides: a colliding pair answers without it).
fn nearest(
    candidates: &[(usize, usize)],
    among: Among,
    tree: &(dyn Fn() -> Option<Arc<ObjectTree>> + Sync),
    a: &[Arc<Placed>],
    b: &[Arc<Placed>],
    memo: Memory<'_>,
) -> Option<Near> {
    let key = |i: usize, j: usize| (a[i].id(), b[j].id());
    let signed = |i: usize, j: usize, bound: f64| -> Option<prepared::Signed> {
        if let Some(s) = memo.signed(key(i, j)) {
            return Some(s);
        }
        let s = prepared::signed_distance(&a[i], &b[j], bound)?;
        memo.keep_signed(key(i, j), &s);
        Some(s)
    };
    // From the kept answers alone when they settle it: the first candidate in order known to
    // have meeting triangles, every candidate before it known not to.
    for &(i, j) in candidates {
        match memo.verdict(key(i, j)) {
            Some(v) if v.collides && v.containment.is_none() => {
                if let Some(s) = memo.signed(key(i, j)) {
                    return Some(near(s, i, j));
                }
                break;
            }
            Some(_) => {}
            None if memo.no_meeting(key(i, j)) => {}
            None => break,
        }
    }
    // Meeting triangles first (a pair known to collide without containment has them), then
    // containment: the first pair in (i, j) order of the first kind found.
    // With the meeting pair found, when this search found it (its signed distance is then
    // computed from it, not searched for again).
    // (The walk itself settles a pair whose boxes meet but whose balls are apart; finding the
    // balls cost more than that.)
    let meeting = |&(i, j): &(usize, usize)| match memo.verdict(key(i, j)) {
        Some(v) => (v.collides && v.containment.is_none()).then_some((i, j, None)),
        None if memo.no_meeting(key(i, j)) => None,
        None => {
            let (x, y) = (&a[i], &b[j]);
            // The outlines settle most pairs with no meeting triangles without the world
            // coordinates.
            let m = if prepared::no_meeting_triangles(x, y) {
                Vec::new()
            } else {
                api::meeting_pairs(&x.corners(), &x.tree(), &y.corners(), &y.tree(), true)
            };
            let Some(first) = m.into_iter().next() else {
                memo.keep_no_meeting(key(i, j));
                return None;
            };
            memo.keep_hint(hint_key(a, b, (i, j)), (first.a, first.b));
            memo.keep_verdict(key(i, j), Verdict { collides: true, containment: None });
            Some((i, j, Some(first)))
        }
    };
    let contained = |&(i, j): &(usize, usize)| {
        let v = match memo.verdict(key(i, j)) {
            Some(v) => v,
            None if prepared::surely_clear(&a[i], &b[j]) || a[i].apart(&b[j]) => return None,
            None => {
                let c = api::collide(&a[i], &b[j], false);
                let v = Verdict { collides: c.collides(), containment: c.containment.name() };
                memo.keep_verdict(key(i, j), v);
                v
            }
        };
        v.collides.then_some((i, j, None))
    };
    if let Some((i, j, contact)) =
        find_first(candidates, meeting).or_else(|| find_first(candidates, contained))
    {
        let s = match (memo.signed(key(i, j)), contact) {
            (Some(s), _) => s,
            (None, Some(c)) => {
                let s = prepared::signed_meeting(&a[i], &b[j], &c);
                memo.keep_signed(key(i, j), &s);
                s
            }
            (None, None) => signed(i, j, 0.0).expect("colliding"),
        };
        return Some(near(s, i, j));
    }
    let key3 = |x: &(f64, usize, usize), y: &(f64, usize, usize)| {
        x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2)))
    };
    // Best-first over object pairs by their lower bound: every pair whose bound is at most the
    // best distance so far is evaluated, so the smallest (distance, i, j) is the answer a scan
    // of all pairs gives. A node pair's bound (its boxes' distance less the largest search
    // margin of all objects) is at most the bound of every object pair below it: boxes of
    // nodes hold their objects' boxes, and each step of the box distance is monotone.
    let margin = a.iter().chain(b).map(|p| p.reach_margin()).fold(0.0f64, f64::max);
    let boxes = |l: &[Arc<Placed>]| l.iter().map(|p| p.reach()).collect::<Vec<Aabb>>();
    let kept = tree();
    let own_b;
    let tb = match &kept {
        Some(t) => t,
        None => {
            own_b = ObjectTree::build(&boxes(b), (0..b.len()).collect());
            &own_b
        }
    };
    let own_a;
    let (ta, same) = match among {
        Among::Internal => (tb, true),
        Among::Named(k) => {
            own_a = ObjectTree::build(&boxes(a), vec![k]);
            (&own_a, false)
        }
        Among::Across => {
            own_a = ObjectTree::build(&boxes(a), (0..a.len()).collect());
            (&own_a, false)
        }
    };
    let mut best = (f64::INFINITY, usize::MAX, usize::MAX);
    let mut found = None;
    broad::best_first(
        ta,
        tb,
        same,
        |x, y| x.distance_sq(y).sqrt() - margin,
        |i, j| {
            if matches!(among, Among::Named(k) if j == k) {
                return best.0;
            }
            // The bound from the boxes that hold the two first (it needs no world
            // coordinates), then the finer one: each at most the pair's distance.
            let far = |lb: f64| key3(&(lb, i, j), &best).is_gt();
            if far(a[i].reach_gap(&b[j])) || far(a[i].gap(&b[j])) {
                return best.0;
            }
            if let Some(c) = signed(i, j, best.0) {
                if key3(&(c.distance, i, j), &best).is_lt() {
                    best = (c.distance, i, j);
                    found = Some(near(c, i, j));
                }
            }
            best.0
        },
    );
    found
}

/// A sweep-and-prune broad phase over the objects' world boxes, kept across queries: the
/// objects sorted by their boxes' lower x, updated when one is added, moved or removed.
#[derive(Default)]
struct Sweep {
    /// (box min x, object index), ascending.
    order: Vec<(f64, usize)>,
    /// At least the x extent of every box inserted so far (never lowered: an upper bound is
    /// all [`Sweep::against`] needs).
    widest: f64,
}

impl Sweep {
    fn insert(&mut self, i: usize, b: &Aabb) {
        let k = (b.min.x, i);
        let at = self.order.partition_point(|x| x.0.total_cmp(&k.0).then(x.1.cmp(&k.1)).is_lt());
        self.order.insert(at, k);
        self.widest = self.widest.max(b.max.x - b.min.x);
    }
    fn remove(&mut self, i: usize, b: &Aabb) {
        let k = (b.min.x, i);
        let at = self.order.partition_point(|x| x.0.total_cmp(&k.0).then(x.1.cmp(&k.1)).is_lt());
        debug_assert_eq!(self.order[at].1, i);
        self.order.remove(at);
    }
    /// After removing object `i`: the indices above it move down by one.
    fn renumber_after(&mut self, i: usize) {
        for x in &mut self.order {
            if x.1 > i {
                x.1 -= 1;
            }
        }
    }
    /// Every pair (i < j) whose boxes meet (closed boxes), sorted.
    fn pairs(&self, objs: &[Arc<Placed>]) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (k, &(_, i)) in self.order.iter().enumerate() {
            let bi = objs[i].reach();
            for &(min_x, j) in &self.order[k + 1..] {
                if min_x > bi.max.x {
                    break;
                }
                if bi.overlaps(&objs[j].reach()) {
                    out.push((i.min(j), i.max(j)));
                }
            }
        }
        out.sort_unstable();
        out
    }
    /// The objects whose boxes meet `q`, ascending: those whose lower x lies in
    /// `[predicates::sweep_start(q.min.x, widest), q.max.x]` are looked at (a box that meets
    /// `q` has its upper x at least `q.min.x`, and its lower x within its width of it).
    fn against(&self, objs: &[Arc<Placed>], q: &Aabb) -> Vec<usize> {
        let from = predicates::sweep_start(q.min.x, self.widest);
        let start = self.order.partition_point(|x| x.0 < from);
        let end = self.order.partition_point(|x| x.0 <= q.max.x);
        let mut out: Vec<usize> = self.order[start..end.max(start)]
            .iter()
            .map(|x| x.1)
            .filter(|&i| objs[i].reach().overlaps(q))
            .collect();
        out.sort_unstable();
        out
    }
}

/// A list of object pairs, shared between the manager and the queries that read it.
type Pairs = Arc<Vec<(usize, usize)>>;

/// The native collision manager (`meshclash.CollisionManager` wraps it with trimesh's
/// interface). Objects keep their insertion order; names are unique.
#[pyclass(module = "meshclash._meshclash")]
#[derive(Default)]
struct Manager {
    names: Vec<String>,
    index: HashMap<String, usize>,
    objs: Vec<Arc<Placed>>,
    sweep: Sweep,
    /// The candidate pairs (boxes meet) of the objects, sorted, kept across queries: updated
    /// for the one object an add or set_transform places, rebuilt after a removal.
    pairs: Mutex<Option<Pairs>>,
    /// Pair answers kept across queries ([`Memo`]).
    memo: Mutex<Memo>,
    /// The tree over every object's box, built by the first distance query that needs it after
    /// an object was placed or removed.
    tree: Mutex<Option<Arc<ObjectTree>>>,
}

impl Manager {
    fn find(&self, name: &str) -> PyResult<usize> {
        self.index
            .get(name)
            .copied()
            .ok_or_else(|| PyValueError::new_err(format!("{name} not in collision manager!")))
    }

    fn set(&mut self, i: usize, placed: Arc<Placed>) {
        self.sweep.remove(i, &self.objs[i].reach());
        self.sweep.insert(i, &placed.reach());
        self.memo.get_mut().unwrap().forget(self.objs[i].id());
        self.objs[i] = placed;
        self.placed(i);
    }

    /// Object `i` set to the transform it already has (the same bits): its placement is
    /// kept (placing the mesh again gives the same world coordinates; redoing it also pushed
    /// the next query's data out of the caches), under a fresh id so that its pair answers are
    /// dropped as after any move. False (nothing done) when the transform differs or the
    /// placement is shared.
    fn same_place(&mut self, i: usize, t: &DMat4) -> bool {
        let bits = |m: &DMat4| m.to_cols_array().map(f64::to_bits);
        if bits(&self.objs[i].transform) != bits(t) {
            return false;
        }
        let old = self.objs[i].id();
        let Some(p) = Arc::get_mut(&mut self.objs[i]) else { return false };
        p.renew_id();
        // Its box is the same: the sweep, the candidate pairs and the object tree stay.
        self.memo.get_mut().unwrap().forget(old);
        true
    }

    /// Object `i` was placed anew (added or moved): its candidate pairs are found again.
    fn placed(&mut self, i: usize) {
        *self.tree.get_mut().unwrap() = None;
        let Some(pairs) = self.pairs.get_mut().unwrap().as_mut() else { return };
        let pairs = Arc::make_mut(pairs);
        pairs.retain(|&(x, y)| x != i && y != i);
        let with = self.sweep.against(&self.objs, &self.objs[i].reach());
        pairs.extend(with.into_iter().filter(|&j| j != i).map(|j| (i.min(j), i.max(j))));
        pairs.sort_unstable();
    }

    /// The candidate pairs (i < j, boxes meet), sorted (shared with the kept list, not copied).
    fn candidate_pairs(&self) -> Pairs {
        let mut kept = self.pairs.lock().unwrap();
        kept.get_or_insert_with(|| Arc::new(self.sweep.pairs(&self.objs))).clone()
    }

    /// Pairs (ours, theirs) whose boxes meet, sorted.
    fn pairs_with(&self, other: &[Arc<Placed>]) -> Vec<(usize, usize)> {
        let mut out: Vec<(usize, usize)> = other
            .iter()
            .enumerate()
            .flat_map(|(j, o)| self.sweep.against(&self.objs, &o.reach()).into_iter().map(move |i| (i, j)))
            .collect();
        out.sort_unstable();
        out
    }
}

/// The tree over the boxes of `objs`, built once and kept in `kept` (emptied when an object is
/// placed or removed).
fn object_tree(objs: &[Arc<Placed>], kept: &Mutex<Option<Arc<ObjectTree>>>) -> Arc<ObjectTree> {
    let mut kept = kept.lock().unwrap();
    kept.get_or_insert_with(|| {
        let boxes: Vec<Aabb> = objs.iter().map(|p| p.reach()).collect();
        Arc::new(ObjectTree::build(&boxes, (0..boxes.len()).collect()))
    })
    .clone()
}

fn place(py: Python<'_>, p: &Arc<Prepared>, t: DMat4) -> PyResult<Arc<Placed>> {
    let p = p.clone();
    py.detach(move || p.place(t).map(Arc::new)).map_err(py_err)
}

#[pymethods]
impl Manager {
    #[new]
    fn new() -> Self {
        Manager::default()
    }

    /// Add or replace `name`.
    #[pyo3(signature = (name, mesh, transform=None))]
    fn add(
        &mut self,
        py: Python<'_>,
        name: String,
        mesh: PyRef<'_, Mesh>,
        transform: Option<Vec<Vec<f64>>>,
    ) -> PyResult<()> {
        let placed = place(py, &mesh.inner, transform_of(transform)?)?;
        match self.index.get(&name) {
            Some(&i) => self.set(i, placed),
            None => {
                let i = self.objs.len();
                self.sweep.insert(i, &placed.reach());
                self.index.insert(name.clone(), i);
                self.names.push(name);
                self.objs.push(placed);
                self.placed(i);
            }
        }
        Ok(())
    }

    fn remove(&mut self, name: &str) -> PyResult<()> {
        let i = self.find(name)?;
        self.sweep.remove(i, &self.objs[i].reach());
        self.sweep.renumber_after(i);
        self.memo.get_mut().unwrap().forget(self.objs[i].id());
        *self.pairs.get_mut().unwrap() = None;
        *self.tree.get_mut().unwrap() = None;
        self.names.remove(i);
        self.objs.remove(i);
        self.index = self.names.iter().enumerate().map(|(k, n)| (n.clone(), k)).collect();
        Ok(())
    }

    fn set_transform(&mut self, py: Python<'_>, name: &str, transform: Vec<Vec<f64>>) -> PyResult<()> {
        let i = self.find(name)?;
        let t = transform_of(Some(transform))?;
        if self.same_place(i, &t) {
            return Ok(());
        }
        let p = self.objs[i].prepared.clone();
        let placed = place(py, &p, t)?;
        self.set(i, placed);
        Ok(())
    }

    fn names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Colliding pairs among the objects: (name, name, contacts, containment).
    fn collide_internal(&self, py: Python<'_>, data: bool, stop_at_first: bool) -> Vec<NamedHit> {
        let pairs = self.candidate_pairs();
        let (objs, memo) = (&self.objs, &self.memo);
        let hits = py.detach(|| collide_pairs(&pairs, objs, objs, data, stop_at_first, Memory(Some(memo))));
        hits.into_iter().map(|(i, j, c, k)| (self.names[i].clone(), self.names[j].clone(), c, k)).collect()
    }

    /// Colliding pairs (one of ours, one of `other`'s).
    fn collide_other(
        &self,
        py: Python<'_>,
        other: PyRef<'_, Manager>,
        data: bool,
        stop_at_first: bool,
    ) -> Vec<NamedHit> {
        let pairs = self.pairs_with(&other.objs);
        let (a, b, memo) = (&self.objs, &other.objs, &self.memo);
        let hits = py.detach(|| collide_pairs(&pairs, a, b, data, stop_at_first, Memory(Some(memo))));
        hits.into_iter().map(|(i, j, c, k)| (self.names[i].clone(), other.names[j].clone(), c, k)).collect()
    }

    /// Our objects colliding with `mesh` placed by `transform`: (name, contacts with the
    /// manager's face first, containment).
    #[pyo3(signature = (mesh, transform, data, stop_at_first))]
    fn collide_single(
        &self,
        py: Python<'_>,
        mesh: PyRef<'_, Mesh>,
        transform: Option<Vec<Vec<f64>>>,
        data: bool,
        stop_at_first: bool,
    ) -> PyResult<Vec<SingleHit>> {
        let single = vec![place(py, &mesh.inner, transform_of(transform)?)?];
        let pairs = self.pairs_with(&single);
        let a = &self.objs;
        let hits = py.detach(|| collide_pairs(&pairs, a, &single, data, stop_at_first, Memory(None)));
        Ok(hits.into_iter().map(|(i, _, c, k)| (self.names[i].clone(), c, k)).collect())
    }

    /// The closest pair among our objects (or between `name` and the others).
    #[pyo3(signature = (name=None))]
    fn distance_internal(&self, py: Python<'_>, name: Option<String>) -> PyResult<Option<NamedNear>> {
        let objs = &self.objs;
        let k = name.as_deref().map(|n| self.find(n)).transpose()?;
        let mut candidates = self.candidate_pairs();
        if let Some(k) = k {
            let candidates = Arc::make_mut(&mut candidates);
            candidates.retain(|&(i, j)| i == k || j == k);
            // The named object first in every pair.
            for p in candidates.iter_mut() {
                if p.0 != k {
                    *p = (k, p.0);
                }
            }
            candidates.sort_unstable();
        }
        let among = k.map_or(Among::Internal, Among::Named);
        let (kept, memo) = (&self.tree, &self.memo);
        let tree = || Some(object_tree(objs, kept));
        let near = py.detach(|| nearest(&candidates, among, &tree, objs, objs, Memory(Some(memo))));
        Ok(near.map(|(d, i, j, fi, fj, pi, pj)| {
            (d, self.names[i].clone(), self.names[j].clone(), fi, fj, pi, pj)
        }))
    }

    fn distance_other(&self, py: Python<'_>, other: PyRef<'_, Manager>) -> Option<NamedNear> {
        let (a, b) = (&self.objs, &other.objs);
        let candidates = self.pairs_with(b);
        let memo = &self.memo;
        let kept = &other.tree;
        let tree = || Some(object_tree(b, kept));
        let near = py.detach(|| nearest(&candidates, Among::Across, &tree, a, b, Memory(Some(memo))));
        near.map(|(d, i, j, fi, fj, pi, pj)| {
            (d, self.names[i].clone(), other.names[j].clone(), fi, fj, pi, pj)
        })
    }

    #[pyo3(signature = (mesh, transform))]
    fn distance_single(
        &self,
        py: Python<'_>,
        mesh: PyRef<'_, Mesh>,
        transform: Option<Vec<Vec<f64>>>,
    ) -> PyResult<Option<SingleNear>> {
        let single = vec![place(py, &mesh.inner, transform_of(transform)?)?];
        let a = &self.objs;
        let candidates = self.pairs_with(&single);
        let near = py.detach(|| nearest(&candidates, Among::Across, &|| None, a, &single, Memory(None)));
        Ok(near.map(|(d, i, _, fi, fj, pi, pj)| (d, self.names[i].clone(), fi, fj, pi, pj)))
    }
}

/// The library version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _meshclash(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check_json, m)?)?;
    m.add_function(wrap_pyfunction!(scene_json, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_class::<Mesh>()?;
    m.add_class::<Manager>()?;
    Ok(())
}
