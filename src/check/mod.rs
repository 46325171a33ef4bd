//! The checks run over two meshes: [`query`] (candidate pairs, exact classification, closest
//! pair), [`assembly`] (parts, placements, the part-pair run over [`query`]), [`containment`]
//! (closed-mesh topology and winding numbers), [`regions`] (clash regions and penetration
//! estimates), [`cross_check`] (the parry3d reference comparison), [`self_clash`] and [`health`]
//! (one mesh checked against itself: self-clash pairs and mesh health).

pub mod assembly;
pub mod containment;
pub mod cross_check;
pub mod fans;
pub mod finding_id;
pub mod health;
pub mod overlap;
pub mod query;
pub mod regions;
pub mod self_clash;
