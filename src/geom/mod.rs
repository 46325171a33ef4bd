//! Geometry primitives: f64 vectors (glam's `DVec3`), axis-aligned boxes, and — in
//! [`predicates`] — the one module that holds every exact predicate and every tolerance.

pub mod exact;
pub mod predicates;

pub use glam::DVec3;

/// An axis-aligned bounding box in f64. Built from input coordinates by `min`/`max` only, so it
/// is exact: no rounding ever shrinks it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf): the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb { min: DVec3::INFINITY, max: DVec3::NEG_INFINITY };

    /// The box of a triangle.
    #[inline]
    pub fn of_triangle(t: &[DVec3; 3]) -> Aabb {
        Aabb { min: t[0].min(t[1]).min(t[2]), max: t[0].max(t[1]).max(t[2]) }
    }

    /// The box of a set of points (EMPTY for none).
    pub fn of_points<'a>(pts: impl IntoIterator<Item = &'a DVec3>) -> Aabb {
        pts.into_iter().fold(Aabb::EMPTY, |b, p| b.grow(*p))
    }

    /// This box grown to contain `p`.
    #[inline]
    pub fn grow(self, p: DVec3) -> Aabb {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// True for the empty box.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Centre point (rounded; used only to sort, never to decide).
    #[inline]
    pub fn center(&self) -> DVec3 {
        self.min * 0.5 + self.max * 0.5
    }

    /// Edge lengths.
    #[inline]
    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    /// Half the surface area (the SAH cost only needs proportions); 0 for the empty box.
    #[inline]
    pub fn half_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// True if `o` lies inside this box (closed).
    #[inline]
    pub fn contains(&self, o: &Aabb) -> bool {
        self.min.cmple(o.min).all() && o.max.cmple(self.max).all()
    }

    /// Exact closed-box overlap test (touching boxes overlap).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.cmple(o.max).all() && o.min.cmple(self.max).all()
    }

    /// Squared distance between two boxes (0 when they overlap), a lower bound on the squared
    /// distance between anything inside them, up to f64 rounding of the subtractions.
    #[inline]
    pub fn distance_sq(&self, o: &Aabb) -> f64 {
        let gap = (o.min - self.max).max(self.min - o.max).max(DVec3::ZERO);
        gap.length_squared()
    }

    /// The largest absolute coordinate in the box (its scale, for relative tolerances).
    pub fn max_abs(&self) -> f64 {
        self.min.abs().max(self.max.abs()).max_element()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_is_closed_and_distance_is_zero_inside() {
        let a = Aabb { min: DVec3::ZERO, max: DVec3::ONE };
        let b = Aabb { min: DVec3::new(1.0, 0.5, 0.5), max: DVec3::splat(2.0) };
        assert!(a.overlaps(&b) && b.overlaps(&a));
        assert_eq!(a.distance_sq(&b), 0.0);
        let c = Aabb { min: DVec3::new(1.0 + f64::EPSILON, 0.0, 0.0), max: DVec3::splat(2.0) };
        assert!(!a.overlaps(&c));
        assert!(a.distance_sq(&c) > 0.0);
        let d = Aabb { min: DVec3::new(4.0, 5.0, 0.0), max: DVec3::new(5.0, 6.0, 1.0) };
        assert_eq!(a.distance_sq(&d), 9.0 + 16.0);
    }

    #[test]
    fn empty_box_is_union_identity() {
        let a = Aabb { min: DVec3::new(-1.0, 2.0, 3.0), max: DVec3::new(0.0, 4.0, 5.0) };
        assert_eq!(Aabb::EMPTY.union(a), a);
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.half_area(), 0.0);
        assert!(a.contains(&a));
    }
}
