//! A glTF scene check (either detail) runs on the instanced scene, each part placed when the
//! check reads it, and the finding ids and regions reading the pairs' triangles one by one;
//! requests that read the whole world mesh expand the scene first. Both paths must give the
//! same report, byte for byte: each scene here is checked in-process both ways and the JSON
//! compared, and the instanced input's summary (vertex, triangle and zero-area counts, objects,
//! box) and triangles are compared with the expanded mesh's.

use crate::common::{corpus, shared};
use meshclash::check::assembly::Selection;
use meshclash::check::query::{Detail, MeshInfo};
use meshclash::pipeline::{self, Request, Tolerance};
use meshclash::scene::mesh::WorldTriangles;
use std::path::Path;

/// The scene request of `file` at `--detail parts --no-timings`, with `edit` applied.
fn parts_request(file: &Path, edit: impl Fn(&mut Request)) -> Request {
    let mut req = Request::scene(file);
    req.settings.detail = Detail::Parts;
    req.deterministic = true;
    edit(&mut req);
    req
}

fn json(o: &pipeline::Outcome) -> String {
    serde_json::to_string_pretty(&pipeline::report::build(o)).unwrap()
}

/// Runs `req` both ways: asserts that it takes the instanced path, that both reports are the
/// same bytes, and that the instanced summary is the expanded mesh's.
fn both_paths_agree(req: &Request) {
    let name = req.inputs[0].path().display().to_string();
    assert!(pipeline::instanced_path(req), "{name}: takes the instanced path");
    let (placed, expanded) = match (pipeline::run(req, &|_| {}), pipeline::run_expanded(req, &|_| {})) {
        (Ok(p), Ok(e)) => (p, e),
        (Err(p), Err(e)) => return assert_eq!(p.to_string(), e.to_string(), "{name}"),
        (p, e) => panic!("{name}: {:?} against {:?}", p.err(), e.err()),
    };
    let i = placed.inputs[0].instanced.as_ref().expect("instanced input");
    assert!(expanded.inputs[0].instanced.is_none(), "{name}");
    assert_eq!(i.info, MeshInfo::of(&expanded.inputs[0].input.mesh), "{name}");
    assert_eq!(json(&placed), json(&expanded), "{name}");
    // The report read the objects' names alone; an output that draws the geometry sees the
    // expanded mesh.
    let objects = &expanded.inputs[0].input.mesh.objects;
    let names = placed.meshes()[0].world_triangles();
    assert!(objects.iter().enumerate().all(|(k, o)| names.object_name(k as u32) == o.name), "{name}");
    assert_eq!(*placed.meshes()[0].world_mesh(), expanded.inputs[0].input.mesh, "{name}");
}

/// [`parts_request`] at the default detail (the pair lists kept).
fn pairs_request(file: &Path, edit: impl Fn(&mut Request)) -> Request {
    parts_request(file, |r| {
        r.settings.detail = Detail::Pairs;
        edit(r)
    })
}

/// Every triangle the instanced scene of `file` gives one at a time is the expanded mesh's,
/// bit for bit, with its object and the object's name.
fn triangles_are_the_expanded_ones(file: &Path) {
    let name = file.display().to_string();
    let bytes = std::fs::read(file).unwrap();
    let scene = meshclash::load::load_gltf_instanced(file, &bytes).unwrap();
    let mesh = scene.expand().unwrap().mesh;
    for t in 0..mesh.triangles.len() as u32 {
        let (got, want) = (scene.corners(t), mesh.corners(t));
        let bits = |c: [glam::DVec3; 3]| c.map(|p| p.to_array().map(f64::to_bits));
        assert_eq!(bits(got), bits(want), "{name}: triangle {t}");
        assert_eq!(scene.object_of(t), mesh.object_of(t), "{name}: triangle {t}");
    }
    for o in 0..=mesh.objects.len() as u32 {
        assert_eq!(scene.object_name(o), mesh.object_name(o), "{name}: object {o}");
    }
}

#[test]
fn an_instanced_scene_reads_each_triangle_as_the_expanded_mesh_holds_it() {
    for name in ["Box.glb", "SimpleMeshes.gltf", "pins.glb", "simple_pole.glb"] {
        triangles_are_the_expanded_ones(&shared(name));
    }
    if let Some(file) = corpus("2CylinderEngine.glb") {
        triangles_are_the_expanded_ones(&file);
    }
}

#[test]
fn shipped_gltf_scenes_give_the_same_report_with_pairs_instanced_and_expanded() {
    for name in ["Box.glb", "SimpleMeshes.gltf", "pins.glb", "simple_pole.glb"] {
        let file = shared(name);
        both_paths_agree(&pairs_request(&file, |_| {}));
        both_paths_agree(&pairs_request(&file, |r| {
            r.clearance = Tolerance::Rel(0.05);
            r.touch = Tolerance::Rel(1e-3);
        }));
        // A cut list: the ids of the pairs it leaves out are listed too.
        both_paths_agree(&pairs_request(&file, |r| r.max_pairs = 3));
        both_paths_agree(&pairs_request(&file, |r| {
            r.selection = Selection { scene: true, select_a: vec!["*1*".into()], ..Selection::default() };
        }));
    }
}

/// A baseline compares the run's finding ids with a report's: the same comparison on both
/// paths, against a baseline written by a run with another touch tolerance (so some findings
/// are new) and cut to a few listed pairs (the rest under `unlisted`).
fn baseline_runs_agree(file: &Path) {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("base.json");
    let earlier = pipeline::run_expanded(
        &pairs_request(file, |r| {
            r.touch = Tolerance::Rel(1e-3);
            r.max_pairs = 5;
        }),
        &|_| {},
    )
    .unwrap();
    std::fs::write(&base, json(&earlier)).unwrap();
    both_paths_agree(&pairs_request(file, |r| r.baseline = Some(base.clone())));
    both_paths_agree(&pairs_request(file, |r| {
        r.baseline = Some(base.clone());
        r.gate = meshclash::pipeline::Gate::New;
    }));
}

#[test]
fn a_baseline_gives_the_same_comparison_instanced_and_expanded() {
    baseline_runs_agree(&shared("pins.glb"));
    if let Some(file) = corpus("2CylinderEngine.glb") {
        baseline_runs_agree(&file);
    }
}

#[test]
fn engine_scene_gives_the_same_report_with_pairs_instanced_and_expanded() {
    let Some(file) = corpus("2CylinderEngine.glb") else { return };
    both_paths_agree(&pairs_request(&file, |_| {}));
    both_paths_agree(&pairs_request(&file, |r| {
        r.clearance = Tolerance::Abs(1.0);
        r.max_pairs = 50;
    }));
}

#[test]
fn shipped_gltf_scenes_give_the_same_report_instanced_and_expanded() {
    for name in ["Box.glb", "SimpleMeshes.gltf", "pins.glb", "simple_pole.glb"] {
        let file = shared(name);
        both_paths_agree(&parts_request(&file, |_| {}));
        // A clearance makes every near part pair search its distance; a touch tolerance changes
        // which pairs touch.
        both_paths_agree(&parts_request(&file, |r| {
            r.clearance = Tolerance::Rel(0.05);
            r.touch = Tolerance::Rel(1e-3);
        }));
        // A selection of the parts against the rest.
        both_paths_agree(&parts_request(&file, |r| {
            r.selection = Selection { scene: true, select_a: vec!["*1*".into()], ..Selection::default() };
        }));
    }
}

#[test]
fn engine_scene_gives_the_same_report_instanced_and_expanded() {
    let Some(file) = corpus("2CylinderEngine.glb") else { return };
    both_paths_agree(&parts_request(&file, |_| {}));
    both_paths_agree(&parts_request(&file, |r| r.clearance = Tolerance::Abs(1.0)));
}

#[test]
fn what_reads_the_whole_mesh_expands_the_scene() {
    let file = shared("pins.glb");
    assert!(pipeline::instanced_path(&parts_request(&file, |_| {})));
    assert!(pipeline::instanced_path(&pairs_request(&file, |_| {})));
    let expanded: [Request; 4] = [
        pairs_request(&file, |r| r.penetration = true),
        parts_request(&file, |r| r.split_bodies = true),
        parts_request(&file, |r| r.units.scale[0] = Some(2.0)),
        parts_request(&file, |r| r.inputs[0].transform = glam::DMat4::from_scale(glam::DVec3::splat(2.0))),
    ];
    for req in &expanded {
        assert!(!pipeline::instanced_path(req));
        let o = pipeline::run(req, &|_| {}).unwrap();
        assert!(o.inputs[0].instanced.is_none());
    }
    // Another format is loaded as it always is.
    let obj = parts_request(&shared("fcl_env.obj"), |_| {});
    let o = pipeline::run(&obj, &|_| {}).unwrap();
    assert!(o.inputs[0].instanced.is_none());
    assert_eq!(json(&o), json(&pipeline::run_expanded(&obj, &|_| {}).unwrap()));
}
