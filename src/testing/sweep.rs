//! A full-sweep SAH builder, only to measure how far the binned SAH of [`crate::bvh`] is from
//! it: every node sorts its triangles by centroid on each axis and evaluates all `n - 1` split
//! positions. Same termination as the binned build (split until a node has at most `leaf_size`
//! triangles) and the same node layout, so [`Bvh::stats`] costs are comparable.

use crate::bvh::{Bvh, Node};
use crate::geom::{Aabb, DVec3};

#[derive(Clone, Copy)]
struct Item {
    bounds: Aabb,
    cent: DVec3,
    idx: u32,
}

/// Build with a full SAH sweep (sequential; O(n log² n)).
pub fn build_full_sweep(boxes: &[Aabb], leaf_size: u32) -> Bvh {
    let leaf_size = leaf_size.clamp(1, 255) as usize;
    if boxes.is_empty() {
        return Bvh { nodes: Vec::new(), prims: Vec::new() };
    }
    let mut items: Vec<Item> =
        boxes.iter().enumerate().map(|(i, b)| Item { bounds: *b, cent: b.center(), idx: i as u32 }).collect();
    let mut nodes: Vec<Node> = Vec::new();
    let mut right_area = vec![0.0f64; items.len()];
    let mut stack: Vec<(usize, usize, Option<usize>)> = vec![(0, items.len(), None)];
    while let Some((start, end, right_of)) = stack.pop() {
        let idx = nodes.len();
        if let Some(p) = right_of {
            nodes[p].a = idx as u32;
        }
        let slice = &mut items[start..end];
        let bounds = slice.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds));
        let n = slice.len();
        if n <= leaf_size {
            nodes.push(Node { bounds, a: start as u32, count: n as u32 });
            continue;
        }
        let mut best = (f64::INFINITY, 0usize, n / 2);
        for axis in 0..3 {
            sort_axis(slice, axis);
            let mut acc = Aabb::EMPTY;
            for i in (1..n).rev() {
                acc = acc.union(slice[i].bounds);
                right_area[i] = acc.half_area();
            }
            let mut acc = Aabb::EMPTY;
            for i in 1..n {
                acc = acc.union(slice[i - 1].bounds);
                let cost = acc.half_area() * i as f64 + right_area[i] * (n - i) as f64;
                if cost < best.0 {
                    best = (cost, axis, i);
                }
            }
        }
        sort_axis(slice, best.1);
        let mid = start + best.2;
        nodes.push(Node { bounds, a: 0, count: 0 });
        stack.push((mid, end, Some(idx)));
        stack.push((start, mid, None));
    }
    Bvh { nodes, prims: items.iter().map(|it| it.idx).collect() }
}

fn sort_axis(s: &mut [Item], axis: usize) {
    s.sort_unstable_by(|p, q| p.cent[axis].total_cmp(&q.cent[axis]).then(p.idx.cmp(&q.idx)));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, Bvh};

    #[test]
    fn full_sweep_is_valid_and_not_worse_than_binned() {
        let m = crate::testing::gen::torus(4000);
        let boxes: Vec<Aabb> =
            (0..m.triangles.len() as u32).map(|t| Aabb::of_triangle(&crate::bvh::triangle(&m, t))).collect();
        let full = build_full_sweep(&boxes, 4);
        full.validate(&boxes, 4).unwrap();
        let binned = Bvh::build(&m, BuildOptions::default());
        assert!(full.stats().sah_cost <= binned.stats().sah_cost * 1.02);
    }
}
