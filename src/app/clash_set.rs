//! Clash-set files: several named checks in one run (`meshclash clash-set FILE.json`).
//!
//! ```text
//! {
//!   "version": 1,
//!   "units": "mm",                          // optional: the report units of every check
//!   "defaults": {"clearance": 2},           // optional: any check field but name, a, b, scene
//!   "checks": [
//!     {"name": "engine vs frame", "a": "engine.glb", "b": "frame.stl", "units_b": "mm",
//!      "select_a": ["Engine/*"], "clearance": "0.5", "fail_on": "clearance"},
//!     {"name": "engine internal", "scene": "engine.glb", "exclude": ["*bolt*"]}
//!   ]
//! }
//! ```
//!
//! A check's fields are the command-line flags with `_` for `-` (`touch_tolerance` is
//! `--touch-tolerance`), plus `a` and `b` (the two files) or `scene` (one file, all-vs-all).
//! Paths (`a`, `b`, `scene`, `baseline`) are relative to the clash-set file's directory. Numbers
//! may be JSON numbers or strings (`"1e-6rel"`); either way their text is handed to the flag's
//! own parser, so `0.1` means exactly what `--clearance 0.1` means. Vectors (`translate_a`,
//! `transform_a`, ...) are arrays of numbers or the flag's comma-separated string. Unknown fields
//! are errors. The per-run flags (`--threads`, `--no-timings`, `-o`, `--format`, `--junit`,
//! `-q`) belong to the `clash-set` command line, not to the file; `export_glb` is not available.
//!
//! Each check is turned into the argument list of the equivalent `meshclash` command line and
//! parsed by the same [`super::args::Args`], validated by the same [`super::args::Args::into_config`]
//! and run by the same [`super::run::check`]: its report is byte for byte the report that
//! command prints. Every check is validated before any runs, and nothing is written unless every
//! check ran.

use super::args::Args;
use super::args::Unit;
pub use super::args::{ClashSetArgs, SchemaKind, SetFormat};
use super::config;
use super::progress::Phase;
use super::run;
use clap::Parser as _;
use meshclash::error::{CheckRef, Error, InputProblem, Location, Reading, Result, UsageProblem};
use meshclash::output::junit;
use meshclash::report;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer};
use serde_json::value::RawValue;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub use meshclash::report::clash_set::{CheckReport, ClashSetReport, SCHEMA};

/// The clash-set file version this build reads.
pub const VERSION: u32 = 1;

/// A number as its JSON text (or the content of a JSON string): handed unchanged to the flag's
/// parser, so no precision is lost between the file and the check.
#[derive(Debug, Clone, PartialEq)]
pub struct Num(pub String);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let raw: Box<RawValue> = Deserialize::deserialize(d)?;
        let t = raw.get().trim();
        if t.starts_with('"') {
            serde_json::from_str::<String>(t).map(Num).map_err(D::Error::custom)
        } else if t.starts_with(|c: char| c == '-' || c.is_ascii_digit()) {
            Ok(Num(t.to_string()))
        } else {
            Err(D::Error::custom(format!("expected a number or a string, got {t}")))
        }
    }
}

impl schemars::JsonSchema for Num {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "NumberOrString".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "description": "A number, or a string holding what the command-line flag takes (e.g. \"1e-6rel\")",
            "type": ["number", "string"]
        })
    }
}

/// A list of numbers (array, or the flag's comma-separated string), kept as `x,y,z` text.
#[derive(Debug, Clone, PartialEq)]
pub struct Numbers(pub String);

impl<'de> Deserialize<'de> for Numbers {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let raw: Box<RawValue> = Deserialize::deserialize(d)?;
        let t = raw.get().trim();
        if t.starts_with('[') {
            let v: Vec<Num> = serde_json::from_str(t).map_err(D::Error::custom)?;
            Ok(Numbers(v.into_iter().map(|n| n.0).collect::<Vec<_>>().join(",")))
        } else if t.starts_with('"') {
            serde_json::from_str::<String>(t).map(Numbers).map_err(D::Error::custom)
        } else {
            Err(D::Error::custom(format!("expected an array of numbers or a string, got {t}")))
        }
    }
}

impl schemars::JsonSchema for Numbers {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Numbers".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "description": "An array of numbers, or the flag's comma-separated string",
            "oneOf": [
                {"type": "array", "items": {"type": ["number", "string"]}},
                {"type": "string"}
            ]
        })
    }
}

/// One check of a clash-set file (and the `defaults` block, which may not have `name`, `a`,
/// `b` or `scene`). Every field but `name`, `a`, `b`, `scene` is the command-line flag of the same
/// name (with `-` for `_`) and is validated by it.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CheckSpec {
    /// Unique, non-empty name (the JUnit test suite, the line of the text summary).
    pub name: Option<String>,
    /// First file (relative to the clash-set file's directory).
    pub a: Option<String>,
    /// Second file.
    pub b: Option<String>,
    /// In place of `a` and `b`: one file, its parts checked against each other.
    pub scene: Option<String>,
    /// `--units`: report units of this check (overrides the file's top-level `units`).
    pub units: Option<Unit>,
    /// `--units-a` (in scene mode: the file's units).
    pub units_a: Option<Unit>,
    /// `--units-b`.
    pub units_b: Option<Unit>,
    /// `--scale-a`.
    pub scale_a: Option<Num>,
    /// `--scale-b`.
    pub scale_b: Option<Num>,
    /// `--translate-a`: [x, y, z].
    pub translate_a: Option<Numbers>,
    /// `--translate-b`.
    pub translate_b: Option<Numbers>,
    /// `--transform-a`: 12 or 16 numbers, row-major.
    pub transform_a: Option<Numbers>,
    /// `--transform-b`.
    pub transform_b: Option<Numbers>,
    /// `--touch-tolerance` (number, or string with a `rel` suffix).
    pub touch_tolerance: Option<Num>,
    /// `--clearance`.
    pub clearance: Option<Num>,
    /// `--fail-on`: clash, touching, clearance, never, new.
    pub fail_on: Option<String>,
    /// `--mode`: exact, fast.
    pub mode: Option<String>,
    /// `--bvh`: sah, median, equal.
    pub bvh: Option<String>,
    /// `--leaf-size`.
    pub leaf_size: Option<Num>,
    /// `--max-pairs`.
    pub max_pairs: Option<Num>,
    /// `--first-hit`.
    pub first_hit: Option<bool>,
    /// `--detail`: pairs, parts.
    pub detail: Option<String>,
    /// `--split-bodies`.
    pub split_bodies: Option<bool>,
    /// `--penetration`.
    pub penetration: Option<bool>,
    /// `--distance-rel-err`.
    pub distance_rel_err: Option<Num>,
    /// `--distance-abs-err`.
    pub distance_abs_err: Option<Num>,
    /// `--select-a` globs.
    pub select_a: Option<Vec<String>>,
    /// `--select-b` globs.
    pub select_b: Option<Vec<String>>,
    /// `--exclude` globs.
    pub exclude: Option<Vec<String>>,
    /// `--cross-check`: parry.
    pub cross_check: Option<String>,
    /// `--baseline`: an earlier report of this check (relative to the clash-set file).
    pub baseline: Option<String>,
}

/// The clash-set file (for its JSON Schema; parsing goes check by check, see [`load`]).
#[derive(Debug, Clone, PartialEq, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ClashSetFile {
    /// Always 1.
    pub version: u32,
    /// Report units of every check (a check's own `units` wins); same as `defaults.units`.
    pub units: Option<Unit>,
    /// Fields applied to every check that does not set them.
    pub defaults: Option<CheckSpec>,
    /// The checks, run in order.
    pub checks: Vec<CheckSpec>,
}

/// The top level with each check kept as raw text, so that an error can name its check.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile<'a> {
    version: u32,
    #[serde(default)]
    units: Option<Unit>,
    #[serde(default, borrow)]
    defaults: Option<&'a RawValue>,
    #[serde(borrow)]
    checks: Vec<&'a RawValue>,
}

/// Only the name of a check, read leniently for error messages.
#[derive(Deserialize)]
struct NameOnly {
    name: Option<serde_json::Value>,
}

/// A validated check: its name, the argument list it stands for, and its configuration.
#[derive(Debug, Clone)]
pub struct Check {
    /// The check's name.
    pub name: String,
    /// The equivalent command line (argv\[0\] is `meshclash`).
    #[cfg_attr(not(test), allow(dead_code))]
    pub argv: Vec<OsString>,
    /// What [`super::args::Args::into_config`] made of it.
    pub config: config::Config,
}

/// A rule of the clash-set format broken in `file` (at `at`).
fn invalid(file: &Path, at: Option<Location>, msg: impl Into<String>) -> Error {
    Error::located(file, at, InputProblem::Invalid(msg.into()))
}

/// A serde_json error inside the text `sub` (a slice of `text`), located in `text`.
fn located(text: &str, sub: &str, e: &serde_json::Error) -> String {
    let msg = e.to_string();
    let msg = match msg.rfind(" at line ") {
        Some(i) if e.line() > 0 => msg[..i].to_string(),
        _ => return msg,
    };
    let base = (sub.as_ptr() as usize).saturating_sub(text.as_ptr() as usize).min(text.len());
    let before = &text[..base];
    let base_line = before.matches('\n').count() + 1;
    let base_col = before.len() - before.rfind('\n').map_or(0, |i| i + 1);
    let line = base_line + e.line() - 1;
    let col = if e.line() == 1 { base_col + e.column() } else { e.column() };
    format!("{msg} at line {line} column {col}")
}

fn check_label(raw: &RawValue, i: usize) -> CheckRef {
    match serde_json::from_str::<NameOnly>(raw.get()).ok().and_then(|n| n.name) {
        Some(serde_json::Value::String(s)) => CheckRef::Name(s),
        _ => CheckRef::Number(i + 1),
    }
}

/// Fill the fields `c` does not set from `d`.
fn merge(c: &mut CheckSpec, d: &CheckSpec) {
    macro_rules! take {
        ($($f:ident),*) => { $( if c.$f.is_none() { c.$f = d.$f.clone(); } )* };
    }
    take!(
        units,
        units_a,
        units_b,
        scale_a,
        scale_b,
        translate_a,
        translate_b,
        transform_a,
        transform_b,
        touch_tolerance,
        clearance,
        fail_on,
        mode,
        bvh,
        leaf_size,
        max_pairs,
        first_hit,
        detail,
        split_bodies,
        penetration,
        distance_rel_err,
        distance_abs_err,
        select_a,
        select_b,
        exclude,
        cross_check,
        baseline
    );
}

/// A path from the file, relative to the clash-set file's directory `dir` (`""` for the current
/// one). A relative path that would read as the word `scene` gets a `./`.
fn resolve(dir: &Path, p: &str) -> PathBuf {
    let joined = dir.join(p);
    if joined.as_os_str() == "scene" {
        PathBuf::from("./scene")
    } else {
        joined
    }
}

fn flag(name: &str, value: &str) -> OsString {
    OsString::from(format!("--{name}={value}"))
}

/// The equivalent command line of check `c` (already merged with the defaults).
pub fn argv(c: &CheckSpec, dir: &Path, run: &ClashSetArgs) -> std::result::Result<Vec<OsString>, String> {
    let mut v: Vec<OsString> = vec!["meshclash".into()];
    macro_rules! text {
        ($($f:ident => $name:literal),*) => { $( if let Some(x) = &c.$f { v.push(flag($name, &x.0)); } )* };
    }
    text!(
        scale_a => "scale-a", scale_b => "scale-b",
        translate_a => "translate-a", translate_b => "translate-b",
        transform_a => "transform-a", transform_b => "transform-b",
        touch_tolerance => "touch-tolerance", clearance => "clearance",
        leaf_size => "leaf-size", max_pairs => "max-pairs",
        distance_rel_err => "distance-rel-err", distance_abs_err => "distance-abs-err"
    );
    macro_rules! unit {
        ($($f:ident => $name:literal),*) => { $( if let Some(u) = c.$f { v.push(flag($name, u.name())); } )* };
    }
    unit!(units => "units", units_a => "units-a", units_b => "units-b");
    macro_rules! word {
        ($($f:ident => $name:literal),*) => { $( if let Some(x) = &c.$f { v.push(flag($name, x)); } )* };
    }
    word!(fail_on => "fail-on", mode => "mode", bvh => "bvh", detail => "detail", cross_check => "cross-check");
    macro_rules! list {
        ($($f:ident => $name:literal),*) => { $( for g in c.$f.iter().flatten() { v.push(flag($name, g)); } )* };
    }
    list!(select_a => "select-a", select_b => "select-b", exclude => "exclude");
    macro_rules! switch {
        ($($f:ident => $name:literal),*) => { $( if c.$f == Some(true) { v.push($name.into()); } )* };
    }
    switch!(first_hit => "--first-hit", split_bodies => "--split-bodies", penetration => "--penetration");
    if let Some(b) = &c.baseline {
        let mut f = OsString::from("--baseline=");
        f.push(resolve(dir, b).as_os_str());
        v.push(f);
    }
    v.push(flag("threads", &run.threads.to_string()));
    if run.no_timings {
        v.push("--no-timings".into());
    }
    if let Some(dir) = &run.cache {
        // As given on the command line: relative to the working directory, not to the file.
        let mut f = OsString::from("--cache=");
        f.push(dir.as_os_str());
        v.push(f);
    }
    if let Some(n) = run.cache_max_bytes {
        v.push(flag("cache-max-bytes", &n.to_string()));
    }
    v.push("--".into());
    match (&c.a, &c.b, &c.scene) {
        (Some(a), Some(b), None) => {
            v.push(resolve(dir, a).into_os_string());
            v.push(resolve(dir, b).into_os_string());
        }
        (None, None, Some(s)) => {
            v.push("scene".into());
            v.push(resolve(dir, s).into_os_string());
        }
        _ => return Err("needs \"a\" and \"b\" (two files) or \"scene\" (one file), not both".into()),
    }
    Ok(v)
}

/// Read and validate the clash-set file `file`: every check parsed, merged with the defaults,
/// turned into its command line and validated into a [`config::Config`]. Any problem is an
/// [`Error::Input`] naming the file and the check.
pub fn load(file: &Path, run: &ClashSetArgs) -> Result<Vec<Check>> {
    let bytes =
        meshclash::load::read_small_file(file, Reading::ClashSet, meshclash::load::MAX_SMALL_FILE_BYTES)?;
    let text =
        String::from_utf8(bytes).map_err(|_| Error::in_file(file, InputProblem::NotUtf8 { byte: None }))?;
    parse(file, &text, run)
}

/// [`load`] on the file's text.
pub fn parse(file: &Path, text: &str, run: &ClashSetArgs) -> Result<Vec<Check>> {
    let syntax = |at: Option<Location>, sub: &str, e: &serde_json::Error| {
        Error::located(file, at, InputProblem::Syntax(located(text, sub, e)))
    };
    let top: RawFile = serde_json::from_str(text).map_err(|e| syntax(None, text, &e))?;
    if top.version != VERSION {
        let msg =
            format!("version {} is not supported (this meshclash reads version {VERSION})", top.version);
        return Err(invalid(file, None, msg));
    }
    if top.checks.is_empty() {
        return Err(invalid(file, None, "\"checks\" is empty"));
    }
    let mut defaults = match top.defaults {
        Some(raw) => serde_json::from_str::<CheckSpec>(raw.get())
            .map_err(|e| syntax(Some(Location::Defaults), raw.get(), &e))?,
        None => CheckSpec::default(),
    };
    if defaults.name.is_some() || defaults.a.is_some() || defaults.b.is_some() || defaults.scene.is_some() {
        let msg = "\"name\", \"a\", \"b\" and \"scene\" belong to each check";
        return Err(invalid(file, Some(Location::Defaults), msg));
    }
    if let Some(u) = top.units {
        if defaults.units.is_some() {
            return Err(invalid(file, None, "\"units\" is given both at the top level and in \"defaults\""));
        }
        defaults.units = Some(u);
    }
    let dir = file.parent().unwrap_or(Path::new(""));
    let mut checks: Vec<Check> = Vec::with_capacity(top.checks.len());
    for (i, raw) in top.checks.iter().enumerate() {
        let at = Some(Location::Check(check_label(raw, i)));
        let fail = |m: String| invalid(file, at.clone(), m);
        // The check's own error, as it would be on the command line.
        let in_check = |e: Error| Error::located(file, at.clone(), InputProblem::InCheck(Box::new(e)));
        let mut spec: CheckSpec =
            serde_json::from_str(raw.get()).map_err(|e| syntax(at.clone(), raw.get(), &e))?;
        let name = match spec.name.take() {
            Some(n) if !n.trim().is_empty() => n,
            Some(_) => return Err(fail("\"name\" is empty".into())),
            None => return Err(fail("has no \"name\"".into())),
        };
        if let Some(j) = checks.iter().position(|c| c.name == name) {
            return Err(fail(format!("the name is used twice (checks #{} and #{})", j + 1, i + 1)));
        }
        merge(&mut spec, &defaults);
        let argv = argv(&spec, dir, run).map_err(&fail)?;
        let args = Args::try_parse_from(&argv).map_err(|e| {
            let m = e.to_string();
            let m = m.lines().next().unwrap_or("bad value").trim_start_matches("error: ").trim().to_string();
            in_check(Error::usage(UsageProblem::Invalid(m)))
        })?;
        let config = args.into_config().map_err(in_check)?;
        checks.push(Check { name, argv, config });
    }
    Ok(checks)
}

/// What the binary should do after a successful clash-set run.
#[derive(Debug, Clone, PartialEq)]
pub struct SetOutcome {
    /// What goes to stdout (None: the document went to `-o` and no `--format` was given).
    pub stdout: Option<String>,
    /// Warnings for stderr, each prefixed with its check.
    pub warnings: Vec<String>,
    /// 0, or 1 if any check failed.
    pub exit_code: u8,
    /// The document.
    pub report: ClashSetReport,
}

/// The JSON Schema of the clash-set file or of the output document, with a trailing newline.
pub fn schema_json(kind: SchemaKind) -> String {
    let schema = match kind {
        SchemaKind::File => schemars::schema_for!(ClashSetFile),
        SchemaKind::Output => schemars::schema_for!(ClashSetReport),
    };
    let mut s = serde_json::to_string_pretty(&schema).expect("schema serialises");
    s.push('\n');
    s
}

/// Run every check of `args.file`, then write the outputs. Bad input in any check is an error
/// and nothing is written.
pub fn run_with_progress(args: &ClashSetArgs, progress: &(dyn Fn(Phase) + Sync)) -> Result<SetOutcome> {
    let file =
        args.file.as_deref().ok_or_else(|| Error::usage(UsageProblem::Missing("clash-set FILE".into())))?;
    let checks = load(file, args)?;
    let outputs: Vec<meshclash::output::write::Named> = [("-o", &args.output), ("--junit", &args.junit)]
        .into_iter()
        .filter_map(|(f, p)| Some((f, p.as_deref()?)))
        .collect();
    let mut inputs = vec![file];
    inputs.extend(checks.iter().flat_map(|c| c.config.input_paths()));
    meshclash::output::write::check_outputs(&outputs, &inputs)?;
    let entries = run::in_pool(args.threads, |_| {
        checks
            .iter()
            .map(|c| {
                // A check of a clash set names no output files: nothing is staged.
                let rep = run::check(&c.config, progress).map(|(rep, _)| rep).map_err(|e| {
                    let at = Location::Check(CheckRef::Name(c.name.clone()));
                    Error::at(file, at, InputProblem::InCheck(Box::new(e)))
                })?;
                Ok(CheckReport { name: c.name.clone(), report: rep })
            })
            .collect::<Result<Vec<_>>>()
    })?;
    let doc = ClashSetReport {
        schema: SCHEMA.into(),
        tool: report::Tool::this(),
        file: file.display().to_string(),
        failed: entries.iter().any(|c| c.report.failed),
        checks: entries,
    };
    let mut staged = meshclash::output::write::Staged::new();
    if let Some(path) = &args.junit {
        staged.stage(path, junit_xml(&doc).as_bytes())?;
    }
    if let Some(path) = &args.output {
        staged.stage_with(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &doc)?;
            std::io::Write::write_all(w, b"\n")
        })?;
    }
    staged.commit()?;
    let stdout = match args.format {
        None if args.output.is_some() => None,
        None | Some(SetFormat::Json) => Some(to_json(&doc)),
        Some(SetFormat::Text) => Some(summary(&doc)),
        Some(SetFormat::Junit) => Some(junit_xml(&doc)),
    };
    let warnings = doc
        .checks
        .iter()
        .flat_map(|c| c.report.warnings.iter().map(move |w| format!("check '{}': {w}", c.name)))
        .collect();
    Ok(SetOutcome { stdout, warnings, exit_code: doc.failed as u8, report: doc })
}

/// The document as pretty JSON with a trailing newline.
pub fn to_json(doc: &ClashSetReport) -> String {
    let mut s = serde_json::to_string_pretty(doc).expect("clash-set report serialises");
    s.push('\n');
    s
}

/// The text summary: one line per check, then a total line.
pub fn summary(doc: &ClashSetReport) -> String {
    let mut s = String::new();
    for c in &doc.checks {
        let r = &c.report;
        let m = &r.summary;
        let _ = write!(
            s,
            "{}: {} {} (--fail-on {}): {} crossing, {} touching, {} clearance pairs",
            c.name,
            r.verdict.name().to_uppercase(),
            if r.failed { "FAILED" } else { "passed" },
            r.settings.fail_on,
            m.crossing_pairs,
            m.touching_pairs,
            m.clearance_pairs
        );
        if let Some(ct) = &m.contained {
            let _ = write!(s, ", contained: {ct}");
        }
        match m.min_distance {
            Some(d) if r.settings.units == "model" => {
                let _ = write!(s, ", min distance {}", meshclash::output::text::num(d));
            }
            Some(d) => {
                let _ = write!(s, ", min distance {} {}", meshclash::output::text::num(d), r.settings.units);
            }
            None => {}
        }
        s.push('\n');
    }
    let failed = doc.checks.iter().filter(|c| c.report.failed).count();
    let _ = writeln!(
        s,
        "meshclash clash-set {}: {} check{}, {} failed",
        doc.file,
        doc.checks.len(),
        if doc.checks.len() == 1 { "" } else { "s" },
        failed
    );
    s
}

/// JUnit XML: one `<testsuite>` per check, named after it, holding the test cases the single
/// command's `--junit` would write for that check.
pub fn junit_xml(doc: &ClashSetReport) -> String {
    let mut suites = String::new();
    let (mut tests, mut failures, mut time) = (0usize, 0usize, 0.0f64);
    for c in &doc.checks {
        let cases = junit::cases(&c.report);
        tests += cases.len();
        failures += cases.iter().filter(|k| k.failed).count();
        time += cases.iter().map(|k| k.time_s).sum::<f64>();
        // `junit::render` writes a whole document around one suite: keep the suite.
        let one = junit::render(&c.name, &cases);
        suites.push_str(suite_of(&one));
    }
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        s,
        "<testsuites name=\"{}\" tests=\"{tests}\" failures=\"{failures}\" errors=\"0\" time=\"{time}\">",
        junit::escape(&format!("meshclash clash-set {}", doc.file))
    );
    s.push_str(&suites);
    s.push_str("</testsuites>\n");
    s
}

/// The `<testsuite>` element (with its line breaks) of a document [`junit::render`] wrote: the
/// text between the `<testsuites ...>` line and the closing `</testsuites>`.
fn suite_of(doc: &str) -> &str {
    let start = doc.find("<testsuites").and_then(|i| doc[i..].find('\n').map(|j| i + j + 1)).unwrap_or(0);
    let end = doc.rfind("</testsuites>").unwrap_or(doc.len());
    &doc[start..end.max(start)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> ClashSetArgs {
        ClashSetArgs { threads: 1, no_timings: true, ..ClashSetArgs::default() }
    }

    fn parse_str(text: &str) -> Result<Vec<Check>> {
        parse(Path::new("sets/cs.json"), text, &run())
    }

    fn message(text: &str) -> String {
        parse_str(text).unwrap_err().to_string()
    }

    #[test]
    fn checks_become_their_command_lines() {
        let cs = parse_str(
            r#"{"version": 1, "units": "mm", "defaults": {"clearance": 2, "exclude": ["*bolt*"]},
                "checks": [
                  {"name": "one", "a": "x.obj", "b": "/abs/y.stl", "units_a": "in", "scale_b": 0.5,
                   "translate_b": [1, -2.5, 3e2], "touch_tolerance": "1e-6rel", "fail_on": "touching",
                   "first_hit": true, "select_a": ["p*", "q?"]},
                  {"name": "two", "scene": "../s.glb", "clearance": 0.1, "exclude": [], "penetration": true}
                ]}"#,
        )
        .unwrap();
        let line = |c: &Check| c.argv.iter().map(|a| a.to_string_lossy().into_owned()).collect::<Vec<_>>();
        assert_eq!(
            line(&cs[0]),
            [
                "meshclash",
                "--scale-b=0.5",
                "--translate-b=1,-2.5,3e2",
                "--touch-tolerance=1e-6rel",
                "--clearance=2",
                "--units=mm",
                "--units-a=in",
                "--fail-on=touching",
                "--select-a=p*",
                "--select-a=q?",
                "--exclude=*bolt*",
                "--first-hit",
                "--threads=1",
                "--no-timings",
                "--",
                "sets/x.obj",
                "/abs/y.stl",
            ]
        );
        // The check's own value wins over the defaults, an empty list included.
        assert_eq!(
            line(&cs[1]),
            [
                "meshclash",
                "--clearance=0.1",
                "--units=mm",
                "--penetration",
                "--threads=1",
                "--no-timings",
                "--",
                "scene",
                "sets/../s.glb"
            ]
        );
        let c = &cs[0].config;
        assert_eq!(c.request.clearance, meshclash::pipeline::Tolerance::Abs(2.0));
        assert_eq!(c.request.touch, meshclash::pipeline::Tolerance::Rel(1e-6));
        assert_eq!(c.request.units.report, Some(Unit::Mm));
        assert_eq!(c.request.units.inputs, [Some(Unit::In), None]);
        assert_eq!(c.request.units.scale, [None, Some(0.5)]);
        assert!(cs[1].config.request.selection.scene);
        assert!(cs[1].config.request.selection.exclude.is_empty());
    }

    #[test]
    fn numbers_keep_their_text() {
        // 0.1 + 1 ulp: 17 significant digits, beyond the 2^53 significand of a float parser's
        // fast path; the flag's own (correctly rounded) parser sees the text.
        let cs = parse_str(
            r#"{"version": 1, "checks": [{"name": "n", "a": "a.obj", "b": "b.obj", "clearance": 0.10000000000000002}]}"#,
        )
        .unwrap();
        assert_eq!(
            cs[0].config.request.clearance,
            meshclash::pipeline::Tolerance::Abs(f64::from_bits(0.1f64.to_bits() + 1))
        );
    }

    #[test]
    fn a_file_named_scene_stays_a_file() {
        let cs = parse(
            Path::new("cs.json"),
            r#"{"version": 1, "checks": [{"name": "n", "a": "scene", "b": "b.obj"}]}"#,
            &run(),
        )
        .unwrap();
        assert!(!cs[0].config.request.selection.scene);
        assert_eq!(cs[0].config.request.inputs[0].path(), Path::new("./scene"));
    }

    #[test]
    fn errors_name_the_file_and_the_check() {
        let m = message(
            r#"{"version": 1, "checks": [{"name": "x", "a": "a", "b": "b"}, {"name": "x", "scene": "s"}]}"#,
        );
        assert_eq!(m, "sets/cs.json: check 'x': the name is used twice (checks #1 and #2)");
        // The position is in the whole file: the same as parsing the whole file in one go.
        let text = "{\"version\": 1, \"checks\": [\n{\"name\": \"good\", \"a\": \"a\", \"b\": \"b\"},\n  {\"name\": \"bad\", \"a\": \"a\", \"b\": \"b\", \"colour\": 1}]}";
        let m = message(text);
        assert!(m.starts_with("sets/cs.json: check 'bad': unknown field `colour`"), "{m}");
        let whole = serde_json::from_str::<ClashSetFile>(text).unwrap_err();
        assert_eq!(whole.line(), 3);
        assert!(m.ends_with(&format!("at line 3 column {}", whole.column())), "{m} vs {whole}");
        let m = message(r#"{"version": 1, "checks": [{"a": "a", "b": "b"}]}"#);
        assert_eq!(m, "sets/cs.json: check #1: has no \"name\"");
        let m = message(r#"{"version": 1, "checks": [{"name": "t", "a": "a", "b": "b", "leaf_size": 0}]}"#);
        assert_eq!(m, "sets/cs.json: check 't': --leaf-size must be 1..=64, got 0");
        let m = message(r#"{"version": 1, "checks": [{"name": "t", "a": "a", "b": "b", "mode": "slow"}]}"#);
        assert!(m.starts_with("sets/cs.json: check 't': invalid value 'slow' for '--mode"), "{m}");
        let m = message(r#"{"version": 1, "checks": [{"name": "t", "a": "a", "scene": "s"}]}"#);
        assert!(m.contains("check 't': needs \"a\" and \"b\""), "{m}");
        let m =
            message(r#"{"version": 1, "checks": [{"name": "t", "a": "a", "b": "b", "units": "furlong"}]}"#);
        assert!(m.contains("check 't': unknown variant `furlong`"), "{m}");
        let m = message(r#"{"version": 1, "checks": [{"name": "t", "a": "a", "b": "b", "scale_a": -1}]}"#);
        assert_eq!(m, "sets/cs.json: check 't': --scale-a must be a finite number > 0, got -1");
        assert!(message(r#"{"version": 2, "checks": []}"#).contains("version 2 is not supported"));
        assert!(message(r#"{"version": 1, "checks": []}"#).contains("\"checks\" is empty"));
        assert!(message(
            r#"{"version": 1, "defaults": {"a": "x"}, "checks": [{"name": "t", "scene": "s"}]}"#
        )
        .contains("defaults: \"name\", \"a\""));
        assert!(message(r#"{"version": 1, "extra": 0, "checks": []}"#).contains("unknown field `extra`"));
        // Every message is one line.
        assert!(!message("{\n\"version\": 1,\n\"checks\": [\n{\"name\": 3}]}").contains('\n'));
    }

    #[test]
    fn junit_suites_are_cut_from_whole_documents() {
        let case = junit::Case {
            name: "a vs b".into(),
            verdict: "clash".into(),
            counts: "1 crossing".into(),
            findings: vec!["crossing".into()],
            total: 1,
            failed: true,
            time_s: 0.0,
            output: "line 1\nline 2\n".into(),
        };
        let doc = junit::render("check <1>", &[case]);
        let suite = suite_of(&doc);
        assert!(suite.starts_with("  <testsuite name=\"check &lt;1&gt;\""), "{suite}");
        assert!(suite.ends_with("  </testsuite>\n"), "{suite}");
        assert_eq!(suite.matches("<testcase").count(), 1);
    }
}
