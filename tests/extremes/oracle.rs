//! Exact rational-arithmetic reference for one triangle pair, independent of `meshclash`'s
//! predicates: every f64 coordinate is converted exactly to a `BigRational`, the intersection
//! `A ∩ B` of the two closed (possibly zero-area) triangles is computed exactly by clipping the
//! vertices of `A` against the half-spaces that describe `B`, and classified by its affine
//! dimension. Distances of disjoint pairs are exact squared distances (minimum over the
//! vertex–shape and edge–edge candidates, all rational).
//!
//! Only `Contact` (a label) is taken from the library.

use meshclash::geom::DVec3;
use meshclash::narrow::tri_tri::Contact;
use num_rational::BigRational;
use num_traits::{Signed, ToPrimitive, Zero};

pub type Q = BigRational;
pub type P = [Q; 3];

pub fn q(x: f64) -> Q {
    BigRational::from_float(x).expect("finite")
}

pub fn pt(v: DVec3) -> P {
    [q(v.x), q(v.y), q(v.z)]
}

pub fn to_f64(x: &Q) -> f64 {
    x.to_f64().expect("representable")
}

fn sub(a: &P, b: &P) -> P {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn add(a: &P, b: &P) -> P {
    [&a[0] + &b[0], &a[1] + &b[1], &a[2] + &b[2]]
}

fn mul(a: &P, k: &Q) -> P {
    [&a[0] * k, &a[1] * k, &a[2] * k]
}

fn dot(a: &P, b: &P) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

fn cross(a: &P, b: &P) -> P {
    [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
}

fn is_zero(a: &P) -> bool {
    a.iter().all(|c| c.is_zero())
}

fn norm2(a: &P) -> Q {
    dot(a, a)
}

/// Exact `((b - a) × (c - a)) · (d - a)`.
pub fn orient(a: &P, b: &P, c: &P, d: &P) -> Q {
    dot(&cross(&sub(b, a), &sub(c, a)), &sub(d, a))
}

/// A closed triangle as the convex set it is.
#[derive(Clone, Debug)]
pub enum Shape {
    /// Proper triangle with its normal `(b - a) × (c - a)`.
    Tri([P; 3], P),
    Seg(P, P),
    Pt(P),
}

impl Shape {
    pub fn new(t: &[DVec3; 3]) -> Shape {
        let v = t.map(pt);
        let n = cross(&sub(&v[1], &v[0]), &sub(&v[2], &v[0]));
        if !is_zero(&n) {
            return Shape::Tri(v, n);
        }
        if v[0] == v[1] && v[1] == v[2] {
            return Shape::Pt(v[0].clone());
        }
        // Collinear: the farthest pair spans the hull.
        let pairs = [(0, 1), (0, 2), (1, 2)];
        let (i, j) = pairs
            .into_iter()
            .max_by(|&(i, j), &(k, l)| norm2(&sub(&v[i], &v[j])).cmp(&norm2(&sub(&v[k], &v[l]))))
            .unwrap();
        Shape::Seg(v[i].clone(), v[j].clone())
    }

    pub fn verts(&self) -> Vec<P> {
        match self {
            Shape::Tri(v, _) => v.to_vec(),
            Shape::Seg(p, r) => vec![p.clone(), r.clone()],
            Shape::Pt(p) => vec![p.clone()],
        }
    }

    fn edges(&self) -> Vec<(P, P)> {
        match self {
            Shape::Tri(v, _) => (0..3).map(|i| (v[i].clone(), v[(i + 1) % 3].clone())).collect(),
            Shape::Seg(p, r) => vec![(p.clone(), r.clone())],
            Shape::Pt(_) => vec![],
        }
    }

    /// Half-spaces `m · x >= c` whose intersection is the shape.
    fn halfspaces(&self) -> Vec<(P, Q)> {
        let mut h = Vec::new();
        let plane = |m: P, c: Q, h: &mut Vec<(P, Q)>| {
            h.push((m.clone().map(|x| -x), -c.clone()));
            h.push((m, c));
        };
        match self {
            Shape::Tri(v, n) => {
                plane(n.clone(), dot(n, &v[0]), &mut h);
                for i in 0..3 {
                    // n × edge points into the triangle (counter-clockwise about n).
                    let m = cross(n, &sub(&v[(i + 1) % 3], &v[i]));
                    let c = dot(&m, &v[i]);
                    h.push((m, c));
                }
            }
            Shape::Seg(p, r) => {
                let d = sub(r, p);
                let axes: [P; 3] = [0, 1, 2].map(|k| {
                    let mut e: P = [Q::zero(), Q::zero(), Q::zero()];
                    e[k] = Q::from_integer(1.into());
                    e
                });
                let u = axes.iter().map(|e| cross(&d, e)).find(|u| !is_zero(u)).expect("d != 0");
                let w = cross(&d, &u);
                plane(u.clone(), dot(&u, p), &mut h);
                plane(w.clone(), dot(&w, p), &mut h);
                h.push((d.clone(), dot(&d, p)));
                h.push((d.clone().map(|x| -x), -dot(&d, r)));
            }
            Shape::Pt(p) => {
                for k in 0..3 {
                    let mut e: P = [Q::zero(), Q::zero(), Q::zero()];
                    e[k] = Q::from_integer(1.into());
                    plane(e, p[k].clone(), &mut h);
                }
            }
        }
        h
    }

    /// Is `x` (a point of the shape) in its relative interior?
    fn in_relint(&self, x: &P) -> bool {
        match self {
            Shape::Tri(v, n) => (0..3).all(|i| {
                let m = cross(n, &sub(&v[(i + 1) % 3], &v[i]));
                dot(&m, &sub(x, &v[i])).is_positive()
            }),
            Shape::Seg(p, r) => {
                let d = sub(r, p);
                dot(&d, &sub(x, p)).is_positive() && dot(&d, &sub(x, r)).is_negative()
            }
            Shape::Pt(_) => true,
        }
    }
}

/// Sutherland–Hodgman step on a convex polygon (1, 2 or more points) with `m · x >= c`.
fn clip(poly: Vec<P>, m: &P, c: &Q) -> Vec<P> {
    if poly.len() == 1 {
        return if dot(m, &poly[0]) >= *c { poly } else { vec![] };
    }
    let h: Vec<Q> = poly.iter().map(|p| dot(m, p) - c).collect();
    let mut out: Vec<P> = Vec::new();
    for i in 0..poly.len() {
        let j = (i + 1) % poly.len();
        if !h[i].is_negative() {
            out.push(poly[i].clone());
        }
        if (h[i].is_positive() && h[j].is_negative()) || (h[i].is_negative() && h[j].is_positive()) {
            let t = &h[i] / (&h[i] - &h[j]);
            out.push(add(&poly[i], &mul(&sub(&poly[j], &poly[i]), &t)));
        }
    }
    let mut dedup: Vec<P> = Vec::new();
    for p in out {
        if !dedup.contains(&p) {
            dedup.push(p);
        }
    }
    dedup
}

/// The exact classification of a pair that meets (same vocabulary as `tri_tri::Hit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Meet {
    pub crossing: bool,
    pub contact: Contact,
}

/// Affine dimension of a point set (0..=3).
fn affine_dim(pts: &[P]) -> usize {
    let Some(o) = pts.first() else { return 0 };
    let d: Vec<P> = pts.iter().map(|p| sub(p, o)).filter(|v| !is_zero(v)).collect();
    let Some(u) = d.first() else { return 0 };
    let Some(n) = d.iter().map(|v| cross(u, v)).find(|n| !is_zero(n)) else { return 1 };
    if d.iter().any(|v| !dot(&n, v).is_zero()) {
        3
    } else {
        2
    }
}

/// Exact: `None` if the closed triangles share no point.
pub fn classify(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<Meet> {
    classify_shapes(&Shape::new(a), &Shape::new(b))
}

pub fn classify_shapes(sa: &Shape, sb: &Shape) -> Option<Meet> {
    let mut poly = sa.verts();
    for (m, c) in sb.halfspaces() {
        poly = clip(poly, &m, &c);
        if poly.is_empty() {
            return None;
        }
    }
    let dim = affine_dim(&poly);
    let mut all = sa.verts();
    all.extend(sb.verts());
    let span = affine_dim(&all);
    let both_tris = matches!((sa, sb), (Shape::Tri(..), Shape::Tri(..)));
    if both_tris && span == 2 {
        let contact = if dim == 2 { Contact::CoplanarArea } else { Contact::CoplanarBoundary };
        return Some(Meet { crossing: false, contact });
    }
    assert!(dim <= 1, "a non-coplanar intersection of dimension {dim}");
    let contact = if dim == 0 { Contact::Point } else { Contact::Segment };
    // Relative interiors meet iff the centroid of the intersection lies in both (Rockafellar 6.5).
    let n = Q::from_integer((poly.len() as i64).into());
    let centroid = poly.iter().fold([Q::zero(), Q::zero(), Q::zero()], |s, p| add(&s, p)).map(|x| x / &n);
    let crossing = span == 3 && sa.in_relint(&centroid) && sb.in_relint(&centroid);
    Some(Meet { crossing, contact })
}

// ---------------------------------------------------------------------------------------------
// Distances, generic over the number type: exact with `Q`, and in f64 only as a filter that
// decides which pairs need the exact computation (see `dist_f64_slack`).
// ---------------------------------------------------------------------------------------------

pub trait Num:
    Clone
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    fn n0() -> Self;
    fn n1() -> Self;
}

impl Num for f64 {
    fn n0() -> f64 {
        0.0
    }
    fn n1() -> f64 {
        1.0
    }
}

impl Num for Q {
    fn n0() -> Q {
        Zero::zero()
    }
    fn n1() -> Q {
        Q::from_integer(1.into())
    }
}

type V<T> = [T; 3];

fn gsub<T: Num>(a: &V<T>, b: &V<T>) -> V<T> {
    [a[0].clone() - b[0].clone(), a[1].clone() - b[1].clone(), a[2].clone() - b[2].clone()]
}

fn gadd<T: Num>(a: &V<T>, b: &V<T>) -> V<T> {
    [a[0].clone() + b[0].clone(), a[1].clone() + b[1].clone(), a[2].clone() + b[2].clone()]
}

fn gmul<T: Num>(a: &V<T>, k: &T) -> V<T> {
    [a[0].clone() * k.clone(), a[1].clone() * k.clone(), a[2].clone() * k.clone()]
}

fn gdot<T: Num>(a: &V<T>, b: &V<T>) -> T {
    a[0].clone() * b[0].clone() + a[1].clone() * b[1].clone() + a[2].clone() * b[2].clone()
}

fn gcross<T: Num>(a: &V<T>, b: &V<T>) -> V<T> {
    let m = |i: usize, j: usize| a[i].clone() * b[j].clone() - a[j].clone() * b[i].clone();
    [m(1, 2), m(2, 0), m(0, 1)]
}

fn gmin<T: Num>(a: T, b: T) -> T {
    if b < a {
        b
    } else {
        a
    }
}

/// A shape for distances: its vertices (1, 2 or 3, the triangle proper).
#[derive(Clone, Debug)]
pub struct DShape<T> {
    pub v: Vec<V<T>>,
    /// f64 only: false for slivers whose f64 normal may be inaccurate (never filtered).
    pub ok: bool,
}

impl DShape<f64> {
    pub fn f64(s: &Shape) -> DShape<f64> {
        let v: Vec<V<f64>> = s.verts().iter().map(|p| p.clone().map(|x| to_f64(&x))).collect();
        let ok = v.len() < 3 || {
            let (e1, e2) = (gsub(&v[1], &v[0]), gsub(&v[2], &v[0]));
            let n = gcross(&e1, &e2);
            gdot(&n, &n).sqrt() > 1e-6 * gdot(&e1, &e1).sqrt() * gdot(&e2, &e2).sqrt()
        };
        DShape { v, ok }
    }
}

impl DShape<Q> {
    pub fn exact(s: &Shape) -> DShape<Q> {
        DShape { v: s.verts(), ok: true }
    }
}

fn d2_point_seg<T: Num>(x: &V<T>, p: &V<T>, r: &V<T>) -> T {
    let d = gsub(r, p);
    let dd = gdot(&d, &d);
    let xp = gsub(x, p);
    if dd == T::n0() {
        return gdot(&xp, &xp);
    }
    let mut t = gdot(&d, &xp) / dd;
    if t < T::n0() {
        t = T::n0();
    }
    if t > T::n1() {
        t = T::n1();
    }
    let e = gsub(x, &gadd(p, &gmul(&d, &t)));
    gdot(&e, &e)
}

fn d2_seg_seg<T: Num>(p1: &V<T>, q1: &V<T>, p2: &V<T>, q2: &V<T>) -> T {
    let (d1, d2, r) = (gsub(q1, p1), gsub(q2, p2), gsub(p1, p2));
    let (a, e, b) = (gdot(&d1, &d1), gdot(&d2, &d2), gdot(&d1, &d2));
    let (c, f) = (gdot(&d1, &r), gdot(&d2, &r));
    let denom = a.clone() * e.clone() - b.clone() * b.clone();
    let mut best = gmin(
        gmin(d2_point_seg(p1, p2, q2), d2_point_seg(q1, p2, q2)),
        gmin(d2_point_seg(p2, p1, q1), d2_point_seg(q2, p1, q1)),
    );
    if denom > T::n0() {
        let s = (b.clone() * f.clone() - c.clone() * e) / denom.clone();
        let t = (a * f - b * c) / denom;
        let unit = |x: &T| *x >= T::n0() && *x <= T::n1();
        if unit(&s) && unit(&t) {
            let w = gsub(&gadd(p1, &gmul(&d1, &s)), &gadd(p2, &gmul(&d2, &t)));
            best = gmin(best, gdot(&w, &w));
        }
    }
    best
}

fn d2_point_shape<T: Num>(x: &V<T>, s: &DShape<T>) -> T {
    match s.v.len() {
        1 => {
            let e = gsub(x, &s.v[0]);
            gdot(&e, &e)
        }
        2 => d2_point_seg(x, &s.v[0], &s.v[1]),
        _ => {
            let v = &s.v;
            let n = gcross(&gsub(&v[1], &v[0]), &gsub(&v[2], &v[0]));
            let inside = (0..3).all(|i| {
                let m = gcross(&n, &gsub(&v[(i + 1) % 3], &v[i]));
                gdot(&m, &gsub(x, &v[i])) >= T::n0()
            });
            if inside {
                let h = gdot(&n, &gsub(x, &v[0]));
                h.clone() * h / gdot(&n, &n)
            } else {
                let e = |i: usize| d2_point_seg(x, &v[i], &v[(i + 1) % 3]);
                gmin(gmin(e(0), e(1)), e(2))
            }
        }
    }
}

fn dedges<T: Num>(s: &DShape<T>) -> Vec<(V<T>, V<T>)> {
    match s.v.len() {
        1 => vec![],
        2 => vec![(s.v[0].clone(), s.v[1].clone())],
        _ => (0..3).map(|i| (s.v[i].clone(), s.v[(i + 1) % 3].clone())).collect(),
    }
}

/// Does segment `[p, r]` meet the proper triangle `v` at a point strictly between the planes'
/// sides (a piercing, which the vertex and edge–edge candidates do not see)?
fn pierces<T: Num>(p: &V<T>, r: &V<T>, v: &[V<T>]) -> bool {
    let n = gcross(&gsub(&v[1], &v[0]), &gsub(&v[2], &v[0]));
    let (hp, hr) = (gdot(&n, &gsub(p, &v[0])), gdot(&n, &gsub(r, &v[0])));
    let z = T::n0();
    if !((hp < z && hr > z) || (hp > z && hr < z)) {
        return false;
    }
    let t = hp.clone() / (hp - hr);
    let x = gadd(p, &gmul(&gsub(r, p), &t));
    (0..3).all(|i| gdot(&gcross(&n, &gsub(&v[(i + 1) % 3], &v[i])), &gsub(&x, &v[i])) >= T::n0())
}

/// Squared distance of two shapes (exact with `Q`; 0 when they meet).
pub fn dist2<T: Num>(sa: &DShape<T>, sb: &DShape<T>) -> T {
    for (s, t) in [(sa, sb), (sb, sa)] {
        if t.v.len() == 3 && dedges(s).iter().any(|(p, r)| pierces(p, r, &t.v)) {
            return T::n0();
        }
    }
    let mut best: Option<T> = None;
    let mut take = |d: T| {
        if best.as_ref().is_none_or(|b| d < *b) {
            best = Some(d);
        }
    };
    for x in &sa.v {
        take(d2_point_shape(x, sb));
    }
    for x in &sb.v {
        take(d2_point_shape(x, sa));
    }
    for (p, r) in dedges(sa) {
        for (s, t) in dedges(sb) {
            take(d2_seg_seg(&p, &r, &s, &t));
        }
    }
    best.unwrap()
}

/// Exact squared distance of two shapes known to be disjoint.
pub fn dist2_shapes(sa: &Shape, sb: &Shape) -> Q {
    dist2(&DShape::exact(sa), &DShape::exact(sb))
}

/// A bound on the error of the f64 distance (same formulas) for coordinates up to `scale` in
/// magnitude: generous (1e-10 of the scale, about 4.5e5 ulps), since it only decides which
/// pairs are computed exactly; anything within it of a decision is computed exactly.
pub fn dist_f64_slack(scale: f64) -> f64 {
    1e-10 * scale
}

/// Are the two closed triangles in one plane and both proper (exact)?
pub fn coplanar(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    let (pa, pb) = (a.map(pt), b.map(pt));
    let n = cross(&sub(&pa[1], &pa[0]), &sub(&pa[2], &pa[0]));
    !is_zero(&n) && pb.iter().all(|p| dot(&n, &sub(p, &pa[0])).is_zero()) && {
        let m = cross(&sub(&pb[1], &pb[0]), &sub(&pb[2], &pb[0]));
        !is_zero(&m)
    }
}

/// Exact parity of the crossings of the ray `p + t·d` (`t > 0`) with the proper triangles of
/// `tris`; `None` when the ray meets an edge or a vertex, starts on a triangle, or lies in a
/// triangle's plane (try another direction).
pub fn ray_parity(p: &P, d: &P, tris: &[[DVec3; 3]]) -> Option<bool> {
    let mut odd = false;
    for t in tris {
        let Shape::Tri(v, n) = Shape::new(t) else { continue };
        let s0 = dot(&n, &sub(p, &v[0]));
        let nd = dot(&n, d);
        if nd.is_zero() {
            if s0.is_zero() {
                return None;
            }
            continue;
        }
        let t = -s0 / nd;
        if t.is_negative() {
            continue;
        }
        let x = add(p, &mul(d, &t));
        let e: Vec<Q> =
            (0..3).map(|i| dot(&cross(&n, &sub(&v[(i + 1) % 3], &v[i])), &sub(&x, &v[i]))).collect();
        if e.iter().any(|s| s.is_negative()) {
            continue;
        }
        if t.is_zero() || e.iter().any(|s| s.is_zero()) {
            return None;
        }
        odd = !odd;
    }
    Some(odd)
}

/// Is the exact centroid of `t` strictly inside the closed surface `tris`? (False when it lies
/// on the surface: every ray from a point on a triangle is refused by [`ray_parity`].)
pub fn centroid_strictly_inside(t: &[DVec3; 3], tris: &[[DVec3; 3]]) -> bool {
    let third = Q::new(1.into(), 3.into());
    let c = mul(&add(&add(&pt(t[0]), &pt(t[1])), &pt(t[2])), &third);
    let dirs = [[1.0, 0.3719, 0.1234], [-0.4321, 1.0, 0.2718], [0.1414, -0.5772, -1.0], [0.7, 0.6, 0.5]];
    dirs.iter().filter_map(|d| ray_parity(&c, &[q(d[0]), q(d[1]), q(d[2])], tris)).next().unwrap_or(false)
}

/// Is `p` (not on the surface) inside the closed surface `tris` (odd crossing parity)?
pub fn inside(p: DVec3, tris: &[[DVec3; 3]]) -> bool {
    let dirs = [[1.0, 0.3719, 0.1234], [-0.4321, 1.0, 0.2718], [0.1414, -0.5772, -1.0], [0.7, 0.6, 0.5]];
    dirs.iter()
        .find_map(|d| ray_parity(&pt(p), &[q(d[0]), q(d[1]), q(d[2])], tris))
        .expect("some direction is generic")
}

/// Every edge (by positions) of the proper triangles is used exactly twice.
pub fn closed(tris: &[[DVec3; 3]]) -> bool {
    let key = |p: DVec3| [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
    let mut uses: std::collections::HashMap<([u64; 3], [u64; 3]), u32> = Default::default();
    for t in tris {
        if !matches!(Shape::new(t), Shape::Tri(..)) {
            continue;
        }
        for i in 0..3 {
            let (a, b) = (key(t[i]), key(t[(i + 1) % 3]));
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    !uses.is_empty() && uses.values().all(|&n| n == 2)
}
