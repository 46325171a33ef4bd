//! `--export-glb` through the real binary (two files, scene, `self`), read back with the `gltf`
//! crate: one node per part with the scene written once, one node per clash worst first with a
//! marker, contact lines, faint triangles, extras and a camera, the truncation said in the
//! root's extras, `--up z`, and file names without directories.

use crate::common::boxes_obj;
use assert_cmd::Command;
use meshclash::report::self_report::SelfReport;
use meshclash::report::Report;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn shipped(name: &str) -> String {
    root().join("meshes").join(name).display().to_string()
}

fn bin() -> Command {
    Command::cargo_bin("meshclash").unwrap()
}

/// A GLB read back: the document, its BIN chunk and its JSON.
struct Glb {
    doc: gltf::Document,
    blob: Vec<u8>,
    json: Value,
}

fn load(path: &Path) -> Glb {
    let bytes = std::fs::read(path).unwrap();
    let g = gltf::Gltf::from_slice(&bytes).expect("a valid GLB");
    let blob = g.blob.clone().expect("a BIN chunk");
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + n]).unwrap();
    Glb { doc: g.document, blob, json }
}

impl Glb {
    fn node(&self, name: &str) -> gltf::Node<'_> {
        self.doc.nodes().find(|n| n.name() == Some(name)).unwrap_or_else(|| panic!("no node {name}"))
    }
    fn names(&self) -> Vec<String> {
        self.doc.nodes().map(|n| n.name().unwrap_or("").to_string()).collect()
    }
    /// Clash nodes (`#1 ...`), in file order.
    fn clashes(&self) -> Vec<gltf::Node<'_>> {
        self.doc.nodes().filter(|n| n.name().is_some_and(|s| s.starts_with('#'))).collect()
    }
    fn extras(&self, n: &gltf::Node) -> Value {
        self.json["nodes"][n.index()]["extras"].clone()
    }
    fn root(&self) -> gltf::Node<'_> {
        self.doc.default_scene().unwrap().nodes().next().unwrap()
    }
    /// Primitives of a node with their material name.
    fn prims<'a>(&'a self, n: &gltf::Node<'a>) -> Vec<(gltf::mesh::Mode, String, gltf::Primitive<'a>)> {
        n.mesh()
            .map(|m| {
                m.primitives().map(|p| (p.mode(), p.material().name().unwrap_or("").to_string(), p)).collect()
            })
            .unwrap_or_default()
    }
    /// Triangles of a node's TRIANGLES primitives of material `mat` (any when empty).
    fn tris(&self, n: &gltf::Node, mat: &str) -> usize {
        self.prims(n)
            .iter()
            .filter(|(m, name, _)| *m == gltf::mesh::Mode::Triangles && (mat.is_empty() || name == mat))
            .map(|(_, _, p)| {
                let r = p.reader(|_| Some(&self.blob));
                let idx: Vec<u32> = r.read_indices().expect("indexed").into_u32().collect();
                let count = r.read_positions().unwrap().count() as u32;
                assert!(idx.iter().all(|&i| i < count) && idx.len().is_multiple_of(3));
                idx.len() / 3
            })
            .sum()
    }
    /// Segments of a node's LINES primitives of material `mat`.
    fn lines(&self, n: &gltf::Node, mat: &str) -> usize {
        self.prims(n)
            .iter()
            .filter(|(m, name, _)| *m == gltf::mesh::Mode::Lines && name == mat)
            .map(|(_, _, p)| p.reader(|_| Some(&self.blob)).read_indices().unwrap().into_u32().count() / 2)
            .sum()
    }
    fn material(&self, name: &str) -> gltf::Material<'_> {
        self.doc.materials().find(|m| m.name() == Some(name)).unwrap_or_else(|| panic!("no material {name}"))
    }
    /// Size (largest extent of the POSITION accessor bounds) of a node's primitive of `mat`.
    fn size(&self, n: &gltf::Node, mat: &str, mode: gltf::mesh::Mode) -> f64 {
        let (_, _, p) = self.prims(n).into_iter().find(|(m, name, _)| *m == mode && name == mat).unwrap();
        let b = p.bounding_box();
        (0..3).map(|k| (b.max[k] - b.min[k]) as f64).fold(0.0, f64::max)
    }
}

/// Run with `--export-glb` and `-o`: the GLB, the report and the exit code.
fn run(dir: &Path, args: &[&str]) -> (Glb, Report) {
    let glb = dir.join("r.glb");
    let json = dir.join("r.json");
    let out = bin()
        .args(args)
        .args(["-q", "--no-timings", "--export-glb"])
        .arg(&glb)
        .arg("-o")
        .arg(&json)
        .output()
        .unwrap();
    assert!(out.status.code().unwrap() < 2, "{}", String::from_utf8_lossy(&out.stderr));
    let rep: Report = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    (load(&glb), rep)
}

#[test]
fn two_files_one_node_per_input_and_each_clash_with_marker_lines_triangles_and_camera() {
    let d = tempfile::tempdir().unwrap();
    let (env, rob) = (shipped("fcl_env.obj"), shipped("fcl_rob.obj"));
    let (g, r) = run(d.path(), &[&env, &rob]);
    // Names carry file names only, never the directory the run happened in.
    let dir = root().display().to_string();
    assert!(g.names().iter().all(|n| !n.contains(&dir)), "{:?}", g.names());
    let (a, b) = (g.node("A: fcl_env.obj"), g.node("B: fcl_rob.obj"));
    assert_eq!(g.tris(&a, "part A"), r.inputs.a.triangles);
    // The robot is small next to the environment: nearly opaque, so it keeps its own tint.
    assert_eq!(g.tris(&b, "small part B"), r.inputs.b.triangles);
    let alpha = |m: &str| g.material(m).pbr_metallic_roughness().base_color_factor()[3];
    assert!(alpha("small part B") > alpha("part A"));

    // One clash node per region, named and counted like the region.
    let clashes = g.clashes();
    assert_eq!(clashes.len(), r.regions.len());
    assert_eq!(clashes.len(), 1);
    let (c, region) = (&clashes[0], &r.regions[0]);
    assert_eq!(
        c.name().unwrap(),
        format!("#1 crossing {} \u{d7} {}, {} pairs", region.a_name, region.b_name, region.pairs)
    );
    let x = g.extras(c);
    assert_eq!(x["pairs"], region.pairs as u64);
    assert_eq!(x["id"], region.id.as_str());
    for k in 0..3 {
        let (lo, hi) = (x["bounds"]["min"][k].as_f64().unwrap(), x["bounds"]["max"][k].as_f64().unwrap());
        assert!((lo - region.bounds.min[k]).abs() < 1e-3 && (hi - region.bounds.max[k]).abs() < 1e-3);
        let m = x["centre"][k].as_f64().unwrap();
        assert!(lo <= m && m <= hi);
    }
    // The crossing curve as lines (one segment per crossing pair: 192 < the cap), a marker,
    // and the clash's triangles, each distinct triangle once.
    assert_eq!(g.lines(c, "contact segments"), r.summary.crossing_pairs as usize);
    assert_eq!(g.tris(c, "clash marker"), 8);
    let distinct = |f: fn(&meshclash::report::PairReport) -> u32| {
        r.pairs.iter().map(f).collect::<std::collections::BTreeSet<_>>().len()
    };
    assert_eq!(g.tris(c, "crossing triangles"), distinct(|p| p.a) + distinct(|p| p.b));
    // Its camera looks at its centre (local -Z of the camera node), from the root's frame.
    let cam = c.children().next().expect("a camera node");
    assert!(matches!(cam.camera().unwrap().projection(), gltf::camera::Projection::Perspective(_)));
    let (t, q, _) = cam.transform().decomposed();
    let (root_t, _, _) = g.root().transform().decomposed();
    let look = glam::Quat::from_array(q) * glam::Vec3::NEG_Z;
    let centre = glam::DVec3::new(
        x["centre"][0].as_f64().unwrap(),
        x["centre"][1].as_f64().unwrap(),
        x["centre"][2].as_f64().unwrap(),
    );
    let to_centre =
        (centre - glam::Vec3::from_array(root_t).as_dvec3() - glam::Vec3::from_array(t).as_dvec3())
            .normalize()
            .as_vec3();
    assert!(look.dot(to_centre) > 0.999, "{look} vs {to_centre}");
    assert!(g.doc.nodes().any(|n| n.name() == Some("camera overview") && n.camera().is_some()));

    // Root extras: listed of total, not truncated here.
    let rx = g.extras(&g.root());
    assert_eq!(g.root().name(), Some("meshclash"));
    assert_eq!(rx["pairs"], format!("{} of {}", r.pairs.len(), r.summary.crossing_pairs));
    assert_eq!(rx["truncated"], false);
    assert_eq!(rx["clashes"], 1);

    // Parts see-through, highlighted triangles fainter still, lines and markers opaque; the
    // closest-point markers larger than a clash marker.
    assert_eq!(g.material("part A").alpha_mode(), gltf::material::AlphaMode::Blend);
    assert!(alpha("part A") < 1.0 && alpha("crossing triangles") < alpha("part A"));
    assert_ne!(
        g.material("part A").pbr_metallic_roughness().base_color_factor(),
        g.material("part B").pbr_metallic_roughness().base_color_factor()
    );
    assert_eq!((alpha("contact segments"), alpha("clash marker"), alpha("closest points")), (1.0, 1.0, 1.0));
    let closest = g.node("closest points");
    assert_eq!(g.tris(&closest, "closest points"), 16);
    let tri = gltf::mesh::Mode::Triangles;
    let (m1, m2) = (g.size(c, "clash marker", tri), g.size(&closest, "closest points", tri));
    // Two octahedra of twice the radius: each at least 2x the clash marker.
    assert!(m2 >= 2.0 * m1 * 0.999, "{m2} vs {m1}");

    // Positions + the root's translation give back A's bounds.
    let prim = a.mesh().unwrap().primitives().next().unwrap();
    let p: Vec<[f32; 3]> = prim.reader(|_| Some(&g.blob)).read_positions().unwrap().collect();
    for k in 0..3 {
        let lo = p.iter().map(|v| v[k]).fold(f32::INFINITY, f32::min) as f64 + root_t[k] as f64;
        let hi = p.iter().map(|v| v[k]).fold(f32::NEG_INFINITY, f32::max) as f64 + root_t[k] as f64;
        assert!((lo - r.inputs.a.bounds.min[k]).abs() < 1e-2 && (hi - r.inputs.a.bounds.max[k]).abs() < 1e-2);
    }
}

#[test]
fn scene_is_written_once_with_every_region_however_few_pairs_are_listed() {
    let d = tempfile::tempdir().unwrap();
    let (g, r) = run(d.path(), &["scene", &shipped("pins.glb"), "--max-pairs", "100"]);
    assert!(r.pairs_truncated);
    let parts: Vec<gltf::Node> =
        g.doc.nodes().filter(|n| n.name().is_some_and(|s| s.starts_with("world/"))).collect();
    assert_eq!(parts.len(), r.inputs.a.objects.len());
    let total: usize = parts.iter().map(|n| g.tris(n, "")).sum();
    assert_eq!(total, r.inputs.a.triangles, "the scene is written once");
    // Every region has its node, worst first (all crossing here: by pair count), each with a
    // marker, triangles and a camera, though only 100 of the pairs are listed.
    let clashes = g.clashes();
    assert_eq!(clashes.len(), r.regions.len());
    assert_eq!(clashes.len(), 6);
    let counts: Vec<u64> = clashes.iter().map(|c| g.extras(c)["pairs"].as_u64().unwrap()).collect();
    assert!(counts.windows(2).all(|w| w[0] >= w[1]), "{counts:?}");
    assert_eq!(counts.iter().sum::<u64>(), r.regions.iter().map(|g| g.pairs as u64).sum::<u64>());
    for (i, c) in clashes.iter().enumerate() {
        assert!(c.name().unwrap().starts_with(&format!("#{} crossing world/sides", i + 1)), "{:?}", c.name());
        assert_eq!(g.tris(c, "clash marker"), 8);
        assert!(g.tris(c, "crossing triangles") > 0);
        assert!(g.lines(c, "contact segments") > 0);
        assert!(c.children().any(|k| k.camera().is_some()));
    }
    let rx = g.extras(&g.root());
    let total = r.summary.crossing_pairs + r.summary.touching_pairs + r.summary.clearance_pairs;
    assert_eq!(rx["pairs"], format!("100 of {total}"));
    assert_eq!(rx["truncated"], true);
    let group = g.doc.nodes().find(|n| n.name() == Some("clashes (6)")).unwrap();
    assert_eq!(g.extras(&group), rx);
    // The plate is the A side of the worst clash, the (small) dowels B.
    let tint = |n: &gltf::Node| g.prims(n)[0].1.clone();
    let sides = parts.iter().find(|n| n.name().unwrap().contains("sides")).unwrap();
    assert_eq!(tint(sides), "part A");
    assert!(parts.iter().filter(|n| n.name().unwrap().contains("dowel")).all(|n| tint(n) == "small part B"));

    // Byte-identical whatever the thread count.
    let one = d.path().join("one.glb");
    let two = d.path().join("two.glb");
    for (f, t) in [(&one, "1"), (&two, "2")] {
        let out = bin()
            .args(["scene", &shipped("pins.glb"), "-q", "--no-timings", "--threads", t, "--export-glb"])
            .arg(f)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
    }
    assert_eq!(std::fs::read(one).unwrap(), std::fs::read(two).unwrap());
}

#[test]
fn kinds_get_their_own_colours() {
    let d = tempfile::tempdir().unwrap();
    let a = boxes_obj(d.path(), "slab.obj", &[("slab", [0.0, 0.0, 0.0], [10.0, 10.0, 1.0])]);
    let b = boxes_obj(
        d.path(),
        "parts.obj",
        &[
            ("through", [1.0, 1.0, -1.0], [2.0, 2.0, 2.0]),
            ("sitting", [4.0, 4.0, 1.0], [5.0, 5.0, 2.0]),
            ("hovering", [7.0, 7.0, 1.5], [8.0, 8.0, 2.5]),
        ],
    );
    let (g, _) = run(d.path(), &[&a, &b, "--clearance", "1"]);
    let clashes = g.clashes();
    let kinds: Vec<String> =
        clashes.iter().map(|c| g.extras(c)["kind"].as_str().unwrap().to_string()).collect();
    assert_eq!(kinds, ["crossing", "touching", "clearance"]);
    assert!(g.tris(&clashes[0], "crossing triangles") > 0);
    assert!(g.tris(&clashes[1], "touching triangles") > 0);
    assert!(g.tris(&clashes[2], "clearance triangles") > 0);
    assert!(clashes[1].name().unwrap().starts_with("#2 touching slab \u{d7} sitting"));
    // Two-file parts: `A: file / object` when a file has several objects.
    assert!(g.names().contains(&"B: parts.obj / hovering".to_string()));
    assert!(g.names().contains(&"A: slab.obj".to_string()));
}

#[test]
fn up_z_turns_the_root_so_z_shows_up() {
    let d = tempfile::tempdir().unwrap();
    let a = boxes_obj(d.path(), "tall.obj", &[("tall", [0.0, 0.0, 0.0], [1.0, 2.0, 10.0])]);
    let b = boxes_obj(d.path(), "b.obj", &[("b", [5.0, 0.0, 0.0], [6.0, 1.0, 1.0])]);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    // OBJ: Y up unless told.
    let (g, _) = run(d.path(), &[&a, &b]);
    assert_eq!(g.root().transform().decomposed().1, [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(g.extras(&g.root())["up"], "y");
    let (g, r) = run(d.path(), &[&a, &b, "--up", "z"]);
    let (t, q, _) = g.root().transform().decomposed();
    assert!((q[0] + h).abs() < 1e-6 && q[1] == 0.0 && q[2] == 0.0 && (q[3] - h).abs() < 1e-6, "{q:?}");
    assert_eq!(g.extras(&g.root())["up"], "z");
    // In the viewer's frame the model's Z (0..10) is the height (Y), its Y (0..2) is -Z.
    let prim = g.node("A: tall.obj").mesh().unwrap().primitives().next().unwrap();
    let rot = glam::Quat::from_array(q);
    let world: Vec<glam::Vec3> = prim
        .reader(|_| Some(&g.blob))
        .read_positions()
        .unwrap()
        .map(|p| rot * glam::Vec3::from_array(p) + glam::Vec3::from_array(t))
        .collect();
    let range = |k: usize| {
        let v = world.iter().map(|p| p[k]);
        (v.clone().fold(f32::INFINITY, f32::min), v.fold(f32::NEG_INFINITY, f32::max))
    };
    let close = |(lo, hi): (f32, f32), (a, b): (f64, f64)| {
        (lo as f64 - a).abs() < 1e-4 && (hi as f64 - b).abs() < 1e-4
    };
    let bx = &r.inputs.a.bounds;
    assert!(close(range(1), (bx.min[2], bx.max[2])), "{:?}", range(1));
    assert!(close(range(2), (-bx.max[1], -bx.min[1])), "{:?}", range(2));
    assert!(close(range(0), (bx.min[0], bx.max[0])));
    // STL is Z up by default.
    let (g, _) =
        run(d.path(), &[&shipped("multibody.stl"), &shipped("multibody.stl"), "--translate-b", "100,0,0"]);
    assert_eq!(g.extras(&g.root())["up"], "z");
}

fn obj(dir: &Path, name: &str, v: &[[f64; 3]], f: &[[u32; 3]]) -> PathBuf {
    let mut s = format!("o {}\n", name.trim_end_matches(".obj"));
    for p in v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in f {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

/// A strip folded back through itself (tests/self_clash.rs): 2 crossing and 2 touching pairs
/// between triangles 0, 1 and 4, 5; open, one boundary loop.
pub fn folded_strip(dir: &Path) -> PathBuf {
    let v = [
        [0., 0., 0.],
        [0., 1., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [1., 0., 1.],
        [1., 1., 1.],
        [1., 0., -1.],
        [1., 1., -1.],
    ];
    let f = [[0, 2, 3], [0, 3, 1], [2, 4, 5], [2, 5, 3], [4, 5, 7], [4, 7, 6]];
    obj(dir, "strip.obj", &v, &f)
}

#[test]
fn self_glb_has_a_node_per_self_clash_and_health_problem() {
    let d = tempfile::tempdir().unwrap();
    let strip = folded_strip(d.path());
    let glb = d.path().join("s.glb");
    let out =
        bin().arg("self").arg(&strip).args(["--no-timings", "--export-glb"]).arg(&glb).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let r: SelfReport = serde_json::from_slice(&out.stdout).unwrap();
    let g = load(&glb);
    assert_eq!(g.tris(&g.node("strip"), "part A"), 6);
    let clashes = g.clashes();
    let names: Vec<&str> = clashes.iter().map(|c| c.name().unwrap()).collect();
    let h = &r.parts[0].health;
    assert_eq!(
        names,
        [
            "#1 self-clash crossing strip, 4 pairs".to_string(),
            format!(
                "#2 winding strip: {} edges with inconsistent winding",
                h.inconsistent_winding_edges.count
            ),
            format!("#3 open strip: {} boundary edges, {} loop", h.boundary_edges.count, h.boundary_loops)
        ]
    );
    assert_eq!(h.boundary_loops, 1);
    // The self-clash: lower triangles 0, 1 in the A tint, higher 4, 5 in the B tint, one line
    // per listed pair with a segment.
    assert_eq!(g.tris(&clashes[0], "small part A"), 2);
    assert_eq!(g.tris(&clashes[0], "small part B"), 2);
    let with_segment = r.pairs.iter().filter(|p| p.segment.is_some()).count();
    assert_eq!(g.lines(&clashes[0], "contact segments"), with_segment);
    assert_eq!(g.tris(&clashes[2], "crossing triangles"), h.boundary_edges.triangles.len());
    for c in &clashes {
        assert_eq!(g.tris(c, "clash marker"), 8);
        assert!(c.children().any(|k| k.camera().is_some()));
    }
    let rx = g.extras(&g.root());
    assert_eq!((rx["pairs"].as_str(), rx["truncated"].as_bool()), (Some("4 of 4"), Some(false)));
}

#[test]
fn self_outputs_never_overwrite_the_input() {
    let d = tempfile::tempdir().unwrap();
    let strip = folded_strip(d.path());
    let before = std::fs::read(&strip).unwrap();
    for flag in ["--html", "--export-glb"] {
        let out = bin().arg("self").arg(&strip).arg(flag).arg(&strip).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{flag}");
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(flag) && err.contains("strip.obj"), "{err}");
        assert_eq!(std::fs::read(&strip).unwrap(), before);
    }
}
