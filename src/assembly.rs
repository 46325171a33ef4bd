//! Assemblies: which parts clash with which.
//!
//! A *part* is an object of a loaded file (OBJ `o`/`g`, STL `solid`, glTF mesh instance).
//! Part pairs are found by a broad phase over the parts' world boxes (a BVH over part boxes,
//! walked against itself or the other set with the same dual walk as triangles); only parts that
//! take part in some candidate pair get a triangle BVH, built lazily and in parallel, and each
//! candidate pair is checked exactly with [`crate::query::check_built`]. Parts whose boxes never
//! come within the search margin of another cost nothing beyond their box.
//!
//! Instances of one glTF mesh share the tree *topology* (one SAH build per distinct mesh); each
//! instance refits the boxes to its own world coordinates, so boxes stay exact (a transformed
//! box would need outward rounding and would cull less).

use crate::bvh::{BuildOptions, Bvh, Node};
use crate::containment::Containment;
use crate::geom::{Aabb, DVec3};
use crate::mesh::Mesh;
use crate::query::{check_built, ClashResult, PairFinding, Settings, Verdict};
use crate::traverse;
use rayon::prelude::*;
use std::collections::HashMap;
use std::time::Instant;

/// One part of one input.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Which input (0 = A, 1 = B).
    pub input: u8,
    /// Object index in that input.
    pub object: u32,
    /// Object name (glTF node path, OBJ group, STL solid).
    pub name: String,
    /// Its triangles, as indices into the input mesh, in file order.
    pub triangles: Vec<u32>,
    /// World box.
    pub bounds: Aabb,
    /// glTF mesh it instances, if any.
    pub gltf_mesh: Option<u32>,
}

/// Split a mesh into its parts (objects with at least one triangle), in object order.
pub fn parts_of(mesh: &Mesh, input: u8) -> Vec<Part> {
    let mut tris: Vec<Vec<u32>> = vec![Vec::new(); mesh.objects.len()];
    for (t, &o) in mesh.tri_object.iter().enumerate() {
        tris[o as usize].push(t as u32);
    }
    tris.into_iter()
        .enumerate()
        .filter(|(_, t)| !t.is_empty())
        .map(|(o, triangles)| {
            let bounds = triangles
                .iter()
                .fold(Aabb::EMPTY, |b, &t| b.union(Aabb::of_triangle(&crate::bvh::triangle(mesh, t))));
            Part {
                input,
                object: o as u32,
                name: mesh.objects[o].name.clone(),
                triangles,
                bounds,
                gltf_mesh: mesh.objects[o].gltf_mesh,
            }
        })
        .collect()
}

/// Match a part name against a glob: `*` any run of characters (including `/`), `?` one
/// character; everything else literal.
pub fn glob_match(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    let (mut i, mut j, mut star, mut mark) = (0usize, 0usize, None::<usize>, 0usize);
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// The sub-mesh of one part (its triangles, re-indexed), for building and checking.
fn sub_mesh(mesh: &Mesh, part: &Part) -> Mesh {
    let mut remap: HashMap<u32, u32> = HashMap::new();
    let mut positions = Vec::new();
    let triangles = part
        .triangles
        .iter()
        .map(|&t| {
            mesh.triangles[t as usize].map(|v| {
                *remap.entry(v).or_insert_with(|| {
                    positions.push(mesh.positions[v as usize]);
                    (positions.len() - 1) as u32
                })
            })
        })
        .collect::<Vec<_>>();
    let n = triangles.len();
    Mesh {
        positions,
        triangles,
        tri_object: vec![0; n],
        objects: vec![mesh.objects[part.object as usize].clone()],
    }
}

/// Refit a tree built for another instance of the same mesh to this instance's coordinates:
/// same topology and leaf order, exact boxes.
fn refit(template: &Bvh, mesh: &Mesh) -> Bvh {
    let mut nodes: Vec<Node> = template.nodes.clone();
    for i in (0..nodes.len()).rev() {
        let n = nodes[i];
        nodes[i].bounds = if n.is_leaf() {
            template
                .leaf_prims(&n)
                .iter()
                .fold(Aabb::EMPTY, |b, &t| b.union(Aabb::of_triangle(&crate::bvh::triangle(mesh, t))))
        } else {
            nodes[i + 1].bounds.union(nodes[n.a as usize].bounds)
        };
    }
    Bvh { nodes, prims: template.prims.clone() }
}

/// The result for one part pair.
#[derive(Debug, Clone, PartialEq)]
pub struct PartPair {
    /// Index into [`AssemblyResult::parts`] (the A side).
    pub a: usize,
    /// Index into [`AssemblyResult::parts`] (the B side).
    pub b: usize,
    /// The check of the two parts; triangle indices are those of the input meshes.
    pub result: ClashResult,
}

/// Everything an assembly check finds.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyResult {
    /// All parts of both inputs (selected or not), A's first.
    pub parts: Vec<Part>,
    /// Part pairs whose boxes came within the search margin, sorted by (a, b), with findings
    /// or not.
    pub part_pairs: Vec<PartPair>,
    /// Parts for which a triangle tree was needed (the others were skipped).
    pub built: Vec<bool>,
    /// Distinct SAH builds (instances of one glTF mesh share one build, refit per instance).
    pub sah_builds: usize,
    /// Time to build the part trees, ms.
    pub build_ms: f64,
    /// Time for the broad phase and all part-pair checks, ms.
    pub query_ms: f64,
}

/// Which part pairs to check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pairing {
    /// Every selected part of A against every selected part of B (two files, or two selections
    /// of one file).
    Cross,
    /// Every selected part against every other selected part of the same input (all-vs-all);
    /// each unordered pair once.
    AllVsAll,
}

/// Check parts `sel_a` against `sel_b` (indices into `parts`) of `meshes[input]`.
pub fn check_parts(
    meshes: [&Mesh; 2],
    parts: Vec<Part>,
    sel_a: &[usize],
    sel_b: &[usize],
    pairing: Pairing,
    settings: &Settings,
) -> AssemblyResult {
    let t0 = Instant::now();
    let tol = settings.tolerances;
    // Broad phase: a tree over the selected parts' boxes on each side, walked together.
    let boxes = |sel: &[usize]| sel.iter().map(|&i| parts[i].bounds).collect::<Vec<_>>();
    let opts = BuildOptions { leaf_size: 1, ..settings.bvh };
    let (ba, bb) = (Bvh::build_from_boxes(&boxes(sel_a), opts), Bvh::build_from_boxes(&boxes(sel_b), opts));
    let mut candidates: Vec<(usize, usize)> = traverse::collect_pairs(
        &ba,
        &bb,
        |x, y| tol.boxes_may_meet(x, y),
        |la, lb, out| {
            for &i in la {
                for &j in lb {
                    let (pa, pb) = (sel_a[i as usize], sel_b[j as usize]);
                    if !tol.boxes_may_meet(&parts[pa].bounds, &parts[pb].bounds) {
                        continue;
                    }
                    match pairing {
                        Pairing::Cross => out.push((pa, pb)),
                        Pairing::AllVsAll if pa < pb => out.push((pa, pb)),
                        Pairing::AllVsAll => {}
                    }
                }
            }
        },
    );
    candidates.sort_unstable();
    candidates.dedup();
    // Lazy trees: only parts in some candidate pair; one SAH build per distinct glTF mesh.
    let mut built = vec![false; parts.len()];
    for &(a, b) in &candidates {
        built[a] = true;
        built[b] = true;
    }
    let needed: Vec<usize> = (0..parts.len()).filter(|&i| built[i]).collect();
    let subs: Vec<Option<Mesh>> = (0..parts.len())
        .into_par_iter()
        .map(|i| built[i].then(|| sub_mesh(meshes[parts[i].input as usize], &parts[i])))
        .collect();
    // Group instances: the first needed part of each (input, glTF mesh) is built; others refit.
    let mut leader: HashMap<(u8, u32), usize> = HashMap::new();
    let mut template_of = vec![None; parts.len()];
    for &i in &needed {
        if let Some(m) = parts[i].gltf_mesh {
            let l = *leader.entry((parts[i].input, m)).or_insert(i);
            if l != i && parts[l].triangles.len() == parts[i].triangles.len() {
                template_of[i] = Some(l);
            }
        }
    }
    let leaders: Vec<usize> = needed.iter().copied().filter(|&i| template_of[i].is_none()).collect();
    let mut trees: Vec<Option<Bvh>> = vec![None; parts.len()];
    let built_leaders: Vec<(usize, Bvh)> = leaders
        .par_iter()
        .map(|&i| (i, Bvh::build(subs[i].as_ref().expect("needed part has a sub-mesh"), settings.bvh)))
        .collect();
    let sah_builds = built_leaders.len();
    for (i, t) in built_leaders {
        trees[i] = Some(t);
    }
    let refits: Vec<(usize, Bvh)> = needed
        .par_iter()
        .filter_map(|&i| {
            let l = template_of[i]?;
            Some((i, refit(trees[l].as_ref().expect("leader built"), subs[i].as_ref().expect("sub-mesh"))))
        })
        .collect();
    for (i, t) in refits {
        trees[i] = Some(t);
    }
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t1 = Instant::now();
    let part_pairs: Vec<PartPair> = candidates
        .par_iter()
        .map(|&(a, b)| {
            let (ma, mb) = (subs[a].as_ref().unwrap(), subs[b].as_ref().unwrap());
            let mut r = check_built(ma, trees[a].as_ref().unwrap(), mb, trees[b].as_ref().unwrap(), settings);
            r.timings = Default::default();
            to_input_indices(&mut r, &parts[a], &parts[b]);
            PartPair { a, b, result: r }
        })
        .collect();
    AssemblyResult {
        parts,
        part_pairs,
        built,
        sah_builds,
        build_ms,
        query_ms: t1.elapsed().as_secs_f64() * 1e3,
    }
}

/// Map triangle indices of the part sub-meshes back to the input meshes' indices (order is
/// preserved: a part's triangles are in file order, so sorted pairs stay sorted).
fn to_input_indices(r: &mut ClashResult, pa: &Part, pb: &Part) {
    let (ta, tb) = (&pa.triangles, &pb.triangles);
    for p in &mut r.pairs {
        *p = PairFinding { a: ta[p.a as usize], b: tb[p.b as usize], ..*p };
    }
    if let Some(c) = &mut r.closest {
        c.a.0 = ta[c.a.0 as usize];
        c.b.0 = tb[c.b.0 as usize];
    }
}

impl AssemblyResult {
    /// The worst verdict over all part pairs.
    pub fn verdict(&self) -> Verdict {
        self.part_pairs.iter().map(|p| p.result.verdict).max().unwrap_or(Verdict::Clear)
    }

    /// Part pairs with a finding (verdict other than clear, or containment).
    pub fn findings(&self) -> impl Iterator<Item = &PartPair> {
        self.part_pairs
            .iter()
            .filter(|p| p.result.verdict != Verdict::Clear || p.result.containment != Containment::None)
    }
}

/// The centre of a set of points (used for region markers).
pub fn centroid(points: &[DVec3]) -> DVec3 {
    if points.is_empty() {
        return DVec3::ZERO;
    }
    points.iter().fold(DVec3::ZERO, |s, p| s + *p) / points.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glob_matches_like_a_shell() {
        assert!(glob_match("Engine/*", "Engine/Piston_2"));
        assert!(glob_match("*Piston*", "Engine/Piston_2"));
        assert!(glob_match("Piston_?", "Piston_2"));
        assert!(!glob_match("Piston_?", "Piston_12"));
        assert!(glob_match("*", ""));
        assert!(!glob_match("a*b", "acbd"));
        assert!(glob_match("a*b*", "acbd"));
    }
}

/// What to check in an assembly run.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Selection {
    /// `meshclash scene FILE`: parts of one file against each other.
    pub scene: bool,
    /// Globs selecting the A side (empty = all parts of A; in scene mode, all parts).
    pub select_a: Vec<String>,
    /// Globs selecting the B side (empty = all parts of B; in scene mode: all-vs-all).
    pub select_b: Vec<String>,
    /// Globs removing parts from both sides.
    pub exclude: Vec<String>,
}

impl Selection {
    /// True when parts must be checked pair by pair (scene mode or a selection).
    pub fn by_parts(&self) -> bool {
        self.scene || !self.select_a.is_empty() || !self.select_b.is_empty() || !self.exclude.is_empty()
    }
}

/// One part pair in the report.
#[derive(Debug, Clone, PartialEq)]
pub struct PartPairSummary {
    /// Index into the parts list (A side).
    pub a: usize,
    /// Index into the parts list (B side).
    pub b: usize,
    /// The pair's verdict.
    pub verdict: Verdict,
    /// Counts by kind.
    pub counts: crate::query::Counts,
    /// Minimum distance, when known (checked pairs; or 0 for meeting pairs in file mode).
    pub min_distance: Option<f64>,
    /// Containment between the two parts.
    pub containment: Containment,
}

/// Facts about the assembly run.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyInfo {
    /// `files` (A against B, pairs grouped by part) or `parts` (part pairs checked one by one:
    /// scene mode or a selection).
    pub mode: &'static str,
    /// Selected parts on each side.
    pub selected: [usize; 2],
    /// Part pairs whose boxes came within the search margin.
    pub candidate_part_pairs: usize,
    /// Parts that needed a triangle tree (parts mode only).
    pub built_parts: Option<usize>,
    /// Distinct SAH builds (parts mode only; instances share one).
    pub sah_builds: Option<usize>,
}

/// The whole outcome: a merged [`ClashResult`] (pairs in input triangle indices) plus the
/// per-part view.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// All findings merged, as for a two-file check.
    pub result: ClashResult,
    /// All parts (A's, then B's; in scene mode only the file's).
    pub parts: Vec<Part>,
    /// Part pairs with their verdicts, sorted; clear pairs omitted.
    pub part_pairs: Vec<PartPairSummary>,
    /// Run facts.
    pub info: AssemblyInfo,
}

fn select(parts: &[Part], input: u8, globs: &[String], exclude: &[String]) -> Vec<usize> {
    (0..parts.len())
        .filter(|&i| parts[i].input == input)
        .filter(|&i| globs.is_empty() || globs.iter().any(|g| glob_match(g, &parts[i].name)))
        .filter(|&i| !exclude.iter().any(|g| glob_match(g, &parts[i].name)))
        .collect()
}

/// Check `a` against `b` (in scene mode, `a` against itself) part by part or as whole files.
/// Errors (a selection that matches nothing) are one line.
pub fn run(a: &Mesh, b: &Mesh, sel: &Selection, settings: &Settings) -> Result<Outcome, String> {
    let mut parts = parts_of(a, 0);
    if !sel.scene {
        parts.extend(parts_of(b, 1));
    }
    let b_input = if sel.scene { 0 } else { 1 };
    let sa = select(&parts, 0, &sel.select_a, &sel.exclude);
    let sb = select(&parts, b_input, &sel.select_b, &sel.exclude);
    for (s, globs, side) in [(&sa, &sel.select_a, "a"), (&sb, &sel.select_b, "b")] {
        if s.is_empty() {
            return Err(if globs.is_empty() {
                format!("no part left to check on side {side} after --exclude")
            } else {
                format!("--select-{side} {} matches no part", globs.join(","))
            });
        }
    }
    if !sel.by_parts() {
        let result = crate::query::check(a, b, settings);
        let part_pairs = group_by_part(&parts, a, b, &result);
        let info = AssemblyInfo {
            mode: "files",
            selected: [sa.len(), sb.len()],
            candidate_part_pairs: part_pairs.len(),
            built_parts: None,
            sah_builds: None,
        };
        return Ok(Outcome { result, parts, part_pairs, info });
    }
    let pairing = if sel.scene && sel.select_b.is_empty() { Pairing::AllVsAll } else { Pairing::Cross };
    let ar = check_parts([a, if sel.scene { a } else { b }], parts, &sa, &sb, pairing, settings);
    let mut pairs_seen = std::collections::HashSet::new();
    let mut merged: Vec<PairFinding> = Vec::new();
    let mut part_pairs = Vec::new();
    let mut closest: Option<crate::query::Closest> = None;
    let mut containment = Containment::None;
    let mut counts = crate::query::Counts::default();
    for pp in &ar.part_pairs {
        let (x, y) = (pp.a.min(pp.b), pp.a.max(pp.b));
        if x == y || !pairs_seen.insert((x, y)) {
            continue; // a part selected on both sides, or the mirror of a pair already done
        }
        let r = &pp.result;
        merged.extend(r.pairs.iter().copied());
        counts.merge(&r.counts);
        if let Some(c) = r.closest {
            if closest.is_none_or(|m| (c.distance, c.a.0, c.b.0) < (m.distance, m.a.0, m.b.0)) {
                closest = Some(c);
            }
        }
        if containment == Containment::None && r.containment.is_clash() {
            containment = r.containment.clone();
        }
        if r.verdict != Verdict::Clear || r.containment != Containment::None {
            part_pairs.push(PartPairSummary {
                a: pp.a,
                b: pp.b,
                verdict: r.verdict,
                counts: r.counts,
                min_distance: r.closest.map(|c| c.distance),
                containment: r.containment.clone(),
            });
        }
    }
    merged.sort_unstable_by_key(|p| (p.a, p.b));
    let verdict = part_pairs.iter().map(|p| p.verdict).max().unwrap_or(Verdict::Clear);
    let info = AssemblyInfo {
        mode: "parts",
        selected: [sa.len(), sb.len()],
        candidate_part_pairs: ar.part_pairs.len(),
        built_parts: Some(ar.built.iter().filter(|b| **b).count()),
        sah_builds: Some(ar.sah_builds),
    };
    let result = ClashResult {
        pairs: merged,
        counts,
        closest,
        verdict,
        containment,
        closed: [false, false],
        trees: [crate::bvh::Stats { nodes: 0, leaves: 0, depth: 0, sah_cost: 0.0, bytes: 0 }; 2],
        timings: crate::query::Timings { build_ms: ar.build_ms, query_ms: ar.query_ms },
    };
    Ok(Outcome { result, parts: ar.parts, part_pairs, info })
}

/// File mode: group the pairs of a whole-file check by the parts they belong to.
fn group_by_part(parts: &[Part], a: &Mesh, b: &Mesh, r: &ClashResult) -> Vec<PartPairSummary> {
    let index: HashMap<(u8, u32), usize> =
        parts.iter().enumerate().map(|(i, p)| ((p.input, p.object), i)).collect();
    let mut by: std::collections::BTreeMap<(usize, usize), PartPairSummary> = Default::default();
    for p in &r.pairs {
        let pa = index[&(0, a.tri_object[p.a as usize])];
        let pb = index[&(1, b.tri_object[p.b as usize])];
        let e = by.entry((pa, pb)).or_insert_with(|| PartPairSummary {
            a: pa,
            b: pb,
            verdict: Verdict::Clear,
            counts: Default::default(),
            min_distance: None,
            containment: Containment::None,
        });
        let v = e.counts.record(p);
        e.verdict = e.verdict.max(v);
        e.min_distance = Some(e.min_distance.map_or(p.distance, |d: f64| d.min(p.distance)));
    }
    by.into_values().collect()
}
