//! Cross-check against [parry3d](https://parry.rs): run the same clash query through parry and
//! compare.
//!
//! # What parry does
//!
//! [`parry_f64`] builds one parry `TriMesh` per mesh (which builds parry's own BVH over the
//! triangles' AABBs), walks the two BVHs together with `Bvh::leaf_pairs` to get every pair of
//! triangles whose AABBs touch, and hands each such pair to parry's generic
//! `query::intersection_test`. For two `Triangle`s that dispatches to GJK on the
//! Minkowski difference (`intersection_test_support_map_support_map`). The minimum distance is
//! `query::distance` between the two `TriMesh` shapes: a best-first BVH descent over mesh `a`
//! whose leaves each run a best-first descent over mesh `b`, ending in GJK distance between two
//! triangles. Witness points are `query::closest_points` between the two triangles parry's
//! distance names (`ShapeDistance::subshape1/2`), so they cost one GJK call.
//!
//! # Why parry is not exact
//!
//! GJK is iterative floating-point geometry with *absolute* tolerances, not an exact predicate
//! (`eps_tol = 10 · ε` ≈ 2.2e-15 in f64, ≈ 1.2e-6 in f32):
//!
//! * "Intersecting" is declared once the origin is within `eps_tol` of the simplex, so touching
//!   triangles (shared vertex or edge, coplanar contact) land on either side depending on
//!   rounding, and far from the origin rounding of the Minkowski difference (≈ |x| · ε) can
//!   exceed the threshold.
//! * Its Voronoi simplex refuses a new support point when the simplex would get an edge shorter
//!   than, or a face with `|ab × ac|` below, `sqrt(eps_tol)` (≈ 4.7e-8 in f64, ≈ 1.1e-3 in f32,
//!   in world units). GJK then stalls, and the intersection test, after a few perturbed
//!   directions, answers "intersecting". So **small triangles give false positives on clearly
//!   separated pairs**: in f32 at unit scale (edges ≈ 0.016) parry reports 2.5× too many pairs,
//!   some 0.011 apart; in f64 the same happens once edges are ≈ 1e-5. The distance query stalls
//!   the same way and returns a too-large distance (+21 % for a 1e-4-size pair in f64, for a
//!   1e-2-size pair in f32). Scaling the scene up makes both go away.
//! * The distance converges only to a relative `sqrt(eps_tol)`, returns 0 when GJK gives up
//!   after 100 iterations, and returns 0 for gaps around 1e-14 (f64) or 1e-6 (f32) at unit
//!   scale while the intersection test reports no pair for the same geometry.
//! * `parry_f32` (in the `meshclash-bench` crate, built from the same macro) first rounds every f64 position to the
//!   nearest f32: that rounding is part of what it measures, and it alone opens or closes gaps
//!   of about `|x| · 6e-8`.
//!
//! So on touching, nearly touching or small triangles disagreement with the exact pair set and
//! distance is expected and says nothing about our code; on clearly crossing or clearly
//! separated pairs of reasonably sized triangles it is a bug in one of the two.
//!
//! # What parry does with the input
//!
//! `TriMesh::new` (no flags) keeps the vertex and index buffers exactly as given: it does not
//! merge duplicate vertices, does not drop degenerate (zero-area, collinear or repeated-index)
//! or duplicate triangles, and computes no topology, so non-manifold or inconsistently wound
//! meshes are accepted too. We never pass the flags that would change that
//! (`MERGE_DUPLICATE_VERTICES`, `DELETE_DEGENERATE_TRIANGLES`, …), so parry's triangle `i` is
//! always our triangle `i` and pair indices are directly comparable. The only input it rejects
//! is an empty index buffer (`TriMeshBuilderError::EmptyIndices`), which we pass on as `Err`.
//! GJK handles a degenerate triangle as the segment or point it really is (its support map is
//! that of the hull of its three vertices), so a needle through a face is reported.
//!
//! Two inputs would make parry panic rather than fail, so we reject them first with `Err`: a
//! triangle index past the end of `positions` (parry indexes its vertex buffer unchecked), and
//! a non-finite coordinate (GJK asserts its bounds are finite) — for the f32 variant this
//! includes f64 values that overflow f32.

use crate::scene::mesh::Mesh;

/// rayon, for [`__impl_parry`](crate::__impl_parry) expanded in another crate.
#[doc(hidden)]
pub use rayon as __rayon;

/// What parry3d reports for the same two meshes (already in world coordinates).
#[derive(Debug, Clone, PartialEq)]
pub struct ParryResult {
    /// Triangle pairs (index in a, index in b) parry's triangle–triangle intersection test calls
    /// intersecting, sorted.
    pub intersecting_pairs: Vec<(u32, u32)>,
    /// parry's minimum distance between the two meshes (0 if intersecting); `NaN` when the
    /// distance was not computed (`compute_distance == false`).
    pub distance: f64,
    /// parry's witness points (on a, on b) of `distance`, when it is positive and was computed.
    pub points: Option<([f64; 3], [f64; 3])>,
    /// Wall time of parry's pair search (BVH traversal plus triangle–triangle tests), ms.
    pub pairs_ms: f64,
    /// Wall time of parry's distance query (plus the witness points), ms; 0 when skipped.
    pub distance_ms: f64,
    /// Wall time of building both `TriMesh`es (parry's BVH build included), ms.
    pub build_ms: f64,
    /// Bytes of parry's two BVHs (`Bvh::total_memory_size`), vertex and index buffers excluded.
    pub tree_bytes: usize,
}

/// Pairs only one side reports: (only in ours, only in parry's).
///
/// The inputs need not be sorted or free of duplicates; both outputs are sorted and
/// deduplicated.
#[allow(clippy::type_complexity)] // the plain tuple types are the API
pub fn diff_pairs(ours: &[(u32, u32)], parry: &[(u32, u32)]) -> (Vec<(u32, u32)>, Vec<(u32, u32)>) {
    let sorted = |v: &[(u32, u32)]| {
        let mut v = v.to_vec();
        v.sort_unstable();
        v.dedup();
        v
    };
    let (ours, parry) = (sorted(ours), sorted(parry));
    let (mut only_ours, mut only_parry) = (Vec::new(), Vec::new());
    let (mut i, mut j) = (0, 0);
    while i < ours.len() && j < parry.len() {
        match ours[i].cmp(&parry[j]) {
            std::cmp::Ordering::Less => {
                only_ours.push(ours[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                only_parry.push(parry[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                i += 1;
                j += 1;
            }
        }
    }
    only_ours.extend_from_slice(&ours[i..]);
    only_parry.extend_from_slice(&parry[j..]);
    (only_ours, only_parry)
}

/// Rejects what would make parry panic instead of failing: out-of-range indices and
/// coordinates that are not finite or exceed `max_abs` (the largest finite value of parry's
/// scalar type).
#[doc(hidden)]
pub fn check_input(m: &Mesh, which: &str, max_abs: f64) -> Result<(), String> {
    let n = m.positions.len();
    if let Some((t, tri)) =
        m.triangles.iter().enumerate().find(|(_, tri)| tri.iter().any(|&v| v as usize >= n))
    {
        return Err(format!("mesh {which}: triangle {t} {tri:?} indexes past the {n} vertices"));
    }
    if let Some((v, p)) =
        m.positions.iter().enumerate().find(|(_, p)| !p.is_finite() || p.abs().max_element() > max_abs)
    {
        return Err(format!("mesh {which}: vertex {v} {p} is not finite in parry's precision"));
    }
    Ok(())
}

/// Instantiates the parry cross-check for one parry crate (`parry3d_f64` here, `parry3d` in the
/// `meshclash-bench` crate, which is where the f32 variant lives so that the product does not
/// link parry3d f32) and its scalar type. The caller's crate must depend on `$krate`.
#[doc(hidden)]
#[macro_export]
macro_rules! __impl_parry {
    ($(#[$attr:meta])* $name:ident, $krate:ident, $real:ty) => {
        $(#[$attr])*
        pub fn $name(
            a: &$crate::scene::mesh::Mesh,
            b: &$crate::scene::mesh::Mesh,
            compute_distance: bool,
        ) -> Result<$crate::check::cross_check::ParryResult, String> {
            use $crate::check::cross_check::{check_input, ParryResult};
            use $crate::scene::mesh::Mesh;
            use $crate::check::cross_check::__rayon::prelude::*;
            use std::time::Instant;
            use $krate::math::{Pose, Vector};
            use $krate::query::{self, ClosestPoints};
            use $krate::shape::TriMesh;

            check_input(a, "a", <$real>::MAX as f64)?;
            check_input(b, "b", <$real>::MAX as f64)?;
            let build = |m: &Mesh, which: &str| -> Result<TriMesh, String> {
                let vertices: Vec<Vector> = m
                    .positions
                    .iter()
                    .map(|p| Vector::new(p.x as $real, p.y as $real, p.z as $real))
                    .collect();
                let mesh = TriMesh::new(vertices, m.triangles.clone())
                    .map_err(|e| format!("parry rejected mesh {which}: {e}"))?;
                if mesh.num_triangles() != m.triangles.len() {
                    return Err(format!(
                        "parry changed mesh {which}: {} triangles in, {} kept",
                        m.triangles.len(),
                        mesh.num_triangles()
                    ));
                }
                Ok(mesh)
            };
            let build_start = Instant::now();
            let (ta, tb) = (build(a, "a")?, build(b, "b")?);
            let build_ms = build_start.elapsed().as_secs_f64() * 1e3;
            let tree_bytes = ta.bvh().total_memory_size() + tb.bvh().total_memory_size();
            let id = Pose::identity();
            let unsupported = |what: &str| format!("parry: {what} unsupported for these shapes");
            // Start rayon's pool outside the timed region.
            $crate::check::cross_check::__rayon::current_num_threads();

            let start = Instant::now();
            let candidates: Vec<(u32, u32)> =
                ta.bvh().leaf_pairs(tb.bvh(), |n1, n2| n1.intersects(n2)).collect();
            let tested: Vec<Option<(u32, u32)>> = candidates
                .into_par_iter()
                .map(|(i, j)| {
                    query::intersection_test(&id, &ta.triangle(i), &id, &tb.triangle(j))
                        .map(|r| r.intersecting.then_some((i, j)))
                })
                .collect::<Result<_, _>>()
                .map_err(|_| unsupported("triangle-triangle intersection test"))?;
            let mut intersecting_pairs: Vec<(u32, u32)> = tested.into_iter().flatten().collect();
            intersecting_pairs.par_sort_unstable();
            let pairs_ms = start.elapsed().as_secs_f64() * 1e3;

            let (distance, points, distance_ms) = if compute_distance {
                let start = Instant::now();
                let d = query::distance(&id, &ta, &id, &tb)
                    .map_err(|_| unsupported("TriMesh-TriMesh distance"))?;
                let points = if d.distance > 0.0 {
                    let (t1, t2) = (ta.triangle(d.subshape1), tb.triangle(d.subshape2));
                    match query::closest_points(&id, &t1, &id, &t2, <$real>::MAX) {
                        Ok(ClosestPoints::WithinMargin(p, q)) => Some((
                            [p.x as f64, p.y as f64, p.z as f64],
                            [q.x as f64, q.y as f64, q.z as f64],
                        )),
                        _ => None,
                    }
                } else {
                    None
                };
                (d.distance as f64, points, start.elapsed().as_secs_f64() * 1e3)
            } else {
                (f64::NAN, None, 0.0)
            };

            Ok(ParryResult { intersecting_pairs, distance, points, pairs_ms, distance_ms, build_ms, tree_bytes })
        }
    };
}

__impl_parry!(
    /// Runs parry3d-f64 on `a` and `b` (see the module docs): every triangle pair whose parry
    /// BVH leaves overlap, tested with parry's triangle–triangle `intersection_test`, and, if
    /// `compute_distance`, parry's `TriMesh`–`TriMesh` distance and witness points.
    ///
    /// Cost (two ~80k-triangle spheres, 2 threads): the pair search takes ~10 ms; the
    /// distance 0–60 ms when the meshes are apart, ~0.3 s when they overlap, and ~4 s when one
    /// lies inside the other's bounding box (parry bounds each BVH node of `a` by its distance
    /// to the whole AABB of `b`, which is 0 there). Pass `compute_distance = false` to skip it.
    ///
    /// Errors (one line) if parry rejects a mesh (no triangles) or the input would make it
    /// panic (index out of range, non-finite coordinate).
    parry_f64,
    parry3d_f64,
    f64
);

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn mesh(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            tri_object: vec![0; triangles.len()],
            objects: vec![crate::scene::mesh::Object { name: "o".into(), ..Default::default() }],
            positions,
            triangles,
        }
    }

    /// Axis-aligned cube `[min, min + size]³`, 12 outward-wound triangles.
    fn cube(min: DVec3, size: f64) -> Mesh {
        let positions = (0..8)
            .map(|i| min + size * DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1], // z = 0
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        let triangles = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        mesh(positions, triangles)
    }

    /// UV sphere with `slices × stacks` cells (poles are single vertices), each vertex pushed
    /// radially by a deterministic pseudo-random jitter of up to `jitter · r`.
    fn sphere(center: DVec3, r: f64, slices: u32, stacks: u32, jitter: f64, seed: u64) -> Mesh {
        let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let mut rand = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut positions = vec![DVec3::Z];
        for i in 1..stacks {
            let theta = std::f64::consts::PI * i as f64 / stacks as f64;
            for j in 0..slices {
                let phi = std::f64::consts::TAU * j as f64 / slices as f64;
                positions.push(DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
            }
        }
        positions.push(-DVec3::Z);
        let positions =
            positions.into_iter().map(|p| center + p * r * (1.0 + jitter * rand())).collect::<Vec<_>>();
        let ring = |i: u32, j: u32| 1 + (i - 1) * slices + j % slices;
        let south = positions.len() as u32 - 1;
        let mut triangles = Vec::new();
        for j in 0..slices {
            triangles.push([0, ring(1, j), ring(1, j + 1)]);
            triangles.push([south, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
            for i in 1..stacks - 1 {
                let (a, b, c, d) = (ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1));
                triangles.push([a, c, d]);
                triangles.push([a, d, b]);
            }
        }
        mesh(positions, triangles)
    }

    #[test]
    fn cubes_overlapping_and_separated() {
        let a = cube(DVec3::ZERO, 1.0);
        assert_eq!(a.triangles.len(), 12);
        let b = cube(DVec3::new(0.5, 0.0, 0.0), 1.0);
        let r = parry_f64(&a, &b, true).unwrap();
        assert!(!r.intersecting_pairs.is_empty());
        assert!(r.intersecting_pairs.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(r.distance, 0.0);
        assert_eq!(r.points, None);

        let b = cube(DVec3::new(1.25, 0.0, 0.0), 1.0);
        let r = parry_f64(&a, &b, true).unwrap();
        assert_eq!(r.intersecting_pairs, vec![]);
        assert!((r.distance - 0.25).abs() < 1e-9, "{}", r.distance);
        let (p, q) = r.points.expect("witness points");
        let gap = DVec3::from(q) - DVec3::from(p);
        assert!((gap.length() - 0.25).abs() < 1e-9, "{p:?} {q:?}");
        assert!((p[0] - 1.0).abs() < 1e-9 && (q[0] - 1.25).abs() < 1e-9, "{p:?} {q:?}");

        let r = parry_f64(&a, &b, false).unwrap();
        assert!(r.distance.is_nan() && r.points.is_none() && r.distance_ms == 0.0);
    }

    #[test]
    fn spheres_distance_matches_brute_force() {
        use parry3d_f64::math::{Pose, Vector};
        use parry3d_f64::query;
        use parry3d_f64::shape::Triangle;
        let a = sphere(DVec3::new(0.1, -0.2, 0.3), 1.0, 12, 10, 0.03, 1);
        let b = sphere(DVec3::new(2.2, 0.7, -0.4), 0.8, 12, 10, 0.03, 2);
        assert_eq!(a.triangles.len(), 216);
        let r = parry_f64(&a, &b, true).unwrap();
        assert!(r.intersecting_pairs.is_empty());

        let tri = |m: &Mesh, t: [u32; 3]| {
            let v = |i: u32| {
                let p = m.positions[i as usize];
                Vector::new(p.x, p.y, p.z)
            };
            Triangle::new(v(t[0]), v(t[1]), v(t[2]))
        };
        let id = Pose::identity();
        let mut brute = f64::INFINITY;
        for &ta in &a.triangles {
            for &tb in &b.triangles {
                let d = query::distance(&id, &tri(&a, ta), &id, &tri(&b, tb)).unwrap().distance;
                brute = brute.min(d);
            }
        }
        assert!(brute > 0.1, "{brute}");
        assert!((r.distance - brute).abs() < 1e-9, "parry {} brute {brute}", r.distance);
        let (p, q) = r.points.expect("witness points");
        let gap = (DVec3::from(q) - DVec3::from(p)).length();
        assert!((gap - brute).abs() < 1e-9, "witness gap {gap} brute {brute}");
    }

    #[test]
    fn spheres_overlapping_pairs_are_real_crossings() {
        // Every pair parry reports must at least have overlapping AABBs, and the sphere
        // intersection circle must produce some.
        let a = sphere(DVec3::ZERO, 1.0, 12, 10, 0.03, 3);
        let b = sphere(DVec3::new(1.0, 0.1, 0.05), 1.0, 12, 10, 0.03, 4);
        let r = parry_f64(&a, &b, true).unwrap();
        assert!(r.intersecting_pairs.len() > 10, "{}", r.intersecting_pairs.len());
        assert_eq!(r.distance, 0.0);
    }

    #[test]
    fn diff_pairs_hand_made() {
        let ours = [(0, 1), (2, 3), (2, 5), (7, 0)];
        let parry = [(2, 3), (1, 1), (7, 0), (9, 9)];
        assert_eq!(diff_pairs(&ours, &parry), (vec![(0, 1), (2, 5)], vec![(1, 1), (9, 9)]));
        assert_eq!(diff_pairs(&[], &[]), (vec![], vec![]));
        assert_eq!(diff_pairs(&[(1, 2)], &[]), (vec![(1, 2)], vec![]));
        assert_eq!(diff_pairs(&[], &[(1, 2), (1, 2)]), (vec![], vec![(1, 2)]));
        assert_eq!(diff_pairs(&ours, &ours), (vec![], vec![]));
    }

    #[test]
    fn rejects_what_parry_cannot_take() {
        let a = cube(DVec3::ZERO, 1.0);
        let empty = mesh(vec![DVec3::ZERO], vec![]);
        let e = parry_f64(&a, &empty, true).unwrap_err();
        assert!(e.contains("parry rejected mesh b") && !e.contains('\n'), "{e}");
        let bad_index = mesh(vec![DVec3::ZERO; 3], vec![[0, 1, 3]]);
        assert!(parry_f64(&bad_index, &a, true).unwrap_err().contains("mesh a"));
        let nan = mesh(vec![DVec3::ZERO, DVec3::X, DVec3::NAN], vec![[0, 1, 2]]);
        assert!(parry_f64(&a, &nan, true).is_err());
    }

    #[test]
    fn degenerate_triangles_are_kept_and_tested() {
        // b: a needle (collinear triangle) piercing the cube's z = 0 face, a point-triangle
        // inside the x = 0 face, and a normal triangle far away, with duplicate vertices.
        let a = cube(DVec3::ZERO, 1.0);
        let b = mesh(
            vec![
                DVec3::new(0.3, 0.3, -0.5),
                DVec3::new(0.3, 0.3, 0.5),
                DVec3::new(0.3, 0.3, 0.0),
                DVec3::new(0.0, 0.4, 0.6),
                DVec3::new(0.0, 0.4, 0.6),
                DVec3::new(5.0, 5.0, 5.0),
                DVec3::new(6.0, 5.0, 5.0),
                DVec3::new(5.0, 6.0, 5.0),
            ],
            vec![[0, 1, 2], [3, 4, 3], [5, 6, 7]],
        );
        let r = parry_f64(&a, &b, true).unwrap();
        let bs: Vec<u32> = r.intersecting_pairs.iter().map(|p| p.1).collect();
        assert!(bs.contains(&0), "needle through z = 0 face missed: {bs:?}");
        assert!(!bs.contains(&2));
        assert_eq!(r.distance, 0.0);
    }

    /// Pins the parry 0.31 behaviour the module docs describe: GJK's absolute tolerances make
    /// it stall on small triangles. If this fails after a parry upgrade, update the docs.
    #[test]
    fn parry_tolerances_are_absolute() {
        let pair = |s: f64| {
            let a = mesh(vec![DVec3::ZERO, DVec3::X * s, DVec3::Y * s], vec![[0, 1, 2]]);
            let b = mesh(
                vec![
                    DVec3::new(0.1, 0.1, 0.5) * s,
                    DVec3::new(1.1, 0.2, 0.6) * s,
                    DVec3::new(0.2, 1.1, 0.7) * s,
                ],
                vec![[0, 1, 2]],
            );
            parry_f64(&a, &b, true).unwrap()
        };
        // The true gap is 0.5 · s (b's first vertex, straight above a).
        let r = pair(1.0);
        assert!(r.intersecting_pairs.is_empty() && (r.distance - 0.5).abs() < 1e-12, "{r:?}");
        let r = pair(1e-4);
        assert!(r.intersecting_pairs.is_empty());
        assert!(r.distance > 1.2 * 0.5e-4, "parry's small-triangle distance is now right: {r:?}");
    }
}
