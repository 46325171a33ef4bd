//! Is one part hidden inside the other? A closed part fully inside another touches no triangle
//! of it, so the pair search alone says "clear"; this module decides it.
//!
//! * [`topology`]: exactly coincident vertices are merged; a mesh is *closed* when every edge of
//!   its non-degenerate triangles is shared by exactly two of them; connected components are
//!   found with a union–find over the merged vertices.
//! * [`point_in_closed_mesh`]: parity of the crossings of a segment (a "ray" from the point to
//!   beyond the container's box) with the container's triangles, every crossing decided by exact
//!   `orient3d` signs (a segment–triangle test in the style of Möller–Trumbore, but with exact
//!   predicates instead of floating-point barycentrics). A ray that meets an edge or a vertex
//!   exactly, or lies in a triangle's plane, is discarded and another direction is tried, so the
//!   parity is always taken on a generic ray. For a closed (mod-2) surface the parity is the
//!   "odd" inside rule; for a surface that does not intersect itself it is plain inside.
//!
//! Called only when no pair of triangles meets: then each connected component of one mesh is
//! entirely inside or entirely outside the other, so one vertex per component decides.

use crate::bvh::{self, Bvh};
use crate::geom::predicates as pr;
use crate::geom::{Aabb, DVec3};
use crate::mesh::Mesh;
use crate::tri_tri::Shape;
use std::collections::HashMap;

/// Closedness and components of one mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topology {
    /// Every edge of every non-degenerate triangle is shared by exactly two of them (after
    /// merging exactly coincident vertices).
    pub closed: bool,
    /// One vertex index per connected component (the first, in triangle order).
    pub component_seeds: Vec<u32>,
}

/// Merge exactly coincident vertices (+0 and −0 are the same point) and count edge uses.
pub fn topology(mesh: &Mesh) -> Topology {
    let mut ids: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let merged: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect();
    let mut parent: Vec<u32> = (0..ids.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.triangles.len() * 3 / 2);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let v = tri.map(|i| merged[i as usize]);
        for k in 0..3 {
            let (a, b) = (find(&mut parent, v[k]), find(&mut parent, v[(k + 1) % 3]));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
        if Shape::of(&bvh::triangle(mesh, t as u32)).is_degenerate() {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let closed = !edges.is_empty() && edges.values().all(|&c| c == 2);
    // The first vertex (in triangle order) of each component.
    let mut seen = vec![false; parent.len()];
    let mut component_seeds = Vec::new();
    for tri in &mesh.triangles {
        let v = tri[0];
        let root = find(&mut parent, merged[v as usize]);
        if !std::mem::replace(&mut seen[root as usize], true) {
            component_seeds.push(v);
        }
    }
    Topology { closed, component_seeds }
}

/// Ray directions tried in turn: nearly axis-aligned (so the segment's box stays thin and the
/// exact box test culls well) with irrational-looking tilts so that meeting an edge exactly is
/// unlikely; fixed, so the answer is deterministic.
const DIRECTIONS: [[f64; 3]; 12] = [
    [1.0, 0.013_732_1, 0.029_113_7],
    [-1.0, 0.021_557_3, -0.017_904_1],
    [0.019_364_9, 1.0, 0.011_243_3],
    [-0.027_718_9, -1.0, 0.015_521_7],
    [0.012_659_3, 0.023_401_9, 1.0],
    [-0.018_237_1, 0.016_633_9, -1.0],
    [1.0, -0.031_415_9, 0.027_182_8],
    [0.033_166_2, 1.0, -0.022_360_7],
    [-0.024_494_9, 0.028_284_3, 1.0],
    [1.0, 0.141_421_4, -0.173_205_1],
    [0.223_606_8, -1.0, 0.264_575_1],
    [-0.316_227_8, 0.331_662_5, -1.0],
];

/// The outcome of one point query.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inside {
    /// Inside (odd number of crossings).
    Yes,
    /// Outside.
    No,
    /// Every direction tried met an edge or vertex exactly.
    Undecided,
}

/// Is `p` inside the closed mesh `m` (with tree `t`)? `p` must not lie on `m`'s surface.
pub fn point_in_closed_mesh(p: DVec3, m: &Mesh, t: &Bvh) -> Inside {
    let bounds = t.bounds();
    if !bounds.contains(&Aabb { min: p, max: p }) {
        return Inside::No;
    }
    // Long enough to leave the box from anywhere inside it along any tried direction.
    let reach = bounds.extent().length() * 2.0 + 1.0;
    'dir: for d in DIRECTIONS {
        let q = p + DVec3::from(d) * reach;
        let seg = Aabb { min: p.min(q), max: p.max(q) };
        let mut crossings = 0usize;
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &t.nodes[i as usize];
            if !node.bounds.overlaps(&seg) {
                continue;
            }
            if !node.is_leaf() {
                stack.push(node.a);
                stack.push(i + 1);
                continue;
            }
            for &tri in t.leaf_prims(node) {
                let [a, b, c] = bvh::triangle(m, tri);
                match segment_crosses(p, q, a, b, c) {
                    Crossing::No => {}
                    Crossing::Yes => crossings += 1,
                    Crossing::Degenerate => continue 'dir,
                }
            }
        }
        return if crossings % 2 == 1 { Inside::Yes } else { Inside::No };
    }
    Inside::Undecided
}

enum Crossing {
    No,
    Yes,
    /// Through an edge or vertex, or in the plane: try another ray.
    Degenerate,
}

fn segment_crosses(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Crossing {
    if pr::collinear(a, b, c) {
        return Crossing::No; // zero area: not part of the surface a ray can cross
    }
    let sp = pr::orient3d(a, b, c, p);
    let sq = pr::orient3d(a, b, c, q);
    if sp == 0 && sq == 0 {
        // The ray lies in the triangle's plane: it may graze it; do not count, retry.
        let box_ = Aabb::of_triangle(&[a, b, c]);
        let seg = Aabb { min: p.min(q), max: p.max(q) };
        return if box_.overlaps(&seg) { Crossing::Degenerate } else { Crossing::No };
    }
    if sp * sq > 0 {
        return Crossing::No;
    }
    // p is not on the surface (no pair meets), and q is outside the box of every triangle, so
    // a zero sign means the segment only touches the plane outside the triangle.
    if sp == 0 || sq == 0 {
        return Crossing::No;
    }
    let s = [pr::orient3d(p, q, a, b), pr::orient3d(p, q, b, c), pr::orient3d(p, q, c, a)];
    if s.iter().all(|&v| v > 0) || s.iter().all(|&v| v < 0) {
        Crossing::Yes
    } else if s.iter().all(|&v| v >= 0) || s.iter().all(|&v| v <= 0) {
        Crossing::Degenerate
    } else {
        Crossing::No
    }
}

/// Where one mesh sits relative to the other, when no triangles meet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Containment {
    /// Neither inside the other.
    None,
    /// Every component of A lies inside B.
    AInB,
    /// Every component of B lies inside A.
    BInA,
    /// Some components of A lie inside B, others outside.
    APartlyInB,
    /// Some components of B lie inside A, others outside.
    BPartlyInA,
    /// Could not decide, with the reason.
    Undecided(String),
}

impl Containment {
    /// Name in the report (`None` → null).
    pub fn name(&self) -> Option<&'static str> {
        Some(match self {
            Containment::None => return None,
            Containment::AInB => "a_in_b",
            Containment::BInA => "b_in_a",
            Containment::APartlyInB => "a_partly_in_b",
            Containment::BPartlyInA => "b_partly_in_a",
            Containment::Undecided(_) => "undecided",
        })
    }

    /// Is this an interference (a clash)?
    pub fn is_clash(&self) -> bool {
        !matches!(self, Containment::None | Containment::Undecided(_))
    }
}

/// One direction of [`decide`].
enum OneWay {
    /// (components inside, components in all).
    Counts(usize, usize),
    Undecided(String),
}

/// Which components of `inner` lie inside `outer`?
fn one_way(inner: &Mesh, it: &Topology, outer: &Mesh, ot: &Bvh, otopo: &Topology, name: &str) -> OneWay {
    let n = it.component_seeds.len();
    let ib = Aabb::of_points(&inner.positions);
    if !ot.bounds().overlaps(&ib) {
        return OneWay::Counts(0, n);
    }
    if !otopo.closed {
        // Inside an open surface is undefined; it only matters when the box allows it.
        return if ot.bounds().contains(&ib) {
            OneWay::Undecided(format!(
                "{name} is not closed, so whether the other part lies inside it is undefined"
            ))
        } else {
            OneWay::Counts(0, n)
        };
    }
    let mut inside = 0;
    for &v in &it.component_seeds {
        match point_in_closed_mesh(inner.positions[v as usize], outer, ot) {
            Inside::Yes => inside += 1,
            Inside::No => {}
            Inside::Undecided => {
                return OneWay::Undecided(format!("every ray from vertex {v} met an edge of {name} exactly"))
            }
        }
    }
    OneWay::Counts(inside, n)
}

/// Decide containment both ways for two meshes with no meeting triangles.
pub fn decide(a: &Mesh, ta: &Bvh, topo_a: &Topology, b: &Mesh, tb: &Bvh, topo_b: &Topology) -> Containment {
    let ab = one_way(a, topo_a, b, tb, topo_b, "b");
    let ba = one_way(b, topo_b, a, ta, topo_a, "a");
    match (ab, ba) {
        (OneWay::Counts(i, n), _) if i > 0 && i == n => Containment::AInB,
        (_, OneWay::Counts(i, n)) if i > 0 && i == n => Containment::BInA,
        (OneWay::Counts(i, _), _) if i > 0 => Containment::APartlyInB,
        (_, OneWay::Counts(i, _)) if i > 0 => Containment::BPartlyInA,
        (OneWay::Undecided(e), _) | (_, OneWay::Undecided(e)) => Containment::Undecided(e),
        _ => Containment::None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::mesh::Object;

    /// An axis-aligned box as 12 triangles, outward-facing.
    pub(crate) fn cube(min: DVec3, max: DVec3) -> Mesh {
        let p = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        };
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut triangles = Vec::new();
        for q in quads {
            triangles.push([q[0], q[1], q[2]]);
            triangles.push([q[0], q[2], q[3]]);
        }
        Mesh {
            positions: (0..8).map(p).collect(),
            triangles,
            tri_object: vec![0; 12],
            objects: vec![Object { name: "cube".into(), ..Default::default() }],
        }
    }

    fn inside(p: DVec3, m: &Mesh) -> Inside {
        point_in_closed_mesh(p, m, &Bvh::build(m, BuildOptions::default()))
    }

    #[test]
    fn cube_is_closed_and_one_component() {
        let c = cube(DVec3::ZERO, DVec3::ONE);
        let t = topology(&c);
        assert!(t.closed);
        assert_eq!(t.component_seeds.len(), 1);
        let mut open = c.clone();
        open.triangles.pop();
        open.tri_object.pop();
        assert!(!topology(&open).closed);
    }

    #[test]
    fn points_inside_outside_and_on_axis_aligned_edges_lines() {
        let c = cube(DVec3::ZERO, DVec3::ONE);
        assert_eq!(inside(DVec3::splat(0.5), &c), Inside::Yes);
        assert_eq!(inside(DVec3::new(0.5, 0.5, 1.5), &c), Inside::No);
        assert_eq!(inside(DVec3::new(-0.5, 0.5, 0.5), &c), Inside::No);
        // On the line of a face diagonal (rays along +x from here would hit the diagonal edge).
        assert_eq!(inside(DVec3::new(0.25, 0.25, 0.25), &c), Inside::Yes);
        assert_eq!(inside(DVec3::new(0.5, 0.0 + 1e-300, 0.5), &c), Inside::Yes);
        // Far from the origin.
        let f = cube(DVec3::splat(1e8), DVec3::splat(1e8 + 1.0));
        assert_eq!(inside(DVec3::splat(1e8 + 0.5), &f), Inside::Yes);
    }

    #[test]
    fn box_in_box_both_ways() {
        let outer = cube(DVec3::ZERO, DVec3::splat(10.0));
        let inner = cube(DVec3::splat(4.0), DVec3::splat(5.0));
        let (to, ti) =
            (Bvh::build(&outer, BuildOptions::default()), Bvh::build(&inner, BuildOptions::default()));
        let (po, pi) = (topology(&outer), topology(&inner));
        assert_eq!(decide(&inner, &ti, &pi, &outer, &to, &po), Containment::AInB);
        assert_eq!(decide(&outer, &to, &po, &inner, &ti, &pi), Containment::BInA);
        let apart = cube(DVec3::splat(20.0), DVec3::splat(21.0));
        let ta = Bvh::build(&apart, BuildOptions::default());
        assert_eq!(decide(&apart, &ta, &topology(&apart), &outer, &to, &po), Containment::None);
    }
}
