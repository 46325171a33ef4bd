//! Assemblies: part pairs from the broad phase + lazy per-part trees (+ shared instance
//! topology) against the plain whole-mesh check grouped by object, on real CAD exports.
#![allow(clippy::type_complexity, clippy::large_enum_variant, clippy::field_reassign_with_default)]
#![allow(clippy::doc_lazy_continuation)] // test helpers: tuple rows and long case docs read better as they are

use glam::DMat4;
use meshclash::assembly::{check_parts, parts_of, Pairing};
use meshclash::query::{check, load_input, InputSpec, PairKind, Settings, Verdict};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn shared(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes").join(name)
}

fn load(path: PathBuf) -> meshclash::mesh::Mesh {
    load_input(&InputSpec { path, transform: DMat4::IDENTITY }).unwrap().mesh
}

/// (object a, object b) -> (crossing, touching) from the whole mesh against itself.
fn by_object(mesh: &meshclash::mesh::Mesh) -> BTreeMap<(u32, u32), (u64, u64)> {
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
    mesh: &meshclash::mesh::Mesh,
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
    let mesh = load(shared("2CylinderEngine.glb"));
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
