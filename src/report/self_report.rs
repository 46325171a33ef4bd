//! The JSON wire format of `meshclash self`, documented once here (README shows an example).
//!
//! Schema `meshclash.self/1`: its own document type beside `meshclash.report/2` (a two-mesh
//! report has two inputs, a closest pair and containment; a self report has one input and a
//! health block per part), in the same style: fixed field order, arrays sorted, numbers f64
//! printed shortest-round-trip, and with `--no-timings` the run-dependent fields
//! (`settings.threads`, `timings_ms`) `null`, so the same input gives byte-identical reports
//! whatever the thread count. Pairs are listed as in a two-mesh report, `a` and `b` both
//! triangles of the one input (`a < b`, same part).
//!
//! ```text
//! {
//!   "schema": "meshclash.self/1",
//!   "tool": {"name": "meshclash", "version"},
//!   "input": {"path", "format": "obj|stl|gltf|glb", "vertices", "triangles",
//!             "objects": [{"name", "triangles"}]},
//!   "settings": {"fail_on": ["self-clash", ...], "split_bodies", "whole_file", "select": [glob], "exclude": [glob],
//!                "bvh": "sah|median|equal", "leaf_size", "max_pairs", "first_n", "threads": n | null},
//!   "verdict": "clash" | "touching" | "clear",   // worst self-clash pair: crossing, touching, none
//!   "failed": bool,                              // something in fail_on was found (exit code 1)
//!   "failed_on": ["open", ...],                  // which fail_on conditions were met
//!   "summary": {"parts", "crossing_pairs", "touching_pairs", "parts_with_self_clash", "open_parts",
//!               "duplicate_faces", "zero_area_triangles", "non_manifold_edges",
//!               "non_manifold_vertices", "boundary_edges", "boundary_loops",
//!               "inconsistent_winding_edges"},      // sums over the parts
//!   "pairs": [{"a", "b", "a_object", "b_object", "kind": "crossing|touching",
//!              "contact": "point|segment|coplanar_area|coplanar_boundary", "distance": 0,
//!              "segment": [[x,y,z],[x,y,z]] | null}],
//!   "pairs_truncated": bool,
//!   "parts": [{"object": n | null, "name", "triangles", "crossing_pairs", "touching_pairs",
//!              "health": {"closed", "volume": number | null,
//!                         "duplicate_faces": {"count", "triangles": [ids]}, "zero_area_triangles": {..},
//!                         "non_manifold_edges": {..}, "non_manifold_vertices": {..},
//!                         "boundary_edges": {..}, "boundary_loops",
//!                         "inconsistent_winding_edges": {..}}}],
//!   "warnings": ["..."],
//!   "timings_ms": {"load", "health", "query", "total"} | null
//! }
//! ```
//! Triangle ids are 0-based in file order (see [`crate::load`]), after `--split-bodies` (which
//! keeps the order); `object` indexes `input.objects`. What each health field counts is in
//! [`crate::check::health`]; `volume` is an f64 sum (its sign is not exact).

use crate::check::health::{Finding, Health};
use crate::check::query::Input;
use crate::check::self_clash::PartResult;
use crate::report::{ObjectReport, PairReport, ReportContact, ReportPairKind, ReportVerdict, Tool};
use serde::{Deserialize, Serialize};

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

    /// The condition named `name` (as [`SelfFailOn::name`] writes it; `clash` is `self-clash`).
    pub fn from_name(name: &str) -> Option<SelfFailOn> {
        const ALL: [SelfFailOn; 8] = [
            SelfFailOn::SelfClash,
            SelfFailOn::Touching,
            SelfFailOn::Open,
            SelfFailOn::NonManifold,
            SelfFailOn::Duplicates,
            SelfFailOn::Degenerate,
            SelfFailOn::Winding,
            SelfFailOn::Never,
        ];
        if name == "clash" {
            return Some(SelfFailOn::SelfClash);
        }
        ALL.into_iter().find(|f| f.name() == name)
    }

    /// Does this part's result meet the condition?
    pub fn hit(self, part: &PartResult) -> bool {
        self.met(part.crossing, part.count - part.crossing, &health_report(&part.health))
    }

    /// Does a part with these self-clash counts and this health meet the condition?
    pub fn met(self, crossing: u64, touching: u64, h: &HealthReport) -> bool {
        match self {
            SelfFailOn::SelfClash => crossing > 0,
            SelfFailOn::Touching => crossing + touching > 0,
            SelfFailOn::Open => !h.closed,
            SelfFailOn::NonManifold => h.non_manifold_edges.count + h.non_manifold_vertices.count > 0,
            SelfFailOn::Duplicates => h.duplicate_faces.count > 0,
            SelfFailOn::Degenerate => h.zero_area_triangles.count > 0,
            SelfFailOn::Winding => h.inconsistent_winding_edges.count > 0,
            SelfFailOn::Never => false,
        }
    }
}

/// The schema identifier of a self report.
pub const SELF_SCHEMA: &str = "meshclash.self/1";

/// The whole self report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelfReport {
    /// Always [`SELF_SCHEMA`].
    pub schema: String,
    /// Who wrote it.
    pub tool: Tool,
    /// The input.
    pub input: SelfInput,
    /// The settings used.
    pub settings: SelfSettings,
    /// `clash` (a crossing self-clash pair), `touching` (only touching ones) or `clear`.
    pub verdict: ReportVerdict,
    /// True if something in `settings.fail_on` was found (the process exits 1).
    pub failed: bool,
    /// The `fail_on` conditions that were met.
    pub failed_on: Vec<String>,
    /// Sums over the parts (complete even when `pairs` is truncated).
    pub summary: SelfSummary,
    /// Self-clashing pairs, sorted by (a, b), at most `settings.max_pairs`.
    pub pairs: Vec<PairReport>,
    /// True if `pairs` was cut at `max_pairs`.
    pub pairs_truncated: bool,
    /// Every checked part, in object order.
    pub parts: Vec<SelfPart>,
    /// Loader warnings, prefixed with the file.
    pub warnings: Vec<String>,
    /// Phase times (null with `--no-timings`).
    pub timings_ms: Option<SelfTimings>,
}

/// The input file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelfInput {
    /// Path as given.
    pub path: String,
    /// `obj`, `stl`, `gltf` or `glb`.
    pub format: String,
    /// Vertex count.
    pub vertices: usize,
    /// Triangle count.
    pub triangles: usize,
    /// Objects in file order (after `--split-bodies`).
    pub objects: Vec<ObjectReport>,
}

/// Settings as used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelfSettings {
    /// `--fail-on` conditions, sorted.
    pub fail_on: Vec<String>,
    /// `--split-bodies`.
    pub split_bodies: bool,
    /// `--whole-file`: all triangles checked as one part.
    pub whole_file: bool,
    /// `--select` globs.
    pub select: Vec<String>,
    /// `--exclude` globs.
    pub exclude: Vec<String>,
    /// `sah`, `median` or `equal` (`--bvh`).
    pub bvh: String,
    /// Largest leaf.
    pub leaf_size: u32,
    /// Cap on listed pairs.
    pub max_pairs: usize,
    /// Cap on listed triangle ids per health finding.
    pub first_n: usize,
    /// Worker threads (null with `--no-timings`).
    pub threads: Option<usize>,
}

/// Sums over the parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelfSummary {
    /// Parts checked.
    pub parts: usize,
    /// Self-clash pairs whose interiors cross.
    pub crossing_pairs: u64,
    /// Self-clash pairs that only touch (a fold, a vertex on a face).
    pub touching_pairs: u64,
    /// Parts with at least one self-clash pair.
    pub parts_with_self_clash: usize,
    /// Parts that are not closed.
    pub open_parts: usize,
    /// Duplicate faces.
    pub duplicate_faces: u64,
    /// Zero-area triangles.
    pub zero_area_triangles: u64,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: u64,
    /// Vertices with more than one fan.
    pub non_manifold_vertices: u64,
    /// Edges used by one triangle.
    pub boundary_edges: u64,
    /// Connected components of boundary edges.
    pub boundary_loops: u64,
    /// Edges used twice in the same direction.
    pub inconsistent_winding_edges: u64,
}

/// One part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelfPart {
    /// Index into `input.objects`, or null with `--whole-file` (the part is the whole file,
    /// named by its path).
    pub object: Option<u32>,
    /// Its name.
    pub name: String,
    /// Its triangle count.
    pub triangles: usize,
    /// Its crossing self-clash pairs.
    pub crossing_pairs: u64,
    /// Its touching self-clash pairs.
    pub touching_pairs: u64,
    /// Its health.
    pub health: HealthReport,
}

/// The health of one part (see [`crate::check::health`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HealthReport {
    /// Every edge used by exactly two proper triangles.
    pub closed: bool,
    /// Signed volume (f64; positive = outward winding), null for open parts.
    pub volume: Option<f64>,
    /// Later copies of a face (either winding).
    pub duplicate_faces: FindingReport,
    /// Zero-area triangles.
    pub zero_area_triangles: FindingReport,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: FindingReport,
    /// Vertices with more than one fan of triangles (bow-ties).
    pub non_manifold_vertices: FindingReport,
    /// Edges used by one triangle.
    pub boundary_edges: FindingReport,
    /// Connected components of the boundary edges.
    pub boundary_loops: u64,
    /// Edges used twice in the same direction.
    pub inconsistent_winding_edges: FindingReport,
}

/// A count and the first triangles involved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FindingReport {
    /// How many (triangles, edges or vertices).
    pub count: u64,
    /// The lowest triangle ids involved, ascending, at most `settings.first_n`.
    pub triangles: Vec<u32>,
}

/// Phase times in milliseconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelfTimings {
    /// Reading the file (and splitting bodies).
    pub load: f64,
    /// Vertex merge and health of every part.
    pub health: f64,
    /// Trees and self-clash walks of every part.
    pub query: f64,
    /// Everything.
    pub total: f64,
}

/// What [`build`] needs.
#[derive(Debug, Clone)]
pub struct Context<'a> {
    /// The loaded input.
    pub input: &'a Input,
    /// The checked parts.
    pub parts: &'a [PartResult],
    /// `--fail-on`, sorted and deduplicated.
    pub fail_on: &'a [SelfFailOn],
    /// Those that were met.
    pub failed_on: &'a [SelfFailOn],
    /// `--split-bodies`.
    pub split_bodies: bool,
    /// `--whole-file`.
    pub whole_file: bool,
    /// `--select` globs.
    pub select: &'a [String],
    /// `--exclude` globs.
    pub exclude: &'a [String],
    /// `--bvh` (`sah`, `median` or `equal`).
    pub bvh: &'static str,
    /// `--leaf-size`.
    pub leaf_size: u32,
    /// `--max-pairs`.
    pub max_pairs: usize,
    /// `--first-n`.
    pub first_n: usize,
    /// Pool size, or None when deterministic.
    pub threads: Option<usize>,
    /// Phase times, or None when deterministic.
    pub timings: Option<SelfTimings>,
    /// Warnings.
    pub warnings: Vec<String>,
}

fn finding(f: &Finding) -> FindingReport {
    FindingReport { count: f.count, triangles: f.triangles.clone() }
}

pub(crate) fn health_report(h: &Health) -> HealthReport {
    HealthReport {
        closed: h.closed,
        volume: h.volume,
        duplicate_faces: finding(&h.duplicate_faces),
        zero_area_triangles: finding(&h.zero_area_triangles),
        non_manifold_edges: finding(&h.non_manifold_edges),
        non_manifold_vertices: finding(&h.non_manifold_vertices),
        boundary_edges: finding(&h.boundary_edges),
        boundary_loops: h.boundary_loops,
        inconsistent_winding_edges: finding(&h.inconsistent_winding_edges),
    }
}

/// The listed pairs (sorted by (a, b), at most `max_pairs`) and whether the list was cut.
pub(crate) fn pairs_of(
    mesh: &crate::scene::mesh::Mesh,
    parts: &[PartResult],
    max_pairs: usize,
) -> (Vec<PairReport>, bool) {
    let mut all: Vec<&crate::check::self_clash::SelfPair> = parts.iter().flat_map(|p| &p.pairs).collect();
    all.sort_unstable_by_key(|q| (q.a, q.b));
    let pairs = all
        .iter()
        .take(max_pairs)
        .map(|q| PairReport {
            a: q.a,
            b: q.b,
            a_object: mesh.tri_object[q.a as usize],
            b_object: mesh.tri_object[q.b as usize],
            kind: if q.hit.crossing { ReportPairKind::Crossing } else { ReportPairKind::Touching },
            contact: Some(q.hit.contact.into()),
            distance: 0.0,
            segment: q.hit.segment.map(|s| s.map(|p| p.to_array())),
            id: None,
            status: None,
        })
        .collect();
    (pairs, parts.iter().map(|p| p.count).sum::<u64>() > max_pairs as u64)
}

/// Sums over the parts.
pub(crate) fn summary_of(parts: &[PartResult]) -> SelfSummary {
    let sum = |f: &dyn Fn(&PartResult) -> u64| parts.iter().map(f).sum::<u64>();
    SelfSummary {
        parts: parts.len(),
        crossing_pairs: sum(&|p| p.crossing),
        touching_pairs: sum(&|p| p.count - p.crossing),
        parts_with_self_clash: parts.iter().filter(|p| p.count > 0).count(),
        open_parts: parts.iter().filter(|p| !p.health.closed).count(),
        duplicate_faces: sum(&|p| p.health.duplicate_faces.count),
        zero_area_triangles: sum(&|p| p.health.zero_area_triangles.count),
        non_manifold_edges: sum(&|p| p.health.non_manifold_edges.count),
        non_manifold_vertices: sum(&|p| p.health.non_manifold_vertices.count),
        boundary_edges: sum(&|p| p.health.boundary_edges.count),
        boundary_loops: sum(&|p| p.health.boundary_loops),
        inconsistent_winding_edges: sum(&|p| p.health.inconsistent_winding_edges.count),
    }
}

/// `clash` if a pair crosses, `touching` if pairs only touch, else `clear`.
pub(crate) fn verdict_of(s: &SelfSummary) -> ReportVerdict {
    if s.crossing_pairs > 0 {
        ReportVerdict::Clash
    } else if s.touching_pairs > 0 {
        ReportVerdict::Touching
    } else {
        ReportVerdict::Clear
    }
}

/// The report: a projection of the results, nothing computed here but sums.
pub fn build(ctx: &Context) -> SelfReport {
    let mesh = &ctx.input.mesh;
    let mut objects: Vec<ObjectReport> =
        mesh.objects.iter().map(|o| ObjectReport { name: o.name.clone(), triangles: 0 }).collect();
    for &o in &mesh.tri_object {
        objects[o as usize].triangles += 1;
    }
    let (pairs, pairs_truncated) = pairs_of(mesh, ctx.parts, ctx.max_pairs);
    let summary = summary_of(ctx.parts);
    let verdict = verdict_of(&summary);
    let names = |v: &[SelfFailOn]| v.iter().map(|f| f.name().to_string()).collect::<Vec<_>>();
    SelfReport {
        schema: SELF_SCHEMA.into(),
        tool: Tool::this(),
        input: SelfInput {
            path: ctx.input.path.display().to_string(),
            format: ctx.input.format.name().into(),
            vertices: mesh.positions.len(),
            triangles: mesh.triangles.len(),
            objects,
        },
        settings: SelfSettings {
            fail_on: names(ctx.fail_on),
            split_bodies: ctx.split_bodies,
            whole_file: ctx.whole_file,
            select: ctx.select.to_vec(),
            exclude: ctx.exclude.to_vec(),
            bvh: ctx.bvh.into(),
            leaf_size: ctx.leaf_size,
            max_pairs: ctx.max_pairs,
            first_n: ctx.first_n,
            threads: ctx.threads,
        },
        verdict,
        failed: !ctx.failed_on.is_empty(),
        failed_on: names(ctx.failed_on),
        summary,
        pairs,
        pairs_truncated,
        parts: ctx
            .parts
            .iter()
            .map(|p| SelfPart {
                object: p.object,
                name: p.name.clone(),
                triangles: p.triangles,
                crossing_pairs: p.crossing,
                touching_pairs: p.count - p.crossing,
                health: health_report(&p.health),
            })
            .collect(),
        warnings: ctx.warnings.clone(),
        timings_ms: ctx.timings.clone(),
    }
}

/// The report as pretty JSON with a trailing newline.
pub fn to_json(r: &SelfReport) -> String {
    let mut s = serde_json::to_string_pretty(r).expect("report serialises");
    s.push('\n');
    s
}

/// The JSON Schema (draft 2020-12) of [`SelfReport`].
pub fn schema_json() -> String {
    let mut s = serde_json::to_string_pretty(&schemars::schema_for!(SelfReport)).expect("schema serialises");
    s.push('\n');
    s
}

/// A summary for a person: the verdict, the counts, the worst parts and the first pairs.
pub fn text(r: &SelfReport) -> String {
    use std::fmt::Write;
    let s = &r.summary;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "meshclash self {}: {} ({} part{}, {} triangles){}",
        r.input.path,
        r.verdict,
        s.parts,
        if s.parts == 1 { "" } else { "s" },
        r.input.triangles,
        if r.failed { format!(" — FAILED on {}", r.failed_on.join(", ")) } else { String::new() }
    );
    let _ = writeln!(
        out,
        "  self-clash: {} crossing, {} touching pairs in {} part(s)",
        s.crossing_pairs, s.touching_pairs, s.parts_with_self_clash
    );
    let _ = writeln!(
        out,
        "  health: {} open part(s), {} boundary edges in {} loop(s), {} non-manifold edges, \
         {} non-manifold vertices, {} duplicate faces, {} zero-area triangles, {} inconsistent winding edges",
        s.open_parts,
        s.boundary_edges,
        s.boundary_loops,
        s.non_manifold_edges,
        s.non_manifold_vertices,
        s.duplicate_faces,
        s.zero_area_triangles,
        s.inconsistent_winding_edges
    );
    let problems = |p: &SelfPart| {
        let h = &p.health;
        let mut v = Vec::new();
        let mut add = |n: u64, what: &str| {
            if n > 0 {
                v.push(format!("{n} {what}"));
            }
        };
        add(p.crossing_pairs, "crossing pairs");
        add(p.touching_pairs, "touching pairs");
        add(h.boundary_edges.count, "boundary edges");
        add(h.non_manifold_edges.count, "non-manifold edges");
        add(h.non_manifold_vertices.count, "non-manifold vertices");
        add(h.duplicate_faces.count, "duplicate faces");
        add(h.zero_area_triangles.count, "zero-area triangles");
        add(h.inconsistent_winding_edges.count, "inconsistent winding edges");
        if h.volume.is_some_and(|x| x < 0.0) {
            v.push("negative volume (inside out)".into());
        }
        v
    };
    let listed: Vec<(&SelfPart, Vec<String>)> =
        r.parts.iter().map(|p| (p, problems(p))).filter(|x| !x.1.is_empty()).collect();
    for (p, v) in listed.iter().take(10) {
        let _ = writeln!(out, "  part {}: {}", p.name, v.join(", "));
    }
    if listed.len() > 10 {
        let _ = writeln!(out, "  … and {} more parts with findings", listed.len() - 10);
    }
    for p in r.pairs.iter().take(5) {
        let _ = writeln!(
            out,
            "  pair {} × {}: {} ({})",
            p.a,
            p.b,
            p.kind,
            p.contact.map_or("-", ReportContact::name)
        );
    }
    out
}

// ---------------------------------------------------------------------------------------------
// `meshclash scene FILE --self`: the `self` block of a two-mesh (`meshclash.report/2`) report.
// ---------------------------------------------------------------------------------------------

/// The `self` block of a scene report (`--self`): every selected part checked against itself.
/// Additive: absent without `--self`, and nothing else in the report changes meaning — `verdict`,
/// `summary` and `pairs` stay part against part; this block has its own `verdict`, and
/// `failed` (top level) is also true when this block's `failed` is.
///
/// ```text
/// "self": {"fail_on": ["self-clash", ...], "verdict": "clash|touching|clear", "failed", "failed_on",
///          "checks",                      // parts walked; the others are exact translates of one
///          "summary": {...as in meshclash.self/1...},
///          "pairs": [{"a", "b", "a_object", "b_object", "kind", "contact", "distance", "segment"}],
///          "pairs_truncated",
///          "parts": [{"part", "object", "name", "triangles", "crossing_pairs", "touching_pairs",
///                     "same_as": part | null, "health": {...as in meshclash.self/1...}}],
///          "time_ms": number | null}
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSelfReport {
    /// The conditions that fail the run: `self-clash` (with `--fail-on clash`), `touching`
    /// (with `--fail-on touching` or `clearance`), and those of `--self-fail-on`, sorted.
    pub fail_on: Vec<String>,
    /// `clash` (a crossing self-clash pair), `touching` (only touching ones) or `clear`.
    pub verdict: ReportVerdict,
    /// True if something in `fail_on` was found (then the run fails: exit code 1).
    pub failed: bool,
    /// The `fail_on` conditions that were met.
    pub failed_on: Vec<String>,
    /// Parts whose check ran; every other part's result was taken over from a part its placed
    /// coordinates are an exact translate of (`same_as`).
    pub checks: usize,
    /// Sums over the parts, as in a `meshclash self` report (complete even when `pairs` is cut).
    pub summary: SelfSummary,
    /// Self-clashing pairs (`a < b`, both triangles of one part, indices into the file), sorted
    /// by (a, b), at most `settings.max_pairs`.
    pub pairs: Vec<PairReport>,
    /// True if `pairs` was cut at `settings.max_pairs`.
    pub pairs_truncated: bool,
    /// Every checked part, in part order.
    pub parts: Vec<SceneSelfPart>,
    /// Milliseconds spent (null with `--no-timings`).
    pub time_ms: Option<f64>,
}

/// One part of the `self` block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSelfPart {
    /// Index into the report's `parts`.
    pub part: usize,
    /// Object index (`inputs.a.objects`).
    pub object: u32,
    /// Its name.
    pub name: String,
    /// Its triangle count.
    pub triangles: usize,
    /// Its crossing self-clash pairs.
    pub crossing_pairs: u64,
    /// Its touching self-clash pairs.
    pub touching_pairs: u64,
    /// The part (index into the report's `parts`) whose check this result was taken over from
    /// (an instance of the same mesh whose placed coordinates are an exact translate of this
    /// one's: every verdict is the same), or null when it was checked itself.
    pub same_as: Option<usize>,
    /// Its health.
    pub health: HealthReport,
}

/// What `--fail-on` of a scene means for self-clash: `clash` fails on crossing self-clash pairs,
/// `touching` and `clearance` on any self-clash pair, `never` (and `new`, which compares part
/// pairs with a baseline) on none. `extra` (`--self-fail-on`) adds health conditions.
pub fn scene_fail_on(fail_on: crate::check::query::FailOn, extra: &[SelfFailOn]) -> Vec<SelfFailOn> {
    use crate::check::query::FailOn;
    let mut v: Vec<SelfFailOn> = match fail_on {
        FailOn::Clash => vec![SelfFailOn::SelfClash],
        FailOn::Touching | FailOn::Clearance => vec![SelfFailOn::Touching],
        FailOn::Never => Vec::new(),
    };
    v.extend_from_slice(extra);
    v.sort_unstable();
    v.dedup();
    v
}

/// What is wrong with one part, for a person: `3 crossing pairs, 12 boundary edges, ...`.
pub fn part_problems(crossing: u64, touching: u64, h: &HealthReport) -> Vec<String> {
    let mut v = Vec::new();
    let mut add = |n: u64, what: &str| {
        if n > 0 {
            v.push(format!("{n} {what}"));
        }
    };
    add(crossing, "crossing pairs");
    add(touching, "touching pairs");
    add(h.boundary_edges.count, "boundary edges");
    add(h.non_manifold_edges.count, "non-manifold edges");
    add(h.non_manifold_vertices.count, "non-manifold vertices");
    add(h.duplicate_faces.count, "duplicate faces");
    add(h.zero_area_triangles.count, "zero-area triangles");
    add(h.inconsistent_winding_edges.count, "inconsistent winding edges");
    if h.volume.is_some_and(|x| x < 0.0) {
        v.push("negative volume (inside out)".into());
    }
    v
}

/// Triangle ids listed per health finding of a part in a scene's `self` block.
pub const SCENE_FIRST_N: usize = 10;

/// How many parts with findings the scene summary names.
const SCENE_TEXT_PARTS: usize = 5;

/// The summary lines of the `self` block (for the scene's text summary): the verdict and
/// counts, the health sums and the first parts with findings; each line starts with two spaces.
pub fn scene_text(x: &SceneSelfReport) -> String {
    use std::fmt::Write;
    let s = &x.summary;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "  self: {} — {} crossing, {} touching self-clash pairs in {} of {} part(s){}",
        x.verdict,
        s.crossing_pairs,
        s.touching_pairs,
        s.parts_with_self_clash,
        s.parts,
        if x.failed { format!(" — FAILED on {}", x.failed_on.join(", ")) } else { String::new() }
    );
    let _ = writeln!(
        out,
        "  self health: {} open part(s), {} boundary edges, {} non-manifold edges, {} non-manifold vertices, \
         {} duplicate faces, {} zero-area triangles, {} inconsistent winding edges",
        s.open_parts,
        s.boundary_edges,
        s.non_manifold_edges,
        s.non_manifold_vertices,
        s.duplicate_faces,
        s.zero_area_triangles,
        s.inconsistent_winding_edges
    );
    let listed: Vec<(&SceneSelfPart, Vec<String>)> = x
        .parts
        .iter()
        .map(|p| (p, part_problems(p.crossing_pairs, p.touching_pairs, &p.health)))
        .filter(|(_, v)| !v.is_empty())
        .collect();
    for (p, v) in listed.iter().take(SCENE_TEXT_PARTS) {
        let _ = writeln!(out, "    {}: {}", p.name, v.join(", "));
    }
    if listed.len() > SCENE_TEXT_PARTS {
        let _ = writeln!(out, "    … and {} more parts with findings", listed.len() - SCENE_TEXT_PARTS);
    }
    out
}
