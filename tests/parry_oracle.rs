//! Against parry3d-f64 on unit-scale meshes in random rigid placements, away from touching
//! configurations (random float coordinates make exact contacts a measure-zero event): the same
//! "intersecting?" verdict, the same pair set, distances equal to 1e-9 relative, and witness
//! points on the reported triangles.

use glam::{DMat4, DQuat, DVec3};
use meshclash::bvh::triangle;
use meshclash::check::cross_check::parry_f64;
use meshclash::check::query::{check, place, Settings};
use meshclash::narrow::distance::closest_point_on_triangle;
use meshclash::scene::mesh::{Mesh, Object};
use proptest::prelude::*;
use std::path::Path;

/// A closed UV sphere of radius `r` with `n` segments: unit-scale triangles (parry's GJK is
/// reliable there; it reports false pairs on much smaller triangles).
fn sphere(r: f64, n: usize) -> Mesh {
    let mut positions = vec![DVec3::new(0.0, 0.0, r), DVec3::new(0.0, 0.0, -r)];
    let rings = n / 2;
    for i in 1..rings {
        let th = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..n {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / n as f64;
            positions.push(DVec3::new(r * th.sin() * ph.cos(), r * th.sin() * ph.sin(), r * th.cos()));
        }
    }
    let at = |i: usize, j: usize| (2 + (i - 1) * n + j % n) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        triangles.push([0, at(1, j), at(1, j + 1)]);
        triangles.push([1, at(rings - 1, j + 1), at(rings - 1, j)]);
        for i in 1..rings - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let tri_object = vec![0; triangles.len()];
    Mesh {
        positions,
        triangles,
        tri_object,
        objects: vec![Object { name: "sphere".into(), ..Default::default() }],
    }
}

fn placed(m: &Mesh, axis: DVec3, angle: f64, t: DVec3) -> Mesh {
    let mut m = m.clone();
    let q = DQuat::from_axis_angle(axis.normalize(), angle);
    place(&mut m, &DMat4::from_rotation_translation(q, t), Path::new("test")).unwrap();
    m
}

fn on_triangle(m: &Mesh, t: u32, p: DVec3) -> f64 {
    let [a, b, c] = triangle(m, t);
    (closest_point_on_triangle(p, a, b, c) - p).length()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn pairs_and_distances_match_parry_f64(
        ax in (-1.0f64..1.0, -1.0f64..1.0, 0.1f64..1.0),
        angle in 0.0f64..std::f64::consts::TAU,
        tx in -2.5f64..2.5, ty in -2.5f64..2.5, tz in -2.5f64..2.5,
        ra in 0.6f64..1.2, rb in 0.4f64..1.0,
    ) {
        let a = placed(&sphere(ra, 24), DVec3::new(0.3, 0.2, 1.0), 0.7, DVec3::ZERO);
        let b = placed(&sphere(rb, 16), DVec3::new(ax.0, ax.1, ax.2), angle, DVec3::new(tx, ty, tz));
        let ours = check(&a, &b, &Settings::default());
        let parry = parry_f64(&a, &b, true).unwrap();
        let our_pairs: Vec<(u32, u32)> = ours.pairs.iter().map(|p| (p.a, p.b)).collect();
        prop_assert_eq!(&our_pairs, &parry.intersecting_pairs);
        prop_assert_eq!(ours.counts.touching, 0, "random placements do not touch exactly");
        let c = ours.closest.unwrap();
        if our_pairs.is_empty() {
            prop_assert!((c.distance - parry.distance).abs() <= 1e-9 * parry.distance.max(1e-300),
                "ours {} parry {}", c.distance, parry.distance);
            prop_assert!(on_triangle(&a, c.a.0, c.a.1) <= 1e-12);
            prop_assert!(on_triangle(&b, c.b.0, c.b.1) <= 1e-12);
            prop_assert!(((c.a.1 - c.b.1).length() - c.distance).abs() <= 1e-12);
        } else {
            prop_assert_eq!(c.distance, 0.0);
            prop_assert_eq!(parry.distance, 0.0);
        }
    }
}
