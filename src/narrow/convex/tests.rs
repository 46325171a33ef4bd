//! The exact depth against a brute-force separating-axis test in rational arithmetic: every face
//! normal, every edge-pair cross product (both orientations), supports over all vertices.

use super::*;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use proptest::prelude::*;

#[derive(Debug, Clone)]
struct Shape {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    surface: Surface,
}

impl Shape {
    fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Shape {
        let surface = Surface::of(&triangles).expect("closed");
        Shape { positions, triangles, surface }
    }
    fn poly(&self) -> Polytope<'_> {
        Polytope {
            positions: &self.positions,
            triangles: &self.triangles,
            surface: &self.surface,
            frames: None,
        }
    }
    fn moved(&self, by: DVec3) -> Shape {
        Shape::new(self.positions.iter().map(|p| *p + by).collect(), self.triangles.clone())
    }
}

fn cuboid(lo: DVec3, hi: DVec3) -> Shape {
    use crate::testing::gen::{box_corners, BOX_TRIANGLES};
    Shape::new(box_corners(lo, hi).to_vec(), BOX_TRIANGLES.to_vec())
}

fn tetrahedron(p: [DVec3; 4]) -> Option<Shape> {
    let o = predicates::orient3d(p[0], p[1], p[2], p[3]);
    if o == 0 {
        return None;
    }
    let t = if o < 0 {
        vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [0, 2, 3]]
    } else {
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]
    };
    Some(Shape::new(p.to_vec(), t))
}

/// A triangle `base` extruded by `t` (a slanted prism; its side quads are exactly planar).
fn prism(base: [DVec3; 3], t: DVec3) -> Option<Shape> {
    let top = base.map(|p| p + t);
    // The translation must be exact, or the sides would not be planar.
    predicates::exact_translation(&base, &top)?;
    let mut b = base;
    match predicates::orient3d(b[0], b[1], b[2], top[0]) {
        0 => return None,
        s if s > 0 => b.swap(1, 2),
        _ => {}
    }
    let top = b.map(|p| p + t);
    let v = vec![b[0], b[1], b[2], top[0], top[1], top[2]];
    // Base (0,1,2) faces away from the top; the top reversed; sides outward.
    let mut tris = vec![[0, 1, 2], [3, 5, 4]];
    for i in 0..3u32 {
        let j = (i + 1) % 3;
        tris.push([i, i + 3, j]);
        tris.push([j, i + 3, j + 3]);
    }
    Some(Shape::new(v, tris))
}

type Q = BigRational;
type Qv = [Q; 3];

fn q(x: f64) -> Q {
    BigRational::from_float(x).unwrap()
}
fn qv(p: DVec3) -> Qv {
    [q(p.x), q(p.y), q(p.z)]
}
fn qsub(a: &Qv, b: &Qv) -> Qv {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}
fn qcross(a: &Qv, b: &Qv) -> Qv {
    [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
}
fn qdot(a: &Qv, b: &Qv) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

/// `h(n)` of `A - B` over all vertices.
fn support(a: &Shape, b: &Shape, n: &Qv) -> Q {
    let max_a = a.positions.iter().map(|p| qdot(&qv(*p), n)).max().unwrap();
    let min_b = b.positions.iter().map(|p| qdot(&qv(*p), n)).min().unwrap();
    max_a - min_b
}

/// `h² / |n|²` with the sign of `h`, as a rational: the exact comparison key of `h / |n|`.
fn key(h: &Q, n: &Qv) -> Q {
    let s =
        if h.is_negative() { -Q::from_integer(BigInt::from(1)) } else { Q::from_integer(BigInt::from(1)) };
    s * h * h / qdot(n, n)
}

/// Every candidate axis (face normals out of A, into B, all edge-pair cross products both ways).
fn all_axes(a: &Shape, b: &Shape) -> Vec<Qv> {
    let mut axes = Vec::new();
    for (s, sign) in [(a, 1), (b, -1)] {
        for t in &s.triangles {
            let p = t.map(|v| qv(s.positions[v as usize]));
            let n = qcross(&qsub(&p[1], &p[0]), &qsub(&p[2], &p[0]));
            axes.push(if sign > 0 { n } else { n.map(|x| -x) });
        }
    }
    for ea in &a.surface.edges {
        for eb in &b.surface.edges {
            let da = qsub(&qv(a.positions[ea.v[1] as usize]), &qv(a.positions[ea.v[0] as usize]));
            let db = qsub(&qv(b.positions[eb.v[1] as usize]), &qv(b.positions[eb.v[0] as usize]));
            let n = qcross(&da, &db);
            axes.push(n.clone());
            axes.push(n.map(|x| -x));
        }
    }
    axes.retain(|n| !qdot(n, n).is_zero());
    axes
}

/// The exact depth key by brute force: `None` when separated.
fn brute(a: &Shape, b: &Shape) -> Option<Q> {
    let m = all_axes(a, b).iter().map(|n| key(&support(a, b, n), n)).min().unwrap();
    (!m.is_negative()).then_some(m)
}

/// The exact key of the axis `penetration` chose, by the brute-force support.
fn chosen_key(a: &Shape, b: &Shape, p: &Penetration) -> Q {
    let n = match p.axis {
        Axis::FaceA(f) => {
            let t = a.triangles[f as usize].map(|v| qv(a.positions[v as usize]));
            qcross(&qsub(&t[1], &t[0]), &qsub(&t[2], &t[0]))
        }
        Axis::FaceB(f) => {
            let t = b.triangles[f as usize].map(|v| qv(b.positions[v as usize]));
            qcross(&qsub(&t[1], &t[0]), &qsub(&t[2], &t[0])).map(|x| -x)
        }
        Axis::Edges(i, j) => {
            let (ea, eb) = (a.surface.edges[i as usize], b.surface.edges[j as usize]);
            let da = qsub(&qv(a.positions[ea.v[1] as usize]), &qv(a.positions[ea.v[0] as usize]));
            let db = qsub(&qv(b.positions[eb.v[1] as usize]), &qv(b.positions[eb.v[0] as usize]));
            let n = qcross(&da, &db);
            if qdot(&n, &qv(p.normal)).is_negative() {
                n.map(|x| -x)
            } else {
                n
            }
        }
    };
    key(&support(a, b, &n), &n)
}

fn check(a: &Shape, b: &Shape) {
    assert!(is_convex(&a.positions, &a.triangles, &a.surface));
    assert!(is_convex(&b.positions, &b.triangles, &b.surface));
    let got = penetration(&a.poly(), &b.poly());
    let want = brute(a, b);
    match (&got, &want) {
        (None, None) => {}
        (Some(p), Some(w)) => {
            assert_eq!(&chosen_key(a, b, p), w, "{p:?}");
            let d = w.to_f64().unwrap().sqrt();
            assert!((p.depth - d).abs() <= 1e-9 * (1.0 + d), "{} vs {d}", p.depth);
            assert!((p.normal.length() - 1.0).abs() < 1e-12);
            // Along the reported unit normal the overlap is the depth (up to its rounding).
            let along = support(a, b, &qv(p.normal)).to_f64().unwrap() / p.normal.length();
            assert!((along - p.depth).abs() <= 1e-9 * (1.0 + p.depth), "{along} vs {p:?}");
        }
        _ => panic!("penetration {got:?}, brute force {want:?}"),
    }
}

use num_traits::ToPrimitive;

#[test]
fn boxes_with_known_depths() {
    let unit = cuboid(DVec3::splat(-0.5), DVec3::splat(0.5));
    // Coincident unit cubes: depth 1 along the first face of A, exactly.
    let p = penetration(&unit.poly(), &unit.poly()).unwrap();
    assert_eq!(p.depth, 1.0);
    assert_eq!(p.axis, Axis::FaceA(0));
    assert_eq!(p.normal, DVec3::new(-1.0, 0.0, 0.0));
    // Overlapping by 0.25 along x.
    let b = unit.moved(DVec3::new(0.75, 0.0, 0.0));
    let p = penetration(&unit.poly(), &b.poly()).unwrap();
    assert_eq!(p.depth, 0.25);
    assert_eq!(p.normal, DVec3::new(1.0, 0.0, 0.0));
    // Touching face to face: depth 0; a hair apart: separated.
    let b = unit.moved(DVec3::new(1.0, 0.3, 0.0));
    assert_eq!(penetration(&unit.poly(), &b.poly()).unwrap().depth, 0.0);
    let b = unit.moved(DVec3::new(1.0 + f64::EPSILON, 0.0, 0.0));
    assert!(penetration(&unit.poly(), &b.poly()).is_none());
    // A small box deep inside a big one: the shortest way out.
    let big = cuboid(DVec3::ZERO, DVec3::new(10.0, 6.0, 8.0));
    let small = cuboid(DVec3::new(4.0, 2.0, 3.0), DVec3::new(5.0, 3.0, 4.0));
    let p = penetration(&big.poly(), &small.poly()).unwrap();
    assert_eq!(p.depth, 3.0); // down through y = 0: the small box's top is at 3
    assert_eq!(p.normal, DVec3::new(0.0, -1.0, 0.0));
    let arrays = |s: &Shape| (s.positions.clone(), s.triangles.clone());
    let ((pb, tb), (ps, ts)) = (arrays(&big), arrays(&small));
    assert_eq!(exact_convex_penetration((&pb, &tb), (&ps, &ts)).unwrap().unwrap().depth, 3.0);
    let far = small.moved(DVec3::new(20.0, 0.0, 0.0));
    assert_eq!(exact_convex_penetration((&pb, &tb), (&far.positions, &far.triangles)), Some(None));
    assert_eq!(exact_convex_penetration((&pb, &tb[1..]), (&ps, &ts)), None);
    for (x, y) in [(&unit, &unit), (&big, &small), (&small, &big)] {
        check(x, y);
    }
}

#[test]
fn edge_against_edge() {
    // Two wedges (tetrahedra with opposite edges crosswise): A's top edge along x at z = 1
    // digs 0.25 into B's bottom edge along y at z = 0.75. The answer is that edge pair's axis
    // (z), not a face normal (the faces are inclined, their overlaps larger).
    let a = tetrahedron([
        DVec3::new(-2.0, 0.0, 1.0),
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(0.0, -2.0, -1.0),
        DVec3::new(0.0, 2.0, -1.0),
    ])
    .unwrap();
    let b = tetrahedron([
        DVec3::new(0.0, -2.0, 0.75),
        DVec3::new(0.0, 2.0, 0.75),
        DVec3::new(-2.0, 0.0, 2.75),
        DVec3::new(2.0, 0.0, 2.75),
    ])
    .unwrap();
    let p = penetration(&a.poly(), &b.poly()).unwrap();
    assert!(matches!(p.axis, Axis::Edges(..)), "{p:?}");
    assert_eq!((p.depth, p.normal), (0.25, DVec3::Z));
    assert_eq!(p.point, DVec3::new(0.0, 0.0, 0.875));
    check(&a, &b);
    check(&b, &a);
}

#[test]
fn convexity_is_exact() {
    let unit = cuboid(DVec3::ZERO, DVec3::ONE);
    assert!(is_convex(&unit.positions, &unit.triangles, &unit.surface));
    // Inside out: not convex (every vertex above the faces).
    let flipped: Vec<[u32; 3]> = unit.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let s = Surface::of(&flipped).unwrap();
    assert!(!is_convex(&unit.positions, &flipped, &s));
    // One corner pulled out by one ulp along x: the face x = 1 folds along its diagonal (a
    // valley between its two triangles), not convex.
    let mut dented = unit.positions.clone();
    dented[7] = DVec3::new(1.0 + f64::EPSILON, 1.0, 1.0);
    assert!(!is_convex(&dented, &unit.triangles, &unit.surface));
    // Open (a face missing): no surface.
    assert!(Surface::of(&unit.triangles[1..]).is_none());
    // Two separate cubes in one mesh: closed, each convex, together not.
    let far = unit.moved(DVec3::new(3.0, 0.0, 0.0));
    let mut pos = unit.positions.clone();
    pos.extend(&far.positions);
    let mut tris = unit.triangles.clone();
    tris.extend(far.triangles.iter().map(|t| t.map(|v| v + 8)));
    let s = Surface::of(&tris).unwrap();
    assert!(!is_convex(&pos, &tris, &s));
    // Flat (all vertices coplanar, closed both ways): no volume.
    let flat_t = vec![[0, 1, 2], [0, 2, 1]];
    let flat = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    assert!(!is_convex(&flat, &flat_t, &Surface::of(&flat_t).unwrap()));
}

fn small_int() -> impl Strategy<Value = f64> {
    (-6i32..=6).prop_map(f64::from)
}

fn point() -> impl Strategy<Value = DVec3> {
    prop_oneof![
        (small_int(), small_int(), small_int()).prop_map(|(x, y, z)| DVec3::new(x, y, z)),
        (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z)),
    ]
}

fn shape() -> impl Strategy<Value = Option<Shape>> {
    prop_oneof![
        (point(), point()).prop_map(|(a, b)| {
            let (lo, hi) = (a.min(b), a.max(b));
            (lo.cmplt(hi).all()).then(|| cuboid(lo, hi))
        }),
        [point(), point(), point(), point()].prop_map(tetrahedron),
        ([point(), point(), point()], point()).prop_map(|(b, t)| prism(b, t)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]
    #[test]
    fn random_polytopes_match_brute_force(a in shape(), b in shape()) {
        let (Some(a), Some(b)) = (a, b) else { return Ok(()) };
        check(&a, &b);
    }
}

/// A prism over a regular `n`-gon of radius `r` (turned by `turn`) centered at `c`, of height
/// `h`: exactly convex (a flat fan on each cap, vertical planar sides).
fn ngon_prism(n: u32, r: f64, turn: f64, c: DVec3, h: f64) -> Shape {
    let mut v = Vec::new();
    for z in [c.z, c.z + h] {
        for k in 0..n {
            let a = turn + std::f64::consts::TAU * k as f64 / n as f64;
            v.push(DVec3::new(c.x + r * a.cos(), c.y + r * a.sin(), z));
        }
    }
    let mut t = Vec::new();
    for k in 1..n - 1 {
        t.push([0, k + 1, k]);
        t.push([n, n + k, n + k + 1]);
    }
    for k in 0..n {
        let j = (k + 1) % n;
        t.push([k, j, j + n]);
        t.push([k, j + n, k + n]);
    }
    Shape::new(v, t)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]
    /// Many faces and edges: most axes are settled by the inner-ball bounds, the answer must
    /// still be the brute force's.
    #[test]
    fn many_sided_prisms_match_brute_force(
        n in 5u32..10, m in 5u32..10, turn in 0.0..1.0f64, dx in -3.0..3.0f64, dy in -3.0..3.0f64, dz in -2.0..2.0f64,
    ) {
        let a = ngon_prism(n, 2.0, 0.0, DVec3::ZERO, 3.0);
        let b = ngon_prism(m, 1.5, turn, DVec3::new(dx, dy, dz), 2.5);
        prop_assume!(is_convex(&a.positions, &a.triangles, &a.surface));
        prop_assume!(is_convex(&b.positions, &b.triangles, &b.surface));
        check(&a, &b);
    }
}

/// `h / √n2` is correctly rounded: the two midpoints around the result bracket the exact value
/// (compared squared, in rationals), and exact quotients come out exact.
/// Any interval given as a hint (holding the depth or not) gives the same result.
fn assert_correctly_rounded(h: f64, n2: f64) {
    let (hd, nd) = (Dyadic::from_f64(h), Dyadic::from_f64(n2));
    let r = rounded_depth(&hd, &nd, (0.0, f64::INFINITY));
    let e = h / n2.sqrt();
    let step =
        |x: f64, k: i64| if x > 0.0 { f64::from_bits((x.to_bits() as i64 + k).max(1) as u64) } else { x };
    for near in [
        (step(e, -2), step(e, 2)),
        (step(e, -1), step(e, 1)),
        (e, e),
        (step(e, 1), step(e, 3)),
        (step(e, -3), step(e, -1)),
        (e * 0.5, e * 2.0),
        (e * 2.0, e * 0.5),
        (-1.0, f64::NAN),
        (f64::MIN_POSITIVE, f64::MAX),
    ] {
        assert_eq!(rounded_depth(&hd, &nd, near).to_bits(), r.to_bits(), "{h} / sqrt({n2}) with {near:?}");
    }
    if h <= 0.0 {
        assert_eq!(r, 0.0);
        return;
    }
    let exact = q(h) * q(h) / q(n2); // the depth squared
    let mid = |x: f64, y: f64| (q(x) + q(y)) / Q::from_integer(BigInt::from(2));
    let below = if r == 0.0 { Q::zero() } else { mid(f64::from_bits(r.to_bits() - 1), r) };
    let above = mid(r, f64::from_bits(r.to_bits() + 1));
    assert!(below.clone() * below <= exact, "{r} is too large for {h} / sqrt({n2})");
    assert!(exact <= above.clone() * above, "{r} is too small for {h} / sqrt({n2})");
}

#[test]
fn depths_are_correctly_rounded() {
    for (h, n2, want) in [(3.0, 4.0, 1.5), (0.75, 1.0, 0.75), (7.0 * 1e-3, 1.0, 7.0 * 1e-3), (6.0, 9.0, 2.0)]
    {
        assert_eq!(rounded_depth(&Dyadic::from_f64(h), &Dyadic::from_f64(n2), (0.0, f64::INFINITY)), want);
        assert_correctly_rounded(h, n2);
    }
    assert_eq!(rounded_depth(&Dyadic::from_f64(-1.0), &Dyadic::from_f64(2.0), (0.0, 1.0)), 0.0);
    assert_correctly_rounded(1.0, 2.0);
    assert_correctly_rounded(1e-300, 3.0);
    assert_correctly_rounded(1e300, 3.0);
}

proptest! {
    #[test]
    fn random_depths_are_correctly_rounded(h in 1e-30f64..1e30, n2 in 1e-30f64..1e30) {
        assert_correctly_rounded(h, n2);
    }
}

/// The same polytope with its coordinates snapped to multiples of 2^-10 (so that adding small
/// integers is exact); `None` when snapping broke its exact convexity.
fn snapped(s: &Shape) -> Option<Shape> {
    let p: Vec<DVec3> = s.positions.iter().map(|v| (*v * 1024.0).round() / 1024.0).collect();
    let out = Shape::new(p, s.triangles.clone());
    is_convex(&out.positions, &out.triangles, &out.surface).then_some(out)
}

/// Frames found on a polytope's coordinates and reused for an exact translation of them give
/// every bit of the penetration the frames found on the translated coordinates give.
#[test]
fn frames_of_an_exact_translation_give_the_same_penetration() {
    let mut met = 0;
    for (k, (n, m)) in [(5, 7), (8, 6), (9, 9), (12, 5), (7, 11)].into_iter().enumerate() {
        let turn = 0.1 * k as f64;
        let Some(a0) = snapped(&ngon_prism(n, 2.0, 0.0, DVec3::ZERO, 3.0)) else { continue };
        let Some(b0) = snapped(&ngon_prism(m, 1.5, turn, DVec3::new(0.75, -0.5, 0.25), 2.5)) else {
            continue;
        };
        let (fa, fb) = (Frames::of(&a0.positions, &a0.triangles), Frames::of(&b0.positions, &b0.triangles));
        for by in [DVec3::new(3.0, -2.0, 1.0), DVec3::new(-1.0, 0.0, 0.0), DVec3::new(0.0, 5.0, -4.0)] {
            let (a1, b1) = (a0.moved(by), b0.moved(by + DVec3::new(1.0, 0.0, 0.0)));
            assert!(predicates::exact_translation(&a0.positions, &a1.positions).is_some());
            assert!(predicates::exact_translation(&b0.positions, &b1.positions).is_some());
            let plain = penetration(&a1.poly(), &b1.poly());
            let framed = penetration(
                &Polytope { frames: Some(&fa), ..a1.poly() },
                &Polytope { frames: Some(&fb), ..b1.poly() },
            );
            assert_eq!(format!("{framed:?}"), format!("{plain:?}"));
            met += usize::from(plain.is_some());
        }
    }
    assert!(met >= 5, "only {met} overlapping cases");
}
