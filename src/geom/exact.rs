//! Exact integer arithmetic for the few decisions that need an exact *value* rather than the
//! sign of one determinant: sums of several orientation determinants (the side of a point given
//! by rational barycentric weights), and squared distances compared with a threshold.
//!
//! Every finite f64 is an odd integer times a power of two, so the coordinates of one
//! computation, all written as integers times `2^base` where `base` is the lowest set bit
//! exponent among them ([`Frame`]), turn every polynomial in them into an integer polynomial,
//! evaluated here without rounding ([`Int`]: sign and magnitude in 32-bit limbs, schoolbook
//! products). Used only where the f64 filters of [`crate::geom::predicates`] cannot decide, so
//! the cost of arbitrary precision is paid on borderline cases alone.

use crate::geom::DVec3;
use smallvec::SmallVec;
use std::cmp::Ordering;

/// Limbs kept inline before a magnitude moves to the heap: 512 bits, above the products of
/// the usual frames (a few hundred bits), so the common exact decisions allocate nothing.
const INLINE_LIMBS: usize = 16;

/// A magnitude: little-endian base-2^32 limbs, inline up to [`INLINE_LIMBS`].
pub(crate) type Mag = SmallVec<[u32; INLINE_LIMBS]>;

/// A signed integer of any size. Normalized: no high zero limbs, and zero is never negative.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Int {
    neg: bool,
    mag: Mag,
}

/// `m` without its high zero limbs.
pub(crate) fn trim(mut m: Mag) -> Mag {
    let n = m.iter().rposition(|&l| l != 0).map_or(0, |i| i + 1);
    m.truncate(n);
    m
}

pub(crate) fn cmp_mag(a: &[u32], b: &[u32]) -> Ordering {
    a.len().cmp(&b.len()).then_with(|| a.iter().rev().cmp(b.iter().rev()))
}

/// `a + b`.
pub(crate) fn add_mag(a: &[u32], b: &[u32]) -> Mag {
    let (long, short) = if a.len() >= b.len() { (a, b) } else { (b, a) };
    let mut out = Mag::from_elem(0, long.len() + 1);
    let o = out.as_mut_slice();
    let mut carry = 0u64;
    for i in 0..long.len() {
        let s = long[i] as u64 + short.get(i).map_or(0, |&y| y as u64) + carry;
        o[i] = s as u32;
        carry = s >> 32;
    }
    o[long.len()] = carry as u32;
    trim(out)
}

/// `a - b` for `|a| >= |b|`.
pub(crate) fn sub_mag(a: &[u32], b: &[u32]) -> Mag {
    let mut out = Mag::from_elem(0, a.len());
    let o = out.as_mut_slice();
    let mut borrow = 0i64;
    for i in 0..a.len() {
        let mut d = a[i] as i64 - b.get(i).map_or(0, |&y| y as i64) - borrow;
        borrow = (d < 0) as i64;
        d += borrow << 32;
        o[i] = d as u32;
    }
    trim(out)
}

/// `a · b`.
pub(crate) fn mul_mag(a: &[u32], b: &[u32]) -> Mag {
    if a.is_empty() || b.is_empty() {
        return Mag::new();
    }
    let mut out = Mag::from_elem(0, a.len() + b.len());
    let o = out.as_mut_slice();
    for (i, &x) in a.iter().enumerate() {
        let row = &mut o[i..i + b.len() + 1];
        let (last, body) = row.split_last_mut().expect("a row has b.len() + 1 limbs");
        let mut carry = 0u64;
        for (r, &y) in body.iter_mut().zip(b) {
            let t = x as u64 * y as u64 + *r as u64 + carry;
            *r = t as u32;
            carry = t >> 32;
        }
        *last = carry as u32;
    }
    trim(out)
}

impl Int {
    fn new(neg: bool, mag: Mag) -> Int {
        let mag = trim(mag);
        Int { neg: neg && !mag.is_empty(), mag }
    }

    /// The integer `v`.
    pub fn from_i64(v: i64) -> Int {
        let m = v.unsigned_abs();
        Int::new(v < 0, Mag::from_slice(&[m as u32, (m >> 32) as u32]))
    }

    /// `m · 2^shift` for a non-negative `shift`.
    fn from_parts(neg: bool, m: u64, shift: u32) -> Int {
        let (limbs, bits) = ((shift / 32) as usize, shift % 32);
        let wide = (m as u128) << bits;
        let mut mag = Mag::from_elem(0, limbs);
        mag.extend_from_slice(&[wide as u32, (wide >> 32) as u32, (wide >> 64) as u32]);
        Int::new(neg, mag)
    }

    /// -1, 0 or 1.
    pub fn signum(&self) -> i8 {
        if self.mag.is_empty() {
            0
        } else if self.neg {
            -1
        } else {
            1
        }
    }

    /// `self + (-1)^o_neg · |o|`.
    fn add_signed(&self, o: &Int, o_neg: bool) -> Int {
        if self.neg == o_neg {
            Int::new(self.neg, add_mag(&self.mag, &o.mag))
        } else if cmp_mag(&self.mag, &o.mag) == Ordering::Less {
            Int::new(o_neg, sub_mag(&o.mag, &self.mag))
        } else {
            Int::new(self.neg, sub_mag(&self.mag, &o.mag))
        }
    }

    /// `self + o`.
    pub fn add(&self, o: &Int) -> Int {
        self.add_signed(o, o.neg)
    }

    /// `-self`.
    pub fn neg(&self) -> Int {
        self.clone().negated()
    }

    /// `-self`, reusing the magnitude.
    fn negated(self) -> Int {
        Int { neg: !self.neg && !self.mag.is_empty(), mag: self.mag }
    }

    /// `self - o`.
    pub fn sub(&self, o: &Int) -> Int {
        self.add_signed(o, !o.neg && !o.mag.is_empty())
    }

    /// `self · o`.
    pub fn mul(&self, o: &Int) -> Int {
        Int::new(self.neg != o.neg, mul_mag(&self.mag, &o.mag))
    }

    /// `(m, e)` with `self ≈ m · 2^e`, `m` the leading 65 to 96 bits as an f64 (a relative
    /// error of about one f64 rounding; exactly 0 for 0): an estimate that never overflows.
    pub fn approx(&self) -> (f64, i64) {
        let n = self.mag.len();
        let top = self.mag.iter().rev().take(3).fold(0.0, |acc, &l| acc * 4_294_967_296.0 + l as f64);
        let m = if self.neg { -top } else { top };
        (m, 32 * n.saturating_sub(3) as i64)
    }

    /// `self · 2^bits`.
    pub fn shl(&self, bits: u32) -> Int {
        if self.mag.is_empty() {
            return Int::default();
        }
        let (limbs, rest) = ((bits / 32) as usize, bits % 32);
        let mut mag = Mag::from_elem(0, limbs + self.mag.len() + 1);
        let mut carry = 0u32;
        for (o, &l) in mag[limbs..].iter_mut().zip(&self.mag) {
            let wide = (l as u64) << rest;
            *o = wide as u32 | carry;
            carry = (wide >> 32) as u32;
        }
        mag[limbs + self.mag.len()] = carry;
        Int::new(self.neg, mag)
    }

    /// Numeric order.
    pub fn cmp_value(&self, o: &Int) -> Ordering {
        match (self.neg, o.neg) {
            (false, true) => Ordering::Greater,
            (true, false) => Ordering::Less,
            (false, false) => cmp_mag(&self.mag, &o.mag),
            (true, true) => cmp_mag(&o.mag, &self.mag),
        }
    }
}

/// `x = m · 2^e` with `m` odd (or 0): `(negative, m, e)`.
fn decompose(x: f64) -> (bool, u64, i32) {
    let bits = x.to_bits();
    let (neg, exp, frac) = (bits >> 63 == 1, ((bits >> 52) & 0x7ff) as i32, bits & ((1 << 52) - 1));
    let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | 1 << 52, exp - 1075) };
    if m == 0 {
        return (false, 0, 0);
    }
    let tz = m.trailing_zeros();
    (neg, m >> tz, e + tz as i32)
}

/// A common scale for the coordinates of one exact computation: every value is read as the
/// integer `x / 2^base`, where `2^base` is the lowest set bit among the values the frame was
/// made for (so every product of `k` of them is exact at scale `2^(k·base)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    base: i32,
}

impl Frame {
    /// The frame of a set of finite values.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Frame {
        let base = values.into_iter().filter(|&x| x != 0.0).map(|x| decompose(x).2).min().unwrap_or(0);
        Frame { base }
    }

    /// The frame of a set of points.
    pub fn of_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Frame {
        Frame::of(points.into_iter().flat_map(|p| p.to_array()))
    }

    /// The power of two every value is a multiple of.
    pub fn base(&self) -> i32 {
        self.base
    }

    /// `x / 2^base`, exactly (`x` must be a value the frame was made for, or a multiple of
    /// `2^base`).
    pub fn int(&self, x: f64) -> Int {
        let (neg, m, e) = decompose(x);
        if m == 0 {
            return Int::default();
        }
        debug_assert!(e >= self.base, "value below the frame");
        Int::from_parts(neg, m, (e - self.base) as u32)
    }

    /// A point's coordinates as integers.
    pub fn point(&self, p: DVec3) -> [Int; 3] {
        p.to_array().map(|x| self.int(x))
    }
}

/// `u - v` per coordinate.
pub fn diff(u: &[Int; 3], v: &[Int; 3]) -> [Int; 3] {
    [u[0].sub(&v[0]), u[1].sub(&v[1]), u[2].sub(&v[2])]
}

/// `u · v`.
pub fn dot(u: &[Int; 3], v: &[Int; 3]) -> Int {
    u[0].mul(&v[0]).add(&u[1].mul(&v[1])).add(&u[2].mul(&v[2]))
}

/// `u × v`.
pub fn cross(u: &[Int; 3], v: &[Int; 3]) -> [Int; 3] {
    [
        u[1].mul(&v[2]).sub(&u[2].mul(&v[1])),
        u[2].mul(&v[0]).sub(&u[0].mul(&v[2])),
        u[0].mul(&v[1]).sub(&u[1].mul(&v[0])),
    ]
}

/// The exact value of `((b - a) × (c - a)) · (d - a)` at the frame's scale (times
/// `2^(-3·base)`); its sign is [`crate::geom::predicates::orient3d`]'s.
pub fn orient3d(f: &Frame, a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Int {
    let pa = f.point(a);
    let (u, v, w) = (diff(&f.point(b), &pa), diff(&f.point(c), &pa), diff(&f.point(d), &pa));
    dot(&cross(&u, &v), &w)
}

/// [`orient3d`] of two points `d` and `e` against one plane `(a, b, c)`: the same two values,
/// the plane's normal computed once.
pub fn orient3d_two(f: &Frame, a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> (Int, Int) {
    let pa = f.point(a);
    let n = cross(&diff(&f.point(b), &pa), &diff(&f.point(c), &pa));
    (dot(&n, &diff(&f.point(d), &pa)), dot(&n, &diff(&f.point(e), &pa)))
}

/// The exact value of component `axis` of `(b - a) × (c - a)` at the frame's scale (times
/// `2^(-2·base)`); its sign is [`crate::geom::predicates::orient2d`]'s.
pub fn orient2d(f: &Frame, a: DVec3, b: DVec3, c: DVec3, axis: usize) -> Int {
    let pa = f.point(a);
    let (u, v) = (diff(&f.point(b), &pa), diff(&f.point(c), &pa));
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    u[i].mul(&v[j]).sub(&u[j].mul(&v[i]))
}

/// `Σ w_k · x_k` for small integer weights.
pub fn weighted_sum(terms: impl IntoIterator<Item = (i64, Int)>) -> Int {
    terms.into_iter().fold(Int::default(), |s, (w, x)| s.add(&Int::from_i64(w).mul(&x)))
}

/// A rational `num / den · 2^base` (`den > 0`): a coordinate of a point computed exactly in a
/// [`Frame`] (`base` is the frame's, times the degree of the expression).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ratio {
    /// Numerator.
    pub num: Int,
    /// Denominator (positive).
    pub den: Int,
}

impl Ratio {
    /// `num / den`; `den` must not be zero (its sign is moved to the numerator).
    pub fn new(num: Int, den: Int) -> Ratio {
        debug_assert!(den.signum() != 0, "zero denominator");
        if den.signum() < 0 {
            Ratio { num: num.negated(), den: den.negated() }
        } else {
            Ratio { num, den }
        }
    }

    /// The integer `v`.
    pub fn int(v: Int) -> Ratio {
        Ratio { num: v, den: Int::from_i64(1) }
    }

    /// Numeric order (both at the same scale).
    pub fn cmp_value(&self, o: &Ratio) -> Ordering {
        self.num.mul(&o.den).cmp_value(&o.num.mul(&self.den))
    }

    /// `self · 2^base` rounded once to the nearest f64 (ties to even): the correctly rounded
    /// value. `self · 2^base` must lie within the finite f64 range.
    pub fn round(&self, base: i32) -> f64 {
        if self.num.signum() == 0 {
            return 0.0;
        }
        let ((mn, en), (md, ed)) = (self.num.approx(), self.den.approx());
        // An estimate within a few units in the last place, then corrected exactly.
        let mut x = ldexp(mn / md, en - ed + base as i64);
        for _ in 0..4096 {
            let (down, up) = (x.next_down(), x.next_up());
            let above = self.cmp_dyadic(base, &Dyadic::mid(x, up));
            let below = self.cmp_dyadic(base, &Dyadic::mid(down, x));
            x = match (above, below) {
                (Ordering::Greater, _) => up,
                (_, Ordering::Less) => down,
                (Ordering::Equal, _) if x.to_bits() & 1 == 1 => up,
                (_, Ordering::Equal) if x.to_bits() & 1 == 1 => down,
                _ => return x,
            };
        }
        x
    }

    /// Compare `self · 2^base` with a dyadic value.
    fn cmp_dyadic(&self, base: i32, d: &Dyadic) -> Ordering {
        let low = base.min(d.exp);
        let lhs = self.num.shl((base - low) as u32);
        let rhs = d.mant.mul(&self.den).shl((d.exp - low) as u32);
        lhs.cmp_value(&rhs)
    }
}

/// `mant · 2^exp`, exactly.
#[derive(Clone, Debug)]
struct Dyadic {
    mant: Int,
    exp: i32,
}

impl Dyadic {
    fn of(x: f64) -> Dyadic {
        let (neg, m, e) = decompose(x);
        Dyadic { mant: Int::from_parts(neg, m, 0), exp: e }
    }

    /// The exact midpoint of two finite values (an infinite one counts as the other plus its
    /// distance to its neighbour, so the midpoint stays beyond every finite value between).
    fn mid(x: f64, y: f64) -> Dyadic {
        let finite = |v: f64, other: f64| if v.is_finite() { v } else { other + (other - other.next_down()) };
        let (x, y) = (finite(x, y), finite(y, x));
        let (dx, dy) = (Dyadic::of(x), Dyadic::of(y));
        let low = dx.exp.min(dy.exp);
        let sum = dx.mant.shl((dx.exp - low) as u32).add(&dy.mant.shl((dy.exp - low) as u32));
        Dyadic { mant: sum, exp: low - 1 }
    }
}

/// `m · 2^e` in f64 (an estimate: each step rounds), saturating to 0 or infinity.
fn ldexp(m: f64, e: i64) -> f64 {
    let mut x = m;
    let mut e = e.clamp(-4000, 4000) as i32;
    while e != 0 {
        let step = e.clamp(-1000, 1000);
        x *= 2f64.powi(step);
        e -= step;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::predicates as pr;
    use num_bigint::{BigInt, Sign};
    use proptest::prelude::*;

    fn to_i128(x: &Int) -> i128 {
        let mut v: i128 = 0;
        for &l in x.mag.iter().rev() {
            v = (v << 32) | l as i128;
        }
        if x.neg {
            -v
        } else {
            v
        }
    }

    #[test]
    fn integer_operations_agree_with_i128() {
        let vals = [0i64, 1, -1, 7, -123_456_789, i64::MAX, i64::MIN + 1, 1 << 40, -(1 << 33) + 5];
        for &a in &vals {
            for &b in &vals {
                let (x, y) = (Int::from_i64(a), Int::from_i64(b));
                let (a, b) = (a as i128, b as i128);
                assert_eq!(to_i128(&x.add(&y)), a + b);
                assert_eq!(to_i128(&x.sub(&y)), a - b);
                if let Some(p) = a.checked_mul(b) {
                    assert_eq!(to_i128(&x.mul(&y)), p);
                }
                assert_eq!(x.cmp_value(&y), a.cmp(&b));
                assert_eq!(x.signum() as i128, a.signum());
            }
        }
    }

    fn big(x: &Int) -> BigInt {
        let m = x.mag.iter().rev().fold(BigInt::from(0), |m, &l| (m << 32) + BigInt::from(l));
        if x.neg {
            -m
        } else {
            m
        }
    }

    /// Operands from 0 to 40 limbs (inline and spilled magnitudes), with runs of zero and
    /// all-ones limbs so carries and borrows cross many limbs.
    fn operand() -> impl Strategy<Value = Int> {
        let limb = prop_oneof![Just(0u32), Just(u32::MAX), Just(1u32), any::<u32>()];
        (any::<bool>(), prop::collection::vec(limb, 0..40))
            .prop_map(|(neg, limbs)| Int::new(neg, Mag::from_vec(limbs)))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn integer_operations_agree_with_bigint(x in operand(), y in operand(), bits in 0u32..700) {
            let (a, b) = (big(&x), big(&y));
            for (r, want) in [
                (x.add(&y), &a + &b),
                (x.sub(&y), &a - &b),
                (x.mul(&y), &a * &b),
                (x.neg(), -a.clone()),
                (x.shl(bits), &a << bits as usize),
            ] {
                prop_assert_eq!(big(&r), want);
                // Normalized: no high zero limb, zero not negative.
                prop_assert!(r.mag.last() != Some(&0));
                prop_assert!(!(r.neg && r.mag.is_empty()));
            }
            prop_assert_eq!(x.cmp_value(&y), a.cmp(&b));
            let sign = match a.sign() {
                Sign::Minus => -1,
                Sign::NoSign => 0,
                Sign::Plus => 1,
            };
            prop_assert_eq!(x.signum(), sign);
        }
    }

    #[test]
    fn float_coordinates_stay_inline() {
        // Single-precision coordinates spanning 2^-20 to 2^10 (a mesh read from glTF): the
        // orientation values and the products a ratio comparison forms need no heap.
        let p = [
            DVec3::new(1023.5, -0.000_976_562_5, 3.25),
            DVec3::new(-7.0, 511.75, 2f64.powi(-20)),
            DVec3::new(0.1f32 as f64, 0.2f32 as f64, -1000.3f32 as f64),
            DVec3::new(12.125, -0.3f32 as f64, 0.7f32 as f64),
        ];
        let f = Frame::of_points(&p);
        let o = orient3d(&f, p[0], p[1], p[2], p[3]);
        let d = o.mul(&f.int(p[0].x)).mul(&o);
        assert!(!o.mag.spilled() && !d.mag.spilled(), "{} and {} limbs", o.mag.len(), d.mag.len());
    }

    #[test]
    fn frame_values_are_exact_multiples() {
        let f = Frame::of([0.75, 3.0, -2.5, 0.0, 1e6]);
        assert_eq!(f.base(), -2);
        for x in [0.75, 3.0, -2.5, 0.0, 1e6] {
            assert_eq!(to_i128(&f.int(x)) as f64 * 0.25, x);
        }
        // Subnormal and huge values in one frame: 2^-1074 is the unit.
        let g = Frame::of([f64::from_bits(1), 1.0]);
        assert_eq!(g.base(), -1074);
        assert_eq!(g.int(1.0).mag.len(), 34); // 2^1074 needs 1075 bits
    }

    #[test]
    fn orientation_values_have_the_predicate_signs() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Nearly coplanar points on a coarse grid with tiny offsets: signs are delicate.
            ((s % 17) as f64 - 8.0) * 0.5
                + if s.is_multiple_of(5) { ((s >> 20) % 3) as f64 * 1e-17 } else { 0.0 }
        };
        for _ in 0..2000 {
            let p: Vec<DVec3> = (0..4).map(|_| DVec3::new(rnd(), rnd(), rnd())).collect();
            let f = Frame::of_points(&p);
            assert_eq!(orient3d(&f, p[0], p[1], p[2], p[3]).signum(), pr::orient3d(p[0], p[1], p[2], p[3]));
            let (x, y) = orient3d_two(&f, p[0], p[1], p[2], p[3], p[1] + p[3]);
            assert_eq!(x, orient3d(&f, p[0], p[1], p[2], p[3]));
            assert_eq!(y, orient3d(&f, p[0], p[1], p[2], p[1] + p[3]));
            for k in 0..3 {
                assert_eq!(orient2d(&f, p[0], p[1], p[2], k).signum(), pr::orient2d(p[0], p[1], p[2], k));
            }
        }
    }

    #[test]
    fn ratios_round_correctly() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for _ in 0..5000 {
            // Operands exact in f64, so one IEEE division is the correctly rounded quotient.
            let n = (rnd() >> 11) as i64 * if rnd() & 1 == 0 { 1 } else { -1 };
            let d = ((rnd() >> (11 + rnd() % 50)) as i64).max(1);
            let base = (rnd() % 40) as i32 - 20;
            let r = Ratio::new(Int::from_i64(n), Int::from_i64(d));
            let want = n as f64 / d as f64 * 2f64.powi(base);
            assert_eq!(r.round(base), want, "{n}/{d} · 2^{base}");
            let neg = Ratio::new(Int::from_i64(n), Int::from_i64(-d));
            assert_eq!(neg.round(base), -want);
        }
        // Ties go to even: (2^53 + 1) / 1 lies halfway between 2^53 and 2^53 + 2.
        let tie = Ratio::int(Int::from_i64((1 << 53) + 1));
        assert_eq!(tie.round(0), 9_007_199_254_740_992.0);
        let tie = Ratio::int(Int::from_i64((1 << 53) + 3));
        assert_eq!(tie.round(0), 9_007_199_254_740_996.0);
        assert_eq!(
            Ratio::new(Int::from_i64(1), Int::from_i64(3)).cmp_value(&Ratio::int(Int::default())),
            Ordering::Greater
        );
    }
}
