//! Stable finding ids and the comparison with an earlier report (`--baseline`).
//!
//! **Finding id**: 16 hex digits, a 64-bit FNV-1a hash (with a final mix) of, in this order,
//! A's triangle, A's object name, B's triangle, B's object name. A triangle enters as its three
//! vertices in world coordinates (after `--transform`/`--translate`), each as the bit patterns of
//! its x, y, z (`-0.0` taken as `0.0`), the three vertices sorted, so the id does not depend on
//! triangle order, vertex order within the triangle, vertex indexing, the kind of contact or the
//! thread count; it changes when either triangle moves or is renamed. Swapping A and B changes
//! every id.
//!
//! **Status**: a finding of the current run is `new` if no finding of the baseline has its id,
//! else `persistent`; a baseline finding whose id is not found now is `resolved`. A comparison
//! needs every finding of the baseline: a report whose `pairs` list was cut records the ids of
//! the findings it does not list (`unlisted`), and a report that cannot say what it found (cut
//! by an older version, `--first-hit`, `--detail parts`, a partial merge) is refused as a
//! baseline. The current run's ids cover every pair found, listed or not.
//!
//! **`--fail-on new`** fails (exit 1) exactly when `new_crossing > 0` (a crossing pair whose id
//! was not a crossing pair of the baseline: a new pair, or one that only touched or came within
//! the clearance before) or `new_containment` (the report says one part is inside the other,
//! `a_in_b|b_in_a|a_partly_in_b|b_partly_in_a|volumes_overlap`, and the baseline did not say the
//! same). New touching or clearance pairs are listed but do not fail it.

use crate::check::query::{PairFinding, PairKind};
use crate::report::{ReportContainment, UnlistedFindings};
use crate::scene::mesh::Mesh;
use serde::de::{self, Deserializer, IgnoredAny, Visitor};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeSet, HashMap, HashSet};

/// The `baseline` block of a report written with `--baseline`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BaselineReport {
    /// The baseline report's path as given.
    pub path: String,
    /// Findings of this run (all, not only the listed ones) whose id is not in the baseline.
    pub new: u64,
    /// Findings of this run whose id is in the baseline.
    pub persistent: u64,
    /// Distinct baseline ids not found in this run.
    pub resolved: u64,
    /// Those ids, sorted.
    pub resolved_ids: Vec<String>,
    /// Crossing pairs of this run that were not crossing pairs of the baseline.
    pub new_crossing: u64,
    /// The run reports containment (one part inside the other) that the baseline did not.
    pub new_containment: bool,
    /// Always true: a baseline that does not record every finding is refused.
    pub complete: bool,
}

/// A finding of this run: its id and kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Finding {
    /// Stable id: the number its 16 hex digits spell ([`crate::check::finding_id::format_id`]
    /// writes it).
    pub id: u64,
    /// How the pair meets.
    pub kind: PairKind,
}

/// What is needed from a baseline report: every finding id it records (listed or not), with
/// whether a finding with that id was a crossing, and its containment. Ids are held as the 64-bit
/// numbers their 16 hex digits spell (a large baseline stays small in memory).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Baseline {
    /// Path as given.
    pub path: String,
    /// Every finding id, each with whether any finding with that id was a crossing.
    pub ids: HashMap<u64, bool>,
    /// Its `summary.contained` (a value this version does not know reads as none).
    pub contained: Option<ReportContainment>,
}

impl Baseline {
    /// Does the baseline have a finding with this id (the number its 16 hex digits spell)?
    pub fn contains(&self, id: u64) -> bool {
        self.ids.contains_key(&id)
    }

    fn crossing(&self, id: u64) -> bool {
        self.ids.get(&id).copied().unwrap_or(false)
    }
}

/// A finding id's number (16 hex digits), or None.
fn parse_hex(id: &str) -> Option<u64> {
    (id.len() == 16).then(|| u64::from_str_radix(id, 16).ok()).flatten()
}

pub use crate::check::finding_id::finding_id;

/// Ids and kinds of every pair found (in the order of `pairs`).
pub fn findings(pairs: &[PairFinding], a: &Mesh, b: &Mesh) -> Vec<Finding> {
    findings_of(pairs, &crate::check::finding_id::finding_hashes(pairs, a, b))
}

/// The findings of `pairs` whose ids (`ids[i]` the id of `pairs[i]`) are already known.
pub fn findings_of(pairs: &[PairFinding], ids: &[u64]) -> Vec<Finding> {
    debug_assert_eq!(pairs.len(), ids.len());
    pairs.iter().zip(ids).map(|(p, &id)| Finding { id, kind: p.kind }).collect()
}

/// The ids of the findings a cut list does not show (`listed`: the indices it shows, sorted),
/// split by whether the finding is a crossing, each list sorted and without repeats.
pub fn unlisted(all: &[Finding], listed: &[usize]) -> UnlistedFindings {
    use rayon::prelude::*;
    let mut shown = listed.iter().copied().peekable();
    let (mut crossing, mut other) = (Vec::new(), Vec::new());
    for (i, f) in all.iter().enumerate() {
        if shown.peek() == Some(&i) {
            shown.next();
            continue;
        }
        if f.kind == PairKind::Crossing { &mut crossing } else { &mut other }.push(f.id);
    }
    // 16 hex digits order as the numbers they spell.
    let list = |mut ids: Vec<u64>| -> Vec<String> {
        ids.par_sort_unstable();
        ids.dedup();
        ids.par_iter().map(|&k| crate::check::finding_id::format_id(k)).collect()
    };
    let (crossing_ids, other_ids) = rayon::join(|| list(crossing), || list(other));
    UnlistedFindings { crossing_ids, other_ids }
}

/// A finding id as read from a baseline (16 hex digits; None when malformed).
struct HexId(Option<u64>);

impl<'de> Deserialize<'de> for HexId {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = HexId;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a finding id")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> std::result::Result<HexId, E> {
                Ok(HexId(parse_hex(s)))
            }
        }
        d.deserialize_str(V)
    }
}

/// A pair kind as read from a baseline: is it `crossing`? (Kinds this version does not know
/// read as not crossing.)
struct IsCrossing(bool);

impl<'de> Deserialize<'de> for IsCrossing {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = IsCrossing;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a pair kind")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> std::result::Result<IsCrossing, E> {
                Ok(IsCrossing(s == "crossing"))
            }
        }
        d.deserialize_any(V)
    }
}

/// The fields a comparison reads; everything else is skipped unread.
#[derive(Deserialize)]
struct BaseFile {
    schema: Option<serde_json::Value>,
    complete: Option<IgnoredOr<bool>>,
    settings: Option<BaseSettings>,
    summary: Option<BaseSummary>,
    pairs: Option<Vec<BasePair>>,
    pairs_truncated: Option<IgnoredOr<bool>>,
    unlisted: Option<BaseUnlisted>,
}

/// A value of the expected type, or anything else (read as absent).
#[derive(Deserialize)]
#[serde(untagged)]
enum IgnoredOr<T> {
    Value(T),
    Other(IgnoredAny),
}

impl<T: Copy> IgnoredOr<T> {
    fn get(o: &Option<Self>) -> Option<T> {
        match o {
            Some(IgnoredOr::Value(v)) => Some(*v),
            _ => None,
        }
    }
}

#[derive(Deserialize)]
struct BaseSettings {
    first_hit: Option<IgnoredOr<bool>>,
    detail: Option<IgnoredAny>,
}

#[derive(Deserialize)]
struct BaseSummary {
    contained: Option<serde_json::Value>,
}

#[derive(Deserialize)]
struct BasePair {
    id: Option<HexId>,
    kind: Option<IsCrossing>,
}

#[derive(Deserialize)]
struct BaseUnlisted {
    crossing_ids: Vec<HexId>,
    other_ids: Vec<HexId>,
}

/// Parse a baseline report's JSON; the error is a one-line message.
pub fn parse(path: &str, bytes: &[u8]) -> std::result::Result<Baseline, String> {
    let v: BaseFile = serde_json::from_slice(bytes).map_err(|e| {
        if e.is_data() {
            format!("baseline is not a meshclash report: {e}")
        } else {
            format!("baseline is not JSON: {e}")
        }
    })?;
    // Any version of the report format will do: only ids, kinds and containment are read.
    match &v.schema {
        Some(serde_json::Value::String(s)) if s.starts_with("meshclash.report/") => {}
        Some(serde_json::Value::String(s)) => {
            let hint = if s.starts_with("meshclash.") {
                " (--baseline takes a report of `meshclash A B` or `meshclash scene FILE`)"
            } else {
                ""
            };
            let s = crate::error::clip(s, 60);
            return Err(format!("baseline is not a meshclash report: its schema is '{s}'{hint}"));
        }
        Some(_) => return Err("baseline is not a meshclash report: its \"schema\" is not a string".into()),
        None => return Err("baseline is not a meshclash report: it has no \"schema\"".into()),
    }
    if IgnoredOr::get(&v.complete) == Some(false) {
        // A partial merge: pairs not checked must not read as resolved.
        return Err("baseline is a partial merge (\"complete\": false): merge every shard first".into());
    }
    if let Some(s) = &v.settings {
        if IgnoredOr::get(&s.first_hit) == Some(true) {
            return Err("baseline was written with --first-hit, which stops at the first crossing: it \
                        does not record every finding (write it without --first-hit)"
                .into());
        }
        if s.detail.is_some() && v.pairs.as_ref().is_none_or(Vec::is_empty) && v.unlisted.is_none() {
            return Err("baseline was written with --detail parts, which keeps no triangle pairs: it \
                        cannot be compared (write it with the default --detail pairs)"
                .into());
        }
    }
    let pairs = v.pairs.ok_or("baseline has no pairs list")?;
    let truncated = IgnoredOr::get(&v.pairs_truncated).unwrap_or(false);
    if truncated && v.unlisted.is_none() {
        return Err(format!(
            "baseline lists {} pairs and was cut at its --max-pairs without recording the others' ids \
             (written by an older meshclash?): regenerate it, so that new and resolved findings can be \
             told apart",
            pairs.len()
        ));
    }
    let mut ids: HashMap<u64, bool> = HashMap::with_capacity(pairs.len());
    for (i, p) in pairs.iter().enumerate() {
        let id = match &p.id {
            None => {
                return Err(format!(
                    "baseline pair {i} has no id (written by an older meshclash? regenerate it)"
                ))
            }
            Some(HexId(None)) => return Err(format!("baseline pair {i} has a malformed id (16 hex digits)")),
            Some(HexId(Some(id))) => *id,
        };
        let crossing = p.kind.as_ref().is_some_and(|k| k.0);
        *ids.entry(id).or_insert(false) |= crossing;
    }
    if let Some(u) = &v.unlisted {
        for (list, crossing) in [(&u.crossing_ids, true), (&u.other_ids, false)] {
            for (i, id) in list.iter().enumerate() {
                let id =
                    id.0.ok_or_else(|| format!("baseline unlisted id {i} is malformed (16 hex digits)"))?;
                *ids.entry(id).or_insert(false) |= crossing;
            }
        }
    }
    let contained = v.summary.and_then(|s| s.contained).and_then(|c| ReportContainment::deserialize(c).ok());
    Ok(Baseline { path: path.to_string(), ids, contained })
}

fn is_containment_clash(c: Option<ReportContainment>) -> bool {
    c.is_some_and(ReportContainment::is_clash)
}

/// Compare every finding of this run (`all`) with a baseline that records all of its own;
/// `contained` is this run's containment.
pub fn compare(all: &[Finding], base: &Baseline, contained: Option<ReportContainment>) -> BaselineReport {
    let now: HashSet<u64> = all.iter().map(|f| f.id).collect();
    let persistent = all.iter().filter(|f| base.contains(f.id)).count() as u64;
    let new_crossing =
        all.iter().filter(|f| f.kind == PairKind::Crossing && !base.crossing(f.id)).count() as u64;
    let resolved: BTreeSet<u64> = base.ids.keys().filter(|id| !now.contains(id)).copied().collect();
    BaselineReport {
        path: base.path.clone(),
        new: all.len() as u64 - persistent,
        persistent,
        resolved: resolved.len() as u64,
        resolved_ids: resolved.into_iter().map(|k| format!("{k:016x}")).collect(),
        new_crossing,
        new_containment: is_containment_clash(contained) && base.contained != contained,
        complete: true,
    }
}

/// Does the comparison fail `--fail-on new`? (See the module docs.)
pub fn fails_on_new(b: &BaselineReport) -> bool {
    b.new_crossing > 0 || b.new_containment
}

#[cfg(test)]
mod tests {

    #[test]
    fn volumes_overlap_counts_as_containment_clash_for_fail_on_new() {
        // Regression: a new `volumes_overlap` was not counted as new containment.
        assert!(is_containment_clash(Some(ReportContainment::VolumesOverlap)));
        assert!(is_containment_clash(Some(ReportContainment::AInB)));
        assert!(!is_containment_clash(Some(ReportContainment::Undecided)));
        assert!(!is_containment_clash(None));
        // and it is read back from a baseline as the containment it is
        let b = parse(
            "b.json",
            br#"{"schema": "meshclash.report/2", "pairs": [], "summary": {"contained": "volumes_overlap"}}"#,
        );
        assert_eq!(b.unwrap().contained, Some(ReportContainment::VolumesOverlap));
    }

    use super::*;
    use crate::scene::mesh::Object;
    use glam::DVec3;

    fn mesh(tris: &[[[f64; 3]; 3]], name: &str) -> Mesh {
        let mut m = Mesh::default();
        for t in tris {
            let base = m.positions.len() as u32;
            m.positions.extend(t.iter().map(|&p| DVec3::from_array(p)));
            m.triangles.push([base, base + 1, base + 2]);
            m.tri_object.push(0);
        }
        m.objects.push(Object { name: name.into(), ..Object::default() });
        m
    }

    const T1: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    const T2: [[f64; 3]; 3] = [[0.0, 0.0, -1.0], [0.2, 0.2, 1.0], [0.3, 0.1, 1.0]];

    #[test]
    fn id_ignores_order_and_negative_zero_but_not_geometry_or_names() {
        let a = mesh(&[T1, T2], "a");
        let b = mesh(&[T2], "b");
        let id = finding_id(&a, 0, &b, 0);
        assert_eq!(id.len(), 16);
        assert!(id.chars().all(|c| c.is_ascii_hexdigit()));
        // Rotated vertex order, -0.0, and the triangle at another index: same id.
        let rotated = [[-0.0, 1.0, 0.0], T1[0], T1[1]];
        let a2 = mesh(&[T2, rotated], "a");
        assert_eq!(finding_id(&a2, 1, &b, 0), id);
        // Renamed object, moved vertex, swapped sides: different ids.
        assert_ne!(finding_id(&mesh(&[T1], "a2"), 0, &b, 0), id);
        let moved = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1e-300]];
        assert_ne!(finding_id(&mesh(&[moved], "a"), 0, &b, 0), id);
        assert_ne!(finding_id(&b, 0, &a, 0), id);
    }

    #[test]
    fn baseline_without_ids_or_of_another_schema_is_rejected() {
        let old = br#"{"schema": "meshclash.report/1", "pairs": [{"a": 0, "b": 1, "kind": "crossing"}]}"#;
        assert!(parse("old.json", old).unwrap_err().contains("no id"));
        assert!(parse("x.json", br#"{"schema": "other/1", "pairs": []}"#)
            .unwrap_err()
            .contains("not a meshclash"));
        assert!(parse("x.json", b"not json").is_err());
        // Regression: the schema was shown as `Some("meshclash.clash-set/1")`.
        let e = parse("x.json", br#"{"schema": "meshclash.clash-set/1"}"#).unwrap_err();
        assert_eq!(
            e,
            "baseline is not a meshclash report: its schema is 'meshclash.clash-set/1' (--baseline takes a \
             report of `meshclash A B` or `meshclash scene FILE`)"
        );
        assert!(!e.contains("Some("), "{e}");
        let e = parse("x.json", br#"{"pairs": []}"#).unwrap_err();
        assert_eq!(e, "baseline is not a meshclash report: it has no \"schema\"");
        let (id1, id2, id3) = ("00000000000000a1", "00000000000000a2", "00000000000000a3");
        let n = |id: &str| parse_hex(id).expect("16 hex digits");
        let ok = format!(
            r#"{{"schema": "meshclash.report/1", "pairs_truncated": false, "summary": {{"contained": "a_in_b"}},
            "pairs": [{{"id": "{id1}", "kind": "touching"}}, {{"id": "{id1}", "kind": "crossing"}}, {{"id": "{id2}", "kind": "touching"}}]}}"#
        );
        let b = parse("b.json", ok.as_bytes()).unwrap();
        assert_eq!(b.ids.len(), 2);
        assert!(b.contains(n(id1)) && b.crossing(n(id1)));
        assert!(b.contains(n(id2)) && !b.crossing(n(id2)));
        assert!(!b.contains(n(id3)));
        // A cut list without the ids of what it does not list cannot be compared: refused.
        let cut = ok.replace("\"pairs_truncated\": false", "\"pairs_truncated\": true");
        let e = parse("b.json", cut.as_bytes()).unwrap_err();
        assert!(e.contains("cut at its --max-pairs"), "{e}");
        // With the unlisted ids it is complete: every id counts, crossing or not.
        let whole = cut.replacen(
            "\"pairs\":",
            &format!(r#""unlisted": {{"crossing_ids": ["{id3}"], "other_ids": []}}, "pairs":"#),
            1,
        );
        let b = parse("b.json", whole.as_bytes()).unwrap();
        assert_eq!(b.ids.len(), 3);
        assert!(b.contains(n(id3)) && b.crossing(n(id3)));
        // A first-hit report or a malformed id is refused too.
        let fh = ok.replacen("{\"schema\"", "{\"settings\": {\"first_hit\": true}, \"schema\"", 1);
        assert!(parse("b.json", fh.as_bytes()).unwrap_err().contains("--first-hit"));
        let bad = ok.replace(id2, "xyz");
        assert!(parse("b.json", bad.as_bytes()).unwrap_err().contains("malformed id"));
        assert_eq!(b.contained, Some(ReportContainment::AInB));
    }

    #[test]
    fn unlisted_ids_are_the_sorted_distinct_hex_ids_of_the_pairs_not_shown() {
        let mut r = 3u64;
        let mut next = move || {
            r = r.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            r
        };
        // Ids of every width and with repeats (a repeat may be listed once and unlisted once).
        let all: Vec<Finding> = (0..3000)
            .map(|i| {
                let id = if i % 7 == 0 { 0xa5 } else { next() >> (next() % 64) };
                let kind = if next() % 3 == 0 { PairKind::Crossing } else { PairKind::Touching };
                Finding { id, kind }
            })
            .collect();
        let listed: Vec<usize> = (0..all.len()).filter(|i| i % 5 == 1).collect();
        let (mut crossing, mut other) = (BTreeSet::new(), BTreeSet::new());
        for (i, f) in all.iter().enumerate() {
            if !listed.contains(&i) {
                let id = format!("{:016x}", f.id);
                if f.kind == PairKind::Crossing { &mut crossing } else { &mut other }.insert(id);
            }
        }
        let got = unlisted(&all, &listed);
        assert_eq!(got.crossing_ids, crossing.into_iter().collect::<Vec<_>>());
        assert_eq!(got.other_ids, other.into_iter().collect::<Vec<_>>());
        assert!(got.crossing_ids.len() > 100 && got.crossing_ids.iter().all(|s| s.len() == 16));
    }
}
