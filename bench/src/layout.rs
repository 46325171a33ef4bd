//! Two node layouts for one-tree walks, measured against each other by `meshclash-bench`.
//!
//! * **Stack** (the layout of [`meshclash::bvh`]): depth-first array, left child = next node, right
//!   child index stored in the node, walked with an explicit stack.
//! * **Stackless** (skip pointers): the same depth-first order, but each node stores where to go
//!   when its box is missed (or when its leaf is done): `skip(left) = right`,
//!   `skip(right) = skip(parent)`, `skip(root) = end`. A hit on an interior node goes to the next
//!   node. No stack, no right-child index; the leaf's triangle count is packed into the top 8
//!   bits of the skip word, so a node is 56 bytes like [`meshclash::bvh::Node`].
//!
//! The workload: for each leaf of tree A, find every leaf of tree B whose box overlaps it (the
//! "one-tree" alternative to the dual walk of [`meshclash::bvh::traverse`]).

use meshclash::bvh::Bvh;
use meshclash::geom::Aabb;
use rayon::prelude::*;

/// A skip-pointer node: box, `skip | count << 24`, first triangle (leaves only).
#[derive(Debug, Clone, Copy)]
#[repr(C)]
pub struct SkipNode {
    /// The box around everything below.
    pub bounds: Aabb,
    /// Low 24 bits: index to continue at when this subtree is done or missed. High 8 bits:
    /// triangle count (0 = interior).
    pub skip_count: u32,
    /// Leaf: first index into the prims.
    pub first: u32,
}

const _: () = assert!(std::mem::size_of::<SkipNode>() == 56);

/// A tree in the skip-pointer layout (shares `prims` order with the source [`Bvh`]).
#[derive(Debug, Clone)]
pub struct SkipBvh {
    /// Nodes in depth-first order.
    pub nodes: Vec<SkipNode>,
    /// Triangle indices grouped by leaf.
    pub prims: Vec<u32>,
}

const SKIP_MASK: u32 = (1 << 24) - 1;

impl SkipBvh {
    /// Convert a [`Bvh`] (same order, same boxes). `None` if it has 2^24 nodes or more.
    pub fn from_bvh(t: &Bvh) -> Option<SkipBvh> {
        let n = t.nodes.len();
        if n >= SKIP_MASK as usize {
            return None;
        }
        let mut skip = vec![0u32; n];
        if n > 0 {
            skip[0] = n as u32;
        }
        // Parents come before children in depth-first order, so one forward pass suffices.
        for (i, node) in t.nodes.iter().enumerate() {
            if !node.is_leaf() {
                let right = node.a;
                skip[i + 1] = right;
                skip[right as usize] = skip[i];
            }
        }
        let nodes = t
            .nodes
            .iter()
            .zip(&skip)
            .map(|(node, &s)| {
                let count = if node.is_leaf() { node.count.min(255) } else { 0 };
                SkipNode {
                    bounds: node.bounds,
                    skip_count: s | (count << 24),
                    first: if node.is_leaf() { node.a } else { 0 },
                }
            })
            .collect();
        Some(SkipBvh { nodes, prims: t.prims.clone() })
    }

    /// Bytes of nodes and prims.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<SkipNode>() + self.prims.len() * 4
    }
}

/// Calls `leaf` with the triangle list of every leaf of `t` whose box overlaps `q` (stack walk
/// over the [`Bvh`] layout).
#[inline]
pub fn query_stack(t: &Bvh, q: &Aabb, stack: &mut Vec<u32>, mut leaf: impl FnMut(&[u32])) {
    if t.nodes.is_empty() {
        return;
    }
    stack.clear();
    stack.push(0);
    while let Some(i) = stack.pop() {
        let node = &t.nodes[i as usize];
        if !node.bounds.overlaps(q) {
            continue;
        }
        if node.is_leaf() {
            leaf(t.leaf_prims(node));
        } else {
            stack.push(node.a);
            stack.push(i + 1);
        }
    }
}

/// As [`query_stack`], over the skip-pointer layout, without a stack.
#[inline]
pub fn query_stackless(t: &SkipBvh, q: &Aabb, mut leaf: impl FnMut(&[u32])) {
    let end = t.nodes.len() as u32;
    let mut i = 0u32;
    while i < end {
        let node = &t.nodes[i as usize];
        let skip = node.skip_count & SKIP_MASK;
        if node.bounds.overlaps(q) {
            let count = node.skip_count >> 24;
            if count > 0 {
                leaf(&t.prims[node.first as usize..(node.first + count) as usize]);
                i = skip;
            } else {
                i += 1;
            }
        } else {
            i = skip;
        }
    }
}

/// For each leaf of `ta` (in parallel), walk `tb` with the stack layout; `work(leaf_a, leaf_b)`
/// returns a count to sum.
pub fn leaves_vs_tree_stack(ta: &Bvh, tb: &Bvh, work: impl Fn(&[u32], &[u32]) -> u64 + Sync) -> u64 {
    let leaves: Vec<usize> = (0..ta.nodes.len()).filter(|&i| ta.nodes[i].is_leaf()).collect();
    leaves
        .par_chunks(64)
        .map(|chunk| {
            let mut stack = Vec::with_capacity(64);
            let mut sum = 0u64;
            for &i in chunk {
                let na = &ta.nodes[i];
                let la = ta.leaf_prims(na);
                query_stack(tb, &na.bounds, &mut stack, |lb| sum += work(la, lb));
            }
            sum
        })
        .sum()
}

/// As [`leaves_vs_tree_stack`], walking the skip-pointer layout of B.
pub fn leaves_vs_tree_stackless(ta: &Bvh, tb: &SkipBvh, work: impl Fn(&[u32], &[u32]) -> u64 + Sync) -> u64 {
    let leaves: Vec<usize> = (0..ta.nodes.len()).filter(|&i| ta.nodes[i].is_leaf()).collect();
    leaves
        .par_chunks(64)
        .map(|chunk| {
            let mut sum = 0u64;
            for &i in chunk {
                let na = &ta.nodes[i];
                let la = ta.leaf_prims(na);
                query_stackless(tb, &na.bounds, |lb| sum += work(la, lb));
            }
            sum
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshclash::bvh::{BuildOptions, Strategy};
    use meshclash::geom::DVec3;

    #[test]
    fn stackless_visits_the_same_leaves() {
        let boxes: Vec<Aabb> = (0..500)
            .map(|i| {
                let x = (i * 37 % 101) as f64;
                let y = (i * 11 % 23) as f64;
                Aabb { min: DVec3::new(x, y, 0.0), max: DVec3::new(x + 1.5, y + 1.5, 1.0) }
            })
            .collect();
        for strategy in [Strategy::Sah, Strategy::Median, Strategy::Equal] {
            for leaf_size in [1, 4, 16] {
                let t = Bvh::build_from_boxes(&boxes, BuildOptions { strategy, leaf_size });
                let s = SkipBvh::from_bvh(&t).unwrap();
                let mut st = Vec::new();
                for q in boxes.iter().step_by(7) {
                    let (mut x, mut y) = (Vec::new(), Vec::new());
                    query_stack(&t, q, &mut st, |l| x.extend_from_slice(l));
                    query_stackless(&s, q, |l| y.extend_from_slice(l));
                    x.sort_unstable();
                    y.sort_unstable();
                    assert_eq!(x, y);
                }
                let w = |a: &[u32], b: &[u32]| (a.len() * b.len()) as u64;
                assert_eq!(leaves_vs_tree_stack(&t, &t, w), leaves_vs_tree_stackless(&t, &s, w));
            }
        }
    }
}
