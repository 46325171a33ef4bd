//! Assemblies: part pairs from the broad phase + lazy per-part trees (+ shared instance
//! topology) against the plain whole-mesh check grouped by object, on real CAD exports.
#![allow(clippy::type_complexity, clippy::large_enum_variant, clippy::field_reassign_with_default)]
#![allow(clippy::doc_lazy_continuation)] // test helpers: tuple rows and long case docs read better as they are

use glam::DMat4;
use meshclash::check::assembly::{check_parts, parts_of, Pairing};
use meshclash::check::query::{check, load_input, InputSpec, PairKind, Settings, Verdict};
use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::common::{corpus, shared};

fn load(path: PathBuf) -> meshclash::scene::mesh::Mesh {
    load_input(&InputSpec { path, transform: DMat4::IDENTITY }).unwrap().mesh
}

/// (object a, object b) -> (crossing, touching) from the whole mesh against itself.
fn by_object(mesh: &meshclash::scene::mesh::Mesh) -> BTreeMap<(u32, u32), (u64, u64)> {
    let r = check(mesh, mesh, &Settings::default());
    let mut m = BTreeMap::new();
    for p in &r.pairs {
        let (oa, ob) = (mesh.tri_object[p.a as usize], mesh.tri_object[p.b as usize]);
        if oa < ob {
            let e = m.entry((oa, ob)).or_insert((0, 0));
            match p.kind {
                PairKind::Crossing => e.0 += 1,
                _ => e.1 += 1,
            }
        }
    }
    m
}

fn scene_findings(
    mesh: &meshclash::scene::mesh::Mesh,
    threads: usize,
) -> (BTreeMap<(u32, u32), (u64, u64)>, usize, usize) {
    let parts = parts_of(mesh, 0);
    let all: Vec<usize> = (0..parts.len()).collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let r = pool
        .install(|| check_parts([mesh, mesh], parts, &all, &all, Pairing::AllVsAll, &Settings::default()));
    let mut m = BTreeMap::new();
    for pp in &r.part_pairs {
        let c = &pp.result.counts;
        if c.crossing + c.touching > 0 {
            m.insert((r.parts[pp.a].object, r.parts[pp.b].object), (c.crossing, c.touching));
        }
    }
    (m, r.sah_builds, r.built.iter().filter(|b| **b).count())
}

#[test]
fn engine_part_pairs_match_the_whole_mesh_check() {
    let Some(engine) = corpus("2CylinderEngine.glb") else { return };
    let mesh = load(engine);
    let want = by_object(&mesh);
    let (got, sah_builds, built) = scene_findings(&mesh, 2);
    assert_eq!(got, want);
    assert!(!got.is_empty());
    // Instances of one glTF mesh share one SAH build.
    let distinct: std::collections::BTreeSet<u32> = mesh.objects.iter().filter_map(|o| o.gltf_mesh).collect();
    assert!(sah_builds <= distinct.len(), "{sah_builds} builds for {} distinct meshes", distinct.len());
    assert!(built <= mesh.objects.len());
    // Deterministic across thread counts.
    assert_eq!(scene_findings(&mesh, 1).0, got);
}

#[test]
fn pins_dowels_pass_through_the_plate() {
    let mesh = load(shared("pins.glb"));
    let want = by_object(&mesh);
    let (got, sah_builds, _) = scene_findings(&mesh, 2);
    assert_eq!(got, want);
    // One plate, six instances of one dowel: at most two SAH builds.
    assert!(sah_builds <= 2);
    let parts = parts_of(&mesh, 0);
    assert_eq!(parts.len(), 7);
    let all: Vec<usize> = (0..7).collect();
    let r = check_parts([&mesh, &mesh], parts, &all, &all, Pairing::AllVsAll, &Settings::default());
    assert_eq!(r.verdict(), Verdict::Clash);
}

// ---------------------------------------------------------------------------------------------
// Constructed instanced scenes: one glTF mesh drawn by several nodes, so that every instance but
// the first walks the first one's tree through a box map (mirrored, non-uniformly scaled).

/// Corners of the box `lo..hi` (bit 0 → x, bit 1 → y, bit 2 → z) and its 12 triangles, wound
/// outward.
fn box_mesh(lo: [f32; 3], hi: [f32; 3], base: u16) -> (Vec<[f32; 3]>, Vec<u16>) {
    let p = (0..8).map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 0 { lo[k] } else { hi[k] })).collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let idx = quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).map(|i| i + base).collect();
    (p, idx)
}

/// A glTF with the given meshes (each a list of boxes) and nodes `(name, mesh, scale,
/// translation)`, all roots of the scene, with one base64 buffer.
fn gltf(meshes: &[Vec<([f32; 3], [f32; 3])>], nodes: &[(&str, usize, [f32; 3], [f32; 3])]) -> Vec<u8> {
    use base64::Engine;
    let mut buf: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut gl_meshes) = (Vec::new(), Vec::new(), Vec::new());
    for boxes in meshes {
        let (mut pos, mut idx) = (Vec::new(), Vec::new());
        for &(lo, hi) in boxes {
            let (p, i) = box_mesh(lo, hi, pos.len() as u16);
            pos.extend(p);
            idx.extend(i);
        }
        let lo = [0, 1, 2].map(|k| pos.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min));
        let hi = [0, 1, 2].map(|k| pos.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max));
        let off = buf.len();
        buf.extend(pos.iter().flatten().flat_map(|x| x.to_le_bytes()));
        views.push(format!(r#"{{"buffer":0,"byteOffset":{off},"byteLength":{}}}"#, buf.len() - off));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#,
            views.len() - 1,
            pos.len()
        ));
        let off = buf.len();
        buf.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
        while !buf.len().is_multiple_of(4) {
            buf.push(0);
        }
        views.push(format!(r#"{{"buffer":0,"byteOffset":{off},"byteLength":{}}}"#, idx.len() * 2));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5123,"count":{},"type":"SCALAR"}}"#,
            views.len() - 1,
            idx.len()
        ));
        gl_meshes.push(format!(
            r#"{{"primitives":[{{"attributes":{{"POSITION":{}}},"indices":{}}}]}}"#,
            accessors.len() - 2,
            accessors.len() - 1
        ));
    }
    let nodes_json: Vec<String> = nodes
        .iter()
        .map(|(name, m, s, t)| format!(r#"{{"name":"{name}","mesh":{m},"scale":{s:?},"translation":{t:?}}}"#))
        .collect();
    let data = base64::engine::general_purpose::STANDARD.encode(&buf);
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{:?}}}],"nodes":[{}],"meshes":[{}],
"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{}],"accessors":[{}]}}"#,
        (0..nodes.len()).collect::<Vec<_>>(),
        nodes_json.join(","),
        gl_meshes.join(","),
        buf.len(),
        views.join(","),
        accessors.join(",")
    )
    .into_bytes()
}

fn load_gltf(bytes: &[u8]) -> meshclash::scene::mesh::Mesh {
    meshclash::load::load_bytes(std::path::Path::new("scene.gltf"), bytes, meshclash::load::Format::Gltf)
        .unwrap()
        .mesh
}

/// Every candidate part pair of a scene, by part names, with 1 and 2 threads (which must agree).
fn scene_pairs(
    mesh: &meshclash::scene::mesh::Mesh,
    settings: &Settings,
) -> (
    BTreeMap<(String, String), meshclash::check::query::ClashResult>,
    meshclash::check::assembly::AssemblyResult,
) {
    let run = |threads: usize| {
        let parts = parts_of(mesh, 0);
        let all: Vec<usize> = (0..parts.len()).collect();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| check_parts([mesh, mesh], parts, &all, &all, Pairing::AllVsAll, settings))
    };
    let (r1, r2) = (run(1), run(2));
    assert_eq!(r1.part_pairs, r2.part_pairs, "thread count changed a result");
    assert_eq!((r1.sah_builds, r1.sharing), (r2.sah_builds, r2.sharing));
    let by_name = r2
        .part_pairs
        .iter()
        .map(|pp| ((r2.parts[pp.a].name.clone(), r2.parts[pp.b].name.clone()), pp.result.clone()))
        .collect();
    (by_name, r2)
}

/// The whole-mesh check (no parts, no instancing) grouped by object names: (crossing, touching,
/// clearance) per pair of objects that has any.
fn whole_by_name(
    mesh: &meshclash::scene::mesh::Mesh,
    settings: &Settings,
) -> BTreeMap<(String, String), (u64, u64, u64)> {
    let r = check(mesh, mesh, settings);
    let mut m = BTreeMap::new();
    for p in &r.pairs {
        let (oa, ob) = (mesh.tri_object[p.a as usize], mesh.tri_object[p.b as usize]);
        if oa < ob {
            let key = (mesh.objects[oa as usize].name.clone(), mesh.objects[ob as usize].name.clone());
            let e = m.entry(key).or_insert((0, 0, 0));
            match p.kind {
                PairKind::Crossing => e.0 += 1,
                PairKind::Touching => e.1 += 1,
                PairKind::Clearance => e.2 += 1,
            }
        }
    }
    m
}

fn counted(
    pairs: &BTreeMap<(String, String), meshclash::check::query::ClashResult>,
) -> BTreeMap<(String, String), (u64, u64, u64)> {
    pairs
        .iter()
        .map(|(k, r)| (k.clone(), (r.counts.crossing, r.counts.touching, r.counts.clearance)))
        .filter(|(_, c)| *c != (0, 0, 0))
        .collect()
}

fn key(a: &str, b: &str) -> (String, String) {
    (a.to_string(), b.to_string())
}

/// A unit cube drawn four times: `big` (scale 10, the first, whose tree the others share), and
/// three mirrored unit cubes (scale x −1, so their listed winding faces inward): `inner` wholly
/// inside `big`, `outside` against `big`'s face x = 10 from outside, `flush` against the same
/// face from inside. The other instances' boxes are `big`'s mapped by scale 1/10 (inexact in
/// binary) and a mirror.
#[test]
fn mirrored_instances_keep_containment_and_face_contacts() {
    let unit = vec![([0.0f32; 3], [1.0f32; 3])];
    let bytes = gltf(
        &[unit],
        &[
            ("big", 0, [10.0; 3], [0.0; 3]),
            ("inner", 0, [-1.0, 1.0, 1.0], [5.0, 2.0, 2.0]), // x 4..5, y 2..3, z 2..3
            ("outside", 0, [-1.0, 1.0, 1.0], [11.0, 2.0, 2.0]), // x 10..11, shares x = 10
            ("flush", 0, [-1.0, 1.0, 1.0], [10.0, 5.0, 5.0]), // x 9..10, inside, on x = 10
        ],
    );
    let mesh = load_gltf(&bytes);
    let settings = Settings::default();
    let (pairs, r) = scene_pairs(&mesh, &settings);
    // The broad phase: the three small cubes' boxes are apart from each other (y or x ranges
    // disjoint), and each meets big's.
    let keys: Vec<_> = pairs.keys().cloned().collect();
    assert_eq!(
        keys,
        vec![key("big", "inner"), key("big", "outside"), key("big", "flush")]
            .into_iter()
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect::<Vec<_>>()
    );
    // One tree, built for `big`; the three mirrored cubes walk it through a map.
    assert_eq!(r.sah_builds, 1);
    assert_eq!((r.sharing.shared_trees, r.sharing.mapped_instances), (1, 3));
    assert!(r.sharing.memory_saved_bytes > 0);

    let inner = &pairs[&key("big", "inner")];
    assert!(inner.pairs.is_empty());
    assert_eq!(inner.containment, meshclash::check::containment::Containment::BInA);
    assert_eq!(inner.verdict, Verdict::Clash);
    // Nearest: inner's face x = 4 and big's x = 0 are 4 apart, its face y = 2 is 2 from y = 0,
    // z likewise; the closest is 2 (faces y = 2 / y = 0 or z = 2 / z = 0).
    assert_eq!(inner.closest.unwrap().distance, 2.0);

    let outside = &pairs[&key("big", "outside")];
    assert_eq!(outside.counts.crossing, 0);
    assert!(outside.counts.touching > 0);
    assert_eq!(outside.containment, meshclash::check::containment::Containment::None);
    assert_eq!(outside.verdict, Verdict::Touching);

    let flush = &pairs[&key("big", "flush")];
    assert_eq!(flush.counts.crossing, 0);
    assert!(flush.counts.touching > 0);
    assert_eq!(flush.containment, meshclash::check::containment::Containment::VolumesOverlap);
    assert_eq!(flush.verdict, Verdict::Clash);

    // The triangle pairs are those of the whole-mesh check, which copies and shares nothing.
    assert_eq!(counted(&pairs), whole_by_name(&mesh, &settings));
}

/// Culling must stay conservative under a non-uniform, mirrored map. `n` is the unit cube scaled
/// by (−3, 0.5, 7) and moved by (1, 1, 1): x −2..1, y 1..1.5, z 1..8, sharing the tree of `lead`
/// (scale 10: the map scales by −0.3, 0.05, 0.7, none exact in binary). `touch` (x 1..2, y 0..2,
/// z 0..2) meets n's face x = 1 exactly; `miss` is a second mesh, a slab whose face lies at
/// x = 1 + 2^-52 (one ulp beyond n's face: local x 2^-26 scaled by 2^-26 plus 1, exact in f64)
/// over y 1.125..1.375, z 5..6, plus a block at x 0..0.5, y 3..4 that pulls its box over n's so
/// that the two trees are walked. An inward-rounded box would lose the touch; the near miss must
/// stay clear at distance exactly 2^-52.
#[test]
fn non_uniform_scaled_instance_touches_exactly_and_misses_by_one_ulp() {
    let unit = vec![([0.0f32; 3], [1.0f32; 3])];
    let e = 2f32.powi(26);
    let slab = vec![([1.0 / e, 1.125, 5.0], [e, 1.375, 6.0]), ([-e, 3.0, 5.0], [-e / 2.0, 4.0, 6.0])];
    let bytes = gltf(
        &[unit, slab],
        &[
            ("lead", 0, [10.0; 3], [-40.0, 0.0, 0.0]),   // x −40..−30
            ("partner", 0, [1.0; 3], [-30.0, 0.0, 0.0]), // touches lead at x = −30
            ("n", 0, [-3.0, 0.5, 7.0], [1.0, 1.0, 1.0]),
            ("touch", 0, [1.0, 2.0, 2.0], [1.0, 0.0, 0.0]),
            ("miss", 1, [1.0 / e, 1.0, 1.0], [1.0, 0.0, 0.0]),
        ],
    );
    let mesh = load_gltf(&bytes);
    // The slab's face is where the test says.
    let ulp = 2f64.powi(-52);
    let miss_obj = mesh.objects.iter().position(|o| o.name == "miss").unwrap() as u32;
    let min_x = (0..mesh.triangles.len())
        .filter(|&t| mesh.tri_object[t] == miss_obj)
        .flat_map(|t| mesh.triangles[t])
        .map(|v| mesh.positions[v as usize].x)
        .filter(|&x| x > 0.75)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(min_x, 1.0 + ulp);
    let settings = Settings::default();
    let (pairs, r) = scene_pairs(&mesh, &settings);
    assert_eq!(r.sah_builds, 2, "one tree per distinct mesh");
    assert_eq!((r.sharing.shared_trees, r.sharing.mapped_instances), (1, 3));

    let t = &pairs[&key("n", "touch")];
    assert_eq!(t.counts.crossing, 0);
    assert!(t.counts.touching > 0, "the exact face contact was culled");
    assert_eq!(t.verdict, Verdict::Touching);
    // Opposite outward normals (n is mirrored: its listed winding faces inward): contact only.
    assert_eq!(t.containment, meshclash::check::containment::Containment::None);

    let m = &pairs[&key("n", "miss")];
    assert!(m.pairs.is_empty());
    assert_eq!(m.verdict, Verdict::Clear);
    assert_eq!(m.containment, meshclash::check::containment::Containment::None);
    // A clear part pair's distance is searched only as far as it could be the scene's minimum:
    // other pairs touch here (minimum 0), so it is not searched at all; the clearance run
    // below lists it, and with it the exact 2^-52 gap.
    assert!(m.closest.is_none_or(|c| c.distance == ulp));

    let p = &pairs[&key("lead", "partner")];
    assert_eq!((p.counts.crossing, p.verdict), (0, Verdict::Touching));
    assert!(!pairs.contains_key(&key("touch", "miss")), "boxes apart in z");
    assert_eq!(counted(&pairs), whole_by_name(&mesh, &settings));

    // With a clearance of 2^-51 the near miss becomes a clearance finding at 2^-52.
    let wide = Settings {
        tolerances: meshclash::geom::predicates::Tolerances { touch: 0.0, clearance: 2.0 * ulp },
        ..Settings::default()
    };
    let (pairs, _) = scene_pairs(&mesh, &wide);
    let m = &pairs[&key("n", "miss")];
    assert_eq!(m.verdict, Verdict::Clearance);
    assert!(m.counts.clearance > 0 && m.counts.touching == 0 && m.counts.crossing == 0);
    assert!(m.pairs.iter().all(|p| p.distance == ulp));
    assert_eq!(counted(&pairs), whole_by_name(&mesh, &wide));
}

/// An OBJ with one `o` per box (min, max), 12 triangles each, then one `o` per flat fan of `n`
/// triangles around the origin in the plane z = 0 (radius 1 + the fan's index).
fn boxes_and_fans_obj(boxes: &[([f64; 3], [f64; 3])], fans: &[usize]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let mut base = 1;
    for (k, (lo, hi)) in boxes.iter().enumerate() {
        writeln!(s, "o box{k}").unwrap();
        for i in 0..8 {
            let c = |d: usize| if i >> d & 1 == 1 { hi[d] } else { lo[d] };
            writeln!(s, "v {} {} {}", c(0), c(1), c(2)).unwrap();
        }
        for q in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
            let v = q.map(|x| x + base);
            writeln!(s, "f {} {} {}\nf {} {} {}", v[0], v[1], v[2], v[0], v[2], v[3]).unwrap();
        }
        base += 8;
    }
    for (k, &n) in fans.iter().enumerate() {
        writeln!(s, "o fan{k}\nv 0 0 0").unwrap();
        let r = 1.0 + k as f64;
        for i in 0..=n {
            let t = i as f64 / n as f64 * 3.0;
            writeln!(s, "v {} {} 0", r * t.cos(), r * t.sin()).unwrap();
        }
        for i in 0..n {
            writeln!(s, "f {} {} {}", base, base + 1 + i, base + 2 + i).unwrap();
        }
        base += n + 2;
    }
    s
}

/// A report without its triangle-pair lists and regions (what `--detail parts` leaves out).
fn listless(mut r: serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    let o = r.as_object_mut().unwrap();
    for k in ["pairs", "pairs_truncated", "regions", "unlisted"] {
        o.remove(k);
    }
    let settings = o["settings"].as_object_mut().unwrap();
    settings.remove("detail");
    settings.remove("max_pairs");
    for p in o["part_pairs"].as_array_mut().unwrap() {
        let p = p.as_object_mut().unwrap();
        p.remove("pairs");
        p.remove("pairs_truncated");
    }
    Value::Object(o.clone())
}

#[test]
fn detail_parts_tallies_give_the_listed_report_without_the_lists() {
    let dir = std::env::temp_dir().join(format!("meshclash-tally-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Boxes at pseudo-random small-integer corners: crossing, coincident (closed, face to face),
    // nested, touching and near pairs; and coincident open fans that all meet at their apex.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = |m: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % m
    };
    let mut scenes = Vec::new();
    for _ in 0..4 {
        let boxes: Vec<([f64; 3], [f64; 3])> = (0..5)
            .map(|_| {
                let lo = [0, 1, 2].map(|_| next(4) as f64 * 0.5);
                let hi = lo.map(|x| x + 0.5 + next(3) as f64 * 0.5);
                (lo, hi)
            })
            .collect();
        scenes.push((boxes, vec![]));
    }
    let unit = ([0.0; 3], [1.0; 3]);
    scenes.push((vec![unit, unit, ([0.25; 3], [0.75; 3]), ([1.0, 0.0, 0.0], [2.0, 1.0, 1.0])], vec![40, 40]));
    scenes.push((vec![], vec![60, 60, 60]));
    for (k, (boxes, fans)) in scenes.iter().enumerate() {
        let (one, two) = (dir.join(format!("s{k}a.obj")), dir.join(format!("s{k}b.obj")));
        let (half, rest) = boxes.split_at(boxes.len() / 2);
        std::fs::write(&one, boxes_and_fans_obj(half, &fans[..fans.len().min(1)])).unwrap();
        std::fs::write(&two, boxes_and_fans_obj(rest, &fans[fans.len().min(1)..])).unwrap();
        let all = dir.join(format!("s{k}.obj"));
        std::fs::write(&all, boxes_and_fans_obj(boxes, fans)).unwrap();
        let (one, two, all) = (one.to_str().unwrap(), two.to_str().unwrap(), all.to_str().unwrap());
        let mut cases: Vec<Vec<&str>> = vec![vec!["scene", all], vec!["scene", all, "--clearance", "0.3"]];
        if !half.is_empty() || !fans.is_empty() {
            cases.push(vec![one, two]);
            cases.push(vec![one, two, "--clearance", "0.3", "--touch-tolerance", "0.01"]);
            cases.push(vec![all, all]);
        }
        for case in cases {
            let run = |extra: &[&str]| {
                let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshclash"))
                    .args(&case)
                    .args(extra)
                    .args(["--no-timings", "--threads", "2"])
                    .output()
                    .unwrap();
                let code = out.status.code().unwrap();
                assert!(code < 2, "{case:?}: {}", String::from_utf8_lossy(&out.stderr));
                (code, serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap())
            };
            let (full_code, full) = run(&[]);
            let (parts_code, parts) = run(&["--detail", "parts", "--max-pairs", "0"]);
            assert_eq!(full_code, parts_code, "{case:?}");
            assert_eq!(parts["pairs"].as_array().map(Vec::len), Some(0), "{case:?}");
            let (full, parts) = (listless(full).to_string(), listless(parts).to_string());
            assert!(full == parts, "{case:?}\n{full}\n{parts}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
