//! The topology ([`containment::topology`]: coincident vertices, closedness, components) of a
//! placed mesh from its prepared mesh's, without the full pass over the world coordinates.
//!
//! A placement moves every vertex by at most its rounding ([`PlacementRounding`]) from the
//! exact affine image. Only two things can then change the topology: two distinct vertices
//! rounded onto one point (a merge), and a triangle whose collinearity changes (a sliver). Both
//! need vertices or heights within a few roundings of zero, so [`Fragile`] lists, once per
//! prepared mesh, the vertex pairs and the triangles close enough to that, each with a lower
//! bound of its distance or heights; a placement decides exactly only the ones its rounding
//! could change ([`Fragile::placed`]), and rebuilds the topology only where a merge or a
//! sliver did change it (usually nowhere: the prepared topology is kept as it is).
//!
//! The result equals [`containment::topology`] of the world mesh exactly, merged ids included:
//! those are numbered in order of first occurrence, so equal coincidence classes give equal
//! ids.
//!
//! [`containment::topology`]: crate::check::containment::topology

use crate::check::containment::Topology;
use crate::geom::predicates::{self, PlacementRounding};
use crate::geom::DVec3;
use crate::scene::bodies::{find, union, vertex_key};
use std::collections::HashMap;
use std::sync::Arc;

/// What rounding under a placement could change in a prepared mesh's topology.
#[derive(Debug, Clone, PartialEq)]
pub struct Fragile {
    /// Pairs of distinct vertices (the first vertex of each class of exactly coincident ones)
    /// nearer than `separation`, with a lower bound of their distance, nearest first.
    pub near: Vec<(f64, u32, u32)>,
    /// At most the distance between any two distinct vertices not in `near`.
    pub separation: f64,
    /// Every triangle with three distinct vertices, with a lower bound of its heights
    /// ([`predicates::height_lower_bound`]; `-inf` when not positive), lowest first, and
    /// whether it is proper (exactly not collinear) in the prepared coordinates.
    pub slivers: Vec<(f64, u32, bool)>,
}

impl Fragile {
    /// The fragile pairs and triangles of `positions` and `triangles`, `topo` their topology.
    /// Distinct vertices are hashed into a grid of cells of side `c` ([`predicates::MARGIN_CELL`]
    /// of the coordinates' scale); pairs in the same or adjacent cells are measured
    /// ([`predicates::distance_lower_bound`]) and kept when below `c / 2`; two points whose cells
    /// are not adjacent differ by more than `c / 2` in some coordinate (the f64 quotient by `c`
    /// is off by a few ulps at most), so `separation` is `c / 2`. `None` when the scale is zero
    /// or not finite.
    pub fn of(positions: &[DVec3], triangles: &[[u32; 3]], topo: &Topology) -> Option<Fragile> {
        let merged = &topo.merged;
        let scale = positions.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
        let cell = scale * predicates::MARGIN_CELL;
        if cell <= 0.0 || !cell.is_finite() {
            return None;
        }
        let separation = cell * 0.5;
        let mut near = Vec::new();
        let mut seen = vec![false; merged.iter().map(|&m| m as usize + 1).max().unwrap_or(0)];
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (v, p) in positions.iter().enumerate() {
            if std::mem::replace(&mut seen[merged[v] as usize], true) {
                continue;
            }
            let key = (*p / cell).floor().to_array().map(|x| x as i64);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(cands) = grid.get(&[key[0] + dx, key[1] + dy, key[2] + dz]) else {
                            continue;
                        };
                        for &q in cands {
                            let d = predicates::distance_lower_bound(*p, positions[q as usize]);
                            if d < separation {
                                near.push((d, q, v as u32));
                            }
                        }
                    }
                }
            }
            grid.entry(key).or_default().push(v as u32);
        }
        near.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        let mut slivers = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            let ids = tri.map(|v| merged[v as usize]);
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                continue;
            }
            let corners = tri.map(|v| positions[v as usize]);
            let h = predicates::height_lower_bound(corners);
            let (h, proper) = if h > 0.0 {
                (h, true)
            } else {
                (f64::NEG_INFINITY, !predicates::collinear(corners[0], corners[1], corners[2]))
            };
            slivers.push((h, t as u32, proper));
        }
        slivers.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        Some(Fragile { near, separation, slivers })
    }

    /// The topology of the placed coordinates `world` (the prepared mesh's `positions` under a
    /// placement whose rounding is `r`, every vertex within `r.delta` of its exact image),
    /// `prepared` the prepared mesh's topology: the prepared one itself when no pair its
    /// rounding could merge is merged and no triangle it could flatten (or unflatten) changed;
    /// otherwise rebuilt from the prepared classes and the changes. `None` when the rounding is
    /// too large for the bounds (then only the full computation can tell).
    pub fn placed(
        &self,
        prepared: &Arc<Topology>,
        world: &[DVec3],
        triangles: &[[u32; 3]],
        r: &PlacementRounding,
    ) -> Option<Arc<Topology>> {
        if !r.keeps_apart(self.separation) {
            return None;
        }
        let merges: Vec<(u32, u32)> = self
            .near
            .iter()
            .take_while(|(d, _, _)| !r.keeps_apart(*d))
            .filter(|&&(_, a, b)| vertex_key(&world[a as usize]) == vertex_key(&world[b as usize]))
            .map(|&(_, a, b)| (a, b))
            .collect();
        // Triangles whose collinearity may differ, with their proper flag on the world
        // coordinates (decided exactly).
        let flips: Vec<(u32, bool)> = self
            .slivers
            .iter()
            .take_while(|(h, _, _)| !r.keeps_proper(*h))
            .filter_map(|&(_, t, was)| {
                let [a, b, c] = triangles[t as usize].map(|v| world[v as usize]);
                let now = !predicates::collinear(a, b, c);
                (now != was).then_some((t, now))
            })
            .collect();
        if merges.is_empty() && flips.is_empty() {
            return Some(prepared.clone());
        }
        if merges.is_empty() {
            // Same classes, so the same components; only the closedness may differ.
            let mut proper = self.prepared_proper(triangles.len());
            for &(t, now) in &flips {
                proper[t as usize] = now;
            }
            let closed = closed(triangles, &prepared.merged, prepared_distinct(prepared), &proper);
            return Some(Arc::new(Topology { closed, ..Topology::clone(prepared) }));
        }
        // Merged classes: the prepared classes joined by the merged pairs, numbered in order of
        // first occurrence (as the full computation numbers them).
        let old = &prepared.merged;
        let old_distinct = prepared_distinct(prepared);
        let mut parent: Vec<u32> = (0..old_distinct as u32).collect();
        for &(a, b) in &merges {
            union(&mut parent, old[a as usize], old[b as usize]);
        }
        let mut renumber = vec![u32::MAX; old_distinct];
        let mut distinct = 0u32;
        let merged: Vec<u32> = old
            .iter()
            .map(|&m| {
                let root = find(&mut parent, m) as usize;
                if renumber[root] == u32::MAX {
                    renumber[root] = distinct;
                    distinct += 1;
                }
                renumber[root]
            })
            .collect();
        // A triangle is proper when its three classes are distinct and it is not collinear: the
        // prepared answer unless it was a sliver the rounding could change (decided above).
        let mut proper = self.prepared_proper(triangles.len());
        for &(t, now) in &flips {
            proper[t as usize] = now;
        }
        for (t, tri) in triangles.iter().enumerate() {
            let ids = tri.map(|v| merged[v as usize]);
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                proper[t] = false;
            }
        }
        Some(Arc::new(build(triangles, world.len(), merged, distinct as usize, &proper)))
    }

    /// Per triangle, proper in the prepared coordinates.
    fn prepared_proper(&self, n: usize) -> Vec<bool> {
        let mut proper = vec![false; n];
        for &(_, t, p) in &self.slivers {
            proper[t as usize] = p;
        }
        proper
    }
}

/// The number of distinct classes of a topology's merged ids (they are numbered from 0).
fn prepared_distinct(t: &Topology) -> usize {
    t.merged.iter().map(|&m| m as usize + 1).max().unwrap_or(0)
}

/// Closed: some proper triangle, and every undirected edge (of merged ids) of the proper
/// triangles used exactly twice.
fn closed(triangles: &[[u32; 3]], merged: &[u32], distinct: usize, proper: &[bool]) -> bool {
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * triangles.len());
    for (tri, _) in triangles.iter().zip(proper).filter(|x| *x.1) {
        let v = tri.map(|i| merged[i as usize]);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b)));
        }
    }
    debug_assert!(edges.iter().all(|e| (e.1 as usize) < distinct));
    edges.sort_unstable();
    !edges.is_empty() && edges.chunk_by(|x, y| x == y).all(|run| run.len() == 2)
}

/// The topology of a mesh (`triangles` over `vertex_count` vertices) from its coincidence
/// classes `merged` (`distinct` of them, numbered in order of first occurrence) and each
/// triangle's properness: the closedness and components as [`containment::topology`] finds
/// them (components by a union–find over all triangles, each seeded by its first vertex in
/// triangle order).
///
/// [`containment::topology`]: crate::check::containment::topology
pub fn build(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    merged: Vec<u32>,
    distinct: usize,
    proper: &[bool],
) -> Topology {
    let closed = closed(triangles, &merged, distinct, proper);
    let mut parent: Vec<u32> = (0..distinct as u32).collect();
    for tri in triangles {
        let v = tri.map(|i| merged[i as usize]);
        union(&mut parent, v[0], v[1]);
        union(&mut parent, v[1], v[2]);
    }
    let mut comp_of_root = vec![u32::MAX; distinct];
    let mut component_seeds = Vec::new();
    let mut used = vec![false; vertex_count];
    for tri in triangles {
        let r = find(&mut parent, merged[tri[0] as usize]) as usize;
        if comp_of_root[r] == u32::MAX {
            comp_of_root[r] = component_seeds.len() as u32;
            component_seeds.push(tri[0]);
        }
        for &v in tri {
            used[v as usize] = true;
        }
    }
    let component_of = (0..vertex_count)
        .map(|v| if used[v] { comp_of_root[find(&mut parent, merged[v]) as usize] } else { u32::MAX })
        .collect();
    Topology { closed, component_seeds, component_of, merged }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::check::containment;
    use crate::prepared::{Mapping, Prepared};
    use crate::scene::mesh::{Mesh, Object};
    use glam::DMat4;
    use std::path::Path;

    /// A box of side `s` at `at` whose top face is written with its own copies of its corners,
    /// each nudged by one ulp (a seam: open as written, closed once rounding merges the copies),
    /// plus an exactly collinear triangle on an edge (with its own midpoint vertex) and a sliver
    /// (a triangle 2^-50 from flat).
    fn seamed_box(at: DVec3, s: f64, out: &mut Mesh) {
        let base = out.positions.len() as u32;
        for i in 0..8 {
            let c = DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
            out.positions.push(at + c * s);
        }
        // The top corners (4..8) again, one ulp up in z or x.
        for i in 4..8 {
            let p = out.positions[base as usize + i];
            let nudged = if i % 2 == 0 {
                DVec3::new(p.x, p.y, p.z.next_up())
            } else {
                DVec3::new(p.x.next_up(), p.y, p.z)
            };
            out.positions.push(nudged);
        }
        let mid = out.positions.len() as u32;
        out.positions.push(at + DVec3::new(0.5, 0.0, 0.0) * s);
        let apex = out.positions.len() as u32;
        out.positions.push(at + DVec3::new(0.5 * s, s, 2f64.powi(-50)));
        let top = |v: u32| 8 + (v - 4);
        let tris: [[u32; 3]; 12] = [
            [0, 2, 1],
            [1, 2, 3],
            [top(4), top(5), top(6)],
            [top(5), top(7), top(6)],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        for t in tris {
            out.triangles.push(t.map(|v| base + v));
        }
        out.triangles.push([base, base + 1, mid]);
        out.triangles.push([base + 2, base + 3, apex]);
        out.tri_object.resize(out.triangles.len(), 0);
    }

    fn mesh() -> Mesh {
        let mut m = Mesh {
            positions: Vec::new(),
            triangles: Vec::new(),
            tri_object: Vec::new(),
            objects: vec![Object { name: "seams".into(), ..Default::default() }],
        };
        seamed_box(DVec3::ZERO, 1.0, &mut m);
        seamed_box(DVec3::new(3.0, 0.5, -2.0), 0.75, &mut m);
        m
    }

    /// A deterministic sequence of numbers in [0, 1).
    fn numbers(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Under rotations, scalings and translations, the topology taken from the prepared mesh
    /// (kept, or corrected where rounding merged the seam copies or changed a triangle's
    /// collinearity) is exactly the one found on the world coordinates; the placements cover
    /// all three outcomes.
    #[test]
    fn placed_topology_equals_the_world_meshes() {
        let m = mesh();
        let prepared = Arc::new(Prepared::new(Path::new("<seams>"), m, BuildOptions::default()).unwrap());
        let fragile = prepared.fragile().unwrap();
        // The seam copies are the near pairs (4 per box); the collinear triangles (one per box)
        // are the ones not proper, and come first.
        assert_eq!(fragile.near.len(), 8);
        let flat: Vec<_> = fragile.slivers.iter().filter(|s| !s.2).collect();
        assert_eq!(flat.len(), 2);
        assert!(flat.iter().all(|s| s.0 == f64::NEG_INFINITY));
        let own = prepared.topology().clone();
        assert!(!own.closed);
        let mut next = numbers(7);
        let (mut kept, mut merged, mut reshaped) = (0, 0, 0);
        for k in 0..300 {
            let m = if k % 3 == 0 {
                // Quarter turns and powers of two: exact, nothing changes.
                DMat4::from_translation(DVec3::new(next() * 8.0, -4.0, 2.0).floor())
                    * DMat4::from_rotation_z(std::f64::consts::FRAC_PI_2 * (k % 4) as f64)
                    * DMat4::from_scale(DVec3::splat(2f64.powi(k % 5 - 2)))
            } else {
                DMat4::from_translation(DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 200.0)
                    * DMat4::from_rotation_x(next() * 6.3)
                    * DMat4::from_rotation_y(next() * 6.3)
                    * DMat4::from_rotation_z(next() * 6.3)
                    * DMat4::from_scale(DVec3::new(
                        0.5 + next() * 3.0,
                        0.5 + next() * 3.0,
                        0.5 + next() * 3.0,
                    ))
            };
            let p = prepared.place(m).unwrap();
            let fresh = containment::topology(&p.mesh());
            assert_eq!(*p.topology(), fresh, "placement {k}");
            let Mapping::Mapped(map) = &p.tree else { continue };
            let world = p.world.as_deref().unwrap();
            let t = fragile
                .placed(&own, world, &prepared.mesh.triangles, &PlacementRounding::of(map))
                .expect("the rounding of these placements is within the bounds");
            assert_eq!(*t, fresh, "placement {k}");
            if Arc::ptr_eq(&t, &own) {
                kept += 1;
            } else if t.merged != own.merged {
                merged += 1;
            } else {
                reshaped += 1;
            }
        }
        assert!(kept > 0 && merged > 0 && reshaped > 0, "{kept} {merged} {reshaped}");
    }

    /// With no fragile pair or triangle, every placement keeps the prepared topology; a
    /// rounding beyond the separation bound is left to the full computation.
    #[test]
    fn robust_meshes_keep_the_prepared_topology() {
        let mut m = mesh();
        // Drop the nudged copies' triangles, the collinear ones and the slivers: two closed
        // boxes less their tops.
        let keep: Vec<usize> =
            (0..m.triangles.len()).filter(|t| !matches!(t % 14, 2 | 3 | 12 | 13)).collect();
        m.triangles = keep.iter().map(|&t| m.triangles[t]).collect();
        m.tri_object = vec![0; m.triangles.len()];
        let positions = m.positions.clone();
        let own = Arc::new(containment::topology(&m));
        let fragile = Fragile::of(&m.positions, &m.triangles, &own).unwrap();
        assert!(fragile.slivers.iter().all(|s| s.0 > 0.0 && s.2));
        let r = PlacementRounding { low: 1.0, high: 1.0, delta: 1e-12 };
        let t = fragile.placed(&own, &positions, &m.triangles, &r).unwrap();
        assert!(Arc::ptr_eq(&t, &own));
        let coarse = PlacementRounding { low: 1.0, high: 1.0, delta: fragile.separation };
        assert!(fragile.placed(&own, &positions, &m.triangles, &coarse).is_none());
    }
}
