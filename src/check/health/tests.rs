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

/// The health pass as it was before the vertex groups (a global sort of every edge, then
/// union–find over all corners), kept as an oracle for the one in use.
mod by_edge_sort {
    use super::super::{Finding, Health, VOLUME_CHUNK};
    use crate::narrow::tri_tri::Shape;
    use crate::scene::bodies::{find, union};
    use crate::scene::mesh::Mesh;
    use rayon::prelude::*;

    /// An edge of a proper triangle: (key `lo << 32 | hi`, local triangle, edge number `c` (from
    /// corner `c` to corner `c + 1`), whether corner `c` is the low end); zero-area triangles leave
    /// sentinel entries with key `u64::MAX`.
    type Edge = (u64, u32, u8, bool);

    /// `items` without those `bucket` maps to None (sentinels), sorted (total order of `T`), where
    /// `bucket` is the item's leading sort key (`x < y` implies `bucket(x) <= bucket(y)`): a vertex
    /// id. When the buckets are dense (at most 4 ids per item, as in any part that is most of its
    /// mesh), a counting sort on the bucket (one pass to count, one to scatter) and a sort of each
    /// bucket's few entries; otherwise a comparison sort. Both give the same order.
    fn bucket_sort<T: Ord + Copy + Send + Sync>(
        mut items: Vec<T>,
        bucket: impl Fn(&T) -> Option<usize> + Sync,
    ) -> Vec<T> {
        let real = items.par_iter().filter(|e| bucket(e).is_some()).count();
        let max = items.par_iter().filter_map(&bucket).max().unwrap_or(0);
        if real == 0 || max / 4 > real {
            items.par_sort_unstable();
            items.truncate(real);
            return items;
        }
        let mut next = vec![0u32; max + 2];
        for b in items.iter().filter_map(&bucket) {
            next[b + 1] += 1;
        }
        for i in 1..next.len() {
            next[i] += next[i - 1];
        }
        let Some(&fill) = items.iter().find(|e| bucket(e).is_some()) else { return Vec::new() };
        let mut out: Vec<T> = vec![fill; real];
        for e in items {
            if let Some(b) = bucket(&e) {
                out[next[b] as usize] = e;
                next[b] += 1;
            }
        }
        drop(next);
        // Each bucket's run (a handful of entries) in full order.
        out.par_chunk_by_mut(|x, y| bucket(x) == bucket(y)).for_each(|run| run.sort_unstable());
        out
    }

    /// The health of the part made of triangles `tris` of `mesh`; `merged` gives each vertex its
    /// exact-position id ([`crate::scene::bodies::merge_vertices`]). Triangle ids in the result are
    /// indices into `mesh`.
    pub fn health_by_edge_sort(mesh: &Mesh, merged: &[u32], tris: &[u32], first_n: usize) -> Health {
        let ids = |k: usize| mesh.triangles[tris[k] as usize].map(|v| merged[v as usize]);
        let pos = |k: usize| crate::bvh::triangle(mesh, tris[k]);
        let proper: Vec<bool> =
            (0..tris.len()).into_par_iter().map(|k| !Shape::of(&pos(k)).is_degenerate()).collect();
        let zero: Vec<u32> = (0..tris.len()).filter(|&k| !proper[k]).map(|k| tris[k]).collect();
        let zero_area_triangles = Finding::of(zero.len() as u64, zero, first_n);

        // Duplicates: sorted vertex sets of the triangles with three distinct vertices.
        let faces: Vec<([u32; 3], u32)> = (0..tris.len())
            .into_par_iter()
            .filter_map(|k| {
                let mut v = ids(k);
                v.sort_unstable();
                (v[0] != v[1] && v[1] != v[2]).then_some((v, tris[k]))
            })
            .collect();
        let faces = bucket_sort(faces, |f| Some(f.0[0] as usize));
        let mut dup = Vec::new();
        for run in faces.chunk_by(|x, y| x.0 == y.0) {
            dup.extend(run[1..].iter().map(|x| x.1));
        }
        drop(faces);
        let duplicate_faces = Finding::of(dup.len() as u64, dup, first_n);

        // Edges of the proper triangles: (key (lo, hi), local triangle, edge number c (from corner
        // c to corner c + 1), whether corner c is the low end), 16 bytes. Zero-area triangles get
        // sentinel keys (above every real key: lo < hi <= u32::MAX), cut off after the sort;
        // filling a preallocated array keeps the collection indexed and parallel.
        let mut edges: Vec<Edge> = vec![(u64::MAX, 0, 0, false); 3 * tris.len()];
        edges.par_chunks_mut(3).enumerate().filter(|(k, _)| proper[*k]).for_each(|(k, out)| {
            let v = ids(k);
            for (c, e) in out.iter_mut().enumerate() {
                let (a, b) = (v[c], v[(c + 1) % 3]);
                *e = ((a.min(b) as u64) << 32 | a.max(b) as u64, k as u32, c as u8, a < b);
            }
        });
        let edges = bucket_sort(edges, |e| (e.0 != u64::MAX).then_some((e.0 >> 32) as usize));
        let forward = |e: &Edge| e.3;
        let tri_of = |e: &Edge| tris[e.1 as usize];
        // Corner slots (local triangle × 3 + corner) joined through the edges at their vertex.
        let mut corner: Vec<u32> = (0..tris.len() as u32 * 3).collect();
        let corner_at = |e: &Edge, lo_end: bool| {
            let (k, c) = (e.1, e.2 as u32);
            let at_c = forward(e) == lo_end;
            k * 3 + if at_c { c } else { (c + 1) % 3 }
        };
        let (mut boundary, mut nm, mut wind) = (Vec::new(), Vec::new(), Vec::new());
        let (mut n_boundary, mut n_nm, mut n_wind) = (0u64, 0u64, 0u64);
        let mut boundary_ends: Vec<(u32, u32)> = Vec::new();
        for run in edges.chunk_by(|x, y| x.0 == y.0) {
            match run.len() {
                1 => {
                    n_boundary += 1;
                    boundary.push(tri_of(&run[0]));
                    boundary_ends.push(((run[0].0 >> 32) as u32, run[0].0 as u32));
                }
                2 if forward(&run[0]) == forward(&run[1]) => {
                    n_wind += 1;
                    wind.extend(run.iter().map(tri_of));
                }
                2 => {}
                _ => {
                    n_nm += 1;
                    nm.extend(run.iter().map(tri_of));
                }
            }
            for lo_end in [true, false] {
                for w in run.windows(2) {
                    union(&mut corner, corner_at(&w[0], lo_end), corner_at(&w[1], lo_end));
                }
            }
        }
        let closed = !edges.is_empty() && n_boundary == 0 && n_nm == 0;
        drop(edges);
        // Non-manifold vertices: more than one corner set (fan) at one vertex. Corners are only
        // ever joined with corners at the same vertex, so each fan has one root corner: a vertex
        // with two roots is non-manifold.
        let mut roots: Vec<u32> = Vec::with_capacity(tris.len() / 2 + 1);
        for k in (0..tris.len()).filter(|&k| proper[k]) {
            let v = ids(k);
            for (c, &vc) in v.iter().enumerate() {
                let slot = (k * 3 + c) as u32;
                if find(&mut corner, slot) == slot {
                    roots.push(vc);
                }
            }
        }
        drop(corner);
        roots.par_sort_unstable();
        let nmv_vertices: Vec<u32> =
            roots.chunk_by(|x, y| x == y).filter(|run| run.len() > 1).map(|run| run[0]).collect();
        let n_nmv = nmv_vertices.len() as u64;
        drop(roots);
        let nmv_tris: Vec<u32> = if nmv_vertices.is_empty() {
            Vec::new()
        } else {
            (0..tris.len())
                .filter(|&k| proper[k] && ids(k).iter().any(|v| nmv_vertices.binary_search(v).is_ok()))
                .map(|k| tris[k])
                .collect()
        };
        // Boundary loops: components of the boundary-edge graph.
        let mut ends: Vec<u32> = boundary_ends.iter().flat_map(|&(a, b)| [a, b]).collect();
        ends.sort_unstable();
        ends.dedup();
        let mut parent: Vec<u32> = (0..ends.len() as u32).collect();
        let at = |v: u32| ends.binary_search(&v).unwrap() as u32;
        for &(a, b) in &boundary_ends {
            union(&mut parent, at(a), at(b));
        }
        let boundary_loops = (0..parent.len() as u32).filter(|&i| find(&mut parent, i) == i).count() as u64;

        let volume = closed.then(|| {
            let o = mesh.positions[mesh.triangles[tris[0] as usize][0] as usize];
            let chunks: Vec<f64> = tris
                .par_chunks(VOLUME_CHUNK)
                .enumerate()
                .map(|(c, chunk)| {
                    let mut s = 0.0;
                    for (x, _) in chunk.iter().enumerate() {
                        let k = c * VOLUME_CHUNK + x;
                        if proper[k] {
                            let [a, b, cc] = pos(k);
                            s += (a - o).dot((b - o).cross(cc - o));
                        }
                    }
                    s
                })
                .collect();
            chunks.iter().sum::<f64>() / 6.0
        });
        Health {
            closed,
            duplicate_faces,
            zero_area_triangles,
            non_manifold_edges: Finding::of(n_nm, nm, first_n),
            non_manifold_vertices: Finding::of(n_nmv, nmv_tris, first_n),
            boundary_edges: Finding::of(n_boundary, boundary, first_n),
            boundary_loops,
            inconsistent_winding_edges: Finding::of(n_wind, wind, first_n),
            volume,
        }
    }
}

/// Random small parts with every kind of finding: a grid of vertices (so that faces share
/// vertices, edges and whole vertex sets), triangles over random vertex triples, some with a
/// repeated vertex, some duplicated in either winding, some collinear.
fn messy_mesh() -> impl proptest::strategy::Strategy<Value = Mesh> {
    use proptest::prelude::*;
    (prop::collection::vec((0u32..12, 0u32..12, 0u32..12), 1..60), prop::collection::vec(0u32..4, 0..8))
        .prop_map(|(tris, flips)| {
            let mut m = one(|_| {});
            // 12 vertices: a 2 x 2 x 3 block, with three collinear along z.
            for i in 0..12u32 {
                m.positions.push(DVec3::new((i % 2) as f64, (i / 2 % 2) as f64, (i / 4) as f64));
            }
            for &(a, b, c) in &tris {
                m.triangles.push([a, b, c]);
            }
            for &f in &flips {
                if let Some(&t) = m.triangles.get(f as usize) {
                    m.triangles.push([t[0], t[2], t[1]]);
                }
            }
            m.tri_object = vec![0; m.triangles.len()];
            m
        })
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]
    /// The vertex-group pass gives exactly what the global edge sort gave, on whole meshes and
    /// on a sparse part of them.
    #[test]
    fn vertex_groups_match_the_edge_sort(m in messy_mesh(), first_n in 1usize..12) {
        let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
        let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
        let odd: Vec<u32> = all.iter().copied().filter(|t| t % 3 != 1).collect();
        for part in [&all, &odd] {
            let want = by_edge_sort::health_by_edge_sort(&m, &merged, part, first_n);
            proptest::prop_assert_eq!(health(&m, &merged, part, first_n), want);
        }
    }
}

#[test]
fn the_shared_meshes_match_the_edge_sort() {
    for f in ["stanford-bunny.obj", "fcl_rob.obj", "joined_tetrahedra.obj", "shared.STL", "featuretype.STL"] {
        let Some(path) = crate::load::shared(f) else { continue };
        let (loaded, _) = crate::load::load_path(&path).expect("a test mesh");
        let m = &loaded.mesh;
        let (merged, _) = crate::scene::bodies::merge_vertices(&m.positions);
        let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
        assert_eq!(
            health(m, &merged, &all, 10),
            by_edge_sort::health_by_edge_sort(m, &merged, &all, 10),
            "{f}"
        );
    }
}
