//! Oriented bounds for the closest-pair search: lower bounds on the distance between two
//! triangle sets that follow the surface, where axis-aligned boxes cannot.
//!
//! Two parts at a nearly constant distance (a shaft in a bore, two faces a gap apart, tori
//! linked through each other) defeat axis-aligned boxes: a small curved patch tilted against the
//! axes has a box gap that falls short of the true distance by about the patch's size, so the
//! branch and bound opens every node pair along the band. Oriented bounds (Gottschalk, Lin &
//! Manocha 1996, OBBTree; Larsen, Gottschalk, Lin & Manocha 1999, swept-sphere volumes, as used
//! by PQP and FCL) fall short only by the patch's *thickness* along its normal, which for a
//! smooth surface shrinks with the square of its size.
//!
//! An [`Oriented`] bound is an orthonormal frame whose first axis is the area-weighted normal of
//! the patch, and the interval of every vertex's projection on each axis: the slab intersection
//! `{x : lo ≤ (n·x, u·x, v·x) ≤ hi}` holds the patch. The lower bound between two of them is the
//! largest projected gap over the six axes (a separating-axis bound: the gap between the two
//! sets' projections on any unit axis is at most their distance).
//!
//! Rounding: the frames are orthonormal only to rounding, and every dot product rounds. The
//! bound is therefore reduced by [`crate::geom::predicates::oriented_bound_margin`] (a few dozen
//! ulps of the coordinate scale), so that it never exceeds the true distance; the search then
//! prunes exactly as with boxes, and its answer does not change.

use crate::geom::DVec3;

/// An oriented slab bound of a set of triangles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oriented {
    /// Unit axes: the patch normal first, then two directions across it.
    pub axes: [DVec3; 3],
    /// Smallest projection of any vertex on each axis.
    pub lo: DVec3,
    /// Largest projection of any vertex on each axis.
    pub hi: DVec3,
}

impl Oriented {
    /// The bound of `tris`, or `None` when their area-weighted normals cancel (a closed or
    /// strongly curved set, where a box does as well) or there are none.
    pub fn of_triangles<I>(tris: I) -> Option<Oriented>
    where
        I: Iterator<Item = [DVec3; 3]>,
    {
        // One read of the triangles: the normal pass keeps their corners for the projection
        // pass (a node's triangles come from scattered mesh slots; the copy is contiguous).
        let mut corners: Vec<DVec3> = Vec::with_capacity(3 * tris.size_hint().0);
        let mut nsum = DVec3::ZERO;
        let mut area = 0.0;
        for [a, b, c] in tris {
            let n = (b - a).cross(c - a);
            nsum += n;
            area += n.length();
            corners.extend([a, b, c]);
        }
        let len = nsum.length();
        // A patch whose normals mostly cancel gains nothing over a box.
        if len.partial_cmp(&(0.25 * area)) != Some(std::cmp::Ordering::Greater) || !len.is_finite() {
            return None;
        }
        let n = nsum / len;
        // Across-axes: the world axis least aligned with n, made orthogonal to it.
        let k = n.abs().min_position();
        let mut e = DVec3::ZERO;
        e[k] = 1.0;
        let u = n.cross(e).normalize();
        let v = n.cross(u);
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for p in corners {
            let q = DVec3::new(n.dot(p), u.dot(p), v.dot(p));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        Some(Oriented { axes: [n, u, v], lo, hi })
    }

    /// The largest gap between the projections of `self` and `o` on one of the six axes (0 when
    /// every projection overlaps). Before rounding this is a lower bound on the distance between
    /// the two sets; subtract [`crate::geom::predicates::oriented_bound_margin`] before pruning.
    #[inline]
    #[allow(clippy::needless_range_loop)] // the 3x3 index form reads as the matrix it is
    pub fn gap(&self, o: &Oriented) -> f64 {
        // c[i][j] = self.axes[i] · o.axes[j]
        let c = self.axes.map(|a| o.axes.map(|b| a.dot(b)));
        let mut best: f64 = 0.0;
        // o's interval along each of self's axes (o's slab read back through its frame).
        for i in 0..3 {
            let (mut l, mut h) = (0.0, 0.0);
            for j in 0..3 {
                let (x, y) = (c[i][j] * o.lo[j], c[i][j] * o.hi[j]);
                l += x.min(y);
                h += x.max(y);
            }
            best = best.max(l - self.hi[i]).max(self.lo[i] - h);
        }
        // self's interval along each of o's axes.
        for j in 0..3 {
            let (mut l, mut h) = (0.0, 0.0);
            for i in 0..3 {
                let (x, y) = (c[i][j] * self.lo[i], c[i][j] * self.hi[i]);
                l += x.min(y);
                h += x.max(y);
            }
            best = best.max(l - o.hi[j]).max(o.lo[j] - h);
        }
        best
    }
}

impl Oriented {
    /// A tighter lower bound for sets that [`Oriented::gap`] proves apart (`gap > 0`): the
    /// distance between the two mid-plane rectangles (each slab box is its rectangle swept along
    /// the normal by half its thickness, as in Larsen et al.'s rectangle swept spheres) less both
    /// half-thicknesses. Returns `gap` when it is not positive. Subtract the rounding margin
    /// before pruning, as for `gap`.
    pub fn swept_rect_bound(&self, o: &Oriented, gap: f64) -> f64 {
        self.swept_rect_bound_above(o, gap, f64::NEG_INFINITY)
    }

    /// As [`Oriented::swept_rect_bound`] for a search that can use the bound only where it
    /// exceeds `need` (the pruning cut plus the rounding margin): the same value whenever that
    /// value exceeds `need` (one within rounding of `need` may come back as `gap`), else `gap`,
    /// a lower bound no greater than it. Gives up
    /// as soon as the answer is known not to exceed `need`: first when the rectangles' centres
    /// (points of both rectangles, so their distance is at least the rectangles') are within
    /// `need` plus both half-thicknesses, then at the first corner or edge pair that is.
    pub fn swept_rect_bound_above(&self, o: &Oriented, gap: f64, need: f64) -> f64 {
        if gap <= 0.0 {
            return gap;
        }
        let reach = need + self.half_thickness() + o.half_thickness();
        // Nothing to gain when even the centres are within reach (a NaN stops here too).
        let centres = (self.centre() - o.centre()).length();
        if reach >= 0.0 && centres.partial_cmp(&reach) != Some(std::cmp::Ordering::Greater) {
            return gap;
        }
        let stop = if reach >= 0.0 { reach * reach } else { f64::NEG_INFINITY };
        match self.rect_distance_sq(o, stop) {
            Some(d2) => gap.max(d2.sqrt() - self.half_thickness() - o.half_thickness()),
            None => gap,
        }
    }

    /// The centre of the mid-plane rectangle.
    #[inline]
    fn centre(&self) -> DVec3 {
        let [n, u, v] = self.axes;
        n * (0.5 * (self.lo.x + self.hi.x))
            + u * (0.5 * (self.lo.y + self.hi.y))
            + v * (0.5 * (self.lo.z + self.hi.z))
    }

    /// Half the slab's thickness along its normal.
    #[inline]
    fn half_thickness(&self) -> f64 {
        0.5 * (self.hi.x - self.lo.x)
    }

    /// The corners of the mid-plane rectangle, in order around it.
    #[inline]
    fn corners(&self) -> [DVec3; 4] {
        let [n, u, v] = self.axes;
        let mid = n * (0.5 * (self.lo.x + self.hi.x));
        let p = |s: f64, t: f64| mid + u * s + v * t;
        [p(self.lo.y, self.lo.z), p(self.hi.y, self.lo.z), p(self.hi.y, self.hi.z), p(self.lo.y, self.hi.z)]
    }

    /// Squared distance from `p` to the mid-plane rectangle, read in the slab's own frame: the
    /// height over the plane, and how far the in-plane coordinates lie outside the rectangle.
    #[inline]
    fn rect_point_sq(&self, p: DVec3) -> f64 {
        let [n, u, v] = self.axes;
        let h = n.dot(p) - 0.5 * (self.lo.x + self.hi.x);
        let (s, t) = (u.dot(p), v.dot(p));
        let (ds, dt) = (s - s.clamp(self.lo.y, self.hi.y), t - t.clamp(self.lo.z, self.hi.z));
        h * h + ds * ds + dt * dt
    }

    /// The distance between the mid-plane rectangles of two slabs that are apart: two disjoint
    /// convex polygons are closest at a corner of one against the other, or at two edges, so
    /// eight corner–rectangle and sixteen edge–edge distances give it (a third of the work of
    /// splitting each rectangle into two triangles and taking four triangle distances).
    ///
    /// Squared; `None` as soon as one candidate is at most `stop` (the caller then has no use
    /// for the exact value).
    fn rect_distance_sq(&self, o: &Oriented, stop: f64) -> Option<f64> {
        let (ca, cb) = (self.corners(), o.corners());
        let mut d2 = f64::INFINITY;
        for k in 0..4 {
            d2 = d2.min(o.rect_point_sq(ca[k])).min(self.rect_point_sq(cb[k]));
            if d2 <= stop {
                return None;
            }
        }
        let edges = |c: [DVec3; 4]| {
            [0, 1, 2, 3].map(|k| {
                let d = c[(k + 1) % 4] - c[k];
                (c[k], d, d.dot(d))
            })
        };
        let eb = edges(cb);
        for (p1, d1, a) in edges(ca) {
            for &(p2, d2_, e) in &eb {
                let (x, y) = crate::narrow::distance::segments_core(p1, d1, a, p2, d2_, e);
                d2 = d2.min((x - y).length_squared());
            }
            if d2 <= stop {
                return None;
            }
        }
        Some(d2)
    }
}

/// A lower bound on the distance between two triangles from their planes: the largest gap
/// between one triangle's plane and the other's three vertices, over both triangles (0 when each
/// plane meets the other triangle or a triangle is degenerate). Subtract
/// [`crate::geom::predicates::oriented_bound_margin`] before pruning with it.
#[inline]
pub fn plane_gap(t: &[DVec3; 3], nt: DVec3, s: &[DVec3; 3], ns: DVec3) -> f64 {
    one_plane_gap(t, nt, s).max(one_plane_gap(s, ns, t))
}

/// The gap between the plane of `t` (unit normal `n`, or zero for a degenerate `t`) and `s`.
#[inline]
fn one_plane_gap(t: &[DVec3; 3], n: DVec3, s: &[DVec3; 3]) -> f64 {
    let o = n.dot(t[0]);
    let d = s.map(|p| n.dot(p) - o);
    let lo = d[0].min(d[1]).min(d[2]);
    let hi = d[0].max(d[1]).max(d[2]);
    lo.max(-hi).max(0.0)
}

/// The unit normal of `t`, or zero when it has no area in f64.
#[inline]
pub fn unit_normal(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow::distance::triangle_distance;

    /// A small random generator (xorshift) for reproducible point sets.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn point(&mut self, c: DVec3, r: f64) -> DVec3 {
            c + DVec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5) * r
        }
    }

    fn patch(rng: &mut Rng, c: DVec3, r: f64, flat: f64) -> Vec<[DVec3; 3]> {
        (0..6)
            .map(|_| {
                [0, 1, 2].map(|_| {
                    let mut p = rng.point(c, r);
                    p.z = c.z + (p.z - c.z) * flat;
                    p
                })
            })
            .collect()
    }

    #[test]
    fn oriented_gap_never_exceeds_the_true_distance() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        let mut tight = 0;
        for case in 0..2000 {
            let flat = if case % 2 == 0 { 0.01 } else { 1.0 };
            let a = patch(&mut rng, DVec3::ZERO, 1.0, flat);
            let off = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, 0.2 + 2.0 * rng.next());
            let b = patch(&mut rng, off, 1.0, flat);
            let (Some(oa), Some(ob)) =
                (Oriented::of_triangles(a.iter().copied()), Oriented::of_triangles(b.iter().copied()))
            else {
                continue;
            };
            let truth = a
                .iter()
                .flat_map(|x| b.iter().map(move |y| triangle_distance(x, y).distance))
                .fold(f64::INFINITY, f64::min);
            let g = oa.gap(&ob);
            assert!(g <= truth + 1e-12, "case {case}: gap {g} > distance {truth}");
            let r = oa.swept_rect_bound(&ob, g);
            assert!(r >= g && r <= truth + 1e-12, "case {case}: swept {r} > distance {truth}");
            assert_eq!(g, ob.gap(&oa), "symmetric");
            if flat < 1.0 && g > 0.5 * truth {
                tight += 1;
            }
            for x in &a {
                for y in &b {
                    let pg = plane_gap(x, unit_normal(x), y, unit_normal(y));
                    assert!(pg <= triangle_distance(x, y).distance + 1e-12);
                }
            }
        }
        // Flat patches facing each other are bounded tightly most of the time.
        assert!(tight > 300, "only {tight} tight bounds");
    }

    #[test]
    fn the_bound_above_a_need_equals_the_full_bound_where_it_exceeds_the_need() {
        // Curved and flat patches at every offset, and needs below, around and above the full
        // bound: where the full bound clears the need (by more than rounding) the early-exit
        // form returns it bit for bit; elsewhere it returns the plain gap, never more than the
        // need, so a search pruning at the need prunes exactly the same pairs.
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut same, mut gave_up) = (0, 0);
        for case in 0..3000 {
            let flat = [0.01, 0.1, 1.0][case % 3];
            let a = patch(&mut rng, DVec3::ZERO, 1.0, flat);
            let off = DVec3::new(4.0 * rng.next() - 2.0, 4.0 * rng.next() - 2.0, 0.1 + 2.0 * rng.next());
            let size = 0.2 + rng.next();
            let b = patch(&mut rng, off, size, flat);
            let (Some(oa), Some(ob)) =
                (Oriented::of_triangles(a.iter().copied()), Oriented::of_triangles(b.iter().copied()))
            else {
                continue;
            };
            let g = oa.gap(&ob);
            let full = oa.swept_rect_bound(&ob, g);
            for need in [
                f64::NEG_INFINITY,
                -1.0,
                0.0,
                g,
                0.5 * (g + full),
                full,
                full * (1.0 + 1e-9),
                2.0 * full + 1.0,
            ] {
                let r = oa.swept_rect_bound_above(&ob, g, need);
                if full > need * (1.0 + 1e-9) + 1e-12 {
                    assert_eq!(r.to_bits(), full.to_bits(), "case {case}, need {need}: {r} != {full}");
                    same += 1;
                } else {
                    assert!(
                        r == full || (r == g && r <= need.max(g)),
                        "case {case}, need {need}: {r} ({g}, {full})"
                    );
                    gave_up += usize::from(r != full);
                }
            }
        }
        assert!(same > 3000 && gave_up > 1000, "{same} equal, {gave_up} given up");
    }

    #[test]
    fn parallel_patches_are_bounded_by_their_gap() {
        // Two tilted flat squares 0.5 apart along their common normal: a box bound sees far
        // less, the oriented bound sees the gap.
        let n = DVec3::new(1.0, 1.0, 1.0).normalize();
        let u = DVec3::new(1.0, -1.0, 0.0).normalize();
        let v = n.cross(u);
        let square = |off: f64| {
            let p = |s: f64, t: f64| n * off + u * s + v * t;
            vec![[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)], [p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]]
        };
        let (a, b) = (square(0.0), square(0.5));
        let oa = Oriented::of_triangles(a.iter().copied()).unwrap();
        let ob = Oriented::of_triangles(b.iter().copied()).unwrap();
        assert!((oa.gap(&ob) - 0.5).abs() < 1e-12);
        let ba = crate::geom::Aabb::of_points(a.iter().flatten());
        let bb = crate::geom::Aabb::of_points(b.iter().flatten());
        assert!(ba.distance_sq(&bb).sqrt() < 0.1);
    }

    #[test]
    fn closed_sets_give_no_oriented_bound() {
        // A tetrahedron's outward normals cancel.
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let tris = [[p[0], p[2], p[1]], [p[0], p[1], p[3]], [p[0], p[3], p[2]], [p[1], p[2], p[3]]];
        assert!(Oriented::of_triangles(tris.iter().copied()).is_none());
        assert!(Oriented::of_triangles(std::iter::empty()).is_none());
    }
}
