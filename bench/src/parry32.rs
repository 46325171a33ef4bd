//! parry3d (f32) on the same input as [`meshclash::check::cross_check::parry_f64`], from the
//! same macro. It lives here, not in the library, so that the product (`cargo install
//! meshclash`) links parry3d once, in f64, for `--cross-check parry`.

meshclash::__impl_parry!(
    /// [`meshclash::check::cross_check::parry_f64`] with parry3d (f32): every position is first
    /// rounded to the nearest f32, and parry's tolerances are those of f32. Witness points are
    /// converted back to f64.
    ///
    /// Errors as `parry_f64` does, and also when a coordinate overflows f32.
    parry_f32,
    parry3d,
    f32
);

#[cfg(test)]
mod tests {
    use super::parry_f32;
    use glam::DVec3;
    use meshclash::check::cross_check::parry_f64;
    use meshclash::scene::mesh::{Mesh, Object};

    /// Axis-aligned cube `[min, min + size]³`, 12 outward-wound triangles.
    fn cube(min: DVec3, size: f64) -> Mesh {
        let positions: Vec<DVec3> = (0..8)
            .map(|i| min + size * DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let triangles: Vec<[u32; 3]> =
            quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        Mesh {
            tri_object: vec![0; triangles.len()],
            objects: vec![Object { name: "o".into(), ..Default::default() }],
            positions,
            triangles,
        }
    }

    #[test]
    fn f32_cubes() {
        let a = cube(DVec3::ZERO, 1.0);
        let b = cube(DVec3::new(0.5, 0.0, 0.0), 1.0);
        let r32 = parry_f32(&a, &b, true).unwrap();
        let r64 = parry_f64(&a, &b, true).unwrap();
        assert!(!r32.intersecting_pairs.is_empty());
        assert_eq!(r32.distance, 0.0);
        // Unit-size triangles: rounding to f32 is exact here and f32 GJK agrees with f64.
        assert_eq!(r32.intersecting_pairs, r64.intersecting_pairs);

        let b = cube(DVec3::new(1.25, 0.0, 0.0), 1.0);
        let r = parry_f32(&a, &b, true).unwrap();
        assert_eq!(r.intersecting_pairs, vec![]);
        assert!((r.distance - 0.25).abs() < 1e-6, "{}", r.distance);
        assert!(r.points.is_some());
    }

    #[test]
    fn f32_overflow_is_an_error_not_a_panic() {
        let a = cube(DVec3::ZERO, 1.0);
        let b = cube(DVec3::new(1e39, 0.0, 0.0), 1.0);
        let e = parry_f32(&a, &b, false).unwrap_err();
        assert!(e.contains("mesh b") && e.contains("not finite"), "{e}");
        assert!(parry_f64(&a, &b, false).is_ok());
    }
}
