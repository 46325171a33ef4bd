//! Orchestration: load and place both inputs, build both trees, walk them, classify, and return
//! plain result structs ([`ClashResult`]) that [`crate::report`] turns into JSON.
//!
//! Every candidate pair is classified exactly ([`crate::narrow::tri_tri`]); distances (for tolerance
//! bands, clearance and the closest pair) are f64 closed forms ([`crate::narrow::distance`]).

use crate::bvh::lazy::LazyBvh;
use crate::bvh::slab::{self, Oriented};
use crate::bvh::traverse::{self, Candidate, Tree};
use crate::bvh::{self, BuildOptions};
use crate::check::containment::{self, Containment};
use crate::error::{Error, InputProblem, Location, Result};
use crate::geom::predicates::{self, Tolerances};
use crate::geom::{Aabb, DVec3};
use crate::load::{self, Format};
use crate::narrow::distance::triangle_distance;
use crate::narrow::exact_distance::exact_distance_sq;
use crate::narrow::tri_tri::{self, Contact};
use crate::scene::mesh::{Mesh, TriMesh};
use glam::DMat4;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::Instant;

/// One input file and where to put it.
#[derive(Debug, Clone, PartialEq)]
pub struct InputSpec {
    /// The mesh file.
    pub path: PathBuf,
    /// Affine placement applied to every vertex (in f64) after loading.
    pub transform: DMat4,
}

/// What to look for and how (default: exact contacts only, SAH tree with leaves of 4).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Settings {
    /// Touch tolerance and clearance.
    pub tolerances: Tolerances,
    /// BVH build options.
    pub bvh: BuildOptions,
    /// Exact (default) or fast predicates.
    pub mode: Mode,
    /// Stop at the first crossing pair (a pass/fail gate): counts become lower bounds.
    pub first_hit: bool,
    /// Allowed error of the minimum distance: the reported distance `d` satisfies
    /// `d <= (1 + rel) * true + abs` (PQP-style). Zero (default) = the f64 minimum.
    pub distance_error: DistanceError,
    /// Keep every triangle pair for the report ([`Detail::Pairs`], default) or only the part
    /// pairs' verdicts, counts and witnesses ([`Detail::Parts`]).
    pub detail: Detail,
}

/// How much of what a check finds is kept for the report. Verdicts, counts and closest points
/// are the same in both; [`Detail::Parts`] gives up the triangle-pair lists (and the clash
/// regions and finding ids made from them), so memory no longer grows with the number of
/// meeting triangle pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detail {
    /// Every meeting triangle pair is kept (the report lists up to `max_pairs` of them).
    #[default]
    Pairs,
    /// A pair's triangle list is dropped as soon as its verdict no longer needs it.
    Parts,
}

impl Detail {
    /// Name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            Detail::Pairs => "pairs",
            Detail::Parts => "parts",
        }
    }
}

/// The speed/accuracy trade of the pair classification.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// Exact predicates (adaptive precision): verdicts exact for the coordinates as given.
    #[default]
    Exact,
    /// Plain f64 determinants without exact fallback: gives up exactness on nearly
    /// touching or nearly coplanar pairs (a sign may flip or vanish).
    Fast,
}

impl Mode {
    /// Name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Exact => "exact",
            Mode::Fast => "fast",
        }
    }
}

/// Approximate-distance bounds (see [`Settings::distance_error`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DistanceError {
    /// Relative error allowed.
    pub rel: f64,
    /// Absolute error allowed (model units).
    pub abs: f64,
}

/// A loaded, placed input.
#[derive(Debug, Clone)]
pub struct Input {
    /// Where it came from.
    pub path: PathBuf,
    /// Its format.
    pub format: Format,
    /// The mesh in world coordinates.
    pub mesh: Mesh,
    /// Loader warnings (harmless oddities skipped).
    pub warnings: Vec<String>,
}

/// Load `spec.path` and apply `spec.transform`.
pub fn load_input(spec: &InputSpec) -> Result<Input> {
    let (loaded, format) = load::load_path(&spec.path)?;
    prepare_input(spec, loaded, format, 1.0, None)
}

/// Turn a loaded file into an input: multiply its coordinates by `multiplier` (a unit
/// conversion; 1 = none), apply the placement, check the range. `note` is a warning placed after
/// the loader's (e.g. that the units were assumed).
pub fn prepare_input(
    spec: &InputSpec,
    loaded: crate::scene::mesh::Loaded,
    format: load::Format,
    multiplier: f64,
    note: Option<String>,
) -> Result<Input> {
    let mut mesh = loaded.mesh;
    let mut warnings = loaded.warnings;
    warnings.extend(note);
    mesh.scale(multiplier);
    if spec.transform != DMat4::IDENTITY {
        place(&mut mesh, &spec.transform, &spec.path)?;
    }
    warnings.extend(check_range(&mesh, &spec.path)?);
    Ok(Input { path: spec.path.clone(), format, mesh, warnings })
}

/// The exact predicates need every coordinate to be 0 or within
/// [`predicates::MIN_EXACT_MAGNITUDE`], [`predicates::MAX_EXACT_MAGNITUDE`]: larger ones are an
/// error (no verdict could be trusted), smaller non-zero ones a warning (only pairs whose
/// coordinate differences are all that small could be misjudged).
pub fn check_range(mesh: &Mesh, path: &Path) -> Result<Vec<String>> {
    let mut tiny: Option<(usize, f64)> = None;
    let mut tiny_count = 0usize;
    for (i, p) in mesh.positions.iter().enumerate() {
        for c in p.to_array() {
            let m = c.abs();
            if m > predicates::MAX_EXACT_MAGNITUDE {
                return Err(Error::at(
                    path,
                    Location::Vertex(i),
                    InputProblem::CoordinateBeyondExactRange { coordinate: c },
                ));
            }
            if m != 0.0 && m < predicates::MIN_EXACT_MAGNITUDE {
                tiny_count += 1;
                tiny.get_or_insert((i, c));
            }
        }
    }
    Ok(tiny.map(|(i, c)| tiny_warning(tiny_count, i, c)).into_iter().collect())
}

/// Apply an affine transform to every vertex (f64), rejecting non-finite results.
pub fn place(mesh: &mut Mesh, m: &DMat4, path: &Path) -> Result<()> {
    for (i, p) in mesh.positions.iter_mut().enumerate() {
        *p = m.transform_point3(*p);
        if !p.is_finite() {
            return Err(Error::at(
                path,
                Location::Vertex(i),
                InputProblem::NonFiniteAfterTransform { value: None },
            ));
        }
    }
    Ok(())
}

/// How a listed pair meets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PairKind {
    /// The interiors cross: a real penetration.
    Crossing,
    /// They share points without crossing, or (with a touch tolerance) come within it.
    Touching,
    /// Closer than the clearance, not touching.
    Clearance,
}

impl PairKind {
    /// Name in the report.
    pub fn name(self) -> &'static str {
        match self {
            PairKind::Crossing => "crossing",
            PairKind::Touching => "touching",
            PairKind::Clearance => "clearance",
        }
    }
}

/// One triangle pair worth reporting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairFinding {
    /// Triangle index in input A.
    pub a: u32,
    /// Triangle index in input B.
    pub b: u32,
    /// How they meet.
    pub kind: PairKind,
    /// The exact contact shape; `None` for pairs that only come within a tolerance.
    pub contact: Option<Contact>,
    /// 0 for exact contacts, else the f64 distance.
    pub distance: f64,
    /// The shared segment (f64) for non-coplanar contacts.
    pub segment: Option<[DVec3; 2]>,
}

/// The closest pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// The distance (0 when the inputs touch or cross).
    pub distance: f64,
    /// Triangle in A and the witness point on it.
    pub a: (u32, DVec3),
    /// Triangle in B and the witness point on it.
    pub b: (u32, DVec3),
}

/// Overall answer, ordered by severity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Verdict {
    /// Nothing within the clearance.
    Clear,
    /// Some pair closer than the clearance.
    Clearance,
    /// Some pair touches (exactly, or within the touch tolerance), none crosses.
    Touching,
    /// Some pair crosses, or one part lies inside the other.
    Clash,
}

impl Verdict {
    /// Name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Clear => "clear",
            Verdict::Clearance => "clearance",
            Verdict::Touching => "touching",
            Verdict::Clash => "clash",
        }
    }
}

/// Counts over all pairs (never truncated).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Counts {
    /// Crossing pairs.
    pub crossing: u64,
    /// Touching pairs (exact contact or within the touch tolerance).
    pub touching: u64,
    /// Of the touching pairs, those that only come within the touch tolerance.
    pub within_tolerance: u64,
    /// Clearance pairs.
    pub clearance: u64,
}

impl Counts {
    /// The verdict the pairs alone imply: any crossing is a clash, else any touching pair
    /// touches, else any pair within the clearance is a clearance finding.
    pub fn verdict(&self) -> Verdict {
        if self.crossing > 0 {
            Verdict::Clash
        } else if self.touching > 0 {
            Verdict::Touching
        } else if self.clearance > 0 {
            Verdict::Clearance
        } else {
            Verdict::Clear
        }
    }

    /// Count one pair; returns the verdict that pair alone implies.
    pub fn record(&mut self, p: &PairFinding) -> Verdict {
        match p.kind {
            PairKind::Crossing => {
                self.crossing += 1;
                Verdict::Clash
            }
            PairKind::Touching => {
                self.touching += 1;
                self.within_tolerance += p.contact.is_none() as u64;
                Verdict::Touching
            }
            PairKind::Clearance => {
                self.clearance += 1;
                Verdict::Clearance
            }
        }
    }

    /// Every counted pair (crossing, touching or clearance).
    pub fn total(&self) -> u64 {
        self.crossing + self.touching + self.clearance
    }

    /// Add another set of counts.
    pub fn merge(&mut self, o: &Counts) {
        self.crossing += o.crossing;
        self.touching += o.touching;
        self.within_tolerance += o.within_tolerance;
        self.clearance += o.clearance;
    }
}

/// Facts about one input.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshInfo {
    /// Vertex count.
    pub vertices: usize,
    /// Triangle count.
    pub triangles: usize,
    /// Zero-area triangles (handled as segments or points).
    pub degenerate_triangles: usize,
    /// Objects: name and triangle count, in file order.
    pub objects: Vec<(String, usize)>,
    /// World bounds.
    pub bounds: Aabb,
}

impl MeshInfo {
    /// Summarise a mesh.
    pub fn of(mesh: &Mesh) -> MeshInfo {
        let degenerate_triangles = (0..mesh.triangles.len() as u32)
            .into_par_iter()
            .filter(|&t| {
                // Zero area exactly when collinear (as `tri_tri::Shape::of` decides).
                let [a, b, c] = bvh::triangle(mesh, t);
                predicates::collinear(a, b, c)
            })
            .count();
        let mut counts = vec![0usize; mesh.objects.len()];
        for &o in &mesh.tri_object {
            counts[o as usize] += 1;
        }
        MeshInfo {
            vertices: mesh.positions.len(),
            triangles: mesh.triangles.len(),
            degenerate_triangles,
            objects: mesh.objects.iter().map(|o| o.name.clone()).zip(counts).collect(),
            bounds: Aabb::of_points(&mesh.positions),
        }
    }
}

/// What one placed part of an instanced scene adds to its input's summary and range check.
struct PartSummary {
    vertices: usize,
    triangles: usize,
    degenerate: usize,
    bounds: Aabb,
    /// The box of its triangles (the box the check's broad phase gives the part).
    triangle_bounds: Aabb,
    /// The first coordinate beyond the exact range: (part-local vertex, coordinate).
    beyond: Option<(usize, f64)>,
    /// Non-zero coordinates below the exact range, and the first: (part-local vertex, coordinate).
    tiny: (usize, Option<(usize, f64)>),
}

impl PartSummary {
    fn of(positions: &[DVec3], triangles: &[[u32; 3]]) -> PartSummary {
        let (mut degenerate, mut triangle_bounds) = (0usize, Aabb::EMPTY);
        for t in triangles {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            degenerate += predicates::collinear(a, b, c) as usize;
            triangle_bounds = triangle_bounds.union(Aabb::of_triangle(&[a, b, c]));
        }
        let (mut beyond, mut tiny) = (None, (0usize, None));
        'scan: for (i, p) in positions.iter().enumerate() {
            for c in p.to_array() {
                let m = c.abs();
                if m > predicates::MAX_EXACT_MAGNITUDE {
                    beyond = Some((i, c));
                    break 'scan;
                }
                if m != 0.0 && m < predicates::MIN_EXACT_MAGNITUDE {
                    tiny.0 += 1;
                    tiny.1.get_or_insert((i, c));
                }
            }
        }
        PartSummary {
            vertices: positions.len(),
            triangles: triangles.len(),
            degenerate,
            bounds: Aabb::of_points(positions),
            triangle_bounds,
            beyond,
            tiny,
        }
    }
}

/// The summary ([`MeshInfo::of`]) and the range check ([`check_range`]) of an instanced
/// scene's expanded mesh, with every number, warning and error the same, placing each part once
/// (in parallel, never all at once). Parts never share vertices, so the counts add up part by
/// part; the box and the first out-of-range vertex are taken in part order. Also each part's
/// triangle box, in part order, for the check ([`crate::check::assembly::run_instanced`]).
pub fn scene_info(scene: &load::InstancedScene, path: &Path) -> Result<(MeshInfo, Vec<String>, Vec<Aabb>)> {
    let parts: Vec<PartSummary> = (0..scene.parts.len())
        .into_par_iter()
        .map(|k| match scene.place(k) {
            Ok((positions, triangles)) => Ok(PartSummary::of(&positions, &triangles)),
            Err(e) => Err(e),
        })
        .collect::<Result<_>>()?;
    let (mut vertices, mut triangles, mut degenerate) = (0usize, 0usize, 0usize);
    let mut bounds = Aabb::EMPTY;
    let (mut tiny_count, mut tiny) = (0usize, None);
    for p in &parts {
        if let Some((i, c)) = p.beyond {
            let problem = InputProblem::CoordinateBeyondExactRange { coordinate: c };
            return Err(Error::at(path, Location::Vertex(vertices + i), problem));
        }
        tiny_count += p.tiny.0;
        if tiny.is_none() {
            tiny = p.tiny.1.map(|(i, c)| (vertices + i, c));
        }
        vertices += p.vertices;
        triangles += p.triangles;
        degenerate += p.degenerate;
        bounds = bounds.union(p.bounds);
    }
    let info = MeshInfo {
        vertices,
        triangles,
        degenerate_triangles: degenerate,
        objects: scene.parts.iter().zip(&parts).map(|(s, p)| (s.name.clone(), p.triangles)).collect(),
        bounds,
    };
    let warnings = tiny.map(|(i, c)| tiny_warning(tiny_count, i, c)).into_iter().collect();
    Ok((info, warnings, parts.iter().map(|p| p.triangle_bounds).collect()))
}

/// The warning for `count` coordinates below the exact range, the first `c` at vertex `i`.
fn tiny_warning(count: usize, i: usize, c: f64) -> String {
    format!(
        "{count} coordinates are non-zero but below 2^-250 in magnitude (e.g. {c:e} at vertex {i}): verdicts \
         between triangles that small may be inexact"
    )
}

/// Phase times in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timings {
    /// Building both trees.
    pub build_ms: f64,
    /// Walking, classifying and the distance search.
    pub query_ms: f64,
}

/// Size of one tree.
pub type TreeStats = bvh::Stats;

/// Everything a check finds: plain data, sorted, independent of the thread count.
#[derive(Debug, Clone, PartialEq)]
pub struct ClashResult {
    /// Every pair found, sorted by (a, b).
    pub pairs: Vec<PairFinding>,
    /// Counts by kind.
    pub counts: Counts,
    /// The closest pair (`None` only if an input has no triangles).
    pub closest: Option<Closest>,
    /// The overall answer.
    pub verdict: Verdict,
    /// Whether one part hides inside the other (decided only when no triangles meet).
    pub containment: Containment,
    /// Whether each input is closed (see [`crate::check::containment::topology`]); `None` where
    /// no verdict needed it (assemblies: [`PairPhase::needs_topology`]).
    pub closed: [Option<bool>; 2],
    /// The two trees ([`check_built`]; zero for part pairs of an assembly, whose report has no
    /// per-tree figures).
    pub trees: [TreeStats; 2],
    /// Phase times.
    pub timings: Timings,
}

/// Run the check on two meshes in world coordinates.
pub fn check(a: &Mesh, b: &Mesh, settings: &Settings) -> ClashResult {
    let t0 = Instant::now();
    let (ta, tb) = rayon::join(|| LazyBvh::new(a, settings.bvh), || LazyBvh::new(b, settings.bvh));
    let build_ms = ms(t0);
    let mut r = check_built(a, &ta, b, &tb, settings);
    r.timings.build_ms = build_ms;
    r
}

/// The pair walk alone: every pair that meets (or comes within the tolerances), classified,
/// sorted by (a, b); and whether `first_hit` stopped it early.
pub fn find_pairs<A, TA, B, TB>(
    a: &A,
    ta: &TA,
    b: &B,
    tb: &TB,
    settings: &Settings,
) -> (Vec<PairFinding>, bool)
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let tol = settings.tolerances;
    let stop = AtomicBool::new(false);
    let mut pairs = traverse::collect_pairs(
        ta,
        tb,
        |x, y| !stop.load(Ordering::Relaxed) && tol.boxes_may_meet(x, y),
        |la, lb, out| leaf_pairs(a, la, b, lb, settings, &stop, true, |f, _| out.push(f)),
    );
    pairs.par_sort_unstable_by_key(|p| (p.a, p.b));
    (pairs, stop.load(Ordering::Relaxed))
}

/// Triangles of a leaf prepared at a time ([`leaf_pairs`]; the default leaves hold 4).
const LEAF_CHUNK: usize = 8;

/// Classify every pair of triangles of two leaves whose boxes may meet, handing each finding
/// to `found`; with `first_hit`, the first crossing raises `stop` and the rest are skipped.
///
/// Each triangle is read, boxed and prepared ([`tri_tri::Prepared`]) once per leaf pair, not
/// once per candidate. Without `segments`, an exact contact of two proper triangles comes
/// without its f64 segment; `found` gets, with each finding, a way to classify that pair again
/// with everything (for the few findings it keeps).
#[allow(clippy::too_many_arguments)]
fn leaf_pairs<A, B>(
    a: &A,
    la: &[u32],
    b: &B,
    lb: &[u32],
    settings: &Settings,
    stop: &AtomicBool,
    segments: bool,
    mut found: impl FnMut(PairFinding, &dyn Fn() -> PairFinding),
) where
    A: TriMesh + ?Sized,
    B: TriMesh + ?Sized,
{
    let tol = settings.tolerances;
    for chunk in lb.chunks(LEAF_CHUNK) {
        let side_b: [Option<(Aabb, tri_tri::Prepared)>; LEAF_CHUNK] = std::array::from_fn(|k| {
            chunk.get(k).map(|&j| {
                let t = b.triangle(j);
                (Aabb::of_triangle(&t), tri_tri::Prepared::new(t))
            })
        });
        for &i in la {
            let ti = a.triangle(i);
            let bi = Aabb::of_triangle(&ti);
            let mut pi: Option<tri_tri::Prepared> = None;
            for (&j, (bj, pj)) in chunk.iter().zip(side_b.iter().flatten()) {
                if !tol.boxes_may_meet(&bi, bj) {
                    continue;
                }
                if stop.load(Ordering::Relaxed) {
                    return;
                }
                let pi = &*pi.get_or_insert_with(|| tri_tri::Prepared::new(ti));
                if let Some(f) = classify_pair(i, pi, j, pj, &tol, settings.mode, segments) {
                    if settings.first_hit && f.kind == PairKind::Crossing {
                        stop.store(true, Ordering::Relaxed);
                    }
                    let full = || classify_pair(i, pi, j, pj, &tol, settings.mode, true).unwrap_or(f);
                    found(f, &full);
                }
            }
        }
    }
}

/// What a check keeps of a set of triangle pairs when it does not keep the pairs
/// ([`Detail::Parts`]): everything the verdict, the counts and the witnesses read, in memory
/// that does not grow with the number of pairs. Tallies of disjoint sets of pairs merge into
/// the tally of their union, in any order.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Tally {
    /// Counts by kind.
    pub counts: Counts,
    /// The exact contact with the least (a, b): the witness of a zero distance, as the first
    /// contact of the sorted list would be.
    pub first_contact: Option<PairFinding>,
    /// The pair with the least (distance, a, b): the closest of the pairs, as the first of the
    /// smallest distance in the sorted list would be.
    pub best: Option<PairFinding>,
    /// Some pair is a face-to-face contact ([`Contact::CoplanarArea`]).
    pub coplanar_area: bool,
}

impl Tally {
    /// Count one pair.
    pub fn add(&mut self, p: PairFinding) {
        self.counts.record(&p);
        if p.contact.is_some() && self.first_contact.is_none_or(|f| (p.a, p.b) < (f.a, f.b)) {
            self.first_contact = Some(p);
        }
        if self.best.is_none_or(|f| closer(&p, &f)) {
            self.best = Some(p);
        }
        self.coplanar_area |= p.contact == Some(Contact::CoplanarArea);
    }

    /// Would [`Tally::add`] keep `p` (as the first contact or as the closest pair)? Reads
    /// neither its segment nor anything but its indices, distance and contact.
    pub fn keeps(&self, p: &PairFinding) -> bool {
        (p.contact.is_some() && self.first_contact.is_none_or(|f| (p.a, p.b) < (f.a, f.b)))
            || self.best.is_none_or(|f| closer(p, &f))
    }

    /// The tally of both sets of pairs.
    pub fn merge(mut self, o: Tally) -> Tally {
        self.counts.merge(&o.counts);
        if let Some(f) = o.first_contact {
            if self.first_contact.is_none_or(|g| (f.a, f.b) < (g.a, g.b)) {
                self.first_contact = Some(f);
            }
        }
        if let Some(f) = o.best {
            if self.best.is_none_or(|g| closer(&f, &g)) {
                self.best = Some(f);
            }
        }
        self.coplanar_area |= o.coplanar_area;
        self
    }

    /// The verdict the pairs alone imply (as [`Counts::record`] gives pair by pair).
    pub fn verdict(&self) -> Verdict {
        self.counts.verdict()
    }
}

/// Is `p` before `q` by (distance, a, b)?
fn closer(p: &PairFinding, q: &PairFinding) -> bool {
    p.distance < q.distance || (p.distance == q.distance && (p.a, p.b) < (q.a, q.b))
}

/// The pair walk folded into one [`Tally`] per group (`group(a, b)` names the group of a
/// triangle pair: the part pair in a file-mode check, `()` for one part pair), without
/// collecting the pairs; and whether `first_hit` stopped it early. Memory grows with the
/// number of groups, not with the number of pairs.
pub fn tally_pairs<A, TA, B, TB, K, G>(
    a: &A,
    ta: &TA,
    b: &B,
    tb: &TB,
    settings: &Settings,
    group: G,
) -> (std::collections::BTreeMap<K, Tally>, bool)
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
    K: Ord + Send,
    G: Fn(u32, u32) -> K + Sync,
{
    use std::collections::BTreeMap;
    let tol = settings.tolerances;
    let stop = AtomicBool::new(false);
    let tallies = traverse::fold_pairs(
        ta,
        tb,
        |x, y| !stop.load(Ordering::Relaxed) && tol.boxes_may_meet(x, y),
        BTreeMap::<K, Tally>::new,
        |la, lb, out| {
            leaf_pairs(a, la, b, lb, settings, &stop, false, |f, full| {
                let t = out.entry(group(f.a, f.b)).or_default();
                // A finding the tally keeps carries its segment; the others need none.
                t.add(if f.segment.is_none() && t.keeps(&f) { full() } else { f })
            })
        },
        |mut x, y| {
            for (k, t) in y {
                let e = x.entry(k).or_default();
                *e = e.merge(t);
            }
            x
        },
    );
    (tallies, stop.load(Ordering::Relaxed))
}

/// As [`pair_walk`], keeping only the [`Tally`] of the pairs, not the pairs: the phase has the
/// same counts, closest pair and topology needs, and [`PairPhase::needs_pairs`] says whether
/// containment needs the list after all.
pub fn tally_walk<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB, settings: &Settings) -> PairPhase
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let started = Instant::now();
    let (tallies, stopped) = tally_pairs(a, ta, b, tb, settings, |_, _| ());
    let tally = tallies.into_values().next().unwrap_or_default();
    PairPhase::of_tally(a, b, &tally, stopped, started)
}

/// [`check`] without keeping the triangle pairs ([`Detail::Parts`]): the result's pair list is
/// empty, everything else is as [`check`] gives it; plus the [`Tally`] of each group of pairs
/// (see [`tally_pairs`]). The pairs are walked a second time, and kept, only when containment
/// needs them: no pair crosses, and both inputs are closed with faces or points touching.
pub fn check_tallied<K, G>(
    a: &Mesh,
    b: &Mesh,
    settings: &Settings,
    group: G,
) -> (ClashResult, std::collections::BTreeMap<K, Tally>)
where
    K: Ord + Send,
    G: Fn(u32, u32) -> K + Sync,
{
    let t0 = Instant::now();
    let (ta, tb) = rayon::join(|| LazyBvh::new(a, settings.bvh), || LazyBvh::new(b, settings.bvh));
    let build_ms = ms(t0);
    let started = Instant::now();
    let (tallies, stopped) = tally_pairs(a, &ta, b, &tb, settings, group);
    let tally = tallies.values().fold(Tally::default(), |s, t| s.merge(*t));
    let mut phase = PairPhase::of_tally(a, b, &tally, stopped, started);
    if phase.pending {
        phase.closest = closest_pair(a, &ta, b, &tb, settings.distance_error);
        phase.pending = false;
    }
    let mut r = if phase.needs_topology(a, &ta, b, &tb) {
        let (topo_a, topo_b) = rayon::join(|| containment::topology(a), || containment::topology(b));
        if phase.needs_pairs(&topo_a, &topo_b) {
            phase.set_pairs(find_pairs(a, &ta, b, &tb, settings).0);
        }
        let mut r = phase.finish(a, &ta, b, &tb, Some((&topo_a, &topo_b)));
        r.closed = [Some(topo_a.closed), Some(topo_b.closed)];
        r
    } else {
        phase.finish(a, &ta, b, &tb, None)
    };
    r.pairs = Vec::new();
    r.trees = [ta.stats(), tb.stats()];
    r.timings.build_ms = build_ms;
    (r, tallies)
}

/// As [`check`], with both trees already built. The topology of the inputs (closedness, for
/// containment and face-to-face volume overlap) is computed only when the verdict needs it
/// ([`PairPhase::needs_topology`]); `closed` is `None` otherwise. Assemblies run the same phases
/// themselves ([`pair_phase`], each needed part's topology once, [`PairPhase::finish`]).
pub fn check_built<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB, settings: &Settings) -> ClashResult
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let phase = pair_phase(a, ta, b, tb, settings);
    let mut r = if phase.needs_topology(a, ta, b, tb) {
        let (topo_a, topo_b) = rayon::join(|| containment::topology(a), || containment::topology(b));
        let mut r = phase.finish(a, ta, b, tb, Some((&topo_a, &topo_b)));
        r.closed = [Some(topo_a.closed), Some(topo_b.closed)];
        r
    } else {
        phase.finish(a, ta, b, tb, None)
    };
    r.trees = [ta.stats(), tb.stats()];
    r
}

/// The first phase of a check: the pairs, their counts and the closest pair.
#[derive(Debug, Clone)]
pub struct PairPhase {
    pairs: Vec<PairFinding>,
    /// `pairs` is every pair (not only a [`Tally`] of them).
    listed: bool,
    /// Some pair is a face-to-face contact.
    coplanar_area: bool,
    counts: Counts,
    closest: Option<Closest>,
    /// No pair met exactly and the walk ran to the end: the closest pair is still to find.
    pending: bool,
    started: Instant,
}

/// Find every pair and the closest pair ([`PairPhase::finish`] adds containment and the verdict).
pub fn pair_phase<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB, settings: &Settings) -> PairPhase
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let mut phase = pair_walk(a, ta, b, tb, settings);
    if phase.pending {
        phase.closest = closest_pair(a, ta, b, tb, settings.distance_error);
        phase.pending = false;
    }
    phase
}

/// As [`pair_phase`] without the distance search: the closest pair is known only when some pair
/// meets exactly (a shared point); otherwise [`PairPhase::closest_pending`] says it is still to
/// find, and the caller decides whether it needs it (a scene needs a clear part pair's distance
/// only when it could be the scene's minimum: [`closest_pair_within`]).
pub fn pair_walk<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB, settings: &Settings) -> PairPhase
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let started = Instant::now();
    let (pairs, stopped) = find_pairs(a, ta, b, tb, settings);
    let mut counts = Counts::default();
    for p in &pairs {
        counts.record(p);
    }
    let closest = pairs.iter().find(|p| p.contact.is_some()).map(|p| contact_witness(a, b, p));
    let pending = closest.is_none() && !stopped;
    let coplanar_area = pairs.iter().any(|p| p.contact == Some(Contact::CoplanarArea));
    PairPhase { pairs, listed: true, coplanar_area, counts, closest, pending, started }
}

impl PairPhase {
    fn of_tally<A, B>(a: &A, b: &B, t: &Tally, stopped: bool, started: Instant) -> PairPhase
    where
        A: TriMesh + ?Sized,
        B: TriMesh + ?Sized,
    {
        let closest = t.first_contact.map(|p| contact_witness(a, b, &p));
        PairPhase {
            pairs: Vec::new(),
            listed: false,
            coplanar_area: t.coplanar_area,
            counts: t.counts,
            closest,
            pending: closest.is_none() && !stopped,
            started,
        }
    }

    /// Does containment ([`PairPhase::finish`] with these topologies) read the pair list, and
    /// was it not kept ([`tally_walk`])? Only touching closed parts need their contacts.
    pub fn needs_pairs(&self, topo_a: &containment::Topology, topo_b: &containment::Topology) -> bool {
        !self.listed
            && self.counts.crossing == 0
            && self.counts.touching > self.counts.within_tolerance
            && topo_a.closed
            && topo_b.closed
    }

    /// Put back the pair list a [`tally_walk`] did not keep (from [`find_pairs`]).
    pub fn set_pairs(&mut self, pairs: Vec<PairFinding>) {
        self.pairs = pairs;
        self.listed = true;
    }
    /// Drop the triangle-pair list (counts and the closest pair stay). Only for
    /// [`Detail::Parts`], and only once [`PairPhase::needs_topology`] has said the verdict does
    /// not need the pairs (face-to-face contact decides `volumes_overlap`).
    pub fn forget_pairs(&mut self) {
        self.pairs = Vec::new();
        self.listed = false;
    }

    /// True when no pair met exactly and the walk was not cut short: the closest pair has not
    /// been searched for yet.
    pub fn closest_pending(&self) -> bool {
        self.pending
    }

    /// Does the verdict need both sides' topology? Only when no pair crosses (and the search
    /// was not cut short), and either box meets the other's vertices (nesting is possible) or
    /// faces touch (volumes may overlap).
    pub fn needs_topology<A, TA, B, TB>(&self, a: &A, ta: &TA, b: &B, tb: &TB) -> bool
    where
        A: TriMesh + ?Sized,
        TA: Tree + ?Sized,
        B: TriMesh + ?Sized,
        TB: Tree + ?Sized,
    {
        self.counts.crossing == 0 && (self.coplanar_area || containment::may_nest(a, ta, b, tb))
    }

    /// Containment (with both topologies when [`PairPhase::needs_topology`] said so, else
    /// `None`) and the verdict. `closed` is left `None`: the caller knows what it computed.
    pub fn finish<A, TA, B, TB>(
        self,
        a: &A,
        ta: &TA,
        b: &B,
        tb: &TB,
        topo: Option<(&containment::Topology, &containment::Topology)>,
    ) -> ClashResult
    where
        A: TriMesh + ?Sized,
        TA: Tree + ?Sized,
        B: TriMesh + ?Sized,
        TB: Tree + ?Sized,
    {
        let PairPhase { pairs, counts, closest, started, .. } = self;
        let containment = match topo {
            _ if counts.crossing > 0 => Containment::None,
            None => Containment::None, // no nesting possible and no faces touch
            Some((ta_, tb_)) => {
                let contacts: Vec<_> =
                    pairs.iter().filter_map(|p| p.contact.map(|c| (p.a, p.b, c))).collect();
                let touching = (!contacts.is_empty())
                    .then(|| containment::decide_touching(a, ta, ta_, b, tb, tb_, &contacts))
                    .flatten();
                match touching {
                    Some(c) => c,
                    None if volumes_overlap(a, ta_, b, tb_, &pairs) => Containment::VolumesOverlap,
                    None => containment::decide(a, ta, ta_, b, tb, tb_, containment::OpenInside::Explain),
                }
            }
        };
        let verdict = if containment.is_clash() { Verdict::Clash } else { counts.verdict() };
        ClashResult {
            pairs,
            counts,
            closest,
            verdict,
            containment,
            closed: [None, None],
            trees: Default::default(),
            timings: Timings { build_ms: 0.0, query_ms: ms(started) },
        }
    }
}

/// Face-to-face contacts between two closed, consistently oriented solids whose outward
/// normals agree (see [`containment::coplanar_overlap`]).
fn volumes_overlap<A: TriMesh + ?Sized, B: TriMesh + ?Sized>(
    a: &A,
    topo_a: &containment::Topology,
    b: &B,
    topo_b: &containment::Topology,
    pairs: &[PairFinding],
) -> bool {
    if !pairs.iter().any(|p| p.contact == Some(Contact::CoplanarArea)) || !topo_a.closed || !topo_b.closed {
        return false;
    }
    let (oa, ob) = rayon::join(|| containment::outward(a, topo_a), || containment::outward(b, topo_b));
    let (Some(oa), Some(ob)) = (oa, ob) else { return false };
    pairs.iter().filter(|p| p.contact == Some(Contact::CoplanarArea)).any(|p| {
        let (ta, tb) = (a.triangle(p.a), b.triangle(p.b));
        containment::coplanar_overlap(&ta, oa[p.a as usize], &tb, ob[p.b as usize])
    })
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Exact classification, then the tolerance bands for pairs that do not meet. Without
/// `segment`, see [`tri_tri::classify_prepared`].
fn classify_pair(
    i: u32,
    pi: &tri_tri::Prepared,
    j: u32,
    pj: &tri_tri::Prepared,
    tol: &Tolerances,
    mode: Mode,
    segment: bool,
) -> Option<PairFinding> {
    let (ti, tj) = (pi.triangle(), pj.triangle());
    let hit = match mode {
        Mode::Exact => tri_tri::classify_prepared(pi, pj, segment),
        Mode::Fast => tri_tri::classify_with::<tri_tri::Float>(ti, tj),
    };
    if let Some(h) = hit {
        let kind = if h.crossing { PairKind::Crossing } else { PairKind::Touching };
        return Some(PairFinding {
            a: i,
            b: j,
            kind,
            contact: Some(h.contact),
            distance: 0.0,
            segment: h.segment,
        });
    }
    if tol.search_margin() == 0.0 {
        return None;
    }
    let d = triangle_distance(ti, tj);
    // The exact distance, computed only for a pair near a tolerance.
    let exact = std::cell::OnceCell::new();
    let order = |limit: f64| exact.get_or_init(|| exact_distance_sq(ti, tj)).cmp_distance(limit);
    let scale = Aabb::of_triangle(ti).max_abs().max(Aabb::of_triangle(tj).max_abs());
    let kind = if tol.touch > 0.0 && Tolerances::within(d.distance, tol.touch, true, scale, order) {
        PairKind::Touching
    } else if Tolerances::within(d.distance, tol.clearance, false, scale, order) {
        PairKind::Clearance
    } else {
        return None;
    };
    Some(PairFinding {
        a: i,
        b: j,
        kind,
        contact: None,
        distance: exact.get().map_or(d.distance, |e| e.rounded()),
        segment: Some([d.on_a, d.on_b]),
    })
}

/// The closest points a listed pair shows: a shared point for an exact contact, else the two
/// closest points its `segment` carries (tolerance and clearance pairs).
pub fn pair_witness<A: TriMesh + ?Sized, B: TriMesh + ?Sized>(a: &A, b: &B, p: &PairFinding) -> Closest {
    match (p.contact, p.segment) {
        (None, Some([s, t])) => Closest { distance: p.distance, a: (p.a, s), b: (p.b, t) },
        _ => contact_witness(a, b, p),
    }
}

/// Witness for an exact contact: a shared point.
fn contact_witness<A: TriMesh + ?Sized, B: TriMesh + ?Sized>(a: &A, b: &B, p: &PairFinding) -> Closest {
    let point = match p.segment {
        Some(s) => s[0],
        // Coplanar contacts: the closed-form distance of touching triangles is 0 (up to
        // rounding) at a shared point.
        None => triangle_distance(&a.triangle(p.a), &b.triangle(p.b)).on_a,
    };
    Closest { distance: 0.0, a: (p.a, point), b: (p.b, point) }
}

/// Nodes with at most this many triangles get an oriented bound ([`Oriented`]) in the
/// closest-pair search; larger ones use their box alone. Computing an oriented bound reads every
/// vertex below the node, so it pays only near the leaves, where a band of nearly equal
/// distances (concentric parts) keeps boxes from pruning. Tuned on linked tori and
/// 2CylinderEngine (64–512 all within 10%); a cost knob only: the answer does not depend on it.
pub const ORIENTED_MAX_TRIANGLES: usize = 1024;

/// Oriented bounds of one tree's nodes, computed on first use and shared by every thread of a
/// search (each is a function of its node alone, so the order of computation does not matter).
/// The slots come in chunks allocated on first use, so a lazy tree's wide id range costs only
/// what the search touches.
struct OrientedCache<'a, M: TriMesh + ?Sized, T: Tree + ?Sized> {
    mesh: &'a M,
    tree: &'a T,
    chunks: Vec<OnceLock<Box<[Slot]>>>,
}

type Slot = OnceLock<Option<Box<Oriented>>>;

/// Node ids per chunk of [`OrientedCache`] slots.
const ORIENTED_CHUNK_SHIFT: u32 = 8;

impl<'a, M: TriMesh + ?Sized, T: Tree + ?Sized> OrientedCache<'a, M, T> {
    fn new(mesh: &'a M, tree: &'a T) -> Self {
        let n = tree.id_bound().div_ceil(1 << ORIENTED_CHUNK_SHIFT);
        OrientedCache { mesh, tree, chunks: (0..n).map(|_| OnceLock::new()).collect() }
    }

    #[inline]
    fn get(&self, i: u32) -> Option<&Oriented> {
        let chunk = self.chunks[(i >> ORIENTED_CHUNK_SHIFT) as usize]
            .get_or_init(|| (0..1 << ORIENTED_CHUNK_SHIFT).map(|_| OnceLock::new()).collect());
        chunk[(i & ((1 << ORIENTED_CHUNK_SHIFT) - 1)) as usize]
            .get_or_init(|| {
                let prims = self.tree.subtree_prims(i);
                if prims.len() > ORIENTED_MAX_TRIANGLES {
                    return None;
                }
                Oriented::of_triangles(prims.iter().map(|&t| self.mesh.triangle(t))).map(Box::new)
            })
            .as_deref()
    }
}

/// Branch-and-bound closest pair of two meshes known not to touch (their trees built), within
/// the allowed distance error.
///
/// Lower bounds: the box gap, and for nodes near the leaves ([`ORIENTED_MAX_TRIANGLES`]) the
/// oriented slab gap ([`crate::bvh::slab`]); for triangle pairs the box gap and the plane gap.
/// Every bound is a true lower bound (the oriented ones less their rounding margin), so the
/// search evaluates every pair that could win and returns the minimum of (distance, triangle
/// pair) over all pairs, exactly as an exhaustive search would.
pub fn closest_pair<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB, err: DistanceError) -> Option<Closest>
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    closest_pair_within(a, ta, b, tb, err, &traverse::AtomicU64::new(f64::INFINITY.to_bits()))
}

/// As [`closest_pair`], but only pairs that could come within `best` (the f64 bits of a
/// distance, shared with other searches and lowered by each) are evaluated: `None` when none
/// can. Searches of several part pairs sharing one `best` find the minimum over all of them
/// (the same (distance, triangle pair) as searching each whole), each pruning by what the
/// others found.
pub fn closest_pair_within<A, TA, B, TB>(
    a: &A,
    ta: &TA,
    b: &B,
    tb: &TB,
    err: DistanceError,
    shared_best: &traverse::AtomicU64,
) -> Option<Closest>
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let scale = ta.root_box().max_abs().max(tb.root_box().max_abs());
    let slack = predicates::distance_rounding_slack(scale);
    let margin = predicates::oriented_bound_margin(scale);
    // With an error allowance, a node pair whose lower bound lb has (1 + rel)·lb + abs >= best
    // cannot improve on best by more than the allowance: shrink the bound accordingly.
    let shrink = |lb: f64| {
        if err.rel == 0.0 && err.abs == 0.0 {
            lb
        } else {
            (lb * (1.0 + err.rel) + err.abs).max(lb)
        }
    };
    let (cache_a, cache_b) = (OrientedCache::new(a, ta), OrientedCache::new(b, tb));
    let best = traverse::min_pair_shared(
        ta,
        tb,
        || (),
        |_, i, x, j, y, cut| {
            let boxed = shrink(x.distance_sq(y).sqrt());
            if boxed > cut {
                return boxed;
            }
            let (Some(oa), Some(ob)) = (cache_a.get(i), cache_b.get(j)) else {
                return boxed;
            };
            let gap = oa.gap(ob);
            // The rectangle bound costs four triangle distances: worth it only where a prune
            // saves subtrees on both sides (measured on linked tori and 2CylinderEngine).
            let leafy = ta.is_leaf(i) || tb.is_leaf(j);
            // The rectangle bound prunes only above `cut` (less the margin): it may stop early
            // below that (with an error allowance, `shrink` moves the line: no early stop).
            let need = if err.rel == 0.0 && err.abs == 0.0 { cut + margin } else { f64::NEG_INFINITY };
            let fine = if shrink(gap - margin) > cut || leafy {
                gap
            } else {
                oa.swept_rect_bound_above(ob, gap, need)
            };
            boxed.max(shrink(fine - margin))
        },
        slack,
        |la, lb, bound| {
            let mut best: Option<Candidate<(DVec3, DVec3)>> = None;
            // B's side once per leaf pair, not once per triangle of A.
            let side_b: Vec<LeafTriangle> = lb.iter().map(|&j| LeafTriangle::new(b.triangle(j))).collect();
            for &i in la {
                let ta_ = LeafTriangle::new(a.triangle(i));
                for (&j, tb_) in lb.iter().zip(&side_b) {
                    // What this leaf pair found already bounds the search as the shared best
                    // will once it is published (pairs within `slack` of it may still tie).
                    let bound = best.as_ref().map_or(bound, |m| bound.min(m.distance + slack));
                    if ta_.lower_bound(tb_, bound, margin) > bound {
                        continue;
                    }
                    let (ti, tj) = (&ta_.t, &tb_.t);
                    let d = triangle_distance(ti, tj);
                    let c = Candidate { distance: d.distance, key: (i, j), data: (d.on_a, d.on_b) };
                    if best.as_ref().is_none_or(|m| (c.distance, c.key) < (m.distance, m.key)) {
                        best = Some(c);
                    }
                }
            }
            best
        },
        shared_best,
    )?;
    // The reported distance: the exact distance of the pair found, correctly rounded.
    let (i, j) = best.key;
    let distance = exact_distance_sq(&a.triangle(i), &b.triangle(j)).rounded();
    Some(Closest { distance, a: (i, best.data.0), b: (j, best.data.1) })
}

/// A triangle with what the closest-pair search's triangle-pair bounds read of it.
struct LeafTriangle {
    t: [DVec3; 3],
    bounds: Aabb,
    normal: DVec3,
    centroid: DVec3,
}

impl LeafTriangle {
    #[inline]
    fn new(t: [DVec3; 3]) -> Self {
        LeafTriangle {
            bounds: Aabb::of_triangle(&t),
            normal: slab::unit_normal(&t),
            centroid: (t[0] + t[1] + t[2]) / 3.0,
            t,
        }
    }

    /// A lower bound on the distance of the two triangles, or any value above `bound` once one
    /// of them exceeds it: the box gap, then (less the rounding `margin`) the gap between each
    /// plane and the other triangle, then the gap between their projections on the line
    /// through their centroids (the axis that separates side-by-side triangles on a surface
    /// at a near-constant distance, where the planes are nearly parallel and their gaps say
    /// nothing). Each is a true lower bound; the projections on a unit vector computed in f64
    /// are within the oriented-bound margin of the exact ones
    /// ([`predicates::oriented_bound_margin`]).
    #[inline]
    fn lower_bound(&self, o: &LeafTriangle, bound: f64, margin: f64) -> f64 {
        let boxed = self.bounds.distance_sq(&o.bounds).sqrt();
        if boxed > bound {
            return boxed;
        }
        let planes = slab::plane_gap(&self.t, self.normal, &o.t, o.normal) - margin;
        if planes > bound {
            return planes;
        }
        let axis = (o.centroid - self.centroid).normalize_or_zero();
        let hi = self.t.iter().map(|p| axis.dot(*p)).fold(f64::NEG_INFINITY, f64::max);
        let lo = o.t.iter().map(|p| axis.dot(*p)).fold(f64::INFINITY, f64::min);
        boxed.max(planes).max(lo - hi - margin)
    }
}

/// The severity at which a run fails (exit code 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FailOn {
    /// Fail on crossing pairs (default).
    #[default]
    Clash,
    /// Fail on touching or crossing pairs.
    Touching,
    /// Fail on anything closer than the clearance.
    Clearance,
    /// Never fail on findings (exit 0 unless an error).
    Never,
}

impl FailOn {
    /// Name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            FailOn::Clash => "clash",
            FailOn::Touching => "touching",
            FailOn::Clearance => "clearance",
            FailOn::Never => "never",
        }
    }

    /// Does `v` fail the run?
    pub fn fails(self, v: Verdict) -> bool {
        match self {
            FailOn::Clash => v >= Verdict::Clash,
            FailOn::Touching => v >= Verdict::Touching,
            FailOn::Clearance => v >= Verdict::Clearance,
            FailOn::Never => false,
        }
    }
}
