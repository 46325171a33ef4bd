//! Independent exact oracle for `meshclash::narrow::tri_tri::classify`.
//!
//! The f64 coordinates of both triangles are converted exactly to integers (all f64 are dyadic
//! rationals: multiply by one common power of two, which changes no verdict), and the
//! intersection set `I = A ∩ B` of the two closed (possibly degenerate) triangles is computed
//! exactly, by Sutherland–Hodgman clipping of one shape against the half-spaces of the other (a
//! proper triangle is the slab `n·x >= d`, `n·x <= d` of width zero intersected with its three
//! side half-spaces), or by direct integer linear algebra for segment/point pairs. Clipped
//! points are kept in homogeneous integer coordinates `(X, W)`, `W > 0` (no gcd reductions, which
//! dominate the cost of `BigRational`). `I` is then classified: empty, a point, a segment or an
//! area; crossing iff the shapes are not coplanar and some point of `I` lies in both relative
//! interiors (tested at the midpoint of `I`).
//!
//! Nothing from `meshclash` is used by the oracle; only `classify` and its result types are
//! imported, to be compared with it.
#![allow(clippy::type_complexity, clippy::large_enum_variant, clippy::field_reassign_with_default)]
#![allow(clippy::doc_lazy_continuation)] // test helpers: tuple rows and long case docs read better as they are

use meshclash::geom::DVec3;
use meshclash::narrow::tri_tri::{classify, Contact, Hit};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use std::time::Instant;

// ---------------------------------------------------------------------------------------------
// Exact integer geometry (homogeneous coordinates)
// ---------------------------------------------------------------------------------------------

type Z = BigInt;
/// An integer vector.
type V = [Z; 3];

fn vsub(a: &V, b: &V) -> V {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn vadd(a: &V, b: &V) -> V {
    [&a[0] + &b[0], &a[1] + &b[1], &a[2] + &b[2]]
}

fn vmul(a: &V, k: &Z) -> V {
    [&a[0] * k, &a[1] * k, &a[2] * k]
}

fn vneg(a: &V) -> V {
    [-&a[0], -&a[1], -&a[2]]
}

fn vdot(a: &V, b: &V) -> Z {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

fn vcross(a: &V, b: &V) -> V {
    [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
}

fn vzero(a: &V) -> bool {
    a.iter().all(|c| c.is_zero())
}

/// The point `x / w`, `w > 0`.
#[derive(Clone, Debug)]
struct H {
    x: V,
    w: Z,
}

fn hom(v: &V) -> H {
    H { x: v.clone(), w: Z::one() }
}

fn heq(a: &H, b: &H) -> bool {
    (0..3).all(|k| &a.x[k] * &b.w == &b.x[k] * &a.w)
}

/// A positive multiple of `a - b` (namely `a.w·b.w·(a - b)`).
fn hdiff(a: &H, b: &H) -> V {
    vsub(&vmul(&a.x, &b.w), &vmul(&b.x, &a.w))
}

fn hmid(a: &H, b: &H) -> H {
    H { x: vadd(&vmul(&a.x, &b.w), &vmul(&b.x, &a.w)), w: &a.w * &b.w * Z::from(2) }
}

/// The two triangles with integer coordinates (common power-of-two scale `s`: real = int / s).
struct Scaled {
    a: [V; 3],
    b: [V; 3],
    s: Z,
}

fn scaled(a: &[DVec3; 3], b: &[DVec3; 3]) -> Scaled {
    let rats: Vec<BigRational> = a
        .iter()
        .chain(b.iter())
        .flat_map(|p| [p.x, p.y, p.z])
        .map(|c| BigRational::from_float(c).expect("finite coordinate"))
        .collect();
    // Denominators are powers of two: the largest is a multiple of all.
    let s = rats.iter().map(|r| r.denom().clone()).max().unwrap();
    let ints: Vec<Z> = rats.iter().map(|r| r.numer() * (&s / r.denom())).collect();
    let pt = |i: usize| [ints[3 * i].clone(), ints[3 * i + 1].clone(), ints[3 * i + 2].clone()];
    Scaled { a: [pt(0), pt(1), pt(2)], b: [pt(3), pt(4), pt(5)], s }
}

fn h_to_f64(p: &H, s: &Z) -> DVec3 {
    let f = |c: &Z| BigRational::new(c.clone(), &p.w * s).to_f64().expect("representable");
    DVec3::new(f(&p.x[0]), f(&p.x[1]), f(&p.x[2]))
}

/// The exact shape of a triangle.
#[derive(Clone, Debug)]
enum Shape {
    Pt(V),
    Seg(V, V),
    Tri([V; 3]),
}

fn normal(t: &[V; 3]) -> V {
    vcross(&vsub(&t[1], &t[0]), &vsub(&t[2], &t[0]))
}

fn shape_of(t: &[V; 3]) -> Shape {
    if !vzero(&normal(t)) {
        return Shape::Tri(t.clone());
    }
    if t[0] == t[1] && t[1] == t[2] {
        return Shape::Pt(t[0].clone());
    }
    // Collinear: the pair furthest apart.
    let len2 = |i: usize, j: usize| {
        let d = vsub(&t[i], &t[j]);
        vdot(&d, &d)
    };
    let (i, j) =
        [(0, 1), (1, 2), (0, 2)].into_iter().max_by(|&(i, j), &(k, l)| len2(i, j).cmp(&len2(k, l))).unwrap();
    Shape::Seg(t[i].clone(), t[j].clone())
}

/// Half-space `w · x >= d`.
struct Half {
    w: V,
    d: Z,
}

/// The closed proper triangle as an intersection of five half-spaces: the two bounding its
/// plane and the three side half-spaces (plane through an edge containing the normal, oriented
/// towards the third vertex).
fn halfspaces(t: &[V; 3]) -> Vec<Half> {
    let n = normal(t);
    let d = vdot(&n, &t[0]);
    let mut hs = vec![Half { w: vneg(&n), d: -d.clone() }, Half { w: n.clone(), d }];
    for i in 0..3 {
        let (p0, p1, p2) = (&t[i], &t[(i + 1) % 3], &t[(i + 2) % 3]);
        let mut m = vcross(&n, &vsub(p1, p0));
        if vdot(&m, &vsub(p2, p0)).is_negative() {
            m = vneg(&m);
        }
        assert!(vdot(&m, &vsub(p2, p0)).is_positive());
        let d = vdot(&m, p0);
        hs.push(Half { w: m, d });
    }
    hs
}

/// Sutherland–Hodgman clipping of the convex hull of a cyclic point list (a polygon, a segment
/// as a 2-cycle, or a point) by one half-space.
fn clip(pts: &[H], h: &Half) -> Vec<H> {
    let n = pts.len();
    // Sign-correct values (times w > 0).
    let vals: Vec<Z> = pts.iter().map(|p| vdot(&h.w, &p.x) - &h.d * &p.w).collect();
    let mut out: Vec<H> = Vec::new();
    let push = |p: H, out: &mut Vec<H>| {
        if out.last().is_none_or(|l| !heq(l, &p)) {
            out.push(p);
        }
    };
    for i in 0..n {
        let j = (i + 1) % n;
        let (vc, vn) = (&vals[i], &vals[j]);
        if !vc.is_negative() {
            push(pts[i].clone(), &mut out);
        }
        if (vc.is_positive() && vn.is_negative()) || (vc.is_negative() && vn.is_positive()) {
            // The zero of the (affine) value on the edge: (vc·Xn − vn·Xc) / (vc·Wn − vn·Wc).
            let (c, nx) = (&pts[i], &pts[j]);
            let mut x = vsub(&vmul(&nx.x, vc), &vmul(&c.x, vn));
            let mut w = vc * &nx.w - vn * &c.w;
            if w.is_negative() {
                x = vneg(&x);
                w = -w;
            }
            push(H { x, w }, &mut out);
        }
    }
    while out.len() > 1 && heq(&out[0], out.last().unwrap()) {
        out.pop();
    }
    out
}

/// Exact intersection set, by its shape.
#[derive(Clone, Debug)]
enum Set {
    Empty,
    Point(H),
    Seg(H, H),
    Area,
}

fn set_of(pts: Vec<H>) -> Set {
    let mut u: Vec<H> = Vec::new();
    for p in pts {
        if !u.iter().any(|q| heq(q, &p)) {
            u.push(p);
        }
    }
    match u.len() {
        0 => return Set::Empty,
        1 => return Set::Point(u.pop().unwrap()),
        _ => {}
    }
    let d1 = hdiff(&u[1], &u[0]);
    let dk: Vec<V> = u.iter().map(|p| hdiff(p, &u[0])).collect();
    if dk.iter().any(|d| !vzero(&vcross(&d1, d))) {
        return Set::Area;
    }
    // Collinear: the parameter of p_k along d1 is proportional to (d1·dk) / w_k.
    let num: Vec<Z> = dk.iter().map(|d| vdot(&d1, d)).collect();
    let cmp = |i: &usize, j: &usize| (&num[*i] * &u[*j].w).cmp(&(&num[*j] * &u[*i].w));
    let lo = (0..u.len()).min_by(cmp).unwrap();
    let hi = (0..u.len()).max_by(cmp).unwrap();
    Set::Seg(u[lo].clone(), u[hi].clone())
}

fn clip_by_tri(pts: Vec<H>, t: &[V; 3]) -> Set {
    let mut cur = pts;
    for h in halfspaces(t) {
        cur = clip(&cur, &h);
        if cur.is_empty() {
            return Set::Empty;
        }
    }
    set_of(cur)
}

/// Is `x` (in the plane of proper `t`) strictly inside `t`?
fn strictly_in_tri(x: &H, t: &[V; 3]) -> bool {
    let n = normal(t);
    (0..3).all(|i| {
        let e = vsub(&t[(i + 1) % 3], &t[i]);
        let rel = vsub(&x.x, &vmul(&t[i], &x.w));
        vdot(&vcross(&e, &rel), &n).is_positive()
    })
}

/// `p + d · (num / den)`, `den > 0`, as a homogeneous point.
fn along(p: &V, d: &V, num: &Z, den: &Z) -> H {
    H { x: vadd(&vmul(p, den), &vmul(d, num)), w: den.clone() }
}

fn seg_seg(p: &V, q: &V, r: &V, s: &V) -> Set {
    let d1 = vsub(q, p);
    let d2 = vsub(s, r);
    let rp = vsub(r, p);
    // Coplanarity of the four points.
    if !vdot(&d1, &vcross(&rp, &vsub(s, p))).is_zero() {
        return Set::Empty;
    }
    let dd = vdot(&d1, &d1);
    if vzero(&vcross(&d1, &rp)) && vzero(&vcross(&d1, &vsub(s, p))) {
        // Collinear: parameters along p→q, all with the denominator dd (p ↦ 0, q ↦ dd).
        let (tr, ts) = (vdot(&rp, &d1), vdot(&vsub(s, p), &d1));
        let (a, b) = if tr <= ts { (tr, ts) } else { (ts, tr) };
        let lo = a.max(Z::zero());
        let hi = b.min(dd.clone());
        return match lo.cmp(&hi) {
            std::cmp::Ordering::Greater => Set::Empty,
            std::cmp::Ordering::Equal => Set::Point(along(p, &d1, &lo, &dd)),
            std::cmp::Ordering::Less => Set::Seg(along(p, &d1, &lo, &dd), along(p, &d1, &hi, &dd)),
        };
    }
    let n = vcross(&d1, &d2);
    if vzero(&n) {
        return Set::Empty; // parallel distinct lines
    }
    // p + t·d1 = r + u·d2 with t = ((r−p)×d2)·n / n·n and u = ((r−p)×d1)·n / n·n.
    let nn = vdot(&n, &n);
    let t = vdot(&vcross(&rp, &d2), &n);
    let u = vdot(&vcross(&rp, &d1), &n);
    let inside = |v: &Z| !v.is_negative() && *v <= nn;
    if inside(&t) && inside(&u) {
        let x = along(p, &d1, &t, &nn);
        debug_assert!(heq(&x, &along(r, &d2, &u, &nn)));
        Set::Point(x)
    } else {
        Set::Empty
    }
}

/// The oracle's answer.
#[derive(Clone, Debug)]
struct Oracle {
    verdict: Option<(bool, Contact)>,
    /// For non-coplanar contacts: the extremes of the shared set (exact, rounded to f64).
    ends: Option<(DVec3, DVec3)>,
}

fn oracle(a: &[DVec3; 3], b: &[DVec3; 3]) -> Oracle {
    let Scaled { a, b, s } = scaled(a, b);
    let (sa, sb) = (shape_of(&a), shape_of(&b));
    let none = Oracle { verdict: None, ends: None };
    let from_set = |set: Set, crossing_test: &dyn Fn(&H) -> bool| -> Oracle {
        match set {
            Set::Empty => Oracle { verdict: None, ends: None },
            Set::Point(x) => {
                let e = h_to_f64(&x, &s);
                Oracle { verdict: Some((crossing_test(&x), Contact::Point)), ends: Some((e, e)) }
            }
            Set::Seg(x, y) => {
                let m = hmid(&x, &y);
                Oracle {
                    verdict: Some((crossing_test(&m), Contact::Segment)),
                    ends: Some((h_to_f64(&x, &s), h_to_f64(&y, &s))),
                }
            }
            Set::Area => panic!("oracle: an area shared by non-coplanar shapes"),
        }
    };
    match (&sa, &sb) {
        (Shape::Tri(ta), Shape::Tri(tb)) => {
            let na = normal(ta);
            let coplanar = tb.iter().all(|p| vdot(&na, &vsub(p, &ta[0])).is_zero());
            let set = clip_by_tri(ta.iter().map(hom).collect(), tb);
            if coplanar {
                let c = match set {
                    Set::Empty => return none,
                    Set::Area => Contact::CoplanarArea,
                    _ => Contact::CoplanarBoundary,
                };
                Oracle { verdict: Some((false, c)), ends: None }
            } else {
                from_set(set, &|x| strictly_in_tri(x, ta) && strictly_in_tri(x, tb))
            }
        }
        (Shape::Tri(t), Shape::Seg(p, r)) | (Shape::Seg(p, r), Shape::Tri(t)) => {
            let n = normal(t);
            let in_plane = vdot(&n, &vsub(p, &t[0])).is_zero() && vdot(&n, &vsub(r, &t[0])).is_zero();
            let set = clip_by_tri(vec![hom(p), hom(r)], t);
            if in_plane {
                // Touching only; a point or a segment (never an area).
                from_set(set, &|_| false)
            } else {
                // At most one point, crossing iff strictly inside both the open segment and t.
                from_set(set, &|x| !heq(x, &hom(p)) && !heq(x, &hom(r)) && strictly_in_tri(x, t))
            }
        }
        (Shape::Tri(t), Shape::Pt(p)) | (Shape::Pt(p), Shape::Tri(t)) => {
            from_set(clip_by_tri(vec![hom(p)], t), &|_| false)
        }
        (Shape::Seg(p, r), Shape::Seg(x, y)) => from_set(seg_seg(p, r, x, y), &|_| false),
        (Shape::Seg(p, r), Shape::Pt(x)) | (Shape::Pt(x), Shape::Seg(p, r)) => {
            let d = vsub(r, p);
            let w = vsub(x, p);
            let t = vdot(&w, &d);
            if vzero(&vcross(&d, &w)) && !t.is_negative() && t <= vdot(&d, &d) {
                from_set(Set::Point(hom(x)), &|_| false)
            } else {
                none
            }
        }
        (Shape::Pt(x), Shape::Pt(y)) => {
            if x == y {
                from_set(Set::Point(hom(x)), &|_| false)
            } else {
                none
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Exact distance (rationals), only for judging reported segment ends that look off
// ---------------------------------------------------------------------------------------------

type Q = BigRational;

#[derive(Clone, Debug, PartialEq, Eq)]
struct P([Q; 3]);

fn rp(v: DVec3) -> P {
    let q = |x: f64| Q::from_float(x).expect("finite coordinate");
    P([q(v.x), q(v.y), q(v.z)])
}

fn sub(a: &P, b: &P) -> P {
    P([&a.0[0] - &b.0[0], &a.0[1] - &b.0[1], &a.0[2] - &b.0[2]])
}

fn scale(a: &P, t: &Q) -> P {
    P([&a.0[0] * t, &a.0[1] * t, &a.0[2] * t])
}

fn dot(a: &P, b: &P) -> Q {
    &a.0[0] * &b.0[0] + &a.0[1] * &b.0[1] + &a.0[2] * &b.0[2]
}

fn cross(a: &P, b: &P) -> P {
    P([
        &a.0[1] * &b.0[2] - &a.0[2] * &b.0[1],
        &a.0[2] * &b.0[0] - &a.0[0] * &b.0[2],
        &a.0[0] * &b.0[1] - &a.0[1] * &b.0[0],
    ])
}

// ---------------------------------------------------------------------------------------------
// Deterministic RNG (splitmix64)
// ---------------------------------------------------------------------------------------------

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform integer in `lo..=hi`.
    fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % ((hi - lo + 1) as u64)) as i64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn chance(&mut self, num: u64, den: u64) -> bool {
        self.next() % den < num
    }
    /// Uniform f64 in [-1, 1).
    fn unit(&mut self) -> f64 {
        ((self.next() >> 11) as f64) * (1.0 / (1u64 << 52) as f64) - 1.0
    }
    /// A point on the grid of step `1/den` with coordinates in [-r, r].
    fn grid(&mut self, r: i64, den: i64) -> DVec3 {
        let mut c = || self.int(-r * den, r * den) as f64 / den as f64;
        DVec3::new(c(), c(), c())
    }
}

// ---------------------------------------------------------------------------------------------
// Comparison harness
// ---------------------------------------------------------------------------------------------

fn hex_tri(t: &[DVec3; 3]) -> String {
    let v: Vec<String> = t
        .iter()
        .map(|p| {
            format!(
                "[f64::from_bits({:#018x}), f64::from_bits({:#018x}), f64::from_bits({:#018x})]",
                p.x.to_bits(),
                p.y.to_bits(),
                p.z.to_bits()
            )
        })
        .collect();
    format!("[{}]", v.join(", "))
}

fn dec_tri(t: &[DVec3; 3]) -> String {
    format!(
        "[[{:?}, {:?}, {:?}], [{:?}, {:?}, {:?}], [{:?}, {:?}, {:?}]]",
        t[0].x, t[0].y, t[0].z, t[1].x, t[1].y, t[1].z, t[2].x, t[2].y, t[2].z
    )
}

fn verdict(h: &Option<Hit>) -> Option<(bool, Contact)> {
    h.as_ref().map(|h| (h.crossing, h.contact))
}

const PERMS: [[usize; 3]; 6] = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [0, 2, 1], [2, 1, 0], [1, 0, 2]];

/// An exact similarity applied to a case: `x ↦ s·x + o`.
struct Xform {
    s: f64,
    o: DVec3,
}

fn xforms() -> Vec<Xform> {
    let p20 = 2f64.powi(20);
    let p40 = 2f64.powi(40);
    vec![
        Xform { s: 2f64.powi(-20), o: DVec3::ZERO },
        Xform { s: p20, o: DVec3::ZERO },
        Xform { s: 1.0, o: DVec3::new(p20, -p20, p20) },
        Xform { s: 2f64.powi(-20), o: DVec3::new(p20, p20, -p20) },
        Xform { s: p20, o: DVec3::new(-p40, p40, 2.0 * p40) },
        // Far from 1 but inside the documented range of the predicates (no underflow/overflow).
        Xform { s: 2f64.powi(-300), o: DVec3::ZERO },
        Xform { s: 2f64.powi(300), o: DVec3::ZERO },
    ]
}

/// Apply the transform if it is exact for every coordinate (scaling by a power of two is exact
/// unless it leaves the normal range; the sum is exact iff Knuth's TwoSum error is zero).
fn apply(x: &Xform, t: &[DVec3; 3]) -> Option<[DVec3; 3]> {
    let ok = |v: f64| v == 0.0 || v.is_normal();
    let mut out = *t;
    for (p, r) in t.iter().zip(out.iter_mut()) {
        for k in 0..3 {
            let y = p[k] * x.s;
            if !ok(y) || y / x.s != p[k] {
                return None;
            }
            let o = x.o[k];
            let sum = y + o;
            let bp = sum - y;
            let err = (y - (sum - bp)) + (o - bp);
            if err != 0.0 || !ok(sum) {
                return None;
            }
            r[k] = sum;
        }
    }
    Some(out)
}

#[derive(Default)]
struct Stats {
    name: &'static str,
    cases: usize,
    classify_calls: usize,
    xform_variants: usize,
    xform_skipped: usize,
    mismatches: usize,
    reports: Vec<String>,
    seg_checked: usize,
    seg_bad: usize,
    seg_worst: f64,
    seg_worst_strict: f64,
    seg_strict_off: usize,
    seg_reports: Vec<String>,
    seg_bad_reports: Vec<String>,
    histogram: std::collections::BTreeMap<String, usize>,
}

impl Stats {
    fn new(name: &'static str) -> Stats {
        Stats { name, ..Default::default() }
    }

    fn mismatch(
        &mut self,
        what: &str,
        a: &[DVec3; 3],
        b: &[DVec3; 3],
        want: Option<(bool, Contact)>,
        got: Option<(bool, Contact)>,
    ) {
        self.mismatches += 1;
        if self.reports.len() < 12 {
            self.reports.push(format!(
                "[{}] {what}\n  a = {}\n  b = {}\n  a (hex) = {}\n  b (hex) = {}\n  oracle   = {want:?}\n  classify = {got:?}",
                self.name,
                dec_tri(a),
                dec_tri(b),
                hex_tri(a),
                hex_tri(b)
            ));
        }
    }

    fn finish(self, t0: Instant) {
        eprintln!(
            "[{}] {} cases, {} classify calls, {} exact transformed variants ({} inexact skipped), \
             {} verdict mismatches, segment reports checked {} (off the triangles: {}, worst {:.3e}·scale; \
             off the exact ends: {}, worst {:.3e}·scale), {:.2?}",
            self.name,
            self.cases,
            self.classify_calls,
            self.xform_variants,
            self.xform_skipped,
            self.mismatches,
            self.seg_checked,
            self.seg_bad,
            self.seg_worst,
            self.seg_strict_off,
            self.seg_worst_strict,
            t0.elapsed()
        );
        eprintln!("[{}] oracle verdicts: {:?}", self.name, self.histogram);
        for r in self.seg_bad_reports.iter().chain(&self.seg_reports) {
            eprintln!("{r}");
        }
        for r in &self.reports {
            eprintln!("{r}");
        }
        assert_eq!(self.mismatches, 0, "[{}] classify disagrees with the exact oracle", self.name);
        assert_eq!(
            self.seg_bad, 0,
            "[{}] reported segment end farther than 1e-9·scale from a triangle",
            self.name
        );
    }
}

/// Check the f64 report of the shared set: each reported end must lie within 1e-9·scale of both
/// closed triangles (asserted); how far the ends are from the exact extremes of the shared set
/// is only counted. `scale` is the largest coordinate magnitude of the pair.
fn check_segment(st: &mut Stats, a: &[DVec3; 3], b: &[DVec3; 3], h: &Hit, o: &Oracle) {
    let (Some(seg), Some((e0, e1))) = (h.segment, &o.ends) else {
        return;
    };
    let scale = a.iter().chain(b.iter()).map(|p| p.abs().max_element()).fold(0.0, f64::max);
    let scale = scale.max(f64::MIN_POSITIVE);
    // Strict (statistics only): the reported ends are the exact extremes of the shared set.
    let (e0, e1) = (*e0, *e1);
    let strict = if h.contact == Contact::Point {
        seg.iter().map(|&x| (x - e0).length()).fold(0.0, f64::max)
    } else {
        ((seg[0] - e0).length().max((seg[1] - e1).length()))
            .min((seg[0] - e1).length().max((seg[1] - e0).length()))
    } / scale;
    // Loose (asserted): each reported end lies within 1e-9·scale of both closed triangles. The
    // exact ends lie in both, so this is only computed (exactly) when the strict check fails.
    let loose = if strict <= 1e-9 {
        strict
    } else {
        seg.iter().map(|&x| dist_point_tri(x, a).max(dist_point_tri(x, b))).fold(0.0, f64::max) / scale
    };
    st.seg_checked += 1;
    st.seg_worst = st.seg_worst.max(loose);
    st.seg_worst_strict = st.seg_worst_strict.max(strict);
    if strict > 1e-9 {
        st.seg_strict_off += 1;
        let text = format!(
            "[{}] segment report: distance to the triangles {loose:.3e}·scale, to the exact ends {strict:.3e}·scale\n  a = {}\n  b = {}\n  reported = {seg:?}\n  exact = {e0:?} .. {e1:?}",
            st.name,
            hex_tri(a),
            hex_tri(b)
        );
        if loose > 1e-9 {
            st.seg_bad += 1;
            if st.seg_bad_reports.len() < 6 {
                st.seg_bad_reports.push(text);
            }
        } else if st.seg_reports.len() < 2 {
            st.seg_reports.push(text);
        }
    }
}

/// Exact squared distance from `x` to the closed segment `[p, q]` (`p == q` allowed).
fn dist2_point_seg(x: &P, p: &P, q: &P) -> Q {
    let d = sub(q, p);
    let dd = dot(&d, &d);
    let w = sub(x, p);
    if dd.is_zero() {
        return dot(&w, &w);
    }
    let t = dot(&w, &d) / &dd;
    let t = if t.is_negative() {
        Q::zero()
    } else if t > Q::one() {
        Q::one()
    } else {
        t
    };
    let r = sub(&w, &scale(&d, &t));
    dot(&r, &r)
}

/// Distance from the f64 point `x` to the closed triangle `t` (possibly zero-area), computed
/// exactly and rounded.
fn dist_point_tri(x: DVec3, t: &[DVec3; 3]) -> f64 {
    let x = rp(x);
    let t = t.map(rp);
    let mut best = (0..3).map(|i| dist2_point_seg(&x, &t[i], &t[(i + 1) % 3])).min().unwrap();
    let n = cross(&sub(&t[1], &t[0]), &sub(&t[2], &t[0]));
    if !n.0.iter().all(|c| c.is_zero()) {
        let inside = (0..3).all(|i| {
            let e = sub(&t[(i + 1) % 3], &t[i]);
            !dot(&cross(&e, &sub(&x, &t[i])), &n).is_negative()
        });
        if inside {
            let h = dot(&n, &sub(&x, &t[0]));
            best = &h * &h / dot(&n, &n);
        }
    }
    best.to_f64().unwrap().sqrt()
}

/// Compare classify with the oracle on one case, both ways round, under random vertex
/// permutations, and (if `transform`) under the exact similarity transforms.
fn check_case(st: &mut Stats, rng: &mut Rng, a: [DVec3; 3], b: [DVec3; 3], transform: bool) {
    st.cases += 1;
    let o = oracle(&a, &b);
    let key = match o.verdict {
        None => "none".to_string(),
        Some((c, k)) => format!("{}{:?}", if c { "cross-" } else { "" }, k),
    };
    *st.histogram.entry(key).or_default() += 1;
    let want = o.verdict;

    let h = classify(&a, &b);
    st.classify_calls += 1;
    if verdict(&h) != want {
        st.mismatch("classify(a, b)", &a, &b, want, verdict(&h));
        return;
    }
    if let Some(h) = &h {
        check_segment(st, &a, &b, h, &o);
    }
    let hs = classify(&b, &a);
    st.classify_calls += 1;
    if verdict(&hs) != want {
        st.mismatch("classify(b, a) (symmetry)", &a, &b, want, verdict(&hs));
        return;
    }
    for _ in 0..2 {
        let pa = PERMS[rng.below(6)].map(|i| a[i]);
        let pb = PERMS[rng.below(6)].map(|i| b[i]);
        let (x, y) = if rng.chance(1, 2) { (pa, pb) } else { (pb, pa) };
        let hp = classify(&x, &y);
        st.classify_calls += 1;
        if verdict(&hp) != want {
            st.mismatch("vertex permutation", &x, &y, want, verdict(&hp));
            return;
        }
    }
    if !transform {
        return;
    }
    for (i, xf) in xforms().iter().enumerate() {
        let (Some(ta), Some(tb)) = (apply(xf, &a), apply(xf, &b)) else {
            st.xform_skipped += 1;
            continue;
        };
        st.xform_variants += 1;
        // Occasionally re-run the oracle on the transformed case (self-check of the oracle).
        if rng.chance(1, 64) {
            let ot = oracle(&ta, &tb).verdict;
            assert_eq!(ot, want, "oracle not invariant under transform {i}: {} {}", hex_tri(&a), hex_tri(&b));
        }
        let ht = classify(&ta, &tb);
        let hts = classify(&tb, &ta);
        st.classify_calls += 2;
        if verdict(&ht) != want {
            st.mismatch(
                &format!("transform #{i} (s={:e}, o={:?})", xf.s, xf.o),
                &ta,
                &tb,
                want,
                verdict(&ht),
            );
            return;
        }
        if verdict(&hts) != want {
            st.mismatch(&format!("transform #{i}, swapped"), &tb, &ta, want, verdict(&hts));
            return;
        }
        if let Some(ht) = &ht {
            if ht.segment.is_some() && rng.chance(1, 16) {
                let ot = oracle(&ta, &tb);
                check_segment(st, &ta, &tb, ht, &ot);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Oracle self-checks on hand-made cases (so that a wrong oracle cannot silently agree)
// ---------------------------------------------------------------------------------------------

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

#[test]
fn oracle_self_check() {
    let unit = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    let cases: Vec<([DVec3; 3], Option<(bool, Contact)>)> = vec![
        ([v(0.2, 0.2, -1.0), v(0.3, 0.2, 1.0), v(0.2, 0.6, 1.0)], Some((true, Contact::Segment))),
        ([v(0.2, 0.2, 1.0), v(0.3, 0.2, 1.0), v(0.2, 0.6, 2.0)], None),
        ([v(0.25, 0.25, 0.0), v(0.5, 0.25, 1.0), v(0.25, 0.5, 1.0)], Some((false, Contact::Point))),
        ([v(0.25, 0.25, 0.0), v(0.5, 0.25, 0.0), v(0.25, 0.5, 1.0)], Some((false, Contact::Segment))),
        ([v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.5, -0.5, 1.0)], Some((false, Contact::Segment))),
        ([v(1.0, 0.0, 0.0), v(2.0, 1.0, 1.0), v(2.0, -1.0, 1.0)], Some((false, Contact::Point))),
        (unit, Some((false, Contact::CoplanarArea))),
        ([v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0)], Some((false, Contact::CoplanarBoundary))),
        ([v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(2.0, 1.0, 0.0)], Some((false, Contact::CoplanarBoundary))),
        ([v(1.0, 0.5, 0.0), v(2.0, 0.5, 0.0), v(2.0, 1.0, 0.0)], None),
        ([v(0.25, 0.25, -1.0), v(0.25, 0.25, 1.0), v(0.25, 0.25, 0.5)], Some((true, Contact::Point))),
        ([v(0.5, 0.0, -1.0), v(0.5, 0.0, 1.0), v(0.5, 0.0, 1.0)], Some((false, Contact::Point))),
        ([v(0.25, 0.25, 0.0); 3], Some((false, Contact::Point))),
        ([v(0.25, 0.25, 1e-300); 3], None),
        ([v(-1.0, 0.5, 0.0), v(2.0, 0.2, 0.0), v(2.0, 0.2, 0.0)], Some((false, Contact::Segment))),
        ([v(0.5, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 0.0)], Some((false, Contact::Segment))),
        ([v(1.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 0.0)], Some((false, Contact::Point))),
        ([v(1.0, -1.0, 0.0), v(1.0, 1.0, 0.0), v(1.0, 1.0, 0.0)], Some((false, Contact::Point))),
        ([v(2.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 0.0)], None),
        // A needle ending exactly on the face: touching, not crossing.
        ([v(0.25, 0.25, 0.0), v(0.25, 0.25, 1.0), v(0.25, 0.25, 1.0)], Some((false, Contact::Point))),
    ];
    for (b, want) in cases {
        assert_eq!(oracle(&unit, &b).verdict, want, "b = {b:?}");
        assert_eq!(oracle(&b, &unit).verdict, want, "swapped, b = {b:?}");
    }
    let s1 = [v(0.0, 0.0, 0.0), v(2.0, 2.0, 0.0), v(1.0, 1.0, 0.0)];
    let s2 = [v(0.0, 2.0, 0.0), v(2.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
    let s3 = [v(1.0, 1.0, 0.0), v(3.0, 3.0, 0.0), v(3.0, 3.0, 0.0)];
    let s4 = [v(0.0, 2.0, 1.0), v(2.0, 0.0, 1.0), v(2.0, 0.0, 1.0)];
    let s5 = [v(2.0, 2.0, 0.0), v(3.0, 3.0, 0.0), v(3.0, 3.0, 0.0)];
    assert_eq!(oracle(&s1, &s2).verdict, Some((false, Contact::Point)));
    assert_eq!(oracle(&s1, &s3).verdict, Some((false, Contact::Segment)));
    assert_eq!(oracle(&s1, &s4).verdict, None);
    assert_eq!(oracle(&s1, &s5).verdict, Some((false, Contact::Point)));
}

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// 1. Small integer coordinates in [-3, 3].
#[test]
fn oracle_small_integers() {
    let t0 = Instant::now();
    let mut st = Stats::new("small-int");
    let mut rng = Rng(0x5EED_0001);
    for i in 0..60_000 {
        // Alternate ranges: [-3,3] mostly, [-1,1] for denser degeneracies.
        let r = if i % 4 == 3 { 1 } else { 3 };
        let a = [rng.grid(r, 1), rng.grid(r, 1), rng.grid(r, 1)];
        let b = [rng.grid(r, 1), rng.grid(r, 1), rng.grid(r, 1)];
        check_case(&mut st, &mut rng, a, b, true);
    }
    st.finish(t0);
}

/// A point of `a`'s plane with dyadic barycentric-like coordinates `(s, t)`, biased towards
/// the boundary (vertices, edges, edge lines).
fn plane_point(rng: &mut Rng, a: &[DVec3; 3]) -> DVec3 {
    let f = |rng: &mut Rng| rng.int(-4, 12) as f64 / 8.0;
    let (s, t) = match rng.below(6) {
        0 => (f(rng), 0.0),
        1 => (0.0, f(rng)),
        2 => {
            let s = f(rng);
            (s, 1.0 - s)
        }
        3 => ([0.0, 1.0, 0.0][rng.below(3)], [0.0, 0.0, 1.0][rng.below(3)]),
        _ => (f(rng), f(rng)),
    };
    a[0] + (a[1] - a[0]) * s + (a[2] - a[0]) * t
}

/// 2. Exact touching constructions on a dyadic grid.
#[test]
fn oracle_touching_constructions() {
    let t0 = Instant::now();
    let mut st = Stats::new("touching");
    let mut rng = Rng(0x5EED_0002);
    for i in 0..40_000 {
        let kind = i % 10;
        let mut a = [rng.grid(3, 4), rng.grid(3, 4), rng.grid(3, 4)];
        if kind == 8 {
            for p in &mut a {
                p.z = 0.0;
            }
        }
        let (i0, j0) = (rng.below(3), rng.below(3));
        let j0 = if j0 == i0 { (i0 + 1) % 3 } else { j0 };
        let mut r = || rng.grid(3, 4);
        let (r1, r2) = (r(), r());
        let b = match kind {
            0 => [a[i0], r1, r2],                   // shared vertex
            1 => [a[i0], a[j0], r1],                // shared edge
            2 => PERMS[rng.below(6)].map(|k| a[k]), // whole face
            3 => [(a[i0] + a[j0]) * 0.5, r1, r2],   // vertex on an edge midpoint
            4 => {
                // vertex on an edge at k/8, and maybe a second one on another edge
                let k = rng.int(0, 8) as f64 / 8.0;
                let p = a[i0] + (a[j0] - a[i0]) * k;
                let other = if rng.chance(1, 2) { plane_point(&mut rng, &a) } else { r1 };
                [p, other, r2]
            }
            5 => [plane_point(&mut rng, &a), r1, r2], // vertex on the plane
            6 => [plane_point(&mut rng, &a), plane_point(&mut rng, &a), r1], // edge in the plane
            7 => [plane_point(&mut rng, &a), plane_point(&mut rng, &a), plane_point(&mut rng, &a)],
            8 => {
                // coplanar in z = 0, dense small grid
                let mut g = || {
                    let p = rng.grid(2, 2);
                    DVec3::new(p.x, p.y, 0.0)
                };
                [g(), g(), g()]
            }
            _ => {
                // b straddles a's plane with one vertex on a's edge line / vertex
                let p = plane_point(&mut rng, &a);
                let n = (a[1] - a[0]).cross(a[2] - a[0]);
                [
                    p,
                    p + n * (rng.int(1, 4) as f64 / 4.0) + r1 * 0.25,
                    p - n * (rng.int(1, 4) as f64 / 4.0) + r2 * 0.25,
                ]
            }
        };
        let (a, b) = if rng.chance(1, 2) { (a, b) } else { (b, a) };
        check_case(&mut st, &mut rng, a, b, true);
    }
    st.finish(t0);
}

/// 3. Random f64 coordinates in [-1, 1] (general position), also with exactly shared vertices
/// and edges, scaled by powers of two (translations are skipped when inexact).
#[test]
fn oracle_random_floats() {
    let t0 = Instant::now();
    let mut st = Stats::new("random-f64");
    let mut rng = Rng(0x5EED_0003);
    for i in 0..30_000 {
        let mut u = || DVec3::new(rng.unit(), rng.unit(), rng.unit());
        let a = [u(), u(), u()];
        let (r1, r2, r3) = (u(), u(), u());
        let b = match i % 4 {
            0 | 1 => [r1, r2, r3],
            2 => [a[rng.below(3)], r1, r2],
            _ => {
                let k = rng.below(3);
                [a[k], a[(k + 1) % 3], r1]
            }
        };
        check_case(&mut st, &mut rng, a, b, true);
    }
    st.finish(t0);
}

/// `x` moved by `k` ulps; from zero, by `k`·2^-100 instead (subnormal coordinates are outside
/// the documented domain of the predicates).
fn ulps(x: f64, k: i64) -> f64 {
    if x == 0.0 {
        return k as f64 * 2f64.powi(-100);
    }
    let mut y = x;
    for _ in 0..k.abs() {
        y = if k > 0 { y.next_up() } else { y.next_down() };
    }
    y
}

/// 4. Near-degenerate: vertices one ulp off a z-plane, one ulp off an edge line, slivers, and
/// f64-rounded "coplanar" points.
#[test]
fn oracle_near_degenerate() {
    let t0 = Instant::now();
    let mut st = Stats::new("near-degenerate");
    let mut rng = Rng(0x5EED_0004);
    let planes = [1.0, 0.75, -3.0, 2f64.powi(-40), 1.0e8, 12345.678, 2f64.powi(30) + 1.0];
    for i in 0..20_000 {
        let kind = i % 6;
        let c = planes[rng.below(planes.len())];
        let xy = |rng: &mut Rng| {
            if rng.chance(1, 2) {
                rng.int(-8, 8) as f64 / 4.0
            } else {
                rng.unit() * 2.0
            }
        };
        let (a, b) = match kind {
            0 | 1 => {
                // a in z = c; b's vertex (or edge, kind 1) ±0..2 ulps off the plane.
                let a = [0, 1, 2].map(|_| DVec3::new(xy(&mut rng), xy(&mut rng), c));
                let mut p = plane_point(&mut rng, &a);
                p.z = ulps(c, rng.int(-2, 2));
                let far = |rng: &mut Rng, sgn: f64| {
                    DVec3::new(xy(rng), xy(rng), c + sgn * (rng.int(1, 8) as f64 / 4.0))
                };
                let s1 = if rng.chance(1, 2) { 1.0 } else { -1.0 };
                let s2 = if rng.chance(2, 3) { s1 } else { -s1 };
                let b = if kind == 0 {
                    [p, far(&mut rng, s1), far(&mut rng, s2)]
                } else {
                    let mut p2 = plane_point(&mut rng, &a);
                    p2.z = ulps(c, rng.int(-2, 2));
                    [p, p2, far(&mut rng, s1)]
                };
                (a, b)
            }
            2 => {
                // coplanar in z = c: b's vertex ±1 ulp off a's edge line (in y), a's edge along x.
                let y0 = xy(&mut rng);
                let (x0, x1) = (xy(&mut rng), xy(&mut rng) + 3.0);
                let a = [DVec3::new(x0, y0, c), DVec3::new(x1, y0, c), DVec3::new(xy(&mut rng), y0 + 1.5, c)];
                let xm = x0 + (x1 - x0) * (rng.int(-2, 10) as f64 / 8.0);
                let p = DVec3::new(xm, ulps(y0, rng.int(-1, 1)), c);
                let z2 = if rng.chance(3, 4) { c } else { c + rng.int(-2, 2) as f64 };
                let b = [p, DVec3::new(xy(&mut rng), y0 - 1.0, z2), DVec3::new(xy(&mut rng), y0 - 1.5, c)];
                (a, b)
            }
            3 => {
                // a sliver: the midpoint of an edge nudged by a few ulps (or not at all).
                let (p, q) = (rng.grid(3, 4), rng.grid(3, 4));
                let mut m = (p + q) * 0.5;
                let k = rng.below(3);
                m[k] = ulps(m[k], rng.int(-2, 2));
                let a = [p, q, m];
                // b pierces the segment p–q near its middle, or is random.
                let b = if rng.chance(2, 3) {
                    let d = DVec3::new(rng.unit(), rng.unit(), rng.unit());
                    let e = DVec3::new(rng.unit(), rng.unit(), rng.unit());
                    let o = m + (q - p) * (rng.int(-2, 2) as f64 / 16.0);
                    [o + d, o - d + e * 0.25, o - d - e * 0.25]
                } else {
                    [rng.grid(3, 4), rng.grid(3, 4), rng.grid(3, 4)]
                };
                (a, b)
            }
            4 => {
                // b's vertices on a's plane, rounded by f64 (tiny exact orientations).
                let mut u = || DVec3::new(rng.unit(), rng.unit(), rng.unit());
                let a = [u(), u(), u()];
                let pp = |rng: &mut Rng| {
                    let (s, t) = (rng.unit() + 0.5, rng.unit() + 0.5);
                    a[0] + (a[1] - a[0]) * s + (a[2] - a[0]) * t
                };
                let b = if rng.chance(1, 2) {
                    [pp(&mut rng), pp(&mut rng), pp(&mut rng)]
                } else {
                    let p0 = pp(&mut rng);
                    let mut u = || DVec3::new(rng.unit(), rng.unit(), rng.unit());
                    [p0, u(), u()]
                };
                (a, b)
            }
            _ => {
                // a zero-area needle along z through a's plane at a grid point, ending ±1 ulp.
                let a = [0, 1, 2]
                    .map(|_| DVec3::new(rng.int(-8, 8) as f64 / 4.0, rng.int(-8, 8) as f64 / 4.0, c));
                let mut p = plane_point(&mut rng, &a);
                let lo = ulps(c, rng.int(-1, 1));
                let hi = c + rng.int(-2, 2) as f64;
                p.z = lo;
                let mut q = p;
                q.z = hi;
                let b = if rng.chance(1, 2) { [p, q, q] } else { [p, (p + q) * 0.5, q] };
                (a, b)
            }
        };
        let (a, b) = if rng.chance(1, 2) { (a, b) } else { (b, a) };
        check_case(&mut st, &mut rng, a, b, true);
    }
    st.finish(t0);
}

// ---------------------------------------------------------------------------------------------
// Minimised failures found by the generators above (they fail until `src/` is fixed)
// ---------------------------------------------------------------------------------------------

/// Nearly coplanar crossing triangles (`a` is `b`'s plane `z = (x + y) / 4` with its vertices
/// nudged by about 1e-15). The verdict is right, but the reported shared segment is not: one
/// end is placed about 0.065 away from `a` (triangles of size ~2), and the true end
/// (1.12905, 0.87095, 0.5) is missed by 0.1 along `b`'s edge. The ends are placed with the
/// approximate `orient3d_value`s, whose relative error is large when a vertex is nearly on the
/// other plane; the verdict only uses their signs.
/// Fixed by evaluating the plane distances that place segment ends in double-double
/// arithmetic (`predicates::orient3d_value`).
#[test]
fn near_coplanar_crossing_reports_a_segment_end_off_the_triangles() {
    let a = [v(0.9, 0.6, 0.375000000000001), v(1.5, 1.1, 0.649999999999999), v(0.1, 0.5, 0.150000000000002)];
    let b = [v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.5), v(0.0, 2.0, 0.5)];
    let o = oracle(&a, &b);
    assert_eq!(o.verdict, Some((true, Contact::Segment)));
    let (e0, e1) = o.ends.unwrap();
    assert!((e0 - v(1.1290480863591756, 0.8709519136408244, 0.5)).length() < 1e-15);
    assert!((e1 - v(1.0322505800464037, 0.8995359628770302, 0.4829466357308585)).length() < 1e-15);
    for (x, y) in [(&a, &b), (&b, &a)] {
        let h = classify(x, y).expect("they cross");
        assert_eq!((h.crossing, h.contact), (true, Contact::Segment));
        for end in h.segment.expect("non-coplanar contacts report a segment") {
            let d = dist_point_tri(end, &a).max(dist_point_tri(end, &b));
            assert!(
                d <= 2e-9,
                "reported end {end:?} is {d:e} away from a triangle (exact ends {e0:?}, {e1:?})"
            );
        }
    }
}

/// Parallel triangles 1e120 apart, with coordinates of magnitude 1e120: inside the range that
/// `geom::predicates` documents as exact ("about 1e-140 to 1e140"), but products of three
/// coordinate differences overflow f64 (from about 1e102 on), every orientation comes out 0 and
/// the disjoint pair is classified as `CoplanarArea`.
#[test]
#[ignore = "outside the supported range: coordinates beyond 2^250 are rejected at load \
            (query::check_range; tested in tests/cli.rs)"]
fn coordinates_of_1e120_are_misclassified() {
    let a = [v(0.0, 0.0, 0.0), v(1e120, 0.0, 0.0), v(0.0, 1e120, 0.0)];
    let b = [v(0.0, 0.0, 1e120), v(1e120, 0.0, 1e120), v(0.0, 1e120, 1e120)];
    assert_eq!(oracle(&a, &b).verdict, None);
    assert_eq!(verdict(&classify(&a, &b)), None);
}

/// The same at 1e-120 (products of three differences underflow, from about 1e-105 on).
#[test]
#[ignore = "outside the supported range: non-zero coordinates below 2^-250 get a warning \
            in the report (query::check_range)"]
fn coordinates_of_1e_minus_120_are_misclassified() {
    let a = [v(0.0, 0.0, 0.0), v(1e-120, 0.0, 0.0), v(0.0, 1e-120, 0.0)];
    let b = [v(0.0, 0.0, 1e-120), v(1e-120, 0.0, 1e-120), v(0.0, 1e-120, 1e-120)];
    assert_eq!(oracle(&a, &b).verdict, None);
    assert_eq!(verdict(&classify(&a, &b)), None);
}
