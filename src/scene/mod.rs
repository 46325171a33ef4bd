//! The scene: what was loaded. [`mesh`] (f64 positions, u32 triangles, an object per
//! triangle) and [`bodies`] (connected bodies, union-find, exact vertex keys).

pub mod bodies;
pub mod mesh;
