//! Top-down construction. Large subtrees are built in parallel with `rayon::join` and
//! concatenated (depth-first order is preserved, so the result does not depend on the thread
//! count); small ones are built with an explicit stack, so no input can overflow the call stack.

use super::{BuildOptions, Bvh, Node, Strategy};
use crate::geom::{Aabb, DVec3};

/// SAH bins per axis. Wald (2007) reports 16–32 bins lose almost nothing against a full sweep.
const BINS: usize = 16;
/// Subtrees larger than this are split across threads.
const PAR_THRESHOLD: usize = 16 * 1024;
/// Beyond this depth parallel recursion stops (bounds the call stack on lopsided splits).
const PAR_MAX_DEPTH: usize = 32;

/// A triangle's box, centroid and index, moved around as one so that every pass over a
/// subtree's triangles reads memory in order (random access by index was the build's bottleneck).
#[derive(Clone, Copy)]
struct Item {
    bounds: Aabb,
    cent: DVec3,
    idx: u32,
}

struct Input {
    opts: BuildOptions,
}

pub(super) fn build(boxes: &[Aabb], opts: BuildOptions) -> Bvh {
    let opts = BuildOptions { leaf_size: opts.leaf_size.clamp(1, 255), ..opts };
    if boxes.is_empty() {
        return Bvh { nodes: Vec::new(), prims: Vec::new() };
    }
    let mut items: Vec<Item> =
        boxes.iter().enumerate().map(|(i, b)| Item { bounds: *b, cent: b.center(), idx: i as u32 }).collect();
    let input = Input { opts };
    let nodes = subtree(&input, &mut items, 0, 0);
    Bvh { nodes, prims: items.iter().map(|it| it.idx).collect() }
}

fn bounds_of(items: &[Item]) -> Aabb {
    items.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds))
}

fn subtree(input: &Input, prims: &mut [Item], base: u32, depth: usize) -> Vec<Node> {
    if prims.len() <= PAR_THRESHOLD || depth >= PAR_MAX_DEPTH {
        return sequential(input, prims, base);
    }
    let bounds = bounds_of(prims);
    let mid = split(input, prims);
    let (l, r) = prims.split_at_mut(mid);
    let (ln, rn) = rayon::join(
        || subtree(input, l, base, depth + 1),
        || subtree(input, r, base + mid as u32, depth + 1),
    );
    let mut nodes = Vec::with_capacity(1 + ln.len() + rn.len());
    nodes.push(Node { bounds, a: 1 + ln.len() as u32, count: 0 });
    for part in [ln, rn] {
        let off = nodes.len() as u32;
        nodes.extend(part.into_iter().map(|mut n| {
            if !n.is_leaf() {
                n.a += off;
            }
            n
        }));
    }
    nodes
}

/// Depth-first build of one subtree with an explicit stack. Node indices are local.
fn sequential(input: &Input, prims: &mut [Item], base: u32) -> Vec<Node> {
    let mut nodes: Vec<Node> = Vec::with_capacity(2 * prims.len() / input.opts.leaf_size as usize + 1);
    // (start, end, parent whose right child this is)
    let mut stack: Vec<(usize, usize, Option<usize>)> = vec![(0, prims.len(), None)];
    while let Some((start, end, right_of)) = stack.pop() {
        let idx = nodes.len();
        if let Some(p) = right_of {
            nodes[p].a = idx as u32;
        }
        let slice = &mut prims[start..end];
        let bounds = bounds_of(slice);
        if slice.len() <= input.opts.leaf_size as usize {
            nodes.push(Node { bounds, a: base + start as u32, count: slice.len() as u32 });
            continue;
        }
        let mid = start + split(input, slice);
        nodes.push(Node { bounds, a: 0, count: 0 });
        stack.push((mid, end, Some(idx)));
        stack.push((start, mid, None));
    }
    nodes
}

/// Partition `prims` in place and return the split point, in `1..prims.len()`.
fn split(input: &Input, prims: &mut [Item]) -> usize {
    let n = prims.len();
    let cb = prims.iter().fold(Aabb::EMPTY, |b, it| b.grow(it.cent));
    let ext = cb.extent();
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    if ext[axis] <= 0.0 {
        return n / 2; // all centroids coincide: any split is as good as another
    }
    let mid = match input.opts.strategy {
        Strategy::Sah => sah_split(prims, &cb),
        Strategy::Median => {
            let plane = cb.center()[axis];
            partition(prims, |it| it.cent[axis] < plane)
        }
        Strategy::Equal => {
            let k = n / 2;
            prims.select_nth_unstable_by(k, |p, q| {
                p.cent[axis].total_cmp(&q.cent[axis]).then(p.idx.cmp(&q.idx))
            });
            k
        }
    };
    if mid == 0 || mid == n {
        n / 2
    } else {
        mid
    }
}

#[inline]
fn bin_of(c: f64, min: f64, scale: f64, nb: usize) -> usize {
    (((c - min) * scale) as usize).min(nb - 1)
}

/// Bins used for a node of `n` triangles: 16 for large nodes; fewer for small ones, where the
/// fixed cost of clearing and sweeping 3 × 16 bins dominated the build (a bin per two triangles
/// is still finer than the triangles can be split).
#[inline]
fn bins_for(n: usize) -> usize {
    (n / 2).clamp(2, BINS)
}

/// Binned SAH over all three axes (one pass over the triangles bins them on all three);
/// returns the partition point.
fn sah_split(prims: &mut [Item], cb: &Aabb) -> usize {
    let ext = cb.extent();
    let nb = bins_for(prims.len());
    let scale = DVec3::splat(nb as f64) / ext; // inf on flat axes: those are skipped below
    let mut counts = [[0usize; BINS]; 3];
    let mut boxes = [[Aabb::EMPTY; BINS]; 3];
    for it in prims.iter() {
        for axis in 0..3 {
            if ext[axis] > 0.0 {
                let b = bin_of(it.cent[axis], cb.min[axis], scale[axis], nb);
                counts[axis][b] += 1;
                boxes[axis][b] = boxes[axis][b].union(it.bounds);
            }
        }
    }
    let mut best = (f64::INFINITY, 0usize, 0usize); // (cost, axis, first bin of the right side)
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
            continue;
        }
        let (counts, boxes) = (&counts[axis], &boxes[axis]);
        // Right-to-left sweep: area and count of bins[i..].
        let mut right = [(0.0f64, 0usize); BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..nb).rev() {
            acc = acc.union(boxes[i]);
            cnt += counts[i];
            right[i] = (acc.half_area(), cnt);
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 1..nb {
            acc = acc.union(boxes[i - 1]);
            cnt += counts[i - 1];
            let (ra, rc) = right[i];
            if cnt == 0 || rc == 0 {
                continue;
            }
            let cost = acc.half_area() * cnt as f64 + ra * rc as f64;
            if cost < best.0 {
                best = (cost, axis, i);
            }
        }
    }
    if !best.0.is_finite() {
        return prims.len() / 2;
    }
    let (_, axis, split_bin) = best;
    let (min, scale) = (cb.min[axis], scale[axis]);
    partition(prims, |it| bin_of(it.cent[axis], min, scale, nb) < split_bin)
}

/// In-place partition (deterministic): elements satisfying `left` first; returns their count.
fn partition(prims: &mut [Item], left: impl Fn(&Item) -> bool) -> usize {
    let mut i = 0;
    for j in 0..prims.len() {
        if left(&prims[j]) {
            prims.swap(i, j);
            i += 1;
        }
    }
    i
}
