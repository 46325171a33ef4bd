//! `--html FILE`: one self-contained HTML page to look at a report: the text summary (verdict,
//! inputs, settings, timings) at the top, a sortable and filterable list of clashes (one row per
//! clash region, or per part pair when a part pair has no region), and a small WebGL viewer
//! (`html/viewer.js`, written for this page: orbit camera, flat shading, no library) that frames
//! the clash of a clicked row, draws its two parts in two colours, everything else faded, and the
//! crossing segments and the witness segment on top.
//!
//! Nothing is fetched: the geometry, the script and the style are inside the file. The geometry
//! is only what the clashes need: every part of a clash (a part larger than [`PART_FULL`]
//! triangles is clipped to the neighbourhood of its clashes plus a thin stride sample of the
//! rest), then the other parts as faded context while the page stays under [`MAX_TRIANGLES`]
//! triangles, and the remaining ones as their boxes. Positions are f32 relative to the centre of
//! the inputs, so far-from-origin models keep their precision.
//!
//! The page is a pure function of the report and the meshes: reports written with
//! `--no-timings` give byte-identical pages whatever the thread count.

use crate::check::query::{ClashResult, PairKind};
use crate::geom::Aabb;
use crate::report::self_report::SelfReport;
use crate::report::Report;
use crate::report::{ReportContainment, ReportVerdict};
use crate::scene::mesh::Mesh;
use base64::Engine;
use glam::DVec3;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

const STYLE: &str = include_str!("html/viewer.css");
const SCRIPT: &str = include_str!("html/viewer.js");

/// Triangles of geometry a page carries at most (clash parts first, then context parts).
pub const MAX_TRIANGLES: usize = 400_000;
/// A clash part up to this many triangles is kept whole; a larger one is clipped around its
/// clashes.
pub const PART_FULL: usize = 100_000;
/// Triangles of a clipped part kept as a stride sample away from its clashes.
pub const CLIP_CONTEXT: usize = 10_000;
/// Segments (crossing curve pieces) drawn per clash row at most.
pub const MAX_SEGMENTS: usize = 4_000;

/// A part of one input: (mesh slot, object index). In scene and self checks both sides are
/// the same mesh, slot 0.
type PartKey = (usize, u32);

/// A row's two parts and its member pairs (carried through the sort).
type RowExtra = ((PartKey, PartKey), Vec<usize>);

/// One row of the clash list.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Stable id (region id, or `pair:<a>:<b>` for a part pair without a region).
    pub id: String,
    /// Index of the A part in the page's `parts`.
    pub a: usize,
    /// Index of the B part.
    pub b: usize,
    /// Names.
    pub a_name: String,
    /// Names.
    pub b_name: String,
    /// `crossing`, `touching`, `contained`, `volumes overlap`, `clearance`, `closest`.
    pub kind: String,
    /// Triangle pairs in the clash.
    pub pairs: u64,
    /// Of those, crossing.
    pub crossing: u64,
    /// Distance (0 for contacts), or null.
    pub distance: Option<f64>,
    /// Penetration estimate, when computed.
    pub penetration: Option<f64>,
    /// The penetration depth is exact (both objects convex: `method: "exact_convex"`); absent
    /// for a sampled lower bound.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub penetration_exact: bool,
    /// Extent of the exact overlap box of the two parts (clashing closed parts; a region only
    /// when it is its part pair's only region), else absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overlap: Option<[f64; 3]>,
    /// `new`, `persistent`, or null (no baseline, or no listed pair in the row).
    pub status: Option<String>,
    /// Box of the clash (world, relative to the page centre).
    pub bounds: [[f32; 3]; 2],
    /// Contact segments, flat `[x0,y0,z0,x1,y1,z1, ...]`, relative to the page centre.
    pub segments: Vec<f32>,
    /// Segments of the row that are not drawn (over [`MAX_SEGMENTS`]).
    pub segments_left_off: usize,
    /// The witness segment (closest points or penetration point), flat 6 numbers, or empty.
    pub witness: Vec<f32>,
}

#[derive(Debug, Clone, Serialize)]
struct PartView {
    name: String,
    /// `a` or `b`: the side it is on in the first row naming it (colour in the overview).
    side: String,
    /// Triangles in the part.
    triangles: usize,
    /// Triangles carried (0 when only the box is).
    shown: usize,
    clipped: bool,
    involved: bool,
    /// Base64 of little-endian f32 xyz, relative to the page centre.
    positions: String,
    /// Base64 of little-endian u32 triangle indices.
    indices: String,
    bounds: [[f32; 3]; 2],
}

#[derive(Debug, Clone, Serialize)]
struct Page {
    title: String,
    verdict: String,
    failed: bool,
    units: String,
    /// `z` or `y` (`--up`; `z` by default for STL inputs, CAD being Z up).
    up: String,
    centre: [f64; 3],
    parts: Vec<PartView>,
    rows: Vec<Row>,
    triangles_shown: usize,
    triangles_total: usize,
}

/// The HTML page for a two-file or scene report. `result` and the meshes are those the report
/// was built from (scene mode: `a` and `b` are the same mesh).
/// `z_up`: the viewer orbits around Z (`--up`).
pub fn export(rep: &Report, result: &ClashResult, a: &Mesh, b: &Mesh, z_up: bool) -> String {
    let same = std::ptr::eq(a, b);
    let meshes: Vec<&Mesh> = if same { vec![a] } else { vec![a, b] };
    let Clashes { rows, keys, centre, .. } = clashes(rep, result, a, b);
    let title = if same {
        format!("meshclash scene {}", rep.inputs.a.path)
    } else {
        format!("meshclash {} {}", rep.inputs.a.path, rep.inputs.b.path)
    };
    let summary = crate::output::text::render(rep, false);
    page(
        PageInput {
            title,
            verdict: rep.verdict.name().to_string(),
            failed: rep.failed,
            units: rep.settings.units.clone(),
            up: if z_up { "z" } else { "y" }.into(),
            summary,
            meshes: &meshes,
            centre,
        },
        rows,
        &keys,
    )
}

/// The clashes of a report, worst first, as the page lists them (the BCF topics use them too).
pub struct Clashes {
    /// One per clash region, or part pair without one, or the closest points of a clear run.
    pub rows: Vec<Row>,
    /// For each row, its A and B part: (mesh slot: 0, or 1 for B in a two-file check; object).
    pub keys: Vec<((usize, u32), (usize, u32))>,
    /// The world point the rows' coordinates are relative to.
    pub centre: DVec3,
    /// For each row, its pairs (indices into the result's pairs; empty for a part pair without
    /// a region).
    pub members: Vec<Vec<usize>>,
}

/// The rows of [`Clashes`] for a report (see [`export`] for the arguments).
pub fn clashes(rep: &Report, result: &ClashResult, a: &Mesh, b: &Mesh) -> Clashes {
    let same = std::ptr::eq(a, b);
    let meshes: Vec<&Mesh> = if same { vec![a] } else { vec![a, b] };
    let slot_b = if same { 0 } else { 1 };
    let centre = centre_of(&meshes);
    let rel = |p: DVec3| -> [f32; 3] { (p - centre).as_vec3().to_array() };
    let mut rows = Vec::new();
    let mut keys: Vec<(PartKey, PartKey)> = Vec::new();
    let mut members_of: Vec<Vec<usize>> = Vec::new();

    // Rows from regions (their member pairs give segments and baseline status).
    let regions = crate::check::regions::regions(&result.pairs, a, b);
    let mut covered: BTreeSet<(PartKey, PartKey)> = BTreeSet::new();
    for (g, gr) in regions.iter().zip(&rep.regions) {
        debug_assert_eq!(g.id, gr.id);
        let ka = (0, g.objects.0);
        let kb = (slot_b, g.objects.1);
        covered.insert((ka, kb));
        let members: Vec<usize> = g.members.clone();
        let kinds: BTreeSet<u8> = members
            .iter()
            .map(|&m| match result.pairs[m].kind {
                PairKind::Crossing => 0,
                PairKind::Touching => 1,
                _ => 2,
            })
            .collect();
        let kind = match kinds.first() {
            Some(0) => "crossing",
            Some(1) => "touching",
            _ => "clearance",
        };
        let (segments, left_off) = segments_of(members.iter().map(|&m| &result.pairs[m]), &rel, kind);
        let nearest = members
            .iter()
            .map(|&m| &result.pairs[m])
            .filter(|p| p.kind == PairKind::Clearance || p.contact.is_none())
            .min_by(|x, y| x.distance.total_cmp(&y.distance).then((x.a, x.b).cmp(&(y.a, y.b))));
        let witness =
            nearest.and_then(|p| p.segment).map(|[s, t]| flat(&[rel(s), rel(t)])).unwrap_or_default();
        let distance = match kind {
            "clearance" => nearest.map(|p| p.distance),
            _ => Some(0.0),
        };
        let status = status_of(rep, &members);
        rows.push(Row {
            id: g.id.clone(),
            a: 0,
            b: 0,
            a_name: gr.a_name.clone(),
            b_name: gr.b_name.clone(),
            kind: kind.into(),
            pairs: g.pairs as u64,
            crossing: g.crossing as u64,
            distance,
            penetration: gr.penetration.as_ref().map(|p| p.depth),
            penetration_exact: gr.penetration.as_ref().is_some_and(|p| p.is_exact()),
            overlap: gr.overlap.as_ref().map(|o| o.extent),
            status,
            bounds: [rel(g.bounds.min), rel(g.bounds.max)],
            segments,
            segments_left_off: left_off,
            witness,
        });
        keys.push((ka, kb));
        members_of.push(members);
    }

    // Part pairs without a region: containment, or findings not grouped.
    for pp in &rep.part_pairs {
        let (Some(pa), Some(pb)) = (rep.parts.get(pp.a), rep.parts.get(pp.b)) else { continue };
        let slot = |input: &str| if input == "b" { slot_b } else { 0 };
        let (ka, kb) = ((slot(&pa.input), pa.object), (slot(&pb.input), pb.object));
        if covered.contains(&(ka, kb)) {
            continue;
        }
        let kind = match pp.contained {
            Some(ReportContainment::VolumesOverlap) => "volumes overlap",
            Some(ReportContainment::Undecided) | None => match pp.verdict {
                ReportVerdict::Clash => "crossing",
                v => v.name(),
            },
            Some(_) => "contained",
        };
        let (bounds, witness) = match &pp.closest {
            Some(c) => {
                let (p, q) = (DVec3::from_array(c.a.point), DVec3::from_array(c.b.point));
                let bx = Aabb { min: p.min(q), max: p.max(q) };
                ([rel(bx.min), rel(bx.max)], flat(&[rel(p), rel(q)]))
            }
            None => {
                let bx = Aabb {
                    min: DVec3::from_array(pa.bounds.min).min(DVec3::from_array(pb.bounds.min)),
                    max: DVec3::from_array(pa.bounds.max).max(DVec3::from_array(pb.bounds.max)),
                };
                ([rel(bx.min), rel(bx.max)], Vec::new())
            }
        };
        rows.push(Row {
            id: format!("pair:{}:{}", pp.a, pp.b),
            a: 0,
            b: 0,
            a_name: pp.a_name.clone(),
            b_name: pp.b_name.clone(),
            kind: kind.into(),
            pairs: pp.crossing_pairs + pp.touching_pairs + pp.clearance_pairs,
            crossing: pp.crossing_pairs,
            distance: pp.min_distance,
            penetration: None,
            penetration_exact: false,
            overlap: pp.overlap.as_ref().map(|o| o.extent),
            status: None,
            bounds,
            segments: Vec::new(),
            segments_left_off: 0,
            witness,
        });
        keys.push((ka, kb));
        members_of.push(Vec::new());
    }

    // Nothing listed: one row for the closest points (or the containment of one input in the
    // other, decided for the inputs as a whole), so the page still shows where.
    if rows.is_empty() {
        if let Some(c) = &rep.closest {
            let kind = match rep.summary.contained {
                Some(ReportContainment::VolumesOverlap) => "volumes overlap",
                Some(ReportContainment::Undecided) | None => "closest",
                Some(_) => "contained",
            };
            let (p, q) = (DVec3::from_array(c.a.point), DVec3::from_array(c.b.point));
            let ka = (0, c.a.object);
            let kb = (slot_b, c.b.object);
            rows.push(Row {
                id: "closest".into(),
                a: 0,
                b: 0,
                a_name: object_name(&meshes, ka),
                b_name: object_name(&meshes, kb),
                kind: kind.into(),
                pairs: 0,
                crossing: 0,
                distance: Some(c.distance),
                penetration: None,
                penetration_exact: false,
                overlap: None,
                status: None,
                bounds: [rel(p.min(q)), rel(p.max(q))],
                segments: Vec::new(),
                segments_left_off: 0,
                witness: flat(&[rel(p), rel(q)]),
            });
            keys.push((ka, kb));
            members_of.push(Vec::new());
        }
    }

    // Worst first: crossing and containment, then touching, clearance, closest; deeper, then
    // more pairs, then nearer; the id breaks ties.
    let rank = |k: &str| match k {
        "crossing" | "contained" | "volumes overlap" => 0,
        "touching" => 1,
        "clearance" => 2,
        _ => 3,
    };
    let mut both: Vec<(Row, RowExtra)> = rows.into_iter().zip(keys.into_iter().zip(members_of)).collect();
    both.sort_by(|(x, _), (y, _)| {
        rank(&x.kind)
            .cmp(&rank(&y.kind))
            .then(y.penetration.unwrap_or(0.0).total_cmp(&x.penetration.unwrap_or(0.0)))
            .then(y.pairs.cmp(&x.pairs))
            .then(x.distance.unwrap_or(f64::INFINITY).total_cmp(&y.distance.unwrap_or(f64::INFINITY)))
            .then(x.id.cmp(&y.id))
    });
    let (rows, rest): (Vec<Row>, Vec<RowExtra>) = both.into_iter().unzip();
    let (keys, members) = rest.into_iter().unzip();
    Clashes { rows, keys, centre, members }
}

/// One finding of a `meshclash self` report, as the HTML list and the GLB show it: a part's
/// self-clashing pairs, or one kind of health problem of a part.
#[derive(Debug, Clone)]
pub struct SelfFinding {
    /// The part's object (None with `--whole-file`).
    pub object: Option<u32>,
    /// The part's name.
    pub part: String,
    /// `crossing` or `touching` (self-clash); `non-manifold`, `duplicate faces`, `zero-area`,
    /// `winding` or `open` (health).
    pub kind: String,
    /// `self-clash crossing bracket, 12 pairs`, `open bracket: 40 boundary edges, 2 loops`.
    pub title: String,
    /// Pairs, edges, faces or vertices (complete).
    pub count: u64,
    /// Of the pairs, crossing.
    pub crossing: u64,
    /// Listed triangles: of a self-clash, the lower triangle of each listed pair; of a health
    /// finding, its first triangles (`--first-n`).
    pub a_tris: Vec<u32>,
    /// Of a self-clash, the higher triangle of each listed pair when it is not also a lower one.
    pub b_tris: Vec<u32>,
    /// Contact segments of the listed pairs (world), at most [`MAX_SEGMENTS`].
    pub segments: Vec<[DVec3; 2]>,
    /// Segments left off.
    pub segments_left_off: usize,
}

/// The findings of a self report, worst first: self-clashes (crossing, then touching; more
/// pairs first), then health problems part by part (non-manifold, duplicate faces, zero-area
/// triangles, winding, open). Only the report's listed pairs are drawn; counts are complete.
pub fn self_findings(rep: &SelfReport) -> Vec<SelfFinding> {
    let (mut clash, mut health) = (Vec::new(), Vec::new());
    for p in &rep.parts {
        // `--whole-file` names the part by the path as given: show the file name only.
        let part = if p.object.is_none() { crate::output::glb::file_name(&p.name) } else { p.name.clone() };
        let pairs = p.crossing_pairs + p.touching_pairs;
        if pairs > 0 {
            let listed: Vec<&crate::report::PairReport> =
                rep.pairs.iter().filter(|q| p.object.is_none_or(|o| q.a_object == o)).collect();
            let a: BTreeSet<u32> = listed.iter().map(|q| q.a).collect();
            let b: BTreeSet<u32> = listed.iter().map(|q| q.b).filter(|t| !a.contains(t)).collect();
            let segs: Vec<[DVec3; 2]> = listed
                .iter()
                .filter_map(|q| q.segment)
                .map(|[s, t]| [DVec3::from_array(s), DVec3::from_array(t)])
                .collect();
            let stride = segs.len().div_ceil(MAX_SEGMENTS).max(1);
            let segments: Vec<[DVec3; 2]> = segs.iter().step_by(stride).copied().collect();
            let kind = if p.crossing_pairs > 0 { "crossing" } else { "touching" };
            let note = if (listed.len() as u64) < pairs {
                format!(" ({} listed)", listed.len())
            } else {
                String::new()
            };
            clash.push(SelfFinding {
                object: p.object,
                part: part.clone(),
                kind: kind.into(),
                title: format!(
                    "self-clash {kind} {}, {pairs} pair{}{note}",
                    p.name,
                    if pairs == 1 { "" } else { "s" }
                ),
                count: pairs,
                crossing: p.crossing_pairs,
                a_tris: a.into_iter().collect(),
                b_tris: b.into_iter().collect(),
                segments_left_off: segs.len() - segments.len(),
                segments,
            });
        }
        let h = &p.health;
        let loops = format!(", {} loop{}", h.boundary_loops, if h.boundary_loops == 1 { "" } else { "s" });
        for (kind, f, what) in [
            ("non-manifold", &h.non_manifold_edges, "non-manifold edges".to_string()),
            ("non-manifold", &h.non_manifold_vertices, "non-manifold vertices".to_string()),
            ("duplicate faces", &h.duplicate_faces, "duplicate faces".to_string()),
            ("zero-area", &h.zero_area_triangles, "zero-area triangles".to_string()),
            ("winding", &h.inconsistent_winding_edges, "edges with inconsistent winding".to_string()),
            ("open", &h.boundary_edges, format!("boundary edges{loops}")),
        ] {
            if f.count == 0 {
                continue;
            }
            health.push(SelfFinding {
                object: p.object,
                part: part.clone(),
                kind: kind.into(),
                title: format!("{kind} {part}: {} {what}", f.count),
                count: f.count,
                crossing: 0,
                a_tris: f.triangles.clone(),
                b_tris: Vec::new(),
                segments: Vec::new(),
                segments_left_off: 0,
            });
        }
    }
    clash.sort_by(|x, y| {
        (x.kind != "crossing")
            .cmp(&(y.kind != "crossing"))
            .then(y.count.cmp(&x.count))
            .then(x.object.cmp(&y.object))
    });
    clash.extend(health);
    clash
}

/// The HTML page of a `meshclash self` report: one row per finding ([`self_findings`]). The
/// viewer draws a self-clash's lower triangles as A (orange) and higher ones as B (blue), and a
/// health finding's triangles as B against the rest of its part as A; other parts faded.
pub fn export_self(rep: &SelfReport, mesh: &Mesh, z_up: bool) -> String {
    let findings = self_findings(rep);
    let centre = centre_of(&[mesh]);
    let rel = |p: DVec3| -> [f32; 3] { (p - centre).as_vec3().to_array() };
    // A page mesh where each finding's triangles are copies in objects of their own. A
    // self-clash's triangles leave their part (its two sides are the row's A and B); a health
    // finding's stay in the part, which is its row's A (the viewer draws the smaller B over it).
    let mut m = mesh.clone();
    if rep.settings.whole_file {
        m.tri_object = vec![0; m.triangles.len()];
        m.objects = vec![crate::scene::mesh::Object {
            name: crate::output::glb::file_name(&rep.input.path),
            ..Default::default()
        }];
    }
    let mut moved = vec![false; mesh.triangles.len()];
    let (mut copies, mut copy_object) = (Vec::new(), Vec::new());
    let mut rows = Vec::new();
    let mut keys = Vec::new();
    for f in &findings {
        let is_clash = f.kind == "crossing" || f.kind == "touching";
        let mut new_object = |m: &mut Mesh, name: String, tris: &[u32]| -> u32 {
            let o = m.objects.len() as u32;
            m.objects.push(crate::scene::mesh::Object { name, ..Default::default() });
            for &t in tris {
                if let Some(slot) = moved.get_mut(t as usize) {
                    *slot |= is_clash;
                    copies.push(mesh.triangles[t as usize]);
                    copy_object.push(o);
                }
            }
            o
        };
        let part_object = f.object.unwrap_or(0);
        let (ka, kb, a_name, b_name) = if is_clash {
            let (na, nb) =
                (format!("{} (lower triangles)", f.part), format!("{} (higher triangles)", f.part));
            (new_object(&mut m, na.clone(), &f.a_tris), new_object(&mut m, nb.clone(), &f.b_tris), na, nb)
        } else {
            let nb = format!("{} ({})", f.part, f.kind);
            (part_object, new_object(&mut m, nb.clone(), &f.a_tris), f.part.clone(), nb)
        };
        let tri_box = f.a_tris.iter().chain(&f.b_tris).fold(Aabb::EMPTY, |b, &t| {
            mesh.triangles[t as usize].iter().fold(b, |b, &v| b.grow(mesh.positions[v as usize]))
        });
        let bx = f.segments.iter().fold(tri_box, |b, [p, q]| b.grow(*p).grow(*q));
        let bounds = if bx.is_empty() { [[0.0; 3]; 2] } else { [rel(bx.min), rel(bx.max)] };
        let segments: Vec<[f32; 3]> = f.segments.iter().flat_map(|[p, q]| [rel(*p), rel(*q)]).collect();
        rows.push(Row {
            id: format!("self:{}:{}", f.object.map_or_else(|| "file".to_string(), |o| o.to_string()), f.kind),
            a: 0,
            b: 0,
            a_name,
            b_name,
            kind: f.kind.clone(),
            pairs: f.count,
            crossing: f.crossing,
            distance: is_clash.then_some(0.0),
            penetration: None,
            penetration_exact: false,
            overlap: None,
            status: None,
            bounds,
            segments: flat(&segments),
            segments_left_off: f.segments_left_off,
            witness: Vec::new(),
        });
        keys.push(((0, ka), (0, kb)));
    }
    let keep: Vec<usize> = (0..mesh.triangles.len()).filter(|&t| !moved[t]).collect();
    m.triangles = keep.iter().map(|&t| mesh.triangles[t]).chain(copies).collect();
    let mut objs: Vec<u32> = keep.iter().map(|&t| m.tri_object[t]).collect();
    objs.extend(copy_object);
    m.tri_object = objs;
    page(
        PageInput {
            title: format!("meshclash self {}", rep.input.path),
            verdict: rep.verdict.name().to_string(),
            failed: rep.failed,
            units: "model".into(),
            up: if z_up { "z" } else { "y" }.into(),
            summary: crate::report::self_report::text(rep),
            meshes: &[&m],
            centre,
        },
        rows,
        &keys,
    )
}

/// Everything [`page`] needs besides the rows.
struct PageInput<'a> {
    title: String,
    verdict: String,
    failed: bool,
    units: String,
    up: String,
    summary: String,
    meshes: &'a [&'a Mesh],
    centre: DVec3,
}

fn centre_of(meshes: &[&Mesh]) -> DVec3 {
    let bx = meshes.iter().fold(Aabb::EMPTY, |b, m| b.union(Aabb::of_points(&m.positions)));
    let c = (bx.min + bx.max) * 0.5;
    if c.is_finite() {
        c
    } else {
        DVec3::ZERO
    }
}

fn object_name(meshes: &[&Mesh], k: PartKey) -> String {
    meshes[k.0].objects.get(k.1 as usize).map_or_else(|| format!("object {}", k.1), |o| o.name.clone())
}

fn flat(points: &[[f32; 3]]) -> Vec<f32> {
    points.iter().flatten().copied().collect()
}

/// The contact segments of `pairs` (for a clearance row: the closest-point segments), at most
/// [`MAX_SEGMENTS`] taken at an even stride, and how many were left off.
fn segments_of<'p>(
    pairs: impl Iterator<Item = &'p crate::check::query::PairFinding>,
    rel: &impl Fn(DVec3) -> [f32; 3],
    kind: &str,
) -> (Vec<f32>, usize) {
    let segs: Vec<[DVec3; 2]> =
        pairs.filter(|p| kind == "clearance" || p.contact.is_some()).filter_map(|p| p.segment).collect();
    let stride = segs.len().div_ceil(MAX_SEGMENTS).max(1);
    let kept: Vec<[f32; 3]> = segs.iter().step_by(stride).flat_map(|[s, t]| [rel(*s), rel(*t)]).collect();
    let n = kept.len() / 2;
    (flat(&kept), segs.len() - n)
}

/// `new` if a listed member pair is new, else `persistent` if one is persistent, else None.
fn status_of(rep: &Report, members: &[usize]) -> Option<String> {
    let st: BTreeSet<&str> = members.iter().filter_map(|&m| rep.pairs.get(m)?.status.as_deref()).collect();
    if st.contains("new") {
        Some("new".into())
    } else if st.contains("persistent") {
        Some("persistent".into())
    } else {
        None
    }
}

fn b64<T: Copy>(v: &[T], bytes: impl Fn(T) -> [u8; 4]) -> String {
    let raw: Vec<u8> = v.iter().flat_map(|&x| bytes(x)).collect();
    base64::engine::general_purpose::STANDARD.encode(raw)
}

/// Assemble the page: geometry for the parts of `keys` (and context), the rows pointing at
/// their parts, the data embedded as JSON.
fn page(input: PageInput, mut rows: Vec<Row>, keys: &[(PartKey, PartKey)]) -> String {
    let PageInput { title, verdict, failed, units, up, summary, meshes, centre } = input;
    // Triangles of every object, per mesh slot.
    let by_object: Vec<Vec<Vec<u32>>> = meshes
        .iter()
        .map(|m| {
            let mut v = vec![Vec::new(); m.objects.len().max(1)];
            for (t, &o) in m.tri_object.iter().enumerate() {
                if let Some(list) = v.get_mut(o as usize) {
                    list.push(t as u32);
                }
            }
            v
        })
        .collect();
    // Involved parts in order of first appearance, with their side and the boxes of their rows.
    let mut order: Vec<PartKey> = Vec::new();
    let mut side: BTreeMap<PartKey, &str> = BTreeMap::new();
    let mut near: BTreeMap<PartKey, Vec<Aabb>> = BTreeMap::new();
    for (row, &(ka, kb)) in rows.iter().zip(keys) {
        let bx = Aabb {
            min: DVec3::from_array(row.bounds[0].map(f64::from)) + centre,
            max: DVec3::from_array(row.bounds[1].map(f64::from)) + centre,
        };
        for (k, s) in [(ka, "a"), (kb, "b")] {
            if let std::collections::btree_map::Entry::Vacant(e) = side.entry(k) {
                e.insert(s);
                order.push(k);
            }
            near.entry(k).or_default().push(bx);
        }
    }
    let involved: BTreeSet<PartKey> = order.iter().copied().collect();
    for (slot, objs) in by_object.iter().enumerate() {
        for o in 0..objs.len() as u32 {
            if !involved.contains(&(slot, o)) && !objs[o as usize].is_empty() {
                order.push((slot, o));
            }
        }
    }

    let mut parts = Vec::new();
    let mut index: BTreeMap<PartKey, usize> = BTreeMap::new();
    let mut shown_total = 0usize;
    let mut total = 0usize;
    for &k in &order {
        let mesh = meshes[k.0];
        let all: &[u32] = by_object[k.0].get(k.1 as usize).map_or(&[], |v| v.as_slice());
        total += all.len();
        let is_involved = involved.contains(&k);
        let (tris, clipped): (Vec<u32>, bool) = if is_involved {
            if all.len() <= PART_FULL {
                (all.to_vec(), false)
            } else {
                (clip(mesh, all, &near[&k]), true)
            }
        } else if shown_total + all.len() <= MAX_TRIANGLES {
            (all.to_vec(), false)
        } else {
            (Vec::new(), false)
        };
        shown_total += tris.len();
        let bx = part_box(mesh, all);
        let (tri_idx, vmap) = mesh.reindex(&tris);
        let pos: Vec<f32> =
            vmap.iter().flat_map(|&v| (mesh.positions[v as usize] - centre).as_vec3().to_array()).collect();
        let idx: Vec<u32> = tri_idx.iter().flatten().copied().collect();
        index.insert(k, parts.len());
        let rel_box = |p: DVec3| (p - centre).as_vec3().to_array();
        parts.push(PartView {
            name: object_name(meshes, k),
            side: side.get(&k).copied().unwrap_or("").into(),
            triangles: all.len(),
            shown: tris.len(),
            clipped,
            involved: is_involved,
            positions: b64(&pos, f32::to_le_bytes),
            indices: b64(&idx, u32::to_le_bytes),
            bounds: if bx.min.is_finite() { [rel_box(bx.min), rel_box(bx.max)] } else { [[0.0; 3]; 2] },
        });
    }
    for (row, (ka, kb)) in rows.iter_mut().zip(keys) {
        row.a = index[ka];
        row.b = index[kb];
    }
    let data = Page {
        title: title.clone(),
        verdict: verdict.clone(),
        failed,
        units,
        up,
        centre: centre.to_array(),
        parts,
        rows,
        triangles_shown: shown_total,
        triangles_total: total,
    };
    let json = serde_json::to_string(&data).expect("page data serialises");
    // Inside <script>: no `<` may appear raw (`</script>`, `<!--`).
    let json = json.replace('<', "\\u003c");
    let verdict_class = if failed { "failed" } else { "passed" };
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:\">\n\
<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
<title>{title}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n\
<header><h1 class=\"{verdict_class}\">{title}</h1>\n<pre id=\"summary\">{summary}</pre></header>\n\
<main>\n<section id=\"list\"><div class=\"tools\"><input id=\"filter\" type=\"search\" placeholder=\"filter part names\">\
<button id=\"overview\" type=\"button\">overview</button>\
<label><input id=\"xray\" type=\"checkbox\" checked> see through</label><span id=\"count\"></span></div>\n\
<table id=\"clashes\"><thead><tr><th data-key=\"rank\">#</th><th data-key=\"a_name\">part A</th>\
<th data-key=\"b_name\">part B</th><th data-key=\"kind\">kind</th><th data-key=\"pairs\">pairs</th>\
<th data-key=\"measure\">distance / depth</th><th data-key=\"status\">status</th></tr></thead><tbody></tbody></table>\n\
</section>\n<section id=\"view\"><canvas id=\"gl\" width=\"960\" height=\"640\"></canvas>\
<div id=\"legend\"></div><div id=\"nogl\" hidden>WebGL is not available in this browser: the list above still works.</div></section>\n</main>\n\
<script type=\"application/json\" id=\"meshclash-data\">{json}</script>\n<script>\n{SCRIPT}</script>\n</body>\n</html>\n",
        title = escape(&title),
        summary = escape(&summary),
    )
}

/// The triangles of a large part near its clashes (vertex inside a row box widened by its own
/// size and 2% of the part's), plus an even stride of the rest up to [`CLIP_CONTEXT`].
fn clip(mesh: &Mesh, all: &[u32], boxes: &[Aabb]) -> Vec<u32> {
    let part = part_box(mesh, all);
    let pad = (part.max - part.min).length() * 0.02;
    let grown: Vec<Aabb> = boxes
        .iter()
        .map(|b| {
            let r = (b.max - b.min).length().max(pad);
            Aabb { min: b.min - DVec3::splat(r), max: b.max + DVec3::splat(r) }
        })
        .collect();
    let inside = |p: DVec3| grown.iter().any(|b| p.cmpge(b.min).all() && p.cmple(b.max).all());
    let (mut keep, mut rest) = (Vec::new(), Vec::new());
    for &t in all {
        if mesh.triangles[t as usize].iter().any(|&v| inside(mesh.positions[v as usize])) {
            keep.push(t);
        } else {
            rest.push(t);
        }
    }
    if keep.len() > PART_FULL {
        let stride = keep.len().div_ceil(PART_FULL);
        keep = keep.into_iter().step_by(stride).collect();
    }
    let stride = rest.len().div_ceil(CLIP_CONTEXT).max(1);
    keep.extend(rest.into_iter().step_by(stride));
    keep.sort_unstable();
    keep
}

fn part_box(mesh: &Mesh, tris: &[u32]) -> Aabb {
    tris.iter().fold(Aabb::EMPTY, |b, &t| {
        mesh.triangles[t as usize].iter().fold(b, |b, &v| b.grow(mesh.positions[v as usize]))
    })
}

/// Text for HTML element content and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n × n quad grid on z = 0 (2n² triangles), one object.
    fn grid(n: u32) -> Mesh {
        let mut m = Mesh::default();
        for j in 0..=n {
            for i in 0..=n {
                m.positions.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        for j in 0..n {
            for i in 0..n {
                let v = j * (n + 1) + i;
                m.triangles.push([v, v + 1, v + n + 2]);
                m.triangles.push([v, v + n + 2, v + n + 1]);
            }
        }
        m.tri_object = vec![0; m.triangles.len()];
        m.objects = vec![Default::default()];
        m
    }

    #[test]
    fn clip_keeps_the_clash_neighbourhood_and_a_thin_sample() {
        let m = grid(300); // 180 000 triangles
        let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
        let b = Aabb { min: DVec3::new(10.0, 10.0, -1.0), max: DVec3::new(12.0, 12.0, 1.0) };
        let kept = clip(&m, &all, &[b]);
        assert!(kept.len() <= CLIP_CONTEXT + 2_000, "{}", kept.len());
        assert!(kept.windows(2).all(|w| w[0] < w[1]));
        // Every triangle with a vertex inside the clash box is kept.
        for &t in &all {
            let touches = m.triangles[t as usize].iter().any(|&v| {
                let p = m.positions[v as usize];
                p.cmpge(b.min).all() && p.cmple(b.max).all()
            });
            if touches {
                assert!(kept.binary_search(&t).is_ok(), "triangle {t} near the clash was dropped");
            }
        }
    }

    #[test]
    fn escape_covers_markup() {
        assert_eq!(escape("a<b>&\"'"), "a&lt;b&gt;&amp;&quot;&#39;");
    }
}
