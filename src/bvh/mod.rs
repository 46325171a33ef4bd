//! Bounding volume hierarchy over the triangles of one mesh.
//!
//! One flat array of [`Node`]s in depth-first order: an interior node's left child is the next
//! node, its right child is stored in the node. Boxes are f64 and built by `min`/`max` from the
//! input coordinates, so they are exact and never cull a pair that touches.
//!
//! Build strategies ([`Strategy`]): binned SAH (Wald 2007, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies"), and the two classic splits kept for comparison: spatial median
//! of the centroid bounds and equal counts (object median).

mod build;
pub mod lazy;
pub mod slab;
pub mod traverse;
mod validate;

use crate::geom::{Aabb, DVec3};
use crate::scene::mesh::Mesh;

/// A BVH node: 56 bytes (two f64 corners = 48, two u32 = 8), checked at compile time.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct Node {
    /// The box around everything below.
    pub bounds: Aabb,
    /// Leaf: first index into [`Bvh::prims`]. Interior: index of the right child (the left
    /// child is the next node).
    pub a: u32,
    /// Leaf: number of triangles (> 0). Interior: 0.
    pub count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 56);

impl Node {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// How to choose splits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Strategy {
    /// Binned surface-area heuristic (default): best quality.
    #[default]
    Sah,
    /// Split the centroid bounds at the spatial middle of their longest axis.
    Median,
    /// Split at the median centroid along the longest axis (equal counts).
    Equal,
}

impl Strategy {
    /// The name used on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Sah => "sah",
            Strategy::Median => "median",
            Strategy::Equal => "equal",
        }
    }
}

/// Build options.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuildOptions {
    /// The split strategy.
    pub strategy: Strategy,
    /// Largest leaf (1..=255); nodes with at most this many triangles become leaves.
    pub leaf_size: u32,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions { strategy: Strategy::Sah, leaf_size: 4 }
    }
}

/// A BVH over a mesh's triangles.
#[derive(Debug, Clone)]
pub struct Bvh {
    /// Nodes in depth-first order; node 0 is the root.
    pub nodes: Vec<Node>,
    /// Triangle indices, grouped by leaf.
    pub prims: Vec<u32>,
}

/// Size and quality figures of a tree.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    /// Number of nodes.
    pub nodes: usize,
    /// Number of leaves.
    pub leaves: usize,
    /// Deepest leaf (root = 0).
    pub depth: usize,
    /// SAH cost (traversal cost 1, triangle cost 1, relative to the root's area).
    pub sah_cost: f64,
    /// Bytes of nodes + prim indices.
    pub bytes: usize,
    /// Cells left to be built on first use ([`lazy::LazyBvh`]), each counted above as one leaf;
    /// 0 for a tree built whole.
    pub cells: usize,
}

impl Bvh {
    /// Build over all triangles of `mesh`. Uses rayon for large subtrees.
    ///
    /// The build allocates no per-triangle box array: besides the tree (nodes + indices) it
    /// needs 32 bytes per triangle while it chooses the splits, freed before the nodes are
    /// allocated (see `build.rs`).
    pub fn build(mesh: &Mesh, opts: BuildOptions) -> Bvh {
        build::build(mesh.triangles.len(), |t| Aabb::of_triangle(&triangle(mesh, t)), opts)
    }

    /// Build over precomputed triangle boxes.
    pub fn build_from_boxes(boxes: &[Aabb], opts: BuildOptions) -> Bvh {
        build::build(boxes.len(), |t| boxes[t as usize], opts)
    }

    /// The root box.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// The triangles of leaf `n`.
    #[inline]
    pub fn leaf_prims(&self, n: &Node) -> &[u32] {
        &self.prims[n.a as usize..(n.a + n.count) as usize]
    }

    /// The triangles below node `i`: one contiguous run of [`Bvh::prims`] (leaves are stored in
    /// depth-first order).
    pub fn subtree_prims(&self, i: u32) -> &[u32] {
        let nodes = &self.nodes;
        let mut first = i as usize;
        while !nodes[first].is_leaf() {
            first += 1;
        }
        let mut last = i as usize;
        while !nodes[last].is_leaf() {
            last = nodes[last].a as usize;
        }
        let (s, e) = (nodes[first].a as usize, (nodes[last].a + nodes[last].count) as usize);
        &self.prims[s..e]
    }

    /// Check every invariant: each triangle exactly once, leaves non-empty and at most
    /// `leaf_size`, each node's box contains its children's (and its triangles'), child indices
    /// in depth-first order. Returns the first violation found.
    pub fn validate(&self, tri_boxes: &[Aabb], leaf_size: u32) -> Result<(), String> {
        validate::validate(self, tri_boxes, leaf_size)
    }

    /// Node count, depth and SAH cost.
    pub fn stats(&self) -> Stats {
        validate::stats(self)
    }
}

/// The triangle `t` of `mesh` as three points.
#[inline]
pub fn triangle(mesh: &Mesh, t: u32) -> [DVec3; 3] {
    mesh.triangles[t as usize].map(|i| mesh.positions[i as usize])
}
