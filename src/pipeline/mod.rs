//! The one pipeline: a [`Request`] in, an [`Outcome`] out.
//!
//! Every way of asking for a check — the two-file command, `scene`, each check of a clash set,
//! the steps of a sharded run, the Python package — builds a [`Request`] and calls [`run`]. It
//! loads and places the inputs (units, transforms, `--split-bodies`), resolves the tolerances,
//! runs the check ([`crate::check::assembly::run`]), the parry cross-check, the clash regions and
//! their penetration estimates, the finding ids, the scene self-check and the baseline
//! comparison, and decides **once** whether the run fails ([`Outcome::failed`]).
//!
//! Nothing downstream decides or computes again: [`report::build`] projects an [`Outcome`] into
//! the wire format, and every output (JSON, text, JUnit, GLB, HTML, BCF) is a
//! projection of that report and the outcome's geometry.
//!
//! Combinations whose answer the pipeline cannot give exactly are refused by
//! [`Request::validate`] (exit 2), whichever path asked: `--first-hit` with a baseline (the walk
//! stops before the findings a comparison needs), `--fail-on new` without one, `--detail parts`
//! with what needs triangle pairs.

use crate::bvh::BuildOptions;
use crate::check::assembly::{self, Selection};
use crate::check::query::{self, Detail, FailOn, Input, InputSpec, PairFinding, PairKind, Settings};
use crate::error::{Error, InputProblem, Result, UsageProblem};
use crate::geom::predicates::Tolerances;
use crate::geom::Aabb;
use crate::load::Format;
use crate::report::baseline::{self, Baseline, BaselineReport, Finding};
use crate::report::self_report::{SceneSelfReport, SelfFailOn};
use crate::report::{CrossCheckReport, InputUnitsReport, SettingsReport};
use crate::scene::mesh::{Loaded, Mesh, WorldTriangles};
use glam::DMat4;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod overlaps;
pub mod report;
mod self_block;

/// A phase of a run, in order (for a progress display).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Reading and parsing the files.
    Load,
    /// Building trees and walking them (pairs, closest points, containment).
    Check,
    /// Running parry3d-f64 (`--cross-check parry`).
    CrossCheck,
    /// Regions, finding ids, the baseline comparison; then the outputs.
    Write,
}

impl Phase {
    /// What a progress display says.
    pub fn label(self) -> &'static str {
        match self {
            Phase::Load => "loading meshes",
            Phase::Check => "building trees and walking them",
            Phase::CrossCheck => "cross-checking with parry3d-f64",
            Phase::Write => "writing outputs",
        }
    }
}

/// A unit of length (`--units`, `--units-a`, `--units-b`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub enum Unit {
    /// Micrometre.
    #[serde(rename = "um")]
    Um,
    /// Millimetre.
    #[serde(rename = "mm")]
    Mm,
    /// Centimetre.
    #[serde(rename = "cm")]
    Cm,
    /// Metre (glTF's unit by specification).
    #[serde(rename = "m")]
    M,
    /// Inch (25.4 mm exactly).
    #[serde(rename = "in")]
    In,
    /// Foot (12 in).
    #[serde(rename = "ft")]
    Ft,
    /// Yard (3 ft).
    #[serde(rename = "yd")]
    Yd,
}

impl Unit {
    /// Every unit, in the order the help lists them.
    pub const ALL: [Unit; 7] = [Unit::Um, Unit::Mm, Unit::Cm, Unit::M, Unit::In, Unit::Ft, Unit::Yd];

    /// Its name on the command line and in the report.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Um => "um",
            Unit::Mm => "mm",
            Unit::Cm => "cm",
            Unit::M => "m",
            Unit::In => "in",
            Unit::Ft => "ft",
            Unit::Yd => "yd",
        }
    }

    /// What the help says of it.
    pub fn help(self) -> &'static str {
        match self {
            Unit::Um => "Micrometre",
            Unit::Mm => "Millimetre",
            Unit::Cm => "Centimetre",
            Unit::M => "Metre (glTF's unit by specification)",
            Unit::In => "Inch (25.4 mm exactly)",
            Unit::Ft => "Foot (12 in)",
            Unit::Yd => "Yard (3 ft)",
        }
    }

    /// The unit of that name.
    pub fn from_name(name: &str) -> Option<Unit> {
        Unit::ALL.into_iter().find(|u| u.name() == name)
    }

    /// Its length in micrometres: an exact integer for every unit (the inch is 25.4 mm by
    /// definition).
    pub fn micrometres(self) -> u32 {
        match self {
            Unit::Um => 1,
            Unit::Mm => 1_000,
            Unit::Cm => 10_000,
            Unit::M => 1_000_000,
            Unit::In => 25_400,
            Unit::Ft => 304_800,
            Unit::Yd => 914_400,
        }
    }

    /// The factor that converts coordinates in `self` to `to`: the exact ratio of two integers,
    /// rounded once to f64 (one IEEE division of exactly representable operands).
    pub fn factor_to(self, to: Unit) -> f64 {
        f64::from(self.micrometres()) / f64::from(to.micrometres())
    }
}

/// Units and raw scales. Indices follow [`Request::inputs`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Units {
    /// The report's unit (`--units`, or the first declared input unit); None: no conversion.
    pub report: Option<Unit>,
    /// Declared units of each input.
    pub inputs: [Option<Unit>; 2],
    /// Raw multipliers (None = 1).
    pub scale: [Option<f64>; 2],
}

impl Units {
    /// True if any unit or scale was given (otherwise inputs load exactly as they are, and the
    /// report has no `inputs.*.units` blocks).
    pub fn active(&self) -> bool {
        self.report.is_some()
            || self.inputs.iter().any(Option::is_some)
            || self.scale.iter().any(Option::is_some)
    }

    /// The report's `settings.units`: the report unit, or `model`.
    pub fn report_name(&self) -> &'static str {
        self.report.map_or("model", Unit::name)
    }

    /// Resolve input `i` of format `format`: the multiplier, the report block and a warning when
    /// the units were assumed. `flag` names the units flag for the warning.
    pub fn resolve(&self, i: usize, format: Format, flag: &str) -> (f64, InputUnitsReport, Option<String>) {
        let scale = self.scale[i].unwrap_or(1.0);
        let gltf = matches!(format, Format::Gltf | Format::Glb);
        let (units, source, warning) = match (self.report, self.inputs[i]) {
            (None, _) => (None, None, None),
            (Some(_), Some(u)) => (Some(u), Some("given"), None),
            (Some(_), None) if gltf => (Some(Unit::M), Some("gltf"), None),
            (Some(r), None) => (
                Some(r),
                Some("assumed"),
                Some(format!(
                    "units unknown ({} files carry none): taken to be {}, the report units; give {flag} to declare them",
                    format.name().to_uppercase(),
                    r.name()
                )),
            ),
        };
        let factor = match (units, self.report) {
            (Some(u), Some(r)) => u.factor_to(r),
            _ => 1.0,
        };
        let multiplier = factor * scale;
        let block = InputUnitsReport {
            units: units.map(|u| u.name().to_string()),
            source: source.map(str::to_string),
            factor,
            scale,
            multiplier,
        };
        (multiplier, block, warning)
    }
}

/// A tolerance as given: absolute, or relative to the diagonal of the box around both inputs
/// (the command line's `1e-6rel`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// Model units.
    Abs(f64),
    /// Times the diagonal of the box around both inputs.
    Rel(f64),
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance::Abs(0.0)
    }
}

impl Tolerance {
    /// Parse `0.5` or `1e-6rel` (finite, >= 0); the error names `flag`.
    pub fn parse(flag: &str, s: &str) -> Result<Tolerance> {
        let t = s.trim();
        let (num, rel) = match t.strip_suffix("rel") {
            Some(n) => (n, true),
            None => (t, false),
        };
        match num.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(if rel { Tolerance::Rel(v) } else { Tolerance::Abs(v) }),
            _ => Err(Error::bad_flag(flag, UsageProblem::BadTolerance { text: s.to_string() })),
        }
    }

    /// The absolute value for a model of size `size`.
    pub fn resolve(self, size: f64) -> f64 {
        match self {
            Tolerance::Abs(v) => v,
            Tolerance::Rel(r) => r * size,
        }
    }

    /// As written on the command line (canonical form).
    pub fn spec(self) -> String {
        match self {
            Tolerance::Abs(v) => format!("{v}"),
            Tolerance::Rel(r) => format!("{r}rel"),
        }
    }
}

/// Where an input comes from.
#[derive(Debug, Clone)]
pub enum Source {
    /// A mesh file (OBJ, STL, glTF, GLB).
    File(PathBuf),
    /// A mesh handed over in memory; `label` stands for its path in the report and in errors,
    /// and its `format` in the report is `array`.
    Mesh {
        /// Its name in the report and in error messages.
        label: PathBuf,
        /// The mesh, validated (see [`crate::api::mesh_from_arrays`]).
        mesh: Mesh,
    },
}

/// One input and its placement.
#[derive(Debug, Clone)]
pub struct InputRequest {
    /// The file or mesh.
    pub source: Source,
    /// Affine placement applied to every vertex (in f64) after units and scale.
    pub transform: DMat4,
}

impl InputRequest {
    /// A file, unplaced.
    pub fn file(path: impl Into<PathBuf>) -> InputRequest {
        InputRequest { source: Source::File(path.into()), transform: DMat4::IDENTITY }
    }

    /// The path (or label) errors and the report name it by.
    pub fn path(&self) -> &Path {
        match &self.source {
            Source::File(p) => p,
            Source::Mesh { label, .. } => label,
        }
    }
}

/// When the run fails (exit 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gate {
    /// The verdict is at or above this.
    Verdict(FailOn),
    /// A crossing or a containment that the baseline did not have (needs a baseline).
    New,
}

impl Default for Gate {
    fn default() -> Self {
        Gate::Verdict(FailOn::Clash)
    }
}

impl Gate {
    /// The report's `settings.fail_on`.
    pub fn name(self) -> &'static str {
        match self {
            Gate::Verdict(f) => f.name(),
            Gate::New => "new",
        }
    }
}

/// Everything a check needs: what to load and how, what to look for, when to fail.
#[derive(Debug, Clone, Default)]
pub struct Request {
    /// A and B (two entries), or the one file of a scene (one entry, with `selection.scene`).
    pub inputs: Vec<InputRequest>,
    /// Units and scales (indices follow `inputs`).
    pub units: Units,
    /// `--touch-tolerance`.
    pub touch: Tolerance,
    /// `--clearance`.
    pub clearance: Tolerance,
    /// Search settings; `settings.tolerances` is replaced by the resolved `touch`/`clearance`.
    pub settings: Settings,
    /// When the run fails.
    pub gate: Gate,
    /// Pairs listed in the report (the worst ones; counts stay complete).
    pub max_pairs: usize,
    /// No timings and no thread count in the report (byte-identical reports).
    pub deterministic: bool,
    /// Run parry3d-f64 on the same inputs and report every disagreement.
    pub cross_check: bool,
    /// Scene mode and part selections (and a sharding hook).
    pub selection: Selection,
    /// `--split-bodies`.
    pub split_bodies: bool,
    /// `--penetration`.
    pub penetration: bool,
    /// `scene --self`: the conditions that fail the run on self-clash and health.
    pub self_check: Option<Vec<SelfFailOn>>,
    /// `--baseline REPORT`.
    pub baseline: Option<PathBuf>,
    /// Shards a partial merge is missing ("1/3", ...): such a run never passes.
    pub missing_shards: Vec<String>,
    /// `--cache DIR`: reuse a stored outcome of the same check ([`crate::cache::hook`]).
    pub cache: Option<crate::cache::CacheConfig>,
}

impl Request {
    /// A two-file request with default settings.
    pub fn files(a: impl Into<PathBuf>, b: impl Into<PathBuf>) -> Request {
        Request { inputs: vec![InputRequest::file(a), InputRequest::file(b)], ..Request::defaults() }
    }

    /// A scene request (the file's parts against each other) with default settings.
    pub fn scene(file: impl Into<PathBuf>) -> Request {
        let mut r = Request { inputs: vec![InputRequest::file(file)], ..Request::defaults() };
        r.selection.scene = true;
        r
    }

    /// The command line's defaults (no inputs).
    pub fn defaults() -> Request {
        Request { max_pairs: 1000, ..Request::default() }
    }

    /// Refuse what the pipeline cannot answer exactly (exit 2), whichever path asked.
    pub fn validate(&self) -> Result<()> {
        let conflict = |flag: &str, why: &str| Err(Error::bad_flag(flag, UsageProblem::Conflict(why.into())));
        let want = if self.selection.scene { 1 } else { 2 };
        if self.inputs.len() != want {
            let what = if self.selection.scene { "scene FILE" } else { "mesh A and mesh B" };
            return Err(Error::usage(UsageProblem::Missing(what.into())));
        }
        let leaf = self.settings.bvh.leaf_size;
        if !(1..=64).contains(&leaf) {
            let problem = UsageProblem::OutOfRange { value: leaf.into(), min: 1, max: 64 };
            return Err(Error::bad_flag("leaf-size", problem));
        }
        let de = self.settings.distance_error;
        for (flag, v) in [("distance-rel-err", de.rel), ("distance-abs-err", de.abs)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::bad_flag(flag, UsageProblem::NotNonNegative { value: v }));
            }
        }
        if self.gate == Gate::New && self.baseline.is_none() {
            return conflict("fail-on", "--fail-on new needs --baseline REPORT");
        }
        if self.settings.first_hit && self.baseline.is_some() {
            return conflict(
                "first-hit",
                "--first-hit stops at the first crossing, so a baseline comparison would call unseen findings \
                 resolved and miss new ones: drop --first-hit or --baseline",
            );
        }
        if self.settings.detail == Detail::Parts {
            if self.baseline.is_some() {
                return conflict(
                    "baseline",
                    "--baseline needs the triangle pairs that --detail parts does not keep: drop one of them",
                );
            }
            if self.cross_check {
                return conflict(
                    "cross-check",
                    "--cross-check needs the triangle pairs that --detail parts does not keep: drop one of them",
                );
            }
        }
        if self.self_check.is_some() && !self.selection.scene {
            return conflict(
                "self",
                "--self works with scene (meshclash scene FILE --self); for one mesh use meshclash self FILE",
            );
        }
        if self.selection.scene && self.cross_check {
            return conflict("cross-check", "--cross-check works on two files, not with scene");
        }
        Ok(())
    }
}

/// A loaded, placed input as the check saw it.
#[derive(Debug, Clone)]
pub struct LoadedInput {
    /// The mesh in world coordinates, with its path, format and warnings. For an instanced
    /// input (`instanced`) the mesh is empty: read it through [`LoadedInput::mesh`].
    pub input: Input,
    /// A glTF scene checked without expanding its instances ([`instanced_path`]).
    pub instanced: Option<std::sync::Arc<InstancedInput>>,
    /// The placement applied.
    pub transform: DMat4,
    /// The units block (when units or scales were given).
    pub units: Option<InputUnitsReport>,
    /// An in-memory mesh (reported with format `array`).
    pub array: bool,
}

impl LoadedInput {
    /// The mesh in world coordinates. An instanced input is expanded on first use (by an
    /// output that draws the geometry), exactly as the file's plain load gives it; a scene too
    /// large to expand (the expanded load's limits, which the instanced load does not apply)
    /// reads as an empty mesh here, and as the load's error through
    /// [`LoadedInput::try_world_mesh`].
    pub fn world_mesh(&self) -> &Mesh {
        static EMPTY: Mesh = Mesh {
            positions: Vec::new(),
            triangles: Vec::new(),
            tri_object: Vec::new(),
            objects: Vec::new(),
        };
        self.try_world_mesh().unwrap_or(&EMPTY)
    }

    /// [`LoadedInput::world_mesh`], or the error the expanded load of an instanced scene gives
    /// (a scene beyond its limits or the memory available).
    pub fn try_world_mesh(&self) -> std::result::Result<&Mesh, &Error> {
        match &self.instanced {
            Some(i) => i.expanded.get_or_init(|| i.scene.expand().map(|l| l.mesh)).as_ref(),
            None => Ok(&self.input.mesh),
        }
    }

    /// The world mesh for an output that draws it, or the expansion's error as the caller's
    /// own: where the kept expansion failed, it is tried again (it refuses before it allocates).
    pub fn drawn_mesh(&self) -> Result<std::borrow::Cow<'_, Mesh>> {
        use std::borrow::Cow;
        match (self.try_world_mesh(), &self.instanced) {
            (Ok(m), _) => Ok(Cow::Borrowed(m)),
            (Err(_), Some(i)) => i.scene.expand().map(|l| Cow::Owned(l.mesh)),
            (Err(_), None) => Ok(Cow::Borrowed(&self.input.mesh)),
        }
    }

    /// Where the input's triangles come from, by their index in the world mesh: the mesh
    /// itself, or for an instanced input the scene, placing each triangle read (never the
    /// whole scene).
    pub fn world_triangles(&self) -> &dyn WorldTriangles {
        match &self.instanced {
            Some(i) => &i.scene,
            None => &self.input.mesh,
        }
    }

    /// The summary the report gives of the input (counts, zero-area triangles, objects, box).
    pub fn info(&self) -> std::borrow::Cow<'_, query::MeshInfo> {
        match &self.instanced {
            Some(i) => std::borrow::Cow::Borrowed(&i.info),
            None => std::borrow::Cow::Owned(query::MeshInfo::of(&self.input.mesh)),
        }
    }
}

/// A loaded input reads as its world mesh ([`LoadedInput::world_mesh`]: an instanced scene is
/// expanded on first use).
impl std::ops::Deref for LoadedInput {
    type Target = Mesh;
    fn deref(&self) -> &Mesh {
        self.world_mesh()
    }
}

/// A glTF scene checked without expanding its instances: each mesh once in its own coordinates
/// and every part as (mesh, world matrix), placed when the check reads it.
pub struct InstancedInput {
    /// The scene.
    pub scene: crate::load::InstancedScene,
    /// The expanded mesh's summary, computed part by part.
    pub info: query::MeshInfo,
    /// Each part's triangle box, in part order (found with the summary, so the check need not
    /// place every part again for it).
    pub part_bounds: Vec<Aabb>,
    expanded: std::sync::OnceLock<Result<Mesh>>,
}

impl std::fmt::Debug for InstancedInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InstancedInput").field("parts", &self.scene.parts.len()).finish_non_exhaustive()
    }
}

/// Whether `req` runs on its glTF scene instanced ([`InstancedInput`]) rather than expanded:
/// the one place that decides it. A scene check (at either detail) with nothing that reads the
/// whole world mesh: no sharding hook, scene self-check, penetration estimates, cross-check,
/// `--split-bodies`, units, scales or placement, and a cache only where it reuses part pair by
/// part pair ([`crate::cache::pairs::reuses_placed_pairs`]; a baseline compares finding ids
/// alone, so it runs here).
/// Every other request expands the scene as it is loaded. Both paths give the same outcome;
/// this path's memory grows with the distinct meshes, not the instances. The pair lists keep
/// the expanded mesh's triangle numbers; finding ids and regions read the triangles of the
/// pairs through [`LoadedInput::world_triangles`] (placed one by one), so nothing downstream
/// of the check expands the scene but an output that draws the geometry
/// ([`LoadedInput::world_mesh`]).
pub fn instanced_path(req: &Request) -> bool {
    req.selection.scene
        && (req.cache.is_none() || crate::cache::pairs::reuses_placed_pairs(&req.settings, &req.selection))
        && req.selection.hook.is_none()
        && req.self_check.is_none()
        && !req.penetration
        && !req.cross_check
        && !req.split_bodies
        && !req.units.active()
        && req.inputs.len() == 1
        && req.inputs[0].transform == DMat4::IDENTITY
        && matches!(req.inputs[0].source, Source::File(_))
}

/// Load a glTF scene file instanced (see [`instanced_path`]); any other format loads as usual.
fn load_scene_instanced(req: &Request, path: &Path) -> Result<LoadedInput> {
    use crate::error::Reading;
    let bytes = crate::load::read_regular_file(path, Reading::File, u64::MAX)?;
    let format = crate::load::detect_format(path, &bytes)?;
    if !matches!(format, Format::Gltf | Format::Glb) {
        let loaded = crate::load::load_bytes(path, &bytes, format)?;
        return prepare_loaded(req, 0, "--units-a", loaded, format, false);
    }
    let scene = crate::load::load_gltf_instanced(path, &bytes)?;
    drop(bytes);
    let (info, range_warnings, part_bounds) = query::scene_info(&scene, path)?;
    let mut warnings = scene.warnings.clone();
    warnings.extend(range_warnings);
    let input = Input { path: path.to_path_buf(), format, mesh: Mesh::default(), warnings };
    let instanced = InstancedInput { scene, info, part_bounds, expanded: std::sync::OnceLock::new() };
    Ok(LoadedInput {
        input,
        instanced: Some(std::sync::Arc::new(instanced)),
        transform: req.inputs[0].transform,
        units: None,
        array: false,
    })
}

/// The baseline comparison of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The report's `baseline` block.
    pub block: BaselineReport,
    /// For each listed pair (in [`Outcome::listed`] order): was it in the baseline?
    pub persistent: Vec<bool>,
}

/// Everything a check found and decided; the report is a projection of it.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// A and B (in scene mode both are the one file).
    pub inputs: [std::sync::Arc<LoadedInput>; 2],
    /// The settings as the report shows them (tolerances resolved).
    pub settings: SettingsReport,
    /// The check: result, parts, part pairs.
    pub assembly: assembly::Outcome,
    /// parry3d-f64's answer, when asked.
    pub cross_check: Option<CrossCheckReport>,
    /// Connected interferences (with penetration estimates when asked).
    pub regions: Vec<crate::check::regions::Region>,
    /// With `--penetration`, per region (same order): the exact penetration depth of its two
    /// objects when both are closed and exactly convex and they meet
    /// ([`crate::narrow::convex::parts`]); empty without `--penetration`.
    pub convex_penetrations: Vec<Option<crate::narrow::convex::Penetration>>,
    /// The exact box of A ∩ B per part pair (same order as `assembly.part_pairs`): for each pair
    /// whose verdict is clash and whose two parts are closed ([`crate::check::overlap`]); None
    /// for the others.
    pub overlaps: Vec<Option<crate::check::overlap::Overlap>>,
    /// Two files of one closed part each, clashing by containment with no clashing part pair:
    /// the exact box of A ∩ B ([`files_overlap`]); None otherwise.
    pub files_overlap: Option<crate::check::overlap::Overlap>,
    /// Indices into `assembly.result.pairs` of the pairs the report lists: all of them, or when
    /// there are more than `max_pairs`, the worst (crossing, then touching, then within the
    /// touch tolerance, then clearance by distance), sorted by (a, b).
    pub listed: Vec<usize>,
    /// The finding ids of the listed pairs (same order).
    pub listed_ids: Vec<String>,
    /// When the list is cut: the ids of every finding it does not show, so that this report
    /// can serve as a complete baseline.
    pub unlisted: Option<crate::report::UnlistedFindings>,
    /// The baseline comparison (`--baseline`).
    pub comparison: Option<Comparison>,
    /// The scene self-check block (`scene --self`).
    pub self_check: Option<SceneSelfReport>,
    /// Shards a partial merge is missing.
    pub missing_shards: Vec<String>,
    /// The one decision: does this run fail (exit 1)?
    pub failed: bool,
    /// Load and total times in ms (None in deterministic mode).
    pub times: Option<(f64, f64)>,
    /// The report's `cache` block (`--cache`).
    pub cache: Option<crate::cache::CacheSummary>,
    /// What the cache has to say (entries ignored, results not stored): for stderr, never the
    /// report (a report is the same with or without the cache).
    pub cache_warnings: Vec<String>,
}

impl Outcome {
    /// The two meshes the check ran on, each read as a [`Mesh`] through [`LoadedInput`]'s
    /// `Deref`: an instanced scene is expanded only when an output reads its geometry.
    pub fn meshes(&self) -> [&LoadedInput; 2] {
        [&self.inputs[0], &self.inputs[1]]
    }

    /// Loader and units warnings, each prefixed with its file (in scene mode once).
    pub fn warnings(&self) -> Vec<String> {
        let inputs: Vec<&Input> = if std::sync::Arc::ptr_eq(&self.inputs[0], &self.inputs[1]) {
            vec![&self.inputs[0].input]
        } else {
            self.inputs.iter().map(|i| &i.input).collect()
        };
        inputs
            .iter()
            .flat_map(|i| i.warnings.iter().map(move |w| format!("{}: {}", i.path.display(), w)))
            .collect()
    }
}

/// Load input `i` of `req`: units, placement, `--split-bodies`.
fn load_input(req: &Request, i: usize, flag: &str) -> Result<LoadedInput> {
    let (loaded, format, array) = match &req.inputs[i].source {
        Source::File(p) => {
            let (loaded, format) = crate::load::load_path(p)?;
            (loaded, format, false)
        }
        Source::Mesh { mesh, .. } => (Loaded { mesh: mesh.clone(), warnings: Vec::new() }, Format::Obj, true),
    };
    prepare_loaded(req, i, flag, loaded, format, array)
}

/// Input `i` of `req` from what its loader gave (`array`: handed over in memory): units,
/// placement, `--split-bodies`.
fn prepare_loaded(
    req: &Request,
    i: usize,
    flag: &str,
    loaded: Loaded,
    format: Format,
    array: bool,
) -> Result<LoadedInput> {
    let r = &req.inputs[i];
    let spec = InputSpec { path: r.path().to_path_buf(), transform: r.transform };
    let (mut input, units) = if req.units.active() {
        let (multiplier, block, warning) = req.units.resolve(i, format, flag);
        (query::prepare_input(&spec, loaded, format, multiplier, warning)?, Some(block))
    } else {
        (query::prepare_input(&spec, loaded, format, 1.0, None)?, None)
    };
    if req.split_bodies {
        crate::scene::bodies::split_bodies(&mut input.mesh);
    }
    Ok(LoadedInput { input, instanced: None, transform: r.transform, units, array })
}

/// The input whose file a selection error names: A's when A's selection (`--select-a`,
/// `--exclude`) leaves no part (the side checked first), else B's; in scene mode the one file.
fn problem_side(req: &Request, a: &Mesh) -> usize {
    use crate::check::assembly::{glob_match, parts_of};
    let sel = &req.selection;
    let kept = |name: &str| {
        (sel.select_a.is_empty() || sel.select_a.iter().any(|g| glob_match(g, name)))
            && !sel.exclude.iter().any(|g| glob_match(g, name))
    };
    let a_empty = !parts_of(a, 0).iter().any(|p| kept(&p.name));
    if !sel.scene && a_empty {
        0
    } else {
        req.inputs.len() - 1
    }
}

/// How bad a pair is, for choosing which pairs a cut list keeps (smaller is worse).
fn severity(p: &PairFinding) -> (u8, f64) {
    match (p.kind, p.contact) {
        (PairKind::Crossing, _) => (0, 0.0),
        (PairKind::Touching, Some(_)) => (1, 0.0),
        (PairKind::Touching, None) => (2, p.distance),
        (PairKind::Clearance, _) => (3, p.distance),
    }
}

/// Indices of the pairs a list of at most `max` shows: all when they fit, else the `max` worst
/// (ties by (a, b)), in (a, b) order. `pairs` is sorted by (a, b).
pub fn listed_pairs(pairs: &[PairFinding], max: usize) -> Vec<usize> {
    if pairs.len() <= max {
        return (0..pairs.len()).collect();
    }
    let mut idx: Vec<usize> = (0..pairs.len()).collect();
    let key = |&i: &usize| {
        let (s, d) = severity(&pairs[i]);
        (s, d.to_bits(), i)
    };
    if max > 0 {
        idx.select_nth_unstable_by_key(max - 1, key);
    }
    idx.truncate(max);
    idx.sort_unstable();
    idx
}

/// Run a check: see the module docs. `progress` is called as each phase starts.
pub fn run(req: &Request, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    run_on(req, progress, instanced_path(req))
}

/// [`run`] with the input expanded whatever [`instanced_path`] says: the same outcome, for
/// comparing the two paths.
#[doc(hidden)]
pub fn run_expanded(req: &Request, progress: &(dyn Fn(Phase) + Sync)) -> Result<Outcome> {
    run_on(req, progress, false)
}

fn run_on(req: &Request, progress: &(dyn Fn(Phase) + Sync), instanced: bool) -> Result<Outcome> {
    req.validate()?;
    // Read the baseline first: a bad one costs nothing, and it is read before any output is
    // written (so `--baseline r.json -o r.json` updates a baseline in place).
    let base = req.baseline.as_deref().map(read_baseline).transpose()?;
    progress(Phase::Load);
    // A cache directory that cannot be used is refused before anything is loaded.
    let store = req.cache.as_ref().map(|c| crate::cache::Store::open(&c.dir, c.max_bytes)).transpose()?;
    let t0 = Instant::now();
    let inputs = if instanced {
        let one = std::sync::Arc::new(load_scene_instanced(req, req.inputs[0].path())?);
        [one.clone(), one]
    } else if req.selection.scene {
        let one = std::sync::Arc::new(load_input(req, 0, "--units-a")?);
        [one.clone(), one]
    } else {
        let (a, b) = rayon::join(|| load_input(req, 0, "--units-a"), || load_input(req, 1, "--units-b"));
        [std::sync::Arc::new(a?), std::sync::Arc::new(b?)]
    };
    let (a, b) = (&inputs[0].input, &inputs[1].input);
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let size = match &inputs[0].instanced {
        Some(i) => i.info.bounds.extent().length(),
        None => {
            Aabb::of_points(&a.mesh.positions).union(Aabb::of_points(&b.mesh.positions)).extent().length()
        }
    };
    let mut settings = req.settings;
    settings.tolerances =
        Tolerances { touch: req.touch.resolve(size), clearance: req.clearance.resolve(size) };
    if !settings.tolerances.touch.is_finite() || !settings.tolerances.clearance.is_finite() {
        return Err(Error::usage(UsageProblem::ToleranceOverflow));
    }
    progress(Phase::Check);
    let cache = store.map(|s| {
        let active = !req.cross_check;
        // The cache finds its index of earlier runs by what the inputs are (their objects'
        // names), never by file name; results are found by their geometry.
        let sides = if req.selection.scene { 1 } else { 2 };
        let lineage = match &inputs[0].instanced {
            Some(i) => crate::cache::key::lineage_of_scene(&i.scene),
            None => crate::cache::key::lineage(&[&a.mesh, &b.mesh][..sides]),
        };
        crate::cache::CheckCache::new(
            std::sync::Arc::new(s),
            &settings,
            &req.selection,
            req.split_bodies,
            req.penetration,
            active,
            &lineage,
        )
    });
    let selection = cache.as_ref().map(|c| c.selection(&req.selection));
    let outcome = match &inputs[0].instanced {
        Some(i) => {
            assembly::run_instanced_with(&i.scene, &i.part_bounds, &req.selection, &settings, |parts| {
                cache.as_ref().and_then(|c| c.check_placed(&i.scene, parts))
            })
        }
        None => assembly::run(&a.mesh, &b.mesh, selection.as_ref().unwrap_or(&req.selection), &settings),
    }
    .map_err(|e| Error::in_file(req.inputs[problem_side(req, &a.mesh)].path(), InputProblem::Selection(e)))?;
    let cross_check = if req.cross_check {
        progress(Phase::CrossCheck);
        let p = crate::check::cross_check::parry_f64(&a.mesh, &b.mesh, true)
            .map_err(|e| Error::bad_flag("cross-check", UsageProblem::CrossCheck(e.to_string())))?;
        Some(crate::report::cross_check_report(&outcome.result, &p, req.max_pairs, req.deterministic))
    } else {
        None
    };
    progress(Phase::Write);
    let result = &outcome.result;
    // Every finding's id, computed once: regions take theirs from them, an uncut list shows
    // them all, a cut one records the rest under `unlisted`, and a baseline compares them all.
    // The triangles of the pairs are read where they come from: an instanced scene places
    // only those. A cache supplies the ids of the pairs it reused.
    let (ta, tb) = (inputs[0].world_triangles(), inputs[1].world_triangles());
    let ids = match &cache {
        Some(c) => c.finding_ids(&outcome, |p| crate::check::finding_id::finding_hashes(p, ta, tb)),
        None => crate::check::finding_id::finding_hashes(&result.pairs, ta, tb),
    };
    let mut regions = crate::check::regions::regions_with_ids(&result.pairs, ta, tb, &ids);
    if req.penetration && !settings.first_hit {
        let opts = BuildOptions::default();
        crate::check::regions::estimate_penetration(&mut regions, &result.pairs, &a.mesh, &b.mesh, opts);
    }
    let convex_penetrations = if req.penetration && !settings.first_hit {
        let objects: Vec<(u32, u32)> = regions.iter().map(|g| g.objects).collect();
        crate::narrow::convex::parts::object_pair_penetrations(
            &a.mesh,
            &b.mesh,
            req.selection.scene,
            &objects,
        )
    } else {
        Vec::new()
    };
    let compute = |need: &(dyn Fn(usize) -> bool + Sync)| {
        overlaps::overlaps(&outcome, [&inputs[0], &inputs[1]], req.selection.scene, req.settings.bvh, need)
    };
    // With the cache, the boxes of reused pairs come from it (and the new ones are stored).
    let overlaps = match &cache {
        Some(c) => c.overlaps(&outcome, compute),
        None => compute(&|_| true),
    };
    let files_overlap =
        overlaps::files_overlap(&outcome, &a.mesh, &b.mesh, req.selection.scene, req.settings.bvh);
    let listed = listed_pairs(&result.pairs, req.max_pairs);
    let cut = listed.len() < result.pairs.len();
    let all: Vec<Finding> = baseline::findings_of(&result.pairs, &ids);
    let listed_ids: Vec<String> =
        listed.iter().map(|&i| crate::check::finding_id::format_id(ids[i])).collect();
    let unlisted = cut.then(|| baseline::unlisted(&all, &listed));
    let contained = crate::report::ReportContainment::of(&result.containment);
    let comparison = base.as_ref().map(|base| compare(base, &all, &listed, contained));
    let self_check = req.self_check.as_ref().map(|fail_on| {
        self_block::scene_self_block(
            &a.mesh,
            &req.selection,
            req.settings.bvh,
            fail_on,
            req.max_pairs,
            req.deterministic,
        )
    });
    let failed = decide(
        req.gate,
        result.verdict,
        comparison.as_ref().map(|c| &c.block),
        self_check.as_ref(),
        &req.missing_shards,
    );
    let threads = rayon::current_num_threads();
    let settings_report = SettingsReport {
        touch_tolerance: settings.tolerances.touch,
        clearance: settings.tolerances.clearance,
        touch_tolerance_given: req.touch.spec(),
        clearance_given: req.clearance.spec(),
        model_size: size,
        units: req.units.report_name().into(),
        fail_on: req.gate.name().into(),
        bvh: req.settings.bvh.strategy.name().into(),
        mode: req.settings.mode.name().into(),
        first_hit: req.settings.first_hit,
        penetration: req.penetration,
        distance_rel_err: req.settings.distance_error.rel,
        distance_abs_err: req.settings.distance_error.abs,
        leaf_size: req.settings.bvh.leaf_size,
        max_pairs: req.max_pairs,
        threads: (!req.deterministic).then_some(threads),
        detail: (req.settings.detail != Detail::Pairs).then(|| req.settings.detail.name().into()),
    };
    Ok(Outcome {
        settings: settings_report,
        cross_check,
        regions,
        convex_penetrations,
        overlaps,
        files_overlap,
        listed,
        listed_ids,
        unlisted,
        comparison,
        self_check,
        missing_shards: req.missing_shards.clone(),
        failed,
        times: (!req.deterministic).then(|| (load_ms, t0.elapsed().as_secs_f64() * 1e3)),
        cache: cache.as_ref().map(|c| c.summary(&outcome)),
        cache_warnings: cache.as_ref().map_or_else(Vec::new, |c| c.take_warnings()),
        assembly: outcome,
        inputs,
    })
}

/// Read a baseline report: a regular file of bounded size (never blocking on a FIFO), parsed
/// for what a comparison needs.
fn read_baseline(path: &Path) -> Result<Baseline> {
    use crate::error::Reading;
    let bytes = crate::load::read_small_file(path, Reading::Baseline, crate::load::MAX_SMALL_FILE_BYTES)?;
    baseline::parse(&path.display().to_string(), &bytes)
        .map_err(|msg| Error::in_file(path, InputProblem::Invalid(msg)))
}

/// Compare every finding of this run (`all`, in pair order) with a complete baseline.
fn compare(
    base: &Baseline,
    all: &[Finding],
    listed: &[usize],
    contained: Option<crate::report::ReportContainment>,
) -> Comparison {
    let block = baseline::compare(all, base, contained);
    let persistent = listed.iter().map(|&i| base.contains(all[i].id)).collect();
    Comparison { block, persistent }
}

/// The one fail decision of a run.
///
/// - the gate: the verdict at or above `--fail-on`, or with `--fail-on new` a new crossing or a
///   new containment against the baseline;
/// - a failing scene self-check (its own `--self-fail-on`) fails the run whatever the gate;
/// - a partial merge never passes: the missing shards may hold what would fail it.
pub fn decide(
    gate: Gate,
    verdict: query::Verdict,
    comparison: Option<&BaselineReport>,
    self_check: Option<&SceneSelfReport>,
    missing_shards: &[String],
) -> bool {
    let gate_fails = match gate {
        Gate::Verdict(f) => f.fails(verdict),
        // Validation guarantees a baseline; without one nothing could be called new, so fail.
        Gate::New => comparison.is_none_or(baseline::fails_on_new),
    };
    gate_fails || self_check.is_some_and(|s| s.failed) || !missing_shards.is_empty()
}
