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

/// What rounding under a placement could change in a prepared mesh's topology, and what a
/// local update of it needs.
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
    /// Per triangle: proper in the prepared coordinates.
    proper: Vec<bool>,
    /// How many are.
    proper_count: usize,
    /// Per class of coincident vertices, the triangles using it: `class_tris[class_start[c] ..
    /// class_start[c + 1]]`.
    class_start: Vec<u32>,
    class_tris: Vec<u32>,
    /// Per class (as many as the prepared mesh has), its component (`u32::MAX` when no
    /// triangle uses it).
    class_component: Vec<u32>,
    /// The edges (classes, lower first) of the proper triangles not used exactly twice.
    bad_edges: Vec<(u32, u32)>,
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
        let distinct = prepared_distinct(topo);
        let mut near = Vec::new();
        let mut seen = vec![false; distinct];
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
        let mut proper = vec![false; triangles.len()];
        for (t, tri) in triangles.iter().enumerate() {
            let ids = tri.map(|v| merged[v as usize]);
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                continue;
            }
            let corners = tri.map(|v| positions[v as usize]);
            let h = predicates::height_lower_bound(corners);
            let (h, is_proper) = if h > 0.0 {
                (h, true)
            } else {
                (f64::NEG_INFINITY, !predicates::collinear(corners[0], corners[1], corners[2]))
            };
            proper[t] = is_proper;
            slivers.push((h, t as u32, is_proper));
        }
        slivers.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let proper_count = proper.iter().filter(|&&p| p).count();
        // Triangles by class (a counting sort).
        let mut class_start = vec![0u32; distinct + 1];
        for tri in triangles {
            for &v in tri {
                class_start[merged[v as usize] as usize + 1] += 1;
            }
        }
        for c in 0..distinct {
            class_start[c + 1] += class_start[c];
        }
        let mut fill = class_start.clone();
        let mut class_tris = vec![0u32; class_start[distinct] as usize];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                let c = merged[v as usize] as usize;
                class_tris[fill[c] as usize] = t as u32;
                fill[c] += 1;
            }
        }
        let mut class_component = vec![u32::MAX; distinct];
        for (v, &c) in topo.component_of.iter().enumerate() {
            if c != u32::MAX {
                class_component[merged[v] as usize] = c;
            }
        }
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for (tri, _) in triangles.iter().zip(&proper).filter(|x| *x.1) {
            edges.extend(class_edges(tri.map(|v| merged[v as usize])));
        }
        edges.sort_unstable();
        let bad_edges =
            edges.chunk_by(|x, y| x == y).filter(|run| run.len() != 2).map(|run| run[0]).collect();
        Some(Fragile {
            near,
            separation,
            slivers,
            proper,
            proper_count,
            class_start,
            class_tris,
            class_component,
            bad_edges,
        })
    }

    /// The topology of the placed coordinates `world` (the prepared mesh's `positions` under a
    /// placement whose rounding is `r`, every vertex within `r.delta` of its exact image),
    /// `prepared` the prepared mesh's topology: the prepared one itself when no pair its
    /// rounding could merge is merged and no triangle it could flatten (or unflatten) changed;
    /// otherwise the prepared one updated where they changed it. `None` when the rounding is
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
        let old = &prepared.merged;
        // Every pair of classes whose world coordinates are equal is among these: their exact
        // images are within `2 delta`, so their distance is below what the rounding keeps apart.
        let merges: Vec<(u32, u32)> = self
            .near
            .iter()
            .take_while(|(d, _, _)| !r.keeps_apart(*d))
            .filter(|&&(_, a, b)| vertex_key(&world[a as usize]) == vertex_key(&world[b as usize]))
            .map(|&(_, a, b)| (old[a as usize], old[b as usize]))
            .collect();
        // Triangles whose collinearity the rounding may have changed (decided exactly).
        let flips: Vec<u32> = self
            .slivers
            .iter()
            .take_while(|(h, _, _)| !r.keeps_proper(*h))
            .filter(|&&(_, t, was)| {
                let [a, b, c] = triangles[t as usize].map(|v| world[v as usize]);
                predicates::collinear(a, b, c) == was // proper now differs from before
            })
            .map(|s| s.1)
            .collect();
        if merges.is_empty() && flips.is_empty() {
            return Some(prepared.clone());
        }
        // The merged classes: a union–find over the classes that merge, each group under its
        // lowest (first occurring) class.
        let mut involved: Vec<u32> = merges.iter().flat_map(|&(a, b)| [a, b]).collect();
        involved.sort_unstable();
        involved.dedup();
        let slot = |c: u32| involved.binary_search(&c).ok();
        let mut parent: Vec<u32> = (0..involved.len() as u32).collect();
        for &(a, b) in &merges {
            union(&mut parent, slot(a).unwrap() as u32, slot(b).unwrap() as u32);
        }
        let roots: Vec<u32> =
            (0..involved.len() as u32).map(|i| involved[find(&mut parent, i) as usize]).collect();
        let class = |c: u32| slot(c).map_or(c, |i| roots[i]);
        // Affected triangles: those using a merged class, and the flipped ones; their
        // properness on the world coordinates (exact).
        let mut affected: Vec<u32> = flips.clone();
        for &c in &involved {
            affected.extend_from_slice(self.tris_of(c));
        }
        affected.sort_unstable();
        affected.dedup();
        let now_proper: Vec<bool> = affected
            .iter()
            .map(|&t| {
                let [a, b, c] = triangles[t as usize].map(|v| world[v as usize]);
                !predicates::collinear(a, b, c)
            })
            .collect();
        let proper = |t: u32| affected.binary_search(&t).map_or(self.proper[t as usize], |k| now_proper[k]);
        let proper_count = self.proper_count + now_proper.iter().filter(|&&p| p).count()
            - affected.iter().filter(|&&t| self.proper[t as usize]).count();
        let edges_of = |t: u32| class_edges(triangles[t as usize].map(|v| class(old[v as usize])));
        // Every edge an affected triangle has (or had), in merged classes: its uses are counted
        // again over the triangles of its lower end (those of every class merged into it).
        let mut recount: Vec<(u32, u32)> = affected.iter().flat_map(|&t| edges_of(t)).collect();
        recount.sort_unstable();
        recount.dedup();
        let mut groups: HashMap<u32, Vec<u32>> = HashMap::new();
        for (&c, &root) in involved.iter().zip(&roots) {
            groups.entry(root).or_default().push(c);
        }
        let uses = |e: (u32, u32)| {
            // The classes merged into the lower end (itself alone when it merged with none).
            let of: &[u32] = groups.get(&e.0).map_or(std::slice::from_ref(&e.0), |g| g.as_slice());
            of.iter()
                .flat_map(|&c| self.tris_of(c).iter().copied())
                .filter(|&t| proper(t) && edges_of(t).any(|x| x == e))
                .count()
        };
        // An edge used other than twice before and not recounted keeps its count.
        let closed = proper_count > 0
            && recount.iter().all(|&e| uses(e) == 2)
            && self.bad_edges.iter().all(|&(a, b)| {
                slot(a).is_some() || slot(b).is_some() || recount.binary_search(&(a, b)).is_ok()
            });
        if merges.is_empty() {
            return Some(Arc::new(Topology { closed, ..Topology::clone(prepared) }));
        }
        // Class ids numbered in order of first occurrence: a group keeps its lowest id, the
        // classes absorbed into a lower one are dropped from the numbering.
        // One ascending pass over the classes (`involved` is sorted, a root comes before the
        // classes absorbed into it), then one over the vertices.
        let mut renumber = Vec::with_capacity(self.class_component.len());
        let (mut next, mut k) = (0u32, 0usize);
        for c in 0..self.class_component.len() as u32 {
            let root = if involved.get(k) == Some(&c) {
                k += 1;
                roots[k - 1]
            } else {
                c
            };
            if root == c {
                renumber.push(next);
                next += 1;
            } else {
                renumber.push(renumber[root as usize]);
            }
        }
        let merged: Vec<u32> = old.iter().map(|&c| renumber[c as usize]).collect();
        // Components joined by the merges: a group of components takes the place (and seed) of
        // its first one (the one whose first triangle comes first).
        let comps = prepared.component_seeds.len();
        let mut comp_parent: Vec<u32> = (0..comps as u32).collect();
        let mut joined = false;
        for &(a, b) in &merges {
            let (ca, cb) = (self.class_component[a as usize], self.class_component[b as usize]);
            if ca != u32::MAX && cb != u32::MAX && find(&mut comp_parent, ca) != find(&mut comp_parent, cb) {
                union(&mut comp_parent, ca, cb);
                joined = true;
            }
        }
        if !joined {
            return Some(Arc::new(Topology {
                closed,
                merged,
                component_seeds: prepared.component_seeds.clone(),
                component_of: prepared.component_of.clone(),
            }));
        }
        let mut renumber = vec![u32::MAX; comps];
        let mut component_seeds = Vec::new();
        for k in 0..comps as u32 {
            if find(&mut comp_parent, k) == k {
                renumber[k as usize] = component_seeds.len() as u32;
                component_seeds.push(prepared.component_seeds[k as usize]);
            }
        }
        let component_of = prepared
            .component_of
            .iter()
            .map(|&k| if k == u32::MAX { k } else { renumber[find(&mut comp_parent, k) as usize] })
            .collect();
        Some(Arc::new(Topology { closed, component_seeds, component_of, merged }))
    }

    /// The triangles using class `c` (of the prepared mesh).
    fn tris_of(&self, c: u32) -> &[u32] {
        &self.class_tris[self.class_start[c as usize] as usize..self.class_start[c as usize + 1] as usize]
    }
}

/// The undirected edges (lower class first) of a triangle of classes `ids`, those whose ends
/// differ.
fn class_edges(ids: [u32; 3]) -> impl Iterator<Item = (u32, u32)> {
    (0..3).filter_map(move |k| {
        let (a, b) = (ids[k], ids[(k + 1) % 3]);
        (a != b).then_some((a.min(b), a.max(b)))
    })
}

/// The number of distinct classes of a topology's merged ids (they are numbered from 0).
fn prepared_distinct(t: &Topology) -> usize {
    t.merged.iter().map(|&m| m as usize + 1).max().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BuildOptions;
    use crate::check::containment;
    use crate::prepared::{Mapping, Prepared};
    use crate::scene::mesh::{Mesh, Object};
    use glam::{DMat4, DVec4};
    use std::path::Path;

    /// A box of side `s` at `at` whose top face is written with its own copies of its corners,
    /// each nudged by `nudge` ulps of 1 (a seam: open as written, closed once rounding merges the copies),
    /// plus an exactly collinear triangle on an edge (with its own midpoint vertex) and a sliver
    /// (a triangle 2^-50 from flat).
    fn seamed_box(at: DVec3, s: f64, nudge: f64, out: &mut Mesh) {
        let base = out.positions.len() as u32;
        let base_t = out.triangles.len();
        for i in 0..8 {
            let c = DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
            out.positions.push(at + c * s);
        }
        // The top corners (4..8) again, one ulp up in z or x.
        for i in 4..8 {
            let p = out.positions[base as usize + i];
            let ulps = |x: f64| x + nudge * f64::EPSILON * x.abs().max(1.0);
            let nudged =
                if i % 2 == 0 { DVec3::new(p.x, p.y, ulps(p.z)) } else { DVec3::new(ulps(p.x), p.y, p.z) };
            out.positions.push(nudged);
        }
        // Corner 1 again, one ulp off in x, for one bottom triangle: a seam inside the box's
        // main component.
        let p1 = out.positions[base as usize + 1];
        let copy = out.positions.len() as u32;
        out.positions.push(DVec3::new(p1.x.next_down(), p1.y, p1.z));
        let mid = out.positions.len() as u32;
        out.positions.push(at + DVec3::new(0.5, 0.0, 0.0) * s);
        let apex = out.positions.len() as u32;
        out.positions.push(at + DVec3::new(0.5 * s, s, 2f64.powi(-50)));
        let top = |v: u32| 8 + (v - 4);
        // The top face (triangles 4 and 5) on its own, nudged corners; the sides keep 4..8.
        let mut tris = crate::testing::gen::BOX_TRIANGLES;
        for t in &mut tris[4..6] {
            *t = t.map(top);
        }
        for t in tris {
            out.triangles.push(t.map(|v| base + v));
        }
        out.triangles[base_t + 3][0] = copy;
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
        seamed_box(DVec3::ZERO, 1.0, 4.0, &mut m);
        seamed_box(DVec3::new(3.0, 0.5, -2.0), 0.75, 64.0, &mut m);
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
        // The seam copies are the near pairs (5 per box); the collinear triangles (one per box)
        // are the ones not proper, and come first.
        assert_eq!(fragile.near.len(), 10);
        let flat: Vec<_> = fragile.slivers.iter().filter(|s| !s.2).collect();
        assert_eq!(flat.len(), 2);
        assert!(flat.iter().all(|s| s.0 == f64::NEG_INFINITY));
        let own = prepared.topology().clone();
        assert!(!own.closed);
        let mut next = numbers(7);
        let (mut kept, mut joined, mut merged, mut reshaped) = (0, 0, 0, 0);
        for k in 0..300 {
            let m = if k % 3 == 0 {
                // Quarter turns and powers of two: exact, nothing changes.
                DMat4::from_translation(DVec3::new(next() * 8.0, -4.0, 2.0).floor())
                    * DMat4::from_cols(DVec4::Y, -DVec4::X, DVec4::Z, DVec4::W)
                    * DMat4::from_scale(DVec3::splat(2f64.powi(k % 5 - 2)))
            } else {
                let reach = 10f64.powf(next() * 3.0 - 1.0);
                DMat4::from_translation(DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * reach)
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
            let Mapping::Mapped(map) = &p.laid().tree else { continue };
            let world = p.positions();
            let t = fragile
                .placed(&own, world, &prepared.mesh.triangles, &PlacementRounding::of(map))
                .expect("the rounding of these placements is within the bounds");
            assert_eq!(*t, fresh, "placement {k}");
            if Arc::ptr_eq(&t, &own) {
                kept += 1;
            } else if t.component_seeds != own.component_seeds {
                joined += 1;
            } else if t.merged != own.merged {
                merged += 1;
            } else {
                reshaped += 1;
            }
        }
        assert!(kept > 0 && joined > 0 && merged > 0 && reshaped > 0, "{kept} {joined} {merged} {reshaped}");
    }

    /// With no fragile pair or triangle, every placement keeps the prepared topology; a
    /// rounding beyond the separation bound is left to the full computation.
    #[test]
    fn robust_meshes_keep_the_prepared_topology() {
        let mut m = mesh();
        // Drop the nudged copies' triangles, the collinear ones and the slivers: two open
        // boxes.
        let keep: Vec<usize> =
            (0..m.triangles.len()).filter(|t| !matches!(t % 14, 1 | 2 | 3 | 12 | 13)).collect();
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
