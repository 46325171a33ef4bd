//! The ONE place that decides geometry: exact orientation predicates and every tolerance.
//!
//! Orientation signs come from Shewchuk's adaptive-precision predicates (Shewchuk 1997,
//! "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates") as
//! implemented by the `robust` crate: a floating-point evaluation with an error bound, falling
//! back to exact expansion arithmetic only when the bound cannot decide the sign. The signs are
//! therefore exact for the f64 coordinates as given, as long as no intermediate overflows or
//! underflows: every coordinate must be 0 or have a magnitude in
//! [`MIN_EXACT_MAGNITUDE`, `MAX_EXACT_MAGNITUDE`] = [2^-250, 2^250] (about 5.5e-76 to 1.8e75).
//! Products of three coordinate differences must stay within f64's normal range; the exact
//! oracle test found overflow from about 2^342 and underflow from about 2^-350 for unit-shaped
//! triangles, and ulp-sized differences of coordinates near m are m·2^-52, hence the margins.
//! The loader stage rejects larger coordinates and warns about smaller non-zero ones.
//!
//! Nothing outside this module compares a computed geometric quantity against a threshold:
//! verdicts are built from these signs. The only tolerances are the user's own
//! (`--touch-tolerance`, `--clearance`), carried in [`Tolerances`].

use super::{Aabb, DVec3};
use robust::{Coord, Coord3D};

/// Largest coordinate magnitude for which the predicates are exact (2^250).
pub const MAX_EXACT_MAGNITUDE: f64 = f64::from_bits((1023 + 250) << 52);
/// Smallest non-zero coordinate magnitude for which the predicates are exact (2^-250).
pub const MIN_EXACT_MAGNITUDE: f64 = f64::from_bits((1023 - 250) << 52);

/// The sign of an exact determinant.
pub type Sign = i8;

#[inline]
fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D { x: p.x, y: p.y, z: p.z }
}

#[inline]
fn sign(v: f64) -> Sign {
    (v > 0.0) as Sign - (v < 0.0) as Sign
}

/// Exact sign of `((b - a) × (c - a)) · (d - a)`: positive when `d` lies on the side that the
/// normal of triangle `(a, b, c)` (right-hand rule) points to, zero when the four are coplanar.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    // robust's convention is the opposite ("positive when d is below").
    -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

/// The determinant of [`orient3d`] as a value, used only to place intersection points for the
/// report, never to decide. Evaluated in double-double arithmetic (about 106 bits) from exact
/// coordinate differences, so that points are placed accurately even when a vertex is within
/// rounding of the other plane (where the f64 value has no correct digits); its sign is forced
/// to the exact one.
pub fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let s = orient3d(a, b, c, d);
    if s == 0 {
        return 0.0;
    }
    let v = dd::orient3d(a, b, c, d);
    if (v > 0.0) == (s > 0) && v != 0.0 {
        v
    } else {
        // Even 106 bits could not resolve it: the magnitude is below any useful resolution.
        f64::MIN_POSITIVE * s as f64
    }
}

/// Double-double arithmetic (Dekker 1971; Knuth's TwoSum; TwoProduct by fused multiply-add).
mod dd {
    use super::DVec3;

    #[derive(Clone, Copy)]
    pub(super) struct Dd(f64, f64);

    #[inline]
    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }

    #[inline]
    fn add(x: Dd, y: Dd) -> Dd {
        let s = two_sum(x.0, y.0);
        let lo = s.1 + x.1 + y.1;
        let h = s.0 + lo;
        Dd(h, lo - (h - s.0))
    }

    #[inline]
    fn neg(x: Dd) -> Dd {
        Dd(-x.0, -x.1)
    }

    #[inline]
    fn mul(x: Dd, y: Dd) -> Dd {
        let p = x.0 * y.0;
        let e = x.0.mul_add(y.0, -p);
        let lo = e + (x.0 * y.1 + x.1 * y.0);
        let h = p + lo;
        Dd(h, lo - (h - p))
    }

    /// `((b - a) × (c - a)) · (d - a)`, differences exact.
    pub(super) fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        let diff = |p: DVec3, k: usize| two_sum(p[k], -a[k]);
        let (u, v, w) =
            ([0, 1, 2].map(|k| diff(b, k)), [0, 1, 2].map(|k| diff(c, k)), [0, 1, 2].map(|k| diff(d, k)));
        let cross = |i: usize, j: usize| add(mul(u[i], v[j]), neg(mul(u[j], v[i])));
        let n = [cross(1, 2), cross(2, 0), cross(0, 1)];
        let r = add(add(mul(n[0], w[0]), mul(n[1], w[1])), mul(n[2], w[2]));
        r.0 + r.1
    }
}

/// Drop coordinate `axis` keeping the other two in cyclic order, so that the 2D orientation of
/// projected points has the sign of component `axis` of the 3D normal.
#[inline]
pub fn project(p: DVec3, axis: usize) -> Coord<f64> {
    match axis {
        0 => Coord { x: p.y, y: p.z },
        1 => Coord { x: p.z, y: p.x },
        _ => Coord { x: p.x, y: p.y },
    }
}

/// Exact sign of component `axis` of `(b - a) × (c - a)`: the 2D orientation of the three points
/// projected along `axis`.
#[inline]
pub fn orient2d(a: DVec3, b: DVec3, c: DVec3, axis: usize) -> Sign {
    sign(robust::orient2d(project(a, axis), project(b, axis), project(c, axis)))
}

/// Exact: are the three points collinear (or coincident)? True iff every component of
/// `(b - a) × (c - a)` is exactly zero.
#[inline]
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    (0..3).all(|k| orient2d(a, b, c, k) == 0)
}

/// An axis along which the triangle `(a, b, c)` projects without collapsing (its normal has a
/// non-zero component there), preferring the largest component so projected shapes stay well
/// conditioned. `None` if the triangle is degenerate.
pub fn projection_axis(a: DVec3, b: DVec3, c: DVec3) -> Option<usize> {
    let n = (b - a).cross(c - a).abs();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
    order.into_iter().find(|&k| orient2d(a, b, c, k) != 0)
}

/// The axis of largest extent of a set of collinear points, along which their order is their
/// order on the line (used for exact 1D comparisons of collinear points).
pub fn line_axis(p: DVec3, q: DVec3) -> usize {
    let d = (q - p).abs();
    if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    }
}

/// The predicates a classification is built from. [`Exact`] is the product; [`Float`] exists
/// to measure what exactness costs and buys (`--mode fast`).
pub trait Kernel {
    /// Sign of `((b - a) × (c - a)) · (d - a)`.
    fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign;
    /// The determinant value (sign as `orient3d`), to place points for the report.
    fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64;
    /// Sign of component `axis` of `(b - a) × (c - a)`.
    fn orient2d(a: DVec3, b: DVec3, c: DVec3, axis: usize) -> Sign;
    /// Are the three points collinear?
    fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
        (0..3).all(|k| Self::orient2d(a, b, c, k) == 0)
    }
    /// A projection axis on which the triangle does not collapse.
    fn projection_axis(a: DVec3, b: DVec3, c: DVec3) -> Option<usize> {
        let n = (b - a).cross(c - a).abs();
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
        order.into_iter().find(|&k| Self::orient2d(a, b, c, k) != 0)
    }
}

/// Shewchuk's adaptive exact predicates: signs exact for the f64 inputs.
pub struct Exact;

impl Kernel for Exact {
    #[inline]
    fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
        orient3d(a, b, c, d)
    }
    #[inline]
    fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        orient3d_value(a, b, c, d)
    }
    #[inline]
    fn orient2d(a: DVec3, b: DVec3, c: DVec3, axis: usize) -> Sign {
        orient2d(a, b, c, axis)
    }
}

/// Plain f64 determinants, no error bound, no exact fallback: a sign may be wrong (or zero
/// instead of non-zero, and vice versa) when the points are nearly degenerate.
pub struct Float;

impl Kernel for Float {
    #[inline]
    fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
        sign(Self::orient3d_value(a, b, c, d))
    }
    #[inline]
    fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        (b - a).cross(c - a).dot(d - a)
    }
    #[inline]
    fn orient2d(a: DVec3, b: DVec3, c: DVec3, axis: usize) -> Sign {
        let (u, v) = (b - a, c - a);
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        sign(u[i] * v[j] - u[j] * v[i])
    }
}

/// How much f64 rounding may move a closed-form triangle–triangle distance between inputs whose
/// coordinates are at most `scale` in magnitude: `DISTANCE_ROUNDING_ULPS` ulps of `scale`.
/// The closest-pair search never prunes a node pair whose box distance is within this of the
/// best distance found, so that every pair that could tie is evaluated and the reported pair
/// does not depend on the thread count. It is a search margin, not a tolerance on any verdict.
pub fn distance_rounding_slack(scale: f64) -> f64 {
    DISTANCE_ROUNDING_ULPS * f64::EPSILON * scale
}

/// See [`distance_rounding_slack`]. The closed forms take a few dozen roundings on differences
/// of coordinates; 64 ulps of the coordinate scale bounds them with room to spare.
pub const DISTANCE_ROUNDING_ULPS: f64 = 64.0;

/// User tolerances, all in model units (absolute), all zero by default.
///
/// * `touch`: a pair of triangles that do not share a point but whose f64 closed-form distance
///   is `<= touch` counts as touching (contact `within_tolerance`). With `touch == 0` touching is
///   decided exactly and no distance is consulted.
/// * `clearance`: a pair that does not touch and whose distance is `< clearance` is reported as
///   a clearance finding.
///
/// Distances are computed in f64 closed form (not exactly): a pair whose distance is within a
/// few ulps of a tolerance may fall on either side. Exact contacts never depend on them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tolerances {
    /// Pairs within this distance count as touching.
    pub touch: f64,
    /// Pairs closer than this are clearance findings.
    pub clearance: f64,
}

impl Tolerances {
    /// How far apart two boxes may be and still hold a pair that matters.
    #[inline]
    pub fn search_margin(&self) -> f64 {
        self.touch.max(self.clearance)
    }

    /// Could boxes `a` and `b` hold a pair within the search margin? Exact closed overlap when
    /// the margin is zero; otherwise the f64 box gap compared with the margin (the box gap is
    /// a difference of two input coordinates: at most half an ulp off).
    #[inline]
    pub fn boxes_may_meet(&self, a: &Aabb, b: &Aabb) -> bool {
        let m = self.search_margin();
        if m == 0.0 {
            a.overlaps(b)
        } else {
            a.distance_sq(b) <= m * m
        }
    }

    /// Does a pair at (f64) distance `d`, which does not touch exactly, count as touching?
    #[inline]
    pub fn is_touch(&self, d: f64) -> bool {
        self.touch > 0.0 && d <= self.touch
    }

    /// Is a non-touching pair at distance `d` a clearance finding?
    #[inline]
    pub fn is_clearance(&self, d: f64) -> bool {
        d < self.clearance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient3d_value_is_accurate_near_coplanarity() {
        // d is 2^-40 above the plane z = 0.375 tilted by rounding: the exact value is known.
        let (a, b, c) =
            (DVec3::new(0.0, 0.0, 0.375), DVec3::new(1.0, 0.0, 0.375), DVec3::new(0.0, 1.0, 0.375));
        let h = 2f64.powi(-40);
        let d = DVec3::new(0.3, 0.7, 0.375 + h);
        assert_eq!(orient3d_value(a, b, c, d), h);
        let off = DVec3::splat(1.0e8);
        let v =
            orient3d_value(a + off, b + off, c + off, DVec3::new(0.25, 0.5, 0.375 + 2f64.powi(-20)) + off);
        assert_eq!(v, 2f64.powi(-20));
    }

    #[test]
    fn range_constants_are_powers_of_two() {
        assert_eq!(MAX_EXACT_MAGNITUDE, 2f64.powi(250));
        assert_eq!(MIN_EXACT_MAGNITUDE, 2f64.powi(-250));
    }

    #[test]
    fn orient3d_sign_convention() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert_eq!(orient3d(a, b, c, DVec3::Z), 1);
        assert_eq!(orient3d(a, b, c, -DVec3::Z), -1);
        assert_eq!(orient3d(a, b, c, DVec3::new(5.0, -7.0, 0.0)), 0);
        assert!(orient3d_value(a, b, c, DVec3::Z * 2.0) > 0.0);
    }

    #[test]
    fn orient3d_is_exact_where_floats_round() {
        // d sits 1 ulp above the plane z = 1e8 (spanned by far-away points): naive float
        // evaluation of the determinant loses it; the adaptive predicate does not.
        let z = 1.0e8;
        let a = DVec3::new(1.0e8, 0.0, z);
        let b = DVec3::new(0.0, 1.0e8 + 3.0, z);
        let c = DVec3::new(-1.0e8 + 0.5, -7.0, z);
        let up = f64::from_bits(z.to_bits() + 1);
        assert_eq!(orient3d(a, b, c, DVec3::new(0.25, 0.75, up)), orient3d(a, b, c, a + DVec3::Z));
        assert_eq!(orient3d(a, b, c, DVec3::new(0.25, 0.75, z)), 0);
    }

    #[test]
    fn orient2d_projection_matches_normal_component() {
        let (a, b, c) = (DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0), DVec3::new(-2.0, 0.5, 1.0));
        let n = (b - a).cross(c - a);
        for k in 0..3 {
            assert_eq!(orient2d(a, b, c, k) as f64, n[k].signum());
        }
    }

    #[test]
    fn collinear_and_projection_axis() {
        let a = DVec3::new(0.1, 0.2, 0.3);
        let b = a * 3.0;
        assert!(collinear(a, b, a * 2.0) || !collinear(a, b, a * 2.0)); // rounding may break it
        assert!(collinear(DVec3::ZERO, DVec3::X, DVec3::X * 7.0));
        assert!(collinear(a, a, a));
        assert!(!collinear(DVec3::ZERO, DVec3::X, DVec3::Y));
        assert_eq!(projection_axis(DVec3::ZERO, DVec3::X, DVec3::X * 2.0), None);
        assert_eq!(projection_axis(DVec3::ZERO, DVec3::X, DVec3::Y), Some(2));
    }

    #[test]
    fn tolerance_semantics() {
        let t = Tolerances::default();
        assert!(!t.is_touch(0.0), "zero tolerance never consults distances");
        assert!(!t.is_clearance(0.0));
        let t = Tolerances { touch: 0.5, clearance: 2.0 };
        assert!(t.is_touch(0.5) && !t.is_touch(0.51));
        assert!(t.is_clearance(1.99) && !t.is_clearance(2.0));
        let a = Aabb { min: DVec3::ZERO, max: DVec3::ONE };
        let b = Aabb { min: DVec3::new(3.0, 0.0, 0.0), max: DVec3::new(4.0, 1.0, 1.0) };
        assert!(t.boxes_may_meet(&a, &b));
        assert!(!Tolerances::default().boxes_may_meet(&a, &b));
    }
}
