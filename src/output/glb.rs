//! `--export-glb`: a self-contained binary glTF 2.0 scene to look at a report in any viewer.
//!
//! Under one root node `meshclash` (translated to the centre of both inputs, so the f32
//! positions of glTF keep their precision far from the origin), children named for what they
//! show:
//!
//! * `A: <path>`, `B: <path>`: the two inputs, light grey, semi-transparent (`alphaMode: BLEND`);
//! * `crossing pairs` (red), `touching pairs` (orange), `clearance pairs` (yellow): the
//!   triangles of the listed pairs of that kind, each distinct triangle once (A's, then B's);
//! * `closest points`: small octahedra at the two closest points and a line between them;
//! * `crossing markers`: an octahedron at the midpoint of each listed crossing pair's segment
//!   (at most [`MAX_MARKERS`]).
//!
//! Highlight and marker nodes are present only when they have something to show. Only the
//! report's listed pairs are drawn (`--max-pairs`).

use crate::report::{Report, ReportPairKind};
use crate::scene::mesh::Mesh;
use glam::DVec3;
use serde_json::{json, Value};
use std::collections::BTreeSet;

/// The most crossing markers drawn.
pub const MAX_MARKERS: usize = 1000;

const INPUT: usize = 0;
const CROSSING: usize = 1;
const TOUCHING: usize = 2;
const CLEARANCE: usize = 3;
const CLOSEST: usize = 4;
const MARKER: usize = 5;

const TRIANGLES: u32 = 4;
const LINES: u32 = 1;

fn material(name: &str, rgba: [f32; 4], blend: bool) -> Value {
    let mut m = json!({
        "name": name,
        "pbrMetallicRoughness": {"baseColorFactor": rgba, "metallicFactor": 0.0, "roughnessFactor": 0.9},
        "doubleSided": true,
    });
    if blend {
        m["alphaMode"] = json!("BLEND");
    } else {
        m["emissiveFactor"] = json!([rgba[0] * 0.5, rgba[1] * 0.5, rgba[2] * 0.5]);
    }
    m
}

#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8], target: u32) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(
            json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len(), "target": target}),
        );
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A primitive from positions and indices (both non-empty).
    fn primitive(&mut self, pos: &[[f32; 3]], idx: &[u32], material: usize, mode: u32) -> Value {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        let mut bytes = Vec::with_capacity(pos.len() * 12);
        for p in pos {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
                bytes.extend_from_slice(&p[k].to_le_bytes());
            }
        }
        let v = self.view(&bytes, 34962);
        self.accessors
            .push(json!({"bufferView": v, "componentType": 5126, "count": pos.len(), "type": "VEC3",
                                   "min": min, "max": max}));
        let position = self.accessors.len() - 1;
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        let v = self.view(&bytes, 34963);
        self.accessors
            .push(json!({"bufferView": v, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}));
        json!({"attributes": {"POSITION": position}, "indices": self.accessors.len() - 1,
               "material": material, "mode": mode})
    }

    fn node(&mut self, name: &str, primitives: Vec<Value>, extras: Option<Value>) {
        self.meshes.push(json!({"name": name, "primitives": primitives}));
        let mut n = json!({"name": name, "mesh": self.meshes.len() - 1});
        if let Some(e) = extras {
            n["extras"] = e;
        }
        self.nodes.push(n);
    }
}

/// Positions relative to `centre`, as f32.
fn rel(p: DVec3, centre: DVec3) -> [f32; 3] {
    (p - centre).as_vec3().to_array()
}

/// Triangles `tris` of `mesh`, each with its own three vertices, appended to `pos`/`idx`.
fn push_triangles(
    mesh: &Mesh,
    tris: &BTreeSet<u32>,
    centre: DVec3,
    pos: &mut Vec<[f32; 3]>,
    idx: &mut Vec<u32>,
) {
    for &t in tris {
        for &v in &mesh.triangles[t as usize] {
            idx.push(pos.len() as u32);
            pos.push(rel(mesh.positions[v as usize], centre));
        }
    }
}

/// An octahedron of radius `r` around `c`.
fn octahedron(c: [f32; 3], r: f32, pos: &mut Vec<[f32; 3]>, idx: &mut Vec<u32>) {
    let base = pos.len() as u32;
    for (axis, sign) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0)] {
        let mut p = c;
        p[axis] += sign * r;
        pos.push(p);
    }
    // +x -x +y -y +z -z = 0..6; one face per octant, counter-clockwise from outside.
    for [x, y, z] in [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    {
        idx.extend([base + x, base + y, base + z]);
    }
}

/// The scene as GLB bytes. `a` and `b` are the placed meshes the report was computed on.
pub fn export(r: &Report, a: &Mesh, b: &Mesh) -> Vec<u8> {
    let bounds = crate::geom::Aabb::of_points(&a.positions).union(crate::geom::Aabb::of_points(&b.positions));
    let centre = (bounds.min + bounds.max) * 0.5;
    let centre = if centre.is_finite() { centre } else { DVec3::ZERO };
    let radius = ((bounds.max - bounds.min).length() * 0.004).max(1e-6) as f32;
    let mut g = Builder::default();

    for (label, mesh, path) in [("A", a, &r.inputs.a.path), ("B", b, &r.inputs.b.path)] {
        if mesh.triangles.is_empty() {
            continue;
        }
        let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|&p| rel(p, centre)).collect();
        let idx: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let prim = g.primitive(&pos, &idx, INPUT, TRIANGLES);
        g.node(&format!("{label}: {path}"), vec![prim], None);
    }

    for (kind, name, mat) in [
        (ReportPairKind::Crossing, "crossing pairs", CROSSING),
        (ReportPairKind::Touching, "touching pairs", TOUCHING),
        (ReportPairKind::Clearance, "clearance pairs", CLEARANCE),
    ] {
        let pairs = r.pairs.iter().filter(|p| p.kind == kind);
        let ta: BTreeSet<u32> = pairs.clone().map(|p| p.a).collect();
        let tb: BTreeSet<u32> = pairs.clone().map(|p| p.b).collect();
        if ta.is_empty() {
            continue;
        }
        let (mut pos, mut idx) = (Vec::new(), Vec::new());
        push_triangles(a, &ta, centre, &mut pos, &mut idx);
        push_triangles(b, &tb, centre, &mut pos, &mut idx);
        let prim = g.primitive(&pos, &idx, mat, TRIANGLES);
        let extras = json!({"pairs": pairs.count(), "a_triangles": ta.len(), "b_triangles": tb.len()});
        g.node(name, vec![prim], Some(extras));
    }

    if let Some(c) = &r.closest {
        let (pa, pb) = (rel(DVec3::from_array(c.a.point), centre), rel(DVec3::from_array(c.b.point), centre));
        let (mut pos, mut idx) = (Vec::new(), Vec::new());
        octahedron(pa, radius, &mut pos, &mut idx);
        octahedron(pb, radius, &mut pos, &mut idx);
        let dots = g.primitive(&pos, &idx, CLOSEST, TRIANGLES);
        let line = g.primitive(&[pa, pb], &[0, 1], CLOSEST, LINES);
        g.node("closest points", vec![dots, line], Some(json!({"distance": c.distance})));
    }

    let crossings: Vec<[f64; 3]> = r
        .pairs
        .iter()
        .filter(|p| p.kind == ReportPairKind::Crossing)
        .filter_map(|p| p.segment.map(|[s, t]| [0, 1, 2].map(|k| (s[k] + t[k]) * 0.5)))
        .collect();
    if !crossings.is_empty() {
        let (mut pos, mut idx) = (Vec::new(), Vec::new());
        for m in crossings.iter().take(MAX_MARKERS) {
            octahedron(rel(DVec3::from_array(*m), centre), radius, &mut pos, &mut idx);
        }
        let prim = g.primitive(&pos, &idx, MARKER, TRIANGLES);
        let extras =
            json!({"markers": crossings.len().min(MAX_MARKERS), "crossing_segments": crossings.len()});
        g.node("crossing markers", vec![prim], Some(extras));
    }

    let children: Vec<usize> = (1..=g.nodes.len()).collect();
    let mut nodes =
        vec![json!({"name": "meshclash", "translation": centre.to_array(), "children": children})];
    nodes.append(&mut g.nodes);
    while !g.bin.len().is_multiple_of(4) {
        g.bin.push(0);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": format!("meshclash {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": format!("meshclash: {}", r.verdict), "nodes": [0]}],
        "nodes": nodes,
        "meshes": g.meshes,
        "materials": [
            material("input", [0.8, 0.8, 0.8, 0.3], true),
            material("crossing", [1.0, 0.0, 0.0, 1.0], false),
            material("touching", [1.0, 0.5, 0.0, 1.0], false),
            material("clearance", [1.0, 0.9, 0.0, 1.0], false),
            material("closest points", [0.0, 0.6, 1.0, 1.0], false),
            material("crossing markers", [1.0, 0.0, 1.0, 1.0], false),
        ],
        "accessors": g.accessors,
        "bufferViews": g.views,
        "buffers": [{"byteLength": g.bin.len()}],
    });
    let mut json_bytes = serde_json::to_vec(&doc).expect("glTF JSON serialises");
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + g.bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(g.bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&g.bin);
    out
}
