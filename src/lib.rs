//! # meshclash
//!
//! Do two triangle meshes clash, where, and how close do they come?
//!
//! The pipeline, one module group per step: [`load`] reads OBJ, STL or glTF into a
//! [`scene::mesh::Mesh`] (f64 positions, u32 triangles, an object per triangle; [`scene`] also
//! holds connected bodies); [`bvh`] builds a bounding volume hierarchy
//! per mesh (binned SAH, Wald 2007) and [`bvh::traverse`] walks both trees together; each
//! candidate triangle pair is classified exactly by [`narrow::tri_tri`] (orientation predicates
//! in the style of Guigue & Devillers 2003, evaluated with Shewchuk's adaptive exact arithmetic
//! from [`geom::predicates`]); when nothing touches, [`narrow::distance`] gives the closed-form
//! triangle–triangle distance (Ericson 2005) for the branch and bound over both trees (Larsen et
//! al. 1999). [`check::query`] orchestrates and returns plain result structs ([`check`] also has
//! assemblies of parts, containment, clash regions and the parry cross-check); [`report`] turns them into the JSON
//! wire format (with [`report::baseline`]: stable finding ids); [`output`] renders text, JUnit
//! and GLB. The library never prints; the command line (clap, the spinner, validation into a
//! configuration, the `clash-set` and `self` runners) is the binary's own module tree
//! (`src/main.rs` and `src/app/`).
#![deny(missing_docs)]

pub mod api;
pub mod bvh;
pub mod cache;
pub mod check;
pub mod error;
pub mod geom;
pub mod load;
pub mod narrow;
pub mod output;
pub mod pipeline;
pub mod prepared;
pub mod report;
pub mod scene;
pub mod shard;
#[cfg(any(test, feature = "testing"))]
pub mod testing;

pub use error::{Error, Result};
