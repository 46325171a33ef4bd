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
//! In front of the adaptive predicates, [`orient3d`] runs cheaper stages that each answer only
//! when they have proven the sign: a float filter with a rigorous forward error bound
//! ([`PlaneFilter`], [`ORIENT3D_FILTER_BOUND`]; derivation in the "Filters" notes below, valid
//! over the whole exact range, tiny inputs always falling through), a repeated point (exactly
//! zero), and an exact integer evaluation for coordinates that are short binary fractions
//! ([`orient3d_dyadic`]). [`orient3d_adaptive`] is the adaptive predicate alone: the reference.
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
///
/// Stages, each exact when it answers (see the "Filters" notes in this module): the f64 determinant with its
/// forward error bound ([`PlaneFilter`]); a repeated point (the determinant is then exactly 0);
/// the integer evaluation of [`orient3d_dyadic`]; Shewchuk's adaptive predicate.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    match PlaneFilter::new(&[a, b, c]).side(d) {
        Some(s) => s,
        None => orient3d_undecided(a, b, c, d),
    }
}

/// The exact sign when the f64 filter could not decide: cheap exact special cases first, then
/// the adaptive predicate.
#[inline(never)]
pub fn orient3d_undecided(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    if d == a || d == b || d == c || a == b || a == c || b == c {
        return 0; // two equal rows: the determinant is exactly zero
    }
    match orient3d_dyadic(a, b, c, d) {
        Some(s) => s,
        None => orient3d_adaptive(a, b, c, d),
    }
}

/// [`orient3d`] by Shewchuk's adaptive predicate alone (no filter of ours in front): the
/// reference the filtered stages are tested against.
#[inline]
pub fn orient3d_adaptive(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    // robust's convention is the opposite ("positive when d is below").
    -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

// # Filters
//
// A float filter evaluates a determinant in f64 and answers only when the rounded value is
// farther from zero than a rigorous bound on its rounding error; otherwise the caller falls
// back to exact arithmetic. Error analysis (Higham, "Accuracy and Stability of Numerical
// Algorithms", §3.1): with round-to-nearest, unit roundoff ε = 2^-53 and no underflow or
// overflow, a value obtained from exact inputs through k roundings is the exact value times
// (1 + θ), |θ| <= γ_k = kε / (1 - kε).
//
// * orient3d as evaluated here: u = b - a, v = c - a, w = d - a (one rounding each), the normal
//   n = u × v (a product and a subtraction: n_x = u_y·v_z - v_y·u_z), then n·w summed as
//   (n_x w_x + n_y w_y) + n_z w_z. Each of the six monomials ±U_i·V_j·W_k of the exact
//   determinant (U, V, W the exact differences) passes through at most 3 + 1 + 1 + 1 + 2 = 8
//   roundings, so |det_f64 - det| <= γ_8 · P where P = Σ|U_i V_j W_k| is the permanent. The
//   permanent is computed as P_f64 = (|n|-permanent m)·|w| with m_x = |u_y v_z| + |v_y u_z|
//   (the same rounded products), itself at most 8 roundings from the exact one, so
//   P <= P_f64 / (1 - γ_8). With the bound computed as fl(fl(C3·P_f64) + A) and C3 = 9ε:
//   9ε(1 - ε)² >= 8ε(1 + 17ε) >= γ_8 / (1 - γ_8), so `|det_f64| > bound` proves the sign.
// * orient2d (component k of u × v): 2 differences, a product, a subtraction: 4 roundings, the
//   permanent m_k as above (4 roundings); C2 = 5ε since 5ε(1 - ε)² >= 4ε(1 + 9ε).
// * Underflow and overflow. Inside the exact range (module doc) neither happens: differences
//   of coordinates in [2^-250, 2^250] ∪ {0} are 0 or at least 2^-302, so every product of up
//   to three of them is a normal number, and at most 2^756. Coordinates below the range are
//   accepted by the loader (with a warning): gradual underflow makes additions exact and adds
//   at most 2^-1075 absolute error to each product; through the later products (factors at
//   most 2^251) and sums that is below 2^-820 in total. The absolute allowance
//   A = 2^-800 ([`FILTER_UNDERFLOW_ALLOWANCE`]) covers it, so tiny inputs (whose determinants
//   are all below A) always take the exact path. An overflow makes the bound infinite or the
//   value NaN, and every comparison false: the exact path again.

/// Unit roundoff of f64 (round to nearest): 2^-53.
const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// Relative error constant of the orient3d filter: `|det_f64 - det| <= C3 · P_f64` (derived in
/// the module source, "Filters": γ_8 / (1 - γ_8) rounded up to 9ε).
pub const ORIENT3D_FILTER_BOUND: f64 = 9.0 * UNIT_ROUNDOFF;

/// Relative error constant of the orient2d (normal component) filter: γ_4 / (1 - γ_4) rounded
/// up to 5ε.
pub const ORIENT2D_FILTER_BOUND: f64 = 5.0 * UNIT_ROUNDOFF;

/// Absolute error allowance of the filters for underflow (2^-800): see "Filters" above.
pub const FILTER_UNDERFLOW_ALLOWANCE: f64 = f64::from_bits((1023 - 800) << 52);

/// Float filter data of one triangle `(a, b, c)`: its f64 normal `(b - a) × (c - a)` and the
/// permanents of the normal's components, computed once and reused for every point tested
/// against the triangle's plane.
#[derive(Debug, Clone, Copy)]
pub struct PlaneFilter {
    origin: DVec3,
    normal: DVec3,
    perm: DVec3,
}

impl PlaneFilter {
    /// The filter data of triangle `t`.
    #[inline]
    pub fn new(t: &[DVec3; 3]) -> PlaneFilter {
        let (u, v) = (t[1] - t[0], t[2] - t[0]);
        // The same expressions as glam's `cross`, so `normal` is bit-identical to
        // `(b - a).cross(c - a)` wherever that is computed.
        let normal = u.cross(v);
        let perm = DVec3::new(
            (u.y * v.z).abs() + (v.y * u.z).abs(),
            (u.z * v.x).abs() + (v.z * u.x).abs(),
            (u.x * v.y).abs() + (v.x * u.y).abs(),
        );
        PlaneFilter { origin: t[0], normal, perm }
    }

    /// The f64 normal `(b - a) × (c - a)`.
    #[inline]
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// The exact sign of component `k` of the normal (= [`orient2d`] of the triangle in
    /// projection `k`) if the filter proves it, else `None`.
    #[inline]
    pub fn normal_sign(&self, k: usize) -> Option<Sign> {
        let e = ORIENT2D_FILTER_BOUND * self.perm[k] + FILTER_UNDERFLOW_ALLOWANCE;
        decided(self.normal[k], e)
    }

    /// True if the filter proves the triangle proper (some normal component is non-zero, so it
    /// is not collinear); false if it cannot tell.
    #[inline]
    pub fn proper(&self) -> bool {
        let e = self.perm * ORIENT2D_FILTER_BOUND + DVec3::splat(FILTER_UNDERFLOW_ALLOWANCE);
        let n = self.normal.abs();
        n.x > e.x || n.y > e.y || n.z > e.z
    }

    /// The exact sign of `orient3d(a, b, c, p)` if the filter proves it, else `None`.
    #[inline]
    pub fn side(&self, p: DVec3) -> Option<Sign> {
        let w = p - self.origin;
        let d = self.normal.dot(w);
        let e = ORIENT3D_FILTER_BOUND * self.perm.dot(w.abs()) + FILTER_UNDERFLOW_ALLOWANCE;
        decided(d, e)
    }

    /// The exact sign of `orient3d(t[0], t[1], t[2], p)`, `t` the triangle this filter was
    /// made from: the filter, else the exact stages of [`orient3d`].
    #[inline]
    pub fn side_exact(&self, t: &[DVec3; 3], p: DVec3) -> Sign {
        match self.side(p) {
            Some(s) => s,
            None => orient3d_undecided(t[0], t[1], t[2], p),
        }
    }
}

/// `Some(sign of v)` if `|v| > e`, else `None` (also when either is NaN).
#[inline]
fn decided(v: f64, e: f64) -> Option<Sign> {
    if v > e {
        Some(1)
    } else if -v > e {
        Some(-1)
    } else {
        None
    }
}

/// Largest magnitude (in bits) of the coordinate differences [`orient3d_dyadic`] multiplies:
/// three factors below 2^41 keep every monomial below 2^123 and the determinant below 2^126,
/// inside i128.
const DYADIC_DIFF_BITS: u32 = 41;

/// Exact orient3d in integer arithmetic when the inputs allow it (common for exactly coplanar
/// input whose coordinates are short binary fractions: grids, f32 data, nearby points far from
/// the origin). Per axis, the four coordinates scaled by one power of two `2^-L_axis` (so that
/// the largest is below 2^62) must all be integers: then they are exact i64 values, and so are
/// their differences. Every monomial of the determinant takes
/// one difference from each axis, so the determinant is `2^(L_x + L_y + L_z)` times the integer
/// determinant, computed exactly in i128 when the differences are below 2^41. `None` when the
/// inputs do not allow it (then the adaptive predicate decides).
pub fn orient3d_dyadic(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<Sign> {
    // Per axis: the components of u = b - a, v = c - a, w = d - a (in that axis's units).
    let dx = axis_differences([a.x, b.x, c.x, d.x])?;
    let dy = axis_differences([a.y, b.y, c.y, d.y])?;
    let dz = axis_differences([a.z, b.z, c.z, d.z])?;
    // Each below 2^41 in magnitude: the normal's components are below 2^83, the determinant
    // below 2^126.
    let (ux, uy, uz) = (dx[0] as i128, dy[0] as i128, dz[0] as i128);
    let (vx, vy, vz) = (dx[1] as i128, dy[1] as i128, dz[1] as i128);
    let (wx, wy, wz) = (dx[2] as i128, dy[2] as i128, dz[2] as i128);
    let n = [uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx];
    let det = n[0] * wx + n[1] * wy + n[2] * wz;
    Some(det.signum() as Sign)
}

/// For one axis, the coordinates `[a, b, c, d]` as exact integer multiples of one power of two
/// `2^L`, their lowest set bit (`None` if the four do not fit a 62-bit window), and their
/// differences `[b - a, c - a, d - a]` in units of
/// `2^L` (`None` if one is 2^41 or more).
#[inline]
fn axis_differences(xs: [f64; 4]) -> Option<[i64; 3]> {
    let top = xs.iter().map(|x| (x.to_bits() >> 52) & 0x7ff).max().unwrap_or(0);
    if top == 0 {
        // All zero (or subnormal: left to the adaptive predicate).
        return xs.iter().all(|&x| x == 0.0).then_some([0; 3]);
    }
    // |x| < 2^(top - 1022) for all four; scaling by 2^(1084 - top) (exact: a power of two)
    // puts them below 2^62. The scale's biased exponent 2107 - top is a normal one when
    // top >= 62 (smaller coordinates: below 2^-960, left to the adaptive predicate).
    if top < 62 {
        return None;
    }
    let scale = f64::from_bits((2107 - top) << 52);
    let mut ints = [0i64; 4];
    for (x, out) in xs.iter().zip(ints.iter_mut()) {
        let t = x * scale;
        // |t| < 2^62: the conversion truncates exactly, and converts back exactly iff `t` is an
        // integer. A non-zero coordinate must not have been lost to underflow.
        let i = t as i64;
        if i as f64 != t || (t == 0.0) != (*x == 0.0) {
            return None;
        }
        *out = i;
    }
    // Drop the trailing zero bits common to all four (exact), so that L is their lowest set bit.
    let common = ints.iter().fold(0i64, |acc, &v| acc | v).trailing_zeros().min(62);
    let ints = ints.map(|v| v >> common);
    let mut diffs = [0i64; 3];
    for (r, out) in diffs.iter_mut().enumerate() {
        let v = ints[r + 1] - ints[0]; // below 2^63 in magnitude: no overflow
        if v.unsigned_abs() >= 1u64 << DYADIC_DIFF_BITS {
            return None;
        }
        *out = v;
    }
    Some(diffs)
}

/// The determinant of [`orient3d`] as a value, used only to place intersection points for the
/// report, never to decide. Evaluated in double-double arithmetic (about 106 bits) from exact
/// coordinate differences, so that points are placed accurately even when a vertex is within
/// rounding of the other plane (where the f64 value has no correct digits); its sign is forced
/// to the exact one.
pub fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    orient3d_value_signed(a, b, c, d, orient3d(a, b, c, d))
}

/// [`orient3d_value`] when the exact sign `s` of the determinant is already known (it must be
/// `orient3d(a, b, c, d)`): the same value without deciding the sign again.
pub fn orient3d_value_signed(a: DVec3, b: DVec3, c: DVec3, d: DVec3, s: Sign) -> f64 {
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

    #[inline(always)]
    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }

    #[inline(always)]
    fn add(x: Dd, y: Dd) -> Dd {
        let s = two_sum(x.0, y.0);
        let lo = s.1 + x.1 + y.1;
        let h = s.0 + lo;
        Dd(h, lo - (h - s.0))
    }

    #[inline(always)]
    fn neg(x: Dd) -> Dd {
        Dd(-x.0, -x.1)
    }

    #[inline(always)]
    fn mul(x: Dd, y: Dd) -> Dd {
        let p = x.0 * y.0;
        let e = x.0.mul_add(y.0, -p);
        let lo = e + (x.0 * y.1 + x.1 * y.0);
        let h = p + lo;
        Dd(h, lo - (h - p))
    }

    /// `((b - a) × (c - a)) · (d - a)`, differences exact.
    ///
    /// `mul` needs a fused multiply-add; without the target feature `f64::mul_add` is a
    /// software routine (hundreds of instructions), so on x86-64 CPUs that have FMA the same
    /// code is run compiled for it. Both are the correctly rounded IEEE fma: the same bits.
    pub(super) fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports FMA (checked just above), the only requirement of a
            // `target_feature(enable = "fma")` function.
            return unsafe { orient3d_fma(a, b, c, d) };
        }
        orient3d_portable(a, b, c, d)
    }

    /// [`orient3d_portable`] compiled with hardware FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "fma")]
    fn orient3d_fma(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        orient3d_portable(a, b, c, d)
    }

    #[inline(always)]
    fn orient3d_portable(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
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
///
/// Float-filtered: a component whose f64 value exceeds Shewchuk's first error bound of the 2D
/// orientation ([`CCW_ERRBOUND_A`], the bound `robust::orient2d` applies before its exact
/// stages) is certainly non-zero, so a proper triangle is answered from three pairs of
/// f64 products; only the components the bound cannot decide go to the exact predicate.
#[inline]
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let (u, v) = (b - a, c - a);
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        // orient2d(b, c, a) on the plane of axes i, j (a cyclic turn of (a, b, c): same sign).
        let (l, r) = (u[i] * v[j], u[j] * v[i]);
        if (l - r).abs() > CCW_ERRBOUND_A * (l.abs() + r.abs()) {
            return false;
        }
    }
    // Two equal vertices make any triangle collinear: no exact stage needed (zero-area
    // triangles of tessellated input are mostly of this kind).
    if a == b || b == c || a == c {
        return true;
    }
    (0..3).all(|k| orient2d(a, b, c, k) == 0)
}

/// Shewchuk's `ccwerrboundA` = (3 + 16ε)ε with ε = 2⁻⁵³: when the f64 value of a 2D
/// orientation determinant, computed from rounded coordinate differences, exceeds this times
/// the sum of its two products' magnitudes, its sign is the exact sign (for coordinates within
/// [`MIN_EXACT_MAGNITUDE`], [`MAX_EXACT_MAGNITUDE`], where nothing underflows).
pub const CCW_ERRBOUND_A: f64 = (3.0 + 16.0 * (f64::EPSILON / 2.0)) * (f64::EPSILON / 2.0);

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

/// Exact: is every `b[i]` the point `a[i]` translated by one common vector `t`, in real
/// arithmetic (`b[i] = a[i] + t` with no rounding)? Then `Some(t)`. Each coordinate sum is
/// checked with Knuth's TwoSum, whose error term is exact for finite inputs without overflow:
/// the sum is exact iff its rounded value is `b` and the error is zero. An exact translation
/// preserves every orientation sign (the coordinate differences are the same reals), so every
/// verdict built from them is the same for `a` and `b`.
pub fn exact_translation(a: &[DVec3], b: &[DVec3]) -> Option<DVec3> {
    if a.len() != b.len() || a.is_empty() {
        return None;
    }
    let exact_sum = |x: f64, y: f64, want: f64| {
        let s = x + y;
        let yy = s - x;
        let err = (x - (s - yy)) + (y - yy);
        s == want && err == 0.0 && s.is_finite()
    };
    let t = b[0] - a[0];
    let ok = (0..3).all(|k| exact_sum(a[0][k], t[k], b[0][k]))
        && a.iter().zip(b).all(|(p, q)| (0..3).all(|k| exact_sum(p[k], t[k], q[k])));
    ok.then_some(t)
}

/// The predicates a classification is built from. [`Exact`] is the product; [`Adaptive`] the
/// same exact signs without our filters (the reference they are tested against); [`Float`]
/// exists to measure what exactness costs and buys (`--mode fast`).
pub trait Kernel {
    /// Sign of `((b - a) × (c - a)) · (d - a)`.
    fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign;
    /// The determinant value (sign as `orient3d`), to place points for the report.
    fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64;
    /// [`Kernel::orient3d_value`] when `s = Self::orient3d(a, b, c, d)` is already known.
    fn orient3d_value_signed(a: DVec3, b: DVec3, c: DVec3, d: DVec3, s: Sign) -> f64 {
        let _ = s;
        Self::orient3d_value(a, b, c, d)
    }
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

/// Exact predicates: signs exact for the f64 inputs (our filters, then Shewchuk's adaptive
/// predicates).
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
    fn orient3d_value_signed(a: DVec3, b: DVec3, c: DVec3, d: DVec3, s: Sign) -> f64 {
        orient3d_value_signed(a, b, c, d, s)
    }
    #[inline]
    fn orient2d(a: DVec3, b: DVec3, c: DVec3, axis: usize) -> Sign {
        orient2d(a, b, c, axis)
    }
}

/// Shewchuk's adaptive predicates alone, without our filters in front: the exact reference
/// (the classification as it was before the filters) that the filtered path is tested and
/// measured against.
pub struct Adaptive;

impl Kernel for Adaptive {
    #[inline]
    fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
        orient3d_adaptive(a, b, c, d)
    }
    #[inline]
    fn orient3d_value(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        orient3d_value_signed(a, b, c, d, orient3d_adaptive(a, b, c, d))
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

/// Rounding of an f64 projection `n · p` ([`apart_along`]), in ulps of
/// `(|n_x| + |n_y| + |n_z|) · max_i |p_i|`: three products and two sums are within
/// `γ_3 ≈ 1.5` ulps of that of the exact value; 4 covers it with room (the bound's own
/// rounding included).
pub const PROJECTION_ROUNDING_ULPS: f64 = 4.0;

/// Exact: are the convex hulls of the points `xs` and `ys` strictly apart along the direction
/// `n` (any f64 vector, taken as exact)? True when the f64 projections of one set all lie
/// below those of the other by more than three times their rounding bound
/// ([`PROJECTION_ROUNDING_ULPS`], plus [`FILTER_UNDERFLOW_ALLOWANCE`]): then every exact
/// projection of the one is below every exact projection of the other, so no point is shared.
/// False proves nothing (a zero or non-finite `n` always gives false).
pub fn apart_along<'a>(
    n: DVec3,
    xs: impl Iterator<Item = &'a DVec3>,
    ys: impl Iterator<Item = &'a DVec3>,
) -> bool {
    let range = |ps: &mut dyn Iterator<Item = &'a DVec3>| {
        ps.fold((f64::INFINITY, f64::NEG_INFINITY, 0.0f64), |(lo, hi, m), p| {
            let d = n.dot(*p);
            (lo.min(d), hi.max(d), m.max(p.abs().max_element()))
        })
    };
    let ((xlo, xhi, xm), (ylo, yhi, ym)) = (range(&mut { xs }), range(&mut { ys }));
    let e = PROJECTION_ROUNDING_ULPS * f64::EPSILON * n.abs().element_sum() * xm.max(ym)
        + FILTER_UNDERFLOW_ALLOWANCE;
    // The computed difference is within one rounding of the exact one: above 3e, the exact
    // difference exceeds 2e, the most the two projections' roundings can take off it.
    ylo - xhi > 3.0 * e || xlo - yhi > 3.0 * e
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

/// How much f64 rounding may raise an oriented (slab) lower bound on a distance
/// ([`crate::bvh::slab`]) above the true distance, for coordinates at most `scale` in magnitude:
/// `ORIENTED_BOUND_ROUNDING_ULPS` ulps of `scale`. The search subtracts it from every oriented
/// bound before pruning, so an oriented bound never prunes a pair a box bound would keep for a
/// reason other than geometry. A search margin, not a tolerance on any verdict.
pub fn oriented_bound_margin(scale: f64) -> f64 {
    ORIENTED_BOUND_ROUNDING_ULPS * f64::EPSILON * scale
}

/// See [`oriented_bound_margin`]. A slab bound reads projections (three products and two sums
/// each, on vectors of norm 1 to rounding) back through a second frame that is orthonormal to a
/// few ulps: each step loses at most a few ulps of the largest coordinate; 64 covers their sum
/// several times over.
pub const ORIENTED_BOUND_ROUNDING_ULPS: f64 = 64.0;

/// Relative widening (in ulps) of a segment's entry and exit parameters across a box's slabs
/// ([`crate::bvh::traverse::any_on_segment`]): each parameter is one subtraction and one
/// product away from exact (a few ulps); widening by 8 ulps of its magnitude plus 8 ulps absolute
/// keeps every box the segment touches. Pruning only: the crossings themselves are decided by
/// the exact segment–triangle test.
pub const SEGMENT_BOX_ROUNDING_ULPS: f64 = 8.0;

/// Half-width of the band around a tolerance inside which a pair's f64 closed-form distance
/// does not decide `distance <= touch` or `distance < clearance`, for triangles (and tolerance)
/// at most `scale` in magnitude: the exact distance decides there
/// ([`crate::narrow::exact_distance`]). `THRESHOLD_FILTER_ULPS` ulps of `scale`.
pub fn threshold_filter_margin(scale: f64) -> f64 {
    THRESHOLD_FILTER_ULPS * f64::EPSILON * scale
}

/// See [`threshold_filter_margin`]: 64 times the bound on the closed forms' rounding
/// ([`DISTANCE_ROUNDING_ULPS`]), so the f64 value decides only where it cannot be on the wrong
/// side. The band is a filter, not a tolerance: inside it the exact comparison answers.
pub const THRESHOLD_FILTER_ULPS: f64 = 64.0 * DISTANCE_ROUNDING_ULPS;

/// User tolerances, all in model units (absolute), all zero by default.
///
/// * `touch`: a pair of triangles that do not share a point but whose distance is `<= touch`
///   counts as touching (contact `within_tolerance`). With `touch == 0` touching is decided
///   exactly and no distance is consulted.
/// * `clearance`: a pair that does not touch and whose distance is `< clearance` is reported as
///   a clearance finding.
///
/// Both comparisons are exact ([`Tolerances::within`]): the f64 closed-form distance decides
/// when it is farther than [`threshold_filter_margin`] from the tolerance, the exact rational
/// distance otherwise.
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
            // Widened by the threshold band: the exact comparisons decide the pairs inside it.
            let reach = m + threshold_filter_margin(a.max_abs().max(b.max_abs()).max(m));
            a.distance_sq(b) <= reach * reach
        }
    }

    /// Does a pair at (f64) distance `d`, which does not touch exactly, count as touching?
    /// The f64 comparison alone (see [`Tolerances::within`] for the exact one).
    #[inline]
    pub fn is_touch(&self, d: f64) -> bool {
        self.touch > 0.0 && d <= self.touch
    }

    /// Is a non-touching pair at distance `d` a clearance finding? The f64 comparison alone.
    #[inline]
    pub fn is_clearance(&self, d: f64) -> bool {
        d < self.clearance
    }

    /// Exactly: is the distance of a pair within `limit` (`<=` when `inclusive`, else `<`)?
    /// `d` is its f64 closed-form distance, `scale` the largest coordinate magnitude of the two
    /// triangles; `exact` gives the order of the exact distance against a value, and is called
    /// only when `d` lies within [`threshold_filter_margin`] of `limit`.
    #[inline]
    pub fn within(
        d: f64,
        limit: f64,
        inclusive: bool,
        scale: f64,
        exact: impl FnOnce(f64) -> std::cmp::Ordering,
    ) -> bool {
        let band = threshold_filter_margin(scale.max(limit));
        if d < limit - band {
            true
        } else if d > limit + band {
            false
        } else {
            let o = exact(limit);
            o.is_lt() || (inclusive && o.is_eq())
        }
    }
}

/// A box map that is wider than this many ulps of its coordinate scale (see [`BoxMap::fit`]) is
/// refused: the instance's coordinates are then not (to rounding) an affine image of the shared
/// tree's, and it gets its own refitted boxes instead. Only a cost threshold: any accepted map
/// is conservative.
pub const BOX_MAP_MAX_DEVIATION_ULPS: f64 = 1024.0;

/// The grid cell of the prepared meshes' vertex-separation bound, relative to the coordinates'
/// scale: a separation below it is measured, above it only `cell / 2` is claimed (far above the
/// rounding of any placement).
pub const MARGIN_CELL: f64 = 1.0 / (1u64 << 20) as f64;

/// A lower bound of every height of the triangle `[a, b, c]` whatever the f64 rounding: twice
/// the area over the longest edge, `|(b - a) × (c - a)| / L`. The f64 cross product is within
/// `16u L²` of the exact one (two rounded differences per factor, two products and a difference
/// per component: a few `u` of `L²` each); the result is lowered by that and by `4u` relative for
/// the norm and the quotient. Not positive (or NaN) when the triangle may be degenerate.
pub fn height_lower_bound([a, b, c]: [DVec3; 3]) -> f64 {
    let u = UNIT_ROUNDOFF;
    let l2 = (b - a).length_squared().max((c - a).length_squared()).max((c - b).length_squared());
    let cross = (b - a).cross(c - a).length();
    let area2 = cross * (1.0 - 4.0 * u) - 16.0 * u * l2 * (1.0 + 4.0 * u);
    area2 / (l2.sqrt() * (1.0 + 4.0 * u)) * (1.0 - 4.0 * u)
}

/// A lower bound of the exact distance between `p` and `q`: the f64 distance (`4u` relative
/// error at most) lowered by `8u`.
pub fn distance_lower_bound(p: DVec3, q: DVec3) -> f64 {
    (p - q).length() * (1.0 - 8.0 * UNIT_ROUNDOFF)
}

/// Where a sweep over boxes sorted by their lower x must start looking for the boxes that meet
/// a box whose lower x is `min_x`, when every box's x extent, computed in f64, is at most
/// `widest`: no box with a lower x below the result meets it. Proof: a box `[lo, hi]` that
/// meets it has `hi >= min_x`; if `lo < min_x`, its exact width `hi - lo` is at least
/// `D = min_x - lo > 0`, so `widest >= fl(hi - lo) >= fl(D) >= (1 - u) D` (rounding is
/// monotone), and `min_x - 2 widest <= min_x - 2 (1 - u) D < lo`; the f64 subtraction rounds
/// monotonically and `lo` is an f64, so the computed start is at most `lo`.
pub fn sweep_start(min_x: f64, widest: f64) -> f64 {
    min_x - 2.0 * widest
}

/// What rounding under one placement can do to a mesh's coincidences and degenerate
/// triangles. A placement maps each vertex `p` to an f64 `w` within `delta` (a length: the box
/// map's per-axis slack, as a vector norm) of the exact affine image `R p + t`; `low`, `high`
/// bound `R`'s smallest and largest singular values ([`singular_value_bounds`]).
///
/// * Two vertices at least `d` apart have exact images at least `low · d` apart, so their f64
///   images differ when `low · d > 2 delta`.
/// * A triangle whose heights are all at least `h` has an exact image whose heights are all at
///   least `low² / high · h` (twice its area scales by at least `low²`, each edge by at most
///   `high`), and moving each vertex of a triangle whose heights all exceed `5 delta` by at most
///   `delta` cannot make it collinear (its area, half its longest edge `L` times its smallest
///   height, drops by at most `2 delta (L + delta)`).
///
/// The tests below use `3 delta` and `6 delta`: room for the rounding of the comparisons
/// themselves (a few ulps of each side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacementRounding {
    /// At most the smallest singular value of the linear part.
    pub low: f64,
    /// At least the largest singular value of the linear part.
    pub high: f64,
    /// At least the distance of any placed vertex from its exact image.
    pub delta: f64,
}

impl PlacementRounding {
    /// The rounding of a placement by `map` (its vertices in the map's source root box).
    pub fn of(map: &BoxMap) -> PlacementRounding {
        let (low, high) = singular_value_bounds(&map.rows);
        PlacementRounding { low, high, delta: map.slack.length() }
    }

    /// Certainly distinct after the placement: two vertices whose distance is at least
    /// `separation` ([`distance_lower_bound`]). False for NaN.
    pub fn keeps_apart(&self, separation: f64) -> bool {
        self.low * separation > 3.0 * self.delta
    }

    /// Certainly a proper triangle after the placement: one whose heights are at least `height`
    /// ([`height_lower_bound`]). False for NaN or a bound that is not positive.
    pub fn keeps_proper(&self, height: f64) -> bool {
        height > 0.0 && self.low * self.low / self.high * height > 6.0 * self.delta
    }
}

/// Bounds of the smallest and largest singular values of the linear part of `rows` (the map's
/// 3x3 matrix `R`): square roots of Gershgorin's bounds on the eigenvalues of `G = RᵀR`,
/// `min_j (G_jj - Σ_{k≠j} |G_jk|)` and `max_j Σ_k |G_jk|`. Each f64 entry `Ĝ_jk` (three
/// products, two sums) is within `γ_3 · H_jk` of `G_jk`, `H_jk = Σ_i |r_ij| |r_ik|` (Higham,
/// §3.1): `4u · H_jk` widens every entry; the final sums and square roots round by a few ulps,
/// covered by the factors `1 ∓ 16u`. Both 1 (to a few ulps) for a rotation.
pub fn singular_value_bounds(rows: &[[f64; 4]; 3]) -> (f64, f64) {
    let u = UNIT_ROUNDOFF;
    let (mut low, mut high) = (f64::INFINITY, 0.0f64);
    for j in 0..3 {
        let (mut diag, mut off, mut widen) = (0.0, 0.0, 0.0);
        for k in 0..3 {
            let g: f64 = (0..3).map(|i| rows[i][j] * rows[i][k]).sum();
            let h: f64 = (0..3).map(|i| (rows[i][j] * rows[i][k]).abs()).sum();
            widen += 4.0 * u * h;
            if k == j {
                diag = g;
            } else {
                off += g.abs();
            }
        }
        high = high.max(diag.abs() + off + widen);
        low = low.min(diag - off - widen);
    }
    (low.max(0.0).sqrt() * (1.0 - 16.0 * u), high.sqrt() * (1.0 + 16.0 * u))
}

/// A conservative affine map of boxes, so that instances of one mesh can share one tree: the
/// tree is built over one instance's coordinates `x` (the *source*), and another instance's
/// coordinates `w` (the *target*, computed independently, e.g. by the loader from the mesh's
/// local coordinates) are, up to rounding, `R x + t`.
///
/// [`BoxMap::map_box`] returns a box that contains every target vertex whose source lies in the
/// given box, whatever the rounding of the target coordinates and of the map itself. Proof, per
/// output axis `i`, for a box `[lo, hi]` inside the source root box: let
/// `S_i = |t_i| + Σ_j |r_ij|·max(|root.min_j|, |root.max_j|)`.
/// * The exact range of `(R x + t)_i` over the box is `[L_i, U_i]` with
///   `L_i = t_i + Σ_j min(r_ij·lo_j, r_ij·hi_j)` (a corner per term by the sign of `r_ij`). Its f64
///   evaluation (three products, three sums, in a fixed order) is within `γ_4·S_i` of it
///   (Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1; `γ_n = n·u/(1 − n·u)`,
///   `u = 2^-53`).
/// * Every target vertex is within `dev_i` of the exact image of its source; [`BoxMap::fit`]
///   measures it: the largest f64 `|w_i − fl(R x + t)_i|` over all vertices, which is at least
///   `(1 − u)·|w_i − fl(…)|`, plus `γ_4·S_i` for the rounding of `fl(R x + t)`.
/// * The final `lo − slack` / `hi + slack` rounds by at most `u·(|L̂_i| + slack_i)`.
///
/// So `slack_i ≥ (2γ_4 + u(1 + γ_4))·S_i + dev/(1 − u)` over `(1 − u)` suffices; the map uses
/// `16u·S_i + 2·dev_i + 2^-1022` (roughly twice that; the last term covers products that
/// underflow, each off by at most 2^-1075), and `S_i`, `dev_i` are computed in f64 with a
/// relative error far below the factor 2 of margin. A looser box only costs time; a tighter one
/// could cull a touching pair, so the margin errs outward.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxMap {
    /// The rows `[r_i0, r_i1, r_i2, t_i]` of the affine map (source → target).
    pub rows: [[f64; 4]; 3],
    /// Per output axis, added outward to both sides of every mapped box.
    pub slack: DVec3,
}

impl BoxMap {
    /// Row `i` applied to `x`, in the fixed order the error bound assumes.
    #[inline]
    fn eval(r: &[f64; 4], x: [f64; 3]) -> f64 {
        r[0] * x[0] + r[1] * x[1] + r[2] * x[2] + r[3]
    }

    /// The map `rows` from the source vertices to the target vertices (`pairs` yields each
    /// vertex as (source, target)), with its slack measured over all of them; `source_root` is
    /// a box containing every source vertex (the tree's root). `None` when the map is not
    /// finite or the target is further than [`BOX_MAP_MAX_DEVIATION_ULPS`] ulps of the scale
    /// from the image of the source (not an instance of the same geometry to rounding).
    pub fn fit(
        rows: [[f64; 4]; 3],
        source_root: &Aabb,
        pairs: impl Iterator<Item = (DVec3, DVec3)>,
    ) -> Option<BoxMap> {
        if rows.iter().flatten().any(|x| !x.is_finite()) {
            return None;
        }
        let big = source_root.min.abs().max(source_root.max.abs()).to_array();
        let scale = rows.map(|r| r[3].abs() + (0..3).map(|j| r[j].abs() * big[j]).sum::<f64>());
        let mut dev = [0.0f64; 3];
        for (x, w) in pairs {
            let (x, w) = (x.to_array(), w.to_array());
            for i in 0..3 {
                let d = (w[i] - Self::eval(&rows[i], x)).abs();
                if d.is_nan() {
                    return None;
                }
                dev[i] = dev[i].max(d);
            }
        }
        let u = f64::EPSILON / 2.0;
        let mut slack = [0.0f64; 3];
        for i in 0..3 {
            if !scale[i].is_finite() || dev[i] > BOX_MAP_MAX_DEVIATION_ULPS * f64::EPSILON * scale[i] {
                return None;
            }
            slack[i] = 16.0 * u * scale[i] + 2.0 * dev[i] + f64::MIN_POSITIVE;
        }
        Some(BoxMap { rows, slack: DVec3::from_array(slack) })
    }

    /// The f64 image of `p` (each row evaluated in the fixed order the slack bound assumes): within
    /// `slack` per axis of the exact image of `p` for points in the source root box.
    pub fn image(&self, p: DVec3) -> DVec3 {
        let x = p.to_array();
        DVec3::new(Self::eval(&self.rows[0], x), Self::eval(&self.rows[1], x), Self::eval(&self.rows[2], x))
    }

    /// A box containing every target vertex whose source vertex lies in `b` (which must lie in
    /// the source root given to [`BoxMap::fit`]).
    #[inline]
    pub fn map_box(&self, b: &Aabb) -> Aabb {
        let (lo, hi) = (b.min.to_array(), b.max.to_array());
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        for i in 0..3 {
            let r = &self.rows[i];
            let pick = |j: usize, low: bool| if (r[j] >= 0.0) == low { lo[j] } else { hi[j] };
            min[i] = Self::eval(r, [pick(0, true), pick(1, true), pick(2, true)]);
            max[i] = Self::eval(r, [pick(0, false), pick(1, false), pick(2, false)]);
        }
        Aabb { min: DVec3::from_array(min) - self.slack, max: DVec3::from_array(max) + self.slack }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `apart_along` never separates point sets that share a point, whatever the direction;
    /// separates sets moved apart along the direction by far more than rounding; and, on small
    /// integer inputs (every projection exact), is true only where the exact projections are
    /// apart.
    #[test]
    fn apart_along_is_never_wrong() {
        let mut next = crate::load::test_rng(0xA11A_5EED);
        let mut unit = move || next(1 << 30) as f64 / (1u64 << 30) as f64 - 0.5;
        let (mut separated, mut exact_true) = (0, 0);
        for k in 0..3000 {
            let scale = [1.0, 1.0e-6, 3.0e5][k % 3];
            let n = DVec3::new(unit(), unit(), unit());
            let xs: Vec<DVec3> = (0..6).map(|_| DVec3::new(unit(), unit(), unit()) * scale).collect();
            let mut ys: Vec<DVec3> = (0..6).map(|_| DVec3::new(unit(), unit(), unit()) * scale).collect();
            // A shared point: never apart.
            ys[k % 6] = xs[(k / 6) % 6];
            assert!(!apart_along(n, xs.iter(), ys.iter()), "{k}");
            // Moved along n past the other set's projections: apart.
            let span = xs.iter().chain(&ys).map(|p| n.dot(*p)).fold(0.0f64, |m, d| m.max(d.abs()));
            let shift = n * (3.0 * span / n.length_squared() + 1.0e-9 * scale);
            let moved: Vec<DVec3> = ys.iter().map(|p| *p + shift).collect();
            separated += apart_along(n, xs.iter(), moved.iter()) as usize;
            // Small integers: exact projections decide.
            let int = |v: DVec3| (v * 16.0).round();
            let (ni, xi, yi) = (
                int(n),
                xs.iter().map(|p| int(*p / scale)).collect::<Vec<_>>(),
                ys.iter().map(|p| int(*p / scale) + int(n)).collect::<Vec<_>>(),
            );
            let proj = |ps: &[DVec3]| {
                ps.iter()
                    .map(|p| ni.dot(*p))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| (lo.min(d), hi.max(d)))
            };
            let ((xlo, xhi), (ylo, yhi)) = (proj(&xi), proj(&yi));
            if apart_along(ni, xi.iter(), yi.iter()) {
                assert!(xhi < ylo || yhi < xlo, "{k}");
                exact_true += 1;
            }
        }
        assert!(separated > 2900, "{separated}");
        assert!(exact_true > 100, "{exact_true}");
        assert!(!apart_along(DVec3::ZERO, [DVec3::X].iter(), [DVec3::Y].iter()));
        assert!(!apart_along(DVec3::splat(f64::NAN), [DVec3::X].iter(), [DVec3::Y].iter()));
    }

    /// Collinearity with repeated vertices (the shortcut) and without agrees with the exact
    /// components of the normal, signed zeros included.
    #[test]
    fn collinear_agrees_with_the_exact_normal() {
        let exact = |a: DVec3, b: DVec3, c: DVec3| (0..3).all(|k| orient2d(a, b, c, k) == 0);
        let (p, q) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(-1.5, 2.25, 1e-9));
        let z = DVec3::ZERO;
        let nz = DVec3::new(-0.0, 0.0, -0.0);
        let line = |t: f64| DVec3::new(1.0 + t, 2.0 + 2.0 * t, 3.0 - t);
        let cases = [
            (p, p, q),
            (p, q, p),
            (q, p, p),
            (p, p, p),
            (z, nz, q),
            (line(0.0), line(0.5), line(2.0)),
            (line(0.0), line(0.5), line(2.0) + DVec3::new(0.0, 0.0, 1e-15)),
            (p, q, p + DVec3::new(f64::EPSILON, 0.0, 0.0)),
        ];
        for (a, b, c) in cases {
            for (x, y, w) in [(a, b, c), (b, c, a), (c, a, b), (b, a, c)] {
                assert_eq!(collinear(x, y, w), exact(x, y, w), "{x:?} {y:?} {w:?}");
            }
        }
        assert!(collinear(p, p, q) && collinear(z, nz, q));
        assert!(!collinear(p, q, p + DVec3::new(f64::EPSILON, 0.0, 0.0)));
    }

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
    fn filtered_collinear_equals_the_exact_test() {
        // Points on a line through random f64 coordinates, nudged by a few ulps (or not) in
        // random coordinates, at scales from 2^-200 to 2^200: the filter may only answer
        // "not collinear" where the exact test does.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut rnd2 = rnd;
        let (mut degenerate, mut proper) = (0, 0);
        for i in 0..20_000 {
            let scale = 2f64.powi((i % 41) * 10 - 200);
            let mut unit = || (rnd() >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let a = DVec3::new(unit(), unit(), unit()) * scale;
            let d = DVec3::new(unit(), unit(), unit()) * scale;
            let (s, t) = [(1.0, 2.0), (0.5, -3.0), (0.0, 1.0), (1.0, 1.0)][(i % 4) as usize];
            let mut b = a + d * s;
            let mut c = a + d * t;
            match rnd2() % 4 {
                0 => b.x = f64::from_bits(b.x.to_bits().wrapping_add(1 + rnd2() % 3)),
                1 => c.z = f64::from_bits(c.z.to_bits().wrapping_add(1)),
                2 => c = DVec3::new(unit(), unit(), unit()) * scale,
                _ => {}
            }
            let exact = (0..3).all(|k| orient2d(a, b, c, k) == 0);
            assert_eq!(collinear(a, b, c), exact, "{a} {b} {c}");
            if exact {
                degenerate += 1;
            } else {
                proper += 1;
            }
        }
        assert!(degenerate > 1000 && proper > 1000, "{degenerate} {proper}");
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
    fn filter_never_contradicts_the_exact_sign() {
        // A point walked across a plane far from the origin ulp by ulp: the filter either
        // abstains or gives the exact sign, and abstains right at the plane.
        let z = 1.0e8;
        let t =
            [DVec3::new(1.0e8, 0.0, z), DVec3::new(0.0, 1.0e8 + 3.0, z), DVec3::new(-1.0e8 + 0.5, -7.0, z)];
        let f = PlaneFilter::new(&t);
        assert!(f.proper());
        let mut abstained = 0;
        for k in -40i64..=40 {
            let p = DVec3::new(0.25, 0.75, f64::from_bits((z.to_bits() as i64 + k) as u64));
            let exact = orient3d_adaptive(t[0], t[1], t[2], p);
            assert_eq!(exact, k.signum() as Sign);
            match f.side(p) {
                Some(s) => assert_eq!(s, exact, "k = {k}"),
                None => abstained += 1,
            }
            assert_eq!(f.side_exact(&t, p), exact);
            assert_eq!(orient3d(t[0], t[1], t[2], p), exact);
        }
        assert!(abstained > 0 && f.side(DVec3::new(0.25, 0.75, z)).is_none());
        // Far off the plane it decides.
        assert_eq!(f.side(DVec3::new(0.0, 0.0, z + 1.0)), Some(1));
        // A collinear triangle is never proven proper; tiny coordinates are left to the exact path.
        assert!(!PlaneFilter::new(&[DVec3::ZERO, DVec3::X, DVec3::X * 3.0]).proper());
        let tiny = 2f64.powi(-420);
        let ft = PlaneFilter::new(&[DVec3::ZERO, DVec3::X * tiny, DVec3::Y * tiny]);
        assert!(!ft.proper() && ft.side(DVec3::Z * tiny).is_none());
        assert_eq!(orient3d(DVec3::ZERO, DVec3::X * tiny, DVec3::Y * tiny, DVec3::Z * tiny), 1);
    }

    #[test]
    fn dyadic_stage_is_exact_on_short_binary_fractions() {
        // Exactly coplanar points of x + y + z = 3e8 on a 2^-26 grid: f64 determinants round to
        // non-zero values, the integer evaluation is exactly zero.
        let q = 2f64.powi(-26);
        let base = 100_000_000i64 << 26;
        let p = |i: i64, j: i64| {
            let (x, y) = (base + i, base + j);
            DVec3::new(x as f64 * q, y as f64 * q, (3 * base - x - y) as f64 * q)
            // all exact
        };
        let (a, b, c, d) = (p(0, 0), p(67_108_864, 5), p(3, 67_108_865), p(10_000_000, 20_000_000));
        assert_eq!(orient3d_dyadic(a, b, c, d), Some(0));
        assert_eq!(orient3d_adaptive(a, b, c, d), 0);
        let up = d + DVec3::new(0.0, 0.0, q);
        assert_eq!(orient3d_dyadic(a, b, c, up), Some(orient3d_adaptive(a, b, c, up)));
        assert_eq!(orient3d_dyadic(a, b, c, up), Some(1));
        // Differences spanning too many bits, or inexact: no answer.
        assert_eq!(orient3d_dyadic(DVec3::ZERO, DVec3::X, DVec3::Y * 1e-30, DVec3::Z), None);
        assert_eq!(orient3d_dyadic(DVec3::splat(0.1), DVec3::splat(-1e20), DVec3::Y, DVec3::Z), None);
        // Repeated points are exactly zero.
        assert_eq!(orient3d(a, b, c, b), 0);
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

    /// Boxes whose lower x lies before the sweep's start never meet the query box, at every
    /// scale (widths of an ulp far from the origin included).
    #[test]
    fn sweep_start_misses_no_meeting_box() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20_000 {
            let at = (next() - 0.5) * 10f64.powf(next() * 16.0 - 4.0);
            let ulps = |v: f64, k: f64| v + k * v.abs().max(f64::MIN_POSITIVE) * f64::EPSILON;
            let lo = ulps(at, (next() * 8.0).floor() - 4.0);
            let hi = ulps(lo, (next() * 8.0).floor());
            let widest = hi - lo;
            // Query boxes starting anywhere in the box (it meets them all).
            for q in [lo, hi, ulps(lo, 1.0).min(hi), (lo + hi) * 0.5] {
                assert!(sweep_start(q, widest) <= lo, "{lo} {hi} {q}");
            }
        }
    }
}
