//! A tree that builds only the nodes a walk opens.
//!
//! Up front, one cheap pass orders every triangle along a Morton curve (the centres of the
//! triangles' boxes quantised to a 1024³ grid over the mesh's box, radix-sorted) and splits the
//! order at the highest differing bit of the codes (a spatial median per level, as LBVH does)
//! until each range holds at most [`CELL_MAX`] triangles. Those ranges are the **cells**: leaves
//! of the top tree whose boxes are exact (the union of their triangles' f64 boxes). Below a cell
//! nothing exists until a walk first opens it; then the cell's own subtree is built (binned SAH,
//! exactly as [`Bvh::build`] over the cell's triangles in curve order) and kept.
//!
//! Two parts 0.1 apart thus cost a sort and a box pass per part plus the few cells the distance
//! search opens, not two full SAH builds.
//!
//! Determinism: the top tree is a function of the triangles alone, and each cell's subtree a
//! function of its triangles in their curve order, so the shape of every node is the same
//! whatever the thread count and whichever walk opens a cell first (concurrent openers wait on
//! one [`OnceLock`]). Only *which* cells get built depends on the walks (a distance search
//! prunes by the best distance found so far); no answer depends on it.
//!
//! Node ids: the top tree's nodes keep their indices `0..T`; cell `c` owns the id range
//! `T + base_c ..` reserved for the at most `2k - 1` nodes of a subtree over its `k` triangles
//! (rounded up to blocks of 64, so an id finds its cell with one table lookup). The cell's root
//! is the top node itself; its children and everything below carry the reserved ids.

use super::{build, BuildOptions, Bvh, Node, Stats};
use crate::bvh::traverse::Tree;
use crate::geom::{Aabb, DVec3};
use crate::scene::mesh::TriMesh;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Largest cell: ranges of the curve order with at most this many triangles are left unbuilt
/// until a walk opens them. A cost knob only (no answer depends on it): smaller cells build less
/// of what a walk never opens, larger ones keep more of the tree SAH-quality.
pub const CELL_MAX: usize = 256;

/// Ids are reserved per cell in blocks of `1 << BLOCK_SHIFT`.
const BLOCK_SHIFT: u32 = 6;
/// `cell_of` entry of a top node that is not a cell.
const NOT_A_CELL: u32 = u32::MAX;
/// Bits per axis of the curve codes.
pub(crate) const CODE_BITS: u32 = 10;

struct Cell {
    /// First triangle slot in the top tree's `prims` (curve order).
    first: u32,
    /// Triangles in the cell.
    count: u32,
    /// Id of the cell subtree's node 0 (the top node itself; never handed out).
    base: u32,
    /// The subtree, prims as triangle indices of the mesh.
    tree: OnceLock<Bvh>,
}

/// A BVH over a mesh's triangles whose cells are built on first use (see the module docs).
pub struct LazyBvh<'m, M: TriMesh + ?Sized> {
    mesh: &'m M,
    opts: BuildOptions,
    /// The top tree: its leaves are the cells (and ranges too small to split further); `prims`
    /// holds every triangle in curve order.
    top: Bvh,
    /// Per top node: its cell, or [`NOT_A_CELL`].
    cell_of: Vec<u32>,
    cells: Vec<Cell>,
    /// Per block of reserved ids: the cell that owns it.
    block_cell: Vec<u32>,
    id_bound: usize,
}

impl<'m, M: TriMesh + ?Sized> LazyBvh<'m, M> {
    /// The top tree over `mesh` (its cells unbuilt). Uses rayon for the passes over triangles.
    pub fn new(mesh: &'m M, opts: BuildOptions) -> Self {
        let opts = BuildOptions { leaf_size: opts.leaf_size.clamp(1, 255), ..opts };
        let n = mesh.triangle_count();
        let (order, codes) = curve_order(mesh);
        let top = top_tree(mesh, order, &codes, opts.leaf_size as usize);
        drop(codes);
        let t = top.nodes.len();
        let mut cell_of = vec![NOT_A_CELL; t];
        let mut cells = Vec::new();
        let mut block_cell = Vec::new();
        let mut next = 0usize; // reserved ids so far (relative to t), a multiple of the block size
        for (i, node) in top.nodes.iter().enumerate() {
            if node.is_leaf() && node.count > opts.leaf_size {
                let reserve = (2 * node.count as usize - 1).next_multiple_of(1 << BLOCK_SHIFT);
                cell_of[i] = cells.len() as u32;
                block_cell.extend(std::iter::repeat_n(cells.len() as u32, reserve >> BLOCK_SHIFT));
                cells.push(Cell {
                    first: node.a,
                    count: node.count,
                    base: (t + next) as u32,
                    tree: OnceLock::new(),
                });
                next += reserve;
            }
        }
        let id_bound = t + next;
        assert!(id_bound <= u32::MAX as usize && n <= u32::MAX as usize, "node ids fit in u32");
        LazyBvh { mesh, opts, top, cell_of, cells, block_cell, id_bound }
    }

    /// The same tree with every cell built (for statistics of the whole tree, and tests).
    pub fn new_full(mesh: &'m M, opts: BuildOptions) -> Self {
        let t = Self::new(mesh, opts);
        t.cells.par_iter().for_each(|c| {
            t.cell_tree(c);
        });
        t
    }

    /// Number of cells (built or not).
    pub fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// Number of cells built so far.
    pub fn cells_built(&self) -> usize {
        self.cells.iter().filter(|c| c.tree.get().is_some()).count()
    }

    fn cell_tree<'s>(&'s self, c: &'s Cell) -> &'s Bvh {
        c.tree.get_or_init(|| {
            let slots = &self.top.prims[c.first as usize..(c.first + c.count) as usize];
            let mesh = self.mesh;
            let mut t = build::build_sequential(
                slots.len(),
                |l| Aabb::of_triangle(&mesh.triangle(slots[l as usize])),
                self.opts,
            );
            for p in &mut t.prims {
                *p = slots[*p as usize];
            }
            t
        })
    }

    /// The cell owning reserved id `i` (`i >= T`) and the local index in its subtree.
    #[inline]
    fn locate(&self, i: u32) -> (&Cell, usize) {
        let rel = i as usize - self.top.nodes.len();
        let c = &self.cells[self.block_cell[rel >> BLOCK_SHIFT] as usize];
        (c, (i - c.base) as usize)
    }

    /// The built node behind reserved id `i`.
    #[inline]
    fn cell_node(&self, i: u32) -> (&Cell, &Bvh, Node) {
        let (c, local) = self.locate(i);
        // Reserved ids are handed out only as children of a built cell's nodes.
        let t = c.tree.get().expect("a cell's ids are reached only after it is built");
        (c, t, t.nodes[local])
    }

    #[inline]
    fn top_count(&self) -> u32 {
        self.top.nodes.len() as u32
    }
}

impl<M: TriMesh + ?Sized> Tree for LazyBvh<'_, M> {
    #[inline]
    fn is_empty(&self) -> bool {
        self.top.nodes.is_empty()
    }

    #[inline]
    fn is_leaf(&self, i: u32) -> bool {
        if i < self.top_count() {
            self.top.nodes[i as usize].is_leaf() && self.cell_of[i as usize] == NOT_A_CELL
        } else {
            self.cell_node(i).2.is_leaf()
        }
    }

    #[inline]
    fn children(&self, i: u32) -> [u32; 2] {
        if i < self.top_count() {
            let c = self.cell_of[i as usize];
            if c == NOT_A_CELL {
                return [i + 1, self.top.nodes[i as usize].a];
            }
            let cell = &self.cells[c as usize];
            let t = self.cell_tree(cell);
            [cell.base + 1, cell.base + t.nodes[0].a]
        } else {
            let (c, _, n) = self.cell_node(i);
            [i + 1, c.base + n.a]
        }
    }

    #[inline]
    fn node_box(&self, i: u32) -> Aabb {
        if i < self.top_count() {
            self.top.nodes[i as usize].bounds
        } else {
            self.cell_node(i).2.bounds
        }
    }

    #[inline]
    fn leaf_prims(&self, i: u32) -> &[u32] {
        if i < self.top_count() {
            self.top.leaf_prims(&self.top.nodes[i as usize])
        } else {
            let (_, t, n) = self.cell_node(i);
            t.leaf_prims(&n)
        }
    }

    fn subtree_prims(&self, i: u32) -> &[u32] {
        if i < self.top_count() {
            self.top.subtree_prims(i)
        } else {
            let (c, t, _) = self.cell_node(i);
            t.subtree_prims(i - c.base)
        }
    }

    fn id_bound(&self) -> usize {
        self.id_bound
    }

    /// The top tree, each cell counted as one leaf (the cells below are built on demand, so
    /// counting them would depend on the walks); `cells` says how many there are.
    fn stats(&self) -> Stats {
        Stats { cells: self.cells.len(), ..self.top.stats() }
    }
}

/// Every triangle index sorted by the curve code of its box centre (ties by index), and the
/// codes in that order.
fn curve_order<M: TriMesh + ?Sized>(mesh: &M) -> (Vec<u32>, Vec<u32>) {
    let n = mesh.triangle_count() as u32;
    let tri_box = |t: u32| Aabb::of_triangle(&mesh.triangle(t));
    let bounds = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|t| {
            let b = tri_box(t);
            Aabb { min: b.center(), max: b.center() }
        })
        .reduce(|| Aabb::EMPTY, Aabb::union);
    let cells = (1u32 << CODE_BITS) as f64;
    let ext = bounds.max - bounds.min;
    // A flat axis (or a non-finite extent) quantises to 0.
    let scale =
        DVec3::from_array(ext.to_array().map(|e| if e > 0.0 && e.is_finite() { cells / e } else { 0.0 }));
    let max_q = (1u32 << CODE_BITS) - 1;
    let mut keys: Vec<u64> = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|t| {
            let q = ((tri_box(t).center() - bounds.min) * scale).to_array().map(|v| {
                // `as` saturates (NaN to 0), then clamp the top edge into the last cell.
                (v as u32).min(max_q)
            });
            (interleave(q) << 32) | t as u64
        })
        .collect();
    radix_sort_high(&mut keys);
    keys.into_iter().map(|k| (k as u32, (k >> 32) as u32)).unzip()
}

/// The 30-bit Morton code of three 10-bit coordinates (x in the lowest bit); also the self
/// tree's curve (`check::self_clash::tree`).
pub(crate) fn interleave(q: [u32; 3]) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut x = v as u64 & 0x3ff;
        x = (x | (x << 16)) & 0x30000ff;
        x = (x | (x << 8)) & 0x300f00f;
        x = (x | (x << 4)) & 0x30c30c3;
        x = (x | (x << 2)) & 0x9249249;
        x
    }
    spread(q[0]) | (spread(q[1]) << 1) | (spread(q[2]) << 2)
}

/// Stable LSD radix sort of `keys` by bits 32..62 (three passes of 10 bits).
pub(crate) fn radix_sort_high(keys: &mut Vec<u64>) {
    let mut tmp = vec![0u64; keys.len()];
    for pass in 0..3 {
        let shift = 32 + 10 * pass;
        let mut count = [0usize; 1025];
        for &k in keys.iter() {
            count[((k >> shift) & 0x3ff) as usize + 1] += 1;
        }
        for i in 1..1025 {
            count[i] += count[i - 1];
        }
        for &k in keys.iter() {
            let b = ((k >> shift) & 0x3ff) as usize;
            tmp[count[b]] = k;
            count[b] += 1;
        }
        std::mem::swap(keys, &mut tmp);
    }
}

/// The top tree over the curve order: ranges split at the highest bit where the first and last
/// codes differ (at the middle when all codes are equal) until at most [`CELL_MAX`] triangles
/// remain; leaf boxes are the exact unions of their triangles' boxes.
fn top_tree<M: TriMesh + ?Sized>(mesh: &M, order: Vec<u32>, code: &[u32], leaf_size: usize) -> Bvh {
    let n = order.len();
    if n == 0 {
        return Bvh { nodes: Vec::new(), prims: Vec::new() };
    }
    let tri_box = |t: u32| Aabb::of_triangle(&mesh.triangle(t));
    let limit = CELL_MAX.max(leaf_size);
    let mut nodes: Vec<Node> = Vec::with_capacity(2 * n / limit + 2);
    // (start, end, parent whose right child this is)
    let mut stack: Vec<(usize, usize, Option<usize>)> = vec![(0, n, None)];
    while let Some((s, e, right_of)) = stack.pop() {
        let idx = nodes.len();
        if let Some(p) = right_of {
            nodes[p].a = idx as u32;
        }
        if e - s <= limit {
            nodes.push(Node { bounds: Aabb::EMPTY, a: s as u32, count: (e - s) as u32 });
            continue;
        }
        let diff = code[s] ^ code[e - 1];
        let mid = if diff == 0 {
            s + (e - s) / 2
        } else {
            let bit = 31 - diff.leading_zeros();
            // First index whose code has `bit` set (codes share every higher bit in s..e).
            s + code[s..e].partition_point(|&c| c >> bit & 1 == 0)
        };
        nodes.push(Node { bounds: Aabb::EMPTY, a: 0, count: 0 });
        stack.push((mid, e, Some(idx)));
        stack.push((s, mid, None));
    }
    let leaf_boxes: Vec<Aabb> = nodes
        .par_iter()
        .map(|nd| {
            if nd.is_leaf() {
                order[nd.a as usize..(nd.a + nd.count) as usize]
                    .iter()
                    .fold(Aabb::EMPTY, |b, &t| b.union(tri_box(t)))
            } else {
                Aabb::EMPTY
            }
        })
        .collect();
    for (nd, b) in nodes.iter_mut().zip(leaf_boxes) {
        nd.bounds = b;
    }
    for i in (0..nodes.len()).rev() {
        if !nodes[i].is_leaf() {
            let r = nodes[i].a as usize;
            nodes[i].bounds = nodes[i + 1].bounds.union(nodes[r].bounds);
        }
    }
    Bvh { nodes, prims: order }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::traverse::{self, Tree};
    use crate::scene::mesh::Mesh;
    use crate::testing::gen;

    /// Walk the whole tree (opening every cell); check every node's box holds its triangles
    /// exactly and every triangle is below exactly one leaf.
    fn check_tree<M: TriMesh + ?Sized>(t: &LazyBvh<'_, M>, mesh: &M) {
        let n = mesh.triangle_count();
        let mut seen = vec![0u32; n];
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let b = t.node_box(i);
            let below = t.subtree_prims(i);
            let exact = below.iter().fold(Aabb::EMPTY, |x, &p| x.union(Aabb::of_triangle(&mesh.triangle(p))));
            assert_eq!(b, exact, "node {i}: box is not the exact union of its triangles");
            if t.is_leaf(i) {
                assert!(t.leaf_prims(i).len() <= 4);
                for &p in t.leaf_prims(i) {
                    seen[p as usize] += 1;
                }
            } else {
                let [l, r] = t.children(i);
                assert!((l as usize) < t.id_bound() && (r as usize) < t.id_bound());
                let (nl, nr) = (t.subtree_prims(l).len(), t.subtree_prims(r).len());
                assert_eq!(nl + nr, below.len(), "node {i}: children do not split its triangles");
                stack.extend([r, l]);
            }
        }
        assert!(seen.iter().all(|&c| c == 1), "every triangle in exactly one leaf");
    }

    fn torus(n: usize, centre: DVec3) -> Mesh {
        let mut m = gen::torus(n);
        for p in &mut m.positions {
            *p += centre;
        }
        m
    }

    #[test]
    fn every_node_exact_and_every_triangle_once() {
        for (k, m) in [torus(5_000, DVec3::ZERO), torus(20_000, DVec3::new(1e6, -3.0, 0.5)), gen::torus(80)]
            .iter()
            .enumerate()
        {
            let t = LazyBvh::new(m, BuildOptions::default());
            assert_eq!(t.cells_built(), 0);
            check_tree(&t, m);
            assert_eq!(t.cells_built(), t.cell_count(), "case {k}");
        }
    }

    #[test]
    fn empty_and_tiny_meshes() {
        let empty = Mesh::default();
        let t = LazyBvh::new(&empty, BuildOptions::default());
        assert!(t.is_empty());
        let one = gen::torus(20);
        let t = LazyBvh::new(&one, BuildOptions::default());
        check_tree(&t, &one);
        assert_eq!(t.cell_count(), 1); // 36 triangles: the root is the one cell
    }

    #[test]
    fn cells_are_the_same_whoever_opens_them_and_however_many_threads() {
        let m = torus(80_000, DVec3::ZERO); // many cells
        let whole = LazyBvh::new_full(&m, BuildOptions::default());
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let t = pool.install(|| LazyBvh::new(&m, BuildOptions::default()));
            // Open cells in reverse order on this thread.
            for c in t.cells.iter().rev() {
                t.cell_tree(c);
            }
            assert_eq!(t.top.nodes, whole.top.nodes);
            assert_eq!(t.top.prims, whole.top.prims);
            for (x, y) in t.cells.iter().zip(&whole.cells) {
                let (x, y) = (x.tree.get().unwrap(), y.tree.get().unwrap());
                assert_eq!((&x.nodes, &x.prims), (&y.nodes, &y.prims));
            }
        }
    }

    #[test]
    fn a_walk_opens_only_the_cells_it_reaches() {
        let (a, b) = (torus(80_000, DVec3::ZERO), torus(80_000, DVec3::new(2.5, 0.0, 0.0)));
        let (ta, tb) = (LazyBvh::new(&a, BuildOptions::default()), LazyBvh::new(&b, BuildOptions::default()));
        let pairs: Vec<(u32, u32)> = traverse::collect_pairs(
            &ta,
            &tb,
            |x, y| x.overlaps(y),
            |la, lb, out| {
                for &i in la {
                    for &j in lb {
                        out.push((i, j));
                    }
                }
            },
        );
        assert!(!pairs.is_empty());
        assert!(ta.cells_built() * 4 < ta.cell_count(), "{} of {}", ta.cells_built(), ta.cell_count());
        // The same leaf pairs as the same walk over full SAH trees would give, as triangle pairs
        // whose boxes meet.
        let (fa, fb) = (
            crate::bvh::Bvh::build(&a, BuildOptions::default()),
            crate::bvh::Bvh::build(&b, BuildOptions::default()),
        );
        let meet = |x: &[u32], y: &[u32], out: &mut Vec<(u32, u32)>| {
            for &i in x {
                let bi = Aabb::of_triangle(&a.triangle(i));
                for &j in y {
                    if bi.overlaps(&Aabb::of_triangle(&b.triangle(j))) {
                        out.push((i, j));
                    }
                }
            }
        };
        let mut lazy: Vec<(u32, u32)> = traverse::collect_pairs(&ta, &tb, |x, y| x.overlaps(y), meet);
        let mut full: Vec<(u32, u32)> = traverse::collect_pairs(&fa, &fb, |x, y| x.overlaps(y), meet);
        lazy.sort_unstable();
        full.sort_unstable();
        assert_eq!(lazy, full);
    }
}
