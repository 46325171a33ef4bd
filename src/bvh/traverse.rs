//! Simultaneous (dual-tree) walks of two BVHs. The leaf work is passed in as closures, so the
//! walk knows nothing about triangles and is tested with fake leaves.
//!
//! Both walks descend the larger node of a pair (by surface area; a leaf is never split), keep
//! an explicit stack (no recursion limit), and run in parallel: the root pair is expanded
//! breadth-first into a fixed number of independent sub-walks, which rayon runs on any number of
//! threads. The seeding does not depend on the thread count and results are merged in seed order,
//! so the output is the same whatever the number of threads.
//!
//! The walks see a tree through [`Tree`]: its nodes and each node's box in the walk's frame. A
//! [`Bvh`] is its own frame; an instance sharing another instance's tree maps its boxes
//! (`crate::check::assembly`), and the walk carries each node's mapped box on its stack so that a box
//! is mapped once per node pair opened.

use crate::bvh::Bvh;
use crate::geom::predicates::{self, BoxMap};
use crate::geom::{Aabb, DVec3};
use rayon::prelude::*;
pub use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering;

/// How many independent sub-walks the root pair is split into (fixed, for determinism).
const SEED_TASKS: usize = 256;

/// A tree as the walks see it: node ids, starting at the root 0, with their boxes in the
/// walk's frame. A [`Bvh`] is its own frame and its ids are its node indices; a
/// [`crate::bvh::lazy::LazyBvh`] builds nodes when a walk first asks for a node's children.
pub trait Tree: Sync {
    /// True for a tree with no nodes.
    fn is_empty(&self) -> bool;
    /// Is node `i` a leaf?
    fn is_leaf(&self, i: u32) -> bool;
    /// The two children of interior node `i`.
    fn children(&self, i: u32) -> [u32; 2];
    /// The box of node `i` in the walk's frame: it contains every triangle below the node (as
    /// the leaf closures see them).
    fn node_box(&self, i: u32) -> Aabb;
    /// The triangles of leaf `i`.
    fn leaf_prims(&self, i: u32) -> &[u32];
    /// Every triangle below node `i`.
    fn subtree_prims(&self, i: u32) -> &[u32];
    /// One more than the largest node id (for tables indexed by node).
    fn id_bound(&self) -> usize;
    /// Size and quality of the underlying tree.
    fn stats(&self) -> crate::bvh::Stats;
    /// The root box (empty for an empty tree).
    fn root_box(&self) -> Aabb {
        if self.is_empty() {
            Aabb::EMPTY
        } else {
            self.node_box(0)
        }
    }
}

impl Tree for Bvh {
    #[inline]
    fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
    #[inline]
    fn is_leaf(&self, i: u32) -> bool {
        self.nodes[i as usize].is_leaf()
    }
    #[inline]
    fn children(&self, i: u32) -> [u32; 2] {
        [i + 1, self.nodes[i as usize].a]
    }
    #[inline]
    fn node_box(&self, i: u32) -> Aabb {
        self.nodes[i as usize].bounds
    }
    #[inline]
    fn leaf_prims(&self, i: u32) -> &[u32] {
        Bvh::leaf_prims(self, &self.nodes[i as usize])
    }
    fn subtree_prims(&self, i: u32) -> &[u32] {
        Bvh::subtree_prims(self, i)
    }
    fn id_bound(&self) -> usize {
        self.nodes.len()
    }
    fn stats(&self) -> crate::bvh::Stats {
        Bvh::stats(self)
    }
}

/// A tree seen in another frame: a tree built over one instance's coordinates, its boxes
/// mapped conservatively into this instance's world coordinates by the relative transform
/// ([`BoxMap`]), or read as they are (`map: None`: the tree is this instance's own). The root
/// box is always the instance's exact world box. Assemblies (instances of one glTF mesh) and
/// prepared meshes placed under a transform walk their trees through it.
#[derive(Debug)]
pub struct MappedTree<'a, T: ?Sized = Bvh> {
    /// The tree.
    pub bvh: &'a T,
    /// The map into this frame, if the tree was built in another.
    pub map: Option<BoxMap>,
    /// The exact box of this instance in this frame.
    pub root: Aabb,
}

impl<T: ?Sized> Clone for MappedTree<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T: ?Sized> Copy for MappedTree<'_, T> {}

impl<T: Tree + ?Sized> Tree for MappedTree<'_, T> {
    #[inline]
    fn is_empty(&self) -> bool {
        self.bvh.is_empty()
    }
    #[inline]
    fn is_leaf(&self, i: u32) -> bool {
        self.bvh.is_leaf(i)
    }
    #[inline]
    fn children(&self, i: u32) -> [u32; 2] {
        self.bvh.children(i)
    }
    #[inline]
    fn node_box(&self, i: u32) -> Aabb {
        match (&self.map, i) {
            (_, 0) => self.root,
            (None, _) => self.bvh.node_box(i),
            (Some(m), _) => m.map_box(&self.bvh.node_box(i)),
        }
    }
    #[inline]
    fn leaf_prims(&self, i: u32) -> &[u32] {
        self.bvh.leaf_prims(i)
    }
    fn subtree_prims(&self, i: u32) -> &[u32] {
        self.bvh.subtree_prims(i)
    }
    fn id_bound(&self) -> usize {
        self.bvh.id_bound()
    }
    fn stats(&self) -> crate::bvh::Stats {
        self.bvh.stats()
    }
}

/// A node pair on a walk's stack, with both boxes.
type Entry = (u32, u32, Aabb, Aabb);

/// Which node of a pair to open: the larger, never a leaf. `None` when both are leaves.
#[inline]
fn open_a(a_leaf: bool, ba: &Aabb, b_leaf: bool, bb: &Aabb) -> Option<bool> {
    match (a_leaf, b_leaf) {
        (true, true) => None,
        (true, false) => Some(false),
        (false, true) => Some(true),
        (false, false) => Some(ba.half_area() >= bb.half_area()),
    }
}

/// The two children pairs of `e` after opening one side, with their boxes.
#[inline]
fn children<A: Tree + ?Sized, B: Tree + ?Sized>(ta: &A, tb: &B, e: &Entry) -> Option<[Entry; 2]> {
    let &(i, j, ba, bb) = e;
    Some(if open_a(ta.is_leaf(i), &ba, tb.is_leaf(j), &bb)? {
        let [l, r] = ta.children(i);
        [(l, j, ta.node_box(l), bb), (r, j, ta.node_box(r), bb)]
    } else {
        let [l, r] = tb.children(j);
        [(i, l, ba, tb.node_box(l)), (i, r, ba, tb.node_box(r))]
    })
}

/// Breadth-first expansion of the root pair into about `SEED_TASKS` pairs that pass `keep`.
fn seed<A: Tree + ?Sized, B: Tree + ?Sized>(
    ta: &A,
    tb: &B,
    keep: &dyn Fn(&Aabb, &Aabb) -> bool,
) -> Vec<Entry> {
    if ta.is_empty() || tb.is_empty() {
        return Vec::new();
    }
    let root = (0, 0, ta.node_box(0), tb.node_box(0));
    if !keep(&root.2, &root.3) {
        return Vec::new();
    }
    let mut level = vec![root];
    loop {
        let mut next = Vec::with_capacity(level.len() * 2);
        let mut opened = false;
        for e in &level {
            match children(ta, tb, e) {
                None => next.push(*e),
                Some(kids) => {
                    opened = true;
                    for k in kids {
                        if keep(&k.2, &k.3) {
                            next.push(k);
                        }
                    }
                }
            }
        }
        level = next;
        if !opened || level.len() >= SEED_TASKS || level.is_empty() {
            return level;
        }
    }
}

/// Visit every pair of leaves whose boxes pass `boxes_meet` (tested on every node pair on the
/// way down) and let `leaf` turn the two leaves' triangle lists into results. Results come back
/// in an order that depends only on the trees, not on the thread count.
pub fn collect_pairs<T, A, B, M, L>(ta: &A, tb: &B, boxes_meet: M, leaf: L) -> Vec<T>
where
    T: Send,
    A: Tree + ?Sized,
    B: Tree + ?Sized,
    M: Fn(&Aabb, &Aabb) -> bool + Sync,
    L: Fn(&[u32], &[u32], &mut Vec<T>) + Sync,
{
    let seeds = seed(ta, tb, &boxes_meet);
    let parts: Vec<Vec<T>> = seeds
        .par_iter()
        .map(|s| {
            let mut out = Vec::new();
            let mut stack = vec![*s];
            while let Some(e) = stack.pop() {
                match children(ta, tb, &e) {
                    None => leaf(ta.leaf_prims(e.0), tb.leaf_prims(e.1), &mut out),
                    Some(kids) => {
                        for k in kids.iter().rev() {
                            if boxes_meet(&k.2, &k.3) {
                                stack.push(*k);
                            }
                        }
                    }
                }
            }
            out
        })
        .collect();
    parts.into_iter().flatten().collect()
}

/// As [`collect_pairs`], folding instead of collecting: every leaf pair whose boxes pass
/// `boxes_meet` is handed to `leaf` with a state made by `init`, one state per independent
/// sub-walk, and the states are combined by `merge` in seed order. Memory is one state per
/// sub-walk, whatever the number of pairs the leaves produce; with a `merge` that is associative
/// and commutative the result does not depend on the thread count.
pub fn fold_pairs<S, A, B, M, I, L, G>(ta: &A, tb: &B, boxes_meet: M, init: I, leaf: L, merge: G) -> S
where
    S: Send,
    A: Tree + ?Sized,
    B: Tree + ?Sized,
    M: Fn(&Aabb, &Aabb) -> bool + Sync,
    I: Fn() -> S + Sync,
    L: Fn(&[u32], &[u32], &mut S) + Sync,
    G: Fn(S, S) -> S,
{
    let seeds = seed(ta, tb, &boxes_meet);
    let states: Vec<S> = seeds
        .par_iter()
        .map(|s| {
            let mut state = init();
            let mut stack = vec![*s];
            while let Some(e) = stack.pop() {
                match children(ta, tb, &e) {
                    None => leaf(ta.leaf_prims(e.0), tb.leaf_prims(e.1), &mut state),
                    Some(kids) => {
                        for k in kids.iter().rev() {
                            if boxes_meet(&k.2, &k.3) {
                                stack.push(*k);
                            }
                        }
                    }
                }
            }
            state
        })
        .collect();
    states.into_iter().fold(init(), merge)
}

/// One-tree walk: call `visit` on every triangle in a leaf whose box overlaps `query` (exact
/// closed overlap), stopping early — and returning true — as soon as `visit` returns true.
pub fn any_in_box<T: Tree + ?Sized>(tree: &T, query: &Aabb, visit: impl FnMut(u32) -> bool) -> bool {
    any_where(tree, |b| b.overlaps(query), visit)
}

/// One-tree walk: call `visit` on every triangle in a leaf reached through nodes whose boxes
/// pass `keep`, stopping early — and returning true — as soon as `visit` returns true.
fn any_where<T: Tree + ?Sized>(
    tree: &T,
    keep: impl Fn(&Aabb) -> bool,
    mut visit: impl FnMut(u32) -> bool,
) -> bool {
    if tree.is_empty() {
        return false;
    }
    let mut stack = vec![0u32];
    while let Some(i) = stack.pop() {
        if !keep(&tree.node_box(i)) {
            continue;
        }
        if !tree.is_leaf(i) {
            let [l, r] = tree.children(i);
            stack.push(r);
            stack.push(l);
            continue;
        }
        if tree.leaf_prims(i).iter().any(|&t| visit(t)) {
            return true;
        }
    }
    false
}

/// One-tree walk along the segment `p`–`q`: call `visit` on every triangle in a leaf whose box
/// the segment may touch, stopping early — and returning true — as soon as `visit` returns
/// true. A node is opened only if the segment's parameter intervals across its three slabs
/// (Kay & Kajiya 1986; Williams et al. 2005: per-axis entry and exit times with the inverse
/// direction precomputed, an axis the segment does not move along tested by position) can
/// overlap; the intervals are widened by [`predicates::SEGMENT_BOX_ROUNDING_ULPS`] so rounding
/// never drops a box the segment touches. A ray across a part thus opens the nodes along it,
/// not every node in the segment's bounding box.
pub fn any_on_segment<T: Tree + ?Sized>(
    tree: &T,
    p: DVec3,
    q: DVec3,
    visit: impl FnMut(u32) -> bool,
) -> bool {
    let d = q - p;
    let inv = DVec3::ONE / d; // ±inf on an axis with d = 0 (handled by position below)
    let seg_box = Aabb { min: p.min(q), max: p.max(q) };
    let widen = predicates::SEGMENT_BOX_ROUNDING_ULPS * f64::EPSILON;
    let touches = |b: &Aabb| -> bool {
        if !b.overlaps(&seg_box) {
            return false;
        }
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            if d[k] == 0.0 {
                continue; // the box test above already placed p[k] inside [min, max]
            }
            let a = (b.min[k] - p[k]) * inv[k];
            let c = (b.max[k] - p[k]) * inv[k];
            let (lo, hi) = (a.min(c), a.max(c));
            t0 = t0.max(lo - lo.abs() * widen - widen);
            t1 = t1.min(hi + hi.abs() * widen + widen);
        }
        t0 <= t1
    };
    any_where(tree, touches, visit)
}

/// A candidate for [`min_pair`]: its distance and a key that breaks ties deterministically.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate<R> {
    /// The (non-negative) distance.
    pub distance: f64,
    /// Tie-break key (lowest wins), e.g. the two triangle indices.
    pub key: (u32, u32),
    /// Whatever the leaf wants to return with it.
    pub data: R,
}

fn better<R>(x: &Candidate<R>, y: &Candidate<R>) -> bool {
    (x.distance, x.key) < (y.distance, y.key)
}

/// Branch-and-bound search for the closest pair: node pairs are pruned when the lower bound
/// `box_distance` of their boxes exceeds the best distance found so far plus `slack` (the
/// caller's bound on f64 rounding of distances, so that no pair that could tie is pruned). The
/// winner is the minimum of (distance, key) over all candidates that could be it, so the answer
/// does not depend on the thread count or on the order in which threads find candidates.
pub fn min_pair<R, A, B, D, L>(ta: &A, tb: &B, box_distance: D, slack: f64, leaf: L) -> Option<Candidate<R>>
where
    R: Send + Copy,
    A: Tree + ?Sized,
    B: Tree + ?Sized,
    D: Fn(&Aabb, &Aabb) -> f64 + Sync,
    L: Fn(&[u32], &[u32], f64) -> Option<Candidate<R>> + Sync,
{
    min_pair_with(ta, tb, || (), |_, _, x, _, y, _| box_distance(x, y), slack, leaf)
}

/// As [`min_pair`], with a lower bound that may look at the nodes themselves (their indices in
/// `ta` and `tb` beside their boxes) and keep per-walk state `S` (e.g. a cache of oriented
/// bounds): `new_state` makes one per independent sub-walk. The last argument of `lower_bound`
/// is the current pruning cutoff: once the bound is known to exceed it, any value above it may
/// be returned (a cheap bound first, a finer one only when needed). Pruning uses only the
/// bound's relation to the cutoff and every candidate that could win is evaluated, so the answer
/// does not depend on the state or on the thread count.
pub fn min_pair_with<R, S, A, B, N, D, L>(
    ta: &A,
    tb: &B,
    new_state: N,
    lower_bound: D,
    slack: f64,
    leaf: L,
) -> Option<Candidate<R>>
where
    R: Send + Copy,
    A: Tree + ?Sized,
    B: Tree + ?Sized,
    N: Fn() -> S + Sync,
    D: Fn(&mut S, u32, &Aabb, u32, &Aabb, f64) -> f64 + Sync,
    L: Fn(&[u32], &[u32], f64) -> Option<Candidate<R>> + Sync,
{
    let best = AtomicU64::new(f64::INFINITY.to_bits());
    min_pair_shared(ta, tb, new_state, lower_bound, slack, leaf, &best)
}

/// As [`min_pair_with`], pruning against a best distance shared with other searches (`best`:
/// the f64 bits of a non-negative distance, order-preserving; lowered as candidates are
/// found). Candidates farther than `best` plus `slack` are never evaluated, so the result is
/// `None` when nothing in these trees can come within it; when some searches share one
/// `best`, the minimum of their results is the minimum over all of them, and its (distance,
/// key) does not depend on the order in which they run.
pub fn min_pair_shared<R, S, A, B, N, D, L>(
    ta: &A,
    tb: &B,
    new_state: N,
    lower_bound: D,
    slack: f64,
    leaf: L,
    best: &AtomicU64,
) -> Option<Candidate<R>>
where
    R: Send + Copy,
    A: Tree + ?Sized,
    B: Tree + ?Sized,
    N: Fn() -> S + Sync,
    D: Fn(&mut S, u32, &Aabb, u32, &Aabb, f64) -> f64 + Sync,
    L: Fn(&[u32], &[u32], f64) -> Option<Candidate<R>> + Sync,
{
    let bound = |best: &AtomicU64| f64::from_bits(best.load(Ordering::Relaxed)) + slack;
    let mut seed_state = new_state();
    let mut seeds: Vec<(f64, Entry)> = seed(ta, tb, &|_, _| true)
        .into_iter()
        .map(|e| (lower_bound(&mut seed_state, e.0, &e.2, e.1, &e.3, f64::INFINITY), e))
        .collect();
    drop(seed_state);
    seeds.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1 .0, x.1 .1).cmp(&(y.1 .0, y.1 .1))));
    let found: Vec<Option<Candidate<R>>> = seeds
        .par_iter()
        .map(|&(lb, e)| {
            let mut mine: Option<Candidate<R>> = None;
            if lb > bound(best) {
                return None;
            }
            let mut state = new_state();
            let mut stack = vec![(lb, e)];
            while let Some((lb, e)) = stack.pop() {
                if lb > bound(best) {
                    continue;
                }
                match children(ta, tb, &e) {
                    None => {
                        let cur = f64::from_bits(best.load(Ordering::Relaxed));
                        if let Some(c) = leaf(ta.leaf_prims(e.0), tb.leaf_prims(e.1), cur + slack) {
                            best.fetch_min(c.distance.to_bits(), Ordering::Relaxed);
                            if mine.as_ref().is_none_or(|m| better(&c, m)) {
                                mine = Some(c);
                            }
                        }
                    }
                    Some(kids) => {
                        let cut = bound(best);
                        let d = kids.map(|k| lower_bound(&mut state, k.0, &k.2, k.1, &k.3, cut));
                        // Push the farther first so the nearer is opened first.
                        let order = if d[0] <= d[1] { [1, 0] } else { [0, 1] };
                        for k in order {
                            if d[k] <= bound(best) {
                                stack.push((d[k], kids[k]));
                            }
                        }
                    }
                }
            }
            mine
        })
        .collect();
    found.into_iter().flatten().reduce(|x, y| if better(&y, &x) { y } else { x })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, Strategy};
    use crate::geom::DVec3;

    fn unit_boxes(n: usize, offset: f64) -> Vec<Aabb> {
        // A row of unit-ish boxes along x, spaced 2 apart.
        (0..n)
            .map(|i| {
                let x = offset + 2.0 * i as f64;
                Aabb { min: DVec3::new(x, 0.0, 0.0), max: DVec3::new(x + 1.0, 1.0, 1.0) }
            })
            .collect()
    }

    #[test]
    fn folding_walk_sees_the_same_pairs_as_the_collecting_walk() {
        let a = unit_boxes(300, 0.0);
        let b = unit_boxes(200, 1.0);
        for leaf_size in [1, 4] {
            let opts = BuildOptions { leaf_size, ..BuildOptions::default() };
            let (ta, tb) = (Bvh::build_from_boxes(&a, opts), Bvh::build_from_boxes(&b, opts));
            let each = |la: &[u32], lb: &[u32], f: &mut dyn FnMut(u32, u32)| {
                for &i in la {
                    for &j in lb {
                        if a[i as usize].overlaps(&b[j as usize]) {
                            f(i, j);
                        }
                    }
                }
            };
            let mut listed = collect_pairs(
                &ta,
                &tb,
                |x, y| x.overlaps(y),
                |la, lb, out| each(la, lb, &mut |i, j| out.push((i, j))),
            );
            listed.sort();
            // Count, smallest and largest pair, and a order-free checksum, folded.
            type State = (usize, Option<(u32, u32)>, Option<(u32, u32)>, u64);
            let folded: State = fold_pairs(
                &ta,
                &tb,
                |x, y| x.overlaps(y),
                || (0, None, None, 0),
                |la, lb, s: &mut State| {
                    each(la, lb, &mut |i, j| {
                        s.0 += 1;
                        s.1 = Some(s.1.map_or((i, j), |m| m.min((i, j))));
                        s.2 = Some(s.2.map_or((i, j), |m| m.max((i, j))));
                        s.3 = s.3.wrapping_add((i as u64) << 32 | j as u64);
                    })
                },
                |x, y| {
                    let pick = |p: Option<(u32, u32)>, q: Option<(u32, u32)>, f: fn(_, _) -> _| match (p, q) {
                        (Some(p), Some(q)) => Some(f(p, q)),
                        (p, q) => p.or(q),
                    };
                    (
                        x.0 + y.0,
                        pick(x.1, y.1, std::cmp::min),
                        pick(x.2, y.2, std::cmp::max),
                        x.3.wrapping_add(y.3),
                    )
                },
            );
            let sum = listed.iter().fold(0u64, |s, &(i, j)| s.wrapping_add((i as u64) << 32 | j as u64));
            assert_eq!(folded, (listed.len(), listed.first().copied(), listed.last().copied(), sum));
            assert_eq!(listed.len(), 400);
        }
    }

    #[test]
    fn fake_leaves_find_exactly_the_overlapping_box_pairs() {
        let a = unit_boxes(300, 0.0);
        let b = unit_boxes(200, 1.0); // b_k touches a_k and a_{k+1} at faces
        for strategy in [Strategy::Sah, Strategy::Median, Strategy::Equal] {
            for leaf_size in [1, 4] {
                let opts = BuildOptions { strategy, leaf_size };
                let (ta, tb) = (Bvh::build_from_boxes(&a, opts), Bvh::build_from_boxes(&b, opts));
                let mut got = collect_pairs(
                    &ta,
                    &tb,
                    |x, y| x.overlaps(y),
                    |la, lb, out| {
                        for &i in la {
                            for &j in lb {
                                if a[i as usize].overlaps(&b[j as usize]) {
                                    out.push((i, j));
                                }
                            }
                        }
                    },
                );
                got.sort();
                let mut want = Vec::new();
                for i in 0..a.len() as u32 {
                    for j in 0..b.len() as u32 {
                        if a[i as usize].overlaps(&b[j as usize]) {
                            want.push((i, j));
                        }
                    }
                }
                assert_eq!(got, want, "{strategy:?} leaf {leaf_size}");
                assert_eq!(want.len(), 400);
            }
        }
    }

    #[test]
    fn branch_and_bound_finds_the_brute_force_minimum() {
        let a = unit_boxes(100, 0.0);
        let b: Vec<Aabb> = unit_boxes(100, 0.0)
            .into_iter()
            .map(|x| Aabb { min: x.min + DVec3::new(0.3, 0.0, 5.0), max: x.max + DVec3::new(0.3, 0.0, 5.0) })
            .collect();
        let opts = BuildOptions::default();
        let (ta, tb) = (Bvh::build_from_boxes(&a, opts), Bvh::build_from_boxes(&b, opts));
        let got = min_pair(
            &ta,
            &tb,
            |x, y| x.distance_sq(y).sqrt(),
            0.0,
            |la, lb, _| {
                let mut best: Option<Candidate<()>> = None;
                for &i in la {
                    for &j in lb {
                        let c = Candidate {
                            distance: a[i as usize].distance_sq(&b[j as usize]).sqrt(),
                            key: (i, j),
                            data: (),
                        };
                        if best.as_ref().is_none_or(|m| better(&c, m)) {
                            best = Some(c);
                        }
                    }
                }
                best
            },
        )
        .unwrap();
        // Every b box sits 4 above its a box: all 100 (i, i) pairs tie at 4, and also the
        // neighbours overlapping in x; the lowest key wins.
        assert_eq!(got.distance, 4.0);
        assert_eq!(got.key, (0, 0));
    }

    #[test]
    fn segment_walk_visits_every_box_the_segment_touches() {
        // A 3D grid of unit boxes; segments in many directions (some along an axis, some
        // through corners and faces exactly): the walk must visit every box the segment meets
        // (by brute force, with a closed slab test in exact rational-free form: sampling the
        // segment densely plus the endpoints) and prune most others.
        let mut boxes = Vec::new();
        for x in 0..8 {
            for y in 0..8 {
                for z in 0..8 {
                    let m = DVec3::new(x as f64, y as f64, z as f64) * 1.5;
                    boxes.push(Aabb { min: m, max: m + DVec3::ONE });
                }
            }
        }
        let tree = Bvh::build_from_boxes(&boxes, BuildOptions::default());
        let segs = [
            (DVec3::new(0.5, 0.5, -1.0), DVec3::new(0.5, 0.5, 20.0)),
            (DVec3::new(1.0, 1.0, 1.0), DVec3::new(11.5, 11.5, 11.5)),
            (DVec3::new(-2.0, 3.2, 4.7), DVec3::new(13.0, 3.2, 4.7)),
            (DVec3::new(2.5, -1.0, 0.3), DVec3::new(9.1, 14.0, 10.9)),
            (DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 11.5, 0.0)),
        ];
        for (p, q) in segs {
            let mut seen = Vec::new();
            any_on_segment(&tree, p, q, |t| {
                seen.push(t);
                false
            });
            let n = 20_000;
            for (i, b) in boxes.iter().enumerate() {
                let hit = (0..=n).any(|k| {
                    let x = p + (q - p) * (k as f64 / n as f64);
                    b.overlaps(&Aabb { min: x, max: x })
                });
                if hit {
                    assert!(seen.contains(&(i as u32)), "box {i} missed for {p} -> {q}");
                }
            }
            assert!(seen.len() < boxes.len() / 4, "{} of {} visited", seen.len(), boxes.len());
        }
    }

    #[test]
    fn empty_trees_give_nothing() {
        let a = unit_boxes(10, 0.0);
        let ta = Bvh::build_from_boxes(&a, BuildOptions::default());
        let tb = Bvh::build_from_boxes(&[], BuildOptions::default());
        let got: Vec<()> = collect_pairs(&ta, &tb, |_, _| true, |_, _, _| {});
        assert!(got.is_empty());
    }
}
