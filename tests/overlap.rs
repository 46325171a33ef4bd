//! The exact overlap box of two clashing closed parts (`part_pairs[].overlap`,
//! `regions[].overlap`) against an independent exact oracle: for convex solids, A ∩ B is the
//! set of points inside every face plane of both, and its extremes are among the points where
//! three of those planes meet (solved in big rationals). Each reported bound must be a nearest
//! f64 to the oracle's exact extreme, the same for both part orders and both triangle windings,
//! in two-file and in scene mode, and the same at every tessellation of the same solids (12 to
//! about 1000 triangles per part).

use crate::solids::{both_modes, run, Solid, V};
use meshclash::pipeline::Request;
use meshclash::report::OverlapReport;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use std::path::Path;

/// An axis-aligned box, each face cut into `n × n` squares (12 n² triangles): the same solid
/// for every `n` (inner grid points are rounded within the face's plane).
fn grid_box(min: V, max: V, n: usize) -> Solid {
    let mut points = Vec::new();
    let mut tris = Vec::new();
    for axis in 0..3 {
        for side in 0..2 {
            let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
            let lerp = |k: usize, w: usize| {
                if w == n {
                    max[k]
                } else {
                    min[k] + (max[k] - min[k]) * w as f64 / n as f64
                }
            };
            let start = points.len();
            for u in 0..=n {
                for v in 0..=n {
                    let mut p = [0.0; 3];
                    p[axis] = if side == 0 { min[axis] } else { max[axis] };
                    p[i] = lerp(i, u);
                    p[j] = lerp(j, v);
                    points.push(p);
                }
            }
            let id = |u: usize, v: usize| start + u * (n + 1) + v;
            for u in 0..n {
                for v in 0..n {
                    let (a, b, c, d) = (id(u, v), id(u + 1, v), id(u + 1, v + 1), id(u, v + 1));
                    if side == 1 {
                        tris.extend([[a, b, c], [a, c, d]]);
                    } else {
                        tris.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
    }
    Solid { points, tris }
}

/// A `k`-sided prism approximating a cylinder of radius `r` around the z axis through `c`
/// (corners on an integer grid, so the solid is exactly convex and the same for every `bands`),
/// from `z0` to `z1`, its sides cut into `bands` bands and its caps fanned from the centre.
fn prism(c: [f64; 2], r: f64, k: usize, z0: f64, z1: f64, bands: usize) -> Solid {
    let ring: Vec<[f64; 2]> = (0..k)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / k as f64;
            [c[0] + (r * a.cos()).round(), c[1] + (r * a.sin()).round()]
        })
        .collect();
    let z = |b: usize| if b == bands { z1 } else { z0 + (z1 - z0) * b as f64 / bands as f64 };
    let mut points = Vec::new();
    for b in 0..=bands {
        points.extend(ring.iter().map(|p| [p[0], p[1], z(b)]));
    }
    let (bottom, top) = (points.len(), points.len() + 1);
    points.push([c[0], c[1], z0]);
    points.push([c[0], c[1], z1]);
    let id = |b: usize, i: usize| b * k + i % k;
    let mut tris = Vec::new();
    for b in 0..bands {
        for i in 0..k {
            tris.push([id(b, i), id(b, i + 1), id(b + 1, i + 1)]);
            tris.push([id(b, i), id(b + 1, i + 1), id(b + 1, i)]);
        }
    }
    for i in 0..k {
        tris.push([bottom, id(0, i + 1), id(0, i)]);
        tris.push([top, id(bands, i), id(bands, i + 1)]);
    }
    Solid { points, tris }
}

// ---------------------------------------------------------------------------------------------
// The oracle: vertices of the intersection of two convex solids, in big rationals.

type Q = BigRational;

fn q(x: f64) -> Q {
    Q::from_float(x).unwrap()
}

/// Each face's plane as (n, d) with n · x <= d inside (outward winding).
fn planes(s: &Solid) -> Vec<([Q; 3], Q)> {
    s.tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| s.points[i].map(q));
            let u = [&b[0] - &a[0], &b[1] - &a[1], &b[2] - &a[2]];
            let v = [&c[0] - &a[0], &c[1] - &a[1], &c[2] - &a[2]];
            let n =
                [&u[1] * &v[2] - &u[2] * &v[1], &u[2] * &v[0] - &u[0] * &v[2], &u[0] * &v[1] - &u[1] * &v[0]];
            let d = &n[0] * &a[0] + &n[1] * &a[1] + &n[2] * &a[2];
            (n, d)
        })
        .collect()
}

fn det3(m: &[[Q; 3]; 3]) -> Q {
    &m[0][0] * (&m[1][1] * &m[2][2] - &m[1][2] * &m[2][1])
        - &m[0][1] * (&m[1][0] * &m[2][2] - &m[1][2] * &m[2][0])
        + &m[0][2] * (&m[1][0] * &m[2][1] - &m[1][1] * &m[2][0])
}

/// The exact box of A ∩ B for convex A and B: None when they do not meet.
fn oracle(a: &Solid, b: &Solid) -> Option<[[Q; 3]; 2]> {
    let mut ps = planes(a);
    ps.extend(planes(b));
    // Distinct planes only (a tessellated face repeats its plane), normalized by a positive
    // scale so duplicates compare equal.
    let mut distinct: Vec<([Q; 3], Q)> = Vec::new();
    for (n, d) in ps {
        let s = n.iter().find(|x| !x.is_zero()).unwrap().abs();
        let (n, d) = (n.map(|x| x / &s), d / &s);
        if !distinct.contains(&(n.clone(), d.clone())) {
            distinct.push((n, d));
        }
    }
    let mut lo: Option<[Q; 3]> = None;
    let mut hi: Option<[Q; 3]> = None;
    let m = distinct.len();
    for i in 0..m {
        for j in i + 1..m {
            for k in j + 1..m {
                let rows = [&distinct[i], &distinct[j], &distinct[k]];
                let mat = rows.map(|r| r.0.clone());
                let det = det3(&mat);
                if det.is_zero() {
                    continue;
                }
                let x: Vec<Q> = (0..3)
                    .map(|c| {
                        let mut mc = mat.clone();
                        for (r, row) in rows.iter().enumerate() {
                            mc[r][c] = row.1.clone();
                        }
                        det3(&mc) / &det
                    })
                    .collect();
                let inside =
                    distinct.iter().all(|(n, d)| &n[0] * &x[0] + &n[1] * &x[1] + &n[2] * &x[2] <= *d);
                if !inside {
                    continue;
                }
                let l = lo.get_or_insert_with(|| [x[0].clone(), x[1].clone(), x[2].clone()]);
                let h = hi.get_or_insert_with(|| [x[0].clone(), x[1].clone(), x[2].clone()]);
                for c in 0..3 {
                    if x[c] < l[c] {
                        l[c] = x[c].clone();
                    }
                    if x[c] > h[c] {
                        h[c] = x[c].clone();
                    }
                }
            }
        }
    }
    Some([lo?, hi?])
}

/// True if `x` is a nearest f64 to the exact value `r`.
fn nearest(x: f64, r: &Q) -> bool {
    let err = (q(x) - r).abs();
    [x.next_up(), x.next_down()].iter().all(|&y| (q(y) - r).abs() >= err)
}

#[allow(clippy::needless_range_loop)] // three axes of three arrays at once
fn assert_matches(o: &OverlapReport, want: &[[Q; 3]; 2], what: &str) {
    for c in 0..3 {
        assert!(nearest(o.min[c], &want[0][c]), "{what}: min[{c}] {} vs exact {}", o.min[c], want[0][c]);
        assert!(nearest(o.max[c], &want[1][c]), "{what}: max[{c}] {} vs exact {}", o.max[c], want[1][c]);
        assert_eq!(o.extent[c], o.max[c] - o.min[c]);
    }
}

// ---------------------------------------------------------------------------------------------
// Running the check.

/// The overlap box of the one clashing part pair, two-file mode and scene mode (which must
/// agree), and of its only region.
fn overlap_of(dir: &Path, a: &Solid, b: &Solid) -> Option<OverlapReport> {
    let (files, scene) = both_modes(dir, a, b, |r: Request| r);
    let pick = |r: &meshclash::report::Report| {
        assert!(r.part_pairs.len() <= 1);
        let o = r.part_pairs.first().and_then(|p| p.overlap.clone());
        if r.regions.len() == 1 {
            assert_eq!(r.regions[0].overlap, o, "a single region carries its part pair's box");
        }
        o
    };
    let (f, s) = (pick(&files), pick(&scene));
    assert_eq!(f, s, "two-file and scene mode agree");
    f
}

fn check_case(a: &Solid, b: &Solid, what: &str) -> OverlapReport {
    let dir = tempfile::tempdir().unwrap();
    let want = oracle(a, b).expect("the solids meet");
    let o = overlap_of(dir.path(), a, b).unwrap_or_else(|| panic!("{what}: no overlap box"));
    assert_matches(&o, &want, what);
    // Both part orders and both windings give the same box.
    for (x, y, how) in [(b, a, "swapped"), (&a.flipped(), &b.flipped(), "flipped")] {
        assert_eq!(overlap_of(dir.path(), x, y).as_ref(), Some(&o), "{what}: {how}");
    }
    o
}

#[test]
fn boxes_overlap_by_their_common_box_at_every_tessellation() {
    let (a_min, a_max) = ([0.0, 0.0, 0.0], [2.0, 1.0, 1.0]);
    let (b_min, b_max) = ([0.5, 0.4, -1.0], [3.0, 1.0 / 3.0 + 0.5, 0.6]);
    let mut seen = None;
    for (n, m) in [(1, 1), (2, 5), (4, 1), (8, 3), (9, 9)] {
        let (a, b) = (grid_box(a_min, a_max, n), grid_box(b_min, b_max, m));
        let o = check_case(&a, &b, &format!("boxes {}×{} triangles", a.tris.len(), b.tris.len()));
        assert_eq!(o.min, [0.5, 0.4, 0.0]);
        assert_eq!(o.max, [2.0, 1.0 / 3.0 + 0.5, 0.6]);
        assert_eq!(*seen.get_or_insert_with(|| o.clone()), o, "same box at every tessellation");
    }
}

#[test]
fn prism_through_a_box_matches_the_exact_oracle_at_every_tessellation() {
    // A 12-sided prism (radius 40 around (0, 0)) against a box that cuts its slanted sides,
    // so the y and x extremes are crossing points at non-dyadic fractions.
    let slab = grid_box([13.0, -100.0, -2.0], [27.5, 100.0, 7.25], 2);
    let mut seen = None;
    for bands in [1, 4, 16, 40] {
        let p = prism([0.0, 0.0], 40.0, 12, 0.0, 10.0, bands);
        let o = check_case(&p, &slab, &format!("prism of {} triangles", p.tris.len()));
        assert_eq!(*seen.get_or_insert_with(|| o.clone()), o, "same box at every tessellation");
    }
    // A finer prism and a tilted cut: the oracle still agrees.
    let p = prism([1.0, -2.0], 1000.0, 48, -5.0, 5.0, 8);
    let cut = grid_box([-333.25, 700.5, 1.0], [100.0, 2000.0, 9.0], 3);
    assert!(p.tris.len() >= 768);
    check_case(&p, &cut, "fine prism");
}

#[test]
fn nested_touching_and_clear_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let outer = grid_box([0.0; 3], [4.0; 3], 3);
    // Nested: A ∩ B is the inner part (a clash by containment). Scene mode lists the part
    // pair and its box; two single-part files have no part pair (no triangles meet) and
    // report the containment in `summary.contained` with the box in `summary.overlap`.
    let inner = prism([2.0, 2.0], 1.0, 6, 1.0, 3.0, 2);
    let want = oracle(&outer, &inner).unwrap();
    for (x, y) in [(&outer, &inner), (&inner, &outer)] {
        let ps = dir.path().join("nested.obj");
        std::fs::write(&ps, x.obj("X", 0) + &y.obj("Y", x.points.len())).unwrap();
        let r = run(Request::scene(&ps));
        let o = r.part_pairs[0].overlap.clone().expect("nested parts clash");
        assert_matches(&o, &want, "nested");
        assert_eq!(r.summary.overlap, None, "scene mode: the part pair carries the box");
        let (pa, pb) = (dir.path().join("x.obj"), dir.path().join("y.obj"));
        std::fs::write(&pa, x.obj("X", 0)).unwrap();
        std::fs::write(&pb, y.obj("Y", 0)).unwrap();
        let f = run(Request::files(&pa, &pb));
        assert_eq!(f.verdict, meshclash::report::ReportVerdict::Clash);
        assert!(f.summary.contained.is_some() && f.part_pairs.is_empty());
        let fo = f.summary.overlap.clone().expect("two nested single-part files get the box");
        assert_matches(&fo, &want, "nested files");
        assert_eq!(fo, o, "two-file and scene mode agree");
    }
    // Two files of one part each that meet: the part pair carries the box, the summary none.
    let crossing = grid_box([3.0, 1.0, 1.0], [5.0, 2.0, 2.0], 1);
    let (pa, pb) = (dir.path().join("x.obj"), dir.path().join("y.obj"));
    std::fs::write(&pa, outer.obj("X", 0)).unwrap();
    std::fs::write(&pb, crossing.obj("Y", 0)).unwrap();
    let f = run(Request::files(&pa, &pb));
    assert!(f.part_pairs[0].overlap.is_some());
    assert_eq!(f.summary.overlap, None);
    let json = serde_json::to_string(&f.summary).unwrap();
    assert!(!json.contains("overlap"), "absent, not null: {json}");
    // Touching face to face is not a clash: no box. Apart: no pair at all.
    let side = grid_box([4.0, 1.0, 1.0], [5.0, 2.0, 2.0], 1);
    assert_eq!(overlap_of(dir.path(), &outer, &side), None);
    let apart = grid_box([6.0, 1.0, 1.0], [7.0, 2.0, 2.0], 1);
    assert_eq!(overlap_of(dir.path(), &outer, &apart), None);
}

#[test]
fn open_surfaces_get_no_box() {
    let dir = tempfile::tempdir().unwrap();
    let a = grid_box([0.0; 3], [2.0; 3], 2);
    let mut open = grid_box([1.0; 3], [3.0; 3], 2);
    open.tris.truncate(open.tris.len() - 2);
    assert_eq!(overlap_of(dir.path(), &a, &open), None);
    let r = run(Request::files(dir.path().join("a.obj"), dir.path().join("b.obj")));
    assert_eq!(r.verdict, meshclash::report::ReportVerdict::Clash);
    assert!(r.regions.iter().all(|g| g.overlap.is_none()));
    let json = serde_json::to_string(&r).unwrap();
    assert!(!json.contains("\"overlap\""), "absent, not null");
}
