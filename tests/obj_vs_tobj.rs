//! Our OBJ loader against tobj (f64), an independent parser, on real files: the same triangles
//! with the same coordinates, in the same order.

use meshclash::load::{load_path, Format};
use std::path::PathBuf;

use crate::common::{corpus, shared};

fn same_as_tobj(path: PathBuf) {
    let (ours, format) = load_path(&path).unwrap();
    assert_eq!(format, Format::Obj);
    let opts = tobj::LoadOptions { triangulate: true, single_index: false, ..Default::default() };
    let (models, _) = tobj::load_obj(&path, &opts).unwrap();
    let mut theirs: Vec<[[f64; 3]; 3]> = Vec::new();
    for m in &models {
        let p = &m.mesh.positions;
        for f in m.mesh.indices.chunks(3) {
            theirs.push([0, 1, 2].map(|k| {
                let i = f[k] as usize * 3;
                [p[i], p[i + 1], p[i + 2]]
            }));
        }
    }
    let m = &ours.mesh;
    assert_eq!(m.triangles.len(), theirs.len(), "{}", path.display());
    for (t, want) in m.triangles.iter().zip(&theirs) {
        let got = t.map(|i| m.positions[i as usize].to_array());
        assert_eq!(&got, want, "{}", path.display());
    }
}

#[test]
fn fcl_env_and_rob_parse_like_tobj() {
    same_as_tobj(shared("fcl_env.obj"));
    same_as_tobj(shared("fcl_rob.obj"));
}

#[test]
fn bunny_parses_like_tobj() {
    let Some(bunny) = corpus("stanford-bunny.obj") else { return };
    same_as_tobj(bunny);
}

#[test]
fn joined_tetrahedra_parse_like_tobj() {
    same_as_tobj(shared("joined_tetrahedra.obj"));
}
