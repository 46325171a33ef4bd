//! Exact penetration depth of two convex polytopes: the length of the shortest translation that
//! separates them (makes them at most touch), with its direction.
//!
//! By the separating-axis theorem the depth is the distance from the origin to the boundary of
//! the Minkowski difference `A - B` (the translations `t` with `A ∩ (B + t) ≠ ∅`), i.e. the
//! smallest `h(n) / |n|` over the facet normals `n` of `A - B`, where
//! `h(n) = max_a a·n - min_b b·n` is its support function. Those normals are the outward face
//! normals of `A`, the inward face normals of `B` (outward normals of `-B`), and `eA × eB` for
//! the edge pairs whose arcs on the Gauss map cross (Minkowski faces; Gregorius, "The
//! Separating Axis Test between Convex Polyhedra", GDC 2013). `h(n) / |n| >= depth` for every
//! `n`, so testing a superset is harmless, and no facet normal is missed: a face-normal axis
//! covers every edge pair whose arcs only touch or overlap.
//!
//! Every decision is exact for the f64 coordinates as given (no iteration as in EPA, no
//! tolerance): each candidate's `h / |n|` is first bounded by interval arithmetic with rigorous
//! rounding bounds (the orientation filter's error bounds of [`crate::geom::predicates`] and one
//! unit of widening per further operation), and only the candidates whose intervals reach the
//! smallest upper bound are compared exactly, as `h_i² · |n_j|² <=> h_j² · |n_i|²` in dyadic
//! arithmetic ([`dyadic`]). Ties go to the first candidate: faces of `A` in order, faces of
//! `B`, then edge pairs by `(edge of A, edge of B)`; among tied deepest vertices, the lowest
//! index. Only the reported depth itself, its unit normal and point are rounded f64 values.
//!
//! Convexity is decided exactly too ([`is_convex`]): closed, consistently oriented, and every
//! vertex on or below every face's plane (exact orientation signs), with positive volume.

mod dyadic;
pub mod parts;

use crate::geom::predicates::{
    self, FILTER_UNDERFLOW_ALLOWANCE, ORIENT2D_FILTER_BOUND, ORIENT3D_FILTER_BOUND,
};
use crate::geom::DVec3;
use dyadic::Dyadic;
use std::cmp::Ordering;
use std::collections::HashMap;

/// An edge of a closed, consistently oriented triangle mesh: it runs `v[0] → v[1]` in face
/// `f[0]` and `v[1] → v[0]` in face `f[1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// Its two vertices.
    pub v: [u32; 2],
    /// Its two faces.
    pub f: [u32; 2],
}

/// The surface structure of a closed, consistently oriented triangle mesh: its edges with their
/// two faces, and the vertices its triangles use (sorted).
#[derive(Debug, Clone, Default)]
pub struct Surface {
    /// Every edge once.
    pub edges: Vec<Edge>,
    /// The vertices the triangles use, ascending.
    pub vertices: Vec<u32>,
}

impl Surface {
    /// The surface of `triangles`, or `None` unless every directed edge occurs exactly once and
    /// its reverse exactly once (closed, consistently oriented, no edge on three faces).
    pub fn of(triangles: &[[u32; 3]]) -> Option<Surface> {
        if triangles.is_empty() {
            return None;
        }
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
        for (f, t) in triangles.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return None;
            }
            for k in 0..3 {
                if directed.insert((t[k], t[(k + 1) % 3]), f as u32).is_some() {
                    return None;
                }
            }
        }
        let mut edges = Vec::with_capacity(directed.len() / 2);
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                let back = *directed.get(&(v, u))?;
                if u < v {
                    edges.push(Edge { v: [u, v], f: [f as u32, back] });
                }
            }
        }
        let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        Some(Surface { edges, vertices })
    }
}

/// A convex polytope as the depth computation reads it: world coordinates, outward triangles
/// and their [`Surface`]. Build it only for meshes [`is_convex`] accepts.
#[derive(Debug, Clone, Copy)]
pub struct Polytope<'a> {
    /// Vertex coordinates.
    pub positions: &'a [DVec3],
    /// Triangles, outward (right-hand rule).
    pub triangles: &'a [[u32; 3]],
    /// Their surface.
    pub surface: &'a Surface,
    /// The face frames ([`Frames`]) of coordinates of which `positions` are an exact
    /// translation (or of `positions` themselves); `None`: found here, for each query.
    pub frames: Option<&'a Frames>,
}

/// The parts of a polytope's face planes that depend only on differences of its coordinates:
/// each face's f64 normal `(q - p) × (r - p)` and the permanents of its error bound, and its
/// unit normal with a bound on its direction error ([`Plane::unit`]). Coordinates that are an
/// exact translation of those the frames were found on have the same frames: each difference is
/// the same real number, so its f64 rounding is the same (a placed mesh reuses its prepared
/// mesh's).
#[derive(Debug, Clone)]
pub struct Frames {
    faces: Vec<(DVec3, DVec3)>,
    units: Vec<Unit>,
}

impl Frames {
    /// The frames of every triangle of `triangles` on `positions`.
    pub fn of(positions: &[DVec3], triangles: &[[u32; 3]]) -> Frames {
        let planes: Vec<Plane> =
            triangles.iter().map(|t| Plane::new(&t.map(|v| positions[v as usize]))).collect();
        Frames {
            units: planes.iter().map(Plane::unit).collect(),
            faces: planes.iter().map(|p| (p.n, p.perm)).collect(),
        }
    }
}

impl Polytope<'_> {
    /// Every face's plane and unit normal, from the frames when given.
    fn planes(&self) -> (Vec<Plane>, std::borrow::Cow<'_, [Unit]>) {
        match self.frames {
            Some(f) if f.faces.len() == self.triangles.len() => {
                let planes = (self.triangles.iter().zip(&f.faces))
                    .map(|(t, &(n, perm))| Plane { origin: self.vertex(t[0]), n, perm })
                    .collect();
                (planes, std::borrow::Cow::Borrowed(&f.units))
            }
            _ => {
                let planes: Vec<Plane> = self.triangles.iter().map(|t| Plane::new(&self.tri_of(t))).collect();
                let units = planes.iter().map(Plane::unit).collect();
                (planes, std::borrow::Cow::Owned(units))
            }
        }
    }
    fn tri_of(&self, t: &[u32; 3]) -> [DVec3; 3] {
        t.map(|v| self.positions[v as usize])
    }
    fn tri(&self, f: u32) -> [DVec3; 3] {
        self.triangles[f as usize].map(|v| self.positions[v as usize])
    }
    fn vertex(&self, v: u32) -> DVec3 {
        self.positions[v as usize]
    }
}

/// Exact: is the closed mesh with this surface the boundary of a convex polytope of positive
/// volume, its triangles facing out? Every used vertex must lie on or below the plane of every
/// triangle (exact [`predicates::orient3d`] signs) and one strictly below. `O(faces × vertices)`
/// orientation tests, float-filtered.
pub fn is_convex(positions: &[DVec3], triangles: &[[u32; 3]], surface: &Surface) -> bool {
    let mut solid = false;
    for t in triangles {
        let t = t.map(|v| positions[v as usize]);
        let filter = predicates::PlaneFilter::new(&t);
        for &v in &surface.vertices {
            match filter.side_exact(&t, positions[v as usize]) {
                1 => return false,
                -1 => solid = true,
                _ => {}
            }
        }
    }
    solid
}

/// Which separating axis gives the depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// The outward normal of this triangle of `A`.
    FaceA(u32),
    /// The inward normal of this triangle of `B`.
    FaceB(u32),
    /// The cross product of these edges (indices into the two surfaces' edge lists).
    Edges(u32, u32),
}

/// The penetration of two overlapping convex polytopes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// The length of the shortest separating translation (0 when they only touch); the f64
    /// value of the exactly chosen axis's `h / |n|`.
    pub depth: f64,
    /// Unit direction to move `B` by `depth` (or `A` by `-depth`) to separate them.
    pub normal: DVec3,
    /// Halfway along the deepest penetration: the deepest vertex (or edge point) of the
    /// penetrating polytope moved back by half the depth.
    pub point: DVec3,
    /// The axis (exactly the smallest; ties to the first, see the module notes).
    pub axis: Axis,
}

/// The exact penetration depth of convex polytopes `a` and `b` (both accepted by
/// [`is_convex`]): `None` when they are disjoint (some axis separates them strictly), a depth of
/// 0 when they only touch.
pub fn penetration(a: &Polytope<'_>, b: &Polytope<'_>) -> Option<Penetration> {
    let mut cands: Vec<Candidate> = Vec::new();
    // Each face's plane and unit normal (with its direction error), found once for every bound
    // below (or kept with the polytope's frames).
    let ((na, ua), (nb, ub)) = (a.planes(), b.planes());
    let prune = Prune::new(a, &na, &ua, b, &nb, &ub);
    if prune.separated {
        return None;
    }
    // Each face's lower bound against the other polytope's ball ([`Prune::face_lows`]).
    let (lows_a, lows_b) = (prune.face_lows(a, &ua, prune.ball_b), prune.face_lows(b, &ub, prune.ball_a));
    // Faces of A against the vertices of B, then faces of B against the vertices of A.
    for (side, (p, planes, q)) in [(a, &na, b), (b, &nb, a)].into_iter().enumerate() {
        let (ball, lows) = if side == 0 { (prune.ball_b, &lows_a) } else { (prune.ball_a, &lows_b) };
        for (f, plane) in planes.iter().enumerate() {
            let t = p.tri(f as u32);
            if plane.degenerate(&t) || prune.skips_face(lows[f], ball) {
                continue;
            }
            let (min_lo, min_hi) = q.surface.vertices.iter().fold((f64::INFINITY, f64::INFINITY), |m, &v| {
                let o = plane.value(q.vertex(v));
                (m.0.min(o.lo), m.1.min(o.hi))
            });
            if min_lo > 0.0 {
                return None; // every vertex strictly above this face: separated
            }
            let h = Iv { lo: -min_hi, hi: -min_lo };
            let axis = if side == 0 { Axis::FaceA(f as u32) } else { Axis::FaceB(f as u32) };
            cands.push(Candidate { axis, d: h.div(plane.norm2().sqrt()) });
        }
    }
    // Edge pairs whose Gauss-map arcs cross (of the edges the bounds keep).
    let keep = |p: &Polytope<'_>, units: &[Unit], lows: &[Option<f64>], ball| -> Vec<usize> {
        (0..p.surface.edges.len())
            .filter(|&i| {
                let e = p.surface.edges[i];
                let [f0, f1] = e.f.map(|f| f as usize);
                let faces = [(lows[f0], units[f0]), (lows[f1], units[f1])];
                !prune.skips_edge(faces, p.vertex(e.v[0]), ball)
            })
            .collect()
    };
    let (edges_a, edges_b) = (keep(a, &ua, &lows_a, prune.ball_b), keep(b, &ub, &lows_b, prune.ball_a));
    // The sign of a face normal of one polytope against a kept edge of the other is the same
    // in every edge pair it appears in: each is decided once (exact, through the exact
    // fallback where the filter cannot tell), kept in a table over the kept edges and the faces
    // next to the other polytope's kept edges.
    let (slots_a, count_a) = face_slots(a, &edges_a, na.len());
    let (slots_b, count_b) = face_slots(b, &edges_b, nb.len());
    let mut signs_a = vec![UNKNOWN; edges_b.len() * count_a]; // faces of A · edges of B
    let mut signs_b = vec![UNKNOWN; edges_a.len() * count_b]; // faces of B · edges of A
    let ends_b: Vec<(DVec3, DVec3, Dir)> = (edges_b.iter())
        .map(|&j| {
            let eb = b.surface.edges[j];
            let (b0, b1) = (b.vertex(eb.v[0]), b.vertex(eb.v[1]));
            (b0, b1, Dir::new(b0, b1))
        })
        .collect();
    for (ii, &i) in edges_a.iter().enumerate() {
        let ea = a.surface.edges[i];
        let (a0, a1) = (a.vertex(ea.v[0]), a.vertex(ea.v[1]));
        let da = Dir::new(a0, a1);
        for (jj, &j) in edges_b.iter().enumerate() {
            let eb = b.surface.edges[j];
            let mut sign_b = |f: u32| {
                let slot = &mut signs_b[ii * count_b + slots_b[f as usize] as usize];
                if *slot == UNKNOWN {
                    *slot = face_dot_edge(b, &nb[f as usize], f, &da, a0, a1);
                }
                *slot
            };
            let s1 = sign_b(eb.f[0]);
            let s2 = sign_b(eb.f[1]);
            if s1 * s2 >= 0 {
                continue;
            }
            let (b0, b1, db) = &ends_b[jj];
            let mut sign_a = |f: u32| {
                let slot = &mut signs_a[jj * count_a + slots_a[f as usize] as usize];
                if *slot == UNKNOWN {
                    *slot = face_dot_edge(a, &na[f as usize], f, db, *b0, *b1);
                }
                *slot
            };
            let t1 = sign_a(ea.f[0]);
            let t2 = sign_a(ea.f[1]);
            if t1 * t2 >= 0 || s1 != -t2 {
                continue;
            }
            let (b0, b1) = (*b0, *b1);
            // n = t1 · (eA × eB) points out of A; h = (a0 - b0)·n = t1 · orient3d(a0, a1, b0, b1).
            let o = Plane::new(&[a0, a1, b0]).value(b1);
            let h = if t1 > 0 { o } else { Iv { lo: -o.hi, hi: -o.lo } };
            let d = h.div(cross_norm2(&da, db).sqrt());
            cands.push(Candidate { axis: Axis::Edges(i as u32, j as u32), d });
        }
    }
    let upper = cands.iter().map(|c| c.d.hi).fold(f64::INFINITY, f64::min);
    if upper < 0.0 {
        return None;
    }
    let contenders: Vec<&Candidate> = cands.iter().filter(|c| c.d.lo <= upper).collect();
    // The winning axis, its exact `(h, |n|²)` when already computed, and an interval holding
    // its depth.
    let (winner, exact, d) = match contenders.as_slice() {
        [] => return None, // no axis at all (cannot happen for closed polytopes)
        [only] if only.d.lo > 0.0 => (only.axis, None, only.d),
        _ => {
            let mut best: Option<(Axis, Dyadic, Dyadic, Iv)> = None;
            for c in &contenders {
                let (h, n2) = exact_axis(a, b, c.axis);
                let better = match &best {
                    None => true,
                    Some((_, bh, bn, _)) => compare_depths(&h, &n2, bh, bn) == Ordering::Less,
                };
                if better {
                    best = Some((c.axis, h, n2, c.d));
                }
            }
            let (axis, h, n2, d) = best?;
            if h.signum() < 0 {
                return None;
            }
            if h.signum() == 0 {
                let (normal, point) = witness(a, b, axis, 0.0);
                return Some(Penetration { depth: 0.0, normal, point, axis });
            }
            (axis, Some((h, n2)), d)
        }
    };
    let (h, n2) = exact.unwrap_or_else(|| exact_axis(a, b, winner));
    let depth = rounded_depth(&h, &n2, (d.lo, d.hi));
    let (normal, point) = witness(a, b, winner, depth);
    Some(Penetration { depth, normal, point, axis: winner })
}

/// The exact penetration of two meshes given as arrays, when both are convex
/// ([`is_convex`]): `None` when either is not (then no exact depth exists here), `Some(None)`
/// when both are convex and disjoint, else the penetration (depth 0 when they only touch).
/// The entry point of `--penetration`'s `exact_convex` method.
pub fn exact_convex_penetration(
    a: (&[DVec3], &[[u32; 3]]),
    b: (&[DVec3], &[[u32; 3]]),
) -> Option<Option<Penetration>> {
    let sa = Surface::of(a.1).filter(|s| is_convex(a.0, a.1, s))?;
    let sb = Surface::of(b.1).filter(|s| is_convex(b.0, b.1, s))?;
    let pa = Polytope { positions: a.0, triangles: a.1, surface: &sa, frames: None };
    let pb = Polytope { positions: b.0, triangles: b.1, surface: &sb, frames: None };
    Some(penetration(&pa, &pb))
}

/// Bounds that settle most axes without the `O(vertices)` support: an inner ball of each
/// polytope (a center and a radius the polytope contains around it) and an upper bound `u` of
/// the depth. Along a unit face normal `n` of `A` (plane point `p`) the depth is at least
/// `(p - c_B)·n + r_B` (B's ball reaches that far below the plane), so a face with that bound
/// above `u` cannot give the depth; an edge's axes lie between its two faces' normals, where
/// `(v - c)·n` is at least the smaller of its values at the two normals (when that is not
/// negative), so an edge whose two faces are both skipped has no axis that can give the depth.
/// `u` is the overlap along the centers' direction (any direction's overlap bounds the depth
/// from above). Every bound is computed in f64 and loosened by its rounding: the search margin
/// [`predicates::distance_rounding_slack`] of the coordinates' scale, plus the direction error
/// of each unit normal (its cross product's filter bound over its length) times the lever arm.
/// Only candidates strictly above the depth are skipped, so ties and the exact answer are kept.
struct Prune {
    u: f64,
    slack: f64,
    ball_a: Option<(DVec3, f64)>,
    ball_b: Option<(DVec3, f64)>,
    /// The overlap along the centers' direction is certainly negative: disjoint.
    separated: bool,
}

/// A face's f64 unit normal and a bound on its direction error ([`Plane::unit`]).
type Unit = Option<(DVec3, f64)>;

impl Prune {
    fn new(
        a: &Polytope<'_>,
        na: &[Plane],
        ua: &[Unit],
        b: &Polytope<'_>,
        nb: &[Plane],
        ub: &[Unit],
    ) -> Prune {
        let verts =
            |p: &Polytope<'_>| -> Vec<DVec3> { p.surface.vertices.iter().map(|&v| p.vertex(v)).collect() };
        let (va, vb) = (verts(a), verts(b));
        let scale = va.iter().chain(&vb).fold(0.0f64, |m, v| m.max(v.abs().max_element()));
        let slack = predicates::distance_rounding_slack(scale);
        let center = |v: &[DVec3]| crate::geom::Aabb::of_points(v).center();
        let (ca, cb) = (center(&va), center(&vb));
        let d = (cb - ca).try_normalize().unwrap_or(DVec3::X);
        let max_a = va.iter().map(|v| v.dot(d)).fold(f64::NEG_INFINITY, f64::max);
        let min_b = vb.iter().map(|v| v.dot(d)).fold(f64::INFINITY, f64::min);
        let u = max_a - min_b + slack;
        let ball = |p: &Polytope<'_>, planes: &[Plane], units: &[Unit], c: DVec3| -> Option<(DVec3, f64)> {
            debug_assert_eq!(planes.len(), units.len());
            let r = units
                .iter()
                .zip(p.triangles)
                .map(|(unit, t)| match unit {
                    Some((n, err)) => {
                        let lever = p.vertex(t[0]) - c;
                        lever.dot(*n) - lever.length() * err - slack
                    }
                    None => f64::INFINITY, // degenerate: no facet
                })
                .fold(f64::INFINITY, f64::min);
            (r > 0.0 && r.is_finite()).then_some((c, r))
        };
        let separated = max_a - min_b + 2.0 * slack < 0.0;
        Prune { u, slack, ball_a: ball(a, na, ua, ca), ball_b: ball(b, nb, ub, cb), separated }
    }

    /// A lower bound of `(p - c)·n` for the exact unit normal `n` of a face (through its vertex
    /// `p`), from the f64 unit normal and its direction error; `None` when the normal's
    /// direction is not known well enough.
    fn lower(&self, unit: Unit, p: DVec3, c: DVec3) -> Option<f64> {
        let (n, err) = unit?;
        let lever = p - c;
        Some(lever.dot(n) - lever.length() * err - self.slack)
    }

    /// Every face's [`Prune::lower`] bound (at its first vertex) against the center of the
    /// other polytope's ball; all `None` without a ball. The exact `(p - c)·n` is the same for
    /// every point `p` of the face's plane, so the bound holds at each of its vertices.
    fn face_lows(&self, p: &Polytope<'_>, units: &[Unit], ball: Option<(DVec3, f64)>) -> Vec<Option<f64>> {
        match ball {
            None => vec![None; units.len()],
            Some((c, _)) => {
                units.iter().zip(p.triangles).map(|(&unit, t)| self.lower(unit, p.vertex(t[0]), c)).collect()
            }
        }
    }

    /// Can the face with this lower bound ([`Prune::face_lows`]) be skipped against the other
    /// polytope's ball? Its depth is at least `(p - c)·n + r`, whatever the sign of `(p - c)·n`.
    fn skips_face(&self, low: Option<f64>, ball: Option<(DVec3, f64)>) -> bool {
        let Some((_, r)) = ball else { return false };
        low.is_some_and(|x| x + r > self.u)
    }

    /// Can every axis of the edge between two faces (their lower bounds and unit normals) be
    /// skipped against the other polytope's ball, `v` a vertex of the edge? Its axes are the
    /// unit vectors `m` on the arc between the two normals, where the depth is at least
    /// `(v - c)·m + r`. When that is not negative at both normals it is at least the smaller of
    /// the two along the arc (a sinusoid below both ends of an arc shorter than π would be
    /// negative at one of them); otherwise it falls at most `|v - c|` times half the arc's angle
    /// below the smaller (the slope along the arc is at most `|v - c|`), and half the angle is at
    /// most `π/4` times the chord between the normals (the f64 chord plus both normals'
    /// direction errors). `v` lies on both faces' planes, so their bounds hold at `v`.
    fn skips_edge(&self, faces: [(Option<f64>, Unit); 2], v: DVec3, ball: Option<(DVec3, f64)>) -> bool {
        let Some((c, r)) = ball else { return false };
        let [(Some(x0), Some((n0, e0))), (Some(x1), Some((n1, e1)))] = faces else {
            return false;
        };
        let mut x = x0.min(x1);
        if x < 0.0 {
            let len = (v - c).length();
            let chord = up((n0 - n1).length() + e0 + e1);
            x = x - up(len * up(chord * std::f64::consts::FRAC_PI_4)) - self.slack;
        }
        x + r > self.u
    }
}

/// A sign not decided yet (in the tables of [`penetration`]'s edge pairs).
const UNKNOWN: i8 = 2;

/// A slot for each face next to one of `edges` (of `p`, which has `faces` faces), numbered from
/// 0 in the order met: the slot of every face (`u32::MAX` for the others) and their count.
fn face_slots(p: &Polytope<'_>, edges: &[usize], faces: usize) -> (Vec<u32>, usize) {
    let mut slots = vec![u32::MAX; faces];
    let mut count = 0;
    for &e in edges {
        for f in p.surface.edges[e].f {
            if slots[f as usize] == u32::MAX {
                slots[f as usize] = count as u32;
                count += 1;
            }
        }
    }
    (slots, count)
}

/// One candidate axis with an interval holding its exact `h / |n|`.
struct Candidate {
    axis: Axis,
    d: Iv,
}

/// Unit roundoff of f64.
const U: f64 = f64::EPSILON / 2.0;

/// Each interval endpoint computed in f64 is moved outward by `4u` relative plus the underflow
/// allowance: one correctly rounded operation errs by at most `u` relative (plus `2^-1075`
/// absolute on underflow), and moving by `4u|x|` covers that error and the rounding of the move
/// itself (`u(1 + 4u)|x|`), so every widened endpoint bounds the real one. Non-finite or NaN
/// results widen to infinity, which only makes a candidate go to the exact comparison.
const WIDEN: f64 = 4.0 * U;

fn dn(x: f64) -> f64 {
    if x.is_nan() {
        f64::NEG_INFINITY
    } else if x.is_infinite() {
        x
    } else {
        x - WIDEN * x.abs() - FILTER_UNDERFLOW_ALLOWANCE
    }
}

fn up(x: f64) -> f64 {
    if x.is_nan() {
        f64::INFINITY
    } else if x.is_infinite() {
        x
    } else {
        x + WIDEN * x.abs() + FILTER_UNDERFLOW_ALLOWANCE
    }
}

/// A closed interval of reals, endpoints f64.
#[derive(Debug, Clone, Copy)]
struct Iv {
    lo: f64,
    hi: f64,
}

impl Iv {
    fn around(v: f64, err: f64) -> Iv {
        Iv { lo: dn(v - err), hi: up(v + err) }
    }
    fn add(self, o: Iv) -> Iv {
        Iv { lo: dn(self.lo + o.lo), hi: up(self.hi + o.hi) }
    }
    /// The square of a real in the interval.
    fn sq(self) -> Iv {
        let (a, b) = (self.lo.abs(), self.hi.abs());
        let lo = if self.lo <= 0.0 && self.hi >= 0.0 { 0.0 } else { dn(a.min(b) * a.min(b)) };
        Iv { lo: lo.max(0.0), hi: up(a.max(b) * a.max(b)) }
    }
    fn sqrt(self) -> Iv {
        Iv { lo: dn(self.lo.max(0.0).sqrt()).max(0.0), hi: up(self.hi.sqrt()) }
    }
    /// `self / o` for `o` positive; unbounded when `o` may be 0.
    fn div(self, o: Iv) -> Iv {
        if o.lo.is_nan() || o.lo <= 0.0 || o.hi.is_nan() {
            return Iv { lo: f64::NEG_INFINITY, hi: f64::INFINITY };
        }
        let q = [self.lo / o.lo, self.lo / o.hi, self.hi / o.lo, self.hi / o.hi];
        let lo = q.iter().fold(f64::INFINITY, |m, &x| if x.is_nan() { f64::NEG_INFINITY } else { m.min(x) });
        let hi = q.iter().fold(f64::NEG_INFINITY, |m, &x| if x.is_nan() { f64::INFINITY } else { m.max(x) });
        Iv { lo: dn(lo), hi: up(hi) }
    }
}

/// The f64 plane of a triangle `(p, q, r)`: `n = (q - p) × (r - p)` and the permanents the
/// orientation filter's error bounds use (the same expressions as
/// [`predicates::PlaneFilter`]).
#[derive(Debug, Clone, Copy)]
struct Plane {
    origin: DVec3,
    n: DVec3,
    perm: DVec3,
}

impl Plane {
    fn new(t: &[DVec3; 3]) -> Plane {
        let (u, v) = (t[1] - t[0], t[2] - t[0]);
        let perm = DVec3::new(
            (u.y * v.z).abs() + (v.y * u.z).abs(),
            (u.z * v.x).abs() + (v.z * u.x).abs(),
            (u.x * v.y).abs() + (v.x * u.y).abs(),
        );
        Plane { origin: t[0], n: u.cross(v), perm }
    }

    /// Exact: is the triangle degenerate (its normal exactly zero)?
    fn degenerate(&self, t: &[DVec3; 3]) -> bool {
        let e = self.perm * ORIENT2D_FILTER_BOUND + DVec3::splat(FILTER_UNDERFLOW_ALLOWANCE);
        let n = self.n.abs();
        !(n.x > e.x || n.y > e.y || n.z > e.z) && predicates::collinear(t[0], t[1], t[2])
    }

    /// The unit normal and a bound on its direction error (radians, as a length on the unit
    /// sphere): the f64 normal is within `C2·|perm|` of the exact one, which turns its
    /// direction by at most twice that over its length; normalizing adds a few ulps. `None`
    /// when the bound says nothing (a sliver or degenerate triangle).
    fn unit(&self) -> Option<(DVec3, f64)> {
        let len = self.n.length();
        let err =
            2.0 * (ORIENT2D_FILTER_BOUND * self.perm.length() + FILTER_UNDERFLOW_ALLOWANCE) / len + WIDEN;
        (len > 0.0 && err < 0.5).then(|| (self.n / len, err))
    }

    /// An interval holding `orient3d(p, q, r, x)` (the orient3d filter's bound).
    fn value(&self, x: DVec3) -> Iv {
        let w = x - self.origin;
        let err = ORIENT3D_FILTER_BOUND * self.perm.dot(w.abs()) + FILTER_UNDERFLOW_ALLOWANCE;
        Iv::around(self.n.dot(w), err)
    }

    /// An interval holding `|n|²` (each component within the orient2d filter's bound).
    fn norm2(&self) -> Iv {
        (0..3)
            .map(|k| {
                let e = ORIENT2D_FILTER_BOUND * self.perm[k] + FILTER_UNDERFLOW_ALLOWANCE;
                Iv::around(self.n[k], e).sq()
            })
            .fold(Iv { lo: 0.0, hi: 0.0 }, Iv::add)
    }
}

/// An edge direction `e1 - e0` (f64) and its componentwise magnitude.
struct Dir {
    e: DVec3,
    abs: DVec3,
}

impl Dir {
    fn new(e0: DVec3, e1: DVec3) -> Dir {
        let e = e1 - e0;
        Dir { e, abs: e.abs() }
    }
}

/// `|eA × eB|²` as an interval: each component of the cross product of two rounded coordinate
/// differences is an orient2d determinant, within the orient2d filter's bound.
fn cross_norm2(a: &Dir, b: &Dir) -> Iv {
    let (u, v) = (a.e, b.e);
    let perm = DVec3::new(
        (u.y * v.z).abs() + (v.y * u.z).abs(),
        (u.z * v.x).abs() + (v.z * u.x).abs(),
        (u.x * v.y).abs() + (v.x * u.y).abs(),
    );
    let c = u.cross(v);
    (0..3)
        .map(|k| Iv::around(c[k], ORIENT2D_FILTER_BOUND * perm[k] + FILTER_UNDERFLOW_ALLOWANCE).sq())
        .fold(Iv { lo: 0.0, hi: 0.0 }, Iv::add)
}

/// Exact sign of `n_f · (e1 - e0)`, `n_f` the normal of face `f` of `p`. The f64 value
/// `n·e` of the rounded normal and difference errs by at most
/// `2·C2·(perm·|e|) + 8u·(|n|·|e|)`: the normal's components are within `C2·perm` (the orient2d
/// filter), each difference within `u` relative, and the dot product within `γ3` of its
/// magnitudes; the factors 2 and 8 cover the cross terms and the rounding of the bound itself.
fn face_dot_edge(p: &Polytope<'_>, pl: &Plane, f: u32, d: &Dir, e0: DVec3, e1: DVec3) -> i8 {
    let v = pl.n.dot(d.e);
    let err = (2.0 * ORIENT2D_FILTER_BOUND * pl.perm + 8.0 * U * pl.n.abs()).dot(d.abs)
        + FILTER_UNDERFLOW_ALLOWANCE;
    if v > err {
        return 1;
    }
    if -v > err {
        return -1;
    }
    let t = p.tri(f).map(exact_vec);
    let n = cross(&sub(&t[1], &t[0]), &sub(&t[2], &t[0]));
    dot(&n, &sub(&exact_vec(e1), &exact_vec(e0))).signum()
}

type Dv = [Dyadic; 3];

fn exact_vec(p: DVec3) -> Dv {
    [Dyadic::from_f64(p.x), Dyadic::from_f64(p.y), Dyadic::from_f64(p.z)]
}

fn sub(a: &Dv, b: &Dv) -> Dv {
    [a[0].sub(&b[0]), a[1].sub(&b[1]), a[2].sub(&b[2])]
}

fn cross(a: &Dv, b: &Dv) -> Dv {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

fn dot(a: &Dv, b: &Dv) -> Dyadic {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// Exact `orient3d(t0, t1, t2, x)` and the exact face normal's squared length.
fn exact_plane(t: &[DVec3; 3]) -> (Dv, Dv) {
    let e = t.map(exact_vec);
    let n = cross(&sub(&e[1], &e[0]), &sub(&e[2], &e[0]));
    let [o, ..] = e;
    (n, o)
}

/// The deepest vertex of `q` below the face plane `t` (exactly the smallest orientation value;
/// the lowest index among ties) and that value, exact.
fn deepest(t: &[DVec3; 3], q: &Polytope<'_>) -> (u32, Dyadic) {
    let plane = Plane::new(t);
    let vals: Vec<(u32, Iv)> = q.surface.vertices.iter().map(|&v| (v, plane.value(q.vertex(v)))).collect();
    let min_hi = vals.iter().map(|x| x.1.hi).fold(f64::INFINITY, f64::min);
    let (n, o) = exact_plane(t);
    let mut best: Option<(u32, Dyadic)> = None;
    for &(v, iv) in &vals {
        if iv.lo > min_hi {
            continue;
        }
        let val = dot(&n, &sub(&exact_vec(q.vertex(v)), &o));
        if best.as_ref().is_none_or(|b| val.cmp(&b.1) == Ordering::Less) {
            best = Some((v, val));
        }
    }
    best.expect("a polytope has vertices")
}

/// Exact `(h, |n|²)` of an axis.
fn exact_axis(a: &Polytope<'_>, b: &Polytope<'_>, axis: Axis) -> (Dyadic, Dyadic) {
    match axis {
        Axis::FaceA(f) | Axis::FaceB(f) => {
            let (p, q) = if matches!(axis, Axis::FaceA(_)) { (a, b) } else { (b, a) };
            let t = p.tri(f);
            let (_, min) = deepest(&t, q);
            let (n, _) = exact_plane(&t);
            (min.neg(), dot(&n, &n))
        }
        Axis::Edges(i, j) => {
            let (ea, eb) = (a.surface.edges[i as usize], b.surface.edges[j as usize]);
            let [a0, a1] = ea.v.map(|v| exact_vec(a.vertex(v)));
            let [b0, b1] = eb.v.map(|v| exact_vec(b.vertex(v)));
            let m = cross(&sub(&a1, &a0), &sub(&b1, &b0));
            let h = dot(&m, &sub(&a0, &b0));
            // Oriented out of A: the sign of n_A1 · eB (the arcs cross, so it is not 0).
            let fa = a.tri(ea.f[0]);
            let (na, _) = exact_plane(&fa);
            let s = dot(&na, &sub(&b1, &b0)).signum();
            (if s > 0 { h } else { h.neg() }, dot(&m, &m))
        }
    }
}

/// Exact order of `h1 / √n1` and `h2 / √n2` (`n1`, `n2` positive).
fn compare_depths(h1: &Dyadic, n1: &Dyadic, h2: &Dyadic, n2: &Dyadic) -> Ordering {
    let (s1, s2) = (h1.signum(), h2.signum());
    if s1 != s2 {
        return s1.cmp(&s2);
    }
    let l = h1.mul(h1).mul(n2);
    let r = h2.mul(h2).mul(n1);
    if s1 >= 0 {
        l.cmp(&r)
    } else {
        r.cmp(&l)
    }
}

/// `h / √n2` (`n2 > 0`) correctly rounded to f64 (nearest, ties to even), 0 when `h <= 0`: a
/// bisection over the bit patterns of non-negative floats (ordered as their values), each step an
/// exact comparison of `x² · n2` with `h²`, then the midpoint rule between the two neighbours.
/// `near` is an interval that should hold the depth (an f64 estimate's bounds): each end is
/// compared exactly first and narrows the bisection only where the comparison allows, so a wrong
/// interval costs steps, never the answer.
fn rounded_depth(h: &Dyadic, n2: &Dyadic, near: (f64, f64)) -> f64 {
    if h.signum() <= 0 {
        return 0.0;
    }
    let h2 = h.mul(h);
    // Order of x against the depth (x >= 0).
    let against = |x: f64| {
        let d = Dyadic::from_f64(x);
        d.mul(&d).mul(n2).cmp(&h2)
    };
    // The largest float not above the depth: bits in [lo, hi], `lo` always not above.
    let (mut lo, mut hi) = (0u64, f64::MAX.to_bits());
    let usable = |x: f64| x.is_finite() && x > 0.0;
    if usable(near.0) && against(near.0) != Ordering::Greater {
        lo = near.0.to_bits();
    }
    if usable(near.1) && near.1.to_bits() > lo && against(near.1) == Ordering::Greater {
        hi = near.1.to_bits() - 1;
    }
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if against(f64::from_bits(mid)) == Ordering::Greater {
            hi = mid - 1;
        } else {
            lo = mid;
        }
    }
    let down = f64::from_bits(lo);
    if lo == f64::MAX.to_bits() || against(down) == Ordering::Equal {
        return down;
    }
    let up = f64::from_bits(lo + 1);
    // The midpoint m = (down + up) / 2 against the depth: (down + up)² · n2 against 4 · h².
    let sum = Dyadic::from_f64(down).add(&Dyadic::from_f64(up));
    match sum.mul(&sum).mul(n2).cmp(&h2.mul(&Dyadic::from_f64(4.0))) {
        Ordering::Less => up,
        Ordering::Greater => down,
        Ordering::Equal if down.to_bits() & 1 == 0 => down,
        Ordering::Equal => up,
    }
}

/// The closest points of the two edges' lines (for an edge axis): on A's edge, on B's edge.
fn edge_points(a: &Polytope<'_>, b: &Polytope<'_>, axis: Axis) -> (DVec3, DVec3) {
    let Axis::Edges(i, j) = axis else { unreachable!("edge axis") };
    let (ea, eb) = (a.surface.edges[i as usize], b.surface.edges[j as usize]);
    let (p0, p1) = (a.vertex(ea.v[0]), a.vertex(ea.v[1]));
    let (q0, q1) = (b.vertex(eb.v[0]), b.vertex(eb.v[1]));
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (aa, bb, cc, dd, ee) = (d1.dot(d1), d1.dot(d2), d2.dot(d2), d1.dot(r), d2.dot(r));
    let den = aa * cc - bb * bb;
    let s = if den > 0.0 { ((bb * ee - cc * dd) / den).clamp(0.0, 1.0) } else { 0.0 };
    let t = if cc > 0.0 { ((bb * s + ee) / cc).clamp(0.0, 1.0) } else { 0.0 };
    (p0 + d1 * s, q0 + d2 * t)
}

/// Unit normal (direction to move B) and the halfway point of an axis at `depth`.
fn witness(a: &Polytope<'_>, b: &Polytope<'_>, axis: Axis, depth: f64) -> (DVec3, DVec3) {
    match axis {
        Axis::FaceA(f) => {
            let t = a.tri(f);
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            let (v, _) = deepest(&t, b);
            (n, b.vertex(v) + n * (depth * 0.5))
        }
        Axis::FaceB(f) => {
            let t = b.tri(f);
            let m = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            let (v, _) = deepest(&t, a);
            (-m, a.vertex(v) + m * (depth * 0.5))
        }
        Axis::Edges(i, j) => {
            let (ea, eb) = (a.surface.edges[i as usize], b.surface.edges[j as usize]);
            let da = a.vertex(ea.v[1]) - a.vertex(ea.v[0]);
            let db = b.vertex(eb.v[1]) - b.vertex(eb.v[0]);
            let mut n = da.cross(db).normalize();
            let (b0, b1) = (b.vertex(eb.v[0]), b.vertex(eb.v[1]));
            let plane = Plane::new(&a.tri(ea.f[0]));
            if face_dot_edge(a, &plane, ea.f[0], &Dir::new(b0, b1), b0, b1) < 0 {
                n = -n;
            }
            let (_, q) = edge_points(a, b, axis);
            (n, q + n * (depth * 0.5))
        }
    }
}

#[cfg(test)]
mod tests;
