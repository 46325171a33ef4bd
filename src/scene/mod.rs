//! The scene: what was loaded and how it is arranged. [`mesh`] (f64 positions, u32 triangles,
//! an object per triangle), [`assembly`] (parts, placements, the part-pair run), [`bodies`]
//! (connected bodies, union-find, exact vertex keys).

pub mod assembly;
pub mod bodies;
pub mod mesh;
