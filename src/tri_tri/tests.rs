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
