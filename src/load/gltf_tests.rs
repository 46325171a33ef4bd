//! Tests for the glTF loader: shared sample files and hostile documents built here.

use super::*;
use crate::load::{load_bytes, load_path, shared, Format};
use base64::Engine as _;
use std::path::PathBuf;

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A triangle: positions (36 bytes) then u16 indices 0,1,2 (+2 pad) = 44 bytes.
fn tri_bin() -> Vec<u8> {
    let mut b = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    for i in [0u16, 1, 2, 0] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

const TRI_VIEWS: &str = r#""bufferViews":[{"buffer":0,"byteLength":36},
    {"buffer":0,"byteOffset":36,"byteLength":6}],
  "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
    {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],
  "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#;

/// A .gltf document with one data-URI buffer holding `bin` and the given top-level members.
fn gltf(bin: &[u8], body: &str) -> Vec<u8> {
    format!(
        r#"{{"asset":{{"version":"2.0"}},
  "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
  {body}}}"#,
        bin.len(),
        b64(bin)
    )
    .into_bytes()
}

/// The standard one-triangle document with the given nodes/scenes members.
fn tri_doc(nodes: &str) -> Vec<u8> {
    gltf(&tri_bin(), &format!("{TRI_VIEWS},{nodes}"))
}

fn path() -> PathBuf {
    PathBuf::from("t.gltf")
}

/// Loads `bytes`, and checks that the load without expansion gives the same mesh, warnings and
/// placed parts ([`same_instanced`]).
fn ok(bytes: &[u8]) -> Loaded {
    let l = load_bytes(&path(), bytes, Format::Gltf).unwrap();
    same_instanced(&path(), bytes, &l);
    l
}

/// The error of loading `bytes`, which the load without expansion gives too.
fn err(bytes: &[u8]) -> String {
    let e = load_bytes(&path(), bytes, Format::Gltf).unwrap_err().to_string();
    assert!(e.starts_with("t.gltf: ") && !e.contains('\n'), "{e}");
    let instanced = crate::load::load_gltf_instanced(&path(), bytes).and_then(|s| s.expand());
    assert_eq!(instanced.unwrap_err().to_string(), e);
    e
}

/// The scene loaded without expansion is `l`: expanded, the same mesh (every coordinate the same
/// bits) and warnings; each part placed alone, the same positions and triangles (less its first
/// vertex) as its object in `l`, the same name, mesh and matrix.
fn same_instanced(path: &std::path::Path, bytes: &[u8], l: &Loaded) {
    let scene = crate::load::load_gltf_instanced(path, bytes).unwrap();
    let bits = |p: &[DVec3]| p.iter().map(|v| v.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    let e = scene.expand().unwrap();
    assert_eq!(e.mesh, l.mesh);
    assert_eq!(bits(&e.mesh.positions), bits(&l.mesh.positions));
    assert_eq!(e.warnings, l.warnings);
    assert_eq!(scene.warnings, l.warnings);
    assert_eq!(scene.parts.len(), l.mesh.objects.len());
    let mut first_tri = 0usize;
    for (k, (part, object)) in scene.parts.iter().zip(&l.mesh.objects).enumerate() {
        assert_eq!(
            (Some(&part.name), Some(part.mesh), Some(part.world)),
            (Some(&object.name), object.gltf_mesh, object.world)
        );
        let (pos, tris) = scene.place(k).unwrap();
        assert_eq!(bits(&scene.place_positions(k)), bits(&pos), "part {k}");
        assert_eq!(scene.part_counts(k), (pos.len(), tris.len()));
        let mine = &l.mesh.triangles[first_tri..first_tri + tris.len()];
        assert!(l.mesh.tri_object[first_tri..first_tri + tris.len()].iter().all(|&o| o as usize == k));
        let base = mine.iter().flatten().copied().min().unwrap_or(0);
        assert_eq!(tris, mine.iter().map(|t| t.map(|v| v - base)).collect::<Vec<_>>(), "part {k}");
        assert_eq!(bits(&pos), bits(&l.mesh.positions[base as usize..base as usize + pos.len()]), "part {k}");
        first_tri += tris.len();
    }
    assert_eq!(first_tri, l.mesh.triangles.len());
}

#[test]
fn instanced_loads_of_shipped_and_shared_scenes_place_parts_as_the_expanded_load() {
    let names = ["Box.glb", "SimpleMeshes.gltf", "pins.glb", "simple_pole.glb", "2CylinderEngine.glb"];
    for name in names {
        let Some(p) = shared(name) else {
            eprintln!("skipped {name}: not found (set MESHCLASH_SHARED_MESHES)");
            continue;
        };
        let bytes = std::fs::read(&p).unwrap();
        let (l, _) = load_path(&p).unwrap();
        same_instanced(&p, &bytes, &l);
        // The scene keeps each mesh once: its own size is independent of the instances.
        let scene = crate::load::load_gltf_instanced(&p, &bytes).unwrap();
        let v: usize = (0..scene.parts.len()).map(|k| scene.part_counts(k).0).sum();
        assert_eq!(v, l.mesh.positions.len(), "{name}");
    }
}

/// Wraps JSON and a binary chunk into a GLB.
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut j = json.to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if let Some(b) = bin {
        let mut b = b.to_vec();
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    let len = out.len() as u32;
    out[8..12].copy_from_slice(&len.to_le_bytes());
    out
}

fn bounds(l: &Loaded) -> (DVec3, DVec3) {
    l.mesh
        .positions
        .iter()
        .fold((DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

#[test]
fn one_triangle_trs_and_names() {
    let l = ok(&tri_doc(
        r#""nodes":[{"name":"top","children":[1],"translation":[10,0,0]},
          {"mesh":0,"scale":[2,2,2],"rotation":[0,0,0.7071068,0.7071068]}],
        "scenes":[{"nodes":[0]}],"scene":0"#,
    ));
    assert_eq!(l.mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(l.mesh.objects.len(), 1);
    let o = &l.mesh.objects[0];
    assert_eq!(o.name, "top/node1");
    assert_eq!(o.gltf_mesh, Some(0));
    // (1,0,0) scaled by 2, rotated 90° about z, translated by +10 x
    let p = l.mesh.positions[1];
    assert!((p - DVec3::new(10.0, 2.0, 0.0)).length() < 1e-12, "{p}");
    assert!((o.world.unwrap().transform_point3(DVec3::X) - p).length() < 1e-15);
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
}

#[test]
fn no_scene_uses_root_nodes_and_glb_works() {
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":44}}],{TRI_VIEWS},
        "nodes":[{{"mesh":0,"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}},{{"mesh":0,"children":[0]}}]}}"#
    );
    let l = load_bytes(Path::new("t.glb"), &glb(json.as_bytes(), Some(&tri_bin())), Format::Glb).unwrap();
    // node 1 is the only root; node 0 is its child
    let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["node1", "node1/node0"]);
    assert_eq!(l.mesh.triangles, vec![[0, 1, 2], [3, 4, 5]]);
    assert_eq!(l.mesh.tri_object, vec![0, 1]);
    assert_eq!(l.mesh.positions[5], DVec3::new(0.0, 1.0, 5.0));
}

#[test]
fn strips_fans_and_skipped_modes() {
    // 5 vertices on a zig-zag; no indices
    let pos = f32s(&[0., 0., 0., 0., 1., 0., 1., 0., 0., 1., 1., 0., 2., 0., 0.]);
    let body = r#""bufferViews":[{"buffer":0,"byteLength":60}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3","min":[0,0,0],"max":[2,1,0]}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":5},
          {"attributes":{"POSITION":0},"mode":6},{"attributes":{"POSITION":0},"mode":0},
          {"attributes":{"POSITION":0},"mode":1}]}],
      "nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let l = ok(&gltf(&pos, body));
    // The strip and the fan use one POSITION accessor: its 5 vertices are placed once and both
    // index them (`inputs.*.vertices` counted a shared accessor once per
    // primitive, 10 here).
    let strip = [[0, 1, 2], [1, 3, 2], [2, 3, 4]];
    let fan = [[0, 1, 2], [0, 2, 3], [0, 3, 4]];
    assert_eq!(l.mesh.triangles, [strip, fan].concat());
    assert_eq!(l.mesh.positions.len(), 5);
    assert_eq!(l.warnings.len(), 2, "{:?}", l.warnings);
    assert!(l.warnings[0].contains("mesh 0 primitive 2: skipped Points"), "{:?}", l.warnings);
    assert!(l.warnings[1].contains("Lines"), "{:?}", l.warnings);
}

#[test]
fn u8_and_u32_indices_and_stride() {
    // interleaved: position + 4 pad bytes, stride 16
    let mut bin = Vec::new();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        bin.extend(f32s(&p));
        bin.extend([0xAA; 4]);
    }
    bin.extend([2u8, 1, 0, 0]); // u8 indices at 48
    for i in [0u32, 2, 1] {
        bin.extend(i.to_le_bytes()); // u32 at 52
    }
    let body = r#""bufferViews":[{"buffer":0,"byteLength":48,"byteStride":16},
        {"buffer":0,"byteOffset":48,"byteLength":3},{"buffer":0,"byteOffset":52,"byteLength":12}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
        {"bufferView":1,"componentType":5121,"count":3,"type":"SCALAR"},
        {"bufferView":2,"componentType":5125,"count":3,"type":"SCALAR"}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1},{"attributes":{"POSITION":0},"indices":2}]}],
      "nodes":[{"mesh":0}]"#;
    let l = ok(&gltf(&bin, body));
    // Both primitives index the one POSITION accessor, placed once.
    assert_eq!(l.mesh.triangles, vec![[2, 1, 0], [0, 2, 1]]);
    assert_eq!(l.mesh.positions.len(), 3);
    assert_eq!(l.mesh.positions[2], DVec3::new(0.0, 1.0, 0.0));
    assert_eq!(l.mesh.objects.len(), 1);
}

#[test]
fn sparse_positions() {
    // base positions + sparse override of vertex 2 -> (5,5,5); second accessor has no base view
    let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
    bin.extend(2u16.to_le_bytes());
    bin.extend([0, 0]);
    bin.extend(f32s(&[5., 5., 5.]));
    let body = r#""bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":2},
        {"buffer":0,"byteOffset":40,"byteLength":12}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[5,5,5],
          "sparse":{"count":1,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}},
        {"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[5,5,5],
          "sparse":{"count":1,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0}},{"attributes":{"POSITION":1}}]}],
      "nodes":[{"mesh":0}]"#;
    let l = ok(&gltf(&bin, body));
    let p = &l.mesh.positions;
    assert_eq!(p[..3], [DVec3::ZERO, DVec3::X, DVec3::splat(5.0)]);
    assert_eq!(p[3..], [DVec3::ZERO, DVec3::ZERO, DVec3::splat(5.0)]);
    // sparse index out of range
    let mut bad = bin.clone();
    bad[36..38].copy_from_slice(&7u16.to_le_bytes());
    let e = err(&gltf(&bad, body));
    assert!(e.contains("sparse index 7 is out of range (3 elements)"), "{e}");
}

#[test]
fn non_finite_positions() {
    for (val, word) in [(f32::NAN, "NaN"), (f32::INFINITY, "inf")] {
        let mut bin = tri_bin();
        bin[16..20].copy_from_slice(&val.to_le_bytes()); // vertex 1, y
        let e = err(&gltf(&bin, &format!("{TRI_VIEWS},\"nodes\":[{{\"mesh\":0}}]")));
        assert!(
            e.contains(&format!("position 1 of mesh 0 primitive 0 has a non-finite coordinate ({word})")),
            "{e}"
        );
    }
    // finite positions overflowing under the node transform (f64: needs a product > 1e308)
    let mut bin = tri_bin();
    bin[12..16].copy_from_slice(&f32::MAX.to_le_bytes());
    let nodes: Vec<String> =
        (0..7).map(|i| format!(r#"{{"children":[{}],"scale":[3e38,1,1]}}"#, i + 1)).collect();
    let body = format!(r#"{TRI_VIEWS},"nodes":[{},{{"mesh":0,"scale":[3e38,1,1]}}]"#, nodes.join(","));
    let e = err(&gltf(&bin, &body));
    assert!(e.contains("position 1 of mesh 0 is not finite (inf) after the transform of node 7"), "{e}");
    // a world matrix overflowing
    let nodes: Vec<String> =
        (0..10).map(|i| format!(r#"{{"children":[{}],"scale":[3e38,3e38,3e38]}}"#, i + 1)).collect();
    let body = format!(r#"{TRI_VIEWS},"nodes":[{},{{"mesh":0}}]"#, nodes.join(","));
    let e = err(&gltf(&tri_bin(), &body));
    assert!(e.contains("glTF node 8: world transform is not finite"), "{e}");
}

/// Triangle lists of every index type, tightly packed (read straight into triangles) or with
/// sparse values (read as a flat list): the same triangles, trailing index warning and
/// out-of-range errors (numbered in the flat list) either way.
#[test]
fn triangle_lists_of_every_index_type_packed_or_sparse() {
    let pad = |b: &mut Vec<u8>| b.resize(b.len().div_ceil(4) * 4, 0);
    for (ct, size) in [(5121, 1usize), (5123, 2), (5125, 4)] {
        let enc = |v: u32| v.to_le_bytes()[..size].to_vec();
        for sparse in [false, true] {
            for (bad_at, bad) in [(None, 0), (Some(4), 9), (Some(6), 9)] {
                let mut idx = [0u32, 1, 2, 2, 1, 3, 3];
                if let Some(k) = bad_at {
                    idx[k] = bad;
                }
                let mut bin = f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.]);
                idx.iter().for_each(|&v| bin.extend(enc(v)));
                pad(&mut bin);
                let sparse_at = bin.len();
                bin.push(4);
                pad(&mut bin);
                let value_at = bin.len();
                bin.extend(enc(0));
                pad(&mut bin);
                let sparse_member = if sparse {
                    r#","sparse":{"count":1,"indices":{"bufferView":2,"componentType":5121},"values":{"bufferView":3}}"#
                } else {
                    ""
                };
                let body = format!(
                    r#""bufferViews":[{{"buffer":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":{}}},
                        {{"buffer":0,"byteOffset":{sparse_at},"byteLength":1}},{{"buffer":0,"byteOffset":{value_at},"byteLength":{size}}}],
                      "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                        {{"bufferView":1,"componentType":{ct},"count":7,"type":"SCALAR"{sparse_member}}}],
                      "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
                      "nodes":[{{"mesh":0}}]"#,
                    7 * size
                );
                let doc = gltf(&bin, &body);
                let case = format!("component type {ct}, sparse {sparse}, {bad_at:?}");
                match bad_at {
                    Some(k) if !(sparse && k == 4) => {
                        let e = err(&doc);
                        let want = format!("index {k} refers to vertex 9 but there are 4 vertices");
                        assert!(e.contains(&want), "{case}: {e}");
                    }
                    _ => {
                        let l = ok(&doc);
                        let second = if sparse { [2, 0, 3] } else { [2, 1, 3] };
                        assert_eq!(l.mesh.triangles, [[0, 1, 2], second], "{case}");
                        assert_eq!(l.warnings.len(), 1, "{case}: {:?}", l.warnings);
                        assert!(l.warnings[0].contains("1 trailing indices"), "{case}: {:?}", l.warnings);
                    }
                }
            }
        }
    }
}

#[test]
fn index_out_of_range() {
    let mut bin = tri_bin();
    bin[40..42].copy_from_slice(&907u16.to_le_bytes());
    let e = err(&gltf(&bin, &format!("{TRI_VIEWS},\"nodes\":[{{\"mesh\":0}}]")));
    assert!(e.contains("mesh 0 primitive 0: index 2 refers to vertex 907 but there are 3 vertices"), "{e}");
}

#[test]
fn ranges_checked() {
    // accessor reads past its bufferView
    let body = TRI_VIEWS.replace(r#""count":3,"type":"VEC3""#, r#""count":4,"type":"VEC3""#);
    let e = err(&gltf(&tri_bin(), &format!("{body},\"nodes\":[{{\"mesh\":0}}]")));
    assert!(e.contains("accessor 0 of mesh 0 primitive 0: 4 elements of 12 bytes"), "{e}");
    // bufferView past its buffer
    let body = TRI_VIEWS.replace(r#""byteOffset":36,"byteLength":6"#, r#""byteOffset":40,"byteLength":6"#);
    let e = err(&gltf(&tri_bin(), &format!("{body},\"nodes\":[{{\"mesh\":0}}]")));
    assert!(e.contains("bufferView 1 (offset 40, length 6) does not fit in buffer 0 (44 bytes)"), "{e}");
    // buffer shorter than its byteLength
    let doc = String::from_utf8(tri_doc(r#""nodes":[{"mesh":0}]"#)).unwrap();
    let e = err(doc.replace("\"byteLength\":44", "\"byteLength\":4000000000").as_bytes());
    assert!(e.contains("glTF buffer 0 declares 4000000000 bytes but its data URI has 44 bytes"), "{e}");
    // huge count without a bufferView (sparse, so the zero base is implied)
    let body = r#""bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],
      "accessors":[{"componentType":5126,"count":4000000000,"type":"VEC3","min":[0,0,0],"max":[0,0,0],
        "sparse":{"count":1,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":0}}}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]"#;
    let e = err(&gltf(&tri_bin(), body));
    assert!(e.contains("declares 4000000000 elements without a bufferView"), "{e}");
}

#[test]
fn glb_hostile_sizes() {
    let p = Path::new("h.glb");
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":4294967295}}],{TRI_VIEWS},"nodes":[{{"mesh":0}}]}}"#
    );
    let bytes = glb(json.as_bytes(), Some(&tri_bin()));
    let e = load_bytes(p, &bytes, Format::Glb).unwrap_err().to_string();
    assert!(
        e.contains("glTF buffer 0 declares 4294967295 bytes but the GLB binary chunk has 44 bytes"),
        "{e}"
    );
    let mut bytes = glb(json.as_bytes(), Some(&tri_bin()));
    bytes[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = load_bytes(p, &bytes, Format::Glb).unwrap_err().to_string();
    assert!(e.contains("truncated GLB: header declares 4294967295 bytes"), "{e}");
    let mut bytes = glb(json.as_bytes(), Some(&tri_bin()));
    let bin_len_at = 20 + json.len().div_ceil(4) * 4;
    bytes[bin_len_at..bin_len_at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = load_bytes(p, &bytes, Format::Glb).unwrap_err().to_string();
    assert!(e.contains("chunk 1 ('BIN') declares 4294967295 bytes"), "{e}");
    let e = load_bytes(p, &glb(json.as_bytes(), None), Format::Glb).unwrap_err().to_string();
    assert!(e.contains("buffer 0 refers to the GLB binary chunk but there is none"), "{e}");
}

#[test]
fn external_buffers() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("my tri.bin"), tri_bin()).unwrap();
    let doc = |uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":44,"uri":"{uri}"}}],{TRI_VIEWS},
            "nodes":[{{"mesh":0}}]}}"#
        )
    };
    let f = dir.path().join("ext.gltf");
    std::fs::write(&f, doc("my%20tri.bin")).unwrap();
    let (l, fmt) = load_path(&f).unwrap();
    assert_eq!(fmt, Format::Gltf);
    assert_eq!(l.mesh.triangles.len(), 1);
    std::fs::write(&f, doc("foo.bin")).unwrap();
    let e = load_path(&f).unwrap_err().to_string();
    assert!(e.contains("glTF external buffer 'foo.bin' cannot be read: No such file or directory"), "{e}");
    assert!(e.starts_with(&f.display().to_string()), "{e}");
    std::fs::write(dir.path().join("short.bin"), [0u8; 10]).unwrap();
    std::fs::write(&f, doc("short.bin")).unwrap();
    let e = load_path(&f).unwrap_err().to_string();
    assert!(e.contains("'short.bin' has 10 bytes but buffer 0 declares 44"), "{e}");
    std::fs::write(&f, doc("https://example.com/x.bin")).unwrap();
    let e = load_path(&f).unwrap_err().to_string();
    assert!(e.contains("is refused: a scheme or drive letter (only data: URIs and relative paths"), "{e}");
}

#[test]
fn node_graph_errors() {
    let e = err(&tri_doc(r#""nodes":[{"mesh":0,"children":[1]},{"children":[0]}],"scenes":[{"nodes":[0]}]"#));
    assert!(e.contains("glTF node graph has a cycle at node 0"), "{e}");
    let e = err(&tri_doc(r#""nodes":[{"mesh":0,"children":[0]}]"#));
    assert!(e.contains("glTF node graph has a cycle at node 0"), "{e}");
    let e = err(&tri_doc(r#""nodes":[{"children":[2]},{"children":[2]},{"mesh":0}]"#));
    assert!(e.contains("glTF node 2 has two parents (nodes 0 and 1)"), "{e}");
    let e = err(&tri_doc(r#""nodes":[{"children":[1]},{"mesh":0}],"scenes":[{"nodes":[0,1]}]"#));
    assert!(e.contains("glTF node 1 is a scene root but also a child of node 0"), "{e}");
    let e = err(&tri_doc(r#""nodes":[{"mesh":0,"rotation":[0,0,0,0]}]"#));
    assert!(e.contains("glTF node 0 has a zero rotation quaternion"), "{e}");
    let e = err(&tri_doc(r#""nodes":[{"mesh":0,"translation":[1e39,0,0]}]"#));
    // Either our check or the JSON parser (when serde_json is built with a feature that
    // rejects out-of-range f32) names the problem.
    assert!(
        e.contains("glTF node 0 has a non-finite translation") || e.contains("number out of range"),
        "{e}"
    );
    let e = err(&tri_doc(r#""nodes":[{"mesh":0,"children":[5]}]"#));
    assert!(e.contains("invalid glTF: nodes[0].children[0]"), "{e}");
}

fn chain(depth: usize) -> Vec<u8> {
    let mut nodes: Vec<String> = (0..depth - 1).map(|i| format!(r#"{{"children":[{}]}}"#, i + 1)).collect();
    nodes.push(r#"{"mesh":0}"#.into());
    tri_doc(&format!(r#""nodes":[{}],"scenes":[{{"nodes":[0]}}]"#, nodes.join(",")))
}

#[test]
fn instancing_bomb_refused() {
    // 70 000 vertices (a strip) instanced by 4000 nodes: 2.8e8 vertices > 2^28
    let n = 70_000;
    let bin = vec![0u8; 12 * n];
    let nodes = vec![r#"{"mesh":0}"#; 4000].join(",");
    let body = format!(
        r#""bufferViews":[{{"buffer":0,"byteLength":{}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":[0,0,0],"max":[0,0,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":5}}]}}],"nodes":[{nodes}]"#,
        12 * n
    );
    let e = err(&gltf(&bin, &body));
    assert!(
        e.contains("glTF scene has 280000000 vertices after instancing, more than the 268435456 supported"),
        "{e}"
    );
}

#[test]
fn deep_hierarchies() {
    let e = err(&chain(5000));
    assert!(e.contains("glTF node hierarchy deeper than 1024 levels (at node 1024)"), "{e}");
    let l = ok(&chain(MAX_DEPTH));
    assert_eq!(l.mesh.triangles.len(), 1);
    assert!(l.mesh.objects[0].name.ends_with("/node1022/node1023"));
}

#[test]
fn extensions() {
    let doc = String::from_utf8(tri_doc(r#""nodes":[{"mesh":0}]"#)).unwrap();
    let with = |members: &str| doc.replacen('{', &format!("{{{members},"), 1);
    let e = err(with(r#""extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"]"#).as_bytes());
    assert!(
        e.contains("glTF requires extension 'KHR_draco_mesh_compression', which is not supported"),
        "{e}"
    );
    let e = err(with(r#""extensionsRequired":["EXT_meshopt_compression"]"#).as_bytes());
    assert!(e.contains("'EXT_meshopt_compression'"), "{e}");
    let l = ok(with(r#""extensionsUsed":["EXT_mesh_gpu_instancing"]"#).as_bytes());
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    assert_eq!(l.mesh.objects[0].name, "node0");
    let l =
        ok(with(r#""extensionsUsed":["KHR_materials_unlit"],"extensionsRequired":["KHR_materials_unlit"]"#)
            .as_bytes());
    assert_eq!(l.mesh.triangles.len(), 1);
}

#[test]
fn garbage_documents() {
    let e = err(b"{ not json");
    assert!(e.contains("invalid glTF JSON"), "{e}");
    let e = err(br#"{"asset":{"version":"2.0"}}"#);
    assert!(e.contains("no triangles"), "{e}");
    let e = err(&tri_doc(r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[]}]"#));
    assert!(e.contains("no triangles"), "{e}");
    let e = load_bytes(Path::new("t.glb"), b"glTF\x02\0\0\0\x0c\0\0\0", Format::Glb).unwrap_err().to_string();
    assert!(e.contains("GLB has no JSON chunk"), "{e}");
}

#[test]
fn shared_box() {
    let Some(p) = shared("Box.glb") else { return };
    let (l, f) = load_path(&p).unwrap();
    assert_eq!(f, Format::Glb);
    assert_eq!(l.mesh.triangles.len(), 12);
    let (lo, hi) = bounds(&l);
    assert!((lo - DVec3::splat(-0.5)).abs().max_element() < 1e-6, "{lo}");
    assert!((hi - DVec3::splat(0.5)).abs().max_element() < 1e-6, "{hi}");
    assert_eq!(l.mesh.objects.len(), 1);
    let o = &l.mesh.objects[0];
    assert_eq!(o.name, "node0/node1");
    // the parent matrix (column-major) maps y to -z and z to y (Z-up to Y-up)
    let w = o.world.unwrap();
    assert!((w.transform_point3(DVec3::Y) + DVec3::Z).length() < 1e-12);
    assert!((w.transform_point3(DVec3::Z) - DVec3::Y).length() < 1e-12);
}

#[test]
fn shared_simple_meshes() {
    let Some(p) = shared("SimpleMeshes.gltf") else {
        return;
    };
    let (l, f) = load_path(&p).unwrap();
    assert_eq!(f, Format::Gltf);
    assert_eq!(l.mesh.triangles.len(), 2);
    assert_eq!(l.mesh.objects.len(), 2);
    assert!(l.mesh.objects.iter().all(|o| o.gltf_mesh == Some(0)));
    let t = &l.mesh.triangles;
    let p = |t: u32| l.mesh.positions[t as usize];
    for (&a, &b) in t[0].iter().zip(&t[1]) {
        assert_eq!(p(b) - p(a), DVec3::X);
    }
}

#[test]
fn shared_assemblies() {
    for (name, tris, objects) in
        [("2CylinderEngine.glb", 121496, 67), ("pins.glb", 3408, 7), ("simple_pole.glb", 580, 11)]
    {
        let Some(p) = shared(name) else { return };
        let (l, _) = load_path(&p).unwrap();
        assert_eq!(l.mesh.triangles.len(), tris, "{name}");
        assert_eq!(l.mesh.objects.len(), objects, "{name}");
        assert!(l.warnings.is_empty(), "{name}: {:?}", l.warnings);
        if name == "pins.glb" {
            let (lo, hi) = bounds(&l);
            let ext = hi - lo;
            assert!((ext.x - 254.0).abs() < 0.5 && (ext.y - 254.0).abs() < 0.5, "{ext}");
            assert!(l.mesh.objects[0].name.starts_with("world/sides"));
        }
    }
}

// --- KHR_mesh_quantization ---------------------------------------------------------------

use num_rational::Ratio;
use num_traits::ToPrimitive;

/// Little-endian bytes of integer components, each vertex padded to `stride` bytes.
fn ints(values: &[[i64; 3]], size: usize, stride: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for v in values {
        for &c in v {
            out.extend_from_slice(&c.to_le_bytes()[..size]);
        }
        out.resize(out.len() + stride - 3 * size, 0);
    }
    out
}

/// One triangle whose POSITION accessor has `component_type` (`normalized` or not) over
/// `elems` (`stride` bytes per vertex, `None` = tightly packed), indices 0,1,2, one node
/// `node` (JSON members), and `sparse` (JSON of the accessor's sparse member, with its
/// bufferViews 2 and 3 built from `sparse_bytes`).
fn quantized_doc(
    component_type: u32,
    normalized: bool,
    elems: &[u8],
    stride: Option<usize>,
    node: &str,
    sparse: Option<(&str, &[u8], &[u8])>,
) -> Vec<u8> {
    let mut bin = elems.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let ind_at = bin.len();
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let mut views = format!(
        r#"{{"buffer":0,"byteLength":{}{}}},{{"buffer":0,"byteOffset":{ind_at},"byteLength":6}}"#,
        elems.len(),
        stride.map_or(String::new(), |s| format!(r#","byteStride":{s}"#))
    );
    let mut sparse_json = String::new();
    if let Some((json, idx, vals)) = sparse {
        let (i_at, v_at) = (bin.len(), bin.len() + idx.len().next_multiple_of(4));
        bin.extend_from_slice(idx);
        bin.resize(v_at, 0);
        bin.extend_from_slice(vals);
        views += &format!(
            r#",{{"buffer":0,"byteOffset":{i_at},"byteLength":{}}},{{"buffer":0,"byteOffset":{v_at},"byteLength":{}}}"#,
            idx.len(),
            vals.len()
        );
        sparse_json = format!(r#","sparse":{json}"#);
    }
    let body = format!(
        r#""extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],
        "bufferViews":[{views}],
        "accessors":[{{"bufferView":0,"componentType":{component_type},"normalized":{normalized},"count":3,
            "type":"VEC3","min":[0,0,0],"max":[1,1,1]{sparse_json}}},
          {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "nodes":[{{"mesh":0{node}}}]"#
    );
    gltf(&bin, &body)
}

/// `Ratio` to the nearest f64 (num-rational rounds correctly).
fn f(r: Ratio<i64>) -> f64 {
    r.to_f64().unwrap()
}

#[test]
fn quantized_unnormalized_positions_dequantized_by_the_node_exactly() {
    // Unnormalized integers with a power-of-two node scale and dyadic translation: every world
    // coordinate c/1024 + t is a dyadic rational that f64 holds exactly, so it must come out
    // exactly (checked against exact rationals, not against the loader's own formula).
    let q = [[0, 0, 0], [65535, 1, 2], [3, 40000, 7]];
    let t = [Ratio::new(-16, 1), Ratio::new(1, 2), Ratio::new(3, 1)];
    let node = r#","scale":[0.0009765625,0.0009765625,0.0009765625],"translation":[-16,0.5,3]"#;
    for (ct, size) in [(5123, 2usize), (5122, 2), (5121, 1), (5120, 1)] {
        // signed types: use values in range (negated x), unsigned: as given
        let vals: Vec<[i64; 3]> = q
            .iter()
            .map(|v| match ct {
                5122 => [-(v[0] / 2), v[1] / 2, v[2]],
                5121 => [v[0] % 256, v[1] % 256, v[2]],
                5120 => [-(v[0] % 128), v[1] % 128, v[2]],
                _ => *v,
            })
            .collect();
        // tightly packed (what some exporters write, though the core spec wants 4-byte
        // aligned vertex elements), and padded to 4 bytes as KHR_mesh_quantization says
        for stride in [None, Some((3 * size).next_multiple_of(4))] {
            let stride_bytes = stride.unwrap_or(3 * size);
            let l = ok(&quantized_doc(ct, false, &ints(&vals, size, stride_bytes), stride, node, None));
            assert_eq!(l.mesh.positions.len(), 3);
            for (p, v) in l.mesh.positions.iter().zip(&vals) {
                let want: Vec<f64> = (0..3).map(|k| f(Ratio::new(v[k], 1024) + t[k])).collect();
                assert_eq!(p.to_array().to_vec(), want, "type {ct} stride {stride:?}");
            }
        }
    }
}

#[test]
fn quantized_normalized_positions() {
    // Normalized: the decoded value is the correctly rounded quotient c / (2^n - 1), clamped at
    // -1 for signed types; a node scale of 2 (exact) shows it through the world coordinates.
    let node = r#","scale":[2,2,2]"#;
    let cases: [(u32, usize, i64, [[i64; 3]; 3]); 4] = [
        (5120, 1, 127, [[-128, -127, 127], [0, 1, -1], [64, -64, 100]]),
        (5121, 1, 255, [[0, 255, 1], [128, 254, 3], [17, 200, 77]]),
        (5122, 2, 32767, [[-32768, -32767, 32767], [0, 1, -1], [16384, -12345, 30000]]),
        (5123, 2, 65535, [[0, 65535, 1], [32768, 65534, 3], [4097, 60000, 12345]]),
    ];
    for (ct, size, max, vals) in cases {
        let l = ok(&quantized_doc(ct, true, &ints(&vals, size, 8), Some(8), node, None));
        for (p, v) in l.mesh.positions.iter().zip(&vals) {
            let want: Vec<f64> = (0..3).map(|k| 2.0 * f(Ratio::new(v[k], max)).max(-1.0)).collect();
            assert_eq!(p.to_array().to_vec(), want, "type {ct}");
        }
    }
    // the signed clamp: -128/127 and -127/127 both decode to exactly -1
    let l = ok(&quantized_doc(5120, true, &ints(&cases[0].3, 1, 4), Some(4), "", None));
    assert_eq!(l.mesh.positions[0], DVec3::new(-1.0, -1.0, 1.0));
}

#[test]
fn quantized_positions_with_sparse_substitution() {
    // SHORT normalized base values; vertex 1 replaced through sparse values of the same type.
    let base = [[0, 0, 0], [1, 1, 1], [0, 32767, 0]];
    let over: Vec<u8> = [-32768i16, 32767, 16384].iter().flat_map(|c| c.to_le_bytes()).collect();
    let sparse = r#"{"count":1,"indices":{"bufferView":2,"componentType":5121},"values":{"bufferView":3}}"#;
    let doc = quantized_doc(5122, true, &ints(&base, 2, 6), None, "", Some((sparse, &[1u8], &over)));
    let l = ok(&doc);
    let p = &l.mesh.positions;
    assert_eq!(p[0], DVec3::ZERO);
    assert_eq!(p[1], DVec3::new(-1.0, 1.0, f(Ratio::new(16384, 32767))));
    assert_eq!(p[2], DVec3::Y);
    // unnormalized UNSIGNED_BYTE, sparse over a base without bufferView (zeros)
    let doc = String::from_utf8(quantized_doc(
        5121,
        false,
        &ints(&base, 1, 3),
        None,
        "",
        Some((
            r#"{"count":1,"indices":{"bufferView":2,"componentType":5121},"values":{"bufferView":3}}"#,
            &[2u8],
            &[9, 8, 7],
        )),
    ))
    .unwrap()
    .replacen(r#""bufferView":0,"componentType":5121"#, r#""componentType":5121"#, 1);
    let l = ok(doc.as_bytes());
    assert_eq!(l.mesh.positions[..], [DVec3::ZERO, DVec3::ZERO, DVec3::new(9.0, 8.0, 7.0)]);
}

#[test]
fn quantized_positions_errors() {
    // UNSIGNED_INT positions are not allowed, even with the extension
    let e = err(&quantized_doc(5125, false, &[0u8; 36], None, "", None));
    assert!(e.contains("positions accessor of mesh 0 primitive 0 uses component type UNSIGNED_INT"), "{e}");
    // the accessor must fit its view at the quantized element size
    let doc = String::from_utf8(quantized_doc(5123, false, &[0u8; 18], None, "", None)).unwrap();
    let e = err(doc.replacen(r#""count":3,"#, r#""count":4,"#, 1).as_bytes());
    assert!(e.contains("accessor 0 of mesh 0 primitive 0: 4 elements of 6 bytes"), "{e}");
    // quantized positions load without the extension declared too (the data are unambiguous)
    let doc = String::from_utf8(quantized_doc(
        5121,
        false,
        &ints(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]], 1, 4),
        Some(4),
        "",
        None,
    ))
    .unwrap()
    .replace(
        r#""extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],"#,
        "",
    );
    assert_eq!(ok(doc.as_bytes()).mesh.positions[1], DVec3::X);
}

// --- EXT_mesh_gpu_instancing -------------------------------------------------------------

/// The one-triangle buffer with `extra` appended at byte 44; `views` and `accessors` are the
/// extra bufferViews (numbered from 2) and accessors (from 2), `nodes` the rest.
fn inst_doc(extra: &[u8], views: &str, accessors: &str, rest: &str) -> Vec<u8> {
    let mut bin = tri_bin();
    bin.extend_from_slice(extra);
    let body = TRI_VIEWS
        .replace(r#""byteLength":6}],"#, &format!(r#""byteLength":6}},{views}],"#))
        .replace(r#""type":"SCALAR"}],"#, &format!(r#""type":"SCALAR"}},{accessors}],"#));
    gltf(&bin, &format!(r#""extensionsUsed":["EXT_mesh_gpu_instancing"],{body},{rest}"#))
}

fn shorts(v: &[i16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[test]
fn gpu_instances_are_parts_with_node_world_times_trs() {
    // Three instances of the triangle under node "inst" (scale 2) under "root" (x + 100):
    //   0: T (1,2,3), identity rotation
    //   1: mirrored: S (-1,1,1), R 180° about z
    //   2: non-uniform S (2, 0.5, 4), R 90° about z, T (0,0,-4)
    // ROTATION is normalized SHORT (the extension allows it).
    let mut extra = f32s(&[1., 2., 3., 0., 0., 0., 0., 0., -4.]); // T at 44, 36 bytes
    extra.extend(shorts(&[0, 0, 0, 32767, 0, 0, 32767, 0, 0, 0, 23170, 23170])); // R at 80, 24 bytes
    extra.extend(f32s(&[1., 1., 1., -1., 1., 1., 2., 0.5, 4.])); // S at 104, 36 bytes
    let views = r#"{"buffer":0,"byteOffset":44,"byteLength":36},{"buffer":0,"byteOffset":80,"byteLength":24},
        {"buffer":0,"byteOffset":104,"byteLength":36}"#;
    let accessors = r#"{"bufferView":2,"componentType":5126,"count":3,"type":"VEC3"},
        {"bufferView":3,"componentType":5122,"normalized":true,"count":3,"type":"VEC4"},
        {"bufferView":4,"componentType":5126,"count":3,"type":"VEC3"}"#;
    let rest = r#""nodes":[{"name":"root","translation":[100,0,0],"children":[1,3]},
        {"name":"inst","mesh":0,"scale":[2,2,2],"children":[2],
         "extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":2,"ROTATION":3,"SCALE":4,"_ID":2}}}},
        {"name":"kid","mesh":0},{"name":"plain","mesh":0}],
      "scenes":[{"nodes":[0]}]"#;
    let l = ok(&inst_doc(&extra, views, accessors, rest));
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["root/inst#0", "root/inst#1", "root/inst#2", "root/inst/kid", "root/plain"]);
    assert!(l.mesh.objects.iter().all(|o| o.gltf_mesh == Some(0)));
    assert_eq!(l.mesh.tri_object, [0, 1, 2, 3, 4]);
    assert_eq!(l.mesh.triangles.len(), 5);
    // independent expectations: parent + 2 * (T + R(S v)), rotations written out by hand
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let world = |k: usize, [x, y, z]: [f64; 3]| -> [f64; 3] {
        let local = match k {
            0 => [x + 1.0, y + 2.0, z + 3.0],
            1 => [x, -y, z],                         // (-x, y, z) then (x, y) -> (-x, -y)
            2 => [-0.5 * y, 2.0 * x, 4.0 * z - 4.0], // (2x, y/2, 4z) then (x, y) -> (-y, x)
            _ => [x, y, z],                          // kid: the node's world only
        };
        [100.0 + 2.0 * local[0], 2.0 * local[1], 2.0 * local[2]]
    };
    for k in 0..4 {
        for (j, v) in tri.iter().enumerate() {
            let got = l.mesh.positions[l.mesh.triangles[k][j] as usize];
            let want = DVec3::from_array(world(k, *v));
            if k == 2 {
                // 23170/32767 normalised is 1/√2 only to about 1e-9 before normalising; after
                // normalising, rounding in the rotation matrix stays within a few ulps
                assert!((got - want).abs().max_element() < 1e-12, "instance {k} vertex {j}: {got} vs {want}");
            } else {
                assert_eq!(got, want, "instance {k} vertex {j}");
            }
        }
    }
    // the plain node is untouched by the instancing of another node
    assert_eq!(l.mesh.positions[l.mesh.triangles[4][1] as usize], DVec3::new(101.0, 0.0, 0.0));
    // each part records the matrix that was applied
    let w1 = l.mesh.objects[1].world.unwrap();
    assert_eq!(w1.transform_point3(DVec3::X), DVec3::new(102.0, 0.0, 0.0));
    assert!(w1.determinant() < 0.0, "mirrored instance");
    // mirroring keeps the triangle's index order (winding is decided later from the geometry)
    assert_eq!(l.mesh.triangles[1], [3, 4, 5]);
}

#[test]
fn gpu_instances_optional_attributes_and_float_rotation() {
    // only ROTATION (float), two instances: identity and 180° about x
    let extra = f32s(&[0., 0., 0., 1., 1., 0., 0., 0.]);
    let views = r#"{"buffer":0,"byteOffset":44,"byteLength":32}"#;
    let accessors = r#"{"bufferView":2,"componentType":5126,"count":2,"type":"VEC4"}"#;
    let rest =
        r#""nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"ROTATION":2}}}}]"#;
    let l = ok(&inst_doc(&extra, views, accessors, rest));
    let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["node0#0", "node0#1"]);
    assert_eq!(l.mesh.positions[5], DVec3::new(0.0, -1.0, 0.0));
    // a custom attribute alone gives the count; the instances sit at the node
    let rest = r#""nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"_ID":2}}}}]"#;
    let l = ok(&inst_doc(&extra, views, accessors, rest));
    assert_eq!(l.mesh.objects.len(), 2);
    assert_eq!(l.mesh.positions[3..], l.mesh.positions[..3]);
}

#[test]
fn gpu_instancing_errors() {
    let t = f32s(&[0., 0., 0., 1., 0., 0., f32::NAN, 0., 0.]);
    let views = r#"{"buffer":0,"byteOffset":44,"byteLength":36}"#;
    let acc = |count: usize, ct: u32, ty: &str, norm: bool| {
        format!(
            r#"{{"bufferView":2,"componentType":{ct},"normalized":{norm},"count":{count},"type":"{ty}"}}"#
        )
    };
    let node =
        |attrs: &str| format!(r#""nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{attrs}}}}}]"#);
    let two = format!("{},{}", acc(3, 5126, "VEC3", false), acc(2, 5126, "VEC3", false));
    let cases: Vec<(String, String, &str)> = vec![
        (two.clone(), node(r#"{"attributes":{"TRANSLATION":2,"SCALE":3}}"#), "attributes have different counts (SCALE: 2, TRANSLATION: 3)"),
        (acc(3, 5126, "VEC3", false), node(r#"{"attributes":{"TRANSLATION":2}}"#), "glTF node 0 GPU instance 2: TRANSLATION is not finite (NaN)"),
        (acc(2, 5126, "VEC3", false), node(r#"{"attributes":{"SCALE":2}}"#), "GPU instance 0: SCALE"), // scale 0 is allowed: degenerate, not an error
        (acc(2, 5122, "VEC4", false), node(r#"{"attributes":{"ROTATION":2}}"#), "ROTATION accessor 2 is VEC4 of SHORT (expected VEC4 of FLOAT, or of normalized BYTE or SHORT)"),
        (acc(3, 5126, "VEC4", false), node(r#"{"attributes":{"TRANSLATION":2}}"#), "TRANSLATION accessor 2 is VEC4 of FLOAT (expected VEC3 of FLOAT)"),
        (acc(3, 5122, "VEC3", true), node(r#"{"attributes":{"SCALE":2}}"#), "SCALE accessor 2 is VEC3 of normalized SHORT"),
        (acc(3, 5126, "VEC3", false), node(r#"{"attributes":{"TRANSLATION":9}}"#), "glTF node 0: EXT_mesh_gpu_instancing attribute TRANSLATION uses accessor 9 but there are 3 accessors"),
        (acc(3, 5126, "VEC3", false), node(r#"{"attributes":{"TRANSLATION":"x"}}"#), "attribute TRANSLATION is not an accessor index"),
        (acc(3, 5126, "VEC3", false), node(r#"{"mesh":1}"#), "EXT_mesh_gpu_instancing has no 'attributes' object"),
        (acc(3, 5126, "VEC3", false), node(r#"{"attributes":{}}"#), "has no attributes, so no instance count"),
        (acc(2, 5126, "VEC4", false), node(r#"{"attributes":{"ROTATION":2}}"#), "glTF node 0 GPU instance 0: ROTATION is a zero quaternion"),
    ];
    for (i, (accessors, rest, want)) in cases.into_iter().enumerate() {
        let mut extra = t.clone();
        if want.contains("zero quaternion") {
            extra = vec![0; 36];
        }
        let doc = inst_doc(&extra, views, &accessors, &rest);
        if want == "GPU instance 0: SCALE" {
            // zero scale gives degenerate triangles, not an error
            assert_eq!(ok(&doc).mesh.objects.len(), 2, "case {i}");
            continue;
        }
        let e = err(&doc);
        assert!(e.contains(want), "case {i}: {e}");
    }
    // the extension on a node without a mesh is ignored with a warning
    let rest =
        r#""nodes":[{"mesh":0},{"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":2}}}}]"#;
    let l = ok(&inst_doc(&t, views, &acc(3, 5126, "VEC3", false), rest));
    assert!(
        l.warnings[0].contains("glTF node 1 has EXT_mesh_gpu_instancing but no mesh: ignored"),
        "{:?}",
        l.warnings
    );
    // instance transform overflowing under the node's world
    let big = f32s(&[3e38, 0., 0.]);
    let parents: Vec<String> =
        (0..7).map(|i| format!(r#"{{"children":[{}],"scale":[3e38,1,1]}}"#, i + 1)).collect();
    let rest = format!(
        r#""nodes":[{},{{"mesh":0,"scale":[3e38,1,1],"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"SCALE":2}}}}}}}}]"#,
        parents.join(",")
    );
    let e = err(&inst_doc(
        &big,
        r#"{"buffer":0,"byteOffset":44,"byteLength":12}"#,
        &acc(1, 5126, "VEC3", false),
        &rest,
    ));
    assert!(e.contains("glTF node 7: world transform of GPU instance 0 is not finite (overflow)"), "{e}");
}

#[test]
fn gpu_instancing_bombs_refused_before_reading() {
    // A tiny file declaring 20 million instances of a triangle (TRANSLATION without a
    // bufferView: implied zeros, one sparse value): 6e7 vertices are within the limits but
    // 2e7 parts are not; refused before anything is read.
    let accessors = r#"{"componentType":5126,"count":20000000,"type":"VEC3",
        "sparse":{"count":1,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}}"#;
    let rest =
        r#""nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":2}}}}]"#;
    let doc = String::from_utf8(inst_doc(
        &[0; 12],
        r#"{"buffer":0,"byteOffset":44,"byteLength":12}"#,
        accessors,
        rest,
    ))
    .unwrap();
    let e = err(doc.as_bytes());
    assert!(
        e.contains("glTF scene has 20000000 parts after instancing, more than the 16777216 supported"),
        "{e}"
    );
    // 70 000 vertices (a strip) in 4000 GPU instances: 2.8e8 vertices > 2^28
    let n = 70_000;
    let mut bin = vec![0u8; 12 * n];
    bin.extend(f32s(&vec![0.0; 3 * 4000]));
    let body = format!(
        r#""bufferViews":[{{"buffer":0,"byteLength":{}}},{{"buffer":0,"byteOffset":{},"byteLength":48000}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":[0,0,0],"max":[0,0,0]}},
          {{"bufferView":1,"componentType":5126,"count":4000,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":5}}]}}],
        "nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":1}}}}}}}}]"#,
        12 * n,
        12 * n
    );
    let e = err(&gltf(&bin, &body));
    assert!(
        e.contains("glTF scene has 280000000 vertices after instancing, more than the 268435456 supported"),
        "{e}"
    );
}

// --- required / used extensions, custom attributes, buffer URIs ---------------------------

#[test]
fn extension_policy() {
    let doc = String::from_utf8(tri_doc(r#""nodes":[{"mesh":0}]"#)).unwrap();
    let with = |members: &str| doc.replacen('{', &format!("{{{members},"), 1);
    // decodable or geometry-neutral requirements load
    for ext in
        ["KHR_mesh_quantization", "EXT_mesh_gpu_instancing", "KHR_texture_transform", "EXT_mesh_features"]
    {
        let l = ok(with(&format!(r#""extensionsUsed":["{ext}"],"extensionsRequired":["{ext}"]"#)).as_bytes());
        assert_eq!(l.mesh.triangles.len(), 1, "{ext}");
    }
    // undecodable requirements name the extension and why
    for (ext, why) in [
        ("KHR_draco_mesh_compression", "Draco-compressed geometry cannot be decoded"),
        ("EXT_meshopt_compression", "meshopt-compressed buffers cannot be decoded"),
        ("ACME_unknown_thing", "which is not supported"),
    ] {
        let e =
            err(with(&format!(r#""extensionsUsed":["{ext}"],"extensionsRequired":["{ext}"]"#)).as_bytes());
        assert!(e.contains(&format!("glTF requires extension '{ext}', which is not supported")), "{e}");
        assert!(e.contains(why), "{e}");
    }
    // merely used: loads (uncompressed fallback data present), whatever the extension
    let used = with(r#""extensionsUsed":["KHR_draco_mesh_compression","EXT_meshopt_compression","ACME_x"]"#);
    let used = used.replace(
        r#""indices":1}"#,
        r#""indices":1,"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":0}}}}"#,
    );
    assert_eq!(ok(used.as_bytes()).mesh.triangles.len(), 1);
    // ...but a compressed primitive without fallback data is an error naming the extension
    let no_data = used.replacen(r#""bufferView":0,"componentType":5126"#, r#""componentType":5126"#, 1);
    let e = err(no_data.as_bytes());
    assert!(
        e.contains("glTF accessor 0 has no data (neither bufferView nor sparse values): it would come from an extension that is not supported (extensions used: KHR_draco_mesh_compression, EXT_meshopt_compression, ACME_x)"),
        "{e}"
    );
    // application-specific attributes (`_BATCHID`, feature ids) are ignored, not invalid
    let custom = doc.replace(
        r#""attributes":{"POSITION":0}"#,
        r#""attributes":{"POSITION":0,"_BATCHID":1,"_FEATURE_ID_0":1}"#,
    );
    assert_eq!(ok(custom.as_bytes()).mesh.triangles.len(), 1);
}

#[test]
fn buffer_uri_policy() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::create_dir_all(root.join("model/sub")).unwrap();
    // the same bytes inside and outside the glTF's directory
    for p in ["model/tri.bin", "model/sub/tri.bin", "outside.bin"] {
        std::fs::write(root.join(p), tri_bin()).unwrap();
    }
    let doc = |uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":44,"uri":"{uri}"}}],{TRI_VIEWS},
            "nodes":[{{"mesh":0}}]}}"#
        )
    };
    let f = root.join("model/m.gltf");
    for good in ["tri.bin", "./tri.bin", "sub/tri.bin", "sub/../tri.bin", "sub%2Ftri.bin", "sub//./tri.bin"] {
        std::fs::write(&f, doc(good)).unwrap();
        assert_eq!(load_path(&f).unwrap().0.mesh.triangles.len(), 1, "{good}");
    }
    let outside = root.join("outside.bin").display().to_string();
    for (bad, why) in [
        (outside.as_str(), "an absolute path"),
        ("/etc/passwd", "an absolute path"),
        ("%2Fetc%2Fpasswd", "an absolute path"),
        ("../outside.bin", "'..' leaving the glTF's directory"),
        ("sub/../../outside.bin", "'..' leaving the glTF's directory"),
        ("%2e%2e/outside.bin", "'..' leaving the glTF's directory"),
        ("..%5Coutside.bin", "'..' leaving the glTF's directory"),
        ("file:///etc/passwd", "a scheme or drive letter"),
        ("file:outside.bin", "a scheme or drive letter"),
        ("C:\\\\Windows\\\\x.bin", "a scheme or drive letter"),
        ("C:/x.bin", "a scheme or drive letter"),
        ("\\\\\\\\server\\\\share\\\\x.bin", "an absolute path"),
        ("tri.bin%00", "a NUL byte"),
    ] {
        std::fs::write(&f, doc(bad)).unwrap();
        let e = load_path(&f).unwrap_err().to_string();
        assert!(e.contains("glTF buffer 0 URI") && e.contains(&format!("is refused: {why}")), "{bad}: {e}");
        assert!(e.contains("only data: URIs and relative paths inside the glTF's directory are read"), "{e}");
    }
}

/// Random mutations of documents using both extensions (bytes of the JSON text, including
/// the base64 buffer, flipped, digits changed, truncated) give `Ok` or a one-line `Err`,
/// never a panic.
#[test]
fn mutated_extension_documents_never_panic() {
    let mut extra = f32s(&[1., 2., 3., 0., 0., 0., 0., 0., -4.]);
    extra.extend(shorts(&[0, 0, 0, 32767, 0, 0, 32767, 0, 0, 0, 23170, 23170]));
    extra.extend(f32s(&[1., 1., 1., -1., 1., 1., 2., 0.5, 4.]));
    let views = r#"{"buffer":0,"byteOffset":44,"byteLength":36},{"buffer":0,"byteOffset":80,"byteLength":24},
        {"buffer":0,"byteOffset":104,"byteLength":36}"#;
    let accessors = r#"{"bufferView":2,"componentType":5126,"count":3,"type":"VEC3"},
        {"bufferView":3,"componentType":5122,"normalized":true,"count":3,"type":"VEC4"},
        {"bufferView":4,"componentType":5126,"count":3,"type":"VEC3"}"#;
    let rest = r#""nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":2,"ROTATION":3,"SCALE":4}}}}]"#;
    let sparse = r#"{"count":1,"indices":{"bufferView":2,"componentType":5121},"values":{"bufferView":3}}"#;
    let docs = [
        inst_doc(&extra, views, accessors, rest),
        quantized_doc(
            5122,
            true,
            &ints(&[[0, 0, 0], [1, 1, 1], [0, 32767, 0]], 2, 8),
            Some(8),
            "",
            Some((sparse, &[1], &[1, 0, 2, 0, 3, 0])),
        ),
    ];
    let mut rnd = crate::load::test_rng(0x2545_F491_4F6C_DD1D);
    for orig in docs {
        assert!(load_bytes(&path(), &orig, Format::Gltf).is_ok());
        for _ in 0..3000 {
            let mut b = orig.clone();
            for _ in 0..1 + rnd(3) {
                let at = rnd(b.len());
                match rnd(4) {
                    0 => b[at] = b"0123456789-.e,:[]{}\"ABCDabcd+/="[rnd(31)],
                    1 => {
                        if let Some(d) = b.iter().skip(at).position(|c| c.is_ascii_digit()) {
                            b[at + d] = b"09"[rnd(2)];
                        }
                    }
                    2 => b.truncate(at.max(1)),
                    _ => b.insert(at, b"-9 /"[rnd(4)]),
                }
            }
            match load_bytes(&path(), &b, Format::Gltf) {
                Ok(l) => assert!(!l.mesh.triangles.is_empty()),
                Err(e) => assert!(!e.to_string().contains('\n')),
            }
        }
    }
}

/// Node transforms were read through the `gltf` crate as f32: `0.1000000015` became the f32
/// value of 0.1 and `1000.0000000001` became 1000, moving the part.
#[test]
fn node_transforms_are_read_as_f64_not_f32() {
    let t = 0.1000000015f64;
    assert_eq!(t as f32 as f64, 0.1f32 as f64, "the test needs a value f32 rounds away");
    let l = ok(&tri_doc(r#""nodes":[{"mesh":0,"translation":[0.1000000015,0,0]}]"#));
    assert_eq!(l.mesh.positions[0], DVec3::new(t, 0.0, 0.0));
    // matrix: column-major, a ×1000.0000000001 scale and a translation that f32 cannot hold
    let l = ok(&tri_doc(
        r#""nodes":[{"mesh":0,"matrix":[1000.0000000001,0,0,0, 0,1,0,0, 0,0,1,0, 0.1000000015,0,0,1]}]"#,
    ));
    assert_eq!(l.mesh.positions[1], DVec3::new(1000.0000000001 + t, 0.0, 0.0));
    // rotation and scale: f64 too (the quaternion normalised in f64)
    let l =
        ok(&tri_doc(r#""nodes":[{"mesh":0,"scale":[1.0000000001,1,1],"rotation":[0,0,0,1.0000000001]}]"#));
    assert_eq!(l.mesh.positions[1].x, 1.0000000001);
    // a parent's f64 translation composes with the child's in f64
    let l = ok(&tri_doc(
        r#""nodes":[{"children":[1],"translation":[0.1000000015,0,0]},{"mesh":0,"translation":[0,0.1000000015,0]}],
        "scenes":[{"nodes":[0]}]"#,
    ));
    assert_eq!(l.mesh.positions[0], DVec3::new(t, t, 0.0));
}

#[test]
fn infinite_position_without_bounds_is_refused_for_the_coordinate() {
    // POSITION holds +inf and its accessor has no min/max (which the spec
    // requires): the error names the non-finite position, not the missing bounds.
    let mut bin = f32s(&[0.0, 0.0, 0.0, f32::INFINITY, 0.0, 0.0, 0.0, 1.0, 0.0]);
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let views = TRI_VIEWS.replace(r#","min":[0,0,0],"max":[1,1,0]"#, "");
    assert!(!views.contains("\"min\""));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":44}}],{views},"nodes":[{{"mesh":0}}]}}"#
    );
    let e = load_bytes(Path::new("t.glb"), &glb(json.as_bytes(), Some(&bin)), Format::Glb)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.glb: "), "{e}");
    assert_eq!(e, "t.glb: position 1 of mesh 0 primitive 0 has a non-finite coordinate (inf)");
    assert!(!e.contains("min"), "{e}");
    // The same file with finite values and no bounds loads (the bounds are never read).
    let ok = load_bytes(Path::new("t.glb"), &glb(json.as_bytes(), Some(&tri_bin())), Format::Glb).unwrap();
    assert_eq!(ok.mesh.positions.len(), 3);
}
