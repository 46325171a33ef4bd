//! `meshclash plan | run | merge`: the command-line side of [`meshclash::shard`].
//!
//! App layer: the check arguments of a plan are parsed by the ordinary [`super::args::Args`] into
//! the ordinary [`super::config::Config`], and every step runs the ordinary pipeline
//! ([`super::run::check`], [`super::run::run_with_progress`]) with a
//! [`meshclash::check::assembly::Hook`] in its selection.
//!
//! A plan carries the check, never its outputs: the files a step writes come from that step's
//! own command line (`merge --junit J --html H ...`), so an edited plan or shard report cannot
//! make the merging machine write anywhere.

use super::args::{Args, CheckArgs, Command, MergeArgs, PlanArgs, RunArgs};
use super::config::Config;
use super::run as cli;
use clap::Parser;
use meshclash::check::assembly::Hook;
use meshclash::error::{Error, InputProblem, Reading, Result, UsageProblem};
use meshclash::output::write::{self, Staged};
use meshclash::shard::plan::{self, Plan, PlanInput};
use meshclash::shard::{
    sha256, Covered, MergeHook, PlanHook, ShardHook, ShardReport, MAX_SHARDS, SHARD_SCHEMA,
};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Run `plan`, `run` or `merge`; the exit code (errors are printed here, exit 2).
pub fn dispatch(cmd: super::args::Command) -> u8 {
    use super::args::Command;
    let outcome = match cmd {
        Command::Plan(a) => plan_cmd(a),
        Command::Run(a) => run_cmd(a),
        Command::Merge(a) => merge_cmd(a),
        _ => unreachable!("only the shard steps come here"),
    };
    outcome.unwrap_or_else(|e| {
        eprintln!("meshclash: error: {e}");
        2
    })
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
/// refused: neither splits into part pairs; no output files: they are the merge's).
fn config_of(args: &[String]) -> Result<Config> {
    let cfg = parse_check(args)?.into_config()?;
    if let Some((flag, _)) = cfg.outputs.files().first() {
        return Err(conflict(
            flag.trim_start_matches("--"),
            format!("a plan carries the check, not its outputs: give {flag} to `meshclash merge`"),
        ));
    }
    if cfg.outputs.format.is_some() {
        return Err(conflict(
            "format",
            "a plan carries the check, not its outputs: give --format to `meshclash merge`",
        ));
    }
    if cfg.request.cross_check {
        return Err(conflict(
            "cross-check",
            "--cross-check runs parry on the whole inputs: it cannot be sharded",
        ));
    }
    if cfg.request.settings.first_hit {
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
    cfg.input_paths()
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
    let now = cfg.input_paths();
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
    write::check_outputs(&[("-o", &out)], &cfg.input_paths())?;
    let inputs = hash_inputs(&cfg)?;
    let hook = Arc::new(PlanHook { files: !cfg.request.selection.by_parts(), ..Default::default() });
    cfg.request.selection.hook = Some(Hook(hook.clone()));
    let (rep, _) = cli::in_pool(cfg.threads, |_| cli::check(&cfg, &|_| {}))?;
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
                    let i = i.checked_add(1).ok_or_else(|| usage(format!("{name}={v} is out of range")))?;
                    found = Some((name, i));
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
    if n > MAX_SHARDS {
        return Err(usage(format!("{n} shards: at most {MAX_SHARDS} shards of one plan")));
    }
    Ok((i, n))
}

fn read_plan(path: &Path) -> Result<(Plan, String)> {
    let bytes = meshclash::load::read_small_file(path, Reading::Plan, meshclash::load::MAX_SMALL_FILE_BYTES)?;
    let plan = Plan::parse(&bytes).map_err(|m| invalid(path, m))?;
    Ok((plan, sha256::hex(&bytes)))
}

fn run_cmd(a: RunArgs) -> Result<u8> {
    let (plan, plan_hash) = read_plan(&a.plan)?;
    let (i, n) = shard_index(a.shard.as_deref(), a.shards)?;
    // An output naming an input is refused before anything is written: the failure report
    // below must never replace the plan or a model.
    let cfg = config_of(&plan.args).ok();
    let mut inputs = cfg.as_ref().map(|c| c.input_paths()).unwrap_or_default();
    inputs.push(&a.plan);
    write::check_outputs(&[("-o", &a.output)], &inputs)?;
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
    // The plan is an input too: `-o` may not name it.
    let mut inputs = cfg.input_paths();
    inputs.push(&a.plan);
    write::check_outputs(&[("-o", &a.output)], &inputs)?;
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
        bvh: cfg.request.settings.bvh,
        parts: plan.parts,
        captured: Mutex::new(None),
    });
    cfg.request.selection.hook = Some(Hook(hook.clone()));
    let (rep, _) = cli::in_pool(cfg.threads, |_| cli::check(&cfg, &|_| {}))?;
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
    let bytes =
        meshclash::load::read_small_file(path, Reading::ShardReport, meshclash::load::MAX_SMALL_FILE_BYTES)?;
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

/// Check that the shard reports make one whole plan; returns them sorted by index and the
/// missing shards ("2/3"; some only with `allow_partial`).
pub fn validate(
    files: &[PathBuf],
    reports: Vec<ShardReport>,
    allow_partial: bool,
) -> Result<(Vec<ShardReport>, Vec<String>)> {
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
        if r.shards > MAX_SHARDS || r.shard > MAX_SHARDS {
            return Err(invalid(
                f,
                format!("shard {}/{}: at most {MAX_SHARDS} shards of one plan", r.shard, r.shards),
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
    Ok((shards, missing))
}

fn merge_cmd(a: MergeArgs) -> Result<u8> {
    let reports = a.shards.iter().map(|p| read_shard(p)).collect::<Result<Vec<_>>>()?;
    let (shards, missing) = validate(&a.shards, reports, a.allow_partial)?;
    let plan = shards[0].plan.clone();
    let mut cfg = config_of(&plan.args)?;
    verify_inputs(&plan, &cfg)?;
    if let Some(t) = a.threads {
        cfg.threads = t;
    }
    // The outputs are this command line's own; a baseline given here replaces the plan's.
    if a.outputs.baseline.is_some() {
        cfg.request.baseline = a.outputs.baseline.clone();
    }
    cfg.outputs = a.outputs.clone().into_options();
    cfg.output = a.output.clone();
    cfg.request.missing_shards = missing.clone();
    cfg.request.validate()?;
    let partial = !missing.is_empty();
    cfg.request.selection.hook = Some(Hook(Arc::new(MergeHook { plan, shards, partial })));
    // The shard reports are inputs: no output may name one.
    let mut outputs: Vec<write::Named> = cfg.output.iter().map(|p| ("-o", p.as_path())).collect();
    outputs.extend(cfg.outputs.files());
    let mut inputs = cfg.input_paths();
    inputs.extend(a.shards.iter().map(PathBuf::as_path));
    write::check_outputs(&outputs, &inputs)?;
    let out = cli::run_with_progress(&cfg, &|_| {})?;
    warn(a.quiet, &out.warnings);
    out.write_stdout().map_err(|e| usage(format!("cannot write to stdout: {e}")))?;
    out.staged.commit()?;
    if partial && !a.quiet {
        eprintln!(
            "meshclash: warning: partial merge: shard{} {} missing; the report says \"complete\": false and \
             the run fails",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", ")
        );
    }
    Ok(out.exit_code as u8)
}
