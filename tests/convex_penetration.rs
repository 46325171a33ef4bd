//! `--penetration` on convex parts: the report's `regions[].penetration` carries the exact
//! separating-axis depth with `method: "exact_convex"` when both objects are closed and convex,
//! checked against a brute-force oracle in big rationals (every face normal and every edge-pair
//! cross product of both parts, both signs, supports over all vertices: the depth is the
//! smallest support overlap over those axes). Non-convex parts keep the sampled estimate (no
//! `method`). Both part orders, two-file and scene mode.

use crate::solids::{both_modes, Solid, V};
use meshclash::pipeline::{self, Request};
use meshclash::report::{PenetrationReport, Report};
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use std::path::Path;

type Q = BigRational;

/// An axis-aligned box (12 triangles, outward).
fn cuboid(lo: V, hi: V) -> Solid {
    let points = (0..8)
        .map(|i| {
            [
                if i & 1 == 1 { hi[0] } else { lo[0] },
                if i & 2 == 2 { hi[1] } else { lo[1] },
                if i & 4 == 4 { hi[2] } else { lo[2] },
            ]
        })
        .collect();
    let tris = vec![
        [0, 4, 2],
        [2, 4, 6],
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [1, 3, 5],
        [3, 7, 5],
    ];
    Solid { points, tris }
}

/// A `k`-sided prism around the z axis through `c`, radius `r`, from `z0` to `z1`.
fn prism(c: [f64; 2], r: f64, k: usize, z0: f64, z1: f64) -> Solid {
    let mut points: Vec<V> = Vec::new();
    for z in [z0, z1] {
        points.extend((0..k).map(|i| {
            let a = std::f64::consts::TAU * i as f64 / k as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin(), z]
        }));
    }
    let (bottom, top) = (points.len(), points.len() + 1);
    points.push([c[0], c[1], z0]);
    points.push([c[0], c[1], z1]);
    let mut tris = Vec::new();
    for i in 0..k {
        let j = (i + 1) % k;
        tris.push([i, j, k + j]);
        tris.push([i, k + j, k + i]);
        tris.push([bottom, j, i]);
        tris.push([top, k + i, k + j]);
    }
    Solid { points, tris }
}

/// Rotation by the unit quaternion of (w, x, y, z) (normalized here), then a translation.
fn rotated(s: &Solid, q: [f64; 4], t: V) -> Solid {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    let m = [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
    ];
    s.map(|p| {
        let r = |i: usize| m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + t[i];
        [r(0), r(1), r(2)]
    })
}

// ---------------------------------------------------------------------------------------------
// The oracle.

fn q(x: f64) -> Q {
    Q::from_float(x).unwrap()
}

fn qv(p: V) -> [Q; 3] {
    p.map(q)
}

fn sub(a: &[Q; 3], b: &[Q; 3]) -> [Q; 3] {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn cross(a: &[Q; 3], b: &[Q; 3]) -> [Q; 3] {
    [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
}

fn dot(a: &[Q; 3], b: &[Q; 3]) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

/// The squared exact penetration depth of convex `a` and `b`: None when some axis separates
/// them strictly.
fn oracle_depth_sq(a: &Solid, b: &Solid) -> Option<Q> {
    let (pa, pb): (Vec<[Q; 3]>, Vec<[Q; 3]>) =
        (a.points.iter().map(|&p| qv(p)).collect(), b.points.iter().map(|&p| qv(p)).collect());
    let normals = |s: &Solid, p: &[[Q; 3]]| -> Vec<[Q; 3]> {
        s.tris.iter().map(|t| cross(&sub(&p[t[1]], &p[t[0]]), &sub(&p[t[2]], &p[t[0]]))).collect()
    };
    let edges = |s: &Solid, p: &[[Q; 3]]| -> Vec<[Q; 3]> {
        s.tris
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(u, v)| sub(&p[v], &p[u]))
            .collect()
    };
    let mut axes = normals(a, &pa);
    axes.extend(normals(b, &pb));
    let (ea, eb) = (edges(a, &pa), edges(b, &pb));
    for x in &ea {
        for y in &eb {
            axes.push(cross(x, y));
        }
    }
    let mut best: Option<Q> = None;
    for n in axes {
        let n2 = dot(&n, &n);
        if n2.is_zero() {
            continue;
        }
        for n in [n.clone(), n.map(|c| -c)] {
            let max_a = pa.iter().map(|p| dot(p, &n)).max().unwrap();
            let min_b = pb.iter().map(|p| dot(p, &n)).min().unwrap();
            let h = max_a - min_b;
            if h.is_negative() {
                return None;
            }
            let d2 = &h * &h / &n2;
            if best.as_ref().is_none_or(|b| d2 < *b) {
                best = Some(d2);
            }
        }
    }
    best
}

/// `depth` agrees with the exact depth `sqrt(want_sq)` within a few ulps of the coordinates.
fn assert_depth(depth: f64, want_sq: &Q, scale: f64, what: &str) {
    let d = q(depth);
    let want = want_sq.to_string();
    let err = (&d * &d - want_sq).abs();
    // |d² - D²| = |d - D| (d + D) <= tol (2 D + tol).
    let tol = q(scale * 1e-13);
    let bound = &tol * (q(2.0 * depth) + &tol);
    assert!(err <= bound, "{what}: depth {depth} vs exact sqrt({want})");
}

// ---------------------------------------------------------------------------------------------
// Running the check.

/// The penetration blocks of every region, two-file and scene mode (which must agree).
fn penetrations(dir: &Path, a: &Solid, b: &Solid) -> Vec<PenetrationReport> {
    let (files, scene) = both_modes(dir, a, b, |r: Request| Request { penetration: true, ..r });
    let blocks = |r: &Report| -> Vec<PenetrationReport> {
        r.regions
            .iter()
            .map(|g| g.penetration.clone().expect("closed parts get a penetration block"))
            .collect()
    };
    let (f, s) = (blocks(&files), blocks(&scene));
    assert!(!f.is_empty(), "the parts clash");
    assert_eq!(f, s, "two-file and scene mode agree");
    f
}

/// Both orders: every region reports `exact_convex` with the oracle's depth; the direction is
/// a unit vector that moves B out of A by the depth.
fn check_convex(a: &Solid, b: &Solid, what: &str) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let want = oracle_depth_sq(a, b).unwrap_or_else(|| panic!("{what}: the oracle finds them apart"));
    let scale = a.points.iter().chain(&b.points).flatten().fold(1.0f64, |m, x| m.max(x.abs()));
    let mut depths = Vec::new();
    for (x, y, order) in [(a, b, "A, B"), (b, a, "B, A")] {
        for p in penetrations(dir.path(), x, y) {
            assert_eq!(p.method.as_deref(), Some("exact_convex"), "{what} ({order})");
            assert!(p.is_exact());
            assert_eq!(p.samples, 0);
            assert_depth(p.depth, &want, scale, &format!("{what} ({order})"));
            let n = p.direction.expect("an exact depth has a direction");
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-12, "{what}: unit direction {n:?}");
            depths.push(p.depth);
        }
    }
    depths[0]
}

#[test]
fn coincident_and_shifted_unit_cubes_have_their_known_depths() {
    let cube = cuboid([0.0; 3], [1.0; 3]);
    assert_eq!(check_convex(&cube, &cube, "coincident cubes"), 1.0);
    let shifted = cuboid([0.75, 0.0, 0.0], [1.75, 1.0, 1.0]);
    assert_eq!(check_convex(&cube, &shifted, "cubes overlapping by 0.25 along x"), 0.25);
    // A thin slab pushed 0.125 into a box from above: the shortest way out is up.
    let slab = cuboid([-3.0, -3.0, 0.875], [3.0, 3.0, 1.5]);
    assert_eq!(check_convex(&cube, &slab, "slab on a box"), 0.125);
}

/// An octahedron with a different reach along each half axis (no four vertices coplanar, so it
/// stays exactly convex when rotated and rounded).
fn octahedron(c: V, r: [f64; 6]) -> Solid {
    let points = vec![
        [c[0] + r[0], c[1], c[2]],
        [c[0] - r[1], c[1], c[2]],
        [c[0], c[1] + r[2], c[2]],
        [c[0], c[1] - r[3], c[2]],
        [c[0], c[1], c[2] + r[4]],
        [c[0], c[1], c[2] - r[5]],
    ];
    let mut tris = Vec::new();
    for (x, y) in [(0, 2), (2, 1), (1, 3), (3, 0)] {
        tris.push([x, y, 4]);
        tris.push([y, x, 5]);
    }
    Solid { points, tris }
}

/// Exact: every vertex on or below every face's plane (the oracle's convexity).
fn exactly_convex(s: &Solid) -> bool {
    let p: Vec<[Q; 3]> = s.points.iter().map(|&x| qv(x)).collect();
    s.tris.iter().all(|t| {
        let n = cross(&sub(&p[t[1]], &p[t[0]]), &sub(&p[t[2]], &p[t[0]]));
        p.iter().all(|v| !dot(&n, &sub(v, &p[t[0]])).is_positive())
    })
}

#[test]
fn rotated_convex_polytopes_match_the_rational_oracle() {
    let oct = octahedron([0.0; 3], [1.3, 0.9, 1.1, 0.7, 1.6, 0.8]);
    let tet = Solid {
        points: vec![[0.0, 0.0, 0.0], [2.0, 0.1, 0.0], [0.3, 1.7, 0.2], [0.4, 0.5, 1.9]],
        tris: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    };
    let cases = [
        (
            rotated(&oct, [0.9, 0.3, -0.2, 0.1], [0.3, 0.1, 0.2]),
            rotated(&tet, [0.2, 0.7, 0.1, 0.4], [0.1, -0.2, 0.1]),
        ),
        (
            rotated(&tet, [1.0, 0.0, 0.0, 0.6], [0.0; 3]),
            rotated(&oct, [0.5, 0.5, 0.5, -0.1], [0.1, 0.1, 0.1]),
        ),
        (
            rotated(&oct, [0.3, -0.8, 0.4, 0.2], [0.0; 3]),
            rotated(&oct, [0.7, 0.1, 0.6, -0.3], [0.6, 0.2, -0.5]),
        ),
        (
            rotated(&tet, [0.1, 0.2, 0.3, 0.4], [1e3, -2e3, 5e2]),
            rotated(&tet, [0.4, -0.3, 0.2, 0.9], [1e3 + 0.7, -2e3 + 0.5, 5e2 + 0.4]),
        ),
        (prism([0.0, 0.0], 2.0, 9, 0.0, 1.0), rotated(&oct, [0.6, 0.6, 0.2, 0.1], [1.5, 0.5, 0.5])),
    ];
    for (i, (a, b)) in cases.iter().enumerate() {
        assert!(exactly_convex(a) && exactly_convex(b), "case {i}: triangular faces in general position");
        check_convex(a, b, &format!("rotated case {i}"));
    }
    // A rotated cube's face quads are no longer exactly planar: whether it is exactly convex is
    // decided like the oracle decides it, and only then is the depth exact.
    let dir = tempfile::tempdir().unwrap();
    let cube = cuboid([-1.0; 3], [1.0; 3]);
    for (k, q) in [[0.9, 0.3, -0.2, 0.1], [0.6, 0.0, 0.8, 0.0], [1.0, 0.0, 0.0, 0.0]].into_iter().enumerate()
    {
        let a = rotated(&cube, q, [0.0; 3]);
        let b = rotated(&oct, [0.3, 0.2, 0.1, 0.0], [1.5, 0.2, 0.1]);
        let exact = exactly_convex(&a) && exactly_convex(&b);
        if exact {
            check_convex(&a, &b, &format!("rotated cube {k}"));
        } else {
            let ps = penetrations(dir.path(), &a, &b);
            assert!(ps.iter().all(|p| !p.is_exact()), "rotated cube {k}: not exactly convex, {ps:?}");
        }
    }
}

#[test]
fn a_non_convex_part_keeps_the_sampled_estimate() {
    // An L-shaped solid (a box with a notch: non-convex) against a box cutting its corner.
    let l = Solid {
        points: vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 1.0],
            [2.0, 0.0, 1.0],
            [2.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 2.0, 1.0],
            [0.0, 2.0, 1.0],
        ],
        tris: {
            // Bottom (z = 0, facing down) and top fans over the L outline, then the sides.
            let mut t = vec![[0, 3, 1], [1, 3, 2], [0, 5, 3], [3, 5, 4]];
            t.extend([[6, 7, 9], [7, 8, 9], [6, 9, 11], [9, 10, 11]]);
            for i in 0..6 {
                let j = (i + 1) % 6;
                t.extend([[i, j, 6 + j], [i, 6 + j, 6 + i]]);
            }
            t
        },
    };
    let b = cuboid([0.5, 0.5, 0.5], [1.5, 1.5, 1.5]);
    let dir = tempfile::tempdir().unwrap();
    for (x, y) in [(&l, &b), (&b, &l)] {
        let ps = penetrations(dir.path(), x, y);
        assert!(ps.iter().all(|p| p.method.is_none() && p.direction.is_none() && !p.is_exact()), "{ps:?}");
        let json = serde_json::to_string(&ps).unwrap();
        assert!(!json.contains("method") && !json.contains("direction"), "absent, not null: {json}");
    }
    // Convex parts in the same shapes' places do get the exact depth.
    check_convex(&cuboid([0.0; 3], [2.0, 2.0, 1.0]), &b, "convex stand-in");
}

#[test]
fn without_the_flag_there_is_no_penetration_block() {
    let dir = tempfile::tempdir().unwrap();
    let (pa, pb) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    std::fs::write(&pa, cuboid([0.0; 3], [1.0; 3]).obj("A", 0)).unwrap();
    std::fs::write(&pb, cuboid([0.5; 3], [1.5; 3]).obj("B", 0)).unwrap();
    let o = pipeline::run(&Request { deterministic: true, ..Request::files(&pa, &pb) }, &|_| {}).unwrap();
    assert!(o.convex_penetrations.is_empty());
    let r = pipeline::report::build(&o);
    assert!(r.regions.iter().all(|g| g.penetration.is_none()));
}
