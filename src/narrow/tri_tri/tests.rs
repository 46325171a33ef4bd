//! Hand-made exact cases. The exhaustive comparison with an exact rational oracle lives in
//! `tests/oracle.rs`.

use super::*;

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [DVec3; 3] {
    [DVec3::from(a), DVec3::from(b), DVec3::from(c)]
}

/// Classify both ways round and in every vertex rotation/reflection: the answer must not move.
fn check(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<(bool, Contact)> {
    let base = classify(a, b).map(|h| (h.crossing, h.contact));
    let perms = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [0, 2, 1], [2, 1, 0], [1, 0, 2]];
    for pa in perms {
        for pb in perms {
            let a2 = pa.map(|i| a[i]);
            let b2 = pb.map(|i| b[i]);
            let x = classify(&a2, &b2).map(|h| (h.crossing, h.contact));
            let y = classify(&b2, &a2).map(|h| (h.crossing, h.contact));
            assert_eq!(x, base, "permutation {pa:?} {pb:?}");
            assert_eq!(y, base, "swapped, permutation {pa:?} {pb:?}");
        }
    }
    base
}

const UNIT: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn unit() -> [DVec3; 3] {
    tri(UNIT[0], UNIT[1], UNIT[2])
}

#[test]
fn crossing_through_the_middle() {
    let b = tri([0.2, 0.2, -1.0], [0.3, 0.2, 1.0], [0.2, 0.6, 1.0]);
    assert_eq!(check(&unit(), &b), Some((true, Contact::Segment)));
    let h = classify(&unit(), &b).unwrap();
    let s = h.segment.unwrap();
    for p in s {
        assert!(p.z.abs() < 1e-12, "segment lies in z = 0: {p}");
    }
}

#[test]
fn separated_above() {
    let b = tri([0.2, 0.2, 1.0], [0.3, 0.2, 1.0], [0.2, 0.6, 2.0]);
    assert_eq!(check(&unit(), &b), None);
}

#[test]
fn vertex_on_face_interior_is_a_point_touch() {
    let b = tri([0.2, 0.2, 0.0], [0.3, 0.2, 1.0], [0.2, 0.6, 1.0]);
    assert_eq!(check(&unit(), &b), Some((false, Contact::Point)));
}

#[test]
fn edge_lying_on_face_is_a_segment_touch() {
    let b = tri([0.1, 0.1, 0.0], [0.4, 0.1, 0.0], [0.2, 0.3, 1.0]);
    assert_eq!(check(&unit(), &b), Some((false, Contact::Segment)));
}

#[test]
fn edge_through_face_crossing_plane_only_on_boundary() {
    // b's edge pierces a's interior while b's interior stays on one side? No: b is split by a's
    // plane, a is split by b's plane, the shared segment runs from a's interior to b's edge.
    let b = tri([0.25, 0.25, -1.0], [0.25, 0.25, 1.0], [3.0, 3.0, 0.0]);
    assert_eq!(check(&unit(), &b), Some((true, Contact::Segment)));
}

#[test]
fn edge_to_edge_crossing_is_a_point_touch() {
    let a = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, -1.0, 0.0]);
    let b = tri([1.0, -1.0, 1.0], [1.0, 1.0, -1.0], [1.0, 2.0, 2.0]);
    // a's edge (0,0,0)-(2,0,0) meets b's edge at (1,0,0); a lies below y = 0, b is in x = 1.
    let r = check(&a, &b);
    assert_eq!(r, Some((false, Contact::Point)));
}

#[test]
fn shared_edge_non_coplanar_is_a_segment_touch() {
    let b = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, -0.5, 1.0]);
    assert_eq!(check(&unit(), &b), Some((false, Contact::Segment)));
}

#[test]
fn shared_vertex_only_is_a_point_touch() {
    let b = tri([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], [2.0, -1.0, 1.0]);
    assert_eq!(check(&unit(), &b), Some((false, Contact::Point)));
}

#[test]
fn coplanar_cases() {
    let dup = unit();
    assert_eq!(check(&unit(), &dup), Some((false, Contact::CoplanarArea)));
    let overlap = tri([0.2, 0.2, 0.0], [2.0, 0.2, 0.0], [0.2, 2.0, 0.0]);
    assert_eq!(check(&unit(), &overlap), Some((false, Contact::CoplanarArea)));
    let adjacent = tri([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]);
    assert_eq!(check(&unit(), &adjacent), Some((false, Contact::CoplanarBoundary)));
    let corner = tri([1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]);
    assert_eq!(check(&unit(), &corner), Some((false, Contact::CoplanarBoundary)));
    let apart = tri([1.0, 0.5, 0.0], [2.0, 0.5, 0.0], [2.0, 1.0, 0.0]);
    assert_eq!(check(&unit(), &apart), None);
    // T-junction: a vertex of b on the open edge of a, b outside.
    let t = tri([0.5, 0.0, 0.0], [1.0, -1.0, 0.0], [0.0, -1.0, 0.0]);
    assert_eq!(check(&unit(), &t), Some((false, Contact::CoplanarBoundary)));
}

#[test]
fn one_ulp_gap_and_one_ulp_penetration() {
    let up = f64::from_bits(1.0f64.to_bits() + 1) - 1.0; // 2^-52
    let above = tri([0.2, 0.2, up], [0.3, 0.2, 1.0], [0.2, 0.6, 1.0]);
    assert_eq!(check(&unit(), &above), None);
    let below = tri([0.2, 0.2, -up], [0.3, 0.2, 1.0], [0.2, 0.6, 1.0]);
    assert_eq!(check(&unit(), &below), Some((true, Contact::Segment)));
    // Far from the origin: the same constructions translated by 1e8 stay exact.
    let off = v(1.0e8, -1.0e8, 1.0e8);
    let a = unit().map(|p| p + off);
    let eps = f64::from_bits(1.0e8f64.to_bits() + 1) - 1.0e8; // one ulp at 1e8
    let b = tri([0.25, 0.25, 0.0], [0.5, 0.25, 1.0], [0.25, 0.5, 1.0]).map(|p| p + off);
    assert_eq!(check(&a, &b), Some((false, Contact::Point)));
    let b_up = [b[0] + v(0.0, 0.0, eps), b[1], b[2]];
    assert_eq!(check(&a, &b_up), None);
    let b_dn = [b[0] - v(0.0, 0.0, eps), b[1], b[2]];
    assert_eq!(check(&a, &b_dn), Some((true, Contact::Segment)));
}

#[test]
fn degenerate_triangles() {
    let p = v(0.25, 0.25, 0.0);
    assert_eq!(Shape::of(&[p, p, p]), Shape::Pt(p));
    let needle = [v(0.25, 0.25, -1.0), v(0.25, 0.25, 1.0), v(0.25, 0.25, 0.5)];
    assert!(matches!(Shape::of(&needle), Shape::Seg(..)));
    // A needle through the interior crosses; through an edge it touches.
    assert_eq!(check(&unit(), &needle), Some((true, Contact::Point)));
    let on_edge = [v(0.5, 0.0, -1.0), v(0.5, 0.0, 1.0), v(0.5, 0.0, 1.0)];
    assert_eq!(check(&unit(), &on_edge), Some((false, Contact::Point)));
    // A point-triangle on the face, on a vertex, off the face.
    assert_eq!(check(&unit(), &[p, p, p]), Some((false, Contact::Point)));
    let o = v(0.0, 0.0, 0.0);
    assert_eq!(check(&unit(), &[o, o, o]), Some((false, Contact::Point)));
    let q = v(0.25, 0.25, 1e-300);
    assert_eq!(check(&unit(), &[q, q, q]), None);
    // A coplanar segment through the interior, along an edge, touching a vertex, outside.
    let inside = [v(-1.0, 0.5, 0.0), v(2.0, 0.2, 0.0), v(2.0, 0.2, 0.0)];
    assert_eq!(check(&unit(), &inside), Some((false, Contact::Segment)));
    let along = [v(0.5, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 0.0)];
    assert_eq!(check(&unit(), &along), Some((false, Contact::Segment)));
    let vertex = [v(1.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 0.0)];
    assert_eq!(check(&unit(), &vertex), Some((false, Contact::Point)));
    let grazing = [v(1.0, -1.0, 0.0), v(1.0, 1.0, 0.0), v(1.0, 1.0, 0.0)];
    assert_eq!(check(&unit(), &grazing), Some((false, Contact::Point)));
    let outside = [v(2.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 0.0)];
    assert_eq!(check(&unit(), &outside), None);
    // Segment against segment: crossing in a point, collinear overlap, skew.
    let s1 = [v(0.0, 0.0, 0.0), v(2.0, 2.0, 0.0), v(1.0, 1.0, 0.0)];
    let s2 = [v(0.0, 2.0, 0.0), v(2.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
    assert_eq!(check(&s1, &s2), Some((false, Contact::Point)));
    let s3 = [v(1.0, 1.0, 0.0), v(3.0, 3.0, 0.0), v(3.0, 3.0, 0.0)];
    assert_eq!(check(&s1, &s3), Some((false, Contact::Segment)));
    let s4 = [v(0.0, 2.0, 1.0), v(2.0, 0.0, 1.0), v(2.0, 0.0, 1.0)];
    assert_eq!(check(&s1, &s4), None);
}

#[test]
fn float_kernel_agrees_on_generic_input_and_errs_near_degeneracy() {
    let b = tri([0.2, 0.2, -1.0], [0.3, 0.2, 1.0], [0.2, 0.6, 1.0]);
    let exact = classify(&unit(), &b).map(|h| (h.crossing, h.contact));
    let float = classify_with::<Float>(&unit(), &b).map(|h| (h.crossing, h.contact));
    assert_eq!(exact, float);
    // A vertex one ulp below a plane far from the origin: the float determinant loses it.
    let off = v(1.0e8, 1.0e8, 1.0e8);
    let a = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.3), v(0.0, 1.0, 0.7)].map(|p| p + off);
    let on = a[0] * 0.25 + a[1] * 0.25 + a[2] * 0.5; // rounded: just off the plane
    let b = [on, on + v(0.0, 0.0, 1.0), on + v(0.5, 0.0, 1.0)];
    let e = classify(&a, &b).map(|h| (h.crossing, h.contact));
    let f = classify_with::<Float>(&a, &b).map(|h| (h.crossing, h.contact));
    // Exact says what the coordinates really do; the float kernel may or may not agree, but
    // it must never panic, and the exact answer is invariant under swapping.
    assert_eq!(e, classify(&b, &a).map(|h| (h.crossing, h.contact)));
    let _ = f;
}

// ---------------------------------------------------------------------------------------------
// The float filters may only skip work whose answer they have proven: the filtered classifier
// must agree bit for bit (kind, contact, segment points) with the unfiltered one (every sign
// from the adaptive predicates) on random and on adversarial near-degenerate input.
// ---------------------------------------------------------------------------------------------

mod filtered_vs_unfiltered {
    use super::*;
    use crate::geom::predicates as pr;
    use proptest::prelude::*;

    /// A hit as (crossing, contact, segment end points' coordinate bits).
    type HitBits = (bool, Contact, Option<[[u64; 3]; 2]>);

    /// A hit as bits, so that equal means bit-identical (and -0.0 differs from 0.0).
    fn bits(h: Option<Hit>) -> Option<HitBits> {
        h.map(|h| {
            let seg = h.segment.map(|s| s.map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]));
            (h.crossing, h.contact, seg)
        })
    }

    /// Both classifiers, both orders; also every orient3d of the pair's vertex sets against the
    /// adaptive predicate (which covers the exact stages: repeated points, integers, adaptive).
    fn agree(a: &[DVec3; 3], b: &[DVec3; 3]) -> Result<(), TestCaseError> {
        for (x, y) in [(a, b), (b, a)] {
            let f = bits(classify(x, y));
            let u = bits(classify_unfiltered(x, y));
            prop_assert_eq!(f, u, "a = {:?}, b = {:?}", x, y);
            let shapes = bits(classify_shapes(&Shape::of(x), &Shape::of(y)));
            prop_assert_eq!(shapes, u);
            // Prepared triangles: the same hit; without the segment, the same but for the segment
            // of two proper triangles (absent then, as documented).
            let (px, py) = (Prepared::new(*x), Prepared::new(*y));
            prop_assert_eq!(bits(classify_prepared(&px, &py, true)), u);
            let bare = classify_prepared(&px, &py, false);
            let full = classify(x, y);
            prop_assert_eq!(bare.map(|h| (h.crossing, h.contact)), full.map(|h| (h.crossing, h.contact)));
            let proper = !Shape::of(x).is_degenerate() && !Shape::of(y).is_degenerate();
            if !proper {
                prop_assert_eq!(bits(bare), bits(full));
            }
            for p in y {
                let (s, r) =
                    (pr::orient3d(x[0], x[1], x[2], *p), pr::orient3d_adaptive(x[0], x[1], x[2], *p));
                prop_assert_eq!(s, r, "orient3d {:?} {:?}", x, p);
                if let Some(d) = pr::orient3d_dyadic(x[0], x[1], x[2], *p) {
                    prop_assert_eq!(d, r, "dyadic {:?} {:?}", x, p);
                }
            }
        }
        Ok(())
    }

    fn coord() -> impl Strategy<Value = f64> {
        -1.0f64..1.0
    }

    fn point() -> impl Strategy<Value = DVec3> {
        (coord(), coord(), coord()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    fn triangle() -> impl Strategy<Value = [DVec3; 3]> {
        [point(), point(), point()]
    }

    /// Move `x` by `k` ulps (k in -2..=2).
    fn ulps(x: f64, k: i64) -> f64 {
        if x == 0.0 {
            return k as f64 * f64::from_bits(1);
        }
        let b = x.to_bits() as i64;
        let moved = if x > 0.0 { b + k } else { b - k };
        f64::from_bits(moved as u64)
    }

    /// `b` derived from `a` in a way that makes the pair nearly or exactly degenerate.
    fn adversarial(
        a: [DVec3; 3],
        b: [DVec3; 3],
        how: u8,
        w: [f64; 3],
        k: [i64; 3],
    ) -> ([DVec3; 3], [DVec3; 3]) {
        let in_plane = |s: f64, t: f64| a[0] + (a[1] - a[0]) * s + (a[2] - a[0]) * t; // rounded: near the plane
        match how % 8 {
            // Vertices on a's plane (rounded), one pushed by a few ulps.
            0 => {
                let mut c = [in_plane(w[0], w[1]), in_plane(w[1], w[2]), in_plane(w[2], w[0])];
                c[0].z = ulps(c[0].z, k[0]);
                (a, c)
            }
            // One shared vertex, one vertex on the plane.
            1 => (a, [a[0], in_plane(w[0], w[1]), b[2]]),
            // A shared edge, the third vertex anywhere or near the plane.
            2 => (a, [a[1], a[0], if k[1] > 0 { b[2] } else { in_plane(w[1], -w[2]) }]),
            // The same triangle, with coordinates moved by ulps.
            3 => (a, a.map(|p| DVec3::new(ulps(p.x, k[0]), ulps(p.y, k[1]), ulps(p.z, k[2])))),
            // Far from the origin (1e8): both moved, b through a point of a's plane.
            4 => {
                let off = DVec3::new(1.0e8, -1.0e8, 1.0e8);
                let c = [in_plane(w[0], w[1]), b[1], b[2]];
                (a.map(|p| p + off), c.map(|p| p + off))
            }
            // Exactly coplanar dyadic grid points on x + y + z = 3e8 (multiples of 2^-26).
            5 => {
                let q = 2f64.powi(-26);
                let base = 100_000_000i64 << 26;
                let grid = |s: f64, t: f64| {
                    let x = base + (s * 4.0 / q).round() as i64;
                    let y = base + (t * 4.0 / q).round() as i64;
                    DVec3::new(x as f64 * q, y as f64 * q, (3 * base - x - y) as f64 * q)
                    // exact
                };
                let ga = [grid(a[0].x, a[0].y), grid(a[1].x, a[1].y), grid(a[2].x, a[2].y)];
                let gb = [
                    grid(b[0].x, b[0].y),
                    if k[0] > 0 { ga[1] } else { grid(b[1].x, b[1].y) },
                    grid(w[0], w[1]),
                ];
                (ga, gb)
            }
            // Axis-aligned coplanar (z = 0.5), possibly sharing a vertex.
            6 => {
                let flat = |p: DVec3| DVec3::new(p.x, p.y, 0.5);
                let fa = a.map(flat);
                (fa, [if k[2] > 0 { fa[2] } else { flat(b[0]) }, flat(b[1]), flat(b[2])])
            }
            // Tiny (2^-260, below the exact range) or huge (2^240) scale.
            _ => {
                let s = if k[0] > 0 { 2f64.powi(-260) } else { 2f64.powi(240) };
                let c = [in_plane(w[0], w[1]), b[1], b[2]];
                (a.map(|p| p * s), c.map(|p| p * s))
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        #[test]
        fn random_pairs(a in triangle(), b in triangle()) {
            agree(&a, &b)?;
        }

        #[test]
        fn near_degenerate_pairs(
            a in triangle(),
            b in triangle(),
            how in 0u8..8,
            w in [-0.5f64..1.5, -0.5f64..1.5, -0.5f64..1.5],
            k in [-2i64..=2, -2i64..=2, -2i64..=2],
        ) {
            let (a, b) = adversarial(a, b, how, w, k);
            agree(&a, &b)?;
        }
    }

    #[test]
    fn hand_made_degenerate_pairs_agree() {
        let u = unit();
        let p = v(0.25, 0.25, 0.0);
        let cases = [
            (u, u),
            (u, [p, p, p]),
            (u, [v(0.25, 0.25, -1.0), v(0.25, 0.25, 1.0), v(0.25, 0.25, 0.5)]),
            (u, [v(-1.0, 0.5, 0.0), v(2.0, 0.2, 0.0), v(2.0, 0.2, 0.0)]),
            (u, tri([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0])),
            (u, tri([0.2, 0.2, 0.0], [0.3, 0.2, 1.0], [0.2, 0.6, 1.0])),
            (u, tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, -0.5, 1.0])),
        ];
        for (a, b) in cases {
            agree(&a, &b).unwrap();
        }
    }
}

/// A driver for instruction counts (`valgrind --tool=callgrind`), not a check: replays the
/// candidate pairs (triangle boxes overlap) of a real mesh pair through one classifier.
/// `MESHCLASH_REPLAY` = `tori` (crossing tori, 100k triangles each), `grid` (coplanar grids at
/// 1e8, 20k) or `bunny` (vs its rotated copy; needs ../shared/meshes);
/// `MESHCLASH_CLASSIFIER` = `filtered`, `unfiltered` or `none` (everything but the classifier,
/// to subtract). Prints the candidate count and hits to stderr.
#[test]
#[ignore]
fn replay_candidates_for_profiling() {
    use crate::bvh::{self, BuildOptions, Bvh};
    use crate::geom::Aabb;
    use crate::testing::gen;
    let which = std::env::var("MESHCLASH_REPLAY").unwrap_or_else(|_| "tori".into());
    let (a, b) = match which.as_str() {
        "grid" => gen::coplanar_grids(20_000),
        "bunny" => {
            let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../shared/meshes/stanford-bunny.obj");
            let spec = crate::check::query::InputSpec { path, transform: glam::DMat4::IDENTITY };
            let m = crate::check::query::load_input(&spec).unwrap().mesh;
            (gen::rotated_copy(&m), m)
        }
        _ => gen::crossing_tori(100_000),
    };
    let opts = BuildOptions::default();
    let (ta, tb) = (Bvh::build(&a, opts), Bvh::build(&b, opts));
    let cands: Vec<(u32, u32)> = crate::bvh::traverse::collect_pairs(
        &ta,
        &tb,
        |x, y| x.overlaps(y),
        |la, lb, out| {
            for &i in la {
                let bi = Aabb::of_triangle(&bvh::triangle(&a, i));
                for &j in lb {
                    if bi.overlaps(&Aabb::of_triangle(&bvh::triangle(&b, j))) {
                        out.push((i, j));
                    }
                }
            }
        },
    );
    let f: fn(&[DVec3; 3], &[DVec3; 3]) -> Option<Hit> =
        match std::env::var("MESHCLASH_CLASSIFIER").as_deref().unwrap_or("filtered") {
            "unfiltered" => classify_unfiltered,
            "none" => |_, _| None,
            _ => classify,
        };
    let hits = cands
        .iter()
        .filter(|&&(i, j)| std::hint::black_box(f)(&bvh::triangle(&a, i), &bvh::triangle(&b, j)).is_some())
        .count();
    eprintln!("{which}: {} candidates, {hits} meet", cands.len());
}
