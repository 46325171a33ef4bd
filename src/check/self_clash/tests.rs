use super::*;
use crate::narrow::tri_tri::Contact;
use crate::scene::mesh::Object;
use proptest::prelude::*;

fn mesh(p: &[[f64; 3]], t: &[[u32; 3]]) -> Mesh {
    Mesh {
        positions: p.iter().map(|&x| DVec3::from_array(x)).collect(),
        triangles: t.to_vec(),
        tri_object: vec![0; t.len()],
        objects: vec![Object { name: "m".into(), ..Default::default() }],
    }
}

/// Self-clash pairs of the whole mesh as (a, b, crossing, contact); checked against the brute
/// force on the way, for every leaf size.
fn pairs(m: &Mesh) -> Vec<(u32, u32, bool, Contact)> {
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
    let want = self_pairs_brute_force(m, &merged, &all);
    for leaf_size in [1, 2, 4] {
        let got = self_pairs(m, &merged, &all, BuildOptions { leaf_size, ..Default::default() });
        assert_eq!(got, want, "leaf size {leaf_size}");
    }
    want.iter().map(|p| (p.a, p.b, p.hit.crossing, p.hit.contact)).collect()
}

fn cube() -> Mesh {
    let p: Vec<[f64; 3]> =
        (0..8).map(|i| [(i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64]).collect();
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let t: Vec<[u32; 3]> = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
    mesh(&p, &t)
}

#[test]
fn a_closed_cube_has_no_self_clash_indexed_or_as_a_soup() {
    let m = cube();
    assert!(pairs(&m).is_empty());
    // The same cube with every triangle's vertices stored separately (and one zero negated):
    // the exact merge restores the connectivity.
    let mut soup = Mesh { objects: m.objects.clone(), ..Default::default() };
    for (k, t) in m.triangles.iter().enumerate() {
        for &v in t {
            let mut p = m.positions[v as usize];
            if k == 3 && p.x == 0.0 {
                p.x = -0.0;
            }
            soup.positions.push(p);
        }
        let b = 3 * k as u32;
        soup.triangles.push([b, b + 1, b + 2]);
        soup.tri_object.push(0);
    }
    assert!(pairs(&soup).is_empty());
}

#[test]
fn a_strip_folded_back_through_itself_crosses_exactly_where_it_passes() {
    // Q1: the quad x in [0,2], y in [0,1], z = 0; Q2 climbs from x = 2 back to x = 1, z = 1;
    // Q3 drops vertically at x = 1 from z = 1 to z = -1, through Q1.
    let p = [
        [0., 0., 0.],
        [0., 1., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [1., 0., 1.],
        [1., 1., 1.],
        [1., 0., -1.],
        [1., 1., -1.],
    ];
    let t = [
        [0, 2, 3], // 0: Q1, y <= x/2
        [0, 3, 1], // 1: Q1
        [2, 4, 5], // 2: Q2
        [2, 5, 3], // 3: Q2
        [4, 5, 7], // 4: Q3, meets z = 0 for y in [1/2, 1]
        [4, 7, 6], // 5: Q3, meets z = 0 for y in [0, 1/2]
    ];
    let got = pairs(&mesh(&p, &t));
    assert_eq!(
        got,
        [
            (0, 4, false, Contact::Point),  // only (1, 1/2, 0), on the diagonal of Q1
            (0, 5, true, Contact::Segment), // y in (0, 1/2): both interiors
            (1, 4, true, Contact::Segment),
            (1, 5, false, Contact::Point),
        ]
    );
}

#[test]
fn coplanar_triangles_sharing_an_edge_fold_only_on_the_same_side() {
    let p = [[0., 0., 0.], [4., 0., 0.], [2., 1., 0.], [1., 3., 0.], [2., -1., 0.], [2., 1., 1.]];
    // Same side of the shared edge 0-1: their interiors overlap (a fold).
    assert_eq!(pairs(&mesh(&p, &[[0, 1, 2], [1, 0, 3]])), [(0, 1, false, Contact::CoplanarArea)]);
    // Opposite sides, or another plane: they meet exactly in the shared edge.
    assert!(pairs(&mesh(&p, &[[0, 1, 2], [1, 0, 4]])).is_empty());
    assert!(pairs(&mesh(&p, &[[0, 1, 2], [1, 0, 5]])).is_empty());
    // The fold seen as two fans of two triangles each around the shared edge's ends.
    let fans = mesh(&p, &[[0, 1, 2], [0, 2, 5], [1, 0, 3], [1, 3, 5]]);
    assert!(pairs(&fans).contains(&(0, 2, false, Contact::CoplanarArea)));
}

#[test]
fn triangles_sharing_a_vertex_clash_iff_they_meet_anywhere_else() {
    let p = [
        [0., 0., 0.],  // 0: shared v
        [2., 0., 0.],  // 1
        [0., 2., 0.],  // 2
        [1., 1., 1.],  // 3
        [1., 1., -1.], // 4
        [-1., 0., 0.], // 5
        [0., -1., 0.], // 6
        [1., 0.5, 0.], // 7: inside triangle 0-1-2
        [3., 0., 0.],  // 8
        [0., 0., 1.],  // 9
    ];
    // A fan: only the vertex in common.
    assert!(pairs(&mesh(&p, &[[0, 1, 2], [0, 5, 6]])).is_empty());
    assert!(pairs(&mesh(&p, &[[0, 1, 2], [0, 9, 5]])).is_empty());
    // Through the other's interior: a crossing.
    assert_eq!(pairs(&mesh(&p, &[[0, 1, 2], [0, 3, 4]])), [(0, 1, true, Contact::Segment)]);
    // Coplanar and overlapping near the vertex.
    assert_eq!(pairs(&mesh(&p, &[[0, 1, 2], [0, 7, 8]])), [(0, 1, false, Contact::CoplanarArea)]);
    // Leaning on the other's edge: a segment beyond the vertex, touching.
    assert_eq!(pairs(&mesh(&p, &[[0, 1, 2], [0, 8, 9]])), [(0, 1, false, Contact::Segment)]);
}

#[test]
fn a_vertex_on_a_face_it_is_not_connected_to_touches() {
    let p = [[0., 0., 0.], [4., 0., 0.], [0., 4., 0.], [1., 1., 0.], [1., 1., 2.], [2., 1., 2.]];
    assert_eq!(pairs(&mesh(&p, &[[0, 1, 2], [3, 4, 5]])), [(0, 1, false, Contact::Point)]);
    // The same vertex one ulp above the face: nothing.
    let mut q = p;
    q[3][2] = f64::from_bits(1);
    assert!(pairs(&mesh(&q, &[[0, 1, 2], [3, 4, 5]])).is_empty());
}

#[test]
fn a_duplicated_face_is_not_a_self_clash_pair_but_a_copy_shifted_by_a_vertex_is() {
    let p = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 0.]];
    // Stored twice, once in the other winding and through a copied vertex: all three shared.
    assert!(pairs(&mesh(&p, &[[0, 1, 2], [3, 2, 1]])).is_empty());
    let p2 = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0.5, 0.]];
    assert_eq!(pairs(&mesh(&p2, &[[0, 1, 2], [3, 1, 2]])), [(0, 1, false, Contact::CoplanarArea)]);
}

#[test]
fn zero_area_triangles_follow_the_same_rule() {
    let p =
        [[0., 0., 0.], [2., 0., 0.], [1., 0., 0.], [3., 0., 0.], [0., 2., 0.], [-1., 0., 0.], [1., 0., 1.]];
    // A sliver 0-2-1 lying on the edge 0-1 of triangle 0-1-4: shares the edge, stays on it.
    assert!(pairs(&mesh(&p, &[[0, 1, 4], [0, 2, 1]])).is_empty());
    // A sliver 0-1-3 extending the edge beyond 1: still only the edge in common.
    assert!(pairs(&mesh(&p, &[[0, 1, 4], [0, 1, 3]])).is_empty());
    // Two slivers on one line sharing 0-2, both reaching beyond 2 (to 1 and 3): a clash.
    assert_eq!(pairs(&mesh(&p, &[[0, 2, 1], [2, 0, 3]])), [(0, 1, false, Contact::Segment)]);
    // ... one beyond 2, the other beyond 0: only the shared segment.
    assert!(pairs(&mesh(&p, &[[0, 2, 1], [2, 0, 5]])).is_empty());
    // The sliver 0-2-1 (vertex 2 strictly inside it) shares only vertex 2 with the triangle
    // 2-6-3, whose edge 2-3 runs along the sliver from 2 to 1: they share [2, 1], a clash.
    assert_eq!(pairs(&mesh(&p, &[[0, 2, 1], [2, 6, 3]])), [(0, 1, false, Contact::Segment)]);
    // The same triangle against a sliver reaching from 2 only backwards (to 5): just vertex 2.
    assert!(pairs(&mesh(&p, &[[5, 0, 2], [2, 6, 3]])).is_empty());
    // Sliver 5-1-2 (2 strictly inside it) and triangle 2-3-4 lying on its line beyond 2 to 3:
    // they share vertex 2 and the segment [2, 1] in the edge 2-3: a clash.
    assert_eq!(pairs(&mesh(&p, &[[5, 1, 2], [2, 3, 4]])), [(0, 1, false, Contact::Segment)]);
    // A point-triangle at a shared vertex: nothing else to meet.
    assert!(pairs(&mesh(&p, &[[2, 2, 2], [2, 3, 4]])).is_empty());
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let m = crate::testing::gen::torus(4000);
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
    let run = |n| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
        pool.install(|| self_pairs(&m, &merged, &all, BuildOptions::default()))
    };
    assert!(run(1).is_empty());
    // Squash the torus flat (z = 0): every far-apart pair of the top and bottom halves now
    // overlaps; one thread and two give the same list.
    let mut flat = m.clone();
    for p in &mut flat.positions {
        p.z = 0.0;
    }
    let run_flat = |n| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
        pool.install(|| self_pairs(&flat, &merged, &all, BuildOptions::default()))
    };
    let one = run_flat(1);
    assert!(!one.is_empty());
    assert_eq!(one, run_flat(2));
}

/// Integer coordinates in [0, 3]: many shared, collinear and coplanar configurations.
fn small_mesh() -> impl Strategy<Value = Mesh> {
    (3usize..9).prop_flat_map(|nv| {
        (
            prop::collection::vec(prop::array::uniform3(0i32..4), nv),
            prop::collection::vec(prop::array::uniform3(0..nv as u32), 1..12),
        )
            .prop_map(|(p, t)| {
                let p: Vec<[f64; 3]> = p.iter().map(|v| v.map(|c| c as f64)).collect();
                mesh(&p, &t)
            })
    })
}

/// An independent oracle for two proper triangles: cut a sliver of relative width 2^-20 off
/// each at what they share; with coordinates in [0, 3] every point of the intersection beyond
/// the shared part is much farther from it than that, so the intersection is more than the
/// shared part iff one cut triangle still meets the other whole one.
fn oracle(ta: &[DVec3; 3], ia: [u32; 3], tb: &[DVec3; 3], ib: [u32; 3]) -> bool {
    let lam = (2.0f64).powi(-20);
    let cut = |t: &[DVec3; 3], own: [u32; 3], other: [u32; 3]| -> Vec<[DVec3; 3]> {
        let shared: Vec<usize> = (0..3).filter(|&k| other.contains(&own[k])).collect();
        let toward = |from: DVec3, to: DVec3| from + (to - from) * lam;
        match shared[..] {
            [] => vec![*t],
            [k] => {
                let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let (a2, b2) = (toward(v, a), toward(v, b));
                vec![[a, b, a2], [b, b2, a2]]
            }
            [k, l] => {
                let m = 3 - k - l;
                let (u, w, a) = (t[k], t[l], t[m]);
                vec![[a, toward(u, a), toward(w, a)]]
            }
            _ => vec![],
        }
    };
    cut(ta, ia, ib).iter().any(|c| tri_tri::classify(c, tb).is_some())
        || cut(tb, ib, ia).iter().any(|c| tri_tri::classify(ta, c).is_some())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// The tree walk finds exactly the brute-force pairs (every leaf size), and for proper
    /// triangles the rule agrees with the cut-sliver oracle.
    #[test]
    fn walk_matches_brute_force_and_the_rule_matches_an_oracle(m in small_mesh()) {
        let got = pairs(&m);
        let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
        let ids = |t: usize| m.triangles[t].map(|v| merged[v as usize]);
        for a in 0..m.triangles.len() {
            for b in a + 1..m.triangles.len() {
                let (ta, tb) = (crate::bvh::triangle(&m, a as u32), crate::bvh::triangle(&m, b as u32));
                let distinct = |i: [u32; 3]| i[0] != i[1] && i[1] != i[2] && i[0] != i[2];
                if !distinct(ids(a)) || !distinct(ids(b)) || tri_tri::Shape::of(&ta).is_degenerate()
                    || tri_tri::Shape::of(&tb).is_degenerate() {
                    continue;
                }
                let listed = got.iter().any(|p| (p.0, p.1) == (a as u32, b as u32));
                prop_assert_eq!(listed, oracle(&ta, ids(a), &tb, ids(b)), "pair {} {}", a, b);
            }
        }
    }
}

#[test]
fn a_folded_torus_crosses_only_around_the_fold() {
    let m = gen::folded_torus(2000);
    let got = pairs(&m);
    assert!(got.iter().any(|p| p.2), "the pulled vertex's triangles pierce the inner wall");
    // Every pair involves one of the six triangles around the moved vertex 0.
    let moved = |t: u32| m.triangles[t as usize].contains(&0);
    assert!(got.iter().all(|p| moved(p.0) || moved(p.1)), "{got:?}");
    assert_eq!(m.triangles.iter().filter(|t| t.contains(&0)).count(), 6);
    // The same torus unfolded: nothing.
    assert!(pairs(&crate::testing::gen::torus(2000)).is_empty());
}

#[test]
fn a_tube_swept_along_a_figure_eight_overlaps_itself_only_at_the_crossing() {
    let (u, v) = (96, 12);
    let m = gen::figure_eight_tube(u, v, 0.1);
    let got = pairs(&m);
    assert!(got.iter().filter(|p| p.2).count() >= 4, "{got:?}");
    // Every pair joins the two branches through the origin: one triangle from the ring range
    // around t = π/2, the other from around t = 3π/2 (rings are triangle / (2v)).
    let t_of = |tri: u32| (tri as usize / (2 * v)) as f64 / u as f64 * std::f64::consts::TAU;
    let near = |t: f64, c: f64| (t - c).abs() < 0.35;
    for p in &got {
        let (ta, tb) = (t_of(p.0), t_of(p.1));
        let (h, h3) = (std::f64::consts::FRAC_PI_2, 3.0 * std::f64::consts::FRAC_PI_2);
        assert!((near(ta, h) && near(tb, h3)) || (near(ta, h3) && near(tb, h)), "{p:?}: t = {ta}, {tb}");
    }
    // A thinner tube still crosses itself there.
    assert!(pairs(&gen::figure_eight_tube(u, v, 0.02)).iter().any(|p| p.2));
}

#[test]
fn exact_translation_holds_only_when_every_sum_is_exact() {
    use crate::geom::predicates::exact_translation;
    let a = [DVec3::new(0.5, 1.25, -3.0), DVec3::new(1.0, 2.0, 4.0)];
    let t = DVec3::new(1000.0, -0.25, 8.0);
    let b: Vec<DVec3> = a.iter().map(|&p| p + t).collect();
    assert_eq!(exact_translation(&a, &b), Some(t));
    // 0.1 + 0.2 rounds: b is not an exact translate of a although each b[i] = fl(a[i] + t).
    let (a, t) = ([DVec3::splat(0.1), DVec3::splat(1.0)], DVec3::splat(0.2));
    let b: Vec<DVec3> = a.iter().map(|&p| p + t).collect();
    assert_eq!(exact_translation(&a, &b), None);
    // Different offsets, lengths, nothing.
    let a = [DVec3::ZERO, DVec3::ONE];
    assert_eq!(exact_translation(&a, &[DVec3::ONE, DVec3::splat(3.0)]), None);
    assert_eq!(exact_translation(&a, &a[..1]), None);
    assert_eq!(exact_translation(&[], &[]), None);
}

/// Three instances of one folded strip (one glTF mesh): the original, an exact translate and a
/// copy turned by 30° about z (rounded). With reuse the translate takes over the original's
/// result and the turned copy is checked itself; every result equals a separate check.
#[test]
fn instances_reuse_only_exact_translates_and_give_the_same_results() {
    let strip = [
        [0., 0., 0.],
        [0., 1., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [1., 0., 1.],
        [1., 1., 1.],
        [1., 0., -1.],
        [1., 1., -1.],
    ];
    let f = [[0u32, 2, 3], [0, 3, 1], [2, 4, 5], [2, 5, 3], [4, 5, 7], [4, 7, 6]];
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let place: [Box<dyn Fn([f64; 3]) -> DVec3>; 3] = [
        Box::new(DVec3::from_array),
        Box::new(|p| DVec3::from_array(p) + DVec3::new(16.0, 0.5, -2.0)),
        Box::new(move |p| DVec3::new(c * p[0] - s * p[1] + 40.0, s * p[0] + c * p[1], p[2])),
    ];
    let mut m = Mesh::default();
    for (k, at) in place.iter().enumerate() {
        let base = m.positions.len() as u32;
        m.positions.extend(strip.iter().map(|&p| at(p)));
        m.triangles.extend(f.iter().map(|t| t.map(|i| base + i)));
        m.tri_object.extend([k as u32; 6]);
        m.objects.push(Object { name: format!("strip{k}"), gltf_mesh: Some(7), ..Default::default() });
    }
    let specs = || -> Vec<PartSpec> {
        crate::check::assembly::parts_of(&m, 0)
            .into_iter()
            .map(|p| (Some(p.object), p.name, p.triangles))
            .collect()
    };
    let (with, _, _) = check_part_list(&m, specs(), BuildOptions::default(), 10, usize::MAX, true);
    let (without, _, _) = check_part_list(&m, specs(), BuildOptions::default(), 10, usize::MAX, false);
    assert_eq!(with.iter().map(|p| p.same_as).collect::<Vec<_>>(), [None, Some(0), None]);
    assert!(without.iter().all(|p| p.same_as.is_none()));
    for (x, y) in with.iter().zip(&without) {
        assert_eq!((&x.pairs, &x.health, x.crossing), (&y.pairs, &y.health, y.crossing), "{}", x.name);
    }
    assert_eq!(
        with[1].pairs.iter().map(|q| (q.a, q.b)).collect::<Vec<_>>(),
        [(6, 10), (6, 11), (7, 10), (7, 11)] // the original's (0, 4), (0, 5), (1, 4), (1, 5), shifted by 6
    );
    assert_eq!(with[0].crossing, with[1].crossing);
    assert!(with[1].crossing > 0);
}

/// A closed octahedron of radius 2 with every face split in four (18 vertices, 32 triangles),
/// all coordinates integers, consistently wound: every vertex has a closed fan.
fn split_octahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut p: Vec<[f64; 3]> =
        vec![[2., 0., 0.], [-2., 0., 0.], [0., 2., 0.], [0., -2., 0.], [0., 0., 2.], [0., 0., -2.]];
    let faces = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    let mut mid = std::collections::HashMap::new();
    let mut mid_of = |a: u32, b: u32, p: &mut Vec<[f64; 3]>| -> u32 {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (x, y) = (p[a as usize], p[b as usize]);
            p.push([(x[0] + y[0]) / 2.0, (x[1] + y[1]) / 2.0, (x[2] + y[2]) / 2.0]);
            p.len() as u32 - 1
        })
    };
    let mut t = Vec::new();
    for [a, b, c] in faces {
        let (ab, bc, ca) = (mid_of(a, b, &mut p), mid_of(b, c, &mut p), mid_of(c, a, &mut p));
        t.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    (p, t)
}

/// Bits of the fan certificates of the whole mesh, as a list of certified merged vertices.
fn certified_vertices(m: &Mesh) -> Vec<u32> {
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
    let fans = Fans::new(m, &merged, &all);
    let bits = certified_fans(m, &all, &fans, None);
    let mut out = Vec::new();
    for (k, t) in m.triangles.iter().enumerate() {
        for c in 0..3 {
            let v = fans.ids[k][c];
            if bits[v as usize / 64] >> (v % 64) & 1 != 0 {
                out.push(merged[t[c] as usize]);
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

#[test]
fn fan_certificates_hold_where_the_surface_is_a_clean_sheet_and_only_there() {
    // Every fan of a torus and of the split octahedron is certified.
    let torus = crate::testing::gen::torus(2000);
    assert_eq!(certified_vertices(&torus).len(), torus.positions.len());
    let (p, t) = split_octahedron();
    let oct = mesh(&p, &t);
    assert_eq!(certified_vertices(&oct).len(), 18);
    // Move one ring vertex of the top (0, 0, 2) across its ring: the top's fan folds over
    // itself, is not certified, and the walk still finds exactly the brute-force pairs.
    let mut folded = oct.clone();
    let m0 = folded.positions.iter().position(|q| *q == DVec3::new(1.0, 0.0, 1.0)).unwrap();
    folded.positions[m0] = DVec3::new(-1.0, 1.0, 1.0);
    let (merged, _) = crate::scene::bodies::merge_vertices(&folded.positions);
    assert!(!certified_vertices(&folded).contains(&merged[4]));
    assert!(!pairs(&folded).is_empty());
    // Pull the top through to (0, 0, -3): its fan is a clean cone again (certified); what it
    // now crosses are the far triangles, which the walk tests.
    let mut pulled = oct.clone();
    pulled.positions[4] = DVec3::new(0.0, 0.0, -3.0);
    let (merged, _) = crate::scene::bodies::merge_vertices(&pulled.positions);
    assert!(certified_vertices(&pulled).contains(&merged[4]));
    assert!(pairs(&pulled).iter().any(|p| p.2));
    // An open fan (a boundary vertex) is never certified: drop one triangle.
    let mut open = oct.clone();
    open.triangles.pop();
    open.tri_object.pop();
    assert!(certified_vertices(&open).len() < 18);
    assert!(pairs(&open).is_empty());
}

#[test]
fn a_fan_winding_twice_around_its_vertex_is_not_certified() {
    // v at the origin, a ring of five points visited in pentagram order (each step turns
    // 144° one way), alternately above and below: closed, consistently wound, every triangle
    // proper with a positive z normal component, but the ring goes around v twice.
    let ring: Vec<[f64; 3]> = (0..5)
        .map(|i| {
            let a = (i * 2 % 5) as f64 * std::f64::consts::TAU / 5.0;
            [(4.0 * a.cos()).round(), (4.0 * a.sin()).round(), if i % 2 == 0 { 1.0 } else { -1.0 }]
        })
        .collect();
    let mut p = vec![[0.0, 0.0, 0.0]];
    p.extend(ring);
    let t: Vec<[u32; 3]> = (0..5u32).map(|i| [0, 1 + i, 1 + (i + 1) % 5]).collect();
    let m = mesh(&p, &t);
    assert!(certified_vertices(&m).is_empty());
    // Whatever the fan does, the walk gives the brute-force answer (checked inside).
    pairs(&m);
}

/// The split octahedron with some vertices moved to other integer points in [-3, 3]: folds,
/// coplanar neighbours, fans winding twice or not at all, next to untouched certified fans.
fn bent_octahedron() -> impl Strategy<Value = Mesh> {
    prop::collection::vec((0usize..18, prop::array::uniform3(-3i32..4)), 0..4).prop_map(|moves| {
        let (mut p, t) = split_octahedron();
        for (v, to) in moves {
            p[v] = to.map(|c| c as f64);
        }
        mesh(&p, &t)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// With certified fans skipping their pairs, the walk still finds exactly the brute-force
    /// pairs (every leaf size; checked in `pairs`).
    #[test]
    fn certified_fans_lose_no_pair(m in bent_octahedron()) {
        pairs(&m);
    }
}

/// A fan of `m` triangles around the origin over ring points `ring` (integers), triangle `i`
/// = (v, ring[i], ring[i + 1]), closed when `closed`.
fn fan(ring: &[[f64; 3]], closed: bool) -> Mesh {
    let mut p = vec![[0.0, 0.0, 0.0]];
    p.extend_from_slice(ring);
    let n = ring.len() as u32;
    let last = if closed { n } else { n - 1 };
    let t: Vec<[u32; 3]> = (0..last).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    mesh(&p, &t)
}

/// `m` points on a circle of radius `r`, rounded to integers (distinct for the sizes used).
fn circle(m: usize, r: f64, z: impl Fn(usize) -> f64) -> Vec<[f64; 3]> {
    (0..m)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / m as f64;
            [(r * a.cos()).round(), (r * a.sin()).round(), z(i)]
        })
        .collect()
}

#[test]
fn large_fans_are_certified_by_their_sectors_exactly_when_they_tile() {
    // Flat and closed (a disc of 200 triangles): certified, no pair.
    let flat = fan(&circle(200, 1000.0, |_| 0.0), true);
    assert_eq!(certified_vertices(&flat), [0]);
    assert!(pairs(&flat).is_empty());
    // Open (a half disc), and a wavy cone: certified as well.
    let half: Vec<[f64; 3]> = circle(400, 1000.0, |_| 0.0).into_iter().take(201).collect();
    assert!(certified_vertices(&fan(&half, false)).contains(&0));
    let wavy = fan(&circle(100, 1000.0, |i| (i % 3) as f64 - 1.0), true);
    assert!(certified_vertices(&wavy).contains(&0));
    assert!(pairs(&wavy).is_empty());
    // A fan turning one and a half times: its sectors overlap; not certified, and the walk
    // finds the brute-force pairs (checked inside `pairs`).
    let ring = circle(40, 1000.0, |_| 0.0);
    let twice: Vec<[f64; 3]> = ring.iter().chain(&ring[..20]).map(|q| [q[0], q[1], 0.0]).collect();
    let mut m = fan(&twice, false);
    // The second turn's points are other vertices at the same places: pull them halfway to
    // v so they are distinct points, in the same plane, over the first turn.
    for q in &mut m.positions[41..] {
        *q *= 0.5;
    }
    assert!(!certified_vertices(&m).contains(&0));
    assert!(!pairs(&m).is_empty());
    // Two sectors touching along one ray at different vertices: not certified.
    let mut touching = fan(&circle(60, 1000.0, |_| 0.0), false);
    touching.positions[60] = touching.positions[1] * 0.5; // the last ray is the first one
    assert!(!certified_vertices(&touching).contains(&0));
    pairs(&touching);
}

/// Fans of 33 to 48 triangles around the origin over random integer ring points: folds,
/// repeats, collinear rays, zero-area triangles; certified or not, the walk gives the brute
/// force answer.
fn big_fan() -> impl Strategy<Value = Mesh> {
    (33usize..48, prop::collection::vec((0usize..48, prop::array::uniform3(-3i32..4)), 0..3), any::<bool>())
        .prop_map(|(m, moves, closed)| {
            let mut ring = circle(m, 40.0, |i| (i % 2) as f64);
            for (i, to) in moves {
                ring[i % m] = to.map(|c| c as f64);
            }
            fan(&ring, closed)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn large_fan_certificates_lose_no_pair(m in big_fan()) {
        pairs(&m);
    }
}

#[test]
fn copies_of_a_face_are_walked_once_and_every_pair_of_two_sets_is_listed() {
    // 30 copies of one triangle in every winding and with separate vertices, 20 copies of a
    // triangle crossing it, 10 point triangles at a point on it, 5 segments through it.
    let mut p: Vec<[f64; 3]> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    let mut add = |pts: [[f64; 3]; 3], order: [usize; 3], p: &mut Vec<[f64; 3]>| {
        let b = p.len() as u32;
        p.extend(pts);
        t.push(order.map(|k| b + k as u32));
    };
    let flat = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let upright = [[1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [2.0, 1.0, 1.0]];
    let orders = [[0, 1, 2], [1, 2, 0], [2, 1, 0], [0, 2, 1]];
    for i in 0..30 {
        add(flat, orders[i % 4], &mut p);
    }
    for i in 0..20 {
        add(upright, orders[i % 4], &mut p);
    }
    for _ in 0..10 {
        add([[1.0, 2.0, 0.0]; 3], [0, 1, 2], &mut p);
    }
    for i in 0..5 {
        add([[3.0, 3.0, -1.0], [3.0, 3.0, 1.0], [3.0, 3.0, 1.0]], orders[i % 4], &mut p);
    }
    let m = mesh(&p, &t);
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let fans = Fans::new(&m, &merged, &(0..m.triangles.len() as u32).collect::<Vec<_>>());
    let copies = Copies::new(&fans).expect("copies");
    assert_eq!(copies.firsts().len(), 4);
    let got = pairs(&m);
    // Flat × upright crossing, point × flat touching; the segments (x + y = 6 > 4) miss.
    assert_eq!(got.iter().filter(|q| q.2).count(), 30 * 20);
    assert_eq!(got.len(), 30 * 20 + 30 * 10);
}

/// The constructions that were quadratic, at a size the brute force can check: copies of one
/// triangle, point triangles at one point, a closed flat fan, triangles on one edge, collinear
/// overlapping zero-area triangles.
#[test]
fn hostile_constructions_match_the_brute_force() {
    let n = 300;
    let copies = mesh(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &vec![[0, 1, 2]; n]);
    assert!(pairs(&copies).is_empty());
    let points: Vec<[f64; 3]> = vec![[0.5, 0.5, 0.0]; 3 * n];
    let t: Vec<[u32; 3]> = (0..n as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    assert!(pairs(&mesh(&points, &t)).is_empty());
    let disc = fan(&circle(n, 10_000.0, |_| 0.0), true);
    assert!(pairs(&disc).is_empty());
    // A book: pages at angles k·(2π/n) around the z axis, every third page repeated at twice the
    // distance (coplanar, same side: a fold with the first).
    let mut p = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let mut t = Vec::new();
    for k in 0..n / 3 {
        let a = k as f64 * std::f64::consts::TAU / (n / 3) as f64;
        let (x, y) = ((100.0 * a.cos()).round(), (100.0 * a.sin()).round());
        p.push([x, y, 0.5]);
        t.push([0, 1, p.len() as u32 - 1]);
        if k % 3 == 0 {
            p.push([2.0 * x, 2.0 * y, 0.5]);
            t.push([0, 1, p.len() as u32 - 1]);
        }
    }
    assert!(!pairs(&mesh(&p, &t)).is_empty());
    // Collinear: triangles (i, i + 2, i + 5) on the x axis.
    let p: Vec<[f64; 3]> = (0..n + 5).map(|i| [i as f64, 0.0, 0.0]).collect();
    let t: Vec<[u32; 3]> = (0..n as u32).map(|i| [i, i + 2, i + 5]).collect();
    assert!(!pairs(&mesh(&p, &t)).is_empty());
}

/// `pages` triangles on the edge (0,0,0)-(0,0,1), third vertices `thirds`.
fn book(thirds: &[[f64; 3]]) -> Mesh {
    let mut p = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    p.extend_from_slice(thirds);
    let t: Vec<[u32; 3]> =
        (0..thirds.len() as u32).map(|i| if i % 2 == 0 { [0, 1, 2 + i] } else { [1, 0, 2 + i] }).collect();
    mesh(&p, &t)
}

fn book_edges(m: &Mesh) -> usize {
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
    let fans = Fans::new(m, &merged, &all);
    let bits = certified_fans(m, &all, &fans, None);
    certified_edges(m, &all, &fans, None, &|v: u32| bits[v as usize / 64] >> (v % 64) & 1 != 0).len()
}

#[test]
fn books_of_pages_on_one_edge_are_certified_exactly_when_no_two_pages_fold() {
    // 40 pages at distinct angles, plus collinear pages beyond each end: certified, no pair.
    let mut thirds = circle(40, 1000.0, |i| (i % 5) as f64 * 0.25);
    thirds.extend([[0.0, 0.0, -3.0], [0.0, 0.0, 5.0], [0.0, 0.0, 0.5]]);
    let clean = book(&thirds);
    assert_eq!(book_edges(&clean), 1);
    assert!(pairs(&clean).is_empty());
    // A page at twice the distance of another (one half-plane): a fold, not certified.
    let mut folded = thirds.clone();
    folded.push([2.0 * thirds[3][0], 2.0 * thirds[3][1], 0.7]);
    let m = book(&folded);
    assert_eq!(book_edges(&m), 0);
    assert!(!pairs(&m).is_empty());
    // Two collinear pages beyond one end: they overlap, not certified.
    let mut two_beyond = thirds.clone();
    two_beyond.push([0.0, 0.0, 7.0]);
    let m = book(&two_beyond);
    assert_eq!(book_edges(&m), 0);
    assert!(!pairs(&m).is_empty());
}

/// Books of 16 to 40 pages with random integer third vertices (many in one half-plane, on
/// the edge's line, opposite each other): certified or not, the walk gives the brute force.
fn random_book() -> impl Strategy<Value = Mesh> {
    prop::collection::vec(prop::array::uniform3(-3i32..4), 16..40)
        .prop_map(|t| book(&t.iter().map(|v| v.map(|c| c as f64)).collect::<Vec<_>>()))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn book_certificates_lose_no_pair(m in random_book()) {
        pairs(&m);
    }

    #[test]
    fn book_certificates_lose_no_pair_among_distinct_angles(
        angles in prop::collection::btree_set(0u32..720, 16..60), beyond in 0usize..3
    ) {
        let mut thirds: Vec<[f64; 3]> = angles.iter().map(|&d| {
            let a = (d as f64).to_radians() / 2.0;
            [(1e3 * a.cos()).round(), (1e3 * a.sin()).round(), 0.5]
        }).collect();
        thirds.extend([[0.0, 0.0, 2.0], [0.0, 0.0, 3.0]].iter().take(beyond));
        pairs(&book(&thirds));
    }
}

/// `n` zero-area triangles on the line through the origin along `dir`, triangle `i` spanning
/// `[3i, 3i + 2 + 3h]` (times `dir`) with its own three vertices: members `i < j` meet iff
/// `j - i <= h`. Then `extra` triangles that are not isolated or not on that line: a segment
/// sharing a vertex with triangle 0, a proper triangle through the line, a point on it and a
/// segment on a parallel line.
fn line_soup(n: usize, h: usize, dir: [f64; 3], extra: bool) -> Mesh {
    let at = |t: f64| [t * dir[0], t * dir[1], t * dir[2]];
    let mut p = Vec::new();
    let mut t = Vec::new();
    for i in 0..n {
        let b = p.len() as u32;
        let s = 3.0 * i as f64;
        // Vertex order varies: the middle vertex is stored first, last or in between.
        let pts = [at(s), at(s + 1.0), at(s + 2.0 + 3.0 * h as f64)];
        let order = [[1, 0, 2], [0, 2, 1], [2, 1, 0]][i % 3];
        p.extend(order.map(|k| pts[k]));
        t.push([b, b + 1, b + 2]);
    }
    if extra {
        let b = p.len() as u32;
        p.extend([at(5.5), at(40.0), [1.0, 1.0, 1.0], [-1.0, 2.0, 0.5], at(7.25), at(7.25)]);
        t.push([0, b, b + 1]); // shares triangle 0's first vertex
        t.push([b + 2, b + 3, b + 1]); // a proper triangle with a corner on the line
        t.push([b + 4, b + 5, b + 4]); // a point on the line
        let off = [dir[0] + 1.0, dir[1], dir[2] + 1.0];
        let c = p.len() as u32;
        p.extend([off, [off[0] + 9.0 * dir[0], off[1] + 9.0 * dir[1], off[2] + 9.0 * dir[2]], off]);
        t.push([c, c + 1, c + 2]); // a segment off the line
    }
    mesh(&p, &t)
}

#[test]
fn collinear_segments_are_counted_by_groups_as_the_brute_force_lists_them() {
    // (Scaled by 0.1, -0.7, 0.3 the points are rounded off the line: no group, the walk.)
    for (n, h, dir, extra, grouped) in [
        (40, 5, [1.0, 2.0, 3.0], true, true),
        (60, 100, [0.0, 0.0, 1.0], true, true),
        (50, 0, [0.5, -0.75, 0.25], true, true),
        (30, 7, [1.0, 0.0, 0.0], false, true),
        (40, 4, [0.1, -0.7, 0.3], true, false),
    ] {
        let m = line_soup(n, h, dir, extra);
        let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
        let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
        let fans = Fans::new(&m, &merged, &all);
        assert!(!grouped || lines::LineGroups::new(&m, &all, &fans).is_some(), "{n} {dir:?}: a group");
        let want = self_pairs_brute_force(&m, &merged, &all);
        let crossing = want.iter().filter(|p| p.hit.crossing).count() as u64;
        for leaf_size in [1, 4] {
            let opts = BuildOptions { leaf_size, ..Default::default() };
            assert_eq!(self_pairs(&m, &merged, &all, opts), want, "{n} {h} {dir:?} leaf {leaf_size}");
            for cap in [0, 1, 7, 50, want.len(), usize::MAX] {
                let got = self_pairs_counted(&m, &merged, &all, opts, cap);
                assert_eq!(got.total, want.len() as u64, "{n} {h} {dir:?} cap {cap}");
                assert_eq!(got.crossing, crossing);
                assert_eq!(got.pairs[..], want[..cap.min(want.len())], "{n} {h} {dir:?} cap {cap}");
            }
        }
    }
}

#[test]
fn a_part_lists_its_first_pairs_and_counts_them_all() {
    // A folded torus and a figure-eight tube: crossing and touching pairs from the walk.
    for m in [gen::folded_torus(2_000), gen::figure_eight_tube(64, 12, 0.2)] {
        let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
        let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
        let want = self_pairs(&m, &merged, &all, BuildOptions::default());
        assert!(want.len() > 3);
        let crossing = want.iter().filter(|p| p.hit.crossing).count() as u64;
        for cap in [0, 1, 3, want.len() - 1, want.len(), usize::MAX] {
            let got = self_pairs_counted(&m, &merged, &all, BuildOptions::default(), cap);
            assert_eq!((got.total, got.crossing), (want.len() as u64, crossing), "cap {cap}");
            assert_eq!(got.pairs[..], want[..cap.min(want.len())], "cap {cap}");
        }
        let whole = |cap| check_parts_listing(&m, PartChoice::Whole("m"), BuildOptions::default(), 10, cap).0;
        let (full, cut) = (whole(usize::MAX), whole(2));
        assert_eq!(full[0].pairs, want);
        assert_eq!((cut[0].count, cut[0].crossing), (full[0].count, full[0].crossing));
        assert_eq!(cut[0].pairs[..], want[..2]);
    }
}
