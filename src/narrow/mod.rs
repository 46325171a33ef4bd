//! Narrow phase kernels on one triangle pair: [`tri_tri`] classifies a pair exactly (orientation
//! predicates from [`crate::geom::predicates`]); [`distance`] gives closed-form triangle–triangle
//! and point–triangle distances; [`exact_distance`] the exact distance where a threshold or a
//! reported figure needs it.

pub mod convex;
pub mod distance;
pub mod exact_distance;
pub mod tri_tri;
