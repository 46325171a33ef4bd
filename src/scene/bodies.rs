//! Split objects into their connected bodies.
//!
//! One STL `solid` (or OBJ group, or glTF mesh) often holds several separate bodies: a CAD
//! export of a sub-assembly, or two cubes that touch along one edge (`shared.STL`). With
//! `--split-bodies` each object is split into *bodies*: triangles connected through
//! **manifold edges**, i.e. edges (between exactly coincident vertices) used by exactly two
//! triangles of the object. An edge used by one triangle is a border; an edge used by three or
//! more (two bodies meeting along an edge) or a shared vertex alone does not join bodies, so
//! bodies that merely touch stay apart — their contact is then reported as a clash finding like
//! any other part pair.
//!
//! Pieces cut off by non-manifold edges that are not closed by themselves (the faces of two
//! bodies glued face to face with the same triangulation) are joined back through shared edges,
//! so such bodies stay one body rather than shattering into loose triangles.
//!
//! An object with one body keeps its name; otherwise its bodies are named `name/body1`,
//! `name/body2`, … in order of their first triangle in the file. Triangle order is unchanged;
//! only `tri_object` and `objects` are rewritten. Split glTF instances lose their `gltf_mesh`
//! link (the bodies are no longer whole instances of that mesh).

use crate::scene::mesh::{Mesh, Object};
use glam::DVec3;
use rayon::prelude::*;

/// Exactly-coincident-vertex ids: for each position, the index of its distinct value (+0 and
/// −0 are the same point), and the number of distinct values. Sort-based and parallel.
pub fn merge_vertices(positions: &[DVec3]) -> (Vec<u32>, usize) {
    let key = vertex_key;
    // Keys stored beside their index, so the sort compares contiguous memory instead of
    // chasing each index into `positions` (3x fewer cache misses on large meshes).
    let mut order: Vec<([u64; 3], u32)> =
        positions.par_iter().enumerate().map(|(i, p)| (key(p), i as u32)).collect();
    order.par_sort_unstable();
    let mut merged = vec![0u32; positions.len()];
    let mut next = 0u32;
    for (k, &(key, i)) in order.iter().enumerate() {
        if k > 0 && order[k - 1].0 != key {
            next += 1;
        }
        merged[i as usize] = next;
    }
    let distinct = if order.is_empty() { 0 } else { next as usize + 1 };
    (merged, distinct)
}

/// Exactly-coincident-vertex ids numbered in order of first occurrence (the first position
/// gets 0, the next position with a new value 1, …), and the number of distinct values. The
/// same classes as [`merge_vertices`] (whose ids follow the sorted bit patterns instead), found
/// with one open-addressing hash table: one pass over the positions, no sort.
pub fn merge_vertices_in_order(positions: &[DVec3]) -> (Vec<u32>, usize) {
    let n = positions.len();
    // At most half full. A slot holds (hash tag << 32 | position index + 1); 0 is empty.
    let bits = (usize::BITS - (2 * n).max(16).leading_zeros()).min(40);
    let mask = (1usize << bits) - 1;
    let mut table = vec![0u64; 1 << bits];
    let mut merged = Vec::with_capacity(n);
    let mut next = 0u32;
    for (i, p) in positions.iter().enumerate() {
        let key = vertex_key(p);
        let h = hash_key(&key);
        let tag = h >> 32;
        let mut slot = (h as usize) & mask;
        let id = loop {
            let s = table[slot];
            if s == 0 {
                table[slot] = tag << 32 | (i as u64 + 1);
                next += 1;
                break next - 1;
            }
            if s >> 32 == tag {
                let j = (s as u32 - 1) as usize;
                if vertex_key(&positions[j]) == key {
                    break merged[j];
                }
            }
            slot = (slot + 1) & mask;
        };
        merged.push(id);
    }
    (merged, next as usize)
}

/// A 64-bit mix of a vertex key (high half: the tag [`merge_vertices_in_order`] compares
/// first; low bits: the slot).
fn hash_key(k: &[u64; 3]) -> u64 {
    const M: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut h = k[0].wrapping_mul(M);
    h = (h.rotate_left(29) ^ k[1]).wrapping_mul(M);
    h = (h.rotate_left(29) ^ k[2]).wrapping_mul(M);
    h ^ (h >> 31)
}

/// The exact identity of a position: its coordinates' bit patterns, −0 taken as +0.
pub fn vertex_key(p: &DVec3) -> [u64; 3] {
    [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits)
}

/// Union–find over ids `0..parent.len()` (start with `parent[i] = i`): the root of `x`, halving
/// the path on the way.
pub fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

/// Join the sets of `a` and `b`. The smaller root becomes the root, so every root is the
/// smallest id of its set (callers number sets in order of first member by that).
pub fn union(parent: &mut [u32], a: u32, b: u32) {
    let (a, b) = (find(parent, a), find(parent, b));
    if a != b {
        parent[a.max(b) as usize] = a.min(b);
    }
}

/// For each triangle, its body within its object: (object, body number from 0 in order of the
/// body's first triangle).
pub fn bodies(mesh: &Mesh) -> Vec<u32> {
    let (merged, _) = merge_vertices(&mesh.positions);
    let n = mesh.triangles.len();
    // Undirected edges keyed by (object, lo, hi), with the triangle that uses them.
    let mut edges: Vec<(u32, u32, u32, u32)> = Vec::with_capacity(n * 3);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let v = tri.map(|i| merged[i as usize]);
        let o = mesh.tri_object[t];
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            if a != b {
                edges.push((o, a.min(b), a.max(b), t as u32));
            }
        }
    }
    edges.par_sort_unstable();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for run in edges.chunk_by(|x, y| (x.0, x.1, x.2) == (y.0, y.1, y.2)) {
        // A triangle may use the same edge twice (a degenerate one); count distinct triangles.
        if let [x, y] = run {
            if x.3 != y.3 {
                union(&mut parent, x.3, y.3);
            }
        }
    }
    // Second pass: components that are not closed by themselves (some edge of theirs is not
    // used exactly twice within the component) are fragments of a body cut off by non-manifold
    // edges — faces glued to another body with the same triangulation, say. Fragments that
    // share an edge are joined, so such a pair of bodies stays one body instead of shattering.
    let root: Vec<u32> = (0..n as u32).map(|t| find(&mut parent, t)).collect();
    let mut by_comp: Vec<(u32, u32, u32)> = edges.iter().map(|e| (root[e.3 as usize], e.1, e.2)).collect();
    by_comp.par_sort_unstable();
    let mut open = vec![false; n];
    for run in by_comp.chunk_by(|x, y| x == y) {
        if run.len() != 2 {
            open[run[0].0 as usize] = true;
        }
    }
    for run in edges.chunk_by(|x, y| (x.0, x.1, x.2) == (y.0, y.1, y.2)) {
        let frags: Vec<u32> = run.iter().map(|e| root[e.3 as usize]).filter(|&r| open[r as usize]).collect();
        for w in frags.windows(2) {
            union(&mut parent, w[0], w[1]);
        }
    }
    // Number bodies per object in order of first triangle (the root is the smallest triangle
    // index of its set, so a root is met first in file order).
    let mut body_of_root = vec![u32::MAX; n];
    let mut count = vec![0u32; mesh.objects.len()];
    (0..n)
        .map(|t| {
            let r = find(&mut parent, t as u32) as usize;
            if body_of_root[r] == u32::MAX {
                let o = mesh.tri_object[t] as usize;
                body_of_root[r] = count[o];
                count[o] += 1;
            }
            body_of_root[r]
        })
        .collect()
}

/// Split every object of `mesh` into its bodies (see the module docs). Returns how many objects
/// were split.
pub fn split_bodies(mesh: &mut Mesh) -> usize {
    let body = bodies(mesh);
    let mut per_object = vec![0u32; mesh.objects.len()];
    for (t, &b) in body.iter().enumerate() {
        let o = mesh.tri_object[t] as usize;
        per_object[o] = per_object[o].max(b + 1);
    }
    // New object list: each object, or its bodies in place of it.
    let mut first_new = Vec::with_capacity(mesh.objects.len());
    let mut objects = Vec::with_capacity(mesh.objects.len());
    let mut split = 0;
    for (o, obj) in mesh.objects.iter().enumerate() {
        first_new.push(objects.len() as u32);
        if per_object[o] <= 1 {
            objects.push(obj.clone());
        } else {
            split += 1;
            for k in 0..per_object[o] {
                objects.push(Object {
                    name: format!("{}/body{}", obj.name, k + 1),
                    gltf_mesh: None,
                    ..obj.clone()
                });
            }
        }
    }
    for (t, o) in mesh.tri_object.iter_mut().enumerate() {
        let old = *o as usize;
        *o = first_new[old] + if per_object[old] <= 1 { 0 } else { body[t] };
    }
    mesh.objects = objects;
    split
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed axis-aligned cube as 12 triangles with shared vertex indices, offset by `o`.
    fn cube(m: &mut Mesh, o: DVec3, object: u32) {
        let base = m.positions.len() as u32;
        for i in 0..8 {
            m.positions.push(o + DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64));
        }
        let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
        for f in faces {
            m.triangles.push([f[0], f[1], f[2]].map(|i| base + i));
            m.triangles.push([f[0], f[2], f[3]].map(|i| base + i));
            m.tri_object.extend([object, object]);
        }
    }

    fn one_object(name: &str) -> Mesh {
        Mesh { objects: vec![Object { name: name.into(), ..Default::default() }], ..Default::default() }
    }

    #[test]
    fn cubes_touching_along_an_edge_are_two_bodies() {
        let mut m = one_object("s");
        cube(&mut m, DVec3::ZERO, 0);
        cube(&mut m, DVec3::new(1.0, 1.0, 0.0), 0); // shares the edge x = y = 1
        assert_eq!(split_bodies(&mut m), 1);
        let names: Vec<&str> = m.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["s/body1", "s/body2"]);
        assert_eq!(m.tri_object, [vec![0; 12], vec![1; 12]].concat());
    }

    #[test]
    fn cubes_touching_at_a_vertex_or_face_are_two_bodies_and_one_cube_is_kept() {
        let mut m = one_object("s");
        cube(&mut m, DVec3::ZERO, 0);
        cube(&mut m, DVec3::ONE, 0); // one common vertex
        assert_eq!(split_bodies(&mut m), 1);
        assert_eq!(m.objects.len(), 2);
        // Face on face with the same triangulation: the glued faces' edges are used four times,
        // cutting both faces off their cubes; the fragments are joined, not scattered.
        let mut glued = one_object("g");
        cube(&mut glued, DVec3::ZERO, 0);
        cube(&mut glued, DVec3::new(0.0, 0.0, 1.0), 0);
        cube(&mut glued, DVec3::new(1.0, 0.0, 3.0), 0);
        split_bodies(&mut glued);
        assert_eq!(glued.objects.len(), 2);
        assert_eq!(glued.tri_object, [vec![0; 24], vec![1; 12]].concat());
        let mut kept = one_object("c");
        cube(&mut kept, DVec3::ZERO, 0);
        let before = kept.clone();
        assert_eq!(split_bodies(&mut kept), 0);
        assert_eq!(kept, before);
    }

    #[test]
    fn bodies_follow_file_order_and_other_objects_are_renumbered() {
        // Object 0: cube, object 1: two cubes interleaved triangle by triangle, object 2: cube.
        let mut m = Mesh {
            objects: ["a", "b", "c"].map(|n| Object { name: n.into(), ..Default::default() }).to_vec(),
            ..Default::default()
        };
        cube(&mut m, DVec3::ZERO, 0);
        let mut two = one_object("x");
        cube(&mut two, DVec3::splat(5.0), 0);
        cube(&mut two, DVec3::splat(9.0), 0);
        let base = m.positions.len() as u32;
        m.positions.extend(&two.positions);
        for k in 0..12 {
            for t in [12 + k, k] {
                m.triangles.push(two.triangles[t].map(|i| base + i));
                m.tri_object.push(1);
            }
        }
        cube(&mut m, DVec3::splat(20.0), 2);
        split_bodies(&mut m);
        let names: Vec<&str> = m.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["a", "b/body1", "b/body2", "c"]);
        // The first triangle of object 1 belongs to the cube at 9: it is body1.
        assert_eq!(&m.tri_object[12..16], &[1, 2, 1, 2]);
        assert!(m.tri_object[36..].iter().all(|&o| o == 3));
    }

    #[test]
    fn merged_vertices_identify_signed_zeros() {
        let p = [DVec3::new(0.0, 1.0, 2.0), DVec3::new(-0.0, 1.0, 2.0), DVec3::new(0.0, 1.0, 2.5)];
        let (m, d) = merge_vertices(&p);
        assert_eq!(d, 2);
        assert_eq!(m[0], m[1]);
        assert_ne!(m[0], m[2]);
        assert_eq!(merge_vertices_in_order(&p), (vec![0, 0, 1], 2));
    }

    /// The hash merge finds the classes of the sort merge, numbered by first occurrence, on
    /// points with many exact repeats (few distinct coordinates, signed zeros, a colliding
    /// table's worth of values).
    #[test]
    fn merge_in_order_has_the_classes_of_the_sorted_merge() {
        let mut next = crate::load::test_rng(7);
        for (n, spread) in [(0usize, 1usize), (1, 1), (50, 3), (3000, 5), (20_000, 40)] {
            let coord = |r: usize| match r % 4 {
                0 => 0.0,
                1 => -0.0,
                _ => (r / 4) as f64 * 0.125 - 1.0,
            };
            let p: Vec<DVec3> = (0..n)
                .map(|_| {
                    DVec3::new(coord(next(4 * spread)), coord(next(4 * spread)), coord(next(4 * spread)))
                })
                .collect();
            let (sorted, ds) = merge_vertices(&p);
            let (ordered, dordered) = merge_vertices_in_order(&p);
            assert_eq!(ds, dordered, "{n}");
            let mut first = vec![u32::MAX; ds];
            let mut count = 0u32;
            for i in 0..n {
                let s = sorted[i] as usize;
                if first[s] == u32::MAX {
                    first[s] = count;
                    count += 1;
                }
                assert_eq!(ordered[i], first[s], "{n} {i}");
            }
        }
    }

    #[test]
    fn shipped_stl_files_split_into_their_known_bodies() {
        // SOURCES.md: shared.STL is two unit cubes touching along one edge; counter.unitsmm.STL
        // has 6 connected components; multibody.stl's two solids are one body each.
        for (file, objects, bodies) in
            [("shared.STL", 1, 2), ("counter.unitsmm.STL", 1, 6), ("multibody.stl", 2, 2)]
        {
            let Some(path) = crate::load::shared(file) else { continue };
            let (mut loaded, _) = crate::load::load_path(&path).unwrap();
            assert_eq!(loaded.mesh.objects.len(), objects, "{file}");
            split_bodies(&mut loaded.mesh);
            assert_eq!(loaded.mesh.objects.len(), bodies, "{file}");
            if file == "shared.STL" {
                assert_eq!(loaded.mesh.tri_object.iter().filter(|&&o| o == 0).count(), 12);
            }
        }
    }
}
