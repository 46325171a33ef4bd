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

fn ok(bytes: &[u8]) -> Loaded {
    load_bytes(&path(), bytes, Format::Gltf).unwrap()
}

fn err(bytes: &[u8]) -> String {
    let e = load_bytes(&path(), bytes, Format::Gltf).unwrap_err().to_string();
    assert!(e.starts_with("t.gltf: ") && !e.contains('\n'), "{e}");
    e
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
    let strip = [[0, 1, 2], [1, 3, 2], [2, 3, 4]];
    let fan = [[5, 6, 7], [5, 7, 8], [5, 8, 9]];
    assert_eq!(l.mesh.triangles, [strip, fan].concat());
    assert_eq!(l.mesh.positions.len(), 10);
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
    assert_eq!(l.mesh.triangles, vec![[2, 1, 0], [3, 5, 4]]);
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
    assert!(e.contains("is not supported (only data: URIs and relative file paths)"), "{e}");
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
    assert!(l.warnings[0].contains("EXT_mesh_gpu_instancing is not supported"), "{:?}", l.warnings);
    let l =
        ok(with(r#""extensionsUsed":["KHR_materials_unlit"],"extensionsRequired":["KHR_materials_unlit"]"#)
            .as_bytes());
    assert_eq!(l.mesh.triangles.len(), 1);
}

#[test]
fn quantized_positions_rejected() {
    let bin: Vec<u8> = [0u16, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 2].iter().flat_map(|i| i.to_le_bytes()).collect();
    let body = r#""bufferViews":[{"buffer":0,"byteLength":18},{"buffer":0,"byteOffset":18,"byteLength":6}],
      "accessors":[{"bufferView":0,"componentType":5123,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
        {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"nodes":[{"mesh":0}]"#;
    let e = err(&gltf(&bin, body));
    assert!(
        e.contains("positions accessor of mesh 0 primitive 0 uses component type UNSIGNED_SHORT (KHR_mesh_quantization is not supported yet)"),
        "{e}"
    );
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
