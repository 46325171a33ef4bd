//! The plan file: the work list of one check, and its partition into shards.

use super::sha256;
use crate::check::assembly::Part;
use crate::geom::Aabb;
use serde::{Deserialize, Serialize};

/// `schema` of a plan file.
pub const PLAN_SCHEMA: &str = "meshclash.plan/1";

/// One input file and its content hash.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanInput {
    /// The path as given to the check (relative paths resolve against the working directory
    /// of `run` and `merge`, as they did for `plan`).
    pub path: String,
    /// SHA-256 of its bytes.
    pub sha256: String,
    /// Its size in bytes.
    pub bytes: u64,
}

/// One unit of work: a candidate part pair (parts mode), or the whole two-file check (files
/// mode, one unit: the check is one dual tree walk over both files).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanPair {
    /// Stable id: SHA-256 of the two part paths, 16 hex digits (`-2`, `-3`, … appended when
    /// parts share a name).
    pub id: String,
    /// Part index (A side), or null for the files unit.
    pub a: Option<usize>,
    /// Part index (B side), or null for the files unit.
    pub b: Option<usize>,
    /// Part names (`a`/`b` input prefix and the part path).
    pub names: [String; 2],
    /// Cost estimate: triangles of both parts inside the overlap of their boxes (widened by
    /// the search margin), assuming triangles spread evenly over each box.
    pub cost: u64,
}

/// The whole plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// [`PLAN_SCHEMA`].
    pub schema: String,
    /// meshclash version that wrote it (run and merge refuse another).
    pub tool_version: String,
    /// The check arguments, exactly as they would follow `meshclash` (without `-o`).
    pub args: Vec<String>,
    /// The inputs read (scene mode: the one file).
    pub inputs: Vec<PlanInput>,
    /// `parts` or `files` (as the report's `assembly.mode`).
    pub mode: String,
    /// Parts of the inputs.
    pub parts: usize,
    /// Candidate part pairs as the check counts them (including a part against itself and
    /// mirrored pairs when selections overlap, which are not work).
    pub candidate_part_pairs: usize,
    /// Parts in some candidate pair (they get a triangle tree).
    pub built_parts: usize,
    /// Parts in a candidate pair that is not work (a part against itself): their tree size
    /// still counts in the report's memory figure.
    pub extra_needed: Vec<usize>,
    /// Number of work units (`pairs`; kept when a shard report carries the plan without them).
    pub work_pairs: usize,
    /// Sum of the costs.
    pub total_cost: u64,
    /// The work, sorted by (a, b).
    pub pairs: Vec<PlanPair>,
}

/// The name of part `p` as the plan records it (`a:` or `b:` and its path).
pub fn part_name(p: &Part) -> String {
    format!("{}:{}", if p.input == 0 { "a" } else { "b" }, p.name)
}

/// Give every pair its id: the hash of the two names, disambiguated in order when names repeat.
pub fn assign_ids(pairs: &mut [PlanPair]) {
    let mut seen: std::collections::HashMap<String, usize> = Default::default();
    for p in pairs {
        let base = sha256::hex(format!("{}\n{}", p.names[0], p.names[1]).as_bytes())[..16].to_string();
        let n = seen.entry(base.clone()).or_insert(0);
        *n += 1;
        p.id = if *n == 1 { base } else { format!("{base}-{n}") };
    }
}

fn volume(b: &Aabb) -> f64 {
    let e = b.extent();
    e.x.max(0.0) * e.y.max(0.0) * e.z.max(0.0)
}

/// The cost estimate of a part pair (see [`PlanPair::cost`]): each part's triangles times the
/// share of its box inside the other's (widened by `margin`), at least 1.
pub fn pair_cost(a: &Part, b: &Part, margin: f64) -> u64 {
    let grow = |x: &Aabb| Aabb { min: x.min - margin, max: x.max + margin };
    let share = |own: &Aabb, other: &Aabb| {
        let o = grow(other);
        let cut = Aabb { min: own.min.max(o.min), max: own.max.min(o.max) };
        let (v, c) = (volume(own), volume(&cut));
        // Flat or empty boxes: count the whole part.
        if v > 0.0 && c.is_finite() {
            (c / v).clamp(0.0, 1.0)
        } else {
            1.0
        }
    };
    let t = a.triangles.len() as f64 * share(&a.bounds, &b.bounds)
        + b.triangles.len() as f64 * share(&b.bounds, &a.bounds);
    (t.ceil() as u64).max(1)
}

/// Which shard (0-based) each pair goes to, for `n` shards: longest processing time first
/// (pairs by decreasing cost, ties by position), each to the least loaded shard (ties: the
/// lowest index), so the shards finish together. Deterministic: every shard computes the same.
pub fn partition(pairs: &[PlanPair], n: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..pairs.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(pairs[i].cost), i));
    // More shards than pairs: each pair gets an empty shard, the lowest first, so only the
    // first `pairs.len()` shards can hold any (the rest are empty; no memory per shard).
    let bins = n.min(pairs.len()).max(1);
    let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<(u64, usize)>> =
        (0..bins).map(|s| std::cmp::Reverse((0u64, s))).collect();
    let mut of = vec![0usize; pairs.len()];
    for i in order {
        let std::cmp::Reverse((load, s)) = heap.pop().expect("n > 0");
        of[i] = s;
        heap.push(std::cmp::Reverse((load.saturating_add(pairs[i].cost), s)));
    }
    of
}

impl Plan {
    /// Parse a plan file; errors are one line.
    pub fn parse(bytes: &[u8]) -> Result<Plan, String> {
        let v: serde_json::Value = serde_json::from_slice(bytes).map_err(|e| format!("not JSON: {e}"))?;
        match v.get("schema").and_then(|s| s.as_str()) {
            Some(PLAN_SCHEMA) => {}
            Some(s) => return Err(format!("schema is '{s}', not {PLAN_SCHEMA} (not a meshclash plan)")),
            None => return Err(format!("no schema field (not a {PLAN_SCHEMA} file)")),
        }
        let p: Plan = serde_json::from_value(v).map_err(|e| format!("bad plan: {e}"))?;
        // Indices are data from a file: every one must name a part of the plan.
        let bad = |i: usize| i >= p.parts;
        if let Some(i) = p
            .pairs
            .iter()
            .flat_map(|q| q.a.into_iter().chain(q.b))
            .chain(p.extra_needed.iter().copied())
            .find(|&i| bad(i))
        {
            return Err(format!("part index {i} out of range (the plan has {} parts)", p.parts));
        }
        if p.tool_version != env!("CARGO_PKG_VERSION") {
            return Err(format!(
                "written by meshclash {}, this is {}: plan again with this version",
                p.tool_version,
                env!("CARGO_PKG_VERSION")
            ));
        }
        Ok(p)
    }

    /// The plan without its pair list (what every shard report carries).
    pub fn head(&self) -> Plan {
        Plan { pairs: Vec::new(), ..self.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pp(cost: u64) -> PlanPair {
        PlanPair { id: String::new(), a: Some(0), b: Some(1), names: ["a".into(), "b".into()], cost }
    }

    #[test]
    fn more_shards_than_pairs_cost_nothing_and_match_the_one_pair_per_shard_split() {
        let pairs: Vec<PlanPair> = [5, 9, 1].into_iter().map(pp).collect();
        let few = partition(&pairs, 3);
        assert_eq!(partition(&pairs, usize::MAX), few);
        assert_eq!(partition(&pairs, 10_000_000_000), few);
        assert!(partition(&[], usize::MAX).is_empty());
    }

    #[test]
    fn partition_is_greedy_longest_first_and_balanced() {
        let pairs: Vec<PlanPair> = [7, 5, 4, 3, 3, 2].into_iter().map(pp).collect();
        let of = partition(&pairs, 2);
        // 7 -> s0; 5 -> s1; 4 -> s1 (9); 3 -> s0 (10); 3 -> s1 (12); 2 -> s0 (12).
        assert_eq!(of, vec![0, 1, 1, 0, 1, 0]);
        let load = |s| pairs.iter().zip(&of).filter(|(_, &x)| x == s).map(|(p, _)| p.cost).sum::<u64>();
        assert_eq!((load(0), load(1)), (12, 12));
        // More shards than pairs: some are empty, none gets two.
        let of = partition(&pairs[..3], 7);
        assert_eq!(of, vec![0, 1, 2]);
        // One shard takes everything.
        assert!(partition(&pairs, 1).iter().all(|&s| s == 0));
    }

    #[test]
    fn ids_are_stable_and_unique() {
        let mut pairs = vec![pp(1), pp(1), pp(1)];
        pairs[2].names = ["a".into(), "c".into()];
        assign_ids(&mut pairs);
        assert_eq!(pairs[0].id.len(), 16);
        assert_eq!(pairs[1].id, format!("{}-2", pairs[0].id));
        assert_ne!(pairs[2].id[..16], pairs[0].id[..16]);
        assert_eq!(pairs[0].id, sha256::hex(b"a\nb")[..16]);
    }

    #[test]
    fn cost_counts_triangles_in_the_overlap() {
        use crate::geom::DVec3;
        let part = |min: [f64; 3], max: [f64; 3], n: u32| Part {
            input: 0,
            object: 0,
            name: String::new(),
            triangles: (0..n).collect(),
            bounds: Aabb { min: DVec3::from_array(min), max: DVec3::from_array(max) },
            gltf_mesh: None,
        };
        // Half of A's box and a quarter of B's overlap.
        let a = part([0.0; 3], [2.0, 1.0, 1.0], 100);
        let b = part([1.0, 0.0, 0.0], [5.0, 1.0, 1.0], 40);
        assert_eq!(pair_cost(&a, &b, 0.0), 50 + 10);
        // A flat part counts whole.
        let f = part([1.0, 0.0, 0.0], [1.0, 1.0, 1.0], 8);
        assert_eq!(pair_cost(&a, &f, 0.0), 8);
    }
}
