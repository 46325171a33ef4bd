//! Mesh health of one part: what is wrong with a surface on its own, before it clashes with
//! anything.
//!
//! Everything is counted on exactly merged vertices (bit-identical positions, +0 = −0:
//! [`crate::scene::bodies::merge_vertices`]), the same identification the self-clash rule uses
//! ([`crate::check::self_clash`]). Edges are those of the *proper* (non-zero-area) triangles, as for
//! `closed` in the two-mesh report ([`crate::check::containment::topology`]): a zero-area triangle
//! bounds nothing, and is reported on its own.
//!
//! * `zero_area_triangles`: exactly collinear (or coincident) vertices ([`crate::narrow::tri_tri::Shape`]).
//! * `duplicate_faces`: a triangle with three distinct vertices whose vertex set is that of an
//!   earlier triangle, in either winding (two coincident opposite-winding faces are one
//!   duplicate). The count is of the later copies; removing them leaves every face once.
//! * `boundary_edges`: edges used by one triangle; `boundary_loops` is the number of connected
//!   components of the graph of boundary edges (a hole is one; two holes meeting at a vertex
//!   count as one).
//! * `non_manifold_edges`: edges used by three or more triangles.
//! * `non_manifold_vertices`: vertices around which the triangles form more than one fan
//!   (joined through edges at that vertex): a bow-tie.
//! * `inconsistent_winding_edges`: edges used by exactly two triangles in the same direction
//!   (their normals disagree across the edge).
//! * `closed`: at least one proper triangle and every edge used exactly twice.
//! * `volume` (closed parts): the signed volume, `Σ (a−o)·((b−o)×(c−o)) / 6` over the proper
//!   triangles with `o` the part's first vertex, summed in f64 in a fixed order (so it is the
//!   same whatever the thread count). Positive when the triangles wind counter-clockwise seen
//!   from outside. It is an f64 value, not an exact sign: a part whose volume is tiny next to
//!   its rounding may get the wrong sign (its `volume` is then near 0 anyway).
//!
//! Each finding has a count and the first triangle ids involved (ascending, at most `first_n`).

use crate::check::fans::Fans;
use crate::scene::bodies::{find, union};
use crate::scene::mesh::Mesh;
use rayon::prelude::*;

/// One kind of finding: how many, and the first triangles involved.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Finding {
    /// How many (triangles, edges or vertices, by kind).
    pub count: u64,
    /// The lowest triangle ids involved, ascending, at most `first_n` of them.
    pub triangles: Vec<u32>,
}

impl Finding {
    fn of(count: u64, mut involved: Vec<u32>, first_n: usize) -> Finding {
        involved.sort_unstable();
        involved.dedup();
        involved.truncate(first_n);
        Finding { count, triangles: involved }
    }
}

/// The health of one part (see the module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Health {
    /// Every edge of the proper triangles used exactly twice, and there is one.
    pub closed: bool,
    /// Faces stored more than once (count: the later copies).
    pub duplicate_faces: Finding,
    /// Zero-area triangles (count: triangles).
    pub zero_area_triangles: Finding,
    /// Edges used by three or more triangles (count: edges).
    pub non_manifold_edges: Finding,
    /// Vertices with more than one fan of triangles (count: vertices).
    pub non_manifold_vertices: Finding,
    /// Edges used by one triangle (count: edges).
    pub boundary_edges: Finding,
    /// Connected components of the boundary edges.
    pub boundary_loops: u64,
    /// Edges used twice in the same direction (count: edges).
    pub inconsistent_winding_edges: Finding,
    /// Signed volume (f64), for closed parts only.
    pub volume: Option<f64>,
}

/// How many vertex groups one parallel task tallies.
const GROUPS_PER_TASK: usize = 1024;

/// How many triangles go into one chunk of the volume sum (fixed, for determinism).
const VOLUME_CHUNK: usize = 4096;

/// What the vertex groups find, summed over groups (counts), with the triangles involved (mesh
/// ids, in no particular order) and scratch space reused from one group to the next.
#[derive(Default)]
struct Tally {
    n_boundary: u64,
    n_nm: u64,
    n_wind: u64,
    n_nmv: u64,
    boundary: Vec<u32>,
    nm: Vec<u32>,
    wind: Vec<u32>,
    nmv: Vec<u32>,
    dup: Vec<u32>,
    /// The two ends of each boundary edge.
    ends: Vec<(u32, u32)>,
    /// Scratch: `other end << 32 | local triangle << 1 | 1 if the triangle runs the edge low to
    /// high` of the edges to higher vertices.
    edges: Vec<u64>,
    /// Scratch: (`other two ids` as `low << 32 | high`, local triangle) of the faces whose
    /// lowest id is here.
    faces: Vec<(u64, u32)>,
    /// Scratch: `other end << 32 | position in the fan` of the proper triangles' edges here
    /// (large fans only).
    joins: Vec<u64>,
    /// Scratch: union–find over the proper triangles of the fan.
    parent: Vec<u32>,
    /// Scratch: the proper triangles of the fan, with their other two vertices.
    fan: Vec<(u32, u32, u32)>,
}

impl Tally {
    fn merge(mut self, mut o: Tally) -> Tally {
        self.n_boundary += o.n_boundary;
        self.n_nm += o.n_nm;
        self.n_wind += o.n_wind;
        self.n_nmv += o.n_nmv;
        self.boundary.append(&mut o.boundary);
        self.nm.append(&mut o.nm);
        self.wind.append(&mut o.wind);
        self.nmv.append(&mut o.nmv);
        self.dup.append(&mut o.dup);
        self.ends.append(&mut o.ends);
        self
    }

    /// Everything about the vertex of one group: the edges to higher vertices (each edge is
    /// met once, at its lower end), the faces whose lowest vertex it is (duplicates), and the
    /// fans of the proper triangles around it (joined through the edges at the vertex).
    fn vertex(&mut self, v: u32, fans: &Fans, tris: &[u32]) {
        let (group, ids) = (fans.group(v as usize), &fans.ids);
        self.edges.clear();
        self.faces.clear();
        self.fan.clear();
        for &e in group {
            let (k, c) = (e / 3, e as usize % 3);
            let t = ids[k as usize];
            let (w1, w2) = (t[(c + 1) % 3], t[(c + 2) % 3]);
            if w1 == v || w2 == v || w1 == w2 {
                continue; // fewer than three distinct vertices: not a face, and no edges
            }
            if v < w1 && v < w2 {
                self.faces.push(((w1.min(w2) as u64) << 32 | w1.max(w2) as u64, k));
            }
            if fans.proper(k as usize) {
                // Edge c runs v → w1 (low to high iff w1 > v), edge c + 2 runs w2 → v.
                let key = |w: u32, up: bool| (w as u64) << 32 | (k as u64) << 1 | up as u64;
                if w1 > v {
                    self.edges.push(key(w1, true));
                }
                if w2 > v {
                    self.edges.push(key(w2, false));
                }
                self.fan.push((k, w1, w2));
            }
        }
        // Duplicates: every later copy of a vertex set (entries come in triangle order).
        if self.faces.len() > 1 {
            self.faces.sort_unstable();
            for run in self.faces.chunk_by(|x, y| x.0 == y.0) {
                self.dup.extend(run[1..].iter().map(|x| tris[x.1 as usize]));
            }
        }
        // Edges to higher vertices, by how many triangles use them.
        small_sort(&mut self.edges);
        let tri = |e: u64| tris[(e as u32 >> 1) as usize];
        for run in self.edges.chunk_by(|x, y| x >> 32 == y >> 32) {
            match run.len() {
                1 => {
                    self.n_boundary += 1;
                    self.boundary.push(tri(run[0]));
                    self.ends.push((v, (run[0] >> 32) as u32));
                }
                2 if run[0] & 1 == run[1] & 1 => {
                    self.n_wind += 1;
                    self.wind.extend(run.iter().map(|&e| tri(e)));
                }
                2 => {}
                _ => {
                    self.n_nm += 1;
                    self.nm.extend(run.iter().map(|&e| tri(e)));
                }
            }
        }
        // Fans: proper triangles sharing an edge at v are in one fan; more than one fan is a
        // bow-tie.
        let m = self.fan.len();
        if m > 1 {
            self.parent.clear();
            self.parent.extend(0..m as u32);
            if m <= SMALL_FAN {
                for i in 0..m {
                    let (_, a1, a2) = self.fan[i];
                    for j in i + 1..m {
                        let (_, b1, b2) = self.fan[j];
                        if a1 == b1 || a1 == b2 || a2 == b1 || a2 == b2 {
                            union(&mut self.parent, i as u32, j as u32);
                        }
                    }
                }
            } else {
                self.joins.clear();
                for (i, &(_, w1, w2)) in self.fan.iter().enumerate() {
                    self.joins.extend([(w1 as u64) << 32 | i as u64, (w2 as u64) << 32 | i as u64]);
                }
                self.joins.sort_unstable();
                for w in self.joins.windows(2) {
                    if w[0] >> 32 == w[1] >> 32 {
                        union(&mut self.parent, w[0] as u32, w[1] as u32);
                    }
                }
            }
            let roots = (0..m as u32).filter(|&i| self.parent[i as usize] == i).count();
            if roots > 1 {
                self.n_nmv += 1;
                self.nmv.extend(self.fan.iter().map(|x| tris[x.0 as usize]));
            }
        }
    }
}

/// Fans up to this many proper triangles are joined by comparing every pair; larger ones by a
/// sort of their edges.
const SMALL_FAN: usize = 16;

/// Sort a short slice by insertion (the edges at one vertex: a handful), a long one by
/// `sort_unstable`.
fn small_sort(v: &mut [u64]) {
    if v.len() > 16 {
        v.sort_unstable();
        return;
    }
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && v[j - 1] > x {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// The health of the part made of triangles `tris` of `mesh`; `merged` gives each vertex its
/// exact-position id ([`crate::scene::bodies::merge_vertices`]). Triangle ids in the result are
/// indices into `mesh`.
///
/// The corners are grouped by vertex ([`Fans`]: a counting sort, 4 bytes per corner); then
/// each vertex, in parallel, settles its own edges to higher vertices, the faces it is the
/// lowest vertex of, and its fans. Nothing is sorted globally but the few triangles a finding
/// lists.
pub fn health(mesh: &Mesh, merged: &[u32], tris: &[u32], first_n: usize) -> Health {
    health_with(mesh, &Fans::new(mesh, merged, tris), tris, first_n)
}

/// [`health`], given the part's fans ([`Fans::new`] over the same triangles).
pub fn health_with(mesh: &Mesh, fans: &Fans, tris: &[u32], first_n: usize) -> Health {
    let pos = |k: usize| crate::bvh::triangle(mesh, tris[k]);
    let proper = |k: usize| fans.proper(k);
    let zero: Vec<u32> = (0..tris.len()).filter(|&k| !proper(k)).map(|k| tris[k]).collect();
    let zero_area_triangles = Finding::of(zero.len() as u64, zero, first_n);
    let chunks = fans.vertices().div_ceil(GROUPS_PER_TASK);
    let mut tally = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut t = Tally::default();
            for v in c * GROUPS_PER_TASK..((c + 1) * GROUPS_PER_TASK).min(fans.vertices()) {
                t.vertex(v as u32, fans, tris);
            }
            t
        })
        .reduce(Tally::default, Tally::merge);
    let any_proper = (0..tris.len()).any(proper);
    let closed = any_proper && tally.n_boundary == 0 && tally.n_nm == 0;
    // Boundary loops: components of the boundary-edge graph.
    let boundary_ends = std::mem::take(&mut tally.ends);
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
                    if proper(k) {
                        let [a, b, cc] = pos(k);
                        s += (a - o).dot((b - o).cross(cc - o));
                    }
                }
                s
            })
            .collect();
        chunks.iter().sum::<f64>() / 6.0
    });
    let dup = std::mem::take(&mut tally.dup);
    Health {
        closed,
        duplicate_faces: Finding::of(dup.len() as u64, dup, first_n),
        zero_area_triangles,
        non_manifold_edges: Finding::of(tally.n_nm, std::mem::take(&mut tally.nm), first_n),
        non_manifold_vertices: Finding::of(tally.n_nmv, std::mem::take(&mut tally.nmv), first_n),
        boundary_edges: Finding::of(tally.n_boundary, std::mem::take(&mut tally.boundary), first_n),
        boundary_loops,
        inconsistent_winding_edges: Finding::of(tally.n_wind, std::mem::take(&mut tally.wind), first_n),
        volume,
    }
}

#[cfg(test)]
mod tests;
