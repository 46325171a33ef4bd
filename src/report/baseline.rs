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
//! else `persistent`; a baseline finding whose id is not found now is `resolved`. Only the
//! baseline's *listed* pairs are known (its `--max-pairs`); `complete` says whether that list was
//! cut. The current run's ids cover every pair found, listed or not.
//!
//! **`--fail-on new`** fails (exit 1) exactly when `new_crossing > 0` (a crossing pair whose id
//! was not a crossing pair of the baseline: a new pair, or one that only touched or came within
//! the clearance before) or `new_containment` (the report says one part is inside the other,
//! `a_in_b|b_in_a|a_partly_in_b|b_partly_in_a`, and the baseline did not say the same).
//! New touching or clearance pairs are listed but do not fail it.

use crate::check::query::{PairFinding, PairKind};
use crate::error::{Error, InputProblem, Reading, Result};
use crate::report::{Report, ReportContainment, ReportPairKind};
use crate::scene::mesh::Mesh;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::Path;

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
    /// False when the baseline's pair list was truncated (`pairs_truncated`): findings it did
    /// not list count as new here, and resolved ones it did not list are missing.
    pub complete: bool,
}

/// A finding of this run: its id and kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// Stable id (16 hex digits).
    pub id: String,
    /// How the pair meets.
    pub kind: PairKind,
}

/// What is needed from a baseline report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Baseline {
    /// Path as given.
    pub path: String,
    /// Listed finding ids, each with whether any finding with that id was a crossing.
    pub ids: HashMap<String, bool>,
    /// Its `summary.contained` (a value this version does not know reads as none).
    pub contained: Option<ReportContainment>,
    /// Its `pairs_truncated`.
    pub truncated: bool,
}

pub use crate::check::finding_id::finding_id;

/// Ids and kinds of every pair found (in the order of `pairs`).
pub fn findings(pairs: &[PairFinding], a: &Mesh, b: &Mesh) -> Vec<Finding> {
    use rayon::prelude::*;
    pairs.par_iter().map(|p| Finding { id: finding_id(a, p.a, b, p.b), kind: p.kind }).collect()
}

/// Set `id` on the listed pairs: `rep.pairs` are the first of the pairs `findings` was made from.
pub fn assign_ids(rep: &mut Report, findings: &[Finding]) {
    for (p, f) in rep.pairs.iter_mut().zip(findings) {
        p.id = Some(f.id.clone());
    }
}

/// Read a baseline report (any `meshclash.report/*` written with finding ids; unknown fields
/// are ignored so that reports of later versions can serve as baselines).
pub fn read(path: &Path) -> Result<Baseline> {
    let bytes = std::fs::read(path).map_err(|e| {
        Error::in_file(
            path,
            InputProblem::Unreadable { reading: Reading::Baseline, kind: e.kind(), reason: e.to_string() },
        )
    })?;
    parse(&path.display().to_string(), &bytes).map_err(|msg| Error::in_file(path, InputProblem::Invalid(msg)))
}

/// Parse a baseline report's JSON; the error is a one-line message.
pub fn parse(path: &str, bytes: &[u8]) -> std::result::Result<Baseline, String> {
    let v: serde_json::Value =
        serde_json::from_slice(bytes).map_err(|e| format!("baseline is not JSON: {e}"))?;
    // Any version of the report format will do: only ids, kinds and containment are read.
    match v.get("schema") {
        Some(serde_json::Value::String(s)) if s.starts_with("meshclash.report/") => {}
        Some(serde_json::Value::String(s)) => {
            let hint = if s.starts_with("meshclash.") {
                " (--baseline takes a report of `meshclash A B` or `meshclash scene FILE`)"
            } else {
                ""
            };
            let s = crate::load::clip(s, 60);
            return Err(format!("baseline is not a meshclash report: its schema is '{s}'{hint}"));
        }
        Some(_) => return Err("baseline is not a meshclash report: its \"schema\" is not a string".into()),
        None => return Err("baseline is not a meshclash report: it has no \"schema\"".into()),
    }
    if v.get("complete") == Some(&serde_json::Value::Bool(false)) {
        // `meshclash merge --allow-partial` (issue 14): pairs not re-checked must not read as resolved.
        return Err("baseline is a partial merge (\"complete\": false): merge every shard first".into());
    }
    let pairs = v.get("pairs").and_then(|p| p.as_array()).ok_or("baseline has no pairs list")?;
    let mut ids = HashMap::new();
    for (i, p) in pairs.iter().enumerate() {
        let id = p.get("id").and_then(|s| s.as_str()).ok_or_else(|| {
            format!("baseline pair {i} has no id (written by an older meshclash? regenerate it)")
        })?;
        let kind = p.get("kind").and_then(|k| ReportPairKind::deserialize(k).ok());
        let crossing = kind == Some(ReportPairKind::Crossing);
        *ids.entry(id.to_string()).or_insert(false) |= crossing;
    }
    Ok(Baseline {
        path: path.to_string(),
        ids,
        contained: v.pointer("/summary/contained").and_then(|c| ReportContainment::deserialize(c).ok()),
        truncated: v.get("pairs_truncated").and_then(|t| t.as_bool()).unwrap_or(false),
    })
}

fn is_containment_clash(c: Option<ReportContainment>) -> bool {
    c.is_some_and(ReportContainment::is_clash)
}

/// Mark the listed pairs `new`/`persistent` and add the `baseline` block. `findings` are all the
/// pairs of this run (the listed ones first, in order).
pub fn compare(rep: &mut Report, findings: &[Finding], base: &Baseline) {
    let now: HashSet<&str> = findings.iter().map(|f| f.id.as_str()).collect();
    for (p, f) in rep.pairs.iter_mut().zip(findings) {
        p.status = Some(if base.ids.contains_key(&f.id) { "persistent" } else { "new" }.to_string());
    }
    let persistent = findings.iter().filter(|f| base.ids.contains_key(&f.id)).count() as u64;
    let new_crossing = findings
        .iter()
        .filter(|f| f.kind == PairKind::Crossing && base.ids.get(&f.id) != Some(&true))
        .count() as u64;
    let resolved: BTreeSet<&String> = base.ids.keys().filter(|id| !now.contains(id.as_str())).collect();
    let contained = rep.summary.contained;
    rep.baseline = Some(BaselineReport {
        path: base.path.clone(),
        new: findings.len() as u64 - persistent,
        persistent,
        resolved: resolved.len() as u64,
        resolved_ids: resolved.into_iter().cloned().collect(),
        new_crossing,
        new_containment: is_containment_clash(contained) && base.contained != contained,
        complete: !base.truncated,
    });
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
        let ok = br#"{"schema": "meshclash.report/1", "pairs_truncated": true, "summary": {"contained": "a_in_b"},
            "pairs": [{"id": "01", "kind": "touching"}, {"id": "01", "kind": "crossing"}, {"id": "02", "kind": "touching"}]}"#;
        let b = parse("b.json", ok).unwrap();
        assert_eq!(b.ids.len(), 2);
        assert!(b.ids["01"]);
        assert!(!b.ids["02"]);
        assert!(b.truncated);
        assert_eq!(b.contained, Some(ReportContainment::AInB));
    }
}
