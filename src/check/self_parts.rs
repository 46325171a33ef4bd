//! One mesh checked against itself, part by part: the self-clashing triangle pairs
//! ([`crate::check::self_clash`]) and the health ([`crate::check::health`]) of each chosen part,
//! and the conditions a `meshclash self` run can fail on.

use crate::bvh::BuildOptions;
use crate::check::health::{self, Health};
use crate::check::self_clash::{self, SelfPair};
use std::time::Instant;

/// `--fail-on` values of `self`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum SelfFailOn {
    /// Crossing self-clash pairs (the default).
    SelfClash,
    /// Any self-clash pair, crossing or touching.
    Touching,
    /// A part that is not closed.
    Open,
    /// Non-manifold edges or vertices.
    NonManifold,
    /// Duplicate faces.
    Duplicates,
    /// Zero-area triangles.
    Degenerate,
    /// Edges used twice in the same direction.
    Winding,
    /// Never fail on findings.
    Never,
}

impl SelfFailOn {
    /// Name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            SelfFailOn::SelfClash => "self-clash",
            SelfFailOn::Touching => "touching",
            SelfFailOn::Open => "open",
            SelfFailOn::NonManifold => "non-manifold",
            SelfFailOn::Duplicates => "duplicates",
            SelfFailOn::Degenerate => "degenerate",
            SelfFailOn::Winding => "winding",
            SelfFailOn::Never => "never",
        }
    }

    /// Does this part's result meet the condition?
    pub fn hit(self, part: &PartResult) -> bool {
        let h = &part.health;
        match self {
            SelfFailOn::SelfClash => part.crossing > 0,
            SelfFailOn::Touching => !part.pairs.is_empty(),
            SelfFailOn::Open => !h.closed,
            SelfFailOn::NonManifold => h.non_manifold_edges.count + h.non_manifold_vertices.count > 0,
            SelfFailOn::Duplicates => h.duplicate_faces.count > 0,
            SelfFailOn::Degenerate => h.zero_area_triangles.count > 0,
            SelfFailOn::Winding => h.inconsistent_winding_edges.count > 0,
            SelfFailOn::Never => false,
        }
    }
}

/// The result for one part.
#[derive(Debug, Clone, PartialEq)]
pub struct PartResult {
    /// Object index in the (possibly split) mesh; None for `--whole-file`.
    pub object: Option<u32>,
    /// Its name.
    pub name: String,
    /// Its triangles (indices into the mesh).
    pub triangles: usize,
    /// Its self-clashing pairs, sorted by (a, b).
    pub pairs: Vec<SelfPair>,
    /// How many of them cross.
    pub crossing: u64,
    /// Its health.
    pub health: Health,
}

/// Which parts [`check_parts`] checks.
pub enum PartChoice<'a> {
    /// Every object (object order) whose name passes the filter.
    Objects(&'a dyn Fn(&str) -> bool),
    /// All triangles as one part with this name.
    Whole(&'a str),
}

/// Self-clash and health of the chosen parts of `mesh`, with the milliseconds spent on health
/// (with the vertex merge) and on the self-clash walks (the two run at the same time, so their
/// times overlap).
pub fn check_parts(
    mesh: &crate::scene::mesh::Mesh,
    choice: PartChoice,
    opts: BuildOptions,
    first_n: usize,
) -> (Vec<PartResult>, f64, f64) {
    let t = Instant::now();
    let (merged, _) = crate::scene::bodies::merge_vertices(&mesh.positions);
    let parts: Vec<(Option<u32>, String, Vec<u32>)> = match choice {
        PartChoice::Objects(keep) => crate::check::assembly::parts_of(mesh, 0)
            .into_iter()
            .filter(|p| keep(&p.name))
            .map(|p| (Some(p.object), p.name, p.triangles))
            .collect(),
        PartChoice::Whole(name) => vec![(None, name.to_string(), (0..mesh.triangles.len() as u32).collect())],
    };
    let merge_ms = t.elapsed().as_secs_f64() * 1e3;
    // Health and the self-clash walks run side by side: parts of the health pass are
    // sequential (union-find), and the walk fills the other cores meanwhile.
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let ((healths, health_ms), (found, query_ms)) = rayon::join(
        || {
            let t = Instant::now();
            let h: Vec<Health> = parts.iter().map(|p| health::health(mesh, &merged, &p.2, first_n)).collect();
            (h, ms(t))
        },
        || {
            let t = Instant::now();
            let f: Vec<Vec<SelfPair>> =
                parts.iter().map(|p| self_clash::self_pairs(mesh, &merged, &p.2, opts)).collect();
            (f, ms(t))
        },
    );
    let results = parts
        .into_iter()
        .zip(healths.into_iter().zip(found))
        .map(|((object, name, tris), (health, pairs))| {
            let crossing = pairs.iter().filter(|q| q.hit.crossing).count() as u64;
            PartResult { object, name, triangles: tris.len(), pairs, crossing, health }
        })
        .collect();
    (results, merge_ms + health_ms, query_ms)
}
