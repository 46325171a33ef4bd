//! Test support, compiled for the library's unit tests and behind the `testing` feature (the
//! `meshclash-bench` crate and `examples/self_torus.rs` turn it on); not part of a default build.
//!
//! [`gen`]: deterministic generated meshes (tori, crossing and separated pairs, near-degenerate
//! inputs); [`sweep`]: a full-sweep SAH builder that the binned SAH of [`crate::bvh`] is
//! measured against.

pub mod gen;
pub mod sweep;
