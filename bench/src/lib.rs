//! `meshclash-bench` (was `meshclash bench`): meshclash and parry3d (f64 and f32) on the same
//! inputs in one process,
//! phase by phase, with the answers compared against meshclash's exact ones; and, with
//! `--trade`, every speed/accuracy option a user can pick, timed and compared with the exact
//! default.
//!
//! [`run`] returns plain data ([`BenchReport`], serialisable as JSON); [`render`] formats it as
//! Markdown tables; [`plot_svg`] draws the trade as an SVG scatter plot. The binary prints.
//!
//! What is timed (wall clock, best of a few runs for inputs up to 300k triangles, one run above):
//!
//! * meshclash **build**: both [`Bvh`]s (in parallel, as [`query::check`] does). **pairs**: the
//!   dual walk ([`traverse::collect_pairs`]) with exact [`tri_tri::classify`] of every candidate.
//!   **distance**: what a distance query needs: for inputs that touch, a walk that stops at the
//!   first contact (distance 0); otherwise the branch-and-bound closest pair. **check**: the
//!   whole [`query::check`] (build, pairs, closest pair, topology and containment).
//! * parry: [`cross_check::parry_f64`] / [`parry32::parry_f32`]: `TriMesh::new` (build),
//!   `Bvh::leaf_pairs` + per-pair `intersection_test` (pairs), `query::distance` (distance).
//!
//! Memory: tree bytes are meshclash's [`meshclash::bvh::Stats::bytes`] (nodes + triangle indices)
//! and parry's `Bvh::total_memory_size`; "peak RSS Δ" is `VmHWM` (after resetting it through
//! `/proc/self/clear_refs`) minus `VmRSS` before the run, i.e. everything the run allocated at
//! its peak including transient buffers (and, for parry, its copy of the vertex buffers).

pub mod cases;

/// A problem of the harness's own (bad arguments, missing files, a failed check), as a sentence:
/// exit 2 with `usage: ` and the sentence.
pub(crate) fn usage(msg: impl Into<String>) -> Error {
    Error::usage(UsageProblem::Other(msg.into()))
}

pub mod layout;
pub mod parry32;
pub mod self_case;
pub mod svg;

use meshclash::bvh::traverse;
use meshclash::bvh::{self, BuildOptions, Bvh, Strategy};
use meshclash::check::cross_check::{self, ParryResult};
use meshclash::check::query::{self, ClashResult, DistanceError, Mode, Settings};
use meshclash::error::{Error, Result, UsageProblem};
use meshclash::geom::predicates;
use meshclash::geom::Aabb;
use meshclash::narrow::tri_tri;
use meshclash::scene::mesh::Mesh;
pub use meshclash::testing::{gen, sweep};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// `meshclash-bench` flags.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// Generated input sizes, triangles per mesh (`k` = 1e3, `M` = 1e6), comma-separated.
    #[arg(long, value_name = "N,N,..", default_value = "10k,100k,1M")]
    pub sizes: String,
    /// Also real files: each against a rotated, moved copy of itself and against a copy moved
    /// clear of it.
    #[arg(long = "mesh", value_name = "FILE", num_args = 1..)]
    pub meshes: Vec<PathBuf>,
    /// Worker threads for the main measurements (0 = one per core). The scaling table always
    /// runs 1 and 2 threads.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// Also tabulate every speed/accuracy option (fast mode, first hit, approximate distance,
    /// BVH strategy and leaf size) against the exact default.
    #[arg(long)]
    pub trade: bool,
    /// Write an SVG scatter plot of time against error per option (implies --trade).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Print the results as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Validated options.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchOptions {
    /// Generated sizes (triangles per mesh).
    pub sizes: Vec<usize>,
    /// Real mesh files.
    pub meshes: Vec<PathBuf>,
    /// Threads for the main measurements (0 = default).
    pub threads: usize,
    /// Run the trade tables.
    pub trade: bool,
}

/// Parse `10k,100k,1M` (also plain numbers and `2.5k`).
pub fn parse_sizes(s: &str) -> Result<Vec<usize>> {
    s.split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(|t| {
            let (num, mul) = match t.chars().last() {
                Some('k' | 'K') => (&t[..t.len() - 1], 1e3),
                Some('m' | 'M') => (&t[..t.len() - 1], 1e6),
                _ => (t, 1.0),
            };
            match num.parse::<f64>() {
                Ok(v) if v.is_finite() && v * mul >= 8.0 && v * mul <= 2e7 => Ok((v * mul).round() as usize),
                _ => Err(Error::bad_flag(
                    "sizes",
                    UsageProblem::Other(format!("--sizes: '{t}' is not a size from 8 to 20M (e.g. 10k, 1M)")),
                )),
            }
        })
        .collect()
}

/// What the binary runs for `meshclash-bench`: measure, write the plot, and return the text
/// (tables or JSON) to print on stdout.
pub fn run_command(args: &BenchArgs) -> Result<String> {
    let opts = BenchOptions {
        sizes: parse_sizes(&args.sizes)?,
        meshes: args.meshes.clone(),
        threads: args.threads,
        trade: args.trade || args.plot.is_some(),
    };
    let rep = run(&opts)?;
    if let Some(path) = &args.plot {
        meshclash::output::write::write_file(path, svg::plot_svg(&rep).as_bytes())?;
    }
    let bad: Vec<String> = rep
        .trade
        .iter()
        .flat_map(|t| t.rows.iter().map(move |r| (t, r)))
        .filter(|(_, r)| r.within_bound == Some(false))
        .map(|(t, r)| format!("{} {}", t.input, r.mode))
        .collect();
    if !bad.is_empty() {
        return Err(usage(format!("approximate distance outside its guaranteed bound: {}", bad.join(", "))));
    }
    Ok(if args.json {
        let mut s = serde_json::to_string_pretty(&rep).expect("bench report serialises");
        s.push('\n');
        s
    } else {
        render(&rep)
    })
}

/// Everything one `meshclash-bench` run measured.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Cores, threads and load.
    pub machine: Machine,
    /// One entry per input pair.
    pub inputs: Vec<InputResult>,
    /// OBJ parsing speed.
    pub obj_parse: Vec<ParseResult>,
    /// Trade tables (with `--trade`).
    pub trade: Vec<TradeInput>,
}

/// The machine during the run.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// Cores available (`std::thread::available_parallelism`).
    pub cores: usize,
    /// Threads of the main measurements.
    pub threads: usize,
    /// 1-minute load average at the start and at the end (`/proc/loadavg`).
    pub load: [Option<f64>; 2],
    /// Wall time of the whole bench, s.
    pub total_s: f64,
}

/// One tool's numbers on one input.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ToolRun {
    /// Build time, ms.
    pub build_ms: f64,
    /// Pair search time, ms.
    pub pairs_ms: f64,
    /// Distance time, ms (`None`: skipped or failed).
    pub distance_ms: Option<f64>,
    /// Pairs reported (crossing or touching).
    pub pairs: usize,
    /// Distance found.
    pub distance: Option<f64>,
    /// Pairs reported that meshclash's exact answer does not have.
    pub false_pairs: usize,
    /// Exact pairs not reported.
    pub missed_pairs: usize,
    /// Bytes of the two trees.
    pub tree_bytes: usize,
    /// Peak RSS growth during the run, bytes (`None` if /proc is unavailable).
    pub peak_rss_delta: Option<u64>,
    /// Why the distance was skipped, or why the tool failed.
    pub note: Option<String>,
}

/// One input pair.
#[derive(Debug, Clone, Serialize)]
pub struct InputResult {
    /// Name.
    pub name: String,
    /// Triangles of A and B.
    pub triangles: [usize; 2],
    /// meshclash's exact verdict.
    pub verdict: String,
    /// Exact crossing / touching pair counts.
    pub crossing: u64,
    /// Exact touching pairs.
    pub touching: u64,
    /// meshclash phases.
    pub meshclash: ToolRun,
    /// The whole `check` (ms).
    pub check_ms: f64,
    /// parry3d-f64.
    pub parry_f64: ToolRun,
    /// parry3d (f32).
    pub parry_f32: ToolRun,
    /// Two trees built per second, millions of triangles.
    pub build_mtris_per_s: f64,
    /// SAH cost of A's tree (binned) and of a full-sweep build (None above the size cap).
    pub sah_binned: f64,
    /// Full-sweep SAH cost of A's tree.
    pub sah_full_sweep: Option<f64>,
    /// Candidate triangle pairs (boxes overlap) and the mean time of exact classification, ns.
    pub candidates: u64,
    /// Mean exact classification time per candidate, ns (single thread).
    pub tri_tri_ns: Option<f64>,
    /// The two node layouts.
    pub layouts: Layouts,
    /// 1 and 2 threads.
    pub scaling: Vec<ThreadRun>,
}

/// Stack versus stackless one-tree walks (each leaf of A against tree B).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Layouts {
    /// Overlapping leaf pairs' triangle-box candidates found (the same for all three walks).
    pub candidates: u64,
    /// Stack walk, ms.
    pub stack_ms: f64,
    /// Skip-pointer walk, ms.
    pub stackless_ms: f64,
    /// The dual walk of [`traverse::collect_pairs`] with the same leaf work, ms.
    pub dual_ms: f64,
    /// All three found the same candidates.
    pub agree: bool,
}

/// The phases at one thread count.
#[derive(Debug, Clone, Serialize)]
pub struct ThreadRun {
    /// Threads.
    pub threads: usize,
    /// Build, ms.
    pub build_ms: f64,
    /// Pairs, ms.
    pub pairs_ms: f64,
    /// Distance, ms.
    pub distance_ms: f64,
    /// Whole check, ms.
    pub check_ms: f64,
}

/// OBJ parsing speed.
#[derive(Debug, Clone, Serialize)]
pub struct ParseResult {
    /// What was parsed.
    pub name: String,
    /// Bytes.
    pub bytes: usize,
    /// Best time, ms.
    pub ms: f64,
    /// MB/s (1e6 bytes).
    pub mb_per_s: f64,
}

/// The trade table of one input.
#[derive(Debug, Clone, Serialize)]
pub struct TradeInput {
    /// Input name.
    pub input: String,
    /// Triangles of A + B.
    pub triangles: usize,
    /// One row per option.
    pub rows: Vec<TradeRow>,
}

/// One option against the exact default.
#[derive(Debug, Clone, Default, Serialize)]
pub struct TradeRow {
    /// `exact`, `fast`, `first-hit`, `distance rel=0.1`, `bvh sah leaf 4`, ...
    pub mode: String,
    /// Build, ms.
    pub build_ms: f64,
    /// Query, ms.
    pub query_ms: f64,
    /// Exact default's total / this total.
    pub speedup: f64,
    /// The verdict differs from the exact one.
    pub verdict_changed: bool,
    /// Pairs reported.
    pub pairs: usize,
    /// Pairs the exact answer does not have.
    pub false_pairs: usize,
    /// Exact pairs missing.
    pub missed_pairs: usize,
    /// Pairs in both with a different kind or contact.
    pub kind_changes: usize,
    /// The reported distance (None when not computed).
    pub distance: Option<f64>,
    /// Reported minus exact distance.
    pub distance_error: Option<f64>,
    /// The guaranteed bound `rel·d + abs` on that error.
    pub bound: Option<f64>,
    /// Error within the bound (up to 64 ulps of rounding slack).
    pub within_bound: Option<bool>,
    /// Mean SAH cost of the two trees.
    pub sah_cost: f64,
    /// The distance search alone (trees built, no pair listing, topology or containment), ms.
    pub distance_search_ms: Option<f64>,
    /// Error measure for the plot: fraction of exact pairs wrong, or relative distance error.
    pub error_fraction: f64,
    /// What the option gives up, in words.
    pub note: String,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn loadavg() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

fn status_bytes(key: &str) -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with(key))?;
    let kb: u64 = line[key.len()..].trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kb * 1024)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn release_free_memory() {
    extern "C" {
        fn malloc_trim(pad: usize) -> i32;
    }
    // SAFETY: glibc's malloc_trim only returns free heap pages to the OS.
    unsafe {
        malloc_trim(0);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn release_free_memory() {}

/// Run `f`, returning its result and the peak RSS growth during it (freed heap memory is
/// returned to the OS first with glibc's `malloc_trim`, and VmHWM reset, so that the growth is
/// not hidden by reuse of earlier runs' freed memory).
fn peak_rss<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    release_free_memory();
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let before = status_bytes("VmRSS:");
    let r = f();
    let hwm = status_bytes("VmHWM:");
    let delta = match (reset, before, hwm) {
        (true, Some(b), Some(h)) => Some(h.saturating_sub(b)),
        _ => None,
    };
    (r, delta)
}

/// Best of `reps` runs (the result of the last).
fn best_of<T>(reps: usize, mut f: impl FnMut() -> (T, f64)) -> (T, f64) {
    let (mut r, mut best) = f();
    for _ in 1..reps {
        let (x, t) = f();
        r = x;
        best = best.min(t);
    }
    (r, best)
}

/// An exact pair: (a, b, crossing).
type ExactPair = (u32, u32, bool);

/// The pairs phase: dual walk, exact classification of every candidate (zero tolerances).
pub fn exact_pairs(a: &Mesh, ta: &Bvh, b: &Mesh, tb: &Bvh) -> Vec<ExactPair> {
    let (pairs, _) = meshclash::check::query::find_pairs(a, ta, b, tb, &Settings::default());
    pairs.iter().map(|p| (p.a, p.b, p.kind == meshclash::check::query::PairKind::Crossing)).collect()
}

/// The distance a standalone distance query needs: 0 at the first contact found, else the
/// branch-and-bound minimum (as [`query::check`] computes it).
pub fn exact_distance(a: &Mesh, ta: &Bvh, b: &Mesh, tb: &Bvh) -> Option<f64> {
    distance_within(a, ta, b, tb, DistanceError::default())
}

/// [`exact_distance`] with an error allowance (the pruning of [`query::check`]: a node pair
/// with lower bound `lb` is skipped when `(1 + rel)·lb + abs` cannot beat the best so far).
pub fn distance_within(a: &Mesh, ta: &Bvh, b: &Mesh, tb: &Bvh, err: DistanceError) -> Option<f64> {
    let stop = AtomicBool::new(false);
    let hit: Vec<()> = traverse::collect_pairs(
        ta,
        tb,
        |x, y| !stop.load(Ordering::Relaxed) && x.overlaps(y),
        |la, lb, out| {
            for &i in la {
                let ti = bvh::triangle(a, i);
                let bi = Aabb::of_triangle(&ti);
                for &j in lb {
                    if stop.load(Ordering::Relaxed) {
                        return;
                    }
                    let tj = bvh::triangle(b, j);
                    if bi.overlaps(&Aabb::of_triangle(&tj)) && tri_tri::classify(&ti, &tj).is_some() {
                        stop.store(true, Ordering::Relaxed);
                        out.push(());
                        return;
                    }
                }
            }
        },
    );
    if !hit.is_empty() {
        return Some(0.0);
    }
    meshclash::check::query::closest_pair(a, ta, b, tb, err).map(|c| c.distance)
}

/// Candidate triangle pairs (boxes overlap), at most `cap`.
fn candidates(a: &Mesh, ta: &Bvh, b: &Mesh, tb: &Bvh, cap: usize) -> Vec<(u32, u32)> {
    let mut v: Vec<(u32, u32)> = traverse::collect_pairs(
        ta,
        tb,
        |x, y| x.overlaps(y),
        |la, lb, out| {
            for &i in la {
                let bi = Aabb::of_triangle(&bvh::triangle(a, i));
                for &j in lb {
                    if bi.overlaps(&Aabb::of_triangle(&bvh::triangle(b, j))) {
                        out.push((i, j));
                    }
                }
            }
        },
    );
    v.truncate(cap);
    v
}

/// Pairs (as (a, b)) only in `ours` / only in `theirs`.
fn diff(ours: &[(u32, u32)], theirs: &[(u32, u32)]) -> (usize, usize) {
    let (only_ours, only_theirs) = cross_check::diff_pairs(ours, theirs);
    (only_ours.len(), only_theirs.len())
}

struct Case {
    name: String,
    a: Mesh,
    b: Mesh,
}

fn size_name(n: usize) -> String {
    if n >= 1_000_000 && n.is_multiple_of(100_000) {
        format!("{}M", n as f64 / 1e6)
    } else if n >= 1000 && n.is_multiple_of(100) {
        format!("{}k", n as f64 / 1e3)
    } else {
        n.to_string()
    }
}

fn cases(opts: &BenchOptions) -> Result<Vec<Case>> {
    let mut sizes = opts.sizes.clone();
    sizes.sort_unstable();
    sizes.dedup();
    let mut out = Vec::new();
    let small = sizes.first().copied().unwrap_or(10_000).min(20_000);
    let (a, b) = gen::coplanar_grids(small);
    out.push(Case { name: format!("coplanar grids at 1e8 {}", size_name(a.triangles.len())), a, b });
    let (a, b) = gen::ulp_shifted_tori(small);
    out.push(Case { name: format!("torus vs 1-ulp shift {}", size_name(a.triangles.len())), a, b });
    for &n in &sizes {
        let (a, b) = gen::crossing_tori(n);
        out.push(Case { name: format!("tori crossing {}", size_name(n)), a, b });
        let (a, b) = gen::separated_tori(n);
        out.push(Case { name: format!("tori apart {}", size_name(n)), a, b });
    }
    for path in &opts.meshes {
        let input =
            query::load_input(&query::InputSpec { path: path.clone(), transform: glam::DMat4::IDENTITY })?;
        let stem =
            path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned());
        let m = input.mesh;
        out.push(Case { name: format!("{stem} vs rotated copy"), b: gen::rotated_copy(&m), a: m.clone() });
        out.push(Case { name: format!("{stem} vs moved copy"), b: gen::separated_copy(&m), a: m });
    }
    Ok(out)
}

/// Parry's distance on touching inputs is not a dual walk and can take many seconds: skip it
/// when the time extrapolated from the inputs measured so far (per triangle) exceeds this.
const PARRY_DISTANCE_BUDGET_MS: f64 = 4000.0;
/// Without a measurement to extrapolate from, run parry's distance up to this many triangles.
const PARRY_DISTANCE_BLIND_TRIS: usize = 300_000;
/// Full-sweep SAH builds (sequential, O(n log² n)) only up to this many triangles.
const FULL_SWEEP_MAX: usize = 300_000;
/// Inputs up to this many triangles (A + B) are timed best of 3; larger ones once.
const REPEAT_MAX: usize = 300_000;

/// Run everything.
pub fn run(opts: &BenchOptions) -> Result<BenchReport> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| Error::bad_flag("threads", UsageProblem::Invalid(e.to_string())))?;
    let t0 = Instant::now();
    let load0 = loadavg();
    let cases = cases(opts)?;
    let mut inputs = Vec::new();
    let mut trade = Vec::new();
    // Worst parry distance time per triangle seen on touching inputs (ms per triangle).
    let mut parry_rate: Option<f64> = None;
    for case in &cases {
        let r = pool.install(|| measure(case, &mut parry_rate));
        inputs.push(r);
        if opts.trade {
            trade.push(pool.install(|| trade_input(case)));
        }
    }
    let obj_parse = pool.install(|| obj_parse(opts));
    Ok(BenchReport {
        machine: Machine {
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            threads: pool.current_num_threads(),
            load: [load0, loadavg()],
            total_s: t0.elapsed().as_secs_f64(),
        },
        inputs,
        obj_parse,
        trade,
    })
}

fn build_both(a: &Mesh, b: &Mesh, opts: BuildOptions) -> ((Bvh, Bvh), f64) {
    let t = Instant::now();
    let trees = rayon::join(|| Bvh::build(a, opts), || Bvh::build(b, opts));
    (trees, ms(t))
}

fn measure(case: &Case, parry_rate: &mut Option<f64>) -> InputResult {
    let (a, b) = (&case.a, &case.b);
    let tris = a.triangles.len() + b.triangles.len();
    let reps = if tris <= REPEAT_MAX { 3 } else { 1 };
    rayon::current_num_threads(); // start the pool outside the timed regions

    // meshclash phases.
    let ((ta, tb), build_ms) = best_of(reps, || build_both(a, b, BuildOptions::default()));
    let (pairs, pairs_ms) = best_of(reps, || {
        let t = Instant::now();
        let p = exact_pairs(a, &ta, b, &tb);
        (p, ms(t))
    });
    let (distance, distance_ms) = best_of(reps, || {
        let t = Instant::now();
        let d = exact_distance(a, &ta, b, &tb);
        (d, ms(t))
    });
    let (result, check_ms) = best_of(reps, || {
        let r = query::check(a, b, &Settings::default());
        let t = r.timings.build_ms + r.timings.query_ms;
        (r, t)
    });
    let (_, mc_rss) = peak_rss(|| query::check(a, b, &Settings::default()));
    let exact: Vec<(u32, u32)> = pairs.iter().map(|p| (p.0, p.1)).collect();
    let tree_bytes = ta.stats().bytes + tb.stats().bytes;
    let meshclash = ToolRun {
        build_ms,
        pairs_ms,
        distance_ms: Some(distance_ms),
        pairs: pairs.len(),
        distance,
        false_pairs: 0,
        missed_pairs: 0,
        tree_bytes,
        peak_rss_delta: mc_rss,
        note: None,
    };

    // parry, with the distance capped on touching inputs.
    let touching = !pairs.is_empty();
    let run_distance = if !touching {
        Ok(())
    } else {
        match *parry_rate {
            Some(rate) if rate * tris as f64 > PARRY_DISTANCE_BUDGET_MS => {
                Err(format!("skipped (>{:.0} s expected)", (rate * tris as f64 / 1e3).floor().max(1.0)))
            }
            None if tris > PARRY_DISTANCE_BLIND_TRIS => {
                Err(format!("skipped (>{:.0} s expected)", PARRY_DISTANCE_BUDGET_MS / 1e3))
            }
            _ => Ok(()),
        }
    };
    let parry = |f: fn(&Mesh, &Mesh, bool) -> std::result::Result<ParryResult, String>| -> ToolRun {
        let mut best: Option<ParryResult> = None;
        let mut rss = None;
        for k in 0..reps {
            let (r, delta) = peak_rss(|| f(a, b, run_distance.is_ok()));
            if k == 0 {
                rss = delta;
            }
            match r {
                Err(e) => return ToolRun { note: Some(e), ..Default::default() },
                Ok(r) => {
                    best = Some(match best {
                        None => r,
                        Some(mut x) => {
                            x.build_ms = x.build_ms.min(r.build_ms);
                            x.pairs_ms = x.pairs_ms.min(r.pairs_ms);
                            x.distance_ms = x.distance_ms.min(r.distance_ms);
                            x
                        }
                    })
                }
            }
        }
        let r = best.expect("at least one run");
        let (missed, false_pairs) = diff(&exact, &r.intersecting_pairs);
        ToolRun {
            build_ms: r.build_ms,
            pairs_ms: r.pairs_ms,
            distance_ms: run_distance.is_ok().then_some(r.distance_ms),
            pairs: r.intersecting_pairs.len(),
            distance: run_distance.is_ok().then_some(r.distance),
            false_pairs,
            missed_pairs: missed,
            tree_bytes: r.tree_bytes,
            peak_rss_delta: rss,
            note: run_distance.clone().err(),
        }
    };
    let parry_f64 = parry(cross_check::parry_f64);
    let parry_f32 = parry(parry32::parry_f32);
    if touching {
        if let Some(d) = parry_f64.distance_ms {
            let rate = d / tris as f64;
            *parry_rate = Some(parry_rate.map_or(rate, |r: f64| r.max(rate)));
        }
    }

    // Build quality and kernels.
    let sah_binned = ta.stats().sah_cost;
    let sah_full_sweep = (a.triangles.len() <= FULL_SWEEP_MAX).then(|| {
        let boxes: Vec<Aabb> =
            (0..a.triangles.len() as u32).map(|t| Aabb::of_triangle(&bvh::triangle(a, t))).collect();
        sweep::build_full_sweep(&boxes, BuildOptions::default().leaf_size).stats().sah_cost
    });
    let cands = candidates(a, &ta, b, &tb, 4_000_000);
    let tri_tri_ns = (!cands.is_empty()).then(|| {
        let run = || {
            let t = Instant::now();
            let mut hits = 0usize;
            for &(i, j) in &cands {
                hits += tri_tri::classify(&bvh::triangle(a, i), &bvh::triangle(b, j)).is_some() as usize;
            }
            std::hint::black_box(hits);
            t.elapsed().as_secs_f64() * 1e9 / cands.len() as f64
        };
        (0..reps).map(|_| run()).fold(f64::INFINITY, f64::min)
    });

    // Node layouts.
    let layouts = layouts(a, &ta, b, &tb, reps);

    // Scaling: 1 and 2 threads, each in its own pool.
    let scaling = [1usize, 2]
        .iter()
        .filter_map(|&n| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().ok()?;
            Some(pool.install(|| {
                rayon::current_num_threads();
                let (_, build_ms) = best_of(reps, || build_both(a, b, BuildOptions::default()));
                let (_, pairs_ms) = best_of(reps, || {
                    let t = Instant::now();
                    (exact_pairs(a, &ta, b, &tb).len(), ms(t))
                });
                let (_, distance_ms) = best_of(reps, || {
                    let t = Instant::now();
                    (exact_distance(a, &ta, b, &tb), ms(t))
                });
                let (_, check_ms) = best_of(reps, || {
                    let r = query::check(a, b, &Settings::default());
                    ((), r.timings.build_ms + r.timings.query_ms)
                });
                ThreadRun { threads: n, build_ms, pairs_ms, distance_ms, check_ms }
            }))
        })
        .collect();

    InputResult {
        name: case.name.clone(),
        triangles: [a.triangles.len(), b.triangles.len()],
        verdict: result.verdict.name().into(),
        crossing: result.counts.crossing,
        touching: result.counts.touching,
        meshclash,
        check_ms,
        parry_f64,
        parry_f32,
        build_mtris_per_s: tris as f64 / 1e3 / build_ms,
        sah_binned,
        sah_full_sweep,
        candidates: cands.len() as u64,
        tri_tri_ns,
        layouts,
        scaling,
    }
}

fn layouts(a: &Mesh, ta: &Bvh, b: &Mesh, tb: &Bvh, reps: usize) -> Layouts {
    let Some(skip) = layout::SkipBvh::from_bvh(tb) else { return Layouts::default() };
    // Leaf work: triangle-box tests only, so that the walk itself dominates.
    let work = |la: &[u32], lb: &[u32]| -> u64 {
        let mut n = 0u64;
        for &i in la {
            let bi = Aabb::of_triangle(&bvh::triangle(a, i));
            for &j in lb {
                n += bi.overlaps(&Aabb::of_triangle(&bvh::triangle(b, j))) as u64;
            }
        }
        n
    };
    let (c1, stack_ms) = best_of(reps, || {
        let t = Instant::now();
        (layout::leaves_vs_tree_stack(ta, tb, work), ms(t))
    });
    let (c2, stackless_ms) = best_of(reps, || {
        let t = Instant::now();
        (layout::leaves_vs_tree_stackless(ta, &skip, work), ms(t))
    });
    let (c3, dual_ms) = best_of(reps, || {
        let t = Instant::now();
        let parts: Vec<u64> =
            traverse::collect_pairs(ta, tb, |x, y| x.overlaps(y), |la, lb, out| out.push(work(la, lb)));
        (parts.iter().sum::<u64>(), ms(t))
    });
    Layouts { candidates: c1, stack_ms, stackless_ms, dual_ms, agree: c1 == c2 && c2 == c3 }
}

fn obj_parse(opts: &BenchOptions) -> Vec<ParseResult> {
    let mut files: Vec<(String, Vec<u8>)> = opts
        .meshes
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")))
        .filter_map(|p| Some((p.display().to_string(), std::fs::read(p).ok()?)))
        .collect();
    if let Some(&n) = opts.sizes.iter().max() {
        let n = n.min(1_000_000);
        let m = gen::torus(n);
        files.push((
            format!("generated torus {} (OBJ text)", size_name(m.triangles.len())),
            gen::to_obj(&m).into_bytes(),
        ));
    }
    files
        .into_iter()
        .filter_map(|(name, bytes)| {
            let path = PathBuf::from("bench.obj");
            let mut best = f64::INFINITY;
            for _ in 0..3 {
                let t = Instant::now();
                meshclash::load::load_bytes(&path, &bytes, meshclash::load::Format::Obj).ok()?;
                best = best.min(ms(t));
            }
            Some(ParseResult {
                name,
                bytes: bytes.len(),
                ms: best,
                mb_per_s: bytes.len() as f64 / 1e3 / best,
            })
        })
        .collect()
}

fn mean_sah(r: &ClashResult) -> f64 {
    (r.trees[0].sah_cost + r.trees[1].sah_cost) / 2.0
}

/// Compare a result's pairs with the exact one: (false, missed, kind changes).
fn compare_pairs(exact: &ClashResult, other: &ClashResult) -> (usize, usize, usize) {
    let key = |p: &query::PairFinding| (p.a, p.b);
    let (mut i, mut j) = (0, 0);
    let (e, o) = (&exact.pairs, &other.pairs);
    let (mut fals, mut missed, mut kind) = (0, 0, 0);
    while i < e.len() || j < o.len() {
        if j >= o.len() || (i < e.len() && key(&e[i]) < key(&o[j])) {
            missed += 1;
            i += 1;
        } else if i >= e.len() || key(&o[j]) < key(&e[i]) {
            fals += 1;
            j += 1;
        } else {
            kind += ((e[i].kind, e[i].contact) != (o[j].kind, o[j].contact)) as usize;
            i += 1;
            j += 1;
        }
    }
    (fals, missed, kind)
}

fn trade_input(case: &Case) -> TradeInput {
    let (a, b) = (&case.a, &case.b);
    let tris = a.triangles.len() + b.triangles.len();
    let reps = if tris <= REPEAT_MAX { 3 } else { 1 };
    let run = |s: &Settings| -> (ClashResult, f64, f64) {
        let mut best: Option<(ClashResult, f64, f64)> = None;
        for _ in 0..reps {
            let r = query::check(a, b, s);
            let (bm, qm) = (r.timings.build_ms, r.timings.query_ms);
            best = Some(match best {
                Some((x, b0, q0)) => (x, b0.min(bm), q0.min(qm)),
                None => (r, bm, qm),
            });
        }
        best.expect("reps >= 1")
    };
    let (exact, eb, eq) = run(&Settings::default());
    let base = eb + eq;
    let n_exact = exact.pairs.len().max(1) as f64;
    let d_exact = exact.closest.map(|c| c.distance);
    let row = |mode: String, r: &ClashResult, bm: f64, qm: f64, note: String| {
        let (false_pairs, missed_pairs, kind_changes) = compare_pairs(&exact, r);
        TradeRow {
            mode,
            build_ms: bm,
            query_ms: qm,
            speedup: base / (bm + qm),
            verdict_changed: r.verdict != exact.verdict,
            pairs: r.pairs.len(),
            false_pairs,
            missed_pairs,
            kind_changes,
            distance: r.closest.map(|c| c.distance),
            sah_cost: mean_sah(r),
            error_fraction: (false_pairs + missed_pairs + kind_changes) as f64 / n_exact,
            note,
            ..Default::default()
        }
    };
    let mut rows = vec![row("exact (default)".into(), &exact, eb, eq, "exact verdicts and pair set".into())];
    let (fast, fb, fq) = run(&Settings { mode: Mode::Fast, ..Default::default() });
    rows.push(row(
        "--mode fast".into(),
        &fast,
        fb,
        fq,
        "plain f64 predicates: signs of near-zero determinants may flip".into(),
    ));
    let (fh, hb, hq) = run(&Settings { first_hit: true, ..Default::default() });
    let mut r = row(
        "--first-hit".into(),
        &fh,
        hb,
        hq,
        format!(
            "stops at the first crossing: {} of {} crossing pairs listed, no distance",
            fh.counts.crossing, exact.counts.crossing
        ),
    );
    // First hit is not wrong about what it lists: report what it gives up as "missed" only.
    r.false_pairs = 0;
    r.kind_changes = 0;
    r.error_fraction = r.missed_pairs as f64 / n_exact;
    rows.push(r);
    let dist_only = |err: DistanceError| -> Option<f64> {
        let (ta, tb) = (Bvh::build(a, BuildOptions::default()), Bvh::build(b, BuildOptions::default()));
        let (_, t) = best_of(reps, || {
            let t = Instant::now();
            (distance_within(a, &ta, b, &tb, err), ms(t))
        });
        Some(t)
    };
    if let Some(d) = d_exact.filter(|&d| d > 0.0) {
        rows[0].distance_search_ms = dist_only(DistanceError::default());
        let diag = ta_diag(a, b);
        let scale = Aabb::of_points(&a.positions).union(Aabb::of_points(&b.positions)).max_abs();
        let slack = 2.0 * predicates::distance_rounding_slack(scale);
        let errs = [(0.01, 0.0), (0.1, 0.0), (1.0, 0.0), (0.0, 0.001 * diag), (0.0, 0.01 * diag)];
        for (rel, abs) in errs {
            let s = Settings { distance_error: DistanceError { rel, abs }, ..Default::default() };
            let (r, bm, qm) = run(&s);
            let name =
                if abs > 0.0 { format!("distance abs={abs:.3e}") } else { format!("distance rel={rel}") };
            let mut tr = row(name, &r, bm, qm, "distance within (1+rel)·d + abs".into());
            tr.distance_search_ms = dist_only(DistanceError { rel, abs });
            if let Some(got) = r.closest.map(|c| c.distance) {
                let err = got - d;
                let bound = rel * d + abs;
                tr.distance_error = Some(err);
                tr.bound = Some(bound);
                tr.within_bound = Some(err >= -slack && err <= bound + slack);
                tr.error_fraction = err.max(0.0) / d;
            } else {
                tr.within_bound = Some(false);
            }
            rows.push(tr);
        }
    }
    for strategy in [Strategy::Sah, Strategy::Median, Strategy::Equal] {
        for leaf_size in [1u32, 2, 4, 8, 16] {
            let s = Settings { bvh: BuildOptions { strategy, leaf_size }, ..Default::default() };
            let (r, bm, qm) = run(&s);
            rows.push(row(
                format!("--bvh {} --leaf-size {leaf_size}", strategy.name()),
                &r,
                bm,
                qm,
                "same answers, different speed".into(),
            ));
        }
    }
    TradeInput { input: case.name.clone(), triangles: tris, rows }
}

fn ta_diag(a: &Mesh, b: &Mesh) -> f64 {
    Aabb::of_points(&a.positions).union(Aabb::of_points(&b.positions)).extent().length()
}

// ---------------------------------------------------------------- formatting

/// A Markdown table.
fn table(out: &mut String, title: &str, header: &[&str], rows: &[Vec<String>]) {
    use std::fmt::Write;
    let n = header.len();
    let mut w: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (k, c) in r.iter().enumerate().take(n) {
            w[k] = w[k].max(c.chars().count());
        }
    }
    let _ = writeln!(out, "\n### {title}\n");
    let line = |cells: Vec<String>| {
        let mut s = String::from("|");
        for (k, c) in cells.iter().enumerate() {
            let pad = w[k] - c.chars().count();
            s.push(' ');
            if k == 0 {
                s.push_str(c);
                s.push_str(&" ".repeat(pad));
            } else {
                s.push_str(&" ".repeat(pad));
                s.push_str(c);
            }
            s.push_str(" |");
        }
        s
    };
    let _ = writeln!(out, "{}", line(header.iter().map(|h| h.to_string()).collect()));
    let mut sep = String::from("|");
    for (k, wk) in w.iter().enumerate() {
        sep.push_str(if k == 0 { " :" } else { " " });
        sep.push_str(&"-".repeat((wk - 1).max(1)));
        sep.push_str(if k == 0 { " |" } else { ": |" });
    }
    let _ = writeln!(out, "{sep}");
    for r in rows {
        let mut r = r.clone();
        r.resize(n, String::new());
        let _ = writeln!(out, "{}", line(r));
    }
}

fn f_ms(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else if v >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

fn f_ratio(num: Option<f64>, den: f64) -> String {
    match num {
        Some(x) if den > 0.0 => format!("{:.1}×", x / den),
        _ => "–".into(),
    }
}

fn f_opt_ms(v: Option<f64>, note: &Option<String>) -> String {
    match (v, note) {
        (Some(v), _) => f_ms(v),
        (None, Some(n)) => n.clone(),
        (None, None) => "–".into(),
    }
}

fn f_dist(d: Option<f64>) -> String {
    match d {
        Some(0.0) => "0".into(),
        Some(d) => format!("{d:.6}"),
        None => "–".into(),
    }
}

fn per_tri(bytes: Option<u64>, tris: usize) -> String {
    bytes.map_or("–".into(), |b| format!("{:.1}", b as f64 / tris as f64))
}

/// The report as Markdown tables.
pub fn render(rep: &BenchReport) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let load = |l: Option<f64>| l.map_or("?".into(), |v| format!("{v:.2}"));
    let _ = writeln!(
        out,
        "meshclash-bench: {} cores, {} threads, load average {} at start, {} at end{}, {:.0} s",
        rep.machine.cores,
        rep.machine.threads,
        load(rep.machine.load[0]),
        load(rep.machine.load[1]),
        if rep.machine.load.iter().flatten().any(|&l| l > 1.5) { " (MEASURED UNDER LOAD)" } else { "" },
        rep.machine.total_s
    );
    let mut rows = Vec::new();
    for r in &rep.inputs {
        let tris = format!("{} + {}", r.triangles[0], r.triangles[1]);
        let (m, p, q) = (&r.meshclash, &r.parry_f64, &r.parry_f32);
        let total = |t: &ToolRun| t.distance_ms.map(|d| t.build_ms + t.pairs_ms + d);
        let mc_total = total(m).unwrap_or(m.build_ms + m.pairs_ms);
        #[allow(clippy::type_complexity)] // one row per phase: name, meshclash, parry f64/f32, note
        let phase_rows: [(&str, f64, Option<f64>, Option<f64>, Option<String>); 4] = [
            ("build", m.build_ms, Some(p.build_ms), Some(q.build_ms), None),
            ("pairs", m.pairs_ms, Some(p.pairs_ms), Some(q.pairs_ms), None),
            ("distance", m.distance_ms.unwrap_or(0.0), p.distance_ms, q.distance_ms, p.note.clone()),
            ("build + pairs + distance", mc_total, total(p), total(q), p.note.as_ref().map(|_| "–".into())),
        ];
        for (k, (phase, mc, pf, pq, note)) in phase_rows.into_iter().enumerate() {
            let fail = |t: &ToolRun, v: Option<f64>| match (&t.note, v) {
                (Some(n), None) if t.build_ms == 0.0 => n.clone(),
                _ => f_opt_ms(v, &note),
            };
            rows.push(vec![
                if k == 0 { r.name.clone() } else { String::new() },
                if k == 0 { tris.clone() } else { String::new() },
                phase.into(),
                f_ms(mc),
                fail(p, pf),
                fail(q, pq),
                f_ratio(pf, mc),
                f_ratio(pq, mc),
            ]);
        }
        rows.push(vec![
            String::new(),
            String::new(),
            "whole check (+ topology, containment)".into(),
            f_ms(r.check_ms),
            String::new(),
            String::new(),
            f_ratio(total(p), r.check_ms),
            f_ratio(total(q), r.check_ms),
        ]);
    }
    table(
        &mut out,
        "Time per phase (ms; ratio = parry / meshclash, > 1 means meshclash is faster)",
        &["input", "triangles", "phase", "meshclash", "parry f64", "parry f32", "f64 / mc", "f32 / mc"],
        &rows,
    );

    let rows: Vec<Vec<String>> = rep
        .inputs
        .iter()
        .map(|r| {
            let wrong = |t: &ToolRun| {
                if t.build_ms == 0.0 && t.note.is_some() {
                    t.note.clone().unwrap_or_default()
                } else {
                    format!("{} ({} false, {} missed)", t.pairs, t.false_pairs, t.missed_pairs)
                }
            };
            vec![
                r.name.clone(),
                r.verdict.clone(),
                format!("{} ({} crossing, {} touching)", r.meshclash.pairs, r.crossing, r.touching),
                wrong(&r.parry_f64),
                wrong(&r.parry_f32),
                f_dist(r.meshclash.distance),
                f_dist(r.parry_f64.distance),
                f_dist(r.parry_f32.distance),
            ]
        })
        .collect();
    table(
        &mut out,
        "Answers (pairs = crossing or touching triangle pairs; false/missed against meshclash's exact set)",
        &[
            "input",
            "verdict",
            "meshclash pairs",
            "parry f64 pairs",
            "parry f32 pairs",
            "distance mc",
            "parry f64",
            "parry f32",
        ],
        &rows,
    );

    let rows: Vec<Vec<String>> = rep
        .inputs
        .iter()
        .map(|r| {
            let t = r.triangles[0] + r.triangles[1];
            vec![
                r.name.clone(),
                per_tri(Some(r.meshclash.tree_bytes as u64), t),
                per_tri(Some(r.parry_f64.tree_bytes as u64), t),
                per_tri(Some(r.parry_f32.tree_bytes as u64), t),
                per_tri(r.meshclash.peak_rss_delta, t),
                per_tri(r.parry_f64.peak_rss_delta, t),
                per_tri(r.parry_f32.peak_rss_delta, t),
            ]
        })
        .collect();
    table(
        &mut out,
        "Memory, bytes per triangle (trees: meshclash Bvh::stats().bytes, parry Bvh::total_memory_size; \
         peak RSS Δ: VmHWM after clear_refs minus VmRSS before, whole check / whole parry run incl. its vertex copy)",
        &["input", "mc trees", "parry f64 BVH", "parry f32 BVH", "mc check peak RSS Δ", "parry f64 peak RSS Δ", "parry f32 peak RSS Δ"],
        &rows,
    );

    let rows: Vec<Vec<String>> = rep
        .inputs
        .iter()
        .map(|r| {
            vec![
                r.name.clone(),
                format!("{:.2}", r.build_mtris_per_s),
                format!("{:.3}", r.sah_binned),
                r.sah_full_sweep.map_or("skipped (> 300k)".into(), |c| format!("{c:.3}")),
                r.sah_full_sweep
                    .map_or("–".into(), |c| format!("{:+.1}%", (r.sah_binned / c - 1.0) * 100.0)),
                r.candidates.to_string(),
                r.tri_tri_ns.map_or("–".into(), |v| format!("{v:.1}")),
            ]
        })
        .collect();
    table(
        &mut out,
        "Build and kernels (build: both trees, in parallel; SAH cost of A's tree, binned vs full sweep; exact tri–tri per candidate pair, one thread)",
        &["input", "build Mtris/s", "SAH binned", "SAH full sweep", "binned vs full", "candidates", "tri–tri ns/candidate"],
        &rows,
    );

    let rows: Vec<Vec<String>> = rep
        .inputs
        .iter()
        .map(|r| {
            let l = &r.layouts;
            vec![
                r.name.clone(),
                l.candidates.to_string(),
                f_ms(l.stack_ms),
                f_ms(l.stackless_ms),
                format!("{:.2}", l.stackless_ms / l.stack_ms),
                f_ms(l.dual_ms),
                if l.agree { "yes".into() } else { "NO".into() },
            ]
        })
        .collect();
    table(
        &mut out,
        "Node layouts: each leaf of A walked against tree B (leaf work: triangle-box tests), ms",
        &[
            "input",
            "candidates",
            "stack (current layout)",
            "stackless (skip pointers)",
            "stackless / stack",
            "dual walk (current)",
            "same result",
        ],
        &rows,
    );

    let mut rows = Vec::new();
    for r in &rep.inputs {
        if let [one, two] = &r.scaling[..] {
            let phases = [
                ("build", one.build_ms, two.build_ms),
                ("pairs", one.pairs_ms, two.pairs_ms),
                ("distance", one.distance_ms, two.distance_ms),
                ("whole check", one.check_ms, two.check_ms),
            ];
            for (k, (p, x, y)) in phases.into_iter().enumerate() {
                rows.push(vec![
                    if k == 0 { r.name.clone() } else { String::new() },
                    p.into(),
                    f_ms(x),
                    f_ms(y),
                    format!("{:.2}×", x / y),
                ]);
            }
        }
    }
    table(
        &mut out,
        "Parallel scaling (meshclash, ms)",
        &["input", "phase", "1 thread", "2 threads", "speed-up"],
        &rows,
    );

    let rows: Vec<Vec<String>> = rep
        .obj_parse
        .iter()
        .map(|p| {
            vec![
                p.name.clone(),
                format!("{:.1}", p.bytes as f64 / 1e6),
                f_ms(p.ms),
                format!("{:.0}", p.mb_per_s),
            ]
        })
        .collect();
    table(&mut out, "OBJ parsing (load::load_bytes, best of 3)", &["file", "MB", "ms", "MB/s"], &rows);

    for t in &rep.trade {
        out.push_str(&render_trade(t));
    }
    out
}

/// The trade table of one input.
pub fn render_trade(t: &TradeInput) -> String {
    let mut out = String::new();
    let rows: Vec<Vec<String>> = t
        .rows
        .iter()
        .map(|r| {
            let err = match (r.distance_error, r.bound, r.within_bound) {
                (Some(e), Some(b), Some(ok)) => {
                    format!("{e:.3e} ≤ {b:.3e} {}", if ok { "ok" } else { "VIOLATED" })
                }
                _ => "–".into(),
            };
            vec![
                r.mode.clone(),
                f_ms(r.build_ms),
                f_ms(r.query_ms),
                format!("{:.2}×", r.speedup),
                if r.verdict_changed { "CHANGED".into() } else { "same".into() },
                format!("{} ({}/{}/{})", r.pairs, r.false_pairs, r.missed_pairs, r.kind_changes),
                f_dist(r.distance),
                r.distance_search_ms.map_or("–".into(), f_ms),
                err,
                format!("{:.2}", r.sah_cost),
                r.note.clone(),
            ]
        })
        .collect();
    table(
        &mut out,
        &format!("Speed/accuracy trade: {} ({} triangles)", t.input, t.triangles),
        &[
            "option",
            "build ms",
            "query ms",
            "speed-up",
            "verdict",
            "pairs (false/missed/kind changed)",
            "distance",
            "distance search ms",
            "distance error ≤ bound",
            "SAH cost",
            "gives up",
        ],
        &rows,
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_sizes("10k,100k,1M").unwrap(), vec![10_000, 100_000, 1_000_000]);
        assert_eq!(parse_sizes("2k").unwrap(), vec![2000]);
        assert!(parse_sizes("abc").is_err());
        assert!(parse_sizes("0").is_err());
    }

    #[test]
    fn phases_agree_with_check() {
        let (a, b) = gen::crossing_tori(3000);
        let opts = BuildOptions::default();
        let (ta, tb) = (Bvh::build(&a, opts), Bvh::build(&b, opts));
        let pairs = exact_pairs(&a, &ta, &b, &tb);
        let r = query::check(&a, &b, &Settings::default());
        assert_eq!(pairs.len(), r.pairs.len());
        assert!(pairs.iter().zip(&r.pairs).all(|(p, q)| (p.0, p.1) == (q.a, q.b)));
        assert_eq!(exact_distance(&a, &ta, &b, &tb), Some(0.0));
        let (a, b) = gen::separated_tori(3000);
        let (ta, tb) = (Bvh::build(&a, opts), Bvh::build(&b, opts));
        let r = query::check(&a, &b, &Settings::default());
        assert_eq!(exact_distance(&a, &ta, &b, &tb), r.closest.map(|c| c.distance));
        assert_eq!(r.verdict.name(), "clear");
    }
}
