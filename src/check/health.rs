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

use crate::narrow::tri_tri::Shape;
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

/// How many triangles go into one chunk of the volume sum (fixed, for determinism).
const VOLUME_CHUNK: usize = 4096;

/// The health of the part made of triangles `tris` of `mesh`; `merged` gives each vertex its
/// exact-position id ([`crate::scene::bodies::merge_vertices`]). Triangle ids in the result are
/// indices into `mesh`.
pub fn health(mesh: &Mesh, merged: &[u32], tris: &[u32], first_n: usize) -> Health {
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

#[cfg(test)]
mod tests;
