//! Exact dyadic rationals `m · 2^e` (`m` an integer of any size): every finite f64 is one, and
//! sums, differences and products of them are computed without rounding. Used by the convex
//! penetration depth for the few comparisons its float filter cannot decide; small and slow on
//! purpose (schoolbook multiplication on base-2^32 limbs).

use crate::geom::exact::{add_mag, cmp_mag, mul_mag, sub_mag, trim, Mag};
use std::cmp::Ordering;

/// `(-1)^neg · mag · 2^exp`, `mag` little-endian base-2^32 limbs without trailing zero limbs
/// (zero is the empty magnitude, never negative).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Dyadic {
    neg: bool,
    mag: Mag,
    exp: i64,
}

fn shl_mag(a: &[u32], bits: u64) -> Mag {
    if a.is_empty() {
        return Mag::new();
    }
    let (limbs, rem) = ((bits / 32) as usize, (bits % 32) as u32);
    let mut out = Mag::from_elem(0, limbs);
    if rem == 0 {
        out.extend_from_slice(a);
    } else {
        let mut carry = 0u32;
        for &x in a {
            out.push((x << rem) | carry);
            carry = x >> (32 - rem);
        }
        out.push(carry);
    }
    trim(out)
}

impl Dyadic {
    /// Zero.
    pub fn zero() -> Dyadic {
        Dyadic { neg: false, mag: Mag::new(), exp: 0 }
    }

    /// The exact value of a finite `x` (panics on infinities and NaN: callers pass checked
    /// coordinates).
    pub fn from_f64(x: f64) -> Dyadic {
        assert!(x.is_finite(), "exact arithmetic on a non-finite value");
        let bits = x.to_bits();
        let neg = bits >> 63 == 1;
        let biased = ((bits >> 52) & 0x7ff) as i64;
        let frac = bits & ((1u64 << 52) - 1);
        let (m, e) = if biased == 0 { (frac, -1074) } else { (frac | (1u64 << 52), biased - 1075) };
        if m == 0 {
            return Dyadic::zero();
        }
        Dyadic { neg, mag: trim(Mag::from_slice(&[m as u32, (m >> 32) as u32])), exp: e }
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

    /// `-self`.
    pub fn neg(&self) -> Dyadic {
        Dyadic { neg: !self.neg && !self.mag.is_empty(), mag: self.mag.clone(), exp: self.exp }
    }

    /// `self + other`, exactly.
    pub fn add(&self, other: &Dyadic) -> Dyadic {
        if self.mag.is_empty() {
            return other.clone();
        }
        if other.mag.is_empty() {
            return self.clone();
        }
        let exp = self.exp.min(other.exp);
        let a = shl_mag(&self.mag, (self.exp - exp) as u64);
        let b = shl_mag(&other.mag, (other.exp - exp) as u64);
        if self.neg == other.neg {
            return Dyadic { neg: self.neg, mag: add_mag(&a, &b), exp };
        }
        match cmp_mag(&a, &b) {
            Ordering::Equal => Dyadic::zero(),
            Ordering::Greater => Dyadic { neg: self.neg, mag: sub_mag(&a, &b), exp },
            Ordering::Less => Dyadic { neg: other.neg, mag: sub_mag(&b, &a), exp },
        }
    }

    /// `self - other`, exactly.
    pub fn sub(&self, other: &Dyadic) -> Dyadic {
        self.add(&other.neg())
    }

    /// `self · other`, exactly.
    pub fn mul(&self, other: &Dyadic) -> Dyadic {
        let mag = mul_mag(&self.mag, &other.mag);
        if mag.is_empty() {
            return Dyadic::zero();
        }
        Dyadic { neg: self.neg != other.neg, mag, exp: self.exp + other.exp }
    }

    /// The exact order of two values.
    pub fn cmp(&self, other: &Dyadic) -> Ordering {
        self.sub(other).signum().cmp(&0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;
    use num_rational::BigRational;
    use proptest::prelude::*;

    fn rational(d: &Dyadic) -> BigRational {
        let mut m = BigInt::from(0);
        for &l in d.mag.iter().rev() {
            m = (m << 32) + BigInt::from(l);
        }
        if d.neg {
            m = -m;
        }
        if d.exp >= 0 {
            BigRational::from_integer(m << d.exp as usize)
        } else {
            BigRational::new(m, BigInt::from(1) << (-d.exp) as usize)
        }
    }

    fn exact(x: f64) -> BigRational {
        BigRational::from_float(x).unwrap()
    }

    proptest! {
        #[test]
        fn arithmetic_matches_rationals(
            a in prop_oneof![any::<f64>().prop_filter("finite", |x| x.is_finite()), -8.0..8.0f64],
            b in prop_oneof![any::<f64>().prop_filter("finite", |x| x.is_finite()), -8.0..8.0f64, Just(0.0)],
        ) {
            let (da, db) = (Dyadic::from_f64(a), Dyadic::from_f64(b));
            prop_assert_eq!(rational(&da), exact(a));
            prop_assert_eq!(rational(&da.add(&db)), exact(a) + exact(b));
            prop_assert_eq!(rational(&da.sub(&db)), exact(a) - exact(b));
            prop_assert_eq!(rational(&da.mul(&db)), exact(a) * exact(b));
            prop_assert_eq!(da.cmp(&db), a.partial_cmp(&b).unwrap());
        }
    }

    #[test]
    fn cancellation_and_subnormals_are_exact() {
        let tiny = f64::from_bits(1);
        let d = Dyadic::from_f64(1.0).add(&Dyadic::from_f64(tiny)).sub(&Dyadic::from_f64(1.0));
        assert_eq!(d, Dyadic::from_f64(tiny));
        assert_eq!(Dyadic::from_f64(0.1).sub(&Dyadic::from_f64(0.1)).signum(), 0);
        assert_eq!(Dyadic::from_f64(-0.0).signum(), 0);
    }
}
