//! Object-level search for a collision manager: a tree over the objects' world boxes, and the
//! best-first search over object pairs in increasing order of a lower bound of their distance.

use crate::geom::Aabb;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Objects per leaf of an [`ObjectTree`].
const LEAF_OBJECTS: usize = 4;

/// A bounding volume tree over a list of objects' boxes (median splits on the longest axis of
/// the box centers). Its boxes are unions of the objects' boxes: a node's box holds every box
/// below it.
#[derive(Debug, Clone)]
pub struct ObjectTree {
    nodes: Vec<Node>,
    /// The objects (their indices in the caller's list), leaves' runs contiguous.
    items: Vec<usize>,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    /// Leaf: the run `items[start..start + len]`. Inner: `len == 0`, children `start` and
    /// `start + 1`.
    start: u32,
    len: u32,
}

impl Node {
    fn is_leaf(&self) -> bool {
        self.len > 0
    }
}

impl ObjectTree {
    /// The tree over `items` (indices into `boxes`).
    pub fn build(boxes: &[Aabb], items: Vec<usize>) -> ObjectTree {
        let mut t = ObjectTree { nodes: Vec::with_capacity(2 * items.len() / LEAF_OBJECTS + 1), items };
        if t.items.is_empty() {
            return t;
        }
        t.nodes.push(Node { bounds: Aabb::EMPTY, start: 0, len: 0 });
        let n = t.items.len();
        t.split(boxes, 0, 0, n);
        t
    }

    fn split(&mut self, boxes: &[Aabb], node: usize, lo: usize, hi: usize) {
        let run = &mut self.items[lo..hi];
        let bounds = run.iter().fold(Aabb::EMPTY, |b, &i| b.union(boxes[i]));
        if run.len() <= LEAF_OBJECTS {
            self.nodes[node] = Node { bounds, start: lo as u32, len: run.len() as u32 };
            return;
        }
        let centers = run.iter().fold(Aabb::EMPTY, |b, &i| b.grow(boxes[i].center()));
        let e = centers.extent();
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let mid = run.len() / 2;
        // Ties broken by index: the tree depends only on the boxes and their order.
        run.select_nth_unstable_by(mid, |&a, &b| {
            boxes[a].center()[axis].total_cmp(&boxes[b].center()[axis]).then(a.cmp(&b))
        });
        let first = self.nodes.len();
        self.nodes.push(Node { bounds: Aabb::EMPTY, start: 0, len: 0 });
        self.nodes.push(Node { bounds: Aabb::EMPTY, start: 0, len: 0 });
        self.nodes[node] = Node { bounds, start: first as u32, len: 0 };
        self.split(boxes, first, lo, lo + mid);
        self.split(boxes, first + 1, lo + mid, hi);
    }

    fn children(&self, n: usize) -> [usize; 2] {
        let s = self.nodes[n].start as usize;
        [s, s + 1]
    }

    fn leaf(&self, n: usize) -> &[usize] {
        let x = &self.nodes[n];
        &self.items[x.start as usize..(x.start + x.len) as usize]
    }
}

/// A node pair waiting in the best-first queue, smallest lower bound first (ties: the node
/// pair, so the order of the search depends on nothing but the trees).
struct Pending(f64, usize, usize);

impl PartialEq for Pending {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Pending {}
impl PartialOrd for Pending {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Pending {
    fn cmp(&self, o: &Self) -> Ordering {
        // Reversed: BinaryHeap pops the largest.
        o.0.total_cmp(&self.0).then((o.1, o.2).cmp(&(self.1, self.2)))
    }
}

/// Best-first search over the object pairs of two trees (or, with `same`, the pairs `i < j`
/// of one tree: `tb` is then `ta`), in increasing order of a lower bound of their distance.
///
/// `node_bound(x, y)` must be at most the distance of every object `i` under box `x` and `j`
/// under box `y` (boxes of nodes hold their objects' boxes); `visit(i, j)` is called for each
/// pair not pruned and answers the best distance so far. The search stops when the next node
/// pair's bound exceeds that best distance: every pair whose node bound is at most the best is
/// visited (in no particular order), so a caller that keeps the smallest (distance, i, j) gets
/// the same answer as a scan of all pairs.
pub fn best_first(
    ta: &ObjectTree,
    tb: &ObjectTree,
    same: bool,
    node_bound: impl Fn(&Aabb, &Aabb) -> f64,
    mut visit: impl FnMut(usize, usize) -> f64,
) {
    if ta.nodes.is_empty() || tb.nodes.is_empty() {
        return;
    }
    let mut best = f64::INFINITY;
    let mut heap = BinaryHeap::new();
    heap.push(Pending(node_bound(&ta.nodes[0].bounds, &tb.nodes[0].bounds), 0, 0));
    while let Some(Pending(lb, x, y)) = heap.pop() {
        if lb > best {
            break;
        }
        let (nx, ny) = (&ta.nodes[x], &tb.nodes[y]);
        match (nx.is_leaf(), ny.is_leaf()) {
            (true, true) => {
                for (k, &i) in ta.leaf(x).iter().enumerate() {
                    let from = if same && x == y { k + 1 } else { 0 };
                    for &j in &tb.leaf(y)[from..] {
                        let (i, j) = if same { (i.min(j), i.max(j)) } else { (i, j) };
                        best = best.min(visit(i, j));
                    }
                }
            }
            _ if same && x == y => {
                let [c, d] = ta.children(x);
                for (p, q) in [(c, c), (c, d), (d, d)] {
                    let b = node_bound(&ta.nodes[p].bounds, &ta.nodes[q].bounds);
                    if b <= best {
                        heap.push(Pending(b, p, q));
                    }
                }
            }
            (leaf_x, leaf_y) => {
                let open_x = !leaf_x && (leaf_y || nx.bounds.half_area() >= ny.bounds.half_area());
                let pairs =
                    if open_x { ta.children(x).map(|c| (c, y)) } else { tb.children(y).map(|c| (x, c)) };
                for (p, q) in pairs {
                    let b = node_bound(&ta.nodes[p].bounds, &tb.nodes[q].bounds);
                    if b <= best {
                        heap.push(Pending(b, p, q));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3;

    /// Random boxes; the search visits every pair whose bound is at most the best, and the
    /// smallest (bound, i, j) it keeps is the brute-force minimum.
    #[test]
    fn best_first_finds_the_brute_force_minimum() {
        let mut next = crate::load::test_rng(0x2545_f491_4f6c_dd1d);
        let mut rnd = || next(1 << 30) as f64 / (1u64 << 30) as f64;
        for n in [1usize, 2, 3, 5, 17, 100] {
            let boxes: Vec<Aabb> = (0..n)
                .map(|_| {
                    let c = DVec3::new(rnd(), rnd(), rnd()) * 100.0;
                    let h = DVec3::new(rnd(), rnd(), rnd()) * 3.0;
                    Aabb { min: c - h, max: c + h }
                })
                .collect();
            let d = |i: usize, j: usize| boxes[i].distance_sq(&boxes[j]).sqrt();
            let order = |x: &(f64, usize, usize), y: &(f64, usize, usize)| {
                x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2)))
            };
            // The smallest (distance, i, j) the search keeps, against the brute-force minimum
            // over `pairs`.
            let check = |ta: &ObjectTree, tb: &ObjectTree, same: bool, pairs: Vec<(usize, usize)>| {
                let mut best = (f64::INFINITY, usize::MAX, usize::MAX);
                best_first(
                    ta,
                    tb,
                    same,
                    |x, y| x.distance_sq(y).sqrt(),
                    |i, j| {
                        assert!(!same || i < j);
                        let c = (d(i, j), i, j);
                        if order(&c, &best).is_lt() {
                            best = c;
                        }
                        best.0
                    },
                );
                let brute = pairs.into_iter().map(|(i, j)| (d(i, j), i, j)).min_by(order);
                assert_eq!(Some(best).filter(|b| b.1 != usize::MAX), brute, "n = {n}");
            };
            // Internal pairs.
            let t = ObjectTree::build(&boxes, (0..n).collect());
            check(&t, &t, true, (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j))).collect());
            // Pairs between two lists (the first half against the rest).
            let (a, b): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| i < n / 2);
            let (ta, tb) = (ObjectTree::build(&boxes, a.clone()), ObjectTree::build(&boxes, b.clone()));
            check(&ta, &tb, false, a.iter().flat_map(|&i| b.iter().map(move |&j| (i, j))).collect());
        }
    }
}
