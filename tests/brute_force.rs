//! The whole pipeline (BVH build, dual walk, exact classification, branch-and-bound distance)
//! against brute force over every triangle pair, on random small meshes rich in exact contacts.

use meshclash::bvh::{BuildOptions, Strategy as Split};
use meshclash::check::query::{check, PairKind, Settings};
use meshclash::geom::predicates::Tolerances;
use meshclash::geom::DVec3;
use meshclash::narrow::exact_distance::exact_distance_sq;
use meshclash::narrow::tri_tri::classify;
use meshclash::scene::mesh::{Mesh, Object};
use proptest::prelude::*;

fn mesh(tris: &[[DVec3; 3]]) -> Mesh {
    Mesh {
        positions: tris.iter().flatten().copied().collect(),
        triangles: (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        tri_object: vec![0; tris.len()],
        objects: vec![Object { name: "o".into(), ..Default::default() }],
    }
}

/// Triangles with vertices on a coarse integer grid (scaled): many shared vertices, shared
/// edges, coplanar pairs and zero-area triangles, all exact in binary.
fn grid_tri(scale: f64, offset: f64) -> impl Strategy<Value = [DVec3; 3]> {
    let c = -2i32..=2;
    [(c.clone(), c.clone(), c.clone()), (c.clone(), c.clone(), c.clone()), (c.clone(), c.clone(), c)]
        .prop_map(move |v| {
            v.map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64) * scale + DVec3::splat(offset))
        })
}

fn float_tri() -> impl Strategy<Value = [DVec3; 3]> {
    let c = -1.0f64..1.0;
    [(c.clone(), c.clone(), c.clone()), (c.clone(), c.clone(), c.clone()), (c.clone(), c.clone(), c)]
        .prop_map(|v| v.map(|(x, y, z)| DVec3::new(x, y, z)))
}

struct Brute {
    pairs: Vec<(u32, u32, bool)>,
    min: f64,
}

/// A lower bound of the distance between two triangles: the gap between their bounding boxes,
/// each operation rounded down (one step below the nearest float), so it never exceeds the true
/// distance.
fn gap_lower_bound(a: &[DVec3; 3], b: &[DVec3; 3]) -> f64 {
    let lo = |t: &[DVec3; 3]| t[0].min(t[1]).min(t[2]);
    let hi = |t: &[DVec3; 3]| t[0].max(t[1]).max(t[2]);
    let (alo, ahi, blo, bhi) = (lo(a), hi(a), lo(b), hi(b));
    let mut sq = 0.0f64;
    for k in 0..3 {
        let gap = if blo[k] > ahi[k] {
            blo[k] - ahi[k]
        } else if alo[k] > bhi[k] {
            alo[k] - bhi[k]
        } else {
            0.0
        };
        let gap = gap.next_down().max(0.0);
        sq = (sq + (gap * gap).next_down().max(0.0)).next_down().max(0.0);
    }
    sq.sqrt().next_down().max(0.0)
}

fn brute(a: &[[DVec3; 3]], b: &[[DVec3; 3]]) -> Brute {
    let mut pairs = Vec::new();
    let mut min = f64::INFINITY;
    for (i, ta) in a.iter().enumerate() {
        for (j, tb) in b.iter().enumerate() {
            match classify(ta, tb) {
                Some(h) => {
                    pairs.push((i as u32, j as u32, h.crossing));
                    min = 0.0;
                }
                // The exact distance, correctly rounded (what the reported minimum is), unless
                // it cannot lower `min`: a true distance >= a float `min` rounds to >= `min`
                // (this skips every pair once a contact is found).
                None if gap_lower_bound(ta, tb) >= min => {}
                None => min = min.min(exact_distance_sq(ta, tb).rounded()),
            }
        }
    }
    Brute { pairs, min }
}

fn compare(a: &[[DVec3; 3]], b: &[[DVec3; 3]], opts: BuildOptions) -> Result<(), TestCaseError> {
    let settings = Settings { tolerances: Tolerances::default(), bvh: opts, ..Default::default() };
    let r = check(&mesh(a), &mesh(b), &settings);
    let want = brute(a, b);
    let got: Vec<(u32, u32, bool)> =
        r.pairs.iter().map(|p| (p.a, p.b, p.kind == PairKind::Crossing)).collect();
    prop_assert_eq!(&got, &want.pairs);
    let d = r.closest.expect("non-empty meshes have a closest pair").distance;
    if want.min == 0.0 {
        prop_assert_eq!(d, 0.0);
    } else {
        prop_assert!((d - want.min).abs() <= 1e-12 * want.min.max(1.0), "bvh {} vs brute {}", d, want.min);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn grid_meshes_match_brute_force(
        a in prop::collection::vec(grid_tri(1.0, 0.0), 1..40),
        b in prop::collection::vec(grid_tri(1.0, 0.0), 1..40),
        leaf in 1u32..6,
        strat in 0usize..3,
    ) {
        let strategy = [Split::Sah, Split::Median, Split::Equal][strat];
        compare(&a, &b, BuildOptions { strategy, leaf_size: leaf })?;
    }

    #[test]
    fn far_and_tiny_grid_meshes_match_brute_force(
        a in prop::collection::vec(grid_tri(0.5f64.powi(20), 1.0e8), 1..30),
        b in prop::collection::vec(grid_tri(0.5f64.powi(20), 1.0e8), 1..30),
    ) {
        compare(&a, &b, BuildOptions::default())?;
    }

    #[test]
    fn float_meshes_match_brute_force(
        a in prop::collection::vec(float_tri(), 1..60),
        b in prop::collection::vec(float_tri(), 1..60),
        shift in -2.0f64..2.0,
    ) {
        let b: Vec<[DVec3; 3]> = b.iter().map(|t| t.map(|p| p + DVec3::new(shift, 0.0, 0.0))).collect();
        compare(&a, &b, BuildOptions::default())?;
    }

    /// The oracle's pruning bound is sound: never above the exact distance.
    #[test]
    fn the_box_gap_bound_never_exceeds_the_exact_distance(
        a in float_tri(),
        b in float_tri(),
        shift in prop::sample::select(vec![0.0, 1.0, 2.0, 3.0, 1.0e-3, 1.0e8]),
    ) {
        let b = b.map(|p| p + DVec3::new(shift, shift * 0.5, 0.0));
        let lb = gap_lower_bound(&a, &b);
        if lb > 0.0 {
            prop_assert!(classify(&a, &b).is_none());
            prop_assert!(exact_distance_sq(&a, &b).cmp_distance(lb) != std::cmp::Ordering::Less, "{}", lb);
        }
    }
}

#[test]
fn thread_count_does_not_change_the_result() {
    // Two overlapping bumpy grids, big enough to be split across many sub-walks.
    let grid = |n: usize, dz: f64, k: usize| -> Vec<[DVec3; 3]> {
        let f =
            |x: usize, y: usize| DVec3::new(x as f64, y as f64, ((x * k + y * 13) % 5) as f64 * 0.25 + dz);
        let mut t = Vec::new();
        for x in 0..n {
            for y in 0..n {
                t.push([f(x, y), f(x + 1, y), f(x, y + 1)]);
                t.push([f(x + 1, y), f(x + 1, y + 1), f(x, y + 1)]);
            }
        }
        t
    };
    let (a, b) = (mesh(&grid(60, 0.0, 7)), mesh(&grid(60, 0.3, 3)));
    let settings = Settings {
        tolerances: Tolerances { touch: 0.0, clearance: 0.2 },
        bvh: BuildOptions::default(),
        ..Default::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut r = pool.install(|| check(&a, &b, &settings));
        r.timings = Default::default();
        r
    };
    let one = run(1);
    assert!(one.counts.crossing > 0 && one.counts.clearance > 0);
    for t in [2, 3, 4] {
        assert_eq!(run(t), one, "{t} threads");
    }
}
