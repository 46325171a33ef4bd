//! `meshclash plan | run | merge` (issue 14): the command-line side of [`meshclash::shard`].
//!
//! App layer: the check arguments of a plan are parsed by the ordinary [`super::args::Args`] into
//! the ordinary [`super::config::Config`], and every step runs the ordinary check
//! ([`super::run::check_staged`], [`super::run::run_with_progress`]) with a
//! [`meshclash::check::assembly::Hook`] in its selection. The binary calls [`dispatch`] before
//! parsing its own arguments.

use super::args::{Args, CheckArgs, Command};
use super::config::Config;
use super::run as cli;
use clap::Parser;
use meshclash::check::assembly::Hook;
use meshclash::error::{Error, InputProblem, Reading, Result, UsageProblem};
use meshclash::output::write::{self, Staged};
use meshclash::shard::plan::{self, Plan, PlanInput};
use meshclash::shard::{sha256, Covered, MergeHook, PlanHook, ShardHook, ShardReport, SHARD_SCHEMA};
use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Shard a check across machines: `plan`, then `run` once per shard (any batch engine), then
/// `merge`.
#[derive(Debug, Parser)]
#[command(name = "meshclash", version)]
pub struct ShardCli {
    /// The step.
    #[command(subcommand)]
    pub cmd: ShardCommand,
}

/// `plan`, `run`, `merge`.
#[derive(Debug, clap::Subcommand)]
pub enum ShardCommand {
    /// Write the work list of a check: `meshclash plan <check arguments> -o plan.json`, the
    /// check arguments exactly as they would follow `meshclash` (`scene site.glb --clearance 10
    /// --no-timings`, `a.glb b.stl`). Loads the geometry once, builds no triangle tree.
    Plan(PlanArgs),
    /// Check the pairs of one shard of a plan: `meshclash run --plan plan.json --shard I/N -o
    /// shard-I.json`. Without --shard, I comes from JOB_COMPLETION_INDEX (Kubernetes, 0-based),
    /// AWS_BATCH_JOB_ARRAY_INDEX, CLOUD_RUN_TASK_INDEX or SLURM_ARRAY_TASK_ID, N from --shards,
    /// AWS_BATCH_JOB_ARRAY_SIZE, CLOUD_RUN_TASK_COUNT or SLURM_ARRAY_TASK_COUNT.
    Run(RunArgs),
    /// Merge the shard reports into the report the unsharded check writes (byte for byte
    /// with --no-timings), with its JUnit, baseline status and exit code.
    Merge(MergeArgs),
}

/// `meshclash plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanArgs {
    /// The check arguments and `-o PLAN.json`.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 1.., required = true)]
    pub args: Vec<OsString>,
}

/// `meshclash run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// The plan file.
    #[arg(long, value_name = "PLAN")]
    pub plan: PathBuf,
    /// This shard, I/N (1-based, as cargo-nextest --partition and Playwright --shard).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Number of shards when I comes from the engine's variable.
    #[arg(long, value_name = "N")]
    pub shards: Option<usize>,
    /// The shard report.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Worker threads (overrides the plan's --threads; 0 = one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Nothing on stderr but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `meshclash merge`.
#[derive(Debug, Clone, clap::Args)]
pub struct MergeArgs {
    /// The shard reports, in any order.
    #[arg(required = true, value_name = "SHARD")]
    pub shards: Vec<PathBuf>,
    /// Write the report to FILE (atomically) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Merge what is there when shards are missing: the report says `"complete": false` (and
    /// --baseline refuses it later).
    #[arg(long)]
    pub allow_partial: bool,
    /// Worker threads (overrides the plan's --threads; 0 = one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Nothing on stderr but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// If the first argument is `plan`, `run` or `merge`, do that and return the exit code.
pub fn dispatch() -> Option<u8> {
    let first = std::env::args_os().nth(1)?;
    if !matches!(first.to_str(), Some("plan" | "run" | "merge")) {
        return None;
    }
    let cli = match ShardCli::try_parse() {
        Ok(c) => c,
        Err(e) if e.use_stderr() => {
            let msg = e.to_string();
            eprintln!("meshclash: error: {}", msg.trim_start_matches("error: ").trim_end());
            return Some(2);
        }
        Err(e) => {
            let _ = e.print();
            return Some(0);
        }
    };
    let outcome = match cli.cmd {
        ShardCommand::Plan(a) => plan_cmd(a),
        ShardCommand::Run(a) => run_cmd(a),
        ShardCommand::Merge(a) => merge_cmd(a),
    };
    Some(outcome.unwrap_or_else(|e| {
        eprintln!("meshclash: error: {e}");
        2
    }))
}

/// A problem with the command or with how the plan, shards and reports fit together (exit 2),
/// as a sentence.
fn usage(msg: impl Into<String>) -> Error {
    Error::usage(UsageProblem::Other(msg.into()))
}

/// Flags that do not go together (`flag` is the one at fault).
fn conflict(flag: &str, why: impl Into<String>) -> Error {
    Error::bad_flag(flag, UsageProblem::Conflict(why.into()))
}

/// A file that cannot be read.
fn unreadable(path: &Path, reading: Reading, e: &std::io::Error) -> Error {
    Error::in_file(path, InputProblem::Unreadable { reading, kind: e.kind(), reason: e.to_string() })
}

/// A plan or shard report that breaks its format's rules.
fn invalid(path: &Path, msg: impl Into<String>) -> Error {
    Error::in_file(path, InputProblem::Invalid(msg.into()))
}

/// Parse check arguments as `meshclash ARGS` would.
fn parse_check(args: &[String]) -> Result<Args> {
    let a = Args::try_parse_from(std::iter::once("meshclash".to_string()).chain(args.iter().cloned()))
        .map_err(|e| {
            let msg = e.to_string().trim_start_matches("error: ").trim_end().to_string();
            Error::usage(UsageProblem::Invalid(msg))
        })?;
    if a.command.as_ref().is_some_and(|c| !matches!(c, Command::Scene(_))) {
        return Err(usage("plan takes the arguments of a check (A B, or scene FILE), not a subcommand"));
    }
    Ok(a)
}

/// The flags of a parsed check (`scene FILE` carries its own).
fn check_flags(a: &Args) -> &CheckArgs {
    match &a.command {
        Some(Command::Scene(s)) => &s.check,
        _ => &a.check,
    }
}

/// The configuration of a plan's check (no report file; `--cross-check` and `--first-hit`
/// refused: neither splits into part pairs).
fn config_of(args: &[String]) -> Result<Config> {
    let cfg = parse_check(args)?.into_config()?;
    if cfg.cross_check {
        return Err(conflict(
            "cross-check",
            "--cross-check runs parry on the whole inputs: it cannot be sharded",
        ));
    }
    if cfg.settings.first_hit {
        return Err(conflict(
            "first-hit",
            "--first-hit stops at a timing-dependent pair: it cannot be sharded",
        ));
    }
    if cfg.output.is_some() {
        return Err(usage("give -o FILE (the plan) as its own two arguments"));
    }
    Ok(cfg)
}

/// The check arguments without `-o FILE` / `--output FILE` / `--output=FILE` / `-oFILE`.
fn strip_output(raw: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    let mut it = raw.iter();
    while let Some(a) = it.next() {
        if a == "-o" || a == "--output" {
            it.next();
        } else if !(a.starts_with("--output=") || (a.starts_with("-o") && !a.starts_with("--"))) {
            out.push(a.clone());
        }
    }
    out
}

/// The input files a configuration reads, with their hashes.
fn hash_inputs(cfg: &Config) -> Result<Vec<PlanInput>> {
    cli::input_paths(cfg)
        .into_iter()
        .map(|p| {
            let err = |e: std::io::Error| unreadable(p, Reading::Input, &e);
            Ok(PlanInput {
                path: p.to_string_lossy().into_owned(),
                sha256: sha256::file_hex(p).map_err(err)?,
                bytes: std::fs::metadata(p).map_err(err)?.len(),
            })
        })
        .collect()
}

/// Refuse to go on when an input no longer matches the plan.
fn verify_inputs(plan: &Plan, cfg: &Config) -> Result<()> {
    let now = cli::input_paths(cfg);
    if now.len() != plan.inputs.len() {
        return Err(usage("the plan's arguments and inputs disagree: plan again"));
    }
    for (p, i) in now.into_iter().zip(&plan.inputs) {
        let h = sha256::file_hex(p).map_err(|e| unreadable(p, Reading::Input, &e))?;
        if h != i.sha256 {
            return Err(Error::in_file(
                p,
                InputProblem::ChangedSincePlan { sha256: h, planned: i.sha256.clone() },
            ));
        }
    }
    Ok(())
}

/// Write `v` as JSON: indented for people (the plan), compact for machines (shard reports,
/// which hold every triangle pair).
fn write_json<T: serde::Serialize>(path: &Path, v: &T, pretty: bool) -> Result<()> {
    let text = if pretty { serde_json::to_string_pretty(v) } else { serde_json::to_string(v) };
    let mut text = text.map_err(|e| usage(format!("cannot serialise: {e}")))?;
    text.push('\n');
    let mut staged = Staged::new();
    staged.stage(path, text.as_bytes())?;
    staged.commit()
}

fn plan_cmd(a: PlanArgs) -> Result<u8> {
    let raw = a
        .args
        .into_iter()
        .map(|s| s.into_string().map_err(|s| usage(format!("plan: argument {s:?} is not UTF-8"))))
        .collect::<Result<Vec<String>>>()?;
    let full = parse_check(&raw)?;
    let out = check_flags(&full).output.clone().ok_or_else(|| usage("plan needs -o PLAN.json"))?;
    let quiet = check_flags(&full).quiet;
    let stored = strip_output(&raw);
    let mut cfg = config_of(&stored)?;
    write::check_outputs(&[("-o", &out)], &cli::input_paths(&cfg))?;
    let inputs = hash_inputs(&cfg)?;
    let hook = Arc::new(PlanHook { files: !cfg.selection.by_parts(), ..Default::default() });
    cfg.selection.hook = Some(Hook(hook.clone()));
    cfg.outputs = Default::default();
    let rep = cli::in_pool(cfg.threads, |t| cli::check_staged(&cfg, t, &|_| {}, &mut Staged::new()))?;
    warn(quiet, &rep.warnings);
    let margin = rep.settings.touch_tolerance + rep.settings.clearance;
    let plan = hook.plan(stored, inputs, margin);
    write_json(&out, &plan, true)?;
    if !quiet {
        eprintln!(
            "meshclash: plan: {} work pairs of {} candidate part pairs, {} parts, cost {}",
            plan.work_pairs, plan.candidate_part_pairs, plan.parts, plan.total_cost
        );
    }
    Ok(0)
}

fn warn(quiet: bool, warnings: &[String]) {
    if !quiet {
        for w in warnings {
            eprintln!("meshclash: warning: {w}");
        }
    }
}

/// The engines' shard variables: (name, index base). Slurm's base is SLURM_ARRAY_TASK_MIN.
const INDEX_VARS: [(&str, Option<usize>); 4] = [
    ("JOB_COMPLETION_INDEX", Some(0)),
    ("AWS_BATCH_JOB_ARRAY_INDEX", Some(0)),
    ("CLOUD_RUN_TASK_INDEX", Some(0)),
    ("SLURM_ARRAY_TASK_ID", None),
];
const COUNT_VARS: [&str; 3] = ["AWS_BATCH_JOB_ARRAY_SIZE", "CLOUD_RUN_TASK_COUNT", "SLURM_ARRAY_TASK_COUNT"];

fn env_number(name: &str) -> Result<Option<usize>> {
    match std::env::var(name) {
        Err(_) => Ok(None),
        Ok(v) => v
            .trim()
            .parse::<usize>()
            .map(Some)
            .map_err(|_| usage(format!("{name}={v:?} is not a non-negative integer"))),
    }
}

/// This shard's (I, N), I 1-based: `--shard`, else the engine's variables.
pub fn shard_index(shard: Option<&str>, shards: Option<usize>) -> Result<(usize, usize)> {
    let (i, n) = match shard {
        Some(s) => {
            let bad = || {
                Error::bad_flag(
                    "shard",
                    UsageProblem::Other(format!("--shard takes I/N (1-based, e.g. 2/8), got '{s}'")),
                )
            };
            let (i, n) = s.split_once('/').ok_or_else(bad)?;
            let (i, n) = (
                i.trim().parse::<usize>().map_err(|_| bad())?,
                n.trim().parse::<usize>().map_err(|_| bad())?,
            );
            if shards.is_some_and(|m| m != n) {
                return Err(conflict(
                    "shards",
                    format!("--shard {s} and --shards {} disagree", shards.unwrap_or(0)),
                ));
            }
            (i, n)
        }
        None => {
            let mut found = None;
            for (name, base) in INDEX_VARS {
                if let Some(v) = env_number(name)? {
                    let base = match base {
                        Some(b) => b,
                        None => env_number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0),
                    };
                    let i = v
                        .checked_sub(base)
                        .ok_or_else(|| usage(format!("{name}={v} is below its base {base}")))?;
                    found = Some((name, i + 1));
                    break;
                }
            }
            let (name, i) = found.ok_or_else(|| {
                usage(format!(
                    "no shard given: pass --shard I/N, or run under an engine that sets {}",
                    INDEX_VARS.map(|v| v.0).join(", ")
                ))
            })?;
            let mut n = shards;
            for c in COUNT_VARS {
                if n.is_none() {
                    n = env_number(c)?;
                }
            }
            let n = n.ok_or_else(|| {
                usage(format!(
                    "{name} gives the shard index; give the count with --shards N (or {})",
                    COUNT_VARS.join(", ")
                ))
            })?;
            (i, n)
        }
    };
    if n == 0 || i == 0 || i > n {
        return Err(usage(format!("shard {i}/{n} does not exist: shards are 1/N to N/N with N >= 1")));
    }
    Ok((i, n))
}

fn read_plan(path: &Path) -> Result<(Plan, String)> {
    let bytes = std::fs::read(path).map_err(|e| unreadable(path, Reading::Plan, &e))?;
    let plan = Plan::parse(&bytes).map_err(|m| invalid(path, m))?;
    Ok((plan, sha256::hex(&bytes)))
}

fn run_cmd(a: RunArgs) -> Result<u8> {
    let (plan, plan_hash) = read_plan(&a.plan)?;
    let (i, n) = shard_index(a.shard.as_deref(), a.shards)?;
    match run_shard(&a, &plan, &plan_hash, i, n) {
        Ok(()) => Ok(0),
        Err(e) => {
            // A failed shard leaves a report that says so, for the merge to name.
            let failed = ShardReport {
                schema: SHARD_SCHEMA.into(),
                plan_hash,
                shard: i,
                shards: n,
                plan: plan.head(),
                pairs: Vec::new(),
                error: Some(e.to_string()),
                outcome: None,
                trees: Vec::new(),
            };
            let _ = write_json(&a.output, &failed, true);
            Err(e)
        }
    }
}

fn run_shard(a: &RunArgs, plan: &Plan, plan_hash: &str, i: usize, n: usize) -> Result<()> {
    let mut cfg = config_of(&plan.args)?;
    write::check_outputs(&[("-o", &a.output)], &cli::input_paths(&cfg))?;
    verify_inputs(plan, &cfg)?;
    if let Some(t) = a.threads {
        cfg.threads = t;
    }
    let shard_of = plan::partition(&plan.pairs, n);
    let mine: Vec<&plan::PlanPair> =
        plan.pairs.iter().zip(&shard_of).filter(|(_, &s)| s == i - 1).map(|(p, _)| p).collect();
    let files = plan.mode == "files";
    let owned: BTreeSet<usize> = meshclash::shard::tree_owners(plan, &shard_of)
        .into_iter()
        .filter(|&(_, s)| s == i - 1)
        .map(|(p, _)| p)
        .collect();
    let hook = Arc::new(ShardHook {
        files,
        has_files_unit: files && !mine.is_empty(),
        pairs: mine.iter().filter_map(|p| Some((p.a?, p.b?))).collect(),
        needed: meshclash::shard::needed_parts(plan.pairs.iter().map(|p| (p.a, p.b)), &plan.extra_needed),
        owned,
        bvh: cfg.settings.bvh,
        captured: Mutex::new(None),
    });
    cfg.selection.hook = Some(Hook(hook.clone()));
    cfg.outputs = Default::default();
    let rep = cli::in_pool(cfg.threads, |t| cli::check_staged(&cfg, t, &|_| {}, &mut Staged::new()))?;
    warn(a.quiet, &rep.warnings);
    if rep.parts.len() != plan.parts {
        return Err(usage(format!(
            "the inputs have {} parts, the plan {}: plan again",
            rep.parts.len(),
            plan.parts
        )));
    }
    let (outcome, trees) = hook
        .captured
        .lock()
        .expect("not poisoned")
        .take()
        .ok_or_else(|| usage("the check ran no assembly"))?;
    let report = ShardReport {
        schema: SHARD_SCHEMA.into(),
        plan_hash: plan_hash.into(),
        shard: i,
        shards: n,
        plan: plan.head(),
        pairs: mine.iter().map(|p| Covered { id: p.id.clone(), a: p.a, b: p.b }).collect(),
        error: None,
        outcome: Some(outcome),
        trees,
    };
    write_json(&a.output, &report, false)?;
    if !a.quiet {
        eprintln!("meshclash: shard {i}/{n}: {} of {} pairs", mine.len(), plan.work_pairs);
    }
    Ok(())
}

fn read_shard(path: &Path) -> Result<ShardReport> {
    let bytes = std::fs::read(path).map_err(|e| unreadable(path, Reading::ShardReport, &e))?;
    let v: serde_json::Value = serde_json::from_slice(&bytes)
        .map_err(|e| invalid(path, format!("shard report is not JSON: {e}")))?;
    if v.get("schema").and_then(|s| s.as_str()) != Some(SHARD_SCHEMA) {
        return Err(invalid(
            path,
            format!("not a {SHARD_SCHEMA} report (merge takes the files `meshclash run` writes)"),
        ));
    }
    serde_json::from_value(v).map_err(|e| invalid(path, format!("bad shard report: {e}")))
}

/// Check that the shard reports make one whole plan; returns them sorted by index and whether
/// some are missing (only with `allow_partial`).
pub fn validate(
    files: &[PathBuf],
    reports: Vec<ShardReport>,
    allow_partial: bool,
) -> Result<(Vec<ShardReport>, bool)> {
    // The plan most reports belong to (the first one's on a tie) decides which are foreign.
    let mut votes: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    for (k, r) in reports.iter().enumerate() {
        votes.entry(r.plan_hash.as_str()).or_insert((0, k)).0 += 1;
    }
    let (_, &(_, k0)) = votes
        .iter()
        .max_by_key(|(_, &(count, first))| (count, std::cmp::Reverse(first)))
        .expect("one report at least");
    let reference = &files[k0];
    let (hash, n) = (reports[k0].plan_hash.clone(), reports[k0].shards);
    let mut by_index: BTreeMap<usize, (usize, ShardReport)> = BTreeMap::new();
    for (k, r) in reports.into_iter().enumerate() {
        let f = &files[k];
        if r.plan_hash != hash {
            return Err(invalid(
                f,
                format!(
                    "foreign shard: it belongs to another plan (plan sha256 {}…, {} has {}…)",
                    &r.plan_hash[..12.min(r.plan_hash.len())],
                    reference.display(),
                    &hash[..12.min(hash.len())]
                ),
            ));
        }
        if r.shards != n {
            return Err(invalid(
                f,
                format!(
                    "shard {}/{} of a {n}-shard run ({} is one of {n})",
                    r.shard,
                    r.shards,
                    reference.display()
                ),
            ));
        }
        if let Some(e) = &r.error {
            return Err(invalid(f, format!("shard {}/{n} failed: {e}", r.shard)));
        }
        if r.shard == 0 || r.shard > n {
            return Err(invalid(f, format!("shard {}/{n} does not exist", r.shard)));
        }
        if let Some((other, _)) = by_index.get(&r.shard) {
            return Err(invalid(
                f,
                format!("duplicate shard {}/{n}: {} is the same shard", r.shard, files[*other].display()),
            ));
        }
        by_index.insert(r.shard, (k, r));
    }
    let missing: Vec<String> =
        (1..=n).filter(|i| !by_index.contains_key(i)).map(|i| format!("{i}/{n}")).collect();
    if !missing.is_empty() && !allow_partial {
        return Err(usage(format!(
            "missing shard{} {} of plan {}… (merge them all, or --allow-partial for a report marked incomplete)",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", "),
            &hash[..12.min(hash.len())]
        )));
    }
    let shards: Vec<ShardReport> = by_index.into_values().map(|(_, r)| r).collect();
    // Each pair once: shards of one plan partition it, so a repeat means a tampered report.
    let mut ids = std::collections::HashSet::new();
    for s in &shards {
        for c in &s.pairs {
            if !ids.insert(c.id.as_str()) {
                return Err(usage(format!(
                    "pair {} is in two shards (shard {}/{n} repeats it)",
                    c.id, s.shard
                )));
            }
        }
    }
    let plan = &shards[0].plan;
    if missing.is_empty() && ids.len() != plan.work_pairs {
        return Err(usage(format!("the shards cover {} pairs, the plan has {}", ids.len(), plan.work_pairs)));
    }
    Ok((shards, !missing.is_empty()))
}

fn merge_cmd(a: MergeArgs) -> Result<u8> {
    let reports = a.shards.iter().map(|p| read_shard(p)).collect::<Result<Vec<_>>>()?;
    let (shards, partial) = validate(&a.shards, reports, a.allow_partial)?;
    let plan = shards[0].plan.clone();
    let mut cfg = config_of(&plan.args)?;
    verify_inputs(&plan, &cfg)?;
    if let Some(t) = a.threads {
        cfg.threads = t;
    }
    cfg.output = a.output.clone();
    cfg.selection.hook = Some(Hook(Arc::new(MergeHook { plan, shards, partial })));
    if partial {
        return merge_partial(&cfg, a.quiet);
    }
    let out = cli::run_with_progress(&cfg, &|_| {})?;
    warn(a.quiet, &out.warnings);
    let written = match (&out.stdout, out.json_stdout) {
        (Some(text), _) => write::to_stdout(|w| w.write_all(text.as_bytes())),
        (None, true) => write::to_stdout(|w| meshclash::output::write_report_json(w, &out.report)),
        (None, false) => Ok(true),
    };
    written.map_err(|e| usage(format!("cannot write to stdout: {e}")))?;
    Ok(out.exit_code as u8)
}

/// `--allow-partial` with shards missing: the JSON report with `"complete": false` first.
fn merge_partial(cfg: &Config, quiet: bool) -> Result<u8> {
    if cfg.outputs.format.is_some_and(|f| f != meshclash::output::Format::Json) {
        return Err(conflict("allow-partial", "--allow-partial writes the JSON report only (no --format)"));
    }
    cli::check_outputs(cfg)?;
    let mut staged = Staged::new();
    let rep = cli::in_pool(cfg.threads, |t| cli::check_staged(cfg, t, &|_| {}, &mut staged))?;
    warn(quiet, &rep.warnings);
    let mut text = Vec::new();
    meshclash::output::write_report_json(&mut text, &rep)
        .map_err(|e| usage(format!("cannot serialise: {e}")))?;
    let text = String::from_utf8(text).expect("JSON is UTF-8");
    let text = match text.strip_prefix("{\n") {
        Some(rest) => format!("{{\n  \"complete\": false,\n{rest}"),
        None => text,
    };
    match &cfg.output {
        Some(p) => {
            staged.stage(p, text.as_bytes())?;
            staged.commit()?;
        }
        None => {
            staged.commit()?;
            write::to_stdout(|w| w.write_all(text.as_bytes()))
                .map_err(|e| usage(format!("cannot write to stdout: {e}")))?;
        }
    }
    if !quiet {
        eprintln!(
            "meshclash: warning: partial merge: shards are missing, the report says \"complete\": false"
        );
    }
    Ok(meshclash::error::ExitCode::from_failed(rep.failed) as u8)
}
