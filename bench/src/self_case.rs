//! `meshclash-bench self`: self-clash and mesh health on a generated folded torus
//! (default 1M triangles: [`meshclash::check::self_clash::gen::folded_torus`]) and on given
//! files, phase by phase.
//!
//! Timed (wall clock, best of `--reps` runs, after one untimed warm-up of rayon's pool):
//! **load** (files only: meshclash's loader); **merge** (exact vertex merge,
//! [`meshclash::scene::bodies::merge_vertices`]); **health** ([`meshclash::check::health::health`]
//! alone); **tree** (triangle boxes and the BVH) and **walk** (the tree against itself with every
//! pair test and the final sort) of [`meshclash::check::self_clash::self_pairs_timed`] alone;
//! **check**: [`meshclash::check::self_clash::check_parts`], what `meshclash self` runs after
//! loading (merge, then health beside the walks). The answer (crossing and touching pairs) is
//! printed with the times so a faster run can be seen to give the same one.

use meshclash::bvh::BuildOptions;
use meshclash::check::self_clash::{self, PartChoice};
use meshclash::error::{Error, Result, UsageProblem};
use meshclash::scene::mesh::Mesh;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// `meshclash-bench self` flags.
#[derive(Debug, Clone, clap::Args)]
pub struct SelfCaseArgs {
    /// Triangles of the generated folded torus (`k` = 1e3, `M` = 1e6); 0 leaves it out.
    #[arg(long, value_name = "N", default_value = "1M")]
    pub triangles: String,
    /// Also these mesh files (e.g. the bunny).
    #[arg(long = "mesh", value_name = "FILE", num_args = 1..)]
    pub meshes: Vec<PathBuf>,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// Runs per phase; the best is reported.
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub reps: usize,
    /// BVH split strategy of the self tree: sah, median or equal.
    #[arg(long, value_name = "S", default_value = "sah")]
    pub bvh: String,
    /// Largest BVH leaf.
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub leaf_size: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One input's figures (milliseconds).
#[derive(Debug, Clone, Serialize)]
pub struct SelfCaseResult {
    /// Input name.
    pub name: String,
    /// Triangles.
    pub triangles: usize,
    /// Loading the file (None for the generated mesh).
    pub load_ms: Option<f64>,
    /// Exact vertex merge.
    pub merge_ms: f64,
    /// Health alone.
    pub health_ms: f64,
    /// Boxes and tree alone.
    pub tree_ms: f64,
    /// Walk and pair tests alone.
    pub walk_ms: f64,
    /// `check_parts`: what `meshclash self` runs after loading.
    pub check_ms: f64,
    /// CPU times (all threads, user + system, 10 ms ticks; the best of the runs) of merge,
    /// health, tree + walk and check: on a busy machine the wall clock also counts the time
    /// other processes held the cores.
    pub merge_cpu_ms: Option<f64>,
    /// See `merge_cpu_ms`.
    pub health_cpu_ms: Option<f64>,
    /// See `merge_cpu_ms`.
    pub pairs_cpu_ms: Option<f64>,
    /// See `merge_cpu_ms`.
    pub check_cpu_ms: Option<f64>,
    /// Crossing self-clash pairs.
    pub crossing: u64,
    /// Touching self-clash pairs.
    pub touching: u64,
    /// Worker threads.
    pub threads: usize,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// This process's CPU time so far (user + system, all threads), from `/proc/self/stat`.
fn cpu_ms() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks * 10.0) // USER_HZ is 100 on Linux
}

/// Run `f` `reps` times: the last result, the best wall time and the best CPU time (ms).
fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> (T, f64, Option<f64>) {
    let (mut out, mut wall, mut cpu) = (None, f64::INFINITY, None::<f64>);
    for _ in 0..reps.max(1) {
        let (t, c) = (Instant::now(), cpu_ms());
        let o = f();
        wall = wall.min(ms(t));
        if let (Some(b), Some(a)) = (cpu_ms(), c) {
            cpu = Some(cpu.map_or(b - a, |m| m.min(b - a)));
        }
        out = Some(o);
    }
    (out.expect("one run"), wall, cpu)
}

fn measure(
    name: String,
    mesh: &Mesh,
    load_ms: Option<f64>,
    args: &SelfCaseArgs,
    opts: BuildOptions,
    threads: usize,
) -> SelfCaseResult {
    let all: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
    let reps = args.reps;
    let (merged, merge_ms, merge_cpu) =
        best(reps, || meshclash::scene::bodies::merge_vertices(&mesh.positions).0);
    let (_, health_ms, health_cpu) = best(reps, || meshclash::check::health::health(mesh, &merged, &all, 10));
    let (mut tree_ms, mut walk_ms) = (f64::INFINITY, f64::INFINITY);
    let (_, _, pairs_cpu) = best(reps, || {
        let (_, times) = self_clash::self_pairs_timed(mesh, &merged, &all, opts);
        tree_ms = tree_ms.min(times.tree_ms);
        walk_ms = walk_ms.min(times.walk_ms);
    });
    let keep = |_: &str| true;
    let (parts, check_ms, check_cpu_ms) =
        best(reps, || self_clash::check_parts(mesh, PartChoice::Objects(&keep), opts, 10).0);
    let crossing = parts.iter().map(|p| p.crossing).sum();
    let touching = parts.iter().map(|p| p.pairs.len() as u64 - p.crossing).sum();
    SelfCaseResult {
        name,
        triangles: mesh.triangles.len(),
        load_ms,
        merge_ms,
        health_ms,
        tree_ms,
        walk_ms,
        check_ms,
        merge_cpu_ms: merge_cpu,
        health_cpu_ms: health_cpu,
        pairs_cpu_ms: pairs_cpu,
        check_cpu_ms,
        crossing,
        touching,
        threads,
    }
}

/// Run the self case and return the text to print.
pub fn run_self_case(args: &SelfCaseArgs) -> Result<String> {
    let n = *crate::parse_sizes(&args.triangles)?.first().unwrap_or(&0);
    let strategy = match args.bvh.as_str() {
        "sah" => meshclash::bvh::Strategy::Sah,
        "median" => meshclash::bvh::Strategy::Median,
        "equal" => meshclash::bvh::Strategy::Equal,
        other => {
            let msg = format!("--bvh: sah, median or equal, not '{other}'");
            return Err(Error::bad_flag("bvh", UsageProblem::Other(msg)));
        }
    };
    let opts = BuildOptions { strategy, leaf_size: args.leaf_size.clamp(1, 64) };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .map_err(|e| Error::bad_flag("threads", UsageProblem::Invalid(e.to_string())))?;
    let results = pool.install(|| -> Result<Vec<SelfCaseResult>> {
        rayon::broadcast(|_| ()); // warm the pool
        let threads = rayon::current_num_threads();
        let mut out = Vec::new();
        if n > 0 {
            let mesh = self_clash::gen::folded_torus(n);
            out.push(measure(format!("folded torus {n}"), &mesh, None, args, opts, threads));
        }
        for path in &args.meshes {
            let t = Instant::now();
            let (loaded, _) = meshclash::load::load_path(path)?;
            let load_ms = ms(t);
            out.push(measure(path.display().to_string(), &loaded.mesh, Some(load_ms), args, opts, threads));
        }
        Ok(out)
    })?;
    if args.json {
        let mut s = serde_json::to_string_pretty(&results).expect("serialises");
        s.push('\n');
        return Ok(s);
    }
    let cpu = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.0}"));
    let mut s = String::from(
        "| input | triangles | threads | load | merge | health | tree | walk | check (after load) | \
         CPU: merge | health | tree + walk | check | crossing | touching |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in &results {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {} | {} | {} | {} | {} |\n",
            r.name,
            r.triangles,
            r.threads,
            r.load_ms.map_or("-".to_string(), |v| format!("{v:.1}")),
            r.merge_ms,
            r.health_ms,
            r.tree_ms,
            r.walk_ms,
            r.check_ms,
            cpu(r.merge_cpu_ms),
            cpu(r.health_cpu_ms),
            cpu(r.pairs_cpu_ms),
            cpu(r.check_cpu_ms),
            r.crossing,
            r.touching
        ));
    }
    s.push_str(
        "\nms, best of the runs (wall clock, then CPU time over all threads); merge, health, tree and \
         walk each alone; check = what `meshclash self` runs after loading (merge, then health \
         beside the walks).\n",
    );
    Ok(s)
}
