//! Command-line definition (clap): the flags of the main check, the subcommands, and the value
//! enums. Validation into a [`super::config::Config`] is in [`super::config`].

use clap::{Parser, ValueEnum};

use meshclash::output::bcf::Topics;
use meshclash::output::{Format, OutputOptions};
use meshclash::report::self_report::SelfFailOn;
use std::path::PathBuf;

/// Do two meshes clash, where, and how close do they come? Reads OBJ, STL (ASCII or binary) and
/// glTF (.gltf/.glb); writes a JSON report. Exit code: 0 nothing at or above --fail-on,
/// 1 findings at or above it, 2 bad input, I/O or usage error.
#[derive(Debug, Parser)]
#[command(
    name = "meshclash",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    /// First mesh (A).
    #[arg(required = true)]
    pub a: Option<PathBuf>,
    /// Second mesh (B).
    #[arg(required = true)]
    pub b: Option<PathBuf>,
    /// `scene`, `clash-set`, `self`, `plan`, `run`, `merge`, `schema`, `completions <shell>`,
    /// `man` or `bench` instead of a two-file check.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The check's flags (shared with `scene`).
    #[command(flatten)]
    pub check: CheckArgs,
}

/// The flags of a check (two files, or `scene FILE`).
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// Write the report to FILE (atomically) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Move A by x,y,z (after --transform-a).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub translate_a: Option<String>,
    /// Move B by x,y,z (after --transform-b).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub translate_b: Option<String>,
    /// Affine transform of A: 12 (3×4) or 16 (4×4, last row 0,0,0,1) comma-separated numbers, row-major.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub transform_a: Option<String>,
    /// Affine transform of B, as --transform-a.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub transform_b: Option<String>,
    /// Pairs that do not touch but are within this distance count as touching: in the report
    /// units (--units, else the files' own), or relative to the model size with a `rel` suffix (`1e-6rel` = 1e-6 × the diagonal of the
    /// box around both inputs).
    #[arg(long, value_name = "E", default_value = "0", allow_hyphen_values = true)]
    pub touch_tolerance: String,
    /// Also report every pair closer than D that does not touch (report units, or `rel` suffix).
    #[arg(long, value_name = "D", default_value = "0", allow_hyphen_values = true)]
    pub clearance: String,
    /// Exit 1 when the verdict is at or above this.
    #[arg(long, value_enum, default_value_t = FailOnArg::Clash)]
    pub fail_on: FailOnArg,
    /// BVH split strategy.
    #[arg(long, value_enum, default_value_t = BvhArg::Sah)]
    pub bvh: BvhArg,
    /// Largest BVH leaf, in triangles (1..=64).
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub leaf_size: u32,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// List at most N pairs (the summary counts stay complete).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub max_pairs: usize,
    /// Also run parry3d-f64 on the same input and add a `cross_check` block listing every
    /// disagreement (slow on large overlapping meshes: parry's distance is not a dual walk).
    #[arg(long, value_enum, value_name = "TOOL")]
    pub cross_check: Option<CrossCheckArg>,
    /// Pair classification: `exact` predicates, or `fast` plain f64 determinants (gives up
    /// exactness on nearly touching or coplanar pairs; `meshclash-bench --trade` measures it).
    #[arg(long, value_enum, default_value_t = ModeArg::Exact)]
    pub mode: ModeArg,
    /// Stop at the first crossing pair: a quick pass/fail gate. Counts become lower bounds,
    /// no distance or containment is computed, and which pair is listed depends on timing.
    #[arg(long)]
    pub first_hit: bool,
    /// What the report lists: `pairs` (default) every meeting triangle pair (up to
    /// --max-pairs shown) and the clash regions made from them; `parts` only each part pair's
    /// verdict, counts and closest points — the same verdicts and counts, memory that no longer
    /// grows with the number of meeting triangle pairs, no regions (so no --html,
    /// --export-glb, --baseline or region topics in --bcf).
    #[arg(long, value_enum, value_name = "WHAT", default_value_t = DetailArg::Pairs)]
    pub detail: DetailArg,
    /// Split every part into its connected bodies (triangles joined through edges used by
    /// exactly two triangles), named `part/body1`, `part/body2`, …: e.g. two cubes in one STL
    /// solid that touch along an edge become two parts.
    #[arg(long)]
    pub split_bodies: bool,
    /// Estimate each clash region's penetration depth: the deepest vertex of one part inside
    /// the other closed part, measured to its surface (a lower bound; costs a tree per part
    /// with a region and point queries, at most about 2048 per region and side).
    #[arg(long)]
    pub penetration: bool,
    /// Allowed relative error of the minimum distance (reported d <= (1+R)·true + A).
    #[arg(long, value_name = "R", default_value_t = 0.0)]
    pub distance_rel_err: f64,
    /// Allowed absolute error of the minimum distance (report units).
    #[arg(long, value_name = "A", default_value_t = 0.0)]
    pub distance_abs_err: f64,
    /// Check only parts of A whose name matches GLOB (`*`, `?`; repeatable). Part names are
    /// glTF node paths (`Engine/Piston_2`), OBJ `o`/`g` names, STL solid names.
    #[arg(long, value_name = "GLOB")]
    pub select_a: Vec<String>,
    /// Check only parts of B matching GLOB (in scene mode: the second set; without it, the
    /// selected parts are checked all-vs-all).
    #[arg(long, value_name = "GLOB")]
    pub select_b: Vec<String>,
    /// Leave out parts matching GLOB, on both sides (repeatable).
    #[arg(long, value_name = "GLOB")]
    pub exclude: Vec<String>,
    /// Deterministic report: no timings, no thread count (byte-identical across runs).
    #[arg(long)]
    pub no_timings: bool,
    /// Units of the report: every input is converted into U (multiplied in f64 after loading,
    /// before --transform/--translate, which are therefore in U), and all coordinates,
    /// distances and tolerances are in U. Inputs of unknown units (OBJ, STL, without
    /// --units-a/-b) are taken to be in U, with a warning. Verdicts are exact for the converted
    /// coordinates (a factor that is not a power of two rounds each coordinate once). Default:
    /// --units-a, else --units-b, else none: no conversion, lengths in the files' own units.
    #[arg(long, value_name = "U", value_parser = unit_parser())]
    pub units: Option<Unit>,
    /// Units of A's coordinates [default: m for glTF/GLB (the glTF specification), unknown for
    /// OBJ/STL]. In scene mode, the units of the file.
    #[arg(long, value_name = "U", value_parser = unit_parser())]
    pub units_a: Option<Unit>,
    /// Units of B's coordinates, as --units-a.
    #[arg(long, value_name = "U", value_parser = unit_parser())]
    pub units_b: Option<Unit>,
    /// Multiply A's coordinates by F (finite, > 0) with the unit conversion, before
    /// --transform-a/--translate-a: the coordinates are multiplied once by the f64 product of
    /// the conversion factor and F. In scene mode, applies to the file.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub scale_a: Option<f64>,
    /// Multiply B's coordinates by F, as --scale-a.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub scale_b: Option<f64>,
    /// Scene mode: also check every selected part against itself (self-clashing triangle pairs
    /// and mesh health, as `meshclash self`), in a `self` block of the report. A crossing
    /// self-clash pair fails the run under --fail-on clash (any self-clash pair under touching
    /// or clearance); health findings fail it when named in --self-fail-on.
    #[arg(long = "self")]
    pub self_check: bool,
    /// With --self: also fail on these (comma-separated): open, non-manifold, duplicates,
    /// degenerate, winding, touching, self-clash.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "WHAT", requires = "self_check")]
    pub self_fail_on: Vec<SelfFailOnArg>,
    /// Reuse results stored in the cache directory DIR (created when missing) and store new
    /// ones: a check whose inputs (every placed vertex, triangle and object) and settings are
    /// unchanged is not run again. The report is the same as without the cache but for an added
    /// `cache` block. Default: the MESHCLASH_CACHE environment variable when set and not empty.
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Bound of the cache directory in bytes: past it, the least recently used entries are
    /// removed.
    #[arg(long, value_name = "N", default_value_t = meshclash::cache::DEFAULT_MAX_BYTES)]
    pub cache_max_bytes: u64,
    /// Output flags: --format, --junit, --baseline, --export-glb.
    #[command(flatten)]
    pub outputs: OutputArgs,
    /// Colour in the text summary: auto (at a terminal, unless NO_COLOR is set or TERM is
    /// dumb), always or never.
    #[arg(long, value_enum, value_name = "WHEN", default_value = "auto")]
    pub color: ColorArg,
    /// Nothing on stderr but errors: no warnings, no summary, no progress.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `meshclash scene FILE`: one file's parts against each other.
#[derive(Debug, Clone, clap::Args)]
pub struct SceneArgs {
    /// The file whose parts are checked (glTF nodes, OBJ objects or groups, STL solids).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// The check's flags (as for two files; `-a` flags name the file).
    #[command(flatten)]
    pub check: CheckArgs,
}

/// Subcommands instead of a check: the generated-text ones of [`TextCommand`], and
/// `bench`.
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// Check the parts of one file against each other (all against all, or --select-a
    /// against --select-b); the check's flags apply (`./scene` names a file called scene).
    Scene(Box<SceneArgs>),
    /// `schema`, `completions <shell>`, `man`.
    #[command(flatten)]
    Output(TextCommand),
    /// Moved to the `meshclash-bench` binary (workspace member `bench/`): runs it with these
    /// arguments when it sits next to `meshclash`, else says how to run it.
    #[command(disable_help_flag = true)]
    Bench(BenchForward),
    /// Run the named checks of a clash-set file (JSON) in one go: one JSON document with every
    /// check's report, exit 1 if any check fails its --fail-on, 2 on bad input in any check.
    ClashSet(ClashSetArgs),
    /// Check one mesh against itself: self-clashing triangle pairs and mesh health per part.
    #[command(name = "self")]
    SelfCheck(SelfArgs),
    /// Shard a check across machines, step 1: write its work list (`meshclash plan <check
    /// arguments> -o plan.json`, the check arguments exactly as they would follow `meshclash`).
    /// Loads the geometry once, builds no triangle tree.
    Plan(PlanArgs),
    /// Step 2: check the pairs of one shard of a plan (`meshclash run --plan plan.json --shard
    /// I/N -o shard-I.json`). Without --shard, I comes from JOB_COMPLETION_INDEX (Kubernetes,
    /// 0-based), AWS_BATCH_JOB_ARRAY_INDEX, CLOUD_RUN_TASK_INDEX or SLURM_ARRAY_TASK_ID, N from
    /// --shards, AWS_BATCH_JOB_ARRAY_SIZE, CLOUD_RUN_TASK_COUNT or SLURM_ARRAY_TASK_COUNT.
    Run(RunArgs),
    /// Step 3: merge the shard reports into the report the unsharded check writes (byte for
    /// byte with --no-timings), with the outputs named here and the same exit code.
    Merge(MergeArgs),
}

/// `meshclash plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanArgs {
    /// The check arguments and `-o PLAN.json`.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 1.., required = true)]
    pub args: Vec<std::ffi::OsString>,
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
    /// Merge what is there when shards are missing: the report says `"complete": false` and
    /// names the missing shards, the JUnit file has a failing case for them, the exit code is 1
    /// (a partial merge never passes), and --baseline refuses the report later.
    #[arg(long)]
    pub allow_partial: bool,
    /// The outputs of the merged check (as on the check's own command line).
    #[command(flatten)]
    pub outputs: OutputArgs,
    /// Worker threads (overrides the plan's --threads; 0 = one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Nothing on stderr but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `meshclash bench ARGS..`: forwarded to `meshclash-bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchForward {
    /// Arguments for `meshclash-bench` (see `cargo run --release -p meshclash-bench -- --help`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
    pub args: Vec<std::ffi::OsString>,
}

/// `--color` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// At a terminal, unless NO_COLOR is set (not empty) or TERM is `dumb`.
    Auto,
    /// Always, even in a pipe.
    Always,
    /// Never.
    Never,
}

impl ColorArg {
    /// Colour text for a stream that is (or is not) a terminal?
    pub fn enabled(self, terminal: bool) -> bool {
        match self {
            ColorArg::Always => true,
            ColorArg::Never => false,
            ColorArg::Auto => {
                let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
                let dumb = std::env::var_os("TERM").is_some_and(|t| t == "dumb");
                terminal && !no_color && !dumb
            }
        }
    }
}

/// `--fail-on` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FailOnArg {
    /// Crossing pairs fail.
    Clash,
    /// Touching or crossing pairs fail.
    Touching,
    /// Anything within the clearance fails.
    Clearance,
    /// Never fail on findings.
    Never,
    /// With --baseline: fail only on crossing pairs that were not crossing in the baseline, or
    /// on containment the baseline did not report.
    New,
}

/// `--cross-check` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CrossCheckArg {
    /// parry3d-f64 0.31 (GJK triangle tests, f64).
    Parry,
}

/// `--mode` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Exact predicates (default).
    Exact,
    /// Plain f64 determinants, no exact fallback.
    Fast,
}

/// `--detail` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DetailArg {
    /// Every meeting triangle pair and the clash regions (default).
    Pairs,
    /// Part-pair verdicts, counts and closest points only.
    Parts,
}

/// `--bvh` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BvhArg {
    /// Binned surface-area heuristic.
    Sah,
    /// Spatial median of the centroid bounds.
    Median,
    /// Equal counts (object median).
    Equal,
}

/// The output flags, flattened into [`Args`].
#[derive(Debug, Clone, Default, clap::Args)]
pub struct OutputArgs {
    /// What to print on stdout: the JSON report, a human summary or JUnit XML [default: json,
    /// or nothing when -o is given].
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<FormatArg>,
    /// Also write JUnit XML to FILE (atomically): one test case per checked pair of inputs,
    /// failed when the run fails.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Compare with an earlier report: every finding gets a status (new or persistent) and the
    /// report a `baseline` block with the resolved ones. Findings are matched by stable ids.
    #[arg(long, value_name = "REPORT")]
    pub baseline: Option<PathBuf>,
    /// Write a self-contained GLB scene to FILE for any glTF viewer: a node per part (A orange,
    /// B blue), a node per clash worst first (marker, contact lines, its triangles, a camera,
    /// counts in extras) and the closest points.
    #[arg(long, value_name = "FILE")]
    pub export_glb: Option<PathBuf>,
    /// Write a self-contained HTML report to FILE: the summary, a sortable list of clashes and
    /// a WebGL viewer of the parts involved (no network needed to open it).
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
    /// Write the clashes as BCF topics to FILE (.bcfzip; 2.1 or 3.0: --bcf-version), for BIM tools: one topic per
    /// clash region or part pair (--bcf-topics), with a camera, the parts and the witness line.
    #[arg(long, value_name = "FILE")]
    pub bcf: Option<PathBuf>,
    /// What one BCF topic is.
    #[arg(long, value_enum, value_name = "WHAT", default_value = "regions")]
    pub bcf_topics: TopicsArg,
    /// BCF version of --bcf: 2.1 (read by every BIM tool) or 3.0.
    #[arg(long, value_enum, value_name = "V", default_value = "2.1")]
    pub bcf_version: BcfVersionArg,
    /// Which axis points up in the inputs, for --export-glb and --html: `z` turns the GLB's
    /// root node -90° about X (CAD data shows upright in glTF viewers) and orbits the HTML
    /// viewer around Z; coordinates in the files stay those of the report [default: z for
    /// STL, else y].
    #[arg(long, value_enum, value_name = "AXIS", default_value = "auto", hide_default_value = true)]
    pub up: UpArg,
}

impl OutputArgs {
    /// The output options (the baseline is the request's: it is an input).
    pub fn into_options(self) -> OutputOptions {
        OutputOptions {
            format: self.format.map(Into::into),
            junit: self.junit,
            export_glb: self.export_glb,
            html: self.html,
            bcf: self.bcf.map(|p| (p, self.bcf_topics.into())),
            bcf_version: self.bcf_version.into(),
            up: self.up.into(),
        }
    }
}

/// `--format`: what goes to stdout (the library's [`Format`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// The JSON report (`meshclash.report/2`).
    Json,
    /// The human summary (the one shown on stderr on a terminal).
    Text,
    /// JUnit XML, one test case per checked pair of inputs.
    Junit,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Json => Format::Json,
            FormatArg::Text => Format::Text,
            FormatArg::Junit => Format::Junit,
        }
    }
}

/// `--bcf-topics`: what one topic is (the library's [`Topics`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum TopicsArg {
    /// One topic per clash region (a part pair with several separate interferences gets one
    /// topic per interference).
    #[default]
    Regions,
    /// One topic per clashing part pair.
    PartPairs,
}

impl From<TopicsArg> for Topics {
    fn from(t: TopicsArg) -> Self {
        match t {
            TopicsArg::Regions => Topics::Regions,
            TopicsArg::PartPairs => Topics::PartPairs,
        }
    }
}

/// `--bcf-version` (the library's [`meshclash::output::bcf::Version`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum BcfVersionArg {
    /// BCF 2.1 (every BIM tool reads it).
    #[default]
    #[value(name = "2.1")]
    V21,
    /// BCF 3.0.
    #[value(name = "3.0")]
    V30,
}

impl From<BcfVersionArg> for meshclash::output::bcf::Version {
    fn from(v: BcfVersionArg) -> Self {
        match v {
            BcfVersionArg::V21 => Self::V21,
            BcfVersionArg::V30 => Self::V30,
        }
    }
}

/// `--up` (the library's [`meshclash::output::glb::Up`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum UpArg {
    /// Z when the (first) input is STL, as CAD exports are; else Y (glTF's convention).
    #[default]
    Auto,
    /// Y up (glTF, most OBJ).
    Y,
    /// Z up (CAD: STL, STEP-derived OBJ, IFC converted without a Y-up turn).
    Z,
}

impl From<UpArg> for meshclash::output::glb::Up {
    fn from(u: UpArg) -> Self {
        match u {
            UpArg::Auto => Self::Auto,
            UpArg::Y => Self::Y,
            UpArg::Z => Self::Z,
        }
    }
}

pub use meshclash::pipeline::Unit;

/// `--units U`: the unit names, each with its help line.
fn unit_parser() -> impl clap::builder::TypedValueParser<Value = Unit> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(Unit::ALL.map(|u| PossibleValue::new(u.name()).help(u.help())))
        .map(|s| Unit::from_name(&s).expect("a listed unit"))
}

/// The subcommands beside the main `meshclash A B` job. Each prints to stdout.
#[derive(Debug, Clone, PartialEq, Eq, clap::Subcommand)]
pub enum TextCommand {
    /// Print the JSON Schema (draft 2020-12) of the report.
    Schema,
    /// Print a shell completion script.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff).
    Man,
}

/// `meshclash clash-set FILE`: the file and the per-run flags (same meaning as on the main
/// command).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ClashSetArgs {
    /// The clash-set file (JSON; see the README or `--schema file`).
    #[arg(value_name = "FILE", required_unless_present = "schema")]
    pub file: Option<PathBuf>,
    /// Write the clash-set report to FILE (atomically) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// What to print on stdout: the JSON document, one summary line per check, or JUnit XML
    /// [default: json, or nothing when -o is given].
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<SetFormat>,
    /// Also write JUnit XML to FILE (atomically): one test suite per check.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// Deterministic reports: no timings, no thread count.
    #[arg(long)]
    pub no_timings: bool,
    /// Reuse results stored in the cache directory DIR (created when missing) and store new
    /// ones, for every check of the set (as `--cache` on the check; the checks share one
    /// directory). Default: the MESHCLASH_CACHE environment variable when set and not empty.
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Bound of the cache directory in bytes (as `--cache-max-bytes` on the check)
    /// [default: 1073741824].
    #[arg(long, value_name = "N")]
    pub cache_max_bytes: Option<u64>,
    /// Nothing on stderr but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the JSON Schema of the clash-set `file` or of its `output` document, and exit.
    #[arg(long, value_enum, value_name = "WHICH", exclusive = true)]
    pub schema: Option<SchemaKind>,
}

/// `--format` values of `clash-set`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SetFormat {
    /// The JSON document (`meshclash.clash-set/1`): every check's report.
    Json,
    /// One summary line per check, then the total.
    Text,
    /// JUnit XML, one test suite per check.
    Junit,
}

/// `--schema` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SchemaKind {
    /// The clash-set file format.
    File,
    /// The output document (`meshclash.clash-set/1`).
    Output,
}

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
    pub fail_on: Vec<SelfFailOnArg>,
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
    /// Write a self-contained HTML report to FILE: the summary, a list of the self-clashes
    /// and health problems, and a WebGL viewer highlighting their triangles.
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
    /// Write a GLB scene to FILE: the parts, and a node per self-clash and health problem
    /// with its triangles highlighted, a marker and a camera.
    #[arg(long, value_name = "FILE")]
    pub export_glb: Option<PathBuf>,
    /// Which axis points up, for --html and --export-glb [default: z for STL, else y].
    #[arg(long, value_enum, value_name = "AXIS", default_value = "auto", hide_default_value = true)]
    pub up: UpArg,
    /// List at most N pairs (the counts stay complete).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub max_pairs: usize,
    /// List at most N triangle ids per health finding.
    #[arg(long, value_name = "N", default_value_t = 10)]
    pub first_n: usize,
    /// BVH split strategy (the answer is the same with each; only the time differs).
    #[arg(long, value_enum, default_value_t = super::args::BvhArg::Sah)]
    pub bvh: super::args::BvhArg,
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

/// `--fail-on` values of `self` (the library's [`SelfFailOn`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, clap::ValueEnum)]
pub enum SelfFailOnArg {
    /// Crossing self-clash pairs (the default).
    #[value(name = "self-clash", alias = "clash")]
    SelfClash,
    /// Any self-clash pair, crossing or touching.
    Touching,
    /// A part that is not closed.
    Open,
    /// Non-manifold edges or vertices.
    NonManifold,
    /// Duplicate faces.
    Duplicates,
    /// Zero-area triangles.
    Degenerate,
    /// Edges used twice in the same direction.
    Winding,
    /// Never fail on findings.
    Never,
}

impl From<SelfFailOnArg> for SelfFailOn {
    fn from(a: SelfFailOnArg) -> Self {
        match a {
            SelfFailOnArg::SelfClash => SelfFailOn::SelfClash,
            SelfFailOnArg::Touching => SelfFailOn::Touching,
            SelfFailOnArg::Open => SelfFailOn::Open,
            SelfFailOnArg::NonManifold => SelfFailOn::NonManifold,
            SelfFailOnArg::Duplicates => SelfFailOn::Duplicates,
            SelfFailOnArg::Degenerate => SelfFailOn::Degenerate,
            SelfFailOnArg::Winding => SelfFailOn::Winding,
            SelfFailOnArg::Never => SelfFailOn::Never,
        }
    }
}

/// `--format` values of `self`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SelfFormat {
    /// The JSON report (`meshclash.self/1`).
    Json,
    /// A summary for a person.
    Text,
}

/// Parse the process's arguments: [`hoist_subcommand`] first, then clap, with help wrapped to
/// `width` columns (None: the terminal's width).
pub fn parse(width: Option<usize>) -> std::result::Result<Args, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let argv = hoist_subcommand(std::env::args_os().collect());
    let mut cmd = Args::command();
    if let Some(w) = width {
        cmd = cmd.term_width(w);
    }
    let mut matches = cmd.try_get_matches_from_mut(argv)?;
    Args::from_arg_matches_mut(&mut matches).map_err(|e| e.format(&mut cmd))
}

/// `meshclash --threads 1 clash-set x.json` means `meshclash clash-set --threads 1 x.json`:
/// when the first positional argument is a subcommand's name and flags of the main command come
/// before it, the name moves to the front (the subcommand then parses those flags as its own, or
/// says which one it does not take). Flag values are skipped using the clap definition, so a
/// file called `self` given to `-o` stays a value.
pub fn hoist_subcommand(mut argv: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    use clap::CommandFactory;
    let cmd = Args::command();
    let takes_value = |a: &clap::Arg| a.get_action().takes_values();
    let mut i = 1;
    while i < argv.len() {
        let Some(t) = argv[i].to_str() else { break };
        if t == "--" {
            break;
        }
        if let Some(long) = t.strip_prefix("--") {
            if !long.contains('=')
                && cmd.get_arguments().any(|a| a.get_long() == Some(long) && takes_value(a))
            {
                i += 1;
            }
        } else if t.len() > 1 && t.starts_with('-') {
            let c = t[1..].chars().next();
            if t.chars().count() == 2 && cmd.get_arguments().any(|a| a.get_short() == c && takes_value(a)) {
                i += 1;
            }
        } else {
            if i > 1 && cmd.get_subcommands().any(|s| s.get_name() == t) {
                let name = argv.remove(i);
                argv.insert(1, name);
            }
            break;
        }
        i += 1;
    }
    argv
}
