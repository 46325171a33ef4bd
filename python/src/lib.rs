//! `meshclash._meshclash`: the native half of the Python package. The public API (argument
//! checking, the trimesh-style return values) is in `python/meshclash/__init__.py`; this module
//! converts arrays, releases the GIL and calls `meshclash::api`.

use glam::{DMat4, DVec3, DVec4};
use meshclash::api::{self, Options, Placed, Prepared, Source, Tolerance};
use meshclash::bvh::{BuildOptions, Strategy};
use meshclash::check::assembly::Selection;
use meshclash::check::query::{Detail, DistanceError, Mode};
use meshclash::Error;
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
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

fn mesh_from(
    label: &Path,
    name: &str,
    v: &Bound<'_, PyAny>,
    f: &Bound<'_, PyAny>,
) -> PyResult<meshclash::scene::mesh::Mesh> {
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
    };
    o.validate().map_err(py_err)?;
    Ok(o)
}

/// The report of `a` against `b` as JSON text (see `meshclash.check`).
#[pyfunction]
#[pyo3(signature = (a, b, *, transform_a=None, transform_b=None, touch_tolerance=None, clearance=None,
    max_pairs=1000, mode="exact", first_hit=false, detail="pairs", threads=0, timings=true, penetration=false,
    split_bodies=false, bvh="sah", leaf_size=4, distance_rel_err=0.0, distance_abs_err=0.0,
    select_a=vec![], select_b=vec![], exclude=vec![]))]
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
) -> PyResult<String> {
    let zero = 0.0f64.into_pyobject(py)?.into_any();
    let opts = options(
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
    exclude=vec![]))]
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

/// One meeting triangle pair: (face, face, shared point, unit normal of the second face).
type Contact = (u32, u32, [f64; 3], [f64; 3]);

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
type SingleNear = (f64, String, u32, u32, [f64; 3], [f64; 3]);

/// A closest pair by name: (distance, name, name, face, face, point, point).
type NamedNear = (f64, String, String, u32, u32, [f64; 3], [f64; 3]);

fn hit(i: usize, j: usize, a: &Placed, b: &Placed, all: bool) -> Option<Hit> {
    let c = api::collide(a, b, all);
    if !c.collides() {
        return None;
    }
    let mb = b.positions();
    let tris = &b.prepared.mesh.triangles;
    let contacts = c
        .contacts
        .iter()
        .map(|p| {
            let point = match p.segment {
                Some([s, t]) => (s + t) * 0.5,
                None => meshclash::check::query::pair_witness(&a.mesh(), &b.mesh(), p).a.1,
            };
            let [x, y, z] = tris[p.b as usize].map(|v| mb[v as usize]);
            let n = (y - x).cross(z - x).normalize_or_zero();
            (p.a, p.b, point.to_array(), n.to_array())
        })
        .collect();
    Some((i, j, contacts, c.containment.name()))
}

/// Exact collision of every candidate pair `(i, j)` (boxes meet); `stop_at_first` ends the
/// search at the first colliding pair found (a yes/no question). Sorted by (i, j).
fn collide_pairs(
    pairs: Vec<(usize, usize)>,
    a: &[Arc<Placed>],
    b: &[Arc<Placed>],
    all: bool,
    stop_at_first: bool,
) -> Vec<Hit> {
    let stop = AtomicBool::new(false);
    let mut hits: Vec<Hit> = pairs
        .into_par_iter()
        .filter_map(|(i, j)| {
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            let h = hit(i, j, &a[i], &b[j], all);
            if h.is_some() && stop_at_first {
                stop.store(true, Ordering::Relaxed);
            }
            h
        })
        .collect();
    hits.sort_by_key(|h| (h.0, h.1));
    hits
}

/// Candidate pairs whose world boxes meet (closed boxes: touching boxes count).
#[allow(clippy::needless_range_loop)]
fn box_pairs(a: &[Arc<Placed>], b: Option<&[Arc<Placed>]>) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    match b {
        None => {
            for i in 0..a.len() {
                for j in i + 1..a.len() {
                    if a[i].bounds().overlaps(&a[j].bounds()) {
                        out.push((i, j));
                    }
                }
            }
        }
        Some(b) => {
            for i in 0..a.len() {
                for j in 0..b.len() {
                    if a[i].bounds().overlaps(&b[j].bounds()) {
                        out.push((i, j));
                    }
                }
            }
        }
    }
    out
}

/// The closest pair over candidate object pairs: (distance, i, j, face i, face j, point i,
/// point j); ties broken by (i, j). Pairs whose boxes are farther apart than the best distance
/// so far are skipped.
type Near = (f64, usize, usize, u32, u32, [f64; 3], [f64; 3]);

fn nearest(pairs: Vec<(usize, usize)>, a: &[Arc<Placed>], b: &[Arc<Placed>]) -> Option<Near> {
    let key = |x: &(f64, usize, usize), y: &(f64, usize, usize)| {
        x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2)))
    };
    let mut by_bound: Vec<(f64, usize, usize)> =
        pairs.into_iter().map(|(i, j)| (a[i].bounds().distance_sq(&b[j].bounds()).sqrt(), i, j)).collect();
    by_bound.sort_by(key);
    // The best (distance, i, j) so far: a pair can only beat it if its (lower bound, i, j)
    // comes first, so the answer (smallest distance, then smallest (i, j)) does not depend on
    // the order the threads finish in.
    let best = Mutex::new((f64::INFINITY, usize::MAX, usize::MAX));
    let found: Vec<Near> = by_bound
        .par_iter()
        .filter_map(|&(lb, i, j)| {
            let bound = *best.lock().unwrap();
            if key(&(lb, i, j), &bound).is_gt() {
                return None;
            }
            let c = api::distance(&a[i], &b[j], bound.0)?;
            let mut g = best.lock().unwrap();
            if key(&(c.distance, i, j), &g).is_lt() {
                *g = (c.distance, i, j);
            }
            Some((c.distance, i, j, c.a.0, c.b.0, c.a.1.to_array(), c.b.1.to_array()))
        })
        .collect();
    found.into_iter().min_by(|x, y| key(&(x.0, x.1, x.2), &(y.0, y.1, y.2)))
}

/// The native collision manager (`meshclash.CollisionManager` wraps it with trimesh's
/// interface). Objects keep their insertion order; names are unique.
#[pyclass(module = "meshclash._meshclash")]
#[derive(Default)]
struct Manager {
    names: Vec<String>,
    objs: Vec<Arc<Placed>>,
}

impl Manager {
    fn find(&self, name: &str) -> PyResult<usize> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| PyValueError::new_err(format!("{name} not in collision manager!")))
    }
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
        match self.names.iter().position(|n| *n == name) {
            Some(i) => self.objs[i] = placed,
            None => {
                self.names.push(name);
                self.objs.push(placed);
            }
        }
        Ok(())
    }

    fn remove(&mut self, name: &str) -> PyResult<()> {
        let i = self.find(name)?;
        self.names.remove(i);
        self.objs.remove(i);
        Ok(())
    }

    fn set_transform(&mut self, py: Python<'_>, name: &str, transform: Vec<Vec<f64>>) -> PyResult<()> {
        let i = self.find(name)?;
        let p = self.objs[i].prepared.clone();
        self.objs[i] = place(py, &p, transform_of(Some(transform))?)?;
        Ok(())
    }

    fn names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Colliding pairs among the objects: (name, name, contacts, containment).
    fn collide_internal(&self, py: Python<'_>, all: bool, stop_at_first: bool) -> Vec<NamedHit> {
        let objs = self.objs.clone();
        let hits = py.detach(move || collide_pairs(box_pairs(&objs, None), &objs, &objs, all, stop_at_first));
        hits.into_iter().map(|(i, j, c, k)| (self.names[i].clone(), self.names[j].clone(), c, k)).collect()
    }

    /// Colliding pairs (one of ours, one of `other`'s).
    fn collide_other(
        &self,
        py: Python<'_>,
        other: PyRef<'_, Manager>,
        all: bool,
        stop_at_first: bool,
    ) -> Vec<NamedHit> {
        let (a, b) = (self.objs.clone(), other.objs.clone());
        let hits = py.detach(move || collide_pairs(box_pairs(&a, Some(&b)), &a, &b, all, stop_at_first));
        hits.into_iter().map(|(i, j, c, k)| (self.names[i].clone(), other.names[j].clone(), c, k)).collect()
    }

    /// Our objects colliding with `mesh` placed by `transform`: (name, contacts with the
    /// manager's face first, containment).
    #[pyo3(signature = (mesh, transform, all, stop_at_first))]
    fn collide_single(
        &self,
        py: Python<'_>,
        mesh: PyRef<'_, Mesh>,
        transform: Option<Vec<Vec<f64>>>,
        all: bool,
        stop_at_first: bool,
    ) -> PyResult<Vec<SingleHit>> {
        let single = vec![place(py, &mesh.inner, transform_of(transform)?)?];
        let a = self.objs.clone();
        let hits =
            py.detach(move || collide_pairs(box_pairs(&a, Some(&single)), &a, &single, all, stop_at_first));
        Ok(hits.into_iter().map(|(i, _, c, k)| (self.names[i].clone(), c, k)).collect())
    }

    /// The closest pair among our objects (or between `name` and the others).
    #[pyo3(signature = (name=None))]
    fn distance_internal(&self, py: Python<'_>, name: Option<String>) -> PyResult<Option<NamedNear>> {
        let objs = self.objs.clone();
        let pairs: Vec<(usize, usize)> = match &name {
            None => (0..objs.len()).flat_map(|i| (i + 1..objs.len()).map(move |j| (i, j))).collect(),
            Some(n) => {
                let k = self.find(n)?;
                (0..objs.len()).filter(|&j| j != k).map(|j| (k, j)).collect()
            }
        };
        let near = py.detach(move || nearest(pairs, &objs, &objs));
        Ok(near.map(|(d, i, j, fi, fj, pi, pj)| {
            (d, self.names[i].clone(), self.names[j].clone(), fi, fj, pi, pj)
        }))
    }

    fn distance_other(&self, py: Python<'_>, other: PyRef<'_, Manager>) -> Option<NamedNear> {
        let (a, b) = (self.objs.clone(), other.objs.clone());
        let pairs: Vec<(usize, usize)> =
            (0..a.len()).flat_map(|i| (0..b.len()).map(move |j| (i, j))).collect();
        let near = py.detach(move || nearest(pairs, &a, &b));
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
        let a = self.objs.clone();
        let pairs: Vec<(usize, usize)> = (0..a.len()).map(|i| (i, 0)).collect();
        let near = py.detach(move || nearest(pairs, &a, &single));
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
