//! Past one machine: `plan`, `run --shard I/N`, `merge`.
//!
//! A *plan* is the work list of one check: its arguments, its inputs with their SHA-256, and
//! every candidate part pair the part-level broad phase leaves (no triangle tree is built to
//! plan), each with a stable id and a cost estimate ([`plan`]). A *shard* runs the ordinary
//! check restricted to its pairs (a greedy longest-first partition of the plan by cost, the same
//! in every shard) and writes the per-pair outcome, bit for bit ([`wire`]). The *merge* reduces
//! the shards' outcomes to the outcome the single-machine check computes and hands it to the
//! ordinary report path in place of the check, so the report, its regions, baseline status,
//! JUnit file and exit code are the single-machine ones, byte for byte.
//!
//! Both ends hook into [`crate::check::assembly::run`] through
//! [`crate::check::assembly::PartsHook`]: [`PlanHook`] records the candidates and drops them
//! all, [`ShardHook`] keeps its own, [`MergeHook`] stands in the merged outcome.

pub mod plan;
pub mod sha256;
pub mod stats;
pub mod wire;

use crate::check::assembly::{AssemblyInfo, Outcome, Part, PartsHook};
use crate::check::containment::Containment;
use crate::check::query::{ClashResult, Counts, Timings, Verdict};
use crate::scene::mesh::Mesh;
use plan::{Plan, PlanPair};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeSet, HashMap, HashSet};
use std::sync::Mutex;
use wire::WireOutcome;

/// The most shards one plan may be split into (a count is data from a command line, an
/// engine's variable or a shard report: nothing is allocated per shard beyond this).
pub const MAX_SHARDS: usize = 1_000_000;

/// `schema` of a shard report.
pub const SHARD_SCHEMA: &str = "meshclash.shard/1";

/// A work unit a shard covered.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Covered {
    /// The pair's id in the plan.
    pub id: String,
    /// Part index (A side), null for the files unit.
    pub a: Option<usize>,
    /// Part index (B side), null for the files unit.
    pub b: Option<usize>,
}

/// What `meshclash run` writes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardReport {
    /// [`SHARD_SCHEMA`].
    pub schema: String,
    /// SHA-256 of the plan file's bytes.
    pub plan_hash: String,
    /// This shard, 1-based.
    pub shard: usize,
    /// Number of shards.
    pub shards: usize,
    /// The plan without its pair list.
    pub plan: Plan,
    /// The pairs of this shard, in plan order.
    pub pairs: Vec<Covered>,
    /// Set when the shard failed: the error (the merge refuses the set).
    pub error: Option<String>,
    /// The check's outcome over this shard's pairs.
    pub outcome: Option<WireOutcome>,
    /// Tree sizes of the own-tree parts this shard owns (for the report's memory figures).
    pub trees: Vec<(usize, u64)>,
}

/// An outcome with nothing in it.
pub fn empty_outcome(parts: &[Part], selected: [usize; 2], mode: &'static str) -> Outcome {
    let zero = crate::bvh::Stats::default();
    Outcome {
        result: ClashResult {
            pairs: Vec::new(),
            counts: Counts::default(),
            closest: None,
            verdict: Verdict::Clear,
            containment: Containment::None,
            closed: [None, None],
            trees: [zero; 2],
            timings: Timings::default(),
        },
        parts: parts.to_vec(),
        part_pairs: Vec::new(),
        info: AssemblyInfo {
            mode,
            selected,
            candidate_part_pairs: 0,
            built_parts: None,
            sah_builds: None,
            sharing: None,
        },
    }
}

/// Planning: records the parts and every candidate pair, checks none (no tree is built). In
/// files mode it stands in an empty outcome, so nothing is checked either.
#[derive(Debug, Default)]
pub struct PlanHook {
    /// Files mode (`--select`-less two-file check).
    pub files: bool,
    /// The parts, as the check made them.
    pub parts: Mutex<Vec<Part>>,
    /// Every candidate, sorted.
    pub candidates: Mutex<Vec<(usize, usize)>>,
}

impl PartsHook for PlanHook {
    fn keep(&self, a: usize, b: usize) -> bool {
        self.candidates.lock().expect("not poisoned").push((a, b));
        false
    }
    fn stand_in(
        &self,
        _: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Result<Outcome, String>> {
        *self.parts.lock().expect("not poisoned") = parts.to_vec();
        self.files.then(|| Ok(empty_outcome(parts, selected, "files")))
    }
    fn seen(&self, _: [&Mesh; 2], _: &Outcome) {}
}

impl PlanHook {
    /// The plan of what was recorded. `margin` widens boxes for the cost estimate.
    pub fn plan(&self, args: Vec<String>, inputs: Vec<plan::PlanInput>, margin: f64) -> Plan {
        let parts = self.parts.lock().expect("not poisoned");
        let candidates = self.candidates.lock().expect("not poisoned");
        let mut needed = BTreeSet::new();
        let mut done = HashSet::new();
        let mut pairs = Vec::new();
        if self.files {
            let total = parts.iter().map(|p| p.triangles.len() as u64).sum::<u64>().max(1);
            pairs.push(PlanPair {
                id: String::new(),
                a: None,
                b: None,
                names: ["a".into(), "b".into()],
                cost: total,
            });
        }
        for &(a, b) in candidates.iter() {
            needed.insert(a);
            needed.insert(b);
            // As the check's reduction: a part against itself, or the mirror of a pair already
            // listed, is not work.
            if a == b || !done.insert((a.min(b), a.max(b))) {
                continue;
            }
            pairs.push(PlanPair {
                id: String::new(),
                a: Some(a),
                b: Some(b),
                names: [plan::part_name(&parts[a]), plan::part_name(&parts[b])],
                cost: plan::pair_cost(&parts[a], &parts[b], margin),
            });
        }
        plan::assign_ids(&mut pairs);
        let in_work: HashSet<usize> = pairs.iter().flat_map(|p| p.a.into_iter().chain(p.b)).collect();
        Plan {
            schema: plan::PLAN_SCHEMA.into(),
            tool_version: env!("CARGO_PKG_VERSION").into(),
            args,
            inputs,
            mode: if self.files { "files" } else { "parts" }.into(),
            parts: parts.len(),
            candidate_part_pairs: candidates.len(),
            built_parts: needed.len(),
            extra_needed: needed.iter().copied().filter(|p| !in_work.contains(p)).collect(),
            work_pairs: pairs.len(),
            total_cost: pairs.iter().map(|p| p.cost).sum(),
            pairs,
        }
    }
}

/// Which shard (0-based) owns the tree size of each needed part: the shard of the first pair
/// (in plan order) it is in; parts only in pairs that are not work go to shard 0.
pub fn tree_owners(plan: &Plan, shard_of: &[usize]) -> HashMap<usize, usize> {
    let mut owner = HashMap::new();
    for (p, &s) in plan.pairs.iter().zip(shard_of) {
        for part in p.a.into_iter().chain(p.b) {
            owner.entry(part).or_insert(s);
        }
    }
    for &p in &plan.extra_needed {
        owner.entry(p).or_insert(0);
    }
    owner
}

/// Every needed part of a plan, ascending.
pub fn needed_parts(
    plan_pairs: impl Iterator<Item = (Option<usize>, Option<usize>)>,
    extra: &[usize],
) -> Vec<usize> {
    let mut s: BTreeSet<usize> = extra.iter().copied().collect();
    for (a, b) in plan_pairs {
        s.extend(a);
        s.extend(b);
    }
    s.into_iter().collect()
}

/// What a shard's check leaves: its outcome and the sizes of the trees it owns (part, bytes).
pub type Captured = (WireOutcome, Vec<(usize, u64)>);

/// A shard: checks its pairs only, captures the outcome and measures the trees it owns.
#[derive(Debug)]
pub struct ShardHook {
    /// Files mode.
    pub files: bool,
    /// The files unit is this shard's (files mode).
    pub has_files_unit: bool,
    /// Its part pairs (parts mode).
    pub pairs: HashSet<(usize, usize)>,
    /// Every needed part of the plan, ascending.
    pub needed: Vec<usize>,
    /// The needed parts whose tree size this shard reports (if they own a tree).
    pub owned: BTreeSet<usize>,
    /// Tree options of the check.
    pub bvh: crate::bvh::BuildOptions,
    /// The plan's part count (the inputs must have as many).
    pub parts: usize,
    /// The outcome and the tree sizes, once seen.
    pub captured: Mutex<Option<Captured>>,
}

impl PartsHook for ShardHook {
    fn keep(&self, a: usize, b: usize) -> bool {
        self.pairs.contains(&(a, b))
    }
    fn stand_in(
        &self,
        _: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Result<Outcome, String>> {
        if parts.len() != self.parts {
            return Some(Err(format!(
                "the inputs have {} parts, the plan {}: plan again",
                parts.len(),
                self.parts
            )));
        }
        (self.files && !self.has_files_unit).then(|| Ok(empty_outcome(parts, selected, "files")))
    }
    fn seen(&self, meshes: [&Mesh; 2], o: &Outcome) {
        let trees = if self.files {
            Vec::new()
        } else {
            let g = stats::group(meshes, &o.parts, &self.needed);
            let mine: Vec<usize> = g.own.iter().copied().filter(|p| self.owned.contains(p)).collect();
            stats::owned_tree_bytes(meshes, &o.parts, &mine, self.bvh)
        };
        *self.captured.lock().expect("not poisoned") = Some((WireOutcome::of(o), trees));
    }
}

/// The merge: stands in the reduction of the shards' outcomes for the check.
#[derive(Debug)]
pub struct MergeHook {
    /// The plan head.
    pub plan: Plan,
    /// The shard reports, validated (complete, or `--allow-partial`).
    pub shards: Vec<ShardReport>,
    /// `--allow-partial` with shards missing.
    pub partial: bool,
}

impl PartsHook for MergeHook {
    fn keep(&self, _: usize, _: usize) -> bool {
        false
    }
    fn stand_in(
        &self,
        meshes: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Result<Outcome, String>> {
        Some(self.merge(meshes, parts, selected))
    }
    fn seen(&self, _: [&Mesh; 2], _: &Outcome) {}
}

/// Every triangle index of a shard's outcome names a triangle of its mesh (a shard report is data
/// from a file).
pub(crate) fn in_range(o: &Outcome, meshes: [&Mesh; 2]) -> Result<(), String> {
    let n = [meshes[0].triangles.len(), meshes[1].triangles.len()];
    let check = |side: usize, t: u32| {
        if (t as usize) < n[side] {
            Ok(())
        } else {
            Err(format!("triangle index {t} out of range ({} triangles)", n[side]))
        }
    };
    let r = &o.result;
    for p in &r.pairs {
        check(0, p.a)?;
        check(1, p.b)?;
    }
    let closest = r.closest.iter().chain(o.part_pairs.iter().filter_map(|p| p.closest.as_ref()));
    for c in closest {
        check(0, c.a.0)?;
        check(1, c.b.0)?;
    }
    for pp in &o.part_pairs {
        for &(a, b) in &pp.pairs {
            check(0, a)?;
            check(1, b)?;
        }
    }
    Ok(())
}

impl MergeHook {
    fn merge(&self, meshes: [&Mesh; 2], parts: &[Part], selected: [usize; 2]) -> Result<Outcome, String> {
        if parts.len() != self.plan.parts {
            return Err(format!("the inputs have {} parts, the plan {}", parts.len(), self.plan.parts));
        }
        let mut outcomes = Vec::new();
        for s in &self.shards {
            // A shard without work (files mode) carries an empty stand-in: leave it out.
            if let (Some(o), false) = (&s.outcome, s.pairs.is_empty()) {
                let o = o
                    .outcome(parts.len())
                    .and_then(|o| in_range(&o, meshes).map(|()| o))
                    .map_err(|e| format!("shard {}/{}: {e}", s.shard, s.shards))?;
                outcomes.push(o);
            }
        }
        if self.plan.mode == "files" {
            // One unit: the shard that had it holds the whole outcome.
            return Ok(match outcomes.pop() {
                Some(o) => Outcome { parts: parts.to_vec(), ..o },
                None => empty_outcome(parts, selected, "files"),
            });
        }
        self.reduce(meshes, parts, selected, outcomes)
    }

    /// Parts mode: the reduction [`crate::check::assembly::run`] does over its part pairs, over
    /// the shards' (each already reduced over its own pairs; the reduction is associative).
    fn reduce(
        &self,
        meshes: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
        outcomes: Vec<Outcome>,
    ) -> Result<Outcome, String> {
        let mut out = empty_outcome(parts, selected, "parts");
        let r = &mut out.result;
        for o in outcomes {
            r.pairs.extend(o.result.pairs);
            r.counts.merge(&o.result.counts);
            if let Some(c) = o.result.closest {
                if r.closest.is_none_or(|m| (c.distance, c.a.0, c.b.0) < (m.distance, m.a.0, m.b.0)) {
                    r.closest = Some(c);
                }
            }
            r.timings.build_ms = r.timings.build_ms.max(o.result.timings.build_ms);
            r.timings.query_ms = r.timings.query_ms.max(o.result.timings.query_ms);
            out.part_pairs.extend(o.part_pairs);
        }
        r.pairs.sort_unstable_by_key(|p| (p.a, p.b));
        out.part_pairs.sort_by_key(|p| (p.a, p.b));
        if let Some(p) = out.part_pairs.iter().find(|p| p.containment.is_clash()) {
            r.containment = p.containment.clone();
        }
        r.verdict = out.part_pairs.iter().map(|p| p.verdict).max().unwrap_or(Verdict::Clear);
        let needed = needed_parts(
            self.shards.iter().flat_map(|s| s.pairs.iter().map(|c| (c.a, c.b))),
            &self.plan.extra_needed,
        );
        let trees: HashMap<usize, u64> = self.shards.iter().flat_map(|s| s.trees.iter().copied()).collect();
        let (sah_builds, sharing) = match stats::sharing(meshes, parts, &needed, &trees) {
            Ok((n, s)) => (Some(n), Some(s)),
            // A partial merge may lack the shard that measured a tree.
            Err(_) if self.partial => (None, None),
            Err(p) => return Err(format!("no shard reported the tree size of part {p} ({})", parts[p].name)),
        };
        out.info = AssemblyInfo {
            mode: "parts",
            selected,
            candidate_part_pairs: self.plan.candidate_part_pairs,
            built_parts: Some(self.plan.built_parts),
            sah_builds,
            sharing,
        };
        Ok(out)
    }
}

#[cfg(test)]
mod tests;
