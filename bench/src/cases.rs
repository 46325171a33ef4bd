//! The benchmark cases: `meshclash-bench gen DIR` writes the inputs (generated spheres and tori,
//! the shipped 2CylinderEngine and grids of its instances), `meshclash-bench cases DIR` times
//! them, in one process and one run, through the meshclash library and parry3d (f64 and f32),
//! phase by phase, with same-run ratios.
//!
//! Inputs ("Inputs, so you can rebuild them"):
//!
//! * `spheres_a.obj`, `spheres_b.obj`: icospheres subdivided 7 times (327,680 triangles),
//!   radius 1, A at the origin, B centred at (1.2, 0.1, 0.05); coordinates rounded to f32 and
//!   written with the f64 digits of that f32, so the f64 loader reads the f32 value exactly.
//! * `torus_a.glb` and `torus_b_{crossing,apart,linked}.glb`: major radius 1, tube 0.25,
//!   707 × 707 segments (999,698 triangles), f32 GLB with the placement baked into the
//!   positions. A lies in the xy-plane around the origin; B crossing = A moved to
//!   (0.3, 0, 0.1), apart = moved to (0, 0, 0.6), linked = turned into the xz-plane and centred
//!   at (1, 0, 0) (each tube passes through the other's hole; the centre circles are exactly 1
//!   apart everywhere, so the surfaces are ≈ 0.5 apart along a whole circle).
//! * `engine.glb`: the shipped 2CylinderEngine, copied; `engine_grid100.glb`: its scene's root
//!   node trees cloned 100 times (new nodes, shared meshes) under nodes translated on a
//!   10 × 10 grid 1,000 apart in x and z; `engine_grid1000.glb` (with `--grid1000`, for issue
//!   14): 1,000 copies on a 10 × 10 × 10 grid.
//!
//! Timed per two-file case (wall clock, one run each, after one untimed warm-up of rayon's
//! pool): **load** both files (meshclash's loaders; parry has none, so the same figure is
//! charged to every tool); meshclash **build** (both trees, in parallel), **pairs** (dual walk
//! and exact classification), **distance** (0 at the first contact, else the exact
//! branch-and-bound minimum) and the whole library **check** (`query::check`: build, pairs,
//! closest pair, topology, containment); parry: `TriMesh::new` (build), `Bvh::leaf_pairs` and
//! GJK per candidate (pairs), `query::distance` (distance). Scene cases (the engines) time the
//! load and `assembly::run` in scene mode; parry has no counterpart there.

use crate::usage;
use meshclash::bvh::{BuildOptions, Bvh};
use meshclash::check::assembly::{self, Selection};
use meshclash::check::cross_check::{self, ParryResult};
use meshclash::check::query::{self, InputSpec, Settings};
use meshclash::error::{Error, Result, UsageProblem};
use meshclash::scene::mesh::Mesh;
use serde::Serialize;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `meshclash-bench gen` flags.
#[derive(Debug, Clone, clap::Args)]
pub struct GenArgs {
    /// Directory to write the inputs into (created if missing).
    pub dir: PathBuf,
    /// Icosphere subdivisions (7: 327,680 triangles per sphere).
    #[arg(long, default_value_t = 7)]
    pub sphere_subdivisions: u32,
    /// Torus segments around each circle (707: 999,698 triangles per torus).
    #[arg(long, default_value_t = 707)]
    pub torus_segments: u32,
    /// The 2CylinderEngine GLB to copy and instance (engine cases are skipped without it).
    #[arg(long, value_name = "FILE.glb")]
    pub engine: Option<PathBuf>,
    /// Also write `engine_grid1000.glb` (1,000 instances, for sharding).
    #[arg(long)]
    pub grid1000: bool,
}

/// `meshclash-bench cases` flags.
#[derive(Debug, Clone, clap::Args)]
pub struct CasesArgs {
    /// Directory written by `meshclash-bench gen`.
    pub dir: PathBuf,
    /// Cases to run, comma-separated (default: every case whose files exist): spheres,
    /// tori-crossing, tori-apart, tori-linked, engine, engine-grid100, engine-grid1000.
    #[arg(long, value_name = "NAME,..")]
    pub only: Option<String>,
    /// Where parry computes a distance: `clear` (only where meshclash finds the meshes apart;
    /// on overlapping meshes parry's distance descends almost every node), `all` or `none`.
    #[arg(long, value_name = "WHICH", default_value = "clear")]
    pub parry_distance: String,
    /// Skip parry (meshclash phases only).
    #[arg(long)]
    pub no_parry: bool,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Also run the same-run peers of `bench/peers.py` (trueform, python-fcl: each only when
    /// that Python can import it) with this Python interpreter, and check their answers
    /// against meshclash's.
    #[arg(long, value_name = "PYTHON")]
    pub peers: Option<PathBuf>,
}

/// Every case name, in run order.
pub const CASES: [&str; 7] =
    ["spheres", "tori-crossing", "tori-apart", "tori-linked", "engine", "engine-grid100", "engine-grid1000"];

fn files_of(case: &str) -> &'static [&'static str] {
    match case {
        "spheres" => &["spheres_a.obj", "spheres_b.obj"],
        "tori-crossing" => &["torus_a.glb", "torus_b_crossing.glb"],
        "tori-apart" => &["torus_a.glb", "torus_b_apart.glb"],
        "tori-linked" => &["torus_a.glb", "torus_b_linked.glb"],
        "engine" => &["engine.glb"],
        "engine-grid100" => &["engine_grid100.glb"],
        _ => &["engine_grid1000.glb"],
    }
}

fn io_err(path: &Path, e: std::io::Error) -> Error {
    usage(format!("{}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// A unit icosphere: the icosahedron with every triangle split in four `subdivisions` times,
/// new vertices pushed onto the sphere; `20 · 4^subdivisions` outward-wound triangles.
pub fn icosphere(subdivisions: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| unit(*p))
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(f.len() * 3 / 2);
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<[f64; 3]>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (v[a as usize], v[b as usize]);
                v.push(unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                v.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(f.len() * 4);
        for &[a, b, c] in &f {
            let (ab, bc, ca) = (midpoint(a, b, &mut v), midpoint(b, c, &mut v), midpoint(c, a, &mut v));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v, f)
}

fn unit(p: [f64; 3]) -> [f64; 3] {
    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] / l, p[1] / l, p[2] / l]
}

/// A torus in the xy-plane around the origin (major radius `big`, tube `small`), `n × n`
/// segments, `2n²` outward-wound triangles.
pub fn torus(big: f64, small: f64, n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let tau = std::f64::consts::TAU;
    let mut v = Vec::with_capacity((n * n) as usize);
    for i in 0..n {
        let th = tau * i as f64 / n as f64;
        for j in 0..n {
            let ph = tau * j as f64 / n as f64;
            let ring = big + small * ph.cos();
            v.push([ring * th.cos(), ring * th.sin(), small * ph.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * n + j % n;
    let mut f = Vec::with_capacity(2 * (n * n) as usize);
    for i in 0..n {
        for j in 0..n {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f)
}

/// Positions moved by `map` and rounded to f32.
fn placed(v: &[[f64; 3]], map: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<[f32; 3]> {
    v.iter().map(|p| map(*p).map(|x| x as f32)).collect()
}

/// OBJ text: `v` lines with the f64 digits of each f32 (exact in an f64 reader), 1-based faces.
pub fn obj_text(v: &[[f32; 3]], f: &[[u32; 3]]) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(v.len() * 64 + f.len() * 24);
    for p in v {
        let _ = writeln!(s, "v {} {} {}", p[0] as f64, p[1] as f64, p[2] as f64);
    }
    for t in f {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// GLB bytes: a JSON chunk padded with spaces and a BIN chunk padded with zeros.
pub fn glb_bytes(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).expect("JSON serialises");
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

/// A one-mesh GLB (f32 positions, u32 indices, one node named `name`).
pub fn mesh_glb(name: &str, v: &[[f32; 3]], f: &[[u32; 3]]) -> Vec<u8> {
    let mut bin = Vec::with_capacity(v.len() * 12 + f.len() * 12);
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in v {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
            bin.extend_from_slice(&p[k].to_le_bytes());
        }
    }
    let pos_len = bin.len();
    for t in f {
        for &i in t {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    let json = json!({
        "asset": { "version": "2.0", "generator": "meshclash-bench gen" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "name": name, "mesh": 0 }],
        "meshes": [{ "name": name, "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": pos_len, "target": 34962 },
            { "buffer": 0, "byteOffset": pos_len, "byteLength": bin.len() - pos_len, "target": 34963 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": v.len(), "type": "VEC3",
              "min": lo, "max": hi },
            { "bufferView": 1, "componentType": 5125, "count": f.len() * 3, "type": "SCALAR" }
        ]
    });
    glb_bytes(&json, &bin)
}

/// Split a GLB into its JSON and BIN chunks.
pub fn split_glb(bytes: &[u8]) -> std::result::Result<(Value, Vec<u8>), String> {
    let u32_at = |i: usize| -> std::result::Result<u32, String> {
        let b = bytes.get(i..i + 4).ok_or("truncated GLB")?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    };
    if bytes.get(0..4) != Some(b"glTF") {
        return Err("not a GLB (no glTF magic)".into());
    }
    let jlen = u32_at(12)? as usize;
    if bytes.get(16..20) != Some(b"JSON") {
        return Err("first GLB chunk is not JSON".into());
    }
    let jbytes = bytes.get(20..20 + jlen).ok_or("truncated JSON chunk")?;
    let json: Value = serde_json::from_slice(jbytes).map_err(|e| format!("GLB JSON: {e}"))?;
    let at = 20 + jlen;
    let bin = if at + 8 <= bytes.len() {
        let blen = u32_at(at)? as usize;
        bytes.get(at + 8..at + 8 + blen).ok_or("truncated BIN chunk")?.to_vec()
    } else {
        Vec::new()
    };
    Ok((json, bin))
}

/// The scene's root node trees cloned once per offset (new nodes, shared meshes), each copy
/// under a new node translated by its offset; node names get `@k` (copy `k`) so parts stay
/// distinct.
pub fn instance_grid(json: &Value, offsets: &[[f64; 3]]) -> std::result::Result<Value, String> {
    let mut out = json.clone();
    let nodes = json["nodes"].as_array().ok_or("no nodes")?.clone();
    let scene = json["scene"].as_u64().unwrap_or(0) as usize;
    let roots: Vec<usize> = json["scenes"][scene]["nodes"]
        .as_array()
        .ok_or("the scene has no nodes")?
        .iter()
        .map(|n| n.as_u64().map(|n| n as usize).ok_or("bad node index"))
        .collect::<std::result::Result<_, _>>()?;
    fn clone_tree(
        nodes: &[Value],
        i: usize,
        k: usize,
        out: &mut Vec<Value>,
    ) -> std::result::Result<usize, String> {
        let mut n = nodes.get(i).ok_or("node index out of range")?.clone();
        let kids: Vec<usize> = n["children"]
            .as_array()
            .map(|c| c.iter().filter_map(|x| x.as_u64().map(|x| x as usize)).collect())
            .unwrap_or_default();
        let mut new_kids = Vec::with_capacity(kids.len());
        for c in kids {
            new_kids.push(clone_tree(nodes, c, k, out)?);
        }
        if !new_kids.is_empty() {
            n["children"] = json!(new_kids);
        }
        let name = n["name"].as_str().map_or_else(|| format!("node{i}"), str::to_string);
        n["name"] = json!(format!("{name}@{k}"));
        out.push(n);
        Ok(out.len() - 1)
    }
    let mut new_nodes = Vec::new();
    let mut scene_roots = Vec::new();
    for (k, off) in offsets.iter().enumerate() {
        let kids = roots
            .iter()
            .map(|&r| clone_tree(&nodes, r, k, &mut new_nodes))
            .collect::<std::result::Result<Vec<_>, _>>()?;
        new_nodes.push(json!({ "name": format!("copy{k}"), "translation": off, "children": kids }));
        scene_roots.push(new_nodes.len() - 1);
    }
    out["nodes"] = json!(new_nodes);
    out["scenes"] = json!([{ "nodes": scene_roots }]);
    out["scene"] = json!(0);
    Ok(out)
}

/// Offsets of an `nx × ny × nz` grid `step` apart (x, then z, then y).
pub fn grid(nx: usize, nz: usize, ny: usize, step: f64) -> Vec<[f64; 3]> {
    let mut v = Vec::with_capacity(nx * ny * nz);
    for y in 0..ny {
        for z in 0..nz {
            for x in 0..nx {
                v.push([x as f64 * step, y as f64 * step, z as f64 * step]);
            }
        }
    }
    v
}

/// `meshclash-bench gen`: write the inputs; returns one line per file written.
pub fn generate(args: &GenArgs) -> Result<String> {
    let dir = &args.dir;
    std::fs::create_dir_all(dir).map_err(|e| io_err(dir, e))?;
    let mut log = String::new();
    let mut write = |name: &str, bytes: &[u8], what: String| -> Result<()> {
        let p = dir.join(name);
        std::fs::write(&p, bytes).map_err(|e| io_err(&p, e))?;
        log.push_str(&format!("{}  {what}, {:.1} MB\n", p.display(), bytes.len() as f64 / 1e6));
        Ok(())
    };
    let (sv, sf) = icosphere(args.sphere_subdivisions);
    let what = format!("{} triangles", sf.len());
    write("spheres_a.obj", obj_text(&placed(&sv, |p| p), &sf).as_bytes(), what.clone())?;
    let b = placed(&sv, |p| [p[0] + 1.2, p[1] + 0.1, p[2] + 0.05]);
    write("spheres_b.obj", obj_text(&b, &sf).as_bytes(), what)?;

    let (tv, tf) = torus(1.0, 0.25, args.torus_segments);
    let what = format!("{} triangles", tf.len());
    write("torus_a.glb", &mesh_glb("torus_a", &placed(&tv, |p| p), &tf), what.clone())?;
    let moved = |d: [f64; 3]| move |p: [f64; 3]| [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
    let crossing = placed(&tv, moved([0.3, 0.0, 0.1]));
    write("torus_b_crossing.glb", &mesh_glb("torus_b", &crossing, &tf), what.clone())?;
    let apart = placed(&tv, moved([0.0, 0.0, 0.6]));
    write("torus_b_apart.glb", &mesh_glb("torus_b", &apart, &tf), what.clone())?;
    // A quarter turn about x takes the xy-plane to the xz-plane: (x, y, z) -> (x, -z, y).
    let linked = placed(&tv, |p| [p[0] + 1.0, -p[2], p[1]]);
    write("torus_b_linked.glb", &mesh_glb("torus_b", &linked, &tf), what)?;

    if let Some(engine) = &args.engine {
        let bytes = std::fs::read(engine).map_err(|e| io_err(engine, e))?;
        let (json, bin) = split_glb(&bytes).map_err(|e| usage(format!("{}: {e}", engine.display())))?;
        write("engine.glb", &bytes, "copy".into())?;
        let mut grids = vec![("engine_grid100.glb", grid(10, 10, 1, 1000.0))];
        if args.grid1000 {
            grids.push(("engine_grid1000.glb", grid(10, 10, 10, 1000.0)));
        }
        for (name, offsets) in grids {
            let j =
                instance_grid(&json, &offsets).map_err(|e| usage(format!("{}: {e}", engine.display())))?;
            write(name, &glb_bytes(&j, &bin), format!("{} instances, 1,000 apart", offsets.len()))?;
        }
    }
    Ok(log)
}

// ---------------------------------------------------------------------------------------------
// Timing
// ---------------------------------------------------------------------------------------------

/// One tool's phases on one case, ms (`None`: not run).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Phases {
    /// Loading both files.
    pub load_ms: f64,
    /// Building both trees.
    pub build_ms: Option<f64>,
    /// Pair search with exact (meshclash) or GJK (parry) tests.
    pub pairs_ms: Option<f64>,
    /// Distance query.
    pub distance_ms: Option<f64>,
    /// meshclash only: the whole library check (`query::check`, or `assembly::run` for scenes).
    pub check_ms: Option<f64>,
    /// meshclash only: what the CLI runs, end to end but for writing the report: the library's
    /// pipeline (`pipeline::run` with `--no-timings`: load, check, clash regions, overlap box).
    pub pipeline_ms: Option<f64>,
    /// Pairs reported.
    pub pairs: Option<usize>,
    /// Distance found.
    pub distance: Option<f64>,
    /// Why something was skipped or failed.
    pub note: Option<String>,
}

impl Phases {
    /// load + build + pairs.
    pub fn pairs_total(&self) -> Option<f64> {
        Some(self.load_ms + self.build_ms? + self.pairs_ms?)
    }
    /// load + build + pairs + distance.
    pub fn distance_total(&self) -> Option<f64> {
        Some(self.pairs_total()? + self.distance_ms?)
    }
}

/// One case's figures.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    /// Case name.
    pub name: String,
    /// Triangles of A and B (scene cases: the file, twice).
    pub triangles: [usize; 2],
    /// meshclash's verdict (`clash`, `touching`, `clear`, ...).
    pub verdict: String,
    /// meshclash.
    pub meshclash: Phases,
    /// parry3d-f64.
    pub parry_f64: Option<Phases>,
    /// parry3d (f32).
    pub parry_f32: Option<Phases>,
    /// Peers run by `bench/peers.py` (`--peers`).
    pub peers: Vec<Peer>,
}

/// One peer of `bench/peers.py` on one case, ms, and whether its answers equal meshclash's.
#[derive(Debug, Clone, Default, Serialize, serde::Deserialize)]
pub struct Peer {
    /// Tool and version.
    pub tool: String,
    /// Case name.
    pub case: String,
    /// Loading both files (the peer's reader).
    #[serde(default)]
    pub load_ms: f64,
    /// Building both trees.
    #[serde(default)]
    pub build_ms: f64,
    /// The yes/no intersection query.
    #[serde(default)]
    pub intersects_ms: f64,
    /// Every intersecting triangle pair.
    #[serde(default)]
    pub pairs_ms: f64,
    /// The distance query.
    #[serde(default)]
    pub distance_ms: f64,
    /// Its answers.
    #[serde(default)]
    pub intersects: bool,
    /// Intersecting pairs found.
    #[serde(default)]
    pub pairs: usize,
    /// Distance found (0 when they meet).
    #[serde(default)]
    pub distance: f64,
    /// The peer's error, if it failed.
    pub error: Option<String>,
    /// Filled in here: how its answers compare with meshclash's.
    #[serde(default)]
    pub check: String,
}

impl Peer {
    /// load + build + pairs (the whole answer to "which pairs clash").
    pub fn pairs_total(&self) -> f64 {
        self.load_ms + self.build_ms + self.pairs_ms
    }
    /// load + build + distance.
    pub fn distance_total(&self) -> f64 {
        self.load_ms + self.build_ms + self.distance_ms
    }
}

/// The JSON `bench/peers.py --json` prints.
#[derive(serde::Deserialize)]
struct PeerRun {
    results: Vec<Peer>,
}

/// Runs `bench/peers.py` on `cases` with `python`; an interpreter that cannot be started or
/// output that is not the expected JSON is an error naming the interpreter.
fn run_peers(python: &Path, dir: &Path, cases: &[&str]) -> Result<Vec<Peer>> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("peers.py");
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(dir)
        .args(["--json", "--only", &cases.join(",")])
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| usage(format!("--peers {}: cannot run: {e}", python.display())))?;
    if !out.status.success() {
        return Err(usage(format!(
            "--peers {}: {} exited with {}",
            python.display(),
            script.display(),
            out.status
        )));
    }
    let run: PeerRun = serde_json::from_slice(&out.stdout)
        .map_err(|e| usage(format!("--peers {}: unexpected output: {e}", python.display())))?;
    Ok(run.results)
}

/// How a peer's answers compare with meshclash's (`verdict`, pairs, exact distance).
fn judge(p: &Peer, verdict: &str, pairs: Option<usize>, distance: Option<f64>) -> String {
    if let Some(e) = &p.error {
        return format!("failed: {e}");
    }
    let meet = verdict == "clash" || verdict == "touching";
    let mut out = Vec::new();
    if p.intersects != meet {
        out.push(format!("WRONG: intersects = {} (meshclash: {verdict})", p.intersects));
    }
    if let Some(n) = pairs.filter(|_| meet) {
        if p.pairs != n {
            out.push(format!("pairs {} vs {n}", p.pairs));
        }
    }
    if let Some(d) = distance {
        let err = (p.distance - d).abs();
        // f32 input read exactly into f64: an f64 peer's distance agrees to ~1e-12 relative.
        if err > 1e-9 * d.max(1.0) {
            out.push(format!("distance off by {err:.2e}"));
        }
    }
    if out.is_empty() {
        "answers equal".into()
    } else {
        out.join("; ")
    }
}

/// Everything one `cases` run measured.
#[derive(Debug, Clone, Serialize)]
pub struct CasesReport {
    /// Cores available.
    pub cores: usize,
    /// Worker threads.
    pub threads: usize,
    /// 1-minute load average at start and end.
    pub load: [Option<f64>; 2],
    /// One entry per case.
    pub cases: Vec<CaseResult>,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn loadavg() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

fn load(path: &Path) -> Result<Mesh> {
    Ok(query::load_input(&InputSpec { path: path.to_path_buf(), transform: glam::DMat4::IDENTITY })?.mesh)
}

fn parry_phases(
    f: fn(&Mesh, &Mesh, bool) -> std::result::Result<ParryResult, String>,
    a: &Mesh,
    b: &Mesh,
    load_ms: f64,
    distance: bool,
) -> Phases {
    match f(a, b, distance) {
        Ok(r) => Phases {
            load_ms,
            build_ms: Some(r.build_ms),
            pairs_ms: Some(r.pairs_ms),
            distance_ms: distance.then_some(r.distance_ms),
            check_ms: None,
            pipeline_ms: None,
            pairs: Some(r.intersecting_pairs.len()),
            distance: distance.then_some(r.distance),
            note: (!distance).then(|| "distance skipped (--parry-distance)".into()),
        },
        Err(e) => Phases { load_ms, note: Some(e), ..Default::default() },
    }
}

/// The CLI's whole run of `a` against `b` but for writing the report (`pipeline::run`, as
/// `meshclash A B --no-timings` runs it), ms; its verdict must be `check`'s.
fn pipeline(a: &Path, b: &Path, check: &query::ClashResult) -> Result<f64> {
    let mut req = meshclash::pipeline::Request::files(a, b);
    req.deterministic = true;
    let t = Instant::now();
    let out = meshclash::pipeline::run(&req, &|_| {})?;
    let took = ms(t);
    let verdict = out.assembly.result.verdict;
    if verdict != check.verdict {
        return Err(Error::usage(UsageProblem::Other(format!(
            "the pipeline's verdict {} differs from the check's {}",
            verdict.name(),
            check.verdict.name()
        ))));
    }
    Ok(took)
}

fn run_case(name: &str, dir: &Path, args: &CasesArgs) -> Result<CaseResult> {
    let files: Vec<PathBuf> = files_of(name).iter().map(|f| dir.join(f)).collect();
    if files.len() == 1 {
        // Scene mode: the file's parts against each other.
        let t = Instant::now();
        let m = load(&files[0])?;
        let load_ms = ms(t);
        let sel = Selection { scene: true, ..Default::default() };
        let t = Instant::now();
        let out = assembly::run(&m, &m, &sel, &Settings::default()).map_err(usage)?;
        let check_ms = ms(t);
        let n = m.triangles.len();
        return Ok(CaseResult {
            name: name.into(),
            triangles: [n, n],
            verdict: out.result.verdict.name().into(),
            meshclash: Phases {
                load_ms,
                check_ms: Some(check_ms),
                pairs: Some(out.result.pairs.len()),
                distance: out.result.closest.as_ref().map(|c| c.distance),
                note: Some(format!("scene mode, {} parts", out.parts.len())),
                ..Default::default()
            },
            parry_f64: None,
            parry_f32: None,
            peers: Vec::new(),
        });
    }
    let t = Instant::now();
    let (a, b) = rayon::join(|| load(&files[0]), || load(&files[1]));
    let (a, b) = (a?, b?);
    let load_ms = ms(t);

    let t = Instant::now();
    let (ta, tb) =
        rayon::join(|| Bvh::build(&a, BuildOptions::default()), || Bvh::build(&b, BuildOptions::default()));
    let build_ms = ms(t);
    let t = Instant::now();
    let pairs = crate::exact_pairs(&a, &ta, &b, &tb).len();
    let pairs_ms = ms(t);
    let t = Instant::now();
    let distance = crate::exact_distance(&a, &ta, &b, &tb);
    let distance_ms = ms(t);
    drop((ta, tb));
    let t = Instant::now();
    let r = query::check(&a, &b, &Settings::default());
    let check_ms = ms(t);
    let pipeline_ms = Some(pipeline(&files[0], &files[1], &r)?);
    let meshclash = Phases {
        load_ms,
        build_ms: Some(build_ms),
        pairs_ms: Some(pairs_ms),
        distance_ms: Some(distance_ms),
        check_ms: Some(check_ms),
        pipeline_ms,
        pairs: Some(pairs),
        distance,
        note: None,
    };
    let clear = distance.is_some_and(|d| d > 0.0);
    let want = match args.parry_distance.as_str() {
        "all" => true,
        "none" => false,
        _ => clear,
    };
    let (p64, p32) = if args.no_parry {
        (None, None)
    } else {
        (
            Some(parry_phases(cross_check::parry_f64, &a, &b, load_ms, want)),
            Some(parry_phases(crate::parry32::parry_f32, &a, &b, load_ms, want)),
        )
    };
    Ok(CaseResult {
        name: name.into(),
        triangles: [a.triangles.len(), b.triangles.len()],
        verdict: r.verdict.name().into(),
        meshclash,
        parry_f64: p64,
        parry_f32: p32,
        peers: Vec::new(),
    })
}

/// Parse `--only` and `--parry-distance`; the cases to run are those asked for (all by
/// default) whose files exist.
fn selected(args: &CasesArgs) -> Result<Vec<&'static str>> {
    if !["clear", "all", "none"].contains(&args.parry_distance.as_str()) {
        let msg = format!("--parry-distance: '{}' is not clear, all or none", args.parry_distance);
        return Err(Error::bad_flag("parry-distance", UsageProblem::Other(msg)));
    }
    let want: Vec<&'static str> = match &args.only {
        None => CASES.to_vec(),
        Some(list) => list
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|s| {
                CASES.iter().copied().find(|c| *c == s).ok_or_else(|| {
                    let msg = format!("--only: no case '{s}' (cases: {})", CASES.join(", "));
                    Error::bad_flag("only", UsageProblem::Other(msg))
                })
            })
            .collect::<Result<_>>()?,
    };
    let present: Vec<&'static str> =
        want.iter().copied().filter(|c| files_of(c).iter().all(|f| args.dir.join(f).is_file())).collect();
    if present.is_empty() {
        return Err(usage(format!(
            "{}: no case has its files (run `meshclash-bench gen {}` first)",
            args.dir.display(),
            args.dir.display()
        )));
    }
    if args.only.is_some() && present.len() < want.len() {
        let missing: Vec<&str> = want.iter().copied().filter(|c| !present.contains(c)).collect();
        return Err(usage(format!("{}: files missing for {}", args.dir.display(), missing.join(", "))));
    }
    Ok(present)
}

/// `meshclash-bench cases`: run and return what to print.
pub fn run_cases(args: &CasesArgs) -> Result<String> {
    let cases = selected(args)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .map_err(|e| Error::bad_flag("threads", UsageProblem::Invalid(e.to_string())))?;
    let load0 = loadavg();
    let mut results = pool.install(|| {
        rayon::broadcast(|_| ()); // start the workers outside the timed regions
        cases.iter().map(|c| run_case(c, &args.dir, args)).collect::<Result<Vec<_>>>()
    })?;
    if let Some(python) = &args.peers {
        for mut p in run_peers(python, &args.dir, &cases)? {
            if let Some(c) = results.iter_mut().find(|c| c.name == p.case) {
                p.check = judge(&p, &c.verdict, c.meshclash.pairs, c.meshclash.distance);
                c.peers.push(p);
            }
        }
    }
    let rep = CasesReport {
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        threads: pool.current_num_threads(),
        load: [load0, loadavg()],
        cases: results,
    };
    Ok(if args.json {
        let mut s = serde_json::to_string_pretty(&rep).expect("serialises");
        s.push('\n');
        s
    } else {
        render_cases(&rep)
    })
}

fn cell(v: Option<f64>) -> String {
    v.map_or("–".into(), |v| if v >= 100.0 { format!("{v:.0}") } else { format!("{v:.1}") })
}

fn ratio(theirs: Option<f64>, ours: Option<f64>) -> String {
    match (theirs, ours) {
        (Some(t), Some(o)) if o > 0.0 => format!("{:.2}×", t / o),
        _ => "–".into(),
    }
}

/// Markdown: per case, one row per tool with its phases, then parry ÷ meshclash per phase.
pub fn render_cases(rep: &CasesReport) -> String {
    let f = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.3}"));
    let mut s = format!(
        "meshclash-bench cases: {} cores, {} threads, load average {} at start, {} at end\n",
        rep.cores,
        rep.threads,
        f(rep.load[0]),
        f(rep.load[1])
    );
    for c in &rep.cases {
        s.push_str(&format!(
            "\n### {} ({} + {} triangles, meshclash: {})\n\n",
            c.name, c.triangles[0], c.triangles[1], c.verdict
        ));
        s.push_str(
            "| tool | load ms | build ms | pairs ms | distance ms | load+build+pairs ms | load+build+pairs+distance ms | check ms | pairs | distance | note |\n",
        );
        s.push_str("|---|---|---|---|---|---|---|---|---|---|---|\n");
        let m = &c.meshclash;
        // What the CLI does: load, then the whole check on lazily built trees.
        let cli = m.check_ms.map(|c| m.load_ms + c);
        let mut row = |tool: &str, p: &Phases| {
            s.push_str(&format!(
                "| {tool} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                cell(Some(p.load_ms)),
                cell(p.build_ms),
                cell(p.pairs_ms),
                cell(p.distance_ms),
                cell(p.pairs_total()),
                cell(p.distance_total()),
                cell(p.check_ms),
                p.pairs.map_or("–".into(), |n| n.to_string()),
                p.distance.map_or("–".into(), |d| format!("{d:.9}")),
                p.note.as_deref().unwrap_or("")
            ));
        };
        if m.build_ms.is_some() {
            row("meshclash, eager full trees (not what the CLI runs)", m);
            let cli_only = Phases {
                load_ms: m.load_ms,
                check_ms: m.check_ms,
                pairs: m.pairs,
                distance: m.distance,
                note: Some(format!(
                    "load + check = {} ms; the CLI's whole pipeline (also clash regions and overlap box) = {} ms",
                    cell(cli),
                    cell(m.pipeline_ms)
                )),
                ..Default::default()
            };
            row("meshclash (CLI path)", &cli_only);
        } else {
            row("meshclash", m);
        }
        for (tool, p) in [("parry3d-f64", &c.parry_f64), ("parry3d f32", &c.parry_f32)] {
            if let Some(p) = p {
                row(tool, p);
            }
        }
        for p in &c.peers {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | intersects {} | {} | {:.9} | {} |\n",
                p.tool,
                cell(Some(p.load_ms)),
                cell(Some(p.build_ms)),
                cell(Some(p.pairs_ms)),
                cell(Some(p.distance_ms)),
                cell(Some(p.pairs_total())),
                cell(Some(p.distance_total())),
                cell(Some(p.intersects_ms)),
                p.pairs,
                p.distance,
                p.check
            ));
        }
        for (tool, p) in [("parry3d-f64", &c.parry_f64), ("parry3d f32", &c.parry_f32)] {
            if let Some(p) = p {
                s.push_str(&format!(
                    "| {tool} ÷ meshclash | | {} | {} | {} | {} | {} | | | | same run |\n",
                    ratio(p.build_ms, m.build_ms),
                    ratio(p.pairs_ms, m.pairs_ms),
                    ratio(p.distance_ms, m.distance_ms),
                    ratio(p.pairs_total(), m.pairs_total()),
                    ratio(p.distance_total(), m.distance_total()),
                ));
            }
        }
        // Against what the CLI runs: the peer's whole answer (load + build + pairs, and the
        // distance too where meshclash finds the meshes apart) ÷ meshclash's load + check.
        let clear = m.distance.is_some_and(|d| d > 0.0);
        let mut whole: Vec<(String, Option<f64>)> = Vec::new();
        for (tool, p) in [("parry3d-f64", &c.parry_f64), ("parry3d f32", &c.parry_f32)] {
            if let Some(p) = p {
                whole.push((tool.into(), if clear { p.distance_total() } else { p.pairs_total() }));
            }
        }
        // Peers are charged meshclash's load, as parry is (their readers differ: trueform reads
        // OBJ itself, GLB comes through trimesh), so the ratio compares the geometry work.
        for p in c.peers.iter().filter(|p| p.error.is_none()) {
            let work = p.build_ms + if clear { p.pairs_ms + p.distance_ms } else { p.pairs_ms };
            whole.push((p.tool.clone(), Some(m.load_ms + work)));
        }
        for (tool, t) in whole {
            s.push_str(&format!(
                "| {tool} ÷ meshclash CLI path | | | | | {} | | | | | meshclash's load + {} ÷ load + check, same run |\n",
                ratio(t, cli),
                if clear { "build + pairs + distance" } else { "build + pairs" },
            ));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every directed edge once and its reverse once (closed, consistently wound), and the
    /// signed volume positive (outward).
    fn closed_outward(v: &[[f64; 3]], f: &[[u32; 3]]) -> f64 {
        let mut edges = std::collections::HashSet::new();
        for t in f {
            for k in 0..3 {
                assert!(edges.insert((t[k], t[(k + 1) % 3])), "edge used twice in one direction");
            }
        }
        for &(a, b) in &edges {
            assert!(edges.contains(&(b, a)), "open edge {a}-{b}");
        }
        let mut vol = 0.0;
        for t in f {
            let [p, q, r] = t.map(|i| glam::DVec3::from(v[i as usize]));
            vol += p.dot(q.cross(r)) / 6.0;
        }
        vol
    }

    #[test]
    fn icosphere_counts_and_orientation() {
        let (v, f) = icosphere(3);
        assert_eq!(f.len(), 20 * 4usize.pow(3));
        assert_eq!(v.len(), 10 * 4usize.pow(3) + 2);
        let vol = closed_outward(&v, &f);
        assert!(
            vol > 0.95 * 4.0 / 3.0 * std::f64::consts::PI && vol < 4.0 / 3.0 * std::f64::consts::PI,
            "{vol}"
        );
        assert_eq!(icosphere(7).1.len(), 327_680);
    }

    #[test]
    fn torus_counts_and_orientation() {
        let (v, f) = torus(1.0, 0.25, 40);
        assert_eq!(f.len(), 2 * 40 * 40);
        let vol = closed_outward(&v, &f);
        let exact = 2.0 * std::f64::consts::PI.powi(2) * 0.25f64.powi(2);
        assert!(vol > 0.97 * exact && vol < exact, "{vol} vs {exact}");
        assert_eq!(2 * 707 * 707, 999_698);
    }

    #[test]
    fn glb_round_trips_through_split() {
        let (v, f) = torus(1.0, 0.25, 8);
        let bytes = mesh_glb("t", &placed(&v, |p| p), &f);
        assert_eq!(bytes.len() % 4, 0);
        let (json, bin) = split_glb(&bytes).unwrap();
        assert_eq!(bin.len(), v.len() * 12 + f.len() * 12);
        assert_eq!(json["accessors"][1]["count"], f.len() * 3);
        let grid = instance_grid(&json, &grid(2, 3, 1, 1000.0)).unwrap();
        assert_eq!(grid["nodes"].as_array().unwrap().len(), 12);
        assert_eq!(grid["scenes"][0]["nodes"].as_array().unwrap().len(), 6);
        assert_eq!(grid["nodes"][11]["translation"], json!([1000.0, 0.0, 2000.0]));
    }
}
