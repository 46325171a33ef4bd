//! Exact triangle–triangle classification: disjoint, touching (with the kind of contact) or
//! crossing, decided from exact orientation signs only ([`crate::geom::predicates`]).
//!
//! The non-coplanar case follows the idea of Guigue & Devillers (2003, "Fast and robust
//! triangle-triangle overlap test using orientation predicates"): each triangle meets the other's
//! plane in a segment on the line `L` where the planes meet, and the triangles meet iff those two
//! segments overlap on `L`. The order of two such endpoints along `L` is the sign of one
//! `orient3d` of four input vertices, so every comparison is exact. Unlike the original, which
//! only answers yes/no, the overlap is kept as an interval so that touching (the segments share
//! only endpoints, or a triangle only grazes the other's plane) is told apart from crossing.
//!
//! The coplanar case is a 2D separating-axis test on an exact projection: the triangles'
//! interiors are disjoint iff some edge line has the other triangle weakly outside, and the
//! closed triangles are disjoint iff some edge line has it strictly outside (edges of the
//! Minkowski difference of two triangles are parallel to their edges).
//!
//! Zero-area triangles are classified as what they are — segments or points — and can touch
//! anything, or cross a proper triangle when a segment pierces its interior transversally.

pub use crate::geom::predicates::Float;
use crate::geom::predicates::{self as pr, Adaptive, Exact, Kernel, PlaneFilter, Sign};
use crate::geom::DVec3;
use std::cell::Cell;

/// How two triangles meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Contact {
    /// They share exactly one point.
    Point,
    /// They share a segment of positive length (and are not coplanar).
    Segment,
    /// Coplanar and their interiors overlap (face-to-face contact, duplicated faces).
    CoplanarArea,
    /// Coplanar and they share only boundary points (edge-to-edge or vertex contact in-plane).
    CoplanarBoundary,
}

impl Contact {
    /// The name used in the report.
    pub fn name(self) -> &'static str {
        match self {
            Contact::Point => "point",
            Contact::Segment => "segment",
            Contact::CoplanarArea => "coplanar_area",
            Contact::CoplanarBoundary => "coplanar_boundary",
        }
    }
}

/// The classification of a pair that meets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// True if the relative interiors cross (a real penetration): the triangles are not
    /// coplanar and a point interior to both exists. Otherwise they only touch.
    pub crossing: bool,
    /// The shape of the shared set.
    pub contact: Contact,
    /// For non-coplanar contacts: the shared segment (both ends equal for a point), computed in
    /// f64 for the report (the classification itself does not depend on it).
    pub segment: Option<[DVec3; 2]>,
}

/// A triangle as the geometric object it really is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A proper triangle (non-zero area).
    Tri([DVec3; 3]),
    /// Zero area, not all vertices equal: the segment between the two extreme vertices.
    Seg(DVec3, DVec3),
    /// All three vertices equal.
    Pt(DVec3),
}

impl Shape {
    /// Classify a triangle exactly.
    pub fn of(t: &[DVec3; 3]) -> Shape {
        let [a, b, c] = *t;
        if !pr::collinear(a, b, c) {
            return Shape::Tri(*t);
        }
        if a == b && b == c {
            return Shape::Pt(a);
        }
        // Collinear: the extreme pair along an axis on which they are not all equal.
        let box_ = crate::geom::Aabb::of_triangle(t);
        let e = box_.extent();
        let k = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let lo = *t.iter().min_by(|p, q| p[k].total_cmp(&q[k])).unwrap();
        let hi = *t.iter().max_by(|p, q| p[k].total_cmp(&q[k])).unwrap();
        Shape::Seg(lo, hi)
    }

    /// True for zero-area triangles.
    pub fn is_degenerate(&self) -> bool {
        !matches!(self, Shape::Tri(_))
    }
}

/// Classify the pair `(a, b)` exactly. `None` if they share no point.
///
/// Float-filtered: each triangle's f64 normal and its error-bound data are computed once
/// ([`PlaneFilter`]); when they prove both triangles proper, the other triangle's vertices are
/// placed against each plane by the filter, and only the signs it cannot prove are computed
/// exactly. Every sign used is exact, so the answer is the one of [`classify_unfiltered`], bit
/// for bit (points included).
pub fn classify(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<Hit> {
    classify_facts(a, b, true)
}

/// A triangle with the facts the classifier reads from it alone: its float plane filter, and
/// its exact [`Shape`] once some pair needs it. A triangle met by several candidates (the
/// triangles of two leaves of a walk, tried against each other) is prepared once for all of
/// them; [`classify_prepared`] then answers exactly as [`classify`] does.
pub struct Prepared {
    tri: [DVec3; 3],
    filter: PlaneFilter,
    shape: std::cell::OnceCell<Shape>,
}

impl Prepared {
    /// The facts of triangle `t` (its shape is classified on first use).
    #[inline]
    pub fn new(t: [DVec3; 3]) -> Prepared {
        Prepared { tri: t, filter: PlaneFilter::new(&t), shape: std::cell::OnceCell::new() }
    }

    /// The triangle.
    #[inline]
    pub fn triangle(&self) -> &[DVec3; 3] {
        &self.tri
    }
}

/// [`classify`] of two prepared triangles: the same answer, bit for bit. Without `segment`,
/// the f64 placement of the shared segment of two proper non-coplanar triangles is skipped (a
/// caller that keeps only counts asks again, with it, for the few pairs whose point it keeps):
/// [`Hit::segment`] is then `None` for them, and every other field is as [`classify`] gives.
pub fn classify_prepared(a: &Prepared, b: &Prepared, segment: bool) -> Option<Hit> {
    classify_facts(a, b, segment)
}

/// What [`classify_facts`] reads of a triangle: a bare triangle computes each fact when asked,
/// a [`Prepared`] one keeps them.
trait Facts {
    fn tri(&self) -> &[DVec3; 3];
    fn filter(&self) -> PlaneFilter;
    fn shape(&self) -> Shape;
}

impl Facts for [DVec3; 3] {
    #[inline]
    fn tri(&self) -> &[DVec3; 3] {
        self
    }
    #[inline]
    fn filter(&self) -> PlaneFilter {
        PlaneFilter::new(self)
    }
    #[inline]
    fn shape(&self) -> Shape {
        Shape::of(self)
    }
}

impl Facts for Prepared {
    #[inline]
    fn tri(&self) -> &[DVec3; 3] {
        &self.tri
    }
    #[inline]
    fn filter(&self) -> PlaneFilter {
        self.filter
    }
    #[inline]
    fn shape(&self) -> Shape {
        *self.shape.get_or_init(|| Shape::of(&self.tri))
    }
}

/// The filtered classification of [`classify`], reading each triangle's own facts through
/// [`Facts`].
#[inline]
fn classify_facts<X: Facts + ?Sized, Y: Facts + ?Sized>(x: &X, y: &Y, segment: bool) -> Option<Hit> {
    let (a, b) = (x.tri(), y.tri());
    let fb = y.filter();
    if fb.proper() {
        // The filter's sides of `a`'s vertices against `b`'s plane, computed once: all strictly
        // on one side means apart, whatever shape `a` has (a segment or point of `a` is then
        // strictly on that side too).
        let s = a.map(|p| fb.side(p));
        if s == [Some(1); 3] || s == [Some(-1); 3] {
            return None;
        }
        let fa = x.filter();
        if fa.proper() {
            // Both proven non-collinear: `Shape::of` would return `Tri` for both.
            let sa = Classifier::<Exact>::settle(s, b, a);
            return Classifier::<Exact>::tri_tri_from(
                a,
                b,
                sa,
                || Classifier::<Exact>::sides_all(&fa, a, b),
                segment,
            );
        }
    }
    Classifier::<Exact>::classify_shapes(&x.shape(), &y.shape())
}

/// As [`classify`], for already classified shapes.
pub fn classify_shapes(a: &Shape, b: &Shape) -> Option<Hit> {
    if let (Shape::Tri(a), Shape::Tri(b)) = (a, b) {
        return Classifier::<Exact>::tri_tri_filtered(a, &PlaneFilter::new(a), b, &PlaneFilter::new(b));
    }
    Classifier::<Exact>::classify_shapes(a, b)
}

/// [`classify`] without the float filters of [`crate::geom::predicates`]: every sign from
/// Shewchuk's adaptive predicates, each decided on its own (the classifier as it was before
/// the filters). The reference that tests and benchmarks compare [`classify`] with.
pub fn classify_unfiltered(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<Hit> {
    Classifier::<Adaptive>::classify_shapes(&Shape::of(a), &Shape::of(b))
}

/// As [`classify`], with the predicates of kernel `K`: [`Exact`] (the default everywhere), or
/// [`Float`] (plain f64 determinants with no exact fallback: faster on near-degenerate input,
/// and wrong there — the `fast` mode, measured by `meshclash bench --trade`).
pub fn classify_with<K: Kernel>(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<Hit> {
    Classifier::<K>::classify_shapes(&Classifier::<K>::shape(a), &Classifier::<K>::shape(b))
}

/// The classification code, generic over the predicate kernel.
struct Classifier<K>(std::marker::PhantomData<K>);

impl<K: Kernel> Classifier<K> {
    fn shape(t: &[DVec3; 3]) -> Shape {
        if K::collinear(t[0], t[1], t[2]) {
            Shape::of(t)
        } else {
            Shape::Tri(*t)
        }
    }

    fn classify_shapes(a: &Shape, b: &Shape) -> Option<Hit> {
        match (*a, *b) {
            (Shape::Tri(a), Shape::Tri(b)) => Self::tri_tri(&a, &b),
            (Shape::Tri(t), Shape::Seg(p, q)) => Self::seg_tri(p, q, &t),
            (Shape::Seg(p, q), Shape::Tri(t)) => Self::seg_tri(p, q, &t),
            (Shape::Tri(t), Shape::Pt(p)) | (Shape::Pt(p), Shape::Tri(t)) => Self::point_tri(p, &t),
            (Shape::Seg(p, q), Shape::Seg(r, s)) => Self::seg_seg(p, q, r, s),
            (Shape::Seg(p, q), Shape::Pt(r)) | (Shape::Pt(r), Shape::Seg(p, q)) => Self::point_seg(r, p, q),
            (Shape::Pt(p), Shape::Pt(q)) => (p == q).then(|| Self::point_hit(p)),
        }
    }
    fn point_hit(p: DVec3) -> Hit {
        Hit { crossing: false, contact: Contact::Point, segment: Some([p, p]) }
    }

    fn touch(contact: Contact, segment: Option<[DVec3; 2]>) -> Option<Hit> {
        Some(Hit { crossing: false, contact, segment })
    }

    /// `s`: the signs of the triangle's vertices with respect to the other plane (not all equal
    /// strictly, not all zero). `first`: true for triangle `a` (whose normal comes first in `L`).
    fn section(s: [Sign; 3], first: bool) -> Section {
        let split = s.contains(&1) && s.contains(&-1);
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let sigma = s[i];
            if sigma != 0 && s[j] != sigma && s[k] != sigma {
                // Apex i alone on its side. Derivation (see module doc): for `a` with the apex on
                // the positive side the section runs from edge (i,k) to edge (i,j) along L; for `b`
                // the other way round; a negative apex reverses both.
                let (ij, ik) = (End { apex: i, other: j }, End { apex: i, other: k });
                let forward = (sigma > 0) != first;
                let (lo, hi) = if forward { (ij, ik) } else { (ik, ij) };
                return Section { lo, hi, sigma, single: false, split };
            }
        }
        // Pattern (σ, σ, 0) in some order: the section is the zero vertex.
        let z = s.iter().position(|&v| v == 0).expect("section: one vertex on the plane");
        let i = (z + 1) % 3;
        let e = End { apex: i, other: z };
        Section { lo: e, hi: e, sigma: s[i], single: true, split: false }
    }

    /// Order along `L` of `x` (an end of `a`'s section) and `y` (an end of `b`'s section):
    /// negative if `x` comes first, 0 if they coincide.
    fn cmp_ends(a: &[DVec3; 3], sa: &Section, x: End, b: &[DVec3; 3], sb: &Section, y: End) -> Sign {
        let o = K::orient3d(a[x.apex], a[x.other], b[y.apex], b[y.other]);
        // orient3d > 0 ⟺ x before y when both apexes are on the positive sides; each negative apex
        // side reverses the direction of L relative to the normals used.
        -o * sa.sigma * sb.sigma
    }

    /// The f64 position of an end, for the report only. `d(i)`: the determinant value of
    /// vertex `i` of `t` with respect to the other plane.
    fn end_point(t: &[DVec3; 3], d: impl Fn(usize) -> f64, e: End) -> DVec3 {
        let (p, q) = (t[e.apex], t[e.other]);
        let dq = d(e.other);
        if dq == 0.0 {
            return q;
        }
        let dp = d(e.apex);
        let u = dp / (dp - dq);
        p + (q - p) * u
    }

    fn tri_tri(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<Hit> {
        let sa = a.map(|p| K::orient3d(b[0], b[1], b[2], p));
        Self::tri_tri_from(a, b, sa, || b.map(|p| K::orient3d(a[0], a[1], a[2], p)), true)
    }

    /// [`Self::tri_tri`] with the plane sides from the float filters of both triangles: the
    /// filter's sign where it proves one, the exact stages where it cannot.
    fn tri_tri_filtered(a: &[DVec3; 3], fa: &PlaneFilter, b: &[DVec3; 3], fb: &PlaneFilter) -> Option<Hit> {
        let sa = Self::sides(fb, b, a)?;
        Self::tri_tri_from(a, b, sa, || Self::sides_all(fa, a, b), true)
    }

    /// Exact signs of `pts` against the plane of `t` (filter `f`), or `None` when all three are
    /// proven strictly on one side (the pair is apart; nothing exact is computed).
    #[inline]
    fn sides(f: &PlaneFilter, t: &[DVec3; 3], pts: &[DVec3; 3]) -> Option<[Sign; 3]> {
        let s = pts.map(|p| f.side(p));
        if s == [Some(1); 3] || s == [Some(-1); 3] {
            return None;
        }
        Some(Self::settle(s, t, pts))
    }

    /// The exact signs of `pts` against the plane of `t`: the filter's `s` where it decided,
    /// the exact stages elsewhere.
    #[inline]
    fn settle(s: [Option<Sign>; 3], t: &[DVec3; 3], pts: &[DVec3; 3]) -> [Sign; 3] {
        [0, 1, 2].map(|i| s[i].unwrap_or_else(|| pr::orient3d_undecided(t[0], t[1], t[2], pts[i])))
    }

    /// As [`Self::sides`], always returning the signs.
    #[inline]
    fn sides_all(f: &PlaneFilter, t: &[DVec3; 3], pts: &[DVec3; 3]) -> [Sign; 3] {
        pts.map(|p| f.side_exact(t, p))
    }

    /// The classification from `sa` (the exact sides of `a`'s vertices against `b`'s plane) and
    /// `sb` (those of `b` against `a`'s plane, asked for only when needed); the shared segment
    /// placed only with `segment` (else `None`).
    fn tri_tri_from(
        a: &[DVec3; 3],
        b: &[DVec3; 3],
        sa: [Sign; 3],
        sb: impl FnOnce() -> [Sign; 3],
        segment: bool,
    ) -> Option<Hit> {
        if sa.iter().all(|&s| s > 0) || sa.iter().all(|&s| s < 0) {
            return None;
        }
        if sa.iter().all(|&s| s == 0) {
            return Self::coplanar(a, b);
        }
        let sb = sb();
        if sb.iter().all(|&s| s > 0) || sb.iter().all(|&s| s < 0) {
            return None;
        }
        let ia = Self::section(sa, true);
        let ib = Self::section(sb, false);
        // Meet iff lo_a <= hi_b and lo_b <= hi_a.
        let lo_a_hi_b = Self::cmp_ends(a, &ia, ia.lo, b, &ib, ib.hi);
        let hi_a_lo_b = Self::cmp_ends(a, &ia, ia.hi, b, &ib, ib.lo);
        if lo_a_hi_b > 0 || hi_a_lo_b < 0 {
            return None;
        }
        let positive = lo_a_hi_b < 0 && hi_a_lo_b > 0 && !ia.single && !ib.single;
        let crossing = positive && ia.split && ib.split;
        let contact = if positive { Contact::Segment } else { Contact::Point };
        if !segment {
            return Some(Hit { crossing, contact, segment: None });
        }
        // The shared interval: max of the lows, min of the highs. The determinant values (for
        // placing the ends) only of the vertices used, with their exact signs already known.
        // Each value at most once: both ends of one section share its apex.
        let (memo_a, memo_b) = (Cell::new([None; 3]), Cell::new([None; 3]));
        let da = |i: usize| memo(&memo_a, i, || K::orient3d_value_signed(b[0], b[1], b[2], a[i], sa[i]));
        let db = |i: usize| memo(&memo_b, i, || K::orient3d_value_signed(a[0], a[1], a[2], b[i], sb[i]));
        let lo_cmp = Self::cmp_ends(a, &ia, ia.lo, b, &ib, ib.lo);
        let lo = if lo_cmp >= 0 { Self::end_point(a, da, ia.lo) } else { Self::end_point(b, db, ib.lo) };
        let segment = Some(if positive {
            let hi_cmp = Self::cmp_ends(a, &ia, ia.hi, b, &ib, ib.hi);
            let hi = if hi_cmp <= 0 { Self::end_point(a, da, ia.hi) } else { Self::end_point(b, db, ib.hi) };
            [lo, hi]
        } else {
            [lo, lo]
        });
        Some(Hit { crossing, contact, segment })
    }

    /// Counter-clockwise (in projection `k`) copy of a proper triangle.
    fn ccw(t: &[DVec3; 3], k: usize) -> [DVec3; 3] {
        if K::orient2d(t[0], t[1], t[2], k) > 0 {
            *t
        } else {
            [t[0], t[2], t[1]]
        }
    }

    /// For each edge of `t` (ccw in projection `k`): (all of `pts` strictly outside, all weakly).
    fn separation(t: &[DVec3; 3], pts: &[DVec3], k: usize) -> (bool, bool) {
        let (mut strict, mut weak) = (false, false);
        for i in 0..3 {
            let (e0, e1) = (t[i], t[(i + 1) % 3]);
            let (mut all_neg, mut all_nonpos) = (true, true);
            for &p in pts {
                let v = K::orient2d(e0, e1, p, k);
                all_neg &= v < 0;
                all_nonpos &= v <= 0;
            }
            strict |= all_neg;
            weak |= all_nonpos;
        }
        (strict, weak)
    }

    fn coplanar(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<Hit> {
        let k = K::projection_axis(a[0], a[1], a[2]).expect("proper triangle");
        let (a, b) = (Self::ccw(a, k), Self::ccw(b, k));
        let (sa, wa) = Self::separation(&a, &b, k);
        let (sb, wb) = Self::separation(&b, &a, k);
        if sa || sb {
            return None;
        }
        Self::touch(if wa || wb { Contact::CoplanarBoundary } else { Contact::CoplanarArea }, None)
    }

    /// Point in closed triangle, the point known to be in the triangle's plane.
    fn in_closed_triangle(p: DVec3, t: &[DVec3; 3], k: usize) -> bool {
        let t = Self::ccw(t, k);
        (0..3).all(|i| K::orient2d(t[i], t[(i + 1) % 3], p, k) >= 0)
    }

    fn point_tri(p: DVec3, t: &[DVec3; 3]) -> Option<Hit> {
        if K::orient3d(t[0], t[1], t[2], p) != 0 {
            return None;
        }
        let k = K::projection_axis(t[0], t[1], t[2]).expect("proper triangle");
        Self::in_closed_triangle(p, t, k).then(|| Self::point_hit(p))
    }

    /// Is `p` on the closed segment `[q, r]` (`q != r`)?
    fn on_segment(p: DVec3, q: DVec3, r: DVec3) -> bool {
        if !K::collinear(q, r, p) {
            return false;
        }
        let k = pr::line_axis(q, r);
        let (lo, hi) = if q[k] <= r[k] { (q[k], r[k]) } else { (r[k], q[k]) };
        lo <= p[k] && p[k] <= hi
    }

    fn point_seg(p: DVec3, q: DVec3, r: DVec3) -> Option<Hit> {
        Self::on_segment(p, q, r).then(|| Self::point_hit(p))
    }

    /// Overlap of collinear segments `[p,q]` and `[r,s]`: None, a point, or a segment.
    fn collinear_overlap(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> Option<Hit> {
        let k = pr::line_axis(p, q);
        let (p, q) = if p[k] <= q[k] { (p, q) } else { (q, p) };
        let (r, s) = if r[k] <= s[k] { (r, s) } else { (s, r) };
        let lo = if p[k] >= r[k] { p } else { r };
        let hi = if q[k] <= s[k] { q } else { s };
        if lo[k] > hi[k] {
            None
        } else if lo[k] == hi[k] {
            Self::touch(Contact::Point, Some([lo, lo]))
        } else {
            Self::touch(Contact::Segment, Some([lo, hi]))
        }
    }

    fn seg_seg(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> Option<Hit> {
        if K::orient3d(p, q, r, s) != 0 {
            return None; // skew lines
        }
        if K::collinear(p, q, r) && K::collinear(p, q, s) {
            return Self::collinear_overlap(p, q, r, s);
        }
        // Coplanar, not all collinear: project where the plane does not collapse.
        let k = (0..3)
            .find(|&k| K::orient2d(p, q, r, k) != 0 || K::orient2d(p, q, s, k) != 0)
            .expect("non-collinear coplanar points project somewhere");
        let d1 = K::orient2d(r, s, p, k);
        let d2 = K::orient2d(r, s, q, k);
        let d3 = K::orient2d(p, q, r, k);
        let d4 = K::orient2d(p, q, s, k);
        if d1 * d2 < 0 && d3 * d4 < 0 {
            // Proper crossing of two segments: a single point; place it (f64) for the report.
            let (d1, d2) = (q - p, s - r);
            let n = d1.cross(d2);
            let nn = n.dot(n);
            let m = if nn > 0.0 { p + d1 * ((r - p).cross(d2).dot(n) / nn) } else { p };
            return Self::touch(Contact::Point, Some([m, m]));
        }
        for (x, y, z) in [(p, r, s), (q, r, s), (r, p, q), (s, p, q)] {
            if Self::on_segment(x, y, z) {
                return Self::touch(Contact::Point, Some([x, x]));
            }
        }
        None
    }

    fn seg_tri(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> Option<Hit> {
        let sp = K::orient3d(t[0], t[1], t[2], p);
        let sq = K::orient3d(t[0], t[1], t[2], q);
        if sp * sq > 0 {
            return None;
        }
        let k = K::projection_axis(t[0], t[1], t[2]).expect("proper triangle");
        if sp == 0 && sq == 0 {
            return Self::seg_tri_coplanar(p, q, &Self::ccw(t, k), k);
        }
        if sp == 0 {
            return Self::in_closed_triangle(p, t, k).then(|| Self::point_hit(p));
        }
        if sq == 0 {
            return Self::in_closed_triangle(q, t, k).then(|| Self::point_hit(q));
        }
        // Strictly through the plane: where does the line pass relative to the three edges?
        let s = [0, 1, 2].map(|i| K::orient3d(p, q, t[i], t[(i + 1) % 3]));
        let inside = s.iter().all(|&v| v >= 0) || s.iter().all(|&v| v <= 0);
        if !inside {
            return None;
        }
        let dp = K::orient3d_value(t[0], t[1], t[2], p);
        let dq = K::orient3d_value(t[0], t[1], t[2], q);
        let x = p + (q - p) * (dp / (dp - dq));
        let crossing = s.iter().all(|&v| v != 0);
        Some(Hit { crossing, contact: Contact::Point, segment: Some([x, x]) })
    }

    /// Segment in the plane of proper triangle `t` (ccw in projection `k`).
    fn seg_tri_coplanar(p: DVec3, q: DVec3, t: &[DVec3; 3], k: usize) -> Option<Hit> {
        let (strict_t, weak_t) = Self::separation(t, &[p, q], k);
        let line: Vec<Sign> = t.iter().map(|&v| K::orient2d(p, q, v, k)).collect();
        let strict_l = line.iter().all(|&v| v > 0) || line.iter().all(|&v| v < 0);
        if strict_t || strict_l {
            return None;
        }
        let both_sides = line.contains(&1) && line.contains(&-1);
        if !weak_t && both_sides {
            // The segment passes through the open triangle: a positive-length contact.
            return Self::touch(Contact::Segment, None);
        }
        // Only boundary contact: a segment if collinear with an edge over a positive length.
        let mut best: Option<Hit> = None;
        for i in 0..3 {
            let (e0, e1) = (t[i], t[(i + 1) % 3]);
            if K::orient2d(e0, e1, p, k) == 0 && K::orient2d(e0, e1, q, k) == 0 {
                if let Some(h) = Self::collinear_overlap(p, q, e0, e1) {
                    if h.contact == Contact::Segment {
                        return Some(h);
                    }
                    best = best.or(Some(h));
                }
            }
        }
        if best.is_some() {
            return best;
        }
        // A single boundary point: an endpoint inside, or the segment through a vertex/edge.
        for x in [p, q] {
            if Self::in_closed_triangle(x, t, k) {
                return Self::touch(Contact::Point, Some([x, x]));
            }
        }
        for &v in t {
            if Self::on_segment(v, p, q) {
                return Self::touch(Contact::Point, Some([v, v]));
            }
        }
        for i in 0..3 {
            if let Some(h) = Self::seg_seg(p, q, t[i], t[(i + 1) % 3]) {
                return Some(h);
            }
        }
        Self::touch(Contact::Point, None)
    }
}

/// Slot `i` of `cache`, filled by `f` on first use.
#[inline]
fn memo(cache: &Cell<[Option<f64>; 3]>, i: usize, f: impl FnOnce() -> f64) -> f64 {
    let mut c = cache.get();
    let v = *c[i].get_or_insert_with(f);
    cache.set(c);
    v
}

/// An endpoint of a triangle's section by the other plane: the point where edge
/// `(apex, other)` meets the plane. The apex is strictly off the plane.
#[derive(Clone, Copy)]
struct End {
    apex: usize,
    other: usize,
}
/// A triangle's section by the other triangle's plane, as an interval on the line `L`
/// (direction `n_a × n_b`): its low and high ends, and the sign of the apex side.
struct Section {
    lo: End,
    hi: End,
    sigma: Sign,
    /// The section is a single point (only one vertex on the plane, others on one side).
    single: bool,
    /// The plane cuts the triangle's interior (vertices strictly on both sides).
    split: bool,
}

#[cfg(test)]
mod tests;
