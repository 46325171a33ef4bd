//! The tree a part is walked against itself with: triangles ordered along a Morton curve, split
//! at the highest differing bit of their codes (LBVH), built in a few linear passes.
//!
//! A self walk pairs every node with its spatial neighbours, and on a surface almost every
//! overlapping pair of leaves is a pair of neighbours on the surface, whatever the tree: a
//! binned-SAH tree buys little there, and building it was a third of the time of a self check.
//! This tree is built from one key per triangle:
//!
//! 1. [`curve_keys`]: the centre of each triangle's box, quantised to a `2^CODE_BITS`-cell grid
//!    per axis over the box of the centres, interleaved into a Morton code, and the
//!    `(code, index)` keys sorted with an LSD radix sort: a total order, so the tree is a
//!    function of the triangles alone, whatever the thread count;
//! 2. the caller lays its items out in that order, and [`build`] splits ranges of it at the
//!    highest bit where their first and last codes differ (a spatial median per level), down
//!    to leaves of at most `leaf_size`. A range whose codes are all equal (triangles crowded
//!    into one grid cell) is reordered by its centres along their longest axis and split at the
//!    median instead, so a detail much smaller than its part still gets a tree.
//!
//! Boxes are f32 ([`FBox`], 24 bytes; nodes [`SNode`], 32 bytes), relative to an origin and
//! rounded outward from the exact f64 boxes, so they contain them: the walk may visit a few
//! more pairs than exact boxes would give, never fewer. The layout is [`crate::bvh::Bvh`]'s
//! (depth-first, left child next, right child in `a`); a leaf's `a` and `count` are a range of
//! positions in the items.

use crate::geom::{Aabb, DVec3};
use rayon::prelude::*;

/// A box in f32 that contains an exact f64 box, relative to an origin: 24 bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FBox {
    /// Lower corner (rounded down).
    pub lo: [f32; 3],
    /// Upper corner (rounded up).
    pub hi: [f32; 3],
}

impl FBox {
    /// The empty box (the identity of [`FBox::union`]).
    pub const EMPTY: FBox = FBox { lo: [f32::INFINITY; 3], hi: [f32::NEG_INFINITY; 3] };

    /// A box containing `b - origin`. Each difference is rounded once to f64 (off by at most
    /// half an f64 ulp), then to the next f32 strictly outward unless the f32 is already beyond
    /// the f64 value: an f32 below (above) an f64 value is at least half an f64 ulp below
    /// (above) it, so the f32 bound holds the exact difference. Out-of-range values go to
    /// ±infinity or to ±`f32::MAX` on the safe side.
    #[inline]
    pub fn around(b: &Aabb, origin: DVec3) -> FBox {
        let down = |r: f64| {
            let f = r as f32;
            if f as f64 >= r {
                f.next_down()
            } else {
                f
            }
        };
        let up = |r: f64| {
            let f = r as f32;
            if f as f64 <= r {
                f.next_up()
            } else {
                f
            }
        };
        let (lo, hi) = (b.min - origin, b.max - origin);
        FBox { lo: [down(lo.x), down(lo.y), down(lo.z)], hi: [up(hi.x), up(hi.y), up(hi.z)] }
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(self, o: FBox) -> FBox {
        let lo = |a: f32, b: f32| if b < a { b } else { a };
        let hi = |a: f32, b: f32| if b > a { b } else { a };
        FBox {
            lo: [lo(self.lo[0], o.lo[0]), lo(self.lo[1], o.lo[1]), lo(self.lo[2], o.lo[2])],
            hi: [hi(self.hi[0], o.hi[0]), hi(self.hi[1], o.hi[1]), hi(self.hi[2], o.hi[2])],
        }
    }

    /// Do the closed boxes meet?
    #[inline(always)]
    pub fn meets(&self, o: &FBox) -> bool {
        (self.lo[0] <= o.hi[0])
            & (o.lo[0] <= self.hi[0])
            & (self.lo[1] <= o.hi[1])
            & (o.lo[1] <= self.hi[1])
            & (self.lo[2] <= o.hi[2])
            & (o.lo[2] <= self.hi[2])
    }

    /// Half the surface area (which child of a pair to open first).
    #[inline]
    pub fn half_area(&self) -> f32 {
        let e = [self.hi[0] - self.lo[0], self.hi[1] - self.lo[1], self.hi[2] - self.lo[2]];
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }

    /// Its centre (for ordering only).
    #[inline]
    fn centre(&self, axis: usize) -> f32 {
        self.lo[axis] * 0.5 + self.hi[axis] * 0.5
    }
}

/// A node of the self tree: 32 bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SNode {
    /// The box around everything below.
    pub b: FBox,
    /// Leaf: first item position. Interior: index of the right child (the left is next).
    pub a: u32,
    /// Leaf: number of items (> 0). Interior: 0.
    pub count: u32,
}

const _: () = assert!(std::mem::size_of::<SNode>() == 32);

impl SNode {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Bits per axis of the curve codes (30-bit codes, as the lazy trees': one encoder and sort).
const CODE_BITS: u32 = crate::bvh::lazy::CODE_BITS;

/// Ranges above this many items are split before their subtrees are built in parallel.
const TASK_MIN: usize = 1 << 15;

/// What the tree is built over.
pub trait Item: Send {
    /// Its box.
    fn bounds(&self) -> FBox;
    /// A number unique among the items (orders items of equal code by position).
    fn id(&self) -> u32;
}

/// `(code << 32) | index` for each of `n` items whose box centre is `centre(index)`, sorted;
/// and the box of the centres.
pub fn curve_keys(n: usize, centre: impl Fn(usize) -> DVec3 + Sync) -> (Vec<u64>, Aabb) {
    assert!(n <= u32::MAX as usize, "indices fit in u32");
    let bounds = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|k| {
            let c = centre(k);
            Aabb { min: c, max: c }
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
        .map(|k| {
            // `as` saturates (NaN to 0); the top edge is clamped into the last cell.
            let q = ((centre(k) - bounds.min) * scale).to_array().map(|v| (v as u32).min(max_q));
            (crate::bvh::lazy::interleave(q) << 32) | k as u64
        })
        .collect();
    crate::bvh::lazy::radix_sort_high(&mut keys);
    (keys, bounds)
}

/// The tree over `items`, laid out in the order of `keys` (from [`curve_keys`]: `keys[i] >> 32`
/// is the code of `items[i]`); leaves hold at most `leaf_size` (≥ 1). Items of a range whose
/// codes are all equal may be reordered (see the module docs).
///
/// Two passes: the first decides every split and counts the nodes of each subtree, the second
/// writes the subtrees in parallel straight into their places of one array (depth-first, so a
/// subtree is one run of it).
pub fn build<T: Item>(items: &mut [T], keys: &[u64], leaf_size: usize) -> Vec<SNode> {
    assert_eq!(items.len(), keys.len());
    if items.is_empty() {
        return Vec::new();
    }
    let leaf_size = leaf_size.max(1);
    let sizes = count(keys, items, leaf_size);
    let mut nodes = vec![SNode { b: FBox::EMPTY, a: 0, count: 0 }; sizes.total()];
    write(keys, items, 0, leaf_size, &sizes, &mut nodes, 0);
    nodes
}

/// Node counts of a subtree, split further while its range is above [`TASK_MIN`] (the ranges
/// built in parallel).
enum Sizes {
    /// A subtree built by one task.
    Task(usize),
    /// A split: the node counts of both sides.
    Split(usize, Box<Sizes>, Box<Sizes>),
}

impl Sizes {
    fn total(&self) -> usize {
        match self {
            Sizes::Task(n) | Sizes::Split(n, _, _) => *n,
        }
    }
}

/// The node counts of the subtree over `items`, deciding (and applying) every reordering.
fn count<T: Item>(keys: &[u64], items: &mut [T], leaf_size: usize) -> Sizes {
    let n = items.len();
    if n <= TASK_MIN.max(leaf_size) {
        return Sizes::Task(count_nodes(keys, items, leaf_size));
    }
    let mid = split_point(keys, items);
    let (ki, kj) = keys.split_at(mid);
    let (ii, ij) = items.split_at_mut(mid);
    let (l, r) = rayon::join(|| count(ki, ii, leaf_size), || count(kj, ij, leaf_size));
    Sizes::Split(1 + l.total() + r.total(), Box::new(l), Box::new(r))
}

/// The number of nodes of the subtree over `items`, deciding (and applying) every reordering.
fn count_nodes<T: Item>(keys: &[u64], items: &mut [T], leaf_size: usize) -> usize {
    if items.len() <= leaf_size {
        return 1;
    }
    let mid = split_point(keys, items);
    let (ki, kj) = keys.split_at(mid);
    let (ii, ij) = items.split_at_mut(mid);
    1 + count_nodes(ki, ii, leaf_size) + count_nodes(kj, ij, leaf_size)
}

/// Write the subtree over `items` (which start at position `first` of the item list) into
/// `nodes`, exactly its size and its root first; node `i` of the slice is node `base + i` of
/// the tree. Returns its box.
fn write<T: Item>(
    keys: &[u64],
    items: &mut [T],
    first: usize,
    leaf_size: usize,
    sizes: &Sizes,
    nodes: &mut [SNode],
    base: usize,
) -> FBox {
    match sizes {
        Sizes::Task(_) => {
            let mut at = 0;
            write_seq(keys, items, first, leaf_size, nodes, base, &mut at)
        }
        Sizes::Split(_, l, r) => {
            // The split `count` made (its reordering is applied, and sorting again keeps it).
            let mid = split_point(keys, items);
            let (ki, kj) = keys.split_at(mid);
            let (ii, ij) = items.split_at_mut(mid);
            let (root, rest) = nodes.split_first_mut().expect("a node per subtree");
            let (nl, nr) = rest.split_at_mut(l.total());
            let right = base + 1 + l.total();
            let (bl, br) = rayon::join(
                || write(ki, ii, first, leaf_size, l, nl, base + 1),
                || write(kj, ij, first + mid, leaf_size, r, nr, right),
            );
            let b = bl.union(br);
            *root = SNode { b, a: right as u32, count: 0 };
            b
        }
    }
}

/// [`write`] for one task, depth-first from `nodes[*at]`.
fn write_seq<T: Item>(
    keys: &[u64],
    items: &mut [T],
    first: usize,
    leaf_size: usize,
    nodes: &mut [SNode],
    base: usize,
    at: &mut usize,
) -> FBox {
    let i = *at;
    *at += 1;
    let n = items.len();
    if n <= leaf_size {
        let b = items.iter().fold(FBox::EMPTY, |b, x| b.union(x.bounds()));
        nodes[i] = SNode { b, a: first as u32, count: n as u32 };
        return b;
    }
    let mid = split_point(keys, items);
    let (ki, kj) = keys.split_at(mid);
    let (ii, ij) = items.split_at_mut(mid);
    let l = write_seq(ki, ii, first, leaf_size, nodes, base, at);
    let right = base + *at;
    let r = write_seq(kj, ij, first + mid, leaf_size, nodes, base, at);
    let b = l.union(r);
    nodes[i] = SNode { b, a: right as u32, count: 0 };
    b
}

/// Where to split a range (at least 2 long): the first position whose code has the highest
/// differing bit set; when every code is equal, the median of the centres along their longest
/// axis (the range reordered by that axis, ties by id).
fn split_point<T: Item>(keys: &[u64], items: &mut [T]) -> usize {
    let n = keys.len();
    let diff = (keys[0] ^ keys[n - 1]) >> 32;
    if diff != 0 {
        let bit = 63 - diff.leading_zeros() + 32;
        // Keys are sorted and share every higher bit in the range.
        return keys.partition_point(|&k| k >> bit & 1 == 0);
    }
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for x in items.iter() {
        let b = x.bounds();
        for a in 0..3 {
            lo[a] = lo[a].min(b.centre(a));
            hi[a] = hi[a].max(b.centre(a));
        }
    }
    let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    items.sort_unstable_by(|x, y| {
        x.bounds().centre(axis).total_cmp(&y.bounds().centre(axis)).then(x.id().cmp(&y.id()))
    });
    n / 2
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Item for (FBox, u32) {
        fn bounds(&self) -> FBox {
            self.0
        }
        fn id(&self) -> u32 {
            self.1
        }
    }

    /// The tree over `boxes` (around `origin`): its nodes and the box index of each position.
    fn tree(boxes: &[Aabb], origin: DVec3, leaf: usize) -> (Vec<SNode>, Vec<u32>) {
        let (keys, _) = curve_keys(boxes.len(), |k| boxes[k].center());
        let mut items: Vec<(FBox, u32)> =
            keys.iter().map(|&k| (FBox::around(&boxes[k as u32 as usize], origin), k as u32)).collect();
        let nodes = build(&mut items, &keys, leaf);
        (nodes, items.iter().map(|x| x.1).collect())
    }

    fn boxes_of(m: &crate::scene::mesh::Mesh) -> Vec<Aabb> {
        (0..m.triangles.len() as u32).map(|t| Aabb::of_triangle(&crate::bvh::triangle(m, t))).collect()
    }

    /// Exact: `a + b <= c` (Knuth's TwoSum gives `a + b = s + e` exactly).
    fn sum_at_most(a: f64, b: f64, c: f64) -> bool {
        let s = a + b;
        let bb = s - a;
        let e = (a - (s - bb)) + (b - bb);
        s < c || (s == c && e <= 0.0)
    }

    /// Every node's box is the union of its children's (leaves: of their items'), every item
    /// is in exactly one leaf of at most `leaf` items, and the right child follows the left
    /// subtree; returns the positions below node `i`.
    fn check(nodes: &[SNode], i: usize, items: &[FBox], leaf: usize) -> std::ops::Range<usize> {
        let nd = nodes[i];
        if nd.is_leaf() {
            assert!(nd.count as usize <= leaf);
            let r = nd.a as usize..(nd.a + nd.count) as usize;
            assert_eq!(nd.b, items[r.clone()].iter().fold(FBox::EMPTY, |b, x| b.union(*x)));
            return r;
        }
        let l = check(nodes, i + 1, items, leaf);
        let r = check(nodes, nd.a as usize, items, leaf);
        assert_eq!(l.end, r.start, "children cover adjacent ranges");
        assert_eq!(nd.b, nodes[i + 1].b.union(nodes[nd.a as usize].b));
        l.start..r.end
    }

    #[test]
    fn every_node_holds_its_triangles_and_every_triangle_is_in_one_leaf() {
        let mut crowded = crate::testing::gen::torus(2_000);
        // A dense detail far smaller than one grid cell of its part.
        let far = crowded.positions.len() as u32;
        crowded.positions.push(DVec3::splat(1e6));
        for k in 0..200u32 {
            let s = k as f64 * 1e-9;
            crowded.positions.extend([
                DVec3::new(s, 0.0, 0.0),
                DVec3::new(s, 1e-9, 0.0),
                DVec3::new(s, 0.0, 1e-9),
            ]);
            let b = far + 1 + 3 * k;
            crowded.triangles.push([b, b + 1, b + 2]);
        }
        crowded.triangles.push([far, far, far]);
        crowded.tri_object = vec![0; crowded.triangles.len()];
        for m in [crate::testing::gen::torus(80), crate::testing::gen::torus(100_000), crowded] {
            let boxes = boxes_of(&m);
            let origin = Aabb::of_points(&m.positions).center();
            for leaf in [1, 4, 7] {
                let (nodes, order) = tree(&boxes, origin, leaf);
                let items: Vec<FBox> =
                    order.iter().map(|&k| FBox::around(&boxes[k as usize], origin)).collect();
                assert_eq!(check(&nodes, 0, &items, leaf), 0..boxes.len());
                let mut seen = order.clone();
                seen.sort_unstable();
                assert!(seen.iter().enumerate().all(|(i, &k)| i as u32 == k), "each triangle once");
            }
        }
    }

    #[test]
    fn f32_boxes_contain_the_exact_boxes() {
        let vals: [f64; 11] = [0.0, 1.0, -1.0, 0.1, -0.3, 1e-30, 3.5e38, 1e39, -1e300, 123456.789, 1e6 + 0.1];
        let origins = [DVec3::ZERO, DVec3::splat(0.1), DVec3::new(1e6, -7.25, 3.0e-5)];
        for &o in &origins {
            for &x in &vals {
                for &y in &vals {
                    let b = Aabb { min: DVec3::splat(x.min(y)), max: DVec3::splat(x.max(y)) };
                    let f = FBox::around(&b, o);
                    for a in 0..3 {
                        // lo + o <= min and max <= hi + o, exactly (infinite bounds hold).
                        assert!(f.lo[a] == f32::NEG_INFINITY || sum_at_most(f.lo[a] as f64, o[a], b.min[a]));
                        assert!(f.hi[a] == f32::INFINITY || sum_at_most(-(f.hi[a] as f64), -o[a], -b.max[a]));
                    }
                }
            }
        }
    }

    #[test]
    fn the_tree_does_not_depend_on_the_thread_count() {
        let m = crate::testing::gen::torus(200_000);
        let boxes = boxes_of(&m);
        let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
        let one = pool(1).install(|| tree(&boxes, DVec3::ZERO, 4));
        let three = pool(3).install(|| tree(&boxes, DVec3::ZERO, 4));
        assert_eq!(one, three);
    }

    #[test]
    fn empty_and_single() {
        assert!(tree(&[], DVec3::ZERO, 4).0.is_empty());
        let (nodes, order) = tree(&[Aabb { min: DVec3::ZERO, max: DVec3::ONE }], DVec3::ZERO, 4);
        assert_eq!(nodes.len(), 1);
        assert_eq!(order, vec![0]);
    }
}
