//! Invariant checks and statistics (obvhs-style `validate()`): run in tests and debug builds.

use super::{Bvh, Stats};
use crate::geom::Aabb;

pub(super) fn validate(bvh: &Bvh, tri_boxes: &[Aabb], leaf_size: u32) -> Result<(), String> {
    let n = tri_boxes.len();
    if bvh.prims.len() != n {
        return Err(format!("{} prims for {} triangles", bvh.prims.len(), n));
    }
    if n == 0 {
        return if bvh.nodes.is_empty() { Ok(()) } else { Err("nodes without triangles".into()) };
    }
    let mut seen = vec![false; n];
    let mut visited = 0usize;
    // (node, parent box)
    let mut stack = vec![(0usize, bvh.nodes[0].bounds)];
    let mut expect_next = 0usize; // depth-first order: nodes are visited in index order
    while let Some((i, parent)) = stack.pop() {
        if i != expect_next {
            return Err(format!("node {i} out of depth-first order (expected {expect_next})"));
        }
        expect_next += 1;
        visited += 1;
        let node = bvh.nodes.get(i).ok_or_else(|| format!("child index {i} out of range"))?;
        if !parent.contains(&node.bounds) {
            return Err(format!("node {i} box is not inside its parent's"));
        }
        if node.is_leaf() {
            if node.count > leaf_size.max(1) {
                return Err(format!("leaf {i} holds {} > {leaf_size} triangles", node.count));
            }
            let end = (node.a + node.count) as usize;
            if end > n {
                return Err(format!("leaf {i} range {}..{end} out of range", node.a));
            }
            let mut tight = Aabb::EMPTY;
            for &p in bvh.leaf_prims(node) {
                let p = p as usize;
                if p >= n || std::mem::replace(&mut seen[p], true) {
                    return Err(format!("triangle {p} missing or in two leaves"));
                }
                if !node.bounds.contains(&tri_boxes[p]) {
                    return Err(format!("leaf {i} does not contain triangle {p}"));
                }
                tight = tight.union(tri_boxes[p]);
            }
            if tight != node.bounds {
                return Err(format!("leaf {i} box is not tight"));
            }
        } else {
            let (l, r) = (i + 1, node.a as usize);
            if r <= l || r >= bvh.nodes.len() {
                return Err(format!("node {i} has right child {r}"));
            }
            let (lb, rb) = (bvh.nodes[l].bounds, bvh.nodes[r].bounds);
            if lb.union(rb) != node.bounds {
                return Err(format!("node {i} box is not the union of its children's"));
            }
            stack.push((r, node.bounds));
            stack.push((l, node.bounds));
        }
    }
    if visited != bvh.nodes.len() {
        return Err(format!("{} nodes unreachable", bvh.nodes.len() - visited));
    }
    if let Some(p) = seen.iter().position(|s| !s) {
        return Err(format!("triangle {p} in no leaf"));
    }
    Ok(())
}

pub(super) fn stats(bvh: &Bvh) -> Stats {
    let bytes = bvh.nodes.len() * std::mem::size_of::<super::Node>() + bvh.prims.len() * 4;
    let mut s = Stats { nodes: bvh.nodes.len(), leaves: 0, depth: 0, sah_cost: 0.0, bytes, cells: 0 };
    let Some(root) = bvh.nodes.first() else {
        return s;
    };
    let root_area = root.bounds.half_area();
    let mut stack = vec![(0usize, 0usize)];
    let mut cost = 0.0;
    while let Some((i, d)) = stack.pop() {
        let node = &bvh.nodes[i];
        let rel = if root_area > 0.0 { node.bounds.half_area() / root_area } else { 1.0 };
        if node.is_leaf() {
            s.leaves += 1;
            s.depth = s.depth.max(d);
            cost += rel * node.count as f64;
        } else {
            cost += rel;
            stack.push((node.a as usize, d + 1));
            stack.push((i + 1, d + 1));
        }
    }
    s.sah_cost = cost;
    s
}
