//! The check's outcome on the wire: what a shard hands to the merge. Every f64 travels as its
//! IEEE bits (`u64`), so the merge sees exactly the numbers the shard computed (a decimal
//! round trip may be off by an ulp), and enums travel by their report names.

use crate::check::assembly::{AssemblyInfo, Outcome, PartPairSummary, Sharing};
use crate::check::containment::Containment;
use crate::check::query::{ClashResult, Closest, Counts, PairFinding, PairKind, Timings, Verdict};
use crate::geom::DVec3;
use crate::narrow::tri_tri::Contact;
use serde::{Deserialize, Serialize};

type V3 = [u64; 3];

fn v3(p: DVec3) -> V3 {
    p.to_array().map(f64::to_bits)
}
fn p3(v: V3) -> DVec3 {
    DVec3::from_array(v.map(f64::from_bits))
}

/// A triangle pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WirePair {
    a: u32,
    b: u32,
    kind: String,
    contact: Option<String>,
    distance: u64,
    segment: Option<[V3; 2]>,
}

impl WirePair {
    /// The wire form of a finding (its distance and points bit for bit).
    fn of(p: &PairFinding) -> WirePair {
        WirePair {
            a: p.a,
            b: p.b,
            kind: p.kind.name().into(),
            contact: p.contact.map(|c| c.name().into()),
            distance: p.distance.to_bits(),
            segment: p.segment.map(|s| s.map(v3)),
        }
    }

    /// Back to a finding; errors name the bad field.
    fn finding(&self) -> Result<PairFinding, String> {
        Ok(PairFinding {
            a: self.a,
            b: self.b,
            kind: kind(&self.kind)?,
            contact: self.contact.as_deref().map(contact).transpose()?,
            distance: f64::from_bits(self.distance),
            segment: self.segment.map(|s| s.map(p3)),
        })
    }
}

/// A closest pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WireClosest {
    distance: u64,
    a: (u32, V3),
    b: (u32, V3),
}

/// Containment: its report name (`none` for none) and, when undecided, the reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WireContainment {
    kind: String,
    reason: Option<String>,
}

/// A part pair's summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WireSummary {
    a: usize,
    b: usize,
    verdict: String,
    counts: [u64; 4],
    min_distance: Option<u64>,
    containment: WireContainment,
    closest: Option<WireClosest>,
    pairs: Vec<(u32, u32)>,
}

/// A whole [`Outcome`] but its parts (which the merge recomputes from the inputs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WireOutcome {
    pairs: Vec<WirePair>,
    counts: [u64; 4],
    closest: Option<WireClosest>,
    verdict: String,
    containment: WireContainment,
    closed: [Option<bool>; 2],
    /// Tree stats per input: nodes, leaves, depth, SAH cost bits, bytes.
    trees: [[u64; 6]; 2],
    timings: [u64; 2],
    part_pairs: Vec<WireSummary>,
    mode: String,
    selected: [usize; 2],
    candidate_part_pairs: usize,
    built_parts: Option<usize>,
    sah_builds: Option<usize>,
    sharing: Option<[usize; 3]>,
}

fn verdict(s: &str) -> Result<Verdict, String> {
    [Verdict::Clear, Verdict::Clearance, Verdict::Touching, Verdict::Clash]
        .into_iter()
        .find(|v| v.name() == s)
        .ok_or_else(|| format!("unknown verdict '{s}'"))
}

fn kind(s: &str) -> Result<PairKind, String> {
    [PairKind::Crossing, PairKind::Touching, PairKind::Clearance]
        .into_iter()
        .find(|v| v.name() == s)
        .ok_or_else(|| format!("unknown pair kind '{s}'"))
}

fn contact(s: &str) -> Result<Contact, String> {
    [Contact::Point, Contact::Segment, Contact::CoplanarArea, Contact::CoplanarBoundary]
        .into_iter()
        .find(|v| v.name() == s)
        .ok_or_else(|| format!("unknown contact '{s}'"))
}

fn counts(c: &Counts) -> [u64; 4] {
    [c.crossing, c.touching, c.within_tolerance, c.clearance]
}
fn counts_of(c: [u64; 4]) -> Counts {
    Counts { crossing: c[0], touching: c[1], within_tolerance: c[2], clearance: c[3] }
}

fn closest(c: &Closest) -> WireClosest {
    WireClosest { distance: c.distance.to_bits(), a: (c.a.0, v3(c.a.1)), b: (c.b.0, v3(c.b.1)) }
}
fn closest_of(c: &WireClosest) -> Closest {
    Closest { distance: f64::from_bits(c.distance), a: (c.a.0, p3(c.a.1)), b: (c.b.0, p3(c.b.1)) }
}

fn containment(c: &Containment) -> WireContainment {
    let reason = match c {
        Containment::Undecided(r) => Some(r.clone()),
        _ => None,
    };
    WireContainment { kind: c.name().unwrap_or("none").into(), reason }
}
fn containment_of(c: &WireContainment) -> Result<Containment, String> {
    Ok(match (c.kind.as_str(), &c.reason) {
        ("none", None) => Containment::None,
        ("a_in_b", None) => Containment::AInB,
        ("b_in_a", None) => Containment::BInA,
        ("a_partly_in_b", None) => Containment::APartlyInB,
        ("b_partly_in_a", None) => Containment::BPartlyInA,
        ("volumes_overlap", None) => Containment::VolumesOverlap,
        ("undecided", Some(r)) => Containment::Undecided(r.clone()),
        (k, _) => return Err(format!("bad containment '{k}'")),
    })
}

impl WireOutcome {
    /// The wire form of `o` (its parts left out).
    pub fn of(o: &Outcome) -> WireOutcome {
        let r = &o.result;
        let i = &o.info;
        let tree = |t: &crate::bvh::Stats| {
            [
                t.nodes as u64,
                t.leaves as u64,
                t.depth as u64,
                t.sah_cost.to_bits(),
                t.bytes as u64,
                t.cells as u64,
            ]
        };
        WireOutcome {
            pairs: r.pairs.iter().map(WirePair::of).collect(),
            counts: counts(&r.counts),
            closest: r.closest.as_ref().map(closest),
            verdict: r.verdict.name().into(),
            containment: containment(&r.containment),
            closed: r.closed,
            trees: [tree(&r.trees[0]), tree(&r.trees[1])],
            timings: [r.timings.build_ms.to_bits(), r.timings.query_ms.to_bits()],
            part_pairs: o
                .part_pairs
                .iter()
                .map(|s| WireSummary {
                    a: s.a,
                    b: s.b,
                    verdict: s.verdict.name().into(),
                    counts: counts(&s.counts),
                    min_distance: s.min_distance.map(f64::to_bits),
                    containment: containment(&s.containment),
                    closest: s.closest.as_ref().map(closest),
                    pairs: s.pairs.clone(),
                })
                .collect(),
            mode: i.mode.into(),
            selected: i.selected,
            candidate_part_pairs: i.candidate_part_pairs,
            built_parts: i.built_parts,
            sah_builds: i.sah_builds,
            sharing: i.sharing.map(|s| [s.shared_trees, s.mapped_instances, s.memory_saved_bytes]),
        }
    }

    /// The same outcome with its build and query times set to zero (they are not part of the
    /// answer).
    pub fn without_timings(mut self) -> WireOutcome {
        self.timings = [0.0f64.to_bits(); 2];
        self
    }

    /// Back to an [`Outcome`], without its parts (the caller has them: `n` of them). Errors
    /// name the bad field.
    pub fn outcome(&self, n: usize) -> Result<Outcome, String> {
        let part =
            |i: usize| if i < n { Ok(i) } else { Err(format!("part index {i} out of range ({n} parts)")) };
        let pairs = self.pairs.iter().map(WirePair::finding).collect::<Result<Vec<_>, String>>()?;
        let part_pairs = self
            .part_pairs
            .iter()
            .map(|s| {
                Ok(PartPairSummary {
                    a: part(s.a)?,
                    b: part(s.b)?,
                    verdict: verdict(&s.verdict)?,
                    counts: counts_of(s.counts),
                    min_distance: s.min_distance.map(f64::from_bits),
                    containment: containment_of(&s.containment)?,
                    closest: s.closest.as_ref().map(closest_of),
                    pairs: s.pairs.clone(),
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        let tree = |t: [u64; 6]| crate::bvh::Stats {
            nodes: t[0] as usize,
            leaves: t[1] as usize,
            depth: t[2] as usize,
            sah_cost: f64::from_bits(t[3]),
            bytes: t[4] as usize,
            cells: t[5] as usize,
        };
        let mode = match self.mode.as_str() {
            "files" => "files",
            "parts" => "parts",
            m => return Err(format!("unknown assembly mode '{m}'")),
        };
        Ok(Outcome {
            result: ClashResult {
                pairs,
                counts: counts_of(self.counts),
                closest: self.closest.as_ref().map(closest_of),
                verdict: verdict(&self.verdict)?,
                containment: containment_of(&self.containment)?,
                closed: self.closed,
                trees: [tree(self.trees[0]), tree(self.trees[1])],
                timings: Timings {
                    build_ms: f64::from_bits(self.timings[0]),
                    query_ms: f64::from_bits(self.timings[1]),
                },
            },
            parts: Vec::new(),
            part_pairs,
            info: AssemblyInfo {
                mode,
                selected: self.selected,
                candidate_part_pairs: self.candidate_part_pairs,
                built_parts: self.built_parts,
                sah_builds: self.sah_builds,
                sharing: self.sharing.map(|s| Sharing {
                    shared_trees: s[0],
                    mapped_instances: s[1],
                    memory_saved_bytes: s[2],
                }),
            },
        })
    }
}

/// One part pair's check result on the wire (the result cache's stored value): its triangle
/// pairs, counts, closest pair, verdict and containment, every f64 as its bits. Triangle
/// indices are whatever the caller put in (the cache stores them per part).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WireResult {
    pairs: Vec<WirePair>,
    counts: [u64; 4],
    closest: Option<WireClosest>,
    verdict: String,
    containment: WireContainment,
}

impl WireResult {
    /// The wire form of `r`'s answer (its tree stats, timings and closedness left out).
    pub fn of(r: &ClashResult) -> WireResult {
        WireResult {
            pairs: r.pairs.iter().map(WirePair::of).collect(),
            counts: counts(&r.counts),
            closest: r.closest.as_ref().map(closest),
            verdict: r.verdict.name().into(),
            containment: containment(&r.containment),
        }
    }

    /// How many triangle pairs it holds.
    pub fn findings(&self) -> usize {
        self.pairs.len()
    }

    /// Back to a [`ClashResult`] (no tree stats, zero timings, closedness unknown). Errors
    /// name the bad field.
    pub fn result(&self) -> Result<ClashResult, String> {
        let pairs = self.pairs.iter().map(WirePair::finding).collect::<Result<Vec<_>, String>>()?;
        Ok(ClashResult {
            pairs,
            counts: counts_of(self.counts),
            closest: self.closest.as_ref().map(closest_of),
            verdict: verdict(&self.verdict)?,
            containment: containment_of(&self.containment)?,
            closed: [None, None],
            trees: Default::default(),
            timings: Timings::default(),
        })
    }
}
