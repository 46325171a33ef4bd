//! Narrow phase kernels on one triangle pair: [`tri_tri`] classifies a pair exactly (orientation
//! predicates from [`crate::geom::predicates`]); [`distance`] gives closed-form triangle–triangle
//! and point–triangle distances.

pub mod convex;
pub mod distance;
pub mod tri_tri;
