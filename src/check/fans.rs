//! The vertex fans of one part: its corners grouped by exactly merged vertex, built once and
//! read by the health pass ([`crate::check::health`]) and the self-clash walk
//! ([`crate::check::self_clash`]).
//!
//! Vertices get local numbers `0..vertices`, in the order of their merged ids
//! ([`crate::scene::bodies::merge_vertices`]), so two corners have the same local number iff
//! they have the same merged id, and the numbers of a small part of a large mesh stay small.
//! Group `v` lists every corner at vertex `v` as `3k + c` (corner `c` of local triangle `k`, the
//! part's `k`-th triangle), ascending.
//!
//! Built with a counting sort over the merged ids when they span at most 4 per corner (any
//! part that is most of its mesh: one pass to count, one to place; 4 bytes per corner), else
//! a sort of `(id, corner)` keys; both give the same numbers and groups.
//!
//! Each triangle also carries what the float filter proves about its normal
//! ([`PlaneFilter::normal_sign`], exact when given) and whether it is proper (non-zero area,
//! exact).

use crate::geom::predicates::{self as pr, PlaneFilter};
use crate::scene::mesh::Mesh;
use rayon::prelude::*;

/// The fans of one part (see the module docs).
pub struct Fans {
    /// Per local triangle: the local vertex numbers of its corners.
    pub ids: Vec<[u32; 3]>,
    /// Per local triangle: bit 6 = proper; bits `2a, 2a + 1` = the sign of the normal's
    /// component `a` when the filter proves it (01 positive, 10 negative, 00 not proven).
    shape: Vec<u8>,
    starts: Vec<u32>,
    entries: Vec<u32>,
}

const PROPER: u8 = 1 << 6;

impl Fans {
    /// The fans of the part made of triangles `tris` of `mesh`; `merged` gives each vertex of
    /// `mesh` its exact-position id.
    pub fn new(mesh: &Mesh, merged: &[u32], tris: &[u32]) -> Fans {
        let n = tris.len();
        let shape: Vec<u8> = tris
            .par_iter()
            .map(|&t| {
                let p = crate::bvh::triangle(mesh, t);
                let f = PlaneFilter::new(&p);
                let mut bits = 0u8;
                for a in 0..3 {
                    bits |= match f.normal_sign(a) {
                        Some(1) => 1,
                        Some(-1) => 2,
                        _ => 0,
                    } << (2 * a);
                }
                if bits != 0 || f.proper() || !pr::collinear(p[0], p[1], p[2]) {
                    bits |= PROPER;
                }
                bits
            })
            .collect();
        let merged_of = |k: usize| mesh.triangles[tris[k] as usize].map(|v| merged[v as usize]);
        let corners = 3 * n;
        let (lo, hi) = (0..n)
            .into_par_iter()
            .map(|k| {
                let i = merged_of(k);
                (i[0].min(i[1]).min(i[2]), i[0].max(i[1]).max(i[2]))
            })
            .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        if n == 0 || (hi - lo) as usize >= 4 * corners {
            // Sparse ids: sort the corners by id.
            let mut keys: Vec<u64> = (0..n)
                .into_par_iter()
                .flat_map_iter(|k| {
                    let i = merged_of(k);
                    (0..3).map(move |c| (i[c] as u64) << 32 | (3 * k + c) as u64)
                })
                .collect();
            keys.par_sort_unstable();
            let mut ids = vec![[0u32; 3]; n];
            let mut starts = Vec::new();
            for (x, &key) in keys.iter().enumerate() {
                if x == 0 || key >> 32 != keys[x - 1] >> 32 {
                    starts.push(x as u32);
                }
                let e = key as u32 as usize;
                ids[e / 3][e % 3] = starts.len() as u32 - 1;
            }
            starts.push(keys.len() as u32);
            let entries = keys.into_iter().map(|k| k as u32).collect();
            return Fans { ids, shape, starts, entries };
        }
        // Dense ids: count per id, number the ids in use, place the corners.
        let mut local = vec![0u32; (hi - lo) as usize + 1];
        for k in 0..n {
            for v in merged_of(k) {
                local[(v - lo) as usize] += 1;
            }
        }
        let mut starts = Vec::with_capacity(n);
        let mut at = 0u32;
        for c in local.iter_mut() {
            if *c > 0 {
                let count = *c;
                *c = starts.len() as u32;
                starts.push(at);
                at += count;
            }
        }
        starts.push(at);
        let ids: Vec<[u32; 3]> =
            (0..n).into_par_iter().map(|k| merged_of(k).map(|v| local[(v - lo) as usize])).collect();
        drop(local);
        let mut next = starts.clone();
        let mut entries = vec![0u32; corners];
        for (k, t) in ids.iter().enumerate() {
            for (c, &v) in t.iter().enumerate() {
                let slot = &mut next[v as usize];
                entries[*slot as usize] = (3 * k + c) as u32;
                *slot += 1;
            }
        }
        Fans { ids, shape, starts, entries }
    }

    /// Number of vertices (groups).
    pub fn vertices(&self) -> usize {
        self.starts.len() - 1
    }

    /// The corners at vertex `v`, as `3k + c`, ascending.
    #[inline]
    pub fn group(&self, v: usize) -> &[u32] {
        &self.entries[self.starts[v] as usize..self.starts[v + 1] as usize]
    }

    /// Is local triangle `k` proper (non-zero area; exact)?
    #[inline]
    pub fn proper(&self, k: usize) -> bool {
        self.shape[k] & PROPER != 0
    }

    /// The sign of component `axis` of triangle `k`'s normal `(b - a) × (c - a)` when the
    /// filter proved it (exact), else None.
    #[inline]
    pub fn normal_sign(&self, k: usize, axis: usize) -> Option<pr::Sign> {
        match self.shape[k] >> (2 * axis) & 3 {
            1 => Some(1),
            2 => Some(-1),
            _ => None,
        }
    }
}
