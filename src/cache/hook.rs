//! The cache in the check: a whole check's outcome is stored under the key of both inputs, the
//! settings and the tool version, and stood in for the check when the same key comes again.
//!
//! The unit is the whole check ([`crate::check::assembly::run`]'s outcome, bit for bit in its
//! wire form, [`WireOutcome`]). Its key is the [`PartKey::of_mesh`] of each input — everything
//! the loaded, placed mesh holds, so also the triangle numbering the findings refer to and the
//! vertex sharing closedness depends on — the [`check_fingerprint`] of every setting that
//! changes the outcome, and the tool version. On a hit, [`WholeCheck`] stands the stored
//! outcome in for the check through the [`PartsHook`]; everything after the check (regions,
//! finding ids, the baseline comparison, the report) runs as it does on a computed outcome, so
//! the report is the one a run without the cache writes, but for its `cache` block.
//!
//! Not cached (the check runs, and the block says every candidate part pair was checked): a
//! run whose selection already carries a hook (the steps of a sharded run), and a run with the
//! parry cross-check (parry's answer is not stored).

use super::key::{Fingerprint, PairKey, PartKey, Setting};
use super::store::{CacheSummary, Store};
use crate::check::assembly::{Hook, Outcome, Part, PartsHook, Selection};
use crate::check::query::{Settings, Timings};
use crate::scene::mesh::Mesh;
use crate::shard::wire::WireOutcome;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// The cache a request asks for (`--cache DIR`, `--cache-max-bytes N`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CacheConfig {
    /// The cache directory (created when missing).
    pub dir: PathBuf,
    /// Its size bound in bytes ([`super::DEFAULT_MAX_BYTES`] by default).
    pub max_bytes: u64,
}

/// A list of globs as one unambiguous text: each glob prefixed by its length.
fn globs(g: &[String]) -> Setting {
    Setting::Str(g.iter().map(|s| format!("{}:{s}", s.len())).collect::<Vec<_>>().join(","))
}

/// The fingerprint of everything besides the inputs that changes a whole check's outcome: the
/// resolved tolerances (bits), the predicate mode, `--first-hit`, the detail level, the tree
/// options, the distance error, the scene flag and the selection globs, `--split-bodies` and
/// `--penetration`. The structs are taken apart field by field, so a new setting does not
/// compile until it is placed here.
pub fn check_fingerprint(
    settings: &Settings,
    sel: &Selection,
    split_bodies: bool,
    penetration: bool,
) -> Fingerprint {
    let Settings { tolerances, bvh, mode, first_hit, distance_error, detail } = *settings;
    let crate::geom::predicates::Tolerances { touch, clearance } = tolerances;
    let crate::bvh::BuildOptions { strategy, leaf_size } = bvh;
    let crate::check::query::DistanceError { rel, abs } = distance_error;
    let Selection { scene, select_a, select_b, exclude, hook: _ } = sel;
    Fingerprint::of([
        ("unit", Setting::from("whole-check")),
        ("touch", touch.into()),
        ("clearance", clearance.into()),
        ("mode", mode.name().into()),
        ("first_hit", first_hit.into()),
        ("detail", detail.name().into()),
        ("bvh", strategy.name().into()),
        ("leaf_size", leaf_size.into()),
        ("distance_rel_err", rel.into()),
        ("distance_abs_err", abs.into()),
        ("scene", (*scene).into()),
        ("select_a", globs(select_a)),
        ("select_b", globs(select_b)),
        ("exclude", globs(exclude)),
        ("split_bodies", split_bodies.into()),
        ("penetration", penetration.into()),
    ])
}

/// Whole-check reuse: a [`PartsHook`] that stands a stored outcome in for the check, or lets
/// the check run and stores what it returns.
#[derive(Debug)]
pub struct WholeCheck {
    store: Arc<Store>,
    settings: Fingerprint,
    /// Cache this run (false: a sharding hook or the cross-check is in the way).
    active: bool,
    key: Mutex<Option<PairKey>>,
    reused: AtomicBool,
}

impl WholeCheck {
    /// A hook over `store` for a check under `settings` (see [`check_fingerprint`]);
    /// `active` false checks everything and stores nothing.
    pub fn new(store: Arc<Store>, settings: Fingerprint, active: bool) -> WholeCheck {
        WholeCheck { store, settings, active, key: Mutex::new(None), reused: AtomicBool::new(false) }
    }

    /// `sel` with this hook in it (when active; else `sel` as it is).
    pub fn selection(self: &Arc<Self>, sel: &Selection) -> Selection {
        let mut s = sel.clone();
        if self.active {
            s.hook = Some(Hook(self.clone()));
        }
        s
    }

    /// The report's `cache` block for the check's outcome `o`: every candidate part pair was
    /// reused (a hit) or checked (a miss).
    pub fn summary(&self, o: &Outcome) -> CacheSummary {
        let n = o.info.candidate_part_pairs as u64;
        let reused = self.reused.load(Ordering::Relaxed);
        CacheSummary {
            part_pairs_reused: if reused { n } else { 0 },
            part_pairs_checked: if reused { 0 } else { n },
            dir: self.store.dir().to_string_lossy().into_owned(),
        }
    }

    /// The warnings collected (entries ignored, results not stored).
    pub fn take_warnings(&self) -> Vec<String> {
        self.store.take_warnings()
    }

    /// The stored outcome of `key`, if there is one that fits these inputs.
    fn lookup(
        &self,
        key: &PairKey,
        meshes: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Outcome> {
        let wire: WireOutcome = self.store.get(key)?;
        let fits = wire.outcome(parts.len()).and_then(|o| {
            crate::shard::in_range(&o, meshes)?;
            if o.info.selected == selected {
                Ok(o)
            } else {
                Err(format!("selected parts {:?}, the inputs {selected:?}", o.info.selected))
            }
        });
        match fits {
            Ok(mut o) => {
                o.parts = parts.to_vec();
                // Nothing was built or walked in this run.
                o.result.timings = Timings::default();
                Some(o)
            }
            Err(e) => {
                // The key matched but the value does not fit: never trusted, recomputed.
                let path = self.store.entry_path(key);
                self.store.warn(format!("cache: ignored entry {}: {e}", path.display()));
                None
            }
        }
    }
}

impl PartsHook for WholeCheck {
    fn keep(&self, _: usize, _: usize) -> bool {
        true
    }

    fn stand_in(
        &self,
        meshes: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Result<Outcome, String>> {
        let (ka, kb) = if std::ptr::eq(meshes[0], meshes[1]) {
            let k = PartKey::of_mesh(meshes[0]);
            (k, k)
        } else {
            rayon::join(|| PartKey::of_mesh(meshes[0]), || PartKey::of_mesh(meshes[1]))
        };
        let key = PairKey::new(&ka, &kb, &self.settings);
        *self.key.lock().unwrap_or_else(|p| p.into_inner()) = Some(key);
        let o = self.lookup(&key, meshes, parts, selected)?;
        self.reused.store(true, Ordering::Relaxed);
        Some(Ok(o))
    }

    fn seen(&self, _: [&Mesh; 2], o: &Outcome) {
        if self.reused.load(Ordering::Relaxed) {
            return;
        }
        if let Some(key) = *self.key.lock().unwrap_or_else(|p| p.into_inner()) {
            // Timings are not part of the answer: stored as zero, so equal outcomes store
            // equal bytes.
            self.store.put(&key, &WireOutcome::of(o).without_timings());
        }
    }
}
