//! Part-pair reuse: a re-check costs what changed.
//!
//! In parts mode (`scene`, or a selection) the broad phase over the part boxes runs every
//! time. Each candidate part pair then has a [`PairKey`]: the [`PartKey::of_part_layout`] of
//! its A-side and B-side parts (name, exact world-space vertices, how the triangles share
//! them), the [`pair_fingerprint`] of the settings that change a pair's answer, and the tool
//! version. A pair whose key is stored reuses its stored result — verdict, counts, triangle
//! pairs, closest pair, containment — instead of walking trees; the others are checked
//! together, exactly as the check checks them, and stored. The reduction over the pairs, the
//! tree-sharing figures and everything after the check (regions, finding ids, the baseline
//! comparison, the report) are then those of a run without the cache; the finding ids of the
//! reused pairs' triangle pairs are the stored ones ([`CheckCache::finding_ids`]), the same
//! values (an id is a function of the two parts' names and exact world triangles, which the
//! key holds).
//!
//! Exactness:
//!
//! - A stored result names triangles by their place in their part (the n-th triangle of the
//!   part), so it holds whatever other parts do; it is mapped to the file's triangle numbers
//!   when reused.
//! - A clear pair's distance only matters when it could be the scene's closest. A pair with a
//!   finding is stored with its exact closest pair (the check searches it in full). The clear
//!   pairs a check searches together share one bound, so each search stops as soon as it
//!   cannot beat the least candidate `m` found over all of them: afterwards, each clear pair's
//!   closest pair is the one it found, or comes after `m` in the order the scene's closest is
//!   chosen by (distance, then triangle in A, then in B). A clear pair is stored with `m` (its
//!   *bound*, [`pack::Stored::beyond`], with the digest of the triangle numbering it is in),
//!   and with its closest pair only when that is `m` itself (the others are where the search
//!   stopped, not proven closest).
//! - When no reused or checked pair touches or crosses (the scene's minimum distance is then
//!   positive and could be a clear pair's), let `best` be the least candidate over every
//!   result at hand (listed pairs, checked pairs, stored closest pairs). A reused clear pair
//!   whose bound is not before `best` (compared as stored when the numbering is the same,
//!   else by distance alone, strictly) cannot hold a pair before `best`, and is not searched.
//!   The other reused clear pairs are checked again, together, and count as checked; so the
//!   scene's closest pair is the one a run without the cache finds. A warm re-run of an
//!   unchanged clear scene searches nothing.
//! - A clashing pair of two closed parts carries the exact box of their common volume in the
//!   report ([`crate::check::overlap`]), a function of the two parts alone: it is stored with
//!   the pair's result (after the check, once the boxes are computed: [`CheckCache::overlaps`])
//!   and reused with it, so a warm run computes the boxes of the checked pairs only. A reused
//!   clash whose box is not stored, or whose box does not lie within both parts' boxes, is not
//!   reused: it is checked again.
//! - A run where reuse by pair could differ from a whole check falls back to caching the
//!   whole check ([`WholeCheck`]): file mode (one unit), `--first-hit` (a stop rule),
//!   a distance error allowance (the reported distance may depend on which pairs are searched
//!   together), and a selection that puts one part on both sides (its pairs with itself and
//!   mirrored pairs take part in the check's distance bound).
//!
//! Storage: one run writes an index entry and packs, whatever its number of pairs. A *pack*
//! holds results of pairs the run checked (keyed by their pair keys; at most
//! [`PACK_FINDINGS`] triangle pairs a pack) and the tree sizes it measured (keyed by part key;
//! the report's memory figures need them); the *index* of the run's lineage (its settings,
//! what the inputs are and the selection) lists the packs to read, newest first. The pipeline
//! names the inputs by content, the digest of their object names, not by file name: a model
//! saved under a new name, or one of whose parts moved, finds its earlier runs. A later run reads
//! the index and its packs (at most [`MAX_INDEX`]), reuses what it finds, writes packs of what
//! it checked and a new index (its packs, then the old packs it reused from; a shard also
//! keeps the other shards' packs). A lost index or pack (evicted, corrupt, removed, written by
//! another version) is a miss: the pairs are checked again. Two runs writing one index at
//! once: one wins, and the other's packs are only unreachable (evicted in time).
//!
//! Packs and indexes are binary ([`pack`] describes their bytes): written without any
//! round-trip check, read with every bound checked, whole by the entry's SHA-256.
//!
//! Layouts (SHA-256, integers little-endian): the index key is the tag `meshclash.cache.index`
//! and a zero byte, [`FORMAT`](super::FORMAT) (u32), the fingerprint's 32 bytes, the lineage's
//! length (u64) and UTF-8 text; a pack's key is the tag `meshclash.cache.pack` and a zero
//! byte, [`FORMAT`](super::FORMAT) (u32), the fingerprint's 32 bytes, then the 32 bytes of each
//! pair key it holds, in order, a zero byte, then the 32 bytes of each part key whose tree
//! size it holds, in order. The numbering digest is the tag `meshclash.cache.numbering` and a
//! zero byte, the number of parts (u64), then for each part its input (one byte), its number
//! of triangles (u64) and their numbers in the input mesh (u32 each).

use super::hook::WholeCheck;
use super::key::{Digest, Fingerprint, PairKey, PartKey, Setting};
use super::pack::{self, Beyond, Stored};
use super::store::{CacheSummary, Store};
use crate::check::assembly::{
    check_parts_from, glob_match, AssemblyInfo, Hook, Outcome, Pairing, Part, PartPairReduction, PartsHook,
    Selection, Source, MAX_CANDIDATE_PART_PAIRS,
};
use crate::check::containment::Containment;
use crate::check::overlap::Overlap;
use crate::check::query::{ClashResult, Closest, PairFinding, Settings, Timings, Verdict};
use crate::scene::mesh::Mesh;
use crate::shard::sha256::Sha256;
use crate::shard::stats;
use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// The most packs an index lists (the shards of a plan each add theirs to one index).
pub const MAX_INDEX: usize = 256;

/// The most triangle pairs (plus one per part pair) one pack holds: about 22 MB at most (a
/// triangle pair takes at most 71 bytes, a part pair's result at most 240 and its reason),
/// far below the entry limit ([`super::MAX_ENTRY_BYTES`]).
pub const PACK_FINDINGS: usize = 300_000;

const INDEX_TAG: &[u8] = b"meshclash.cache.index\0";
const PACK_TAG: &[u8] = b"meshclash.cache.pack\0";
const NUMBERING_TAG: &[u8] = b"meshclash.cache.numbering\0";

/// The fingerprint of the settings that change one part pair's answer: the resolved
/// tolerances (bits), the predicate mode, the detail level, the tree options (the tree sizes
/// stored beside the results depend on them), `--split-bodies` and `--penetration`. The
/// selection is not in it (it changes which pairs are checked, not a pair's answer); nor are
/// `--first-hit` and the distance error, under which pairs are not reused one by one. The
/// structs are taken apart field by field, so a new setting does not compile until it is
/// placed here.
pub fn pair_fingerprint(settings: &Settings, split_bodies: bool, penetration: bool) -> Fingerprint {
    let Settings { tolerances, bvh, mode, first_hit: _, distance_error: _, detail } = *settings;
    let crate::geom::predicates::Tolerances { touch, clearance } = tolerances;
    let crate::bvh::BuildOptions { strategy, leaf_size } = bvh;
    Fingerprint::of([
        ("unit", Setting::from("part-pair")),
        ("touch", touch.into()),
        ("clearance", clearance.into()),
        ("mode", mode.name().into()),
        ("detail", detail.name().into()),
        ("bvh", strategy.name().into()),
        ("leaf_size", leaf_size.into()),
        ("split_bodies", split_bodies.into()),
        ("penetration", penetration.into()),
    ])
}

/// Whether a check with `settings` and `sel` can be reused part pair by part pair: its parts
/// are selected (scene mode or a selection), and no stop rule (`--first-hit`) or distance
/// error allowance makes one pair's answer depend on the others. Otherwise the whole check is
/// the unit ([`WholeCheck`]).
fn reusable_by_pairs(settings: &Settings, sel: &Selection) -> bool {
    let exact_distance = settings.distance_error.rel == 0.0 && settings.distance_error.abs == 0.0;
    sel.by_parts() && !settings.first_hit && exact_distance
}

/// Whether an instanced scene's check with `settings` and `sel` is reused pair by pair over
/// its placed parts ([`CheckCache::check_placed`]): reusable by pairs, every part against
/// every other (`--select-b` can put one part on both sides). Then the scene need not be
/// expanded for the cache.
pub fn reuses_placed_pairs(settings: &Settings, sel: &Selection) -> bool {
    reusable_by_pairs(settings, sel) && sel.scene && sel.select_b.is_empty()
}

/// The cache of one check: per part pair when it can be, else the whole check.
#[derive(Debug)]
pub enum CheckCache {
    /// Reuse per part pair (parts mode).
    Pairs(Arc<PairReuse>),
    /// Reuse of the whole check (file mode, `--first-hit`, a distance error allowance).
    Whole(Arc<WholeCheck>),
}

impl CheckCache {
    /// The cache of a check under `settings` (tolerances resolved) and `sel`, over `store`.
    /// `active` false (the parry cross-check is in the way) checks everything and stores
    /// nothing. A hook already in `sel` (a shard's) is kept: its pairs are the candidates, and
    /// a stand-in outcome (a merge's) is not cached. `lineage` names the inputs (the index of
    /// earlier runs is found by it, never a result).
    pub fn new(
        store: Arc<Store>,
        settings: &Settings,
        sel: &Selection,
        split_bodies: bool,
        penetration: bool,
        active: bool,
        lineage: &str,
    ) -> CheckCache {
        let whole_fp = super::hook::check_fingerprint(settings, sel, split_bodies, penetration);
        let inner = sel.hook.clone();
        let whole = WholeCheck::new(store.clone(), whole_fp, active && inner.is_none());
        if !(active && reusable_by_pairs(settings, sel)) {
            return CheckCache::Whole(Arc::new(whole));
        }
        let fingerprint = pair_fingerprint(settings, split_bodies, penetration);
        let mut sha = Sha256::default();
        sha.update(INDEX_TAG);
        sha.update(&super::FORMAT.to_le_bytes());
        sha.update(fingerprint.as_bytes());
        let globs = |g: &[String]| g.iter().map(|s| format!("{}:{s}", s.len())).collect::<Vec<_>>().join(",");
        let lineage = format!(
            "inputs={lineage}\nscene={}\nselect_a={}\nselect_b={}\nexclude={}",
            sel.scene,
            globs(&sel.select_a),
            globs(&sel.select_b),
            globs(&sel.exclude)
        );
        sha.update(&(lineage.len() as u64).to_le_bytes());
        sha.update(lineage.as_bytes());
        CheckCache::Pairs(Arc::new(PairReuse {
            store,
            settings: *settings,
            sel: Selection { hook: None, ..sel.clone() },
            fingerprint,
            index: PairKey::from_digest(sha.digest()),
            whole,
            inner,
            delegated: AtomicBool::new(false),
            reused: AtomicU64::new(0),
            checked: AtomicU64::new(0),
            pending: Mutex::new(None),
        }))
    }

    /// `sel` with this cache's hook in it (when it caches; else `sel` as it is).
    pub fn selection(&self, sel: &Selection) -> Selection {
        match self {
            CheckCache::Whole(w) => w.selection(sel),
            CheckCache::Pairs(p) => Selection { hook: Some(Hook(p.clone())), ..sel.clone() },
        }
    }

    /// The finding id ([`crate::check::finding_id::finding_hash`]) of each of `o`'s triangle
    /// pairs, in their order: the stored ids of the reused part pairs, `compute` (the hashes of
    /// the pairs it is given, in their order) for the others; the checked pairs' ids are stored
    /// with their results. The same ids as `compute(&o.result.pairs)`: an id is a function of
    /// the two parts' names and exact world triangles, which the pair's key holds.
    pub fn finding_ids<F>(&self, o: &Outcome, compute: F) -> Vec<u64>
    where
        F: Fn(&[PairFinding]) -> Vec<u64>,
    {
        match self {
            CheckCache::Whole(_) => compute(&o.result.pairs),
            CheckCache::Pairs(p) => p.finding_ids(o, compute),
        }
    }

    /// The report's `cache` block for the check's outcome `o`.
    pub fn summary(&self, o: &Outcome) -> CacheSummary {
        match self {
            CheckCache::Whole(w) => w.summary(o),
            CheckCache::Pairs(p) => p.summary(o),
        }
    }

    /// The overlap boxes of the check's outcome `o` (one per part pair, as
    /// [`crate::pipeline::Outcome::overlaps`] holds them). `compute` computes the boxes of the
    /// part pairs (by index in `o.part_pairs`) its argument accepts, None for the others; the
    /// boxes of reused pairs come from the cache. Then what this run checked is stored, with
    /// the boxes of its clashing pairs.
    pub fn overlaps<F>(&self, o: &Outcome, compute: F) -> Vec<Option<Overlap>>
    where
        F: FnOnce(&(dyn Fn(usize) -> bool + Sync)) -> Vec<Option<Overlap>>,
    {
        match self {
            CheckCache::Whole(_) => compute(&|_| true),
            CheckCache::Pairs(p) => p.overlaps(o, compute),
        }
    }

    /// The check of the parts `parts` of an instanced scene (scene mode, every part against
    /// every other), reused pair by pair: the outcome a check of the scene gives, or None when
    /// this cache does not reuse by pairs here (then the check runs, and the `cache` block says
    /// every candidate part pair was checked). The keys are those of the expanded scene's parts
    /// ([`PartKey::of_placed_parts`]): an instanced run and an expanded one share their results.
    pub fn check_placed(&self, scene: &crate::load::InstancedScene, parts: &[Part]) -> Option<Outcome> {
        let CheckCache::Pairs(p) = self else { return None };
        let pairwise = p.inner.is_none() && reuses_placed_pairs(&p.settings, &p.sel);
        let o = if pairwise { p.by_pairs([Source::Placed(scene); 2], parts) } else { None };
        if o.is_none() {
            p.delegated.store(true, Ordering::Relaxed);
        }
        o
    }

    /// The warnings collected (entries ignored, results not stored).
    pub fn take_warnings(&self) -> Vec<String> {
        match self {
            CheckCache::Whole(w) => w.take_warnings(),
            CheckCache::Pairs(p) => p.whole.take_warnings(),
        }
    }
}

/// Per-part-pair reuse: a [`PartsHook`] that stands in for the check an outcome made of
/// stored pair results and the results of checking the rest.
#[derive(Debug)]
pub struct PairReuse {
    store: Arc<Store>,
    settings: Settings,
    sel: Selection,
    fingerprint: Fingerprint,
    /// The key of this lineage's index.
    index: PairKey,
    /// The whole-check cache, for a run that cannot be reused pair by pair.
    whole: WholeCheck,
    /// The hook the run already had (a shard's, a plan's or a merge's).
    inner: Option<Hook>,
    delegated: AtomicBool,
    reused: AtomicU64,
    checked: AtomicU64,
    /// What the check left for [`PairReuse::overlaps`] to complete and store.
    pending: Mutex<Option<Pending>>,
}

/// A run's new results, kept until their overlap boxes are known ([`CheckCache::overlaps`]),
/// and the boxes of the reused pairs.
#[derive(Debug, Default)]
struct Pending {
    /// (pair key, answer) of the pairs this run checked.
    fresh: Vec<(Digest, Stored)>,
    /// Part pair (a, b) -> its place in `fresh` (the last, when checked twice).
    fresh_at: HashMap<(usize, usize), usize>,
    /// Tree sizes measured (part key, bytes).
    trees: Vec<(Digest, u64)>,
    /// The older packs a pair was reused from.
    used: Vec<Digest>,
    /// Part pair (a, b) -> the stored box of each reused clashing pair.
    boxes: HashMap<(usize, usize), Option<Overlap>>,
    /// The stored finding ids of the reused pairs' triangle pairs: (triangle in A, in B, id),
    /// in the input meshes' numbering.
    known: Vec<(u32, u32, u64)>,
    /// The part pair each run of `known` came from: (its pair key, the run's start and end).
    known_from: Vec<(Digest, usize, usize)>,
}

/// A candidate pair's stored answer, as the reuse found it.
enum Reused {
    /// Nothing stored under its key.
    Missing,
    /// Stored but not for these parts (the reason): checked again.
    Refused(String),
    /// Reused: from pack `pack`, its result in the file's triangle numbers, its bound, its
    /// overlap box (for a clash) and its finding ids (when stored and wanted).
    Fits {
        pack: usize,
        r: Box<ClashResult>,
        bound: Option<Beyond>,
        overlap: Option<Option<Overlap>>,
        ids: Option<Vec<u64>>,
    },
}

/// What a run read from the cache.
#[derive(Default)]
struct Loaded {
    /// Pack keys, in index order, and whether a pair of this run came from each.
    packs: Vec<(Digest, bool)>,
    /// Pair key -> (pack, stored answer).
    pairs: HashMap<Digest, (usize, Stored)>,
    /// Part key -> tree size.
    trees: HashMap<Digest, u64>,
}

fn select(parts: &[Part], input: u8, globs: &[String], exclude: &[String]) -> Vec<usize> {
    (0..parts.len())
        .filter(|&i| parts[i].input == input)
        .filter(|&i| globs.is_empty() || globs.iter().any(|g| glob_match(g, &parts[i].name)))
        .filter(|&i| !exclude.iter().any(|g| glob_match(g, &parts[i].name)))
        .collect()
}

/// `r` (triangles numbered in the input meshes) with its triangles numbered in their parts;
/// `None` if a triangle is not in its part (never stored then).
fn to_local(r: &ClashResult, pa: &Part, pb: &Part) -> Option<ClashResult> {
    let local = |p: &Part, t: u32| p.triangles.binary_search(&t).ok().map(|i| i as u32);
    let mut out = r.clone();
    for p in &mut out.pairs {
        *p = PairFinding { a: local(pa, p.a)?, b: local(pb, p.b)?, ..*p };
    }
    if let Some(c) = &mut out.closest {
        c.a.0 = local(pa, c.a.0)?;
        c.b.0 = local(pb, c.b.0)?;
    }
    Some(out)
}

/// A stored result back in the input meshes' triangle numbers; an error names an index out
/// of its part.
fn to_global(r: &mut ClashResult, pa: &Part, pb: &Part) -> Result<(), String> {
    let map = |p: &Part, t: u32| {
        p.triangles.get(t as usize).copied().ok_or_else(|| {
            format!("triangle {t} out of range (part {} has {} triangles)", p.name, p.triangles.len())
        })
    };
    for p in &mut r.pairs {
        *p = PairFinding { a: map(pa, p.a)?, b: map(pb, p.b)?, ..*p };
    }
    if let Some(c) = &mut r.closest {
        c.a.0 = map(pa, c.a.0)?;
        c.b.0 = map(pb, c.b.0)?;
    }
    Ok(())
}

/// A closest-pair candidate's place in the order the scene's closest pair is chosen by:
/// distance, then triangle in A, then in B.
fn order(c: &Closest) -> (f64, u32, u32) {
    (c.distance, c.a.0, c.b.0)
}

/// The total order of [`order`] keys (distances are never NaN; `total_cmp` orders them as
/// `<` does, but for -0 before +0, which a distance never is).
trait KeyOrder {
    fn total_cmp_key(&self, o: &Self) -> std::cmp::Ordering;
}

impl KeyOrder for (f64, u32, u32) {
    fn total_cmp_key(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0).then(self.1.cmp(&o.1)).then(self.2.cmp(&o.2))
    }
}

/// The digest of how the parts number their triangles in the input meshes (each part's input,
/// triangle count and triangle numbers, in part order): two runs with the same digest number
/// every part's triangles alike.
fn numbering_digest(parts: &[Part]) -> Digest {
    let mut sha = Sha256::default();
    sha.update(NUMBERING_TAG);
    sha.update(&(parts.len() as u64).to_le_bytes());
    let mut buf: Vec<u8> = Vec::new();
    for p in parts {
        buf.clear();
        buf.push(p.input);
        buf.extend((p.triangles.len() as u64).to_le_bytes());
        buf.extend(p.triangles.iter().flat_map(|t| t.to_le_bytes()));
        sha.update(&buf);
    }
    sha.digest()
}

fn listed(r: &ClashResult) -> bool {
    r.verdict != Verdict::Clear || r.containment != Containment::None
}

/// The overlap box a stored result carries, checked against its two parts: `Ok(None)` for a
/// pair that is not a clash (no box is reported), `Ok(Some(b))` the stored box `b` of a
/// clashing pair (`b` None: known to have none). A clashing pair without a known box, or whose
/// box does not lie within both parts' boxes (where A ∩ B lies, and its bounds correctly
/// rounded too), is an error: the pair is not reused.
fn stored_box(
    verdict: Verdict,
    overlap: Option<Option<Overlap>>,
    pa: &Part,
    pb: &Part,
) -> Result<Option<Option<Overlap>>, String> {
    if verdict != Verdict::Clash {
        return Ok(None);
    }
    match overlap {
        None => Err("a clash stored without its overlap box".into()),
        Some(None) => Ok(Some(None)),
        Some(Some(o)) => {
            let within = |b: &crate::geom::Aabb| b.min.cmple(o.min).all() && o.max.cmple(b.max).all();
            if within(&pa.bounds) && within(&pb.bounds) {
                Ok(Some(Some(o)))
            } else {
                Err(format!(
                    "overlap box {} to {} outside the parts {} and {}",
                    o.min, o.max, pa.name, pb.name
                ))
            }
        }
    }
}

impl PairReuse {
    fn summary(&self, o: &Outcome) -> CacheSummary {
        if self.delegated.load(Ordering::Relaxed) {
            return self.whole.summary(o);
        }
        CacheSummary {
            part_pairs_reused: self.reused.load(Ordering::Relaxed),
            part_pairs_checked: self.checked.load(Ordering::Relaxed),
            dir: self.store.dir().to_string_lossy().into_owned(),
        }
    }

    fn finding_ids<F>(&self, o: &Outcome, compute: F) -> Vec<u64>
    where
        F: Fn(&[PairFinding]) -> Vec<u64>,
    {
        use rayon::prelude::*;
        let pairs = &o.result.pairs;
        let mut guard = self.pending.lock().unwrap_or_else(|p| p.into_inner());
        let Some(pending) = guard.as_mut() else {
            // The check was not by pairs (delegated, or stood in for by a merge).
            return compute(pairs);
        };
        let mut known = std::mem::take(&mut pending.known);
        let from = std::mem::take(&mut pending.known_from);
        if !from.is_empty() {
            // Each part pair's stored ids are checked against the first of them computed again
            // (the entry's checksum proved them as written; this proves them written for these
            // triangles): a list that fails is not used, its ids are computed.
            let probe = |&(a, b, _): &(u32, u32, u64)| PairFinding {
                a,
                b,
                kind: crate::check::query::PairKind::Crossing,
                contact: None,
                distance: 0.0,
                segment: None,
            };
            let firsts: Vec<PairFinding> = from.iter().map(|&(_, s, _)| probe(&known[s])).collect();
            let mut keep = vec![true; known.len()];
            for ((key, s, e), h) in from.iter().zip(compute(&firsts)) {
                if known[*s].2 != h {
                    self.store.warn(format!(
                        "cache: ignored stored finding ids of {}: they are not these triangles'",
                        super::key::to_hex(key)
                    ));
                    keep[*s..*e].iter_mut().for_each(|x| *x = false);
                }
            }
            if keep.contains(&false) {
                let mut i = 0;
                known.retain(|_| {
                    i += 1;
                    keep[i - 1]
                });
            }
        }
        let ids = if known.is_empty() {
            compute(pairs)
        } else {
            // Both lists sorted by (a, b) (the check's pairs are): one merge.
            known.par_sort_unstable_by_key(|&(a, b, _)| (a, b));
            let mut ids = vec![0u64; pairs.len()];
            let mut missing_at = Vec::new();
            let mut k = 0;
            for (i, p) in pairs.iter().enumerate() {
                while k < known.len() && (known[k].0, known[k].1) < (p.a, p.b) {
                    k += 1;
                }
                match known.get(k) {
                    Some(&(a, b, id)) if (a, b) == (p.a, p.b) => ids[i] = id,
                    _ => missing_at.push(i),
                }
            }
            if !missing_at.is_empty() {
                let missing: Vec<PairFinding> = missing_at.iter().map(|&i| pairs[i]).collect();
                for (&i, id) in missing_at.iter().zip(compute(&missing)) {
                    ids[i] = id;
                }
            }
            ids
        };
        // The checked pairs' ids, stored with their results (in their triangle pairs' order).
        let sorted = pairs.windows(2).all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b));
        if sorted && ids.len() == pairs.len() {
            let parts = &o.parts;
            let at: Vec<(usize, usize, usize)> =
                pending.fresh_at.iter().map(|(&(a, b), &i)| (i, a, b)).collect();
            let found: Vec<(usize, Option<Vec<u64>>)> = at
                .par_iter()
                .map(|&(i, pa, pb)| {
                    let (ta, tb) = (&parts[pa].triangles, &parts[pb].triangles);
                    let local = &pending.fresh[i].1.result.pairs;
                    // A part pair's triangle pairs come in order, near one another in the
                    // merged list: each is searched from the last one found, by galloping.
                    let mut from = 0usize;
                    let got: Option<Vec<u64>> = local
                        .iter()
                        .map(|p| {
                            let key = (*ta.get(p.a as usize)?, *tb.get(p.b as usize)?);
                            let at = |k: usize| (pairs[k].a, pairs[k].b);
                            if from >= pairs.len() || at(from) > key {
                                from = 0;
                            }
                            let (mut lo, mut step) = (from, 1usize);
                            while lo + step < pairs.len() && at(lo + step) <= key {
                                lo += step;
                                step *= 2;
                            }
                            let hi = (lo + step + 1).min(pairs.len());
                            let j = lo + pairs[lo..hi].binary_search_by(|q| (q.a, q.b).cmp(&key)).ok()?;
                            from = j;
                            Some(ids[j])
                        })
                        .collect();
                    (i, got)
                })
                .collect();
            for (i, got) in found {
                pending.fresh[i].1.ids = got;
            }
        }
        ids
    }

    fn overlaps<F>(&self, o: &Outcome, compute: F) -> Vec<Option<Overlap>>
    where
        F: FnOnce(&(dyn Fn(usize) -> bool + Sync)) -> Vec<Option<Overlap>>,
    {
        let pending = self.pending.lock().unwrap_or_else(|p| p.into_inner()).take();
        let Some(mut pending) = pending else {
            // The check was not by pairs (delegated, or stood in for by a merge).
            return compute(&|_| true);
        };
        let stored: Vec<Option<Option<Overlap>>> =
            o.part_pairs.iter().map(|pp| pending.boxes.get(&(pp.a, pp.b)).copied()).collect();
        let mut out = compute(&|k| stored.get(k).is_none_or(Option::is_none));
        for (k, pp) in o.part_pairs.iter().enumerate() {
            if let Some(b) = stored[k] {
                out[k] = b;
            } else if pp.verdict == Verdict::Clash {
                if let Some(&i) = pending.fresh_at.get(&(pp.a, pp.b)) {
                    pending.fresh[i].1.overlap = Some(out[k]);
                }
            }
        }
        if !pending.fresh.is_empty() || !pending.trees.is_empty() {
            self.save(pending.fresh, pending.trees, pending.used);
        }
        out
    }

    fn load(&self) -> Loaded {
        let mut l = Loaded::default();
        let Some(index) = self.store.get_with(&self.index, pack::decode_index) else {
            return l;
        };
        for d in index.into_iter().take(MAX_INDEX) {
            let Some(p) = self.store.get_with(&PairKey::from_digest(d), pack::decode_pack) else { continue };
            let at = l.packs.len();
            l.packs.push((d, false));
            l.pairs.reserve(p.pairs.len());
            for (k, stored) in p.pairs {
                l.pairs.entry(k).or_insert((at, stored));
            }
            for (k, b) in p.trees {
                l.trees.entry(k).or_insert(b);
            }
        }
        l
    }

    /// Store `pairs` (pair key, answer in part triangle numbers) and `trees` as a new pack,
    /// and point the index at it and at the `kept` older packs.
    fn save(&self, mut pairs: Vec<(Digest, Stored)>, mut trees: Vec<(Digest, u64)>, kept: Vec<Digest>) {
        pairs.sort_by_key(|x| x.0);
        pairs.dedup_by(|x, y| x.0 == y.0);
        trees.sort_unstable();
        trees.dedup_by(|x, y| x.0 == y.0);
        // Packs of at most PACK_FINDINGS triangle pairs each (an entry stays far below the
        // entry limit); the tree sizes go with the first.
        let mut chunks: Vec<Vec<(Digest, Stored)>> = vec![Vec::new()];
        let mut size = 0usize;
        for p in pairs {
            let n = p.1.result.pairs.len() + 1;
            if size + n > PACK_FINDINGS && !chunks.last().is_some_and(Vec::is_empty) {
                chunks.push(Vec::new());
                size = 0;
            }
            size += n;
            chunks.last_mut().expect("one chunk").push(p);
        }
        let mut trees = Some(trees);
        let mut written: Vec<Digest> = Vec::new();
        for chunk in chunks {
            let trees = trees.take().unwrap_or_default();
            let mut sha = Sha256::default();
            sha.update(PACK_TAG);
            sha.update(&super::FORMAT.to_le_bytes());
            sha.update(self.fingerprint.as_bytes());
            for (k, _) in &chunk {
                sha.update(k);
            }
            sha.update(&[0]);
            for (k, _) in &trees {
                sha.update(k);
            }
            let key = PairKey::from_digest(sha.digest());
            self.store.put_bytes(&key, &pack::encode_pack(&chunk, &trees));
            written.push(*key.as_bytes());
        }
        let mut packs: Vec<Digest> = written;
        if self.inner.is_some() {
            // A shard: the other shards' packs stay listed (read again now, as they may have
            // written meanwhile).
            let now = self.store.get_with(&self.index, pack::decode_index).unwrap_or_default();
            packs.extend(kept.into_iter().chain(now));
        } else {
            packs.extend(kept);
        }
        let mut seen = HashSet::new();
        packs.retain(|k| seen.insert(*k));
        packs.truncate(MAX_INDEX);
        self.store.put_bytes(&self.index, &pack::encode_index(&packs));
    }

    /// The check, by pairs: see the module documentation. `None` when this run cannot be
    /// reused pair by pair (then the whole-check cache takes it).
    fn by_pairs(&self, sources: [Source<'_>; 2], parts: &[Part]) -> Option<Outcome> {
        let sel = &self.sel;
        let settings = &self.settings;
        let b_input = if sel.scene { 0 } else { 1 };
        let sa = select(parts, 0, &sel.select_a, &sel.exclude);
        let sb = select(parts, b_input, &sel.select_b, &sel.exclude);
        let pairing = if sel.scene && sel.select_b.is_empty() { Pairing::AllVsAll } else { Pairing::Cross };
        // The broad phase, as the check runs it: record every candidate, check none.
        let recorded = Mutex::new(Vec::new());
        let over = AtomicBool::new(false);
        let record = |a: usize, b: usize| {
            let mut r = recorded.lock().unwrap_or_else(|p| p.into_inner());
            if r.len() < MAX_CANDIDATE_PART_PAIRS {
                r.push((a, b));
            } else {
                over.store(true, Ordering::Relaxed);
            }
            false
        };
        check_parts_from(sources, parts.to_vec(), &sa, &sb, pairing, settings, &record);
        if over.load(Ordering::Relaxed) {
            return None; // the check refuses it
        }
        let mut candidates: Vec<(usize, usize)> = recorded.into_inner().unwrap_or_else(|p| p.into_inner());
        if let Some(h) = &self.inner {
            // A shard's pairs (asked in the check's order, as the check asks).
            candidates.retain(|&(a, b)| h.0.keep(a, b));
        }
        let mut seen = HashSet::new();
        if candidates.iter().any(|&(a, b)| a == b || !seen.insert((a.min(b), a.max(b)))) {
            return None;
        }
        let mut needed: Vec<usize> = candidates.iter().flat_map(|&(a, b)| [a, b]).collect();
        needed.sort_unstable();
        needed.dedup();
        let needed_parts: Vec<&Part> = needed.iter().map(|&i| &parts[i]).collect();
        let mut part_key: Vec<Option<PartKey>> = vec![None; parts.len()];
        let keys = match sources {
            [Source::Loaded(a), Source::Loaded(b)] => PartKey::of_part_layouts([a, b], &needed_parts),
            // Scene mode: one input, its parts placed one at a time.
            [Source::Placed(scene), _] | [_, Source::Placed(scene)] => {
                PartKey::of_placed_parts(scene, &needed_parts)
            }
        };
        for (&i, k) in needed.iter().zip(keys) {
            part_key[i] = Some(k);
        }
        let key_of = |i: usize| part_key[i].expect("needed part has a key");
        let pair_keys: Vec<PairKey> = candidates
            .iter()
            .map(|&(a, b)| PairKey::new(&key_of(a), &key_of(b), &self.fingerprint))
            .collect();
        let mut loaded = self.load();
        // Reuse what is stored.
        let mut beyond: Vec<Option<Beyond>> = vec![None; candidates.len()];
        let mut boxes: HashMap<(usize, usize), Option<Overlap>> = HashMap::new();
        let mut known: Vec<(u32, u32, u64)> = Vec::new();
        let mut known_from: Vec<(Digest, usize, usize)> = Vec::new();
        let lists = settings.detail != crate::check::query::Detail::Parts;
        // Each stored answer is taken out of what was read (copied only for a key that two
        // candidates share), then mapped back to the file's triangle numbers in parallel.
        let mut uses: HashMap<Digest, u32> = HashMap::with_capacity(pair_keys.len());
        for k in &pair_keys {
            *uses.entry(*k.as_bytes()).or_insert(0) += 1;
        }
        let taken: Vec<Option<(usize, Stored)>> = pair_keys
            .iter()
            .map(|k| match uses[k.as_bytes()] {
                1 => loaded.pairs.remove(k.as_bytes()),
                _ => loaded.pairs.get(k.as_bytes()).cloned(),
            })
            .collect();
        let reuse: Vec<Reused> = {
            use rayon::prelude::*;
            candidates
                .par_iter()
                .zip(taken.into_par_iter())
                .map(|(&(a, b), found)| {
                    let Some((pack, stored)) = found else { return Reused::Missing };
                    let Stored { result: mut r, beyond: bound, overlap, ids } = stored;
                    let verdict = r.verdict;
                    let fits = to_global(&mut r, &parts[a], &parts[b])
                        .and_then(|()| stored_box(verdict, overlap, &parts[a], &parts[b]));
                    match fits {
                        Ok(overlap) => {
                            let ids = ids.filter(|i| lists && !i.is_empty() && i.len() == r.pairs.len());
                            Reused::Fits { pack, r: Box::new(r), bound, overlap, ids }
                        }
                        Err(e) => Reused::Refused(e),
                    }
                })
                .collect()
        };
        let mut results: Vec<Option<ClashResult>> = Vec::with_capacity(candidates.len());
        for (((&(a, b), k), bound), reused) in candidates.iter().zip(&pair_keys).zip(&mut beyond).zip(reuse) {
            results.push(match reused {
                Reused::Missing => None,
                Reused::Refused(e) => {
                    self.store.warn(format!("cache: ignored stored result of {}: {e}", k.hex()));
                    None
                }
                Reused::Fits { pack, r, bound: stored_bound, overlap, ids } => {
                    loaded.packs[pack].1 = true;
                    *bound = stored_bound;
                    if let Some(o) = overlap {
                        boxes.insert((a, b), o);
                    }
                    if let Some(ids) = ids {
                        let start = known.len();
                        known.extend(r.pairs.iter().zip(ids).map(|(p, id)| (p.a, p.b, id)));
                        known_from.push((*k.as_bytes(), start, known.len()));
                    }
                    Some(*r)
                }
            });
        }
        let numbering = std::cell::OnceCell::new();
        let numbering = || *numbering.get_or_init(|| numbering_digest(parts));
        let mut fresh: Vec<(Digest, Stored)> = Vec::new();
        let mut fresh_at: HashMap<(usize, usize), usize> = HashMap::new();
        let mut timings = Timings::default();
        let mut check = |results: &mut Vec<Option<ClashResult>>, which: &HashSet<(usize, usize)>| {
            if which.is_empty() {
                return;
            }
            let keep = |a: usize, b: usize| which.contains(&(a, b));
            let ar = check_parts_from(sources, parts.to_vec(), &sa, &sb, pairing, settings, &keep);
            timings.build_ms += ar.build_ms;
            timings.query_ms += ar.query_ms;
            // The least candidate of the pairs searched together: every clear pair's closest
            // pair is the one it found, or comes after this one (see `pack::Stored::beyond`).
            let least = ar
                .part_pairs
                .iter()
                .filter_map(|pp| pp.result.closest)
                .min_by(|x, y| order(x).total_cmp_key(&order(y)));
            let bound =
                least.map(|c| Beyond { numbering: numbering(), a: c.a.0, b: c.b.0, distance: c.distance });
            let at: HashMap<(usize, usize), usize> =
                candidates.iter().enumerate().map(|(i, &p)| (p, i)).collect();
            for pp in ar.part_pairs {
                let i = at[&(pp.a, pp.b)];
                let clear = !listed(&pp.result);
                let mut keep = pp.result.clone();
                if clear && keep.closest != least {
                    // A clear pair's search may have stopped at a pair that is not its closest
                    // (the shared bound cut the rest): only the least candidate is known to be
                    // its pair's closest. The bound says the rest.
                    keep.closest = None;
                }
                if let Some(l) = to_local(&keep, &parts[pp.a], &parts[pp.b]) {
                    // The overlap box is added when it is known (`PairReuse::overlaps`).
                    let stored = Stored {
                        result: l,
                        beyond: if clear { bound } else { None },
                        overlap: None,
                        ids: None,
                    };
                    fresh_at.insert((pp.a, pp.b), fresh.len());
                    fresh.push((*pair_keys[i].as_bytes(), stored));
                }
                results[i] = Some(pp.result);
            }
        };
        let missing: HashSet<(usize, usize)> =
            candidates.iter().zip(&results).filter(|(_, r)| r.is_none()).map(|(&p, _)| p).collect();
        let mut checked = missing.len() as u64;
        check(&mut results, &missing);
        // When nothing touches or crosses, a clear pair may be the scene's closest. Every
        // result's closest pair is a real candidate; the least of them, `best`, bounds the
        // scene's. A reused clear pair whose stored bound is not before `best` cannot hold a
        // closer pair than `best` (or it holds its stored closest pair, a candidate already);
        // the other reused clear pairs are searched again, together (see the module docs).
        let touching =
            results.iter().flatten().any(|r| listed(r) && r.closest.is_some_and(|c| c.distance == 0.0));
        if !touching {
            let best = results
                .iter()
                .flatten()
                .filter_map(|r| r.closest)
                .min_by(|x, y| order(x).total_cmp_key(&order(y)));
            let settled = |bound: &Option<Beyond>| match (bound, best) {
                (Some(m), Some(b)) => {
                    if m.numbering == numbering() {
                        // The same numbering: the order against `m` holds as stored.
                        (m.distance, m.a, m.b).total_cmp_key(&order(&b)).is_ge()
                    } else {
                        m.distance > b.distance
                    }
                }
                _ => false,
            };
            let clear: HashSet<(usize, usize)> = candidates
                .iter()
                .zip(&results)
                .zip(&beyond)
                .filter(|((p, r), bound)| {
                    !missing.contains(p) && r.as_ref().is_some_and(|r| !listed(r)) && !settled(bound)
                })
                .map(|((&p, _), _)| p)
                .collect();
            checked += clear.len() as u64;
            check(&mut results, &clear);
        }
        let reused = candidates.len() as u64 - checked;
        // The reduction of the check over its part pairs, as the check itself reduces them.
        let mut reduction = PartPairReduction::new(settings.detail);
        if lists {
            reduction.merged.reserve_exact(results.iter().flatten().map(|r| r.pairs.len()).sum());
        }
        for (&(a, b), r) in candidates.iter().zip(results) {
            reduction.add(a, b, r.expect("every candidate reused or checked"));
        }
        // Tree-sharing figures: the tree sizes they need, stored by part key or measured.
        let mut new_trees: Vec<(Digest, u64)> = Vec::new();
        let (sah_builds, sharing) = stats::sharing_lazy_from(sources, parts, &needed, |wanted, _| {
            let mut sizes = HashMap::new();
            let mut build = Vec::new();
            for &p in wanted {
                match loaded.trees.get(key_of(p).as_bytes()) {
                    Some(&b) => {
                        sizes.insert(p, b);
                    }
                    None => build.push(p),
                }
            }
            for (p, b) in stats::owned_tree_bytes_from(sources, parts, &build, settings.bvh) {
                sizes.insert(p, b);
                new_trees.push((*key_of(p).as_bytes(), b));
            }
            Ok(sizes)
        })
        .ok()?;
        let used: Vec<Digest> = loaded.packs.iter().filter(|(_, u)| *u).map(|(k, _)| *k).collect();
        // Stored once the overlap boxes of the clashing pairs are known.
        let pending = Pending { fresh, fresh_at, trees: new_trees, used, boxes, known, known_from };
        *self.pending.lock().unwrap_or_else(|p| p.into_inner()) = Some(pending);
        self.reused.store(reused, Ordering::Relaxed);
        self.checked.store(checked, Ordering::Relaxed);
        let info = AssemblyInfo {
            mode: "parts",
            selected: [sa.len(), sb.len()],
            candidate_part_pairs: candidates.len(),
            built_parts: Some(needed.len()),
            sah_builds: Some(sah_builds),
            sharing: Some(sharing),
        };
        let (result, part_pairs) = reduction.finish(timings);
        Some(Outcome { result, parts: parts.to_vec(), part_pairs, info })
    }
}

impl PartsHook for PairReuse {
    fn keep(&self, a: usize, b: usize) -> bool {
        self.inner.as_ref().is_none_or(|h| h.0.keep(a, b))
    }

    fn stand_in(
        &self,
        meshes: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Result<Outcome, String>> {
        if let Some(o) = self.inner.as_ref().and_then(|h| h.0.stand_in(meshes, parts, selected)) {
            // A merge's outcome (or a shard's refusal): not cached.
            self.delegated.store(true, Ordering::Relaxed);
            return Some(o);
        }
        match self.by_pairs([Source::Loaded(meshes[0]), Source::Loaded(meshes[1])], parts) {
            Some(o) => Some(Ok(o)),
            None => {
                self.delegated.store(true, Ordering::Relaxed);
                match &self.inner {
                    // The check runs, through `keep`.
                    Some(_) => None,
                    None => self.whole.stand_in(meshes, parts, selected),
                }
            }
        }
    }

    fn seen(&self, meshes: [&Mesh; 2], o: &Outcome) {
        match &self.inner {
            Some(h) => h.0.seen(meshes, o),
            None if self.delegated.load(Ordering::Relaxed) => self.whole.seen(meshes, o),
            None => {}
        }
    }
}
