//! The report of a run: a pure projection of the pipeline's [`Outcome`] into the wire format
//! of [`crate::report`]. It computes nothing that decides: the verdict, the fail decision, the
//! regions, the finding ids and the baseline comparison are the outcome's. Nothing writes to a
//! [`Report`] after [`build`] returns it.

use super::{LoadedInput, Outcome};
use crate::check::query::{MeshInfo, PairFinding, TreeStats};
use crate::geom::{Aabb, DVec3};
use crate::report::*;
use glam::DMat4;

fn input_report(l: &LoadedInput, info: &MeshInfo, closed: Option<bool>) -> InputReport {
    let Aabb { min, max } = info.bounds;
    let input = &l.input;
    InputReport {
        path: input.path.display().to_string(),
        format: if l.array { ARRAY_FORMAT.to_string() } else { input.format.name().to_string() },
        vertices: info.vertices,
        triangles: info.triangles,
        degenerate_triangles: info.degenerate_triangles,
        closed,
        objects: info.objects.iter().map(|(n, t)| ObjectReport { name: n.clone(), triangles: *t }).collect(),
        bounds: Bounds { min: v3(min), max: v3(max) },
        transform: (l.transform != DMat4::IDENTITY).then(|| l.transform.transpose().to_cols_array().to_vec()),
        units: l.units.clone(),
    }
}

fn tree_report(s: &TreeStats) -> TreeReport {
    TreeReport {
        nodes: s.nodes,
        leaves: s.leaves,
        depth: s.depth,
        sah_cost: s.sah_cost,
        bytes: s.bytes,
        cells: s.cells,
    }
}

fn pair_report(p: &PairFinding, oa: impl Fn(u32) -> u32, ob: impl Fn(u32) -> u32) -> PairReport {
    PairReport {
        a: p.a,
        b: p.b,
        a_object: oa(p.a),
        b_object: ob(p.b),
        kind: p.kind.into(),
        contact: match (p.contact, p.kind) {
            (Some(c), _) => Some(c.into()),
            (None, crate::check::query::PairKind::Touching) => Some(ReportContact::WithinTolerance),
            (None, _) => None,
        },
        distance: p.distance,
        segment: p.segment.map(|[s, t]| [v3(s), v3(t)]),
        id: None,
        status: None,
    }
}

/// The report of a run: a projection of the pipeline's [`Outcome`], computing nothing that
/// decides (the verdict, the fail decision, regions, ids and the baseline comparison are the
/// outcome's).
pub fn build(o: &Outcome) -> Report {
    let [ia, ib] = [&o.inputs[0], &o.inputs[1]];
    let r = &o.assembly.result;
    // A scene's two sides are one input: summarise it once.
    let (infa, infb): (MeshInfo, MeshInfo) = if std::sync::Arc::ptr_eq(ia, ib) {
        let info = ia.info().into_owned();
        (info.clone(), info)
    } else {
        rayon::join(|| ia.info().into_owned(), || ib.info().into_owned())
    };
    // The object of a triangle of A, of B.
    let (ta, tb) = (ia.world_triangles(), ib.world_triangles());
    let (oa, ob) = (|t| ta.object_of(t), |t| tb.object_of(t));
    let (assembly, parts, mut part_pairs) = assembly_view(&o.assembly, o.settings.max_pairs);
    for (pp, ov) in part_pairs.iter_mut().zip(&o.overlaps) {
        pp.overlap = ov.as_ref().map(OverlapReport::of);
    }
    let region_overlap = region_overlaps(o);
    let pairs = o
        .listed
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            let mut p = pair_report(&r.pairs[i], oa, ob);
            p.id = o.listed_ids.get(k).cloned();
            p.status =
                o.comparison.as_ref().map(|c| if c.persistent[k] { "persistent" } else { "new" }.to_string());
            p
        })
        .collect();
    Report {
        complete: (!o.missing_shards.is_empty()).then_some(false),
        missing_shards: o.missing_shards.clone(),
        schema: SCHEMA.to_string(),
        tool: Tool::this(),
        inputs: Inputs { a: input_report(ia, &infa, r.closed[0]), b: input_report(ib, &infb, r.closed[1]) },
        settings: o.settings.clone(),
        verdict: r.verdict.into(),
        failed: o.failed,
        summary: Summary {
            crossing_pairs: r.counts.crossing,
            touching_pairs: r.counts.touching,
            within_tolerance_pairs: r.counts.within_tolerance,
            clearance_pairs: r.counts.clearance,
            min_distance: r.closest.map(|c| c.distance),
            contained: ReportContainment::of(&r.containment),
            contained_reason: match &r.containment {
                crate::check::containment::Containment::Undecided(why) => Some(why.clone()),
                _ => None,
            },
            overlap: o.files_overlap.as_ref().map(OverlapReport::of),
        },
        closest: r.closest.map(|c| ClosestReport {
            distance: c.distance,
            a: Witness { triangle: c.a.0, object: oa(c.a.0), point: v3(c.a.1) },
            b: Witness { triangle: c.b.0, object: ob(c.b.0), point: v3(c.b.1) },
        }),
        pairs,
        pairs_truncated: o.listed.len() < r.pairs.len() || (r.pairs.is_empty() && r.counts.total() > 0),
        unlisted: o.unlisted.clone(),
        bvh: Trees { a: tree_report(&r.trees[0]), b: tree_report(&r.trees[1]) },
        cross_check: o.cross_check.clone(),
        assembly,
        parts,
        part_pairs,
        regions: o
            .regions
            .iter()
            .zip(region_overlap)
            .enumerate()
            .map(|(i, (g, overlap))| RegionReport {
                a_name: ia.world_triangles().object_name(g.objects.0).to_string(),
                b_name: ib.world_triangles().object_name(g.objects.1).to_string(),
                id: g.id.clone(),
                a_object: g.objects.0,
                b_object: g.objects.1,
                pairs: g.pairs,
                crossing_pairs: g.crossing,
                center: v3(g.center),
                bounds: Bounds { min: v3(g.bounds.min), max: v3(g.bounds.max) },
                extent: g.extent,
                penetration: g.penetration.map(|p| match o.convex_penetrations.get(i).copied().flatten() {
                    Some(c) => exact_convex(&c),
                    None => PenetrationReport {
                        depth: p.depth,
                        point: v3(p.point),
                        side: if p.side == 0 { "a_in_b" } else { "b_in_a" }.to_string(),
                        samples: p.samples,
                        method: None,
                        direction: None,
                    },
                }),
                overlap,
            })
            .collect(),
        warnings: o.warnings(),
        timings_ms: o.times.map(|(load, total)| TimingsReport {
            load,
            build: r.timings.build_ms,
            query: r.timings.query_ms,
            total,
        }),
        baseline: o.comparison.as_ref().map(|c| c.block.clone()),
        self_check: o.self_check.clone(),
        cache: o.cache.clone(),
    }
}

/// The penetration block of an exact convex depth ([`crate::narrow::convex::penetration`]).
fn exact_convex(p: &crate::narrow::convex::Penetration) -> PenetrationReport {
    use crate::narrow::convex::Axis;
    PenetrationReport {
        depth: p.depth,
        point: v3(p.point),
        side: if matches!(p.axis, Axis::FaceA(_)) { "b_in_a" } else { "a_in_b" }.to_string(),
        samples: 0,
        method: Some(PenetrationReport::EXACT_CONVEX.to_string()),
        // A direction along an axis reads as such: no negative zeros.
        direction: Some(v3(p.normal + DVec3::ZERO)),
    }
}

/// Per region, its part pair's overlap box when the region is that pair's only one.
fn region_overlaps(o: &Outcome) -> Vec<Option<OverlapReport>> {
    use std::collections::HashMap;
    let asm = &o.assembly;
    let scene = std::sync::Arc::ptr_eq(&o.inputs[0], &o.inputs[1]);
    // (object of A, object of B) -> part pair index; in scene mode both orders.
    let mut by_objects: HashMap<(u32, u32), usize> = HashMap::new();
    for (i, pp) in asm.part_pairs.iter().enumerate() {
        if o.overlaps.get(i).is_none_or(Option::is_none) {
            continue;
        }
        let (x, y) = (asm.parts[pp.a].object, asm.parts[pp.b].object);
        by_objects.insert((x, y), i);
        if scene {
            by_objects.insert((y, x), i);
        }
    }
    let mut regions_of: HashMap<usize, usize> = HashMap::new();
    let pair_of: Vec<Option<usize>> = o.regions.iter().map(|g| by_objects.get(&g.objects).copied()).collect();
    for i in pair_of.iter().flatten() {
        *regions_of.entry(*i).or_default() += 1;
    }
    pair_of
        .iter()
        .map(|p| {
            let i = (*p)?;
            (regions_of[&i] == 1).then(|| o.overlaps[i].as_ref().map(OverlapReport::of)).flatten()
        })
        .collect()
}

impl From<crate::narrow::tri_tri::Contact> for ReportContact {
    fn from(c: crate::narrow::tri_tri::Contact) -> Self {
        use crate::narrow::tri_tri::Contact;
        match c {
            Contact::Point => ReportContact::Point,
            Contact::Segment => ReportContact::Segment,
            Contact::CoplanarArea => ReportContact::CoplanarArea,
            Contact::CoplanarBoundary => ReportContact::CoplanarBoundary,
        }
    }
}
