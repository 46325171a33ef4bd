//! A glTF scene checked part by part without its pair lists (`scene --detail parts`) runs on the
//! instanced scene, each part placed when the check reads it; every other request expands the
//! scene first. Both paths must give the same report, byte for byte: each scene here is checked
//! in-process both ways and the JSON compared, and the instanced input's summary (vertex,
//! triangle and zero-area counts, objects, box) is compared with the expanded mesh's.

use crate::common::{corpus, shared};
use meshclash::check::assembly::Selection;
use meshclash::check::query::{Detail, MeshInfo};
use meshclash::pipeline::{self, Request, Tolerance};
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
    // An output that draws the geometry sees the expanded mesh.
    assert_eq!(*placed.meshes()[0].mesh(), expanded.inputs[0].input.mesh, "{name}");
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
    let pairs = parts_request(&file, |r| r.settings.detail = Detail::Pairs);
    let expanded: [Request; 4] = [
        pairs,
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
