//! # meshclash
//!
//! Do two triangle meshes clash, where, and how close do they come?
//!
//! The pipeline: [`load`] reads OBJ, STL or glTF into a [`mesh::Mesh`] (f64 positions, u32
//! triangles, an object per triangle); [`bvh`] builds a bounding volume hierarchy per mesh (binned
//! SAH, Wald 2007); [`traverse`] walks both trees together; each candidate triangle pair is
//! classified exactly by [`tri_tri`] (orientation predicates in the style of Guigue & Devillers
//! 2003, evaluated with Shewchuk's adaptive exact arithmetic from [`geom::predicates`]); when
//! nothing touches, [`distance`] finds the closest pair by branch and bound over both trees with
//! closed-form triangle–triangle distance (Ericson 2005; Larsen et al. 1999). [`query`]
//! orchestrates and returns plain result structs; [`report`] turns them into the JSON wire
//! format. The library never prints.
#![deny(missing_docs)]

pub mod assembly;
pub mod bench;
pub mod bodies;
pub mod bvh;
pub mod clash_set;
pub mod cli;
pub mod containment;
pub mod cross_check;
pub mod distance;
pub mod error;
pub mod geom;
pub mod health;
pub mod load;
pub mod mesh;
pub mod output;
pub mod query;
pub mod regions;
pub mod report;
pub mod self_clash;
pub mod self_cmd;
pub mod self_report;
pub mod traverse;
pub mod tri_tri;

pub use error::{Error, Result};
