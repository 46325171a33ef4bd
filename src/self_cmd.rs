//! `meshclash self FILE`: one file checked against itself, part by part — the self-clashing
//! triangle pairs ([`crate::check::self_clash`]) and the mesh health ([`crate::check::health`]) in one report
//! (`meshclash.self/1`, see [`crate::report::self_report`]).
//!
//! Exit code: 0 nothing selected by `--fail-on` was found, 1 something was, 2 bad input, I/O or
//! usage error (as for a check).

use crate::bvh::{BuildOptions, Strategy};
use crate::check::query::{self, InputSpec};
use crate::error::{Error, Result};
use crate::report::self_report::{self as rep, SelfReport};
use glam::DMat4;
use std::path::PathBuf;
use std::time::Instant;

/// Check one mesh against itself: every pair of triangles of one part that meets anywhere the
/// connectivity does not say it meets (after merging exactly coincident vertices), and each
/// part's health (closed, duplicate faces, zero-area triangles, non-manifold edges and
/// vertices, boundary edges, inconsistent winding, signed volume).
#[derive(Debug, Clone, clap::Args)]
pub struct SelfArgs {
    /// The mesh (OBJ, STL, glTF/GLB).
    pub file: PathBuf,
    /// Check only parts whose name matches GLOB (`*`, `?`; repeatable).
    #[arg(long, value_name = "GLOB")]
    pub select: Vec<String>,
    /// Leave out parts matching GLOB (repeatable).
    #[arg(long, value_name = "GLOB")]
    pub exclude: Vec<String>,
    /// Split every part into its connected bodies first (as for a check).
    #[arg(long)]
    pub split_bodies: bool,
    /// Check the whole file as one part (objects ignored): connectivity and health across
    /// objects, e.g. two solids glued face to face.
    #[arg(long, conflicts_with_all = ["select", "exclude", "split_bodies"])]
    pub whole_file: bool,
    /// Exit 1 when any of these is found (comma-separated): `self-clash` (alias `clash`:
    /// crossing pairs), `touching` (any self-clash pair), `open`, `non-manifold` (edges or
    /// vertices), `duplicates`, `degenerate` (zero-area triangles), `winding`, `never`.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "WHAT", default_value = "self-clash")]
    pub fail_on: Vec<SelfFailOn>,
    /// Write the report to FILE (atomically) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Also write JUnit XML to FILE (atomically): one test case per checked part, failed when
    /// the part has something in --fail-on.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// What to print on stdout [default: json, or nothing when -o is given].
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<SelfFormat>,
    /// List at most N pairs (the counts stay complete).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub max_pairs: usize,
    /// List at most N triangle ids per health finding.
    #[arg(long, value_name = "N", default_value_t = 10)]
    pub first_n: usize,
    /// BVH split strategy (the answer is the same with each; only the time differs).
    #[arg(long, value_enum, default_value_t = crate::cli::BvhArg::Sah)]
    pub bvh: crate::cli::BvhArg,
    /// Largest BVH leaf, in triangles (1..=64).
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub leaf_size: u32,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// Deterministic report: no timings, no thread count (byte-identical across runs).
    #[arg(long)]
    pub no_timings: bool,
    /// Nothing on stderr but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

pub use crate::report::self_report::SelfFailOn;

/// `--format` values of `self`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SelfFormat {
    /// The JSON report (`meshclash.self/1`).
    Json,
    /// A summary for a person.
    Text,
}

pub use crate::check::self_clash::{check_parts, PartChoice, PartResult};

/// What the binary prints after a successful run.
#[derive(Debug, Clone, PartialEq)]
pub struct SelfOutcome {
    /// For stdout (None when the report went to `-o` and no `--format` was given).
    pub stdout: Option<String>,
    /// The human summary (the binary shows it on stderr at a terminal).
    pub summary: String,
    /// Warnings, one line each.
    pub warnings: Vec<String>,
    /// 0 or 1.
    pub exit_code: u8,
    /// The report.
    pub report: Box<SelfReport>,
}

/// Do the whole `self` job.
pub fn run(args: &SelfArgs) -> Result<SelfOutcome> {
    if !(1..=64).contains(&args.leaf_size) {
        return Err(Error::Usage(format!("--leaf-size must be 1..=64, got {}", args.leaf_size)));
    }
    let outputs: Vec<crate::output::write::Named> = [("-o", &args.output), ("--junit", &args.junit)]
        .into_iter()
        .filter_map(|(f, p)| Some((f, p.as_deref()?)))
        .collect();
    crate::output::write::check_outputs(&outputs, &[&args.file])?;
    crate::cli::in_pool(args.threads, |threads| run_in_pool(args, threads))
}

fn run_in_pool(args: &SelfArgs, threads: usize) -> Result<SelfOutcome> {
    let t0 = Instant::now();
    let mut input = query::load_input(&InputSpec { path: args.file.clone(), transform: DMat4::IDENTITY })?;
    if args.split_bodies {
        crate::scene::bodies::split_bodies(&mut input.mesh);
    }
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    // Health numbers triangle corners in u32 (3 per triangle).
    if input.mesh.triangles.len() > (u32::MAX / 3) as usize {
        return Err(Error::input(
            &args.file,
            format!("{} triangles: `self` handles at most {}", input.mesh.triangles.len(), u32::MAX / 3),
        ));
    }
    let keep = |name: &str| {
        (args.select.is_empty() || args.select.iter().any(|g| crate::check::assembly::glob_match(g, name)))
            && !args.exclude.iter().any(|g| crate::check::assembly::glob_match(g, name))
    };
    let strategy = match args.bvh {
        crate::cli::BvhArg::Sah => Strategy::Sah,
        crate::cli::BvhArg::Median => Strategy::Median,
        crate::cli::BvhArg::Equal => Strategy::Equal,
    };
    let opts = BuildOptions { strategy, leaf_size: args.leaf_size };
    let whole_name = args.file.display().to_string();
    let choice = if args.whole_file { PartChoice::Whole(&whole_name) } else { PartChoice::Objects(&keep) };
    let (parts, health_ms, query_ms) = check_parts(&input.mesh, choice, opts, args.first_n);
    let mut warnings: Vec<String> =
        input.warnings.iter().map(|w| format!("{}: {w}", args.file.display())).collect();
    if parts.is_empty() {
        warnings.push(format!("{}: no part matches the selection", args.file.display()));
    }
    let mut fail_on = args.fail_on.clone();
    fail_on.sort_unstable();
    fail_on.dedup();
    let failed_on: Vec<SelfFailOn> =
        fail_on.iter().copied().filter(|f| parts.iter().any(|p| f.hit(p))).collect();
    let deterministic = args.no_timings;
    let report = rep::build(&rep::Context {
        input: &input,
        parts: &parts,
        fail_on: &fail_on,
        failed_on: &failed_on,
        split_bodies: args.split_bodies,
        whole_file: args.whole_file,
        select: &args.select,
        exclude: &args.exclude,
        bvh: strategy.name(),
        leaf_size: args.leaf_size,
        max_pairs: args.max_pairs,
        first_n: args.first_n,
        threads: (!deterministic).then_some(threads),
        timings: (!deterministic).then(|| rep::SelfTimings {
            load: load_ms,
            health: health_ms,
            query: query_ms,
            total: t0.elapsed().as_secs_f64() * 1e3,
        }),
        warnings: warnings.clone(),
    });
    let mut staged = crate::output::write::Staged::new();
    if let Some(path) = &args.junit {
        staged.stage(path, junit(&parts, &fail_on).as_bytes())?;
    }
    if let Some(path) = &args.output {
        staged.stage_with(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &report)?;
            std::io::Write::write_all(w, b"\n")
        })?;
    }
    staged.commit()?;
    let summary = rep::text(&report);
    let stdout = match args.format {
        None if args.output.is_some() => None,
        None | Some(SelfFormat::Json) => Some(rep::to_json(&report)),
        Some(SelfFormat::Text) => Some(summary.clone()),
    };
    Ok(SelfOutcome { stdout, summary, warnings, exit_code: report.failed as u8, report: Box::new(report) })
}

/// JUnit XML: one test case per part, failed when the part meets a `fail_on` condition; the
/// failure lists its first pairs and health findings.
pub fn junit(parts: &[PartResult], fail_on: &[SelfFailOn]) -> String {
    use crate::output::junit::{render, Case, FIRST};
    let cases: Vec<Case> = parts
        .iter()
        .map(|p| {
            let h = &p.health;
            let touching = p.pairs.len() as u64 - p.crossing;
            let mut findings: Vec<String> = p
                .pairs
                .iter()
                .take(FIRST)
                .map(|q| {
                    let kind = if q.hit.crossing { "crossing" } else { "touching" };
                    format!("triangles {} × {}: {kind} ({})", q.a, q.b, q.hit.contact.name())
                })
                .collect();
            let health = [
                ("boundary edges", &h.boundary_edges),
                ("non-manifold edges", &h.non_manifold_edges),
                ("non-manifold vertices", &h.non_manifold_vertices),
                ("duplicate faces", &h.duplicate_faces),
                ("zero-area triangles", &h.zero_area_triangles),
                ("inconsistent winding edges", &h.inconsistent_winding_edges),
            ];
            let mut total = p.pairs.len() as u64;
            for (what, f) in health {
                if f.count > 0 {
                    total += 1; // one line per kind of health finding
                    findings.push(format!("{} {what}, first triangles {:?}", f.count, f.triangles));
                }
            }
            let verdict = if p.crossing > 0 {
                "clash"
            } else if touching > 0 {
                "touching"
            } else {
                "clear"
            };
            Case {
                name: p.name.clone(),
                verdict: verdict.into(),
                counts: format!(
                    "{} crossing, {touching} touching self-clash pairs; {}",
                    p.crossing,
                    if h.closed { "closed" } else { "open" }
                ),
                findings,
                total,
                failed: fail_on.iter().any(|f| f.hit(p)),
                time_s: 0.0,
                output: String::new(),
            }
        })
        .collect();
    render("meshclash self", &cases)
}
