use super::*;
use crate::geom::DVec3;
use crate::scene::mesh::Object;

/// A closed unit cube (12 triangles, normals pointing in) offset by `o`, appended to `m`.
fn cube(m: &mut Mesh, o: [f64; 3]) {
    let base = m.positions.len() as u32;
    for i in 0..8 {
        m.positions.push(
            DVec3::from_array(o) + DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64),
        );
    }
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    for f in faces {
        m.triangles.push([f[0], f[1], f[2]].map(|i| base + i));
        m.triangles.push([f[0], f[2], f[3]].map(|i| base + i));
        m.tri_object.extend([0, 0]);
    }
}

fn one(f: impl FnOnce(&mut Mesh)) -> Mesh {
    let mut m =
        Mesh { objects: vec![Object { name: "m".into(), ..Default::default() }], ..Default::default() };
    f(&mut m);
    m
}

fn health_of(m: &Mesh, first_n: usize) -> Health {
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
    health(m, &merged, &all, first_n)
}

fn found(count: u64, triangles: &[u32]) -> Finding {
    Finding { count, triangles: triangles.to_vec() }
}

#[test]
fn a_clean_cube_is_closed_with_its_volume_and_nothing_else() {
    let m = one(|m| cube(m, [0.0; 3]));
    let h = health_of(&m, 10);
    assert_eq!(h, Health { closed: true, volume: Some(-1.0), ..Health::default() });
    // Turned inside out: the volume changes sign, nothing else.
    let mut flipped = m.clone();
    for t in &mut flipped.triangles {
        t.swap(1, 2);
    }
    assert_eq!(health_of(&flipped, 10), Health { closed: true, volume: Some(1.0), ..Health::default() });
}

#[test]
fn a_missing_triangle_is_one_hole_of_three_boundary_edges() {
    let mut m = one(|m| cube(m, [0.0; 3]));
    m.triangles.remove(0); // [0, 1, 3]: its edges 0-1, 1-3 and 3-0 lose a user
    m.tri_object.pop();
    let h = health_of(&m, 10);
    assert!(!h.closed);
    assert_eq!(h.volume, None);
    // The other users of 0-1, 1-3 and 3-0: [0, 5, 1], [1, 7, 3], [0, 3, 2] (renumbered).
    assert_eq!(h.boundary_edges, found(3, &[0, 4, 10]));
    assert_eq!(h.boundary_loops, 1);
    assert_eq!(h.non_manifold_edges.count + h.inconsistent_winding_edges.count + h.duplicate_faces.count, 0);
}

#[test]
fn duplicated_faces_in_either_winding_are_counted_once_each() {
    for flip in [false, true] {
        let mut m = one(|m| cube(m, [0.0; 3]));
        let mut t = m.triangles[5];
        if flip {
            t.swap(0, 1);
        }
        m.triangles.push(t);
        m.tri_object.push(0);
        let h = health_of(&m, 10);
        assert_eq!(h.duplicate_faces, found(1, &[12]), "flip {flip}");
        // The copy's three edges are now used three times.
        assert_eq!(h.non_manifold_edges.count, 3);
        assert!(!h.closed);
    }
}

#[test]
fn zero_area_triangles_are_counted_and_bound_nothing() {
    let mut m = one(|m| cube(m, [0.0; 3]));
    // A sliver on the edge 0-1 (through its midpoint) and a triangle with a repeated index.
    m.positions.push(DVec3::new(0.5, 0.0, 0.0));
    m.triangles.extend([[0, 8, 1], [2, 2, 3]]);
    m.tri_object.extend([0, 0]);
    let h = health_of(&m, 10);
    assert_eq!(h.zero_area_triangles, found(2, &[12, 13]));
    assert!(h.closed, "zero-area triangles do not open a closed part");
    assert_eq!(h.duplicate_faces.count, 0);
}

#[test]
fn a_flipped_triangle_gives_three_inconsistent_edges() {
    let mut m = one(|m| cube(m, [0.0; 3]));
    m.triangles[7].swap(1, 2);
    let h = health_of(&m, 10);
    assert_eq!(h.inconsistent_winding_edges.count, 3);
    assert_eq!(h.inconsistent_winding_edges.triangles.len(), 4);
    assert!(h.inconsistent_winding_edges.triangles.contains(&7));
    assert!(h.closed, "winding does not change closedness");
}

#[test]
fn bow_ties_are_non_manifold_vertices() {
    // Two cubes sharing one corner: closed, every edge used twice, one bow-tie vertex.
    let m = one(|m| {
        cube(m, [0.0; 3]);
        cube(m, [1.0; 3]);
    });
    let h = health_of(&m, 100);
    assert!(h.closed);
    assert_eq!(h.non_manifold_edges.count, 0);
    assert_eq!(h.non_manifold_vertices.count, 1);
    // Every triangle using (1, 1, 1): three corners per cube, 2 + 1 + 2 triangles each... all
    // six faces meeting there, so 2 cubes × 3 faces × (1 or 2) triangles.
    let at = DVec3::ONE;
    let using: Vec<u32> =
        (0..m.triangles.len() as u32).filter(|&t| crate::bvh::triangle(&m, t).contains(&at)).collect();
    assert_eq!(h.non_manifold_vertices.triangles, using);
    // Two triangles touching at one vertex: an open bow-tie.
    let p = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [-1., 0., 0.], [0., -1., 0.]];
    let bow = one(|m| {
        m.positions = p.iter().map(|&x| DVec3::from_array(x)).collect();
        m.triangles = vec![[0, 1, 2], [0, 3, 4]];
        m.tri_object = vec![0, 0];
    });
    let h = health_of(&bow, 10);
    assert_eq!(h.non_manifold_vertices, found(1, &[0, 1]));
    assert_eq!(h.boundary_edges.count, 6);
    assert_eq!(h.boundary_loops, 1, "the two triangles' boundaries meet at the bow-tie vertex");
}

#[test]
fn cubes_sharing_an_edge_have_one_non_manifold_edge_and_lists_are_capped() {
    let m = one(|m| {
        cube(m, [0.0; 3]);
        cube(m, [1.0, 1.0, 0.0]);
    });
    let h = health_of(&m, 2);
    assert_eq!(h.non_manifold_edges.count, 1);
    assert_eq!(h.non_manifold_edges.triangles.len(), 2, "capped at first_n");
    assert!(!h.closed);
    assert_eq!(h.boundary_edges.count, 0);
}

/// A small part of a large mesh has sparse vertex ids (the comparison-sort path of the edge
/// sort); its health is the same as that of the part copied out on its own (dense ids, the
/// counting-sort path), triangle ids aside.
#[test]
fn sparse_and_dense_edge_sorts_agree() {
    let mut m = Mesh::default();
    for k in 0..40 {
        cube(&mut m, [3.0 * k as f64, 0.0, 0.0]);
    }
    // Make the last cube open and non-manifold: drop a triangle, add a fin on an edge.
    let last = m.triangles.len() - 1;
    m.triangles.remove(last);
    m.tri_object.pop();
    let fin = m.positions.len() as u32;
    m.positions.push(DVec3::new(3.0 * 39.0 + 0.5, -1.0, 0.5));
    let e = m.triangles[m.triangles.len() - 11]; // the last cube's first triangle
    m.triangles.push([e[0], e[1], fin]);
    m.tri_object.push(0);
    m.objects.push(Object { name: "m".into(), ..Default::default() });
    let part: Vec<u32> = ((m.triangles.len() - 12) as u32..m.triangles.len() as u32).collect();
    let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
    let sparse = health(&m, &merged, &part, 100);
    let alone = m.sub_mesh(&part);
    let (merged2, _) = crate::scene::bodies::merge_vertices(&alone.positions);
    let all: Vec<u32> = (0..alone.triangles.len() as u32).collect();
    let dense = health(&alone, &merged2, &all, 100);
    let shift = |f: &Finding| f.triangles.iter().map(|&t| t + part[0]).collect::<Vec<u32>>();
    assert_eq!((sparse.closed, dense.closed), (false, false));
    for (s, d) in [
        (&sparse.boundary_edges, &dense.boundary_edges),
        (&sparse.non_manifold_edges, &dense.non_manifold_edges),
        (&sparse.inconsistent_winding_edges, &dense.inconsistent_winding_edges),
        (&sparse.non_manifold_vertices, &dense.non_manifold_vertices),
    ] {
        assert_eq!((s.count, s.triangles.clone()), (d.count, shift(d)));
    }
    assert!(sparse.boundary_edges.count > 0 && sparse.non_manifold_edges.count > 0);
    assert_eq!(sparse.boundary_loops, dense.boundary_loops);
}
