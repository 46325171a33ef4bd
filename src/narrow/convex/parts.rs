//! Exact penetration depths of the object pairs of a report: for each pair of objects (one of
//! the A mesh, one of the B mesh, in world coordinates) both closed and exactly convex, the
//! separating-axis depth of [`super::penetration`].
//!
//! An object's triangles are taken as they are in the loaded mesh, with exactly coincident
//! positions welded into one vertex (formats such as STL repeat every vertex per triangle), so
//! convexity and closedness are decided on the solid's surface, not on how the file indexes
//! it. Anything not closed, not consistently oriented or not convex (exactly:
//! [`super::is_convex`]) has no exact depth here.

use super::{is_convex, Penetration, Polytope, Surface};
use crate::geom::DVec3;
use crate::scene::mesh::Mesh;
use rayon::prelude::*;
use std::collections::HashMap;

/// One object as a welded, closed, exactly convex polytope.
#[derive(Debug, Clone)]
pub struct ConvexPart {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    surface: Surface,
}

impl ConvexPart {
    /// The triangles `tris` of `mesh` as a convex polytope, or `None` when they are not the
    /// outward boundary of a convex solid of positive volume.
    pub fn of(mesh: &Mesh, tris: &[u32]) -> Option<ConvexPart> {
        let sub = mesh.sub_mesh(tris);
        let (merged, distinct) = crate::scene::bodies::merge_vertices(&sub.positions);
        let mut positions = vec![DVec3::ZERO; distinct];
        for (i, &m) in merged.iter().enumerate() {
            positions[m as usize] = sub.positions[i];
        }
        let triangles: Vec<[u32; 3]> = sub.triangles.iter().map(|t| t.map(|v| merged[v as usize])).collect();
        let surface = Surface::of(&triangles)?;
        is_convex(&positions, &triangles, &surface).then_some(ConvexPart { positions, triangles, surface })
    }

    /// The polytope the depth computation reads.
    pub fn polytope(&self) -> Polytope<'_> {
        Polytope {
            positions: &self.positions,
            triangles: &self.triangles,
            surface: &self.surface,
            frames: None,
        }
    }
}

/// For each `(object of a, object of b)` in `pairs`, the exact penetration when both objects
/// are convex ([`ConvexPart::of`]) and meet (depth 0 when they only touch); `None` otherwise.
/// `same` says `a` and `b` are one mesh (scene mode): an object is then welded once. Objects
/// and pairs run in parallel; the answers do not depend on the thread count.
pub fn object_pair_penetrations(
    a: &Mesh,
    b: &Mesh,
    same: bool,
    pairs: &[(u32, u32)],
) -> Vec<Option<Penetration>> {
    if pairs.is_empty() {
        return Vec::new();
    }
    let side_b = if same { 0u8 } else { 1u8 };
    let mut wanted: Vec<(u8, u32)> = pairs.iter().flat_map(|&(x, y)| [(0u8, x), (side_b, y)]).collect();
    wanted.sort_unstable();
    wanted.dedup();
    let meshes = [a, b];
    // Each wanted object's triangles, in one pass per mesh.
    let mut tris: HashMap<(u8, u32), Vec<u32>> = wanted.iter().map(|&k| (k, Vec::new())).collect();
    for side in 0..=side_b {
        let m = meshes[side as usize];
        for (t, &o) in m.tri_object.iter().enumerate() {
            if let Some(v) = tris.get_mut(&(side, o)) {
                v.push(t as u32);
            }
        }
    }
    let parts: HashMap<(u8, u32), Option<ConvexPart>> =
        wanted.par_iter().map(|&k| (k, ConvexPart::of(meshes[k.0 as usize], &tris[&k]))).collect();
    let mut distinct: Vec<(u32, u32)> = pairs.to_vec();
    distinct.sort_unstable();
    distinct.dedup();
    let depths: HashMap<(u32, u32), Option<Penetration>> = distinct
        .par_iter()
        .map(|&(x, y)| {
            let depth = parts[&(0, x)]
                .as_ref()
                .zip(parts[&(side_b, y)].as_ref())
                .and_then(|(pa, pb)| super::penetration(&pa.polytope(), &pb.polytope()));
            ((x, y), depth)
        })
        .collect();
    pairs.iter().map(|k| depths[k]).collect()
}
