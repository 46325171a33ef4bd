//! The JSON wire format, documented once here (README repeats it with an example).
//!
//! Schema `meshclash.report/2`: version 1 plus the additive `assembly`, `parts` and `part_pairs`
//! blocks (every version-1 field keeps its meaning; in scene mode both `inputs` describe the one
//! file and `pairs` lists triangle pairs between different parts of it). Field order is fixed; arrays are sorted; numbers are f64 printed
//! shortest-round-trip. With `deterministic` (`--no-timings`) the run-dependent fields
//! (`settings.threads`, `timings_ms`) are `null`, so the same inputs give byte-identical reports
//! whatever the thread count.
//!
//! ```text
//! {
//!   "schema": "meshclash.report/2",
//!   "tool": {"name": "meshclash", "version": "0.1.0"},
//!   "inputs": {
//!     "a": {"path", "format": "obj|stl|gltf|glb", "vertices", "triangles", "degenerate_triangles", "closed",
//!           "objects": [{"name", "triangles"}], "bounds": {"min": [x,y,z], "max": [x,y,z]},
//!           "transform": [16 numbers, row-major] | null,
//!           "units"?: {"units": "mm" | null, "source": "given|gltf|assumed" | null, "factor",
//!                      "scale", "multiplier"}},   // only with --units/--units-a/-b/--scale-a/-b
//!     "b": { ...same... }
//!   },
//!   "settings": {"touch_tolerance", "clearance", "touch_tolerance_given", "clearance_given",
//!                "model_size", "units": "model", "fail_on", "bvh", "mode": "exact|fast", "first_hit",
//!                "distance_rel_err", "distance_abs_err", "leaf_size", "max_pairs",
//!                "threads": n | null},
//!   "verdict": "clash" | "touching" | "clearance" | "clear",  // containment is a clash
//!   "failed": bool,                  // verdict at or above fail_on (exit code 1)
//!   "summary": {"crossing_pairs", "touching_pairs", "within_tolerance_pairs", "clearance_pairs",
//!               "min_distance": number | null,
//!               "contained": "a_in_b|b_in_a|a_partly_in_b|b_partly_in_a|undecided" | null,
//!               "contained_reason": string | null},
//!   "closest": {"distance", "a": {"triangle", "object", "point": [x,y,z]}, "b": {...}} | null,
//!   "pairs": [{"a", "b", "a_object", "b_object", "kind": "crossing|touching|clearance",
//!              "contact": "point|segment|coplanar_area|coplanar_boundary|within_tolerance" | null,
//!              "distance", "segment": [[x,y,z],[x,y,z]] | null}],
//!   "pairs_truncated": bool,
//!   "bvh": {"a": {"nodes", "leaves", "depth", "sah_cost", "bytes", "cells"}, "b": {...}},
//!   "assembly": {"mode": "files|parts", "selected": [a, b], "candidate_part_pairs",
//!                "built_parts": n | null, "sah_builds": n | null,
//!                "shared_trees"?: n, "memory_saved_bytes"?: n},
//!   "parts": [{"input": "a|b", "object", "name", "triangles", "bounds"}],
//!   "part_pairs": [{"a", "b", "a_name", "b_name", "verdict", "crossing_pairs", "touching_pairs",
//!                   "clearance_pairs", "min_distance": number | null, "contained": string | null}],
//!   "regions": [{"id", "a_object", "b_object", "a_name", "b_name", "pairs", "crossing_pairs",
//!                "center": [x,y,z], "bounds", "extent"}],
//!   "cross_check": null | {"tool", "intersects", "verdict_agrees", "intersecting_pairs",
//!                  "distance", "distance_difference", "only_meshclash": [[a,b]], "only_parry": [[a,b]],
//!                  "only_meshclash_count", "only_parry_count", "parry_ms": [pairs, distance] | null},
//!   "warnings": ["..."],
//!   "timings_ms": {"load", "build", "query", "total"} | null
//! }
//! ```
//! Triangle indices are 0-based in file order (see [`crate::load`]); `object` / `a_object`
//! index into `inputs.*.objects`.

pub mod baseline;
pub mod clash_set;
pub mod pretty;
pub mod self_report;

use crate::check::query::{ClashResult, Verdict};
use crate::geom::DVec3;
use serde::{Deserialize, Serialize};

/// The `format` an in-memory input has in the report.
pub const ARRAY_FORMAT: &str = "array";

/// The schema identifier written in every report.
pub const SCHEMA: &str = "meshclash.report/2";

/// A verdict as written in reports (`clear` < `clearance` < `touching` < `clash`: the order is
/// the severity, as [`Verdict`]'s).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum ReportVerdict {
    /// Nothing within the clearance.
    Clear,
    /// Some pair closer than the clearance.
    Clearance,
    /// Some pair touches (exactly, or within the touch tolerance), none crosses.
    Touching,
    /// Some pair crosses, or one part lies inside the other.
    Clash,
}

impl ReportVerdict {
    /// The name in the report.
    pub fn name(self) -> &'static str {
        self.verdict().name()
    }

    /// The engine's verdict.
    pub fn verdict(self) -> Verdict {
        match self {
            ReportVerdict::Clear => Verdict::Clear,
            ReportVerdict::Clearance => Verdict::Clearance,
            ReportVerdict::Touching => Verdict::Touching,
            ReportVerdict::Clash => Verdict::Clash,
        }
    }
}

impl From<Verdict> for ReportVerdict {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Clear => ReportVerdict::Clear,
            Verdict::Clearance => ReportVerdict::Clearance,
            Verdict::Touching => ReportVerdict::Touching,
            Verdict::Clash => ReportVerdict::Clash,
        }
    }
}

/// A triangle pair's kind as written in reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ReportPairKind {
    /// The interiors cross: a real penetration.
    Crossing,
    /// They share points without crossing, or come within the touch tolerance.
    Touching,
    /// Closer than the clearance, not touching.
    Clearance,
}

impl ReportPairKind {
    /// The name in the report.
    pub fn name(self) -> &'static str {
        match self {
            ReportPairKind::Crossing => "crossing",
            ReportPairKind::Touching => "touching",
            ReportPairKind::Clearance => "clearance",
        }
    }
}

impl From<crate::check::query::PairKind> for ReportPairKind {
    fn from(k: crate::check::query::PairKind) -> Self {
        use crate::check::query::PairKind;
        match k {
            PairKind::Crossing => ReportPairKind::Crossing,
            PairKind::Touching => ReportPairKind::Touching,
            PairKind::Clearance => ReportPairKind::Clearance,
        }
    }
}

/// The shape of a contact as written in reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ReportContact {
    /// They share exactly one point.
    Point,
    /// They share a segment of positive length (and are not coplanar).
    Segment,
    /// Coplanar and their interiors overlap (face-to-face contact, duplicated faces).
    CoplanarArea,
    /// Coplanar and they share only boundary points.
    CoplanarBoundary,
    /// They do not meet but come within the touch tolerance.
    WithinTolerance,
}

impl ReportContact {
    /// The name in the report.
    pub fn name(self) -> &'static str {
        match self {
            ReportContact::Point => "point",
            ReportContact::Segment => "segment",
            ReportContact::CoplanarArea => "coplanar_area",
            ReportContact::CoplanarBoundary => "coplanar_boundary",
            ReportContact::WithinTolerance => "within_tolerance",
        }
    }
}

/// Containment as written in reports (`summary.contained`, `part_pairs[].contained`); every
/// value but `undecided` is a clash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ReportContainment {
    /// Every component of A lies inside B.
    AInB,
    /// Every component of B lies inside A.
    BInA,
    /// Some components of A lie inside B, others outside.
    APartlyInB,
    /// Some components of B lie inside A, others outside.
    BPartlyInA,
    /// Surfaces only touch, but face-to-face contacts show the two solids share volume.
    VolumesOverlap,
    /// Could not decide (`contained_reason` says why).
    Undecided,
}

impl ReportContainment {
    /// The name in the report.
    pub fn name(self) -> &'static str {
        match self {
            ReportContainment::AInB => "a_in_b",
            ReportContainment::BInA => "b_in_a",
            ReportContainment::APartlyInB => "a_partly_in_b",
            ReportContainment::BPartlyInA => "b_partly_in_a",
            ReportContainment::VolumesOverlap => "volumes_overlap",
            ReportContainment::Undecided => "undecided",
        }
    }

    /// Is this an interference (a clash)? Every value but `undecided`.
    pub fn is_clash(self) -> bool {
        self != ReportContainment::Undecided
    }

    /// The report value of the engine's containment (None for no containment).
    pub fn of(c: &crate::check::containment::Containment) -> Option<Self> {
        use crate::check::containment::Containment;
        Some(match c {
            Containment::None => return None,
            Containment::AInB => ReportContainment::AInB,
            Containment::BInA => ReportContainment::BInA,
            Containment::APartlyInB => ReportContainment::APartlyInB,
            Containment::BPartlyInA => ReportContainment::BPartlyInA,
            Containment::VolumesOverlap => ReportContainment::VolumesOverlap,
            Containment::Undecided(_) => ReportContainment::Undecided,
        })
    }
}

/// `Display` as the report name, and `==` against a report name (`r.verdict == "clash"`).
macro_rules! wire_name {
    ($($t:ty),*) => {$(
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl PartialEq<&str> for $t {
            fn eq(&self, other: &&str) -> bool {
                self.name() == *other
            }
        }
    )*};
}

wire_name!(ReportVerdict, ReportPairKind, ReportContact, ReportContainment);

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// `false` for a partial merge (shards missing; such a report always fails and is refused
    /// as a baseline); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub complete: Option<bool>,
    /// The shards a partial merge is missing ("2/3"); absent otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub missing_shards: Vec<String>,
    /// Always [`SCHEMA`].
    pub schema: String,
    /// Who wrote it.
    pub tool: Tool,
    /// The two inputs.
    pub inputs: Inputs,
    /// The settings used.
    pub settings: SettingsReport,
    /// `clash`, `touching`, `clearance` or `clear`.
    pub verdict: ReportVerdict,
    /// True if the verdict is at or above `settings.fail_on` (the process exits 1).
    pub failed: bool,
    /// Counts (complete even when `pairs` is truncated).
    pub summary: Summary,
    /// The closest pair of points.
    pub closest: Option<ClosestReport>,
    /// The pairs found, sorted by (a, b), at most `settings.max_pairs`: when there are more,
    /// the worst are kept (crossing, then touching, then within the touch tolerance, then
    /// clearance by distance; ties by (a, b)).
    pub pairs: Vec<PairReport>,
    /// True if `pairs` was cut at `max_pairs`.
    pub pairs_truncated: bool,
    /// When `pairs` was cut: the ids of every finding it does not list, so that the report is a
    /// complete baseline whatever `--max-pairs` listed; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unlisted: Option<UnlistedFindings>,
    /// Tree sizes.
    pub bvh: Trees,
    /// What parry3d-f64 says on the same input (`--cross-check parry`), else null.
    pub cross_check: Option<CrossCheckReport>,
    /// How the inputs were split into parts and which part pairs were checked (v2).
    pub assembly: AssemblyReport,
    /// Every part of the inputs (A's first; in scene mode only the file's) (v2).
    pub parts: Vec<PartReport>,
    /// Part pairs with a finding, sorted by (a, b) (v2).
    pub part_pairs: Vec<PartPairReport>,
    /// Connected interferences: all pairs (not only the listed ones) grouped per part pair,
    /// sorted by their stable id (v2).
    pub regions: Vec<RegionReport>,
    /// Loader warnings, prefixed with the file.
    pub warnings: Vec<String>,
    /// Phase times (null in deterministic mode).
    pub timings_ms: Option<TimingsReport>,
    /// With `--baseline`: the comparison with the earlier report; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub baseline: Option<crate::report::baseline::BaselineReport>,
    /// `scene --self`: every part checked against itself (see
    /// [`self_report::SceneSelfReport`]); absent otherwise.
    #[serde(rename = "self", default, skip_serializing_if = "Option::is_none")]
    pub self_check: Option<self_report::SceneSelfReport>,
    /// The result cache (`--cache DIR`): how many candidate part pairs reused a stored result
    /// and how many were checked; absent without `--cache`. Everything else in the report is
    /// the same with or without the cache.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cache: Option<crate::cache::CacheSummary>,
}

/// The finding ids a cut `pairs` list does not show.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UnlistedFindings {
    /// Ids of the unlisted crossing pairs, sorted, without repeats.
    pub crossing_ids: Vec<String>,
    /// Ids of the other unlisted pairs (touching, within tolerance, clearance), sorted, without
    /// repeats.
    pub other_ids: Vec<String>,
}

/// How deep one part reaches into the other at a region.
///
/// Two methods: without `method` (the sampled estimate), `depth` is the largest distance from a
/// sampled point of one part's surface (vertices near the region, the region's triangles'
/// centroids and edge midpoints), inside the other (closed) part, to the other's surface: a
/// lower bound on the local interpenetration, 0 when none is. With `method: "exact_convex"`
/// (both objects closed and exactly convex), `depth` is the exact penetration depth of the two
/// objects: the length of the shortest translation that separates them, by the separating-axis
/// theorem with the deepest axis chosen in exact arithmetic (`crate::narrow::convex`) and the
/// depth along it evaluated in f64 (within a few ulps of the coordinate scale).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PenetrationReport {
    /// The depth: a sampled lower bound, or with `method: "exact_convex"` the exact minimum
    /// separating translation of the two objects (0 when they only touch).
    pub depth: f64,
    /// Sampled: the deepest sampled point (the region's centre when `depth` is 0). Exact: the
    /// deepest point of the penetrating vertex or edge moved back by half the depth.
    pub point: [f64; 3],
    /// `a_in_b` (a point of A's surface inside B) or `b_in_a`. Exact: `b_in_a` when the
    /// separating axis is a face normal of A (B's deepest vertex is inside A), else `a_in_b`.
    pub side: String,
    /// Points found inside the other part and measured (sampled: at most about 2048 per
    /// region and side); 0 with `method: "exact_convex"` (nothing is sampled).
    pub samples: usize,
    /// `exact_convex` when the depth is exact; absent for the sampled estimate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<String>,
    /// With `method: "exact_convex"`: the unit direction in which moving B by `depth` (or A by
    /// `-depth`) separates the two objects; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
}

impl PenetrationReport {
    /// The `method` of an exact depth of two convex objects.
    pub const EXACT_CONVEX: &'static str = "exact_convex";

    /// Is the depth exact (`method: "exact_convex"`)?
    pub fn is_exact(&self) -> bool {
        self.method.as_deref() == Some(Self::EXACT_CONVEX)
    }
}

/// A clash region (v2), see [`crate::regions`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RegionReport {
    /// Stable id: the smallest finding id among its pairs.
    pub id: String,
    /// Object of A (`inputs.a.objects`).
    pub a_object: u32,
    /// Object of B.
    pub b_object: u32,
    /// Name of that object of A.
    pub a_name: String,
    /// Name of that object of B.
    pub b_name: String,
    /// Triangle pairs in the region.
    pub pairs: usize,
    /// Of those, crossing.
    pub crossing_pairs: usize,
    /// Centre of the contact set.
    pub center: [f64; 3],
    /// Box of the contact set.
    pub bounds: Bounds,
    /// Diagonal of that box (size of the interference; not a penetration depth).
    pub extent: f64,
    /// Penetration depth (with `--penetration`; null otherwise, or when neither part is
    /// closed): exact for two convex objects, else a sampled lower bound (see
    /// [`PenetrationReport`]).
    #[serde(default)]
    pub penetration: Option<PenetrationReport>,
    /// The exact box of A ∩ B when this region is its part pair's only region and the pair
    /// has one (see [`PartPairReport::overlap`]); absent otherwise (a share of a part pair's
    /// overlap among several regions would not be exact).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overlap: Option<OverlapReport>,
}

/// The exact axis-aligned box of the intersection A ∩ B of two clashing closed parts (see
/// [`crate::check::overlap`]): the same at every tessellation of the same solids.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OverlapReport {
    /// Lower corner; each coordinate the exact extreme rounded once to the nearest f64.
    pub min: [f64; 3],
    /// Upper corner, rounded the same way.
    pub max: [f64; 3],
    /// `max - min` per axis (in f64).
    pub extent: [f64; 3],
}

impl OverlapReport {
    /// The report block of an overlap box.
    pub fn of(o: &crate::check::overlap::Overlap) -> OverlapReport {
        OverlapReport { min: v3(o.min), max: v3(o.max), extent: v3(o.extent()) }
    }
}

/// The `assembly` block (v2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AssemblyReport {
    /// `files` (two files; pairs grouped by part) or `parts` (scene mode or a selection: each
    /// candidate part pair checked on its own).
    pub mode: String,
    /// Selected parts on the A and B sides.
    pub selected: [usize; 2],
    /// Part pairs whose boxes came within the search margin (parts mode), or part pairs with
    /// findings (files mode).
    pub candidate_part_pairs: usize,
    /// Parts that needed a triangle tree; the others cost no build (parts mode only).
    pub built_parts: Option<usize>,
    /// Distinct SAH builds: instances of one glTF mesh share one (parts mode only).
    pub sah_builds: Option<usize>,
    /// Trees walked by more than one part: an instance walks its mesh's shared tree through
    /// the relative transform instead of a copy (parts mode only; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shared_trees: Option<usize>,
    /// Bytes not allocated compared with copying every checked part (positions, triangles, tree)
    /// per instance (parts mode only; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory_saved_bytes: Option<u64>,
}

/// A part (v2): an OBJ `o`/`g`, an STL `solid`, or a glTF mesh instance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PartReport {
    /// `a` or `b`.
    pub input: String,
    /// Object index in that input (`inputs.*.objects`).
    pub object: u32,
    /// Name (glTF node path, OBJ group, STL solid).
    pub name: String,
    /// Triangle count.
    pub triangles: usize,
    /// World box.
    pub bounds: Bounds,
}

/// A part pair with findings (v2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PartPairReport {
    /// Index into `parts` (A side).
    pub a: usize,
    /// Index into `parts` (B side).
    pub b: usize,
    /// Name of part `a`.
    pub a_name: String,
    /// Name of part `b`.
    pub b_name: String,
    /// The pair's verdict.
    pub verdict: ReportVerdict,
    /// Crossing triangle pairs.
    pub crossing_pairs: u64,
    /// Touching triangle pairs.
    pub touching_pairs: u64,
    /// Clearance triangle pairs.
    pub clearance_pairs: u64,
    /// Minimum distance between the two parts, when computed.
    pub min_distance: Option<f64>,
    /// Containment between the two parts (a clash), or null.
    pub contained: Option<ReportContainment>,
    /// The witness of `min_distance` (triangles are input indices, objects those of the parts).
    #[serde(default)]
    pub closest: Option<ClosestReport>,
    /// The part pair's triangle pairs as `[a, b]` input triangle indices, sorted by (a, b); at
    /// most `settings.max_pairs` of them.
    #[serde(default)]
    pub pairs: Vec<[u32; 2]>,
    /// More triangle pairs than listed (the counts stay complete).
    #[serde(default)]
    pub pairs_truncated: bool,
    /// The exact box of the intersection of the two parts, for a clashing pair of closed
    /// parts; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overlap: Option<OverlapReport>,
}

/// Build the v2 part view from an assembly outcome.
pub fn assembly_view(
    o: &crate::check::assembly::Outcome,
    max_pairs: usize,
) -> (AssemblyReport, Vec<PartReport>, Vec<PartPairReport>) {
    let parts = o
        .parts
        .iter()
        .map(|p| PartReport {
            input: if p.input == 0 { "a".into() } else { "b".into() },
            object: p.object,
            name: p.name.clone(),
            triangles: p.triangles.len(),
            bounds: Bounds { min: v3(p.bounds.min), max: v3(p.bounds.max) },
        })
        .collect();
    let pairs = o
        .part_pairs
        .iter()
        .map(|pp| PartPairReport {
            a: pp.a,
            b: pp.b,
            a_name: o.parts[pp.a].name.clone(),
            b_name: o.parts[pp.b].name.clone(),
            verdict: pp.verdict.into(),
            crossing_pairs: pp.counts.crossing,
            touching_pairs: pp.counts.touching,
            clearance_pairs: pp.counts.clearance,
            min_distance: pp.min_distance,
            contained: ReportContainment::of(&pp.containment),
            closest: pp.closest.map(|c| {
                let (pa, pb) = (&o.parts[pp.a], &o.parts[pp.b]);
                ClosestReport {
                    distance: c.distance,
                    a: Witness { triangle: c.a.0, object: pa.object, point: v3(c.a.1) },
                    b: Witness { triangle: c.b.0, object: pb.object, point: v3(c.b.1) },
                }
            }),
            pairs: pp.pairs.iter().take(max_pairs).map(|&(x, y)| [x, y]).collect(),
            pairs_truncated: pp.pairs.len() > max_pairs || (pp.pairs.is_empty() && pp.counts.total() > 0),
            overlap: None,
        })
        .collect();
    let i = &o.info;
    let a = AssemblyReport {
        mode: i.mode.into(),
        selected: i.selected,
        candidate_part_pairs: i.candidate_part_pairs,
        built_parts: i.built_parts,
        sah_builds: i.sah_builds,
        shared_trees: i.sharing.map(|s| s.shared_trees),
        memory_saved_bytes: i.sharing.map(|s| s.memory_saved_bytes as u64),
    };
    (a, parts, pairs)
}

/// The `cross_check` block: parry3d-f64's answer and every disagreement with ours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CrossCheckReport {
    /// "parry3d-f64 0.31".
    pub tool: String,
    /// parry's verdict on "do they intersect (touch or cross)".
    pub intersects: bool,
    /// Does it agree with ours (crossing or exact touching pairs exist)?
    pub verdict_agrees: bool,
    /// Pairs parry calls intersecting.
    pub intersecting_pairs: usize,
    /// parry's minimum distance.
    pub distance: f64,
    /// Our minimum distance minus parry's.
    pub distance_difference: f64,
    /// Pairs only we report as meeting (at most `max_pairs` listed).
    pub only_meshclash: Vec<[u32; 2]>,
    /// Pairs only parry reports (at most `max_pairs` listed).
    pub only_parry: Vec<[u32; 2]>,
    /// Total counts of the two lists above (never truncated).
    pub only_meshclash_count: usize,
    /// See `only_meshclash_count`.
    pub only_parry_count: usize,
    /// parry's pair search and distance times, ms (null in deterministic mode).
    pub parry_ms: Option<[f64; 2]>,
}

/// Compare our result with parry's.
pub fn cross_check_report(
    r: &ClashResult,
    p: &crate::check::cross_check::ParryResult,
    max: usize,
    deterministic: bool,
) -> CrossCheckReport {
    let ours: Vec<(u32, u32)> = r.pairs.iter().filter(|f| f.contact.is_some()).map(|f| (f.a, f.b)).collect();
    let (only_ours, only_parry) = crate::check::cross_check::diff_pairs(&ours, &p.intersecting_pairs);
    let ours_min = r.closest.map_or(f64::NAN, |c| c.distance);
    let list = |v: &[(u32, u32)]| v.iter().take(max).map(|&(a, b)| [a, b]).collect();
    CrossCheckReport {
        tool: "parry3d-f64 0.31".into(),
        intersects: !p.intersecting_pairs.is_empty(),
        verdict_agrees: p.intersecting_pairs.is_empty() == ours.is_empty(),
        intersecting_pairs: p.intersecting_pairs.len(),
        distance: p.distance,
        distance_difference: ours_min - p.distance,
        only_meshclash: list(&only_ours),
        only_parry: list(&only_parry),
        only_meshclash_count: only_ours.len(),
        only_parry_count: only_parry.len(),
        parry_ms: (!deterministic).then_some([p.pairs_ms, p.distance_ms]),
    }
}

/// Tool name and version.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Tool {
    /// "meshclash".
    pub name: String,
    /// Crate version.
    pub version: String,
}

impl Tool {
    /// This build of meshclash.
    pub fn this() -> Tool {
        Tool { name: "meshclash".into(), version: env!("CARGO_PKG_VERSION").into() }
    }
}

/// Inputs A and B.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Inputs {
    /// First input.
    pub a: InputReport,
    /// Second input.
    pub b: InputReport,
}

/// One input.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InputReport {
    /// Path as given.
    pub path: String,
    /// `obj`, `stl`, `gltf` or `glb`.
    pub format: String,
    /// Vertex count.
    pub vertices: usize,
    /// Triangle count.
    pub triangles: usize,
    /// Zero-area triangles.
    pub degenerate_triangles: usize,
    /// Every edge of its non-degenerate triangles is shared by exactly two of them (after
    /// merging exactly coincident vertices): it bounds a volume and can contain the other part.
    /// `null`: not computed, because no verdict needed it (a crossing decides the verdict
    /// alone, and parts whose boxes cannot nest and whose faces do not touch need no inside);
    /// `meshclash self FILE` always reports it.
    pub closed: Option<bool>,
    /// Objects in file order.
    pub objects: Vec<ObjectReport>,
    /// World bounds (after the transform).
    pub bounds: Bounds,
    /// The placement applied, row-major 4×4, or null for none.
    pub transform: Option<Vec<f64>>,
    /// With `--units`, `--units-a/-b` or `--scale-a/-b`: how this input was converted to the
    /// report units; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<InputUnitsReport>,
}

/// How one input's coordinates were converted (`inputs.*.units`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InputUnitsReport {
    /// The units the file's coordinates were taken to be in (`um`, `mm`, `cm`, `m`, `in`, `ft`,
    /// `yd`), or null when the report has no units (only a `--scale` was given).
    pub units: Option<String>,
    /// Where `units` comes from: `given` (`--units-a`/`--units-b`), `gltf` (glTF is metres by
    /// specification), `assumed` (OBJ and STL carry no units: taken to be the report units, and
    /// a warning says so), or null with `units`.
    pub source: Option<String>,
    /// Unit conversion factor into the report units: the exact ratio rounded once to f64.
    pub factor: f64,
    /// The raw `--scale-a`/`--scale-b` multiplier (1 when not given).
    pub scale: f64,
    /// `factor × scale` rounded once: every coordinate was multiplied by this number (each
    /// product rounded once) before `--transform`/`--translate`.
    pub multiplier: f64,
}

/// An object (OBJ `o`/`g`, STL solid, glTF mesh instance).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectReport {
    /// Its name.
    pub name: String,
    /// Its triangle count.
    pub triangles: usize,
}

/// An axis-aligned box.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

/// Settings as used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SettingsReport {
    /// Absolute touch tolerance used (model units).
    pub touch_tolerance: f64,
    /// Absolute clearance used (model units).
    pub clearance: f64,
    /// The touch tolerance as given: a number (absolute) or `<r>rel` (relative to model_size).
    pub touch_tolerance_given: String,
    /// The clearance as given.
    pub clearance_given: String,
    /// Diagonal of the box around both inputs (the base of relative tolerances).
    pub model_size: f64,
    /// Units of every length in the report: "model" (the files' own units), or the `--units`
    /// value (`um`, `mm`, `cm`, `m`, `in`, `ft`, `yd`) the inputs were converted to.
    pub units: String,
    /// `clash`, `touching`, `clearance` or `never`.
    pub fail_on: String,
    /// `sah`, `median` or `equal`.
    pub bvh: String,
    /// `exact` or `fast` (plain f64 determinants, no exact fallback).
    pub mode: String,
    /// Stopped at the first crossing pair: counts are lower bounds.
    pub first_hit: bool,
    /// `--penetration`: regions carry a penetration estimate.
    #[serde(default)]
    pub penetration: bool,
    /// Allowed relative error of `min_distance`.
    pub distance_rel_err: f64,
    /// Allowed absolute error of `min_distance`.
    pub distance_abs_err: f64,
    /// Largest leaf.
    pub leaf_size: u32,
    /// Cap on listed pairs.
    pub max_pairs: usize,
    /// Worker threads (null in deterministic mode).
    pub threads: Option<usize>,
    /// `parts` with `--detail parts`: no triangle-pair lists (`pairs` and every
    /// `part_pairs[].pairs` empty, `pairs_truncated` true where pairs were found), no regions.
    /// Absent with the default, `pairs`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detail: Option<String>,
}

/// Counts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Summary {
    /// Pairs whose interiors cross.
    pub crossing_pairs: u64,
    /// Pairs that touch (exactly or within the touch tolerance).
    pub touching_pairs: u64,
    /// Of those, pairs that only come within the touch tolerance.
    pub within_tolerance_pairs: u64,
    /// Pairs closer than the clearance.
    pub clearance_pairs: u64,
    /// The minimum distance between the two surfaces.
    pub min_distance: Option<f64>,
    /// `a_in_b`, `b_in_a`, `a_partly_in_b`, `b_partly_in_a` (all a clash), `undecided`, or null.
    pub contained: Option<ReportContainment>,
    /// Why containment is `undecided`, else null.
    pub contained_reason: Option<String>,
    /// Two files of one closed part each that clash by containment (`contained` is a clash)
    /// with no clashing part pair to carry the box: the exact box of A ∩ B, as
    /// [`PartPairReport::overlap`]. Absent otherwise (a clashing part pair carries its own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overlap: Option<OverlapReport>,
}

/// The closest pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ClosestReport {
    /// The distance.
    pub distance: f64,
    /// Witness on A.
    pub a: Witness,
    /// Witness on B.
    pub b: Witness,
}

/// A point on a triangle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Witness {
    /// Triangle index.
    pub triangle: u32,
    /// Object index of that triangle.
    pub object: u32,
    /// The point.
    pub point: [f64; 3],
}

/// One listed pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PairReport {
    /// Triangle in A.
    pub a: u32,
    /// Triangle in B.
    pub b: u32,
    /// Object of `a` (index into `inputs.a.objects`).
    pub a_object: u32,
    /// Object of `b`.
    pub b_object: u32,
    /// `crossing`, `touching` or `clearance`.
    pub kind: ReportPairKind,
    /// Contact shape, `within_tolerance`, or null for clearance pairs.
    pub contact: Option<ReportContact>,
    /// 0 for exact contacts.
    pub distance: f64,
    /// Shared segment, or (tolerance/clearance pairs) the two closest points.
    pub segment: Option<[[f64; 3]; 2]>,
    /// Stable finding id, 16 hex digits, from the two triangles' coordinates and object names
    /// (see [`crate::output::baseline`]); absent only in reports of older versions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// With `--baseline`: `new` or `persistent`; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status: Option<String>,
}

/// Tree sizes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Trees {
    /// A's tree.
    pub a: TreeReport,
    /// B's tree.
    pub b: TreeReport,
}

/// One tree.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TreeReport {
    /// Nodes.
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Depth.
    pub depth: usize,
    /// SAH cost.
    pub sah_cost: f64,
    /// Bytes.
    pub bytes: usize,
    /// Cells: subtrees of at most a thousand-odd triangles that are built only when a walk first
    /// opens them. The figures above describe the tree built up front, each cell counted as one
    /// leaf (which cells a run opens depends on the walk, so they are not counted). 0 for a
    /// tree built whole (scenes' part trees).
    #[serde(default)]
    pub cells: usize,
}

/// Phase times.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimingsReport {
    /// Reading and parsing both files.
    pub load: f64,
    /// Building both trees.
    pub build: f64,
    /// Pair search and distance.
    pub query: f64,
    /// Everything.
    pub total: f64,
}

/// A point as written in reports.
pub fn v3(p: DVec3) -> [f64; 3] {
    p.to_array()
}

/// Verdict severity from its report name (for readers of old reports).
pub fn verdict_from_name(s: &str) -> Option<Verdict> {
    [Verdict::Clear, Verdict::Clearance, Verdict::Touching, Verdict::Clash]
        .into_iter()
        .find(|v| v.name() == s)
}

/// The report as pretty JSON with a trailing newline.
pub fn to_json(report: &Report) -> String {
    let mut s = Vec::new();
    pretty::write_pretty(&mut s, report).expect("report serialises");
    s.push(b'\n');
    String::from_utf8(s).expect("JSON is UTF-8")
}
