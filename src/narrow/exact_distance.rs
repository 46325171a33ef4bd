//! The exact distance between two disjoint triangles with f64 vertices, for the decisions and
//! figures that must not depend on rounding: `distance < clearance`, `distance <= touch`, and
//! the reported minimum distance, correctly rounded.
//!
//! The squared distance is rational: it is the least of the candidates of the closed form
//! ([`crate::narrow::distance`]), each a quotient of integer polynomials in the coordinates —
//! vertex to face `(n·(p − a))² / n·n` when `p` projects inside the face, point to segment
//! `(|w|²·|e|² − (w·e)²) / |e|²` when it projects inside the segment (else an endpoint
//! distance), and edge to edge `(w·n)² / n·n` with `n = u × v` when both closest points lie
//! inside the edges. Every candidate and every "inside" condition is evaluated in exact
//! integers over a common power-of-two frame ([`crate::geom::exact`]).

use crate::geom::exact::{cross, diff, dot, Frame, Int};
use crate::geom::DVec3;
use std::cmp::Ordering;

/// An exact squared distance `num / den` (in units of `4^base`, the frame's scale squared).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExactSq {
    num: Int,
    den: Int,
    base: i32,
}

/// `x · 2^k` for `k >= 0`.
fn shl(x: &Int, k: u32) -> Int {
    let mut p = Int::from_i64(1);
    let mut left = k;
    while left > 0 {
        let step = left.min(62);
        p = p.mul(&Int::from_i64(1i64 << step));
        left -= step;
    }
    x.mul(&p)
}

/// `(m, e)` with `x = m · 2^e`, `m` an integer (0 for 0).
fn split(x: f64) -> (Int, i32) {
    let f = Frame::of([x]);
    (f.int(x), f.base())
}

impl ExactSq {
    /// Order of `self` against `s² `, where `s = m · 2^e` (`m` an integer).
    fn cmp_square(&self, m: &Int, e: i32) -> Ordering {
        // num/den · 4^base  vs  m² · 4^e   ⇔   num · 4^(base−k)  vs  m² · den · 4^(e−k).
        let k = self.base.min(e);
        let lhs = shl(&self.num, 2 * (self.base - k) as u32);
        let rhs = shl(&m.mul(m).mul(&self.den), 2 * (e - k) as u32);
        lhs.cmp_value(&rhs)
    }

    /// Order of the distance against `t >= 0`.
    pub fn cmp_distance(&self, t: f64) -> Ordering {
        let (m, e) = split(t);
        self.cmp_square(&m, e)
    }

    /// The distance, correctly rounded to f64 (nearest, ties to even).
    pub fn rounded(&self) -> f64 {
        if self.num.signum() == 0 {
            return 0.0;
        }
        // An estimate within a few ulps: sqrt(num/den) · 2^base from the leading bits.
        let ((nm, ne), (dm, de)) = (self.num.approx(), self.den.approx());
        let mut e = ne - de + 2 * self.base as i64;
        let mut ratio = nm / dm;
        if e % 2 != 0 {
            ratio *= 2.0;
            e -= 1;
        }
        let half = (e / 2).clamp(-2000, 2000) as i32;
        // 2^half in two steps, so neither factor overflows before the product settles.
        let mut r = ratio.sqrt() * 2f64.powi(half / 2) * 2f64.powi(half - half / 2);
        if r.is_nan() || r <= 0.0 {
            r = f64::from_bits(1);
        }
        r = r.min(f64::MAX);
        // The midpoint of two adjacent floats, exact as an integer times a power of two.
        let mid = |x: f64, y: f64| {
            let f = Frame::of([x, y]);
            (f.int(x).add(&f.int(y)), f.base() - 1)
        };
        let even = |x: f64| x.to_bits() & 1 == 0;
        loop {
            let (down, up) = (f64::from_bits(r.to_bits() - 1), f64::from_bits(r.to_bits() + 1));
            let (m, e) = mid(down, r);
            let below = self.cmp_square(&m, e);
            let (m, e) = mid(r, up);
            let above = self.cmp_square(&m, e);
            match (below, above) {
                (Ordering::Less, _) if down == 0.0 => return 0.0,
                (Ordering::Less, _) => r = down,
                (Ordering::Equal, _) => return if even(down) { down } else { r },
                (_, Ordering::Greater) => r = up,
                (_, Ordering::Equal) => return if even(up) { up } else { r },
                _ => return r,
            }
        }
    }
}

/// The least of the candidates, as `(num, den)` with `den > 0`.
struct Least(Option<(Int, Int)>);

impl Least {
    fn offer(&mut self, num: Int, den: Int) {
        let better = match &self.0 {
            None => true,
            Some((n, d)) => num.mul(d).cmp_value(&n.mul(&den)) == Ordering::Less,
        };
        if better {
            self.0 = Some((num, den));
        }
    }
}

/// Squared distance from `p` to segment `[a, b]`.
fn point_segment(p: &[Int; 3], a: &[Int; 3], b: &[Int; 3], out: &mut Least) {
    let (e, w) = (diff(b, a), diff(p, a));
    let (t, l) = (dot(&w, &e), dot(&e, &e));
    if t.signum() <= 0 || l.signum() == 0 {
        out.offer(dot(&w, &w), Int::from_i64(1));
    } else if t.cmp_value(&l) != Ordering::Less {
        let v = diff(p, b);
        out.offer(dot(&v, &v), Int::from_i64(1));
    } else {
        out.offer(dot(&w, &w).mul(&l).sub(&t.mul(&t)), l);
    }
}

/// Squared distance from `p` to the plane of proper triangle `t` when `p` projects inside `t`.
fn point_face(p: &[Int; 3], t: &[[Int; 3]; 3], out: &mut Least) {
    let n = cross(&diff(&t[1], &t[0]), &diff(&t[2], &t[0]));
    let nn = dot(&n, &n);
    if nn.signum() == 0 {
        return;
    }
    // Inside (boundary included): p − t_i is on the inner side of every edge within the plane.
    let inside = (0..3).all(|i| {
        let e = diff(&t[(i + 1) % 3], &t[i]);
        dot(&cross(&e, &diff(p, &t[i])), &n).signum() >= 0
    });
    if inside {
        let h = dot(&n, &diff(p, &t[0]));
        out.offer(h.mul(&h), nn);
    }
}

/// Squared distance between the lines of `[a, b]` and `[c, d]` when their closest points lie
/// inside both segments (non-parallel edges only; the rest is covered by endpoint candidates).
fn edge_edge(a: &[Int; 3], b: &[Int; 3], c: &[Int; 3], d: &[Int; 3], out: &mut Least) {
    let (u, v, w) = (diff(b, a), diff(d, c), diff(a, c));
    let n = cross(&u, &v);
    let den = dot(&n, &n);
    if den.signum() == 0 {
        return;
    }
    let (uu, uv, vv, uw, vw) = (dot(&u, &u), dot(&u, &v), dot(&v, &v), dot(&u, &w), dot(&v, &w));
    // Closest points a + s·u, c + t·v with s = (uv·vw − vv·uw)/den, t = (uu·vw − uv·uw)/den.
    let s = uv.mul(&vw).sub(&vv.mul(&uw));
    let t = uu.mul(&vw).sub(&uv.mul(&uw));
    let within = |x: &Int| x.signum() >= 0 && x.cmp_value(&den) != Ordering::Greater;
    if within(&s) && within(&t) {
        let h = dot(&w, &n);
        out.offer(h.mul(&h), den);
    }
}

/// The exact squared distance between two triangles that share no point (zero-area ones
/// included). For triangles that meet, the result is still a true upper bound of 0 only
/// through its candidates; callers decide contact exactly first.
pub fn exact_distance_sq(ta: &[DVec3; 3], tb: &[DVec3; 3]) -> ExactSq {
    let f = Frame::of_points(ta.iter().chain(tb));
    let (a, b) = (ta.map(|p| f.point(p)), tb.map(|p| f.point(p)));
    let mut least = Least(None);
    for (s, t) in [(&a, &b), (&b, &a)] {
        for p in s {
            point_face(p, t, &mut least);
            for i in 0..3 {
                point_segment(p, &t[i], &t[(i + 1) % 3], &mut least);
            }
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            edge_edge(&a[i], &a[(i + 1) % 3], &b[j], &b[(j + 1) % 3], &mut least);
        }
    }
    let (num, den) = least.0.expect("a triangle has vertices");
    ExactSq { num, den, base: f.base() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow::distance::triangle_distance;

    #[test]
    fn quarter_gaps_are_exact_and_round_to_a_quarter() {
        let a = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        for (shift, tilt) in [(0.25f64, 0.0f64), (0.25, 0.3), (0.25, -0.7)] {
            let b = [
                DVec3::new(0.1, 0.1, shift),
                DVec3::new(0.9, 0.0, shift + tilt.max(0.0)),
                DVec3::new(0.0, 0.9, shift - tilt.min(0.0)),
            ];
            let e = exact_distance_sq(&a, &b);
            assert_eq!(e.cmp_distance(0.25), Ordering::Equal);
            assert_eq!(e.cmp_distance(0.25f64.next_down()), Ordering::Greater);
            assert_eq!(e.rounded(), 0.25);
        }
        // Edge to edge, skew: distance 1/sqrt(2)·... checked against the f64 value.
        let c = [DVec3::new(0.5, -1.0, 1.0), DVec3::new(0.5, 1.0, 1.0), DVec3::new(0.5, 0.0, 3.0)];
        let d = [DVec3::new(-1.0, 0.2, 2.0), DVec3::new(1.0, 0.2, 2.0), DVec3::new(0.0, 0.2, 5.0)];
        let e = exact_distance_sq(&c, &d);
        let f = triangle_distance(&c, &d).distance;
        assert!((e.rounded() - f).abs() <= 4.0 * f64::EPSILON * f.max(1.0), "{} {f}", e.rounded());
    }
}
