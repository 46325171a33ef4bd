//! `meshclash self FILE`: one file checked against itself, part by part — the self-clashing
//! triangle pairs ([`meshclash::check::self_clash`]) and the mesh health ([`meshclash::check::health`]) in one report
//! (`meshclash.self/1`, see [`meshclash::report::self_report`]).
//!
//! Exit code: 0 nothing selected by `--fail-on` was found, 1 something was, 2 bad input, I/O or
//! usage error (as for a check).

use super::args::BvhArg;
pub use super::args::{SelfArgs, SelfFormat};
use glam::DMat4;
use meshclash::bvh::{BuildOptions, Strategy};
use meshclash::check::query::{self, InputSpec};
use meshclash::check::self_clash::{check_parts_listing, PartChoice, PartResult};
use meshclash::error::{Error, InputProblem, Quantity, Result, UsageProblem};
use meshclash::report::self_report::SelfFailOn;
use meshclash::report::self_report::{self as rep, SelfReport};
use std::time::Instant;

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
        let problem = UsageProblem::OutOfRange { value: args.leaf_size.into(), min: 1, max: 64 };
        return Err(Error::bad_flag("leaf-size", problem));
    }
    let outputs: Vec<meshclash::output::write::Named> = [
        ("-o", &args.output),
        ("--junit", &args.junit),
        ("--html", &args.html),
        ("--export-glb", &args.export_glb),
    ]
    .into_iter()
    .filter_map(|(f, p)| Some((f, p.as_deref()?)))
    .collect();
    meshclash::output::write::check_outputs(&outputs, &[&args.file])?;
    super::run::in_pool(args.threads, |threads| run_in_pool(args, threads))
}

fn run_in_pool(args: &SelfArgs, threads: usize) -> Result<SelfOutcome> {
    let t0 = Instant::now();
    let mut input = query::load_input(&InputSpec { path: args.file.clone(), transform: DMat4::IDENTITY })?;
    if args.split_bodies {
        meshclash::scene::bodies::split_bodies(&mut input.mesh);
    }
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    // Health numbers triangle corners in u32 (3 per triangle).
    if input.mesh.triangles.len() > (u32::MAX / 3) as usize {
        let problem = InputProblem::TooLarge {
            quantity: Quantity::SelfTriangles,
            count: input.mesh.triangles.len() as u64,
            limit: (u32::MAX / 3) as u64,
        };
        return Err(Error::in_file(&args.file, problem));
    }
    let keep = |name: &str| {
        (args.select.is_empty()
            || args.select.iter().any(|g| meshclash::check::assembly::glob_match(g, name)))
            && !args.exclude.iter().any(|g| meshclash::check::assembly::glob_match(g, name))
    };
    let strategy = match args.bvh {
        BvhArg::Sah => Strategy::Sah,
        BvhArg::Median => Strategy::Median,
        BvhArg::Equal => Strategy::Equal,
    };
    let opts = BuildOptions { strategy, leaf_size: args.leaf_size };
    let whole_name = args.file.display().to_string();
    let choice = if args.whole_file { PartChoice::Whole(&whole_name) } else { PartChoice::Objects(&keep) };
    // Each part lists what the report and the JUnit failures show; every pair is counted.
    let listed = args.max_pairs.max(meshclash::output::junit::FIRST);
    let (parts, health_ms, query_ms) = check_parts_listing(&input.mesh, choice, opts, args.first_n, listed);
    let warnings: Vec<String> =
        input.warnings.iter().map(|w| format!("{}: {w}", args.file.display())).collect();
    if parts.is_empty() && !args.whole_file {
        // As in the other modes: a selection that leaves nothing to check is an error.
        let why = if args.select.is_empty() {
            "no part left to check after --exclude".to_string()
        } else {
            format!("--select {} matches no part", args.select.join(","))
        };
        return Err(Error::in_file(&args.file, InputProblem::Selection(why)));
    }
    let mut fail_on: Vec<SelfFailOn> = args.fail_on.iter().map(|&f| f.into()).collect();
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
    let mut staged = meshclash::output::write::Staged::new();
    if let Some(path) = &args.junit {
        staged.stage(path, junit(&parts, &fail_on).as_bytes())?;
    }
    let z_up = meshclash::output::glb::Up::from(args.up).z_up(&report.input.format);
    if let Some(path) = &args.html {
        staged.stage(path, meshclash::output::html::export_self(&report, &input.mesh, z_up).as_bytes())?;
    }
    if let Some(path) = &args.export_glb {
        staged.stage(path, &meshclash::output::glb::export_self(&report, &input.mesh, z_up))?;
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
    use meshclash::output::junit::{render, Case, FIRST};
    let cases: Vec<Case> = parts
        .iter()
        .map(|p| {
            let h = &p.health;
            let touching = p.count - p.crossing;
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
            let mut total = p.count;
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
