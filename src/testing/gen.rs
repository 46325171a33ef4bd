//! Deterministic generated inputs for tests and the benchmark: tessellated tori (closed, no degenerate
//! triangles, ~n triangles each), placed so that they cross or stay apart, and two
//! near-degenerate inputs on which plain f64 predicates change answers.

use crate::geom::{Aabb, DVec3};
use crate::scene::mesh::{Mesh, Object};
use glam::DMat4;

/// The 12 outward-facing triangles of a box whose corner `i` has bit 0, 1, 2 of `i` set for
/// the maximum in x, y, z (the corner numbering of [`box_corners`]).
/// Faces in the order x = min, z = min, z = max, y = min, y = max, x = max.
pub const BOX_TRIANGLES: [[u32; 3]; 12] = [
    [0, 4, 2],
    [2, 4, 6],
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [1, 3, 5],
    [3, 7, 5],
];

/// The 8 corners of the box `[lo, hi]`, corner `i` taking `hi` on the axes of its set bits.
pub fn box_corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        let pick = |bit: usize, axis: usize| if i >> bit & 1 == 1 { hi[axis] } else { lo[axis] };
        DVec3::new(pick(0, 0), pick(1, 1), pick(2, 2))
    })
}

/// A torus around the z axis (major radius 1, minor 0.35) with `2·u·v ≈ n` triangles, u = 2v.
pub fn torus(n: usize) -> Mesh {
    let v = ((n as f64 / 4.0).sqrt().round() as usize).max(3);
    let u = 2 * v;
    let (big, small) = (1.0f64, 0.35f64);
    let mut positions = Vec::with_capacity(u * v);
    for i in 0..u {
        let th = i as f64 / u as f64 * std::f64::consts::TAU;
        for j in 0..v {
            let ph = j as f64 / v as f64 * std::f64::consts::TAU;
            let r = big + small * ph.cos();
            positions.push(DVec3::new(r * th.cos(), r * th.sin(), small * ph.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % u) * v + (j % v)) as u32;
    let mut triangles = Vec::with_capacity(2 * u * v);
    for i in 0..u {
        for j in 0..v {
            let (p00, p10, p11, p01) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([p00, p10, p11]);
            triangles.push([p00, p11, p01]);
        }
    }
    one_object(positions, triangles, "torus")
}

fn one_object(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>, name: &str) -> Mesh {
    Mesh {
        positions,
        tri_object: vec![0; triangles.len()],
        triangles,
        objects: vec![Object { name: name.into(), ..Default::default() }],
    }
}

/// `m` with every vertex transformed (f64, rounded once).
pub fn placed(m: &Mesh, t: &DMat4) -> Mesh {
    let mut out = m.clone();
    for p in &mut out.positions {
        *p = t.transform_point3(*p);
    }
    out
}

/// The placement used for "a mesh vs a rotated, moved copy of itself" (as in the kernels bench):
/// a rotation by atan(0.75) about z through the mesh centre, then a shift of 1% of the diagonal.
pub fn rotated_copy(m: &Mesh) -> Mesh {
    let b = Aabb::of_points(&m.positions);
    let c = b.center();
    let d = b.extent().length();
    let rot = DMat4::from_cols_array(&[
        0.8, 0.6, 0.0, 0.0, -0.6, 0.8, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    let t =
        DMat4::from_translation(c + DVec3::new(0.01, 0.005, 0.002) * d) * rot * DMat4::from_translation(-c);
    placed(m, &t)
}

/// A copy moved along x by 1.02 × the mesh's x extent: the boxes are disjoint, so the meshes
/// are apart and the distance is positive.
pub fn separated_copy(m: &Mesh) -> Mesh {
    let e = Aabb::of_points(&m.positions).extent();
    placed(m, &DMat4::from_translation(DVec3::new(1.02 * e.x.max(1e-300), 0.0, 0.0)))
}

/// Two crossing tori of ~n triangles each: B is A rotated 0.3 rad about z and moved (0.25, 0.15, 0.1).
pub fn crossing_tori(n: usize) -> (Mesh, Mesh) {
    let a = torus(n);
    let t = DMat4::from_translation(DVec3::new(0.25, 0.15, 0.1)) * DMat4::from_rotation_z(0.3);
    let b = placed(&a, &t);
    (a, b)
}

/// Two tori apart: B is A moved 3 along x (gap 0.3 between the outer equators).
pub fn separated_tori(n: usize) -> (Mesh, Mesh) {
    let a = torus(n);
    let b = placed(&a, &DMat4::from_translation(DVec3::new(3.0, 0.0, 0.0)));
    (a, b)
}

/// A torus against a copy moved by one ulp (of 1.0) along (1, 1, 1): nearly coincident
/// surfaces, every triangle nearly coplanar with its own copy and its neighbours'.
pub fn ulp_shifted_tori(n: usize) -> (Mesh, Mesh) {
    let a = torus(n);
    let mut b = a.clone();
    for p in &mut b.positions {
        *p = DVec3::new(p.x + f64::EPSILON, p.y + f64::EPSILON, p.z + f64::EPSILON);
    }
    (a, b)
}

/// Exactly coplanar duplicated surface far from the origin: a k×k grid of unit quads (with
/// jittered vertices) on the plane x + y + z = 3e8, every coordinate a multiple of 2^-26 so the
/// plane equation holds exactly. A splits each quad along one diagonal, B along the other, so
/// every overlapping pair is coplanar (exact answer: `coplanar_area`/`coplanar_boundary`), while
/// f64 determinants of these points round to non-zero values.
pub fn coplanar_grids(n: usize) -> (Mesh, Mesh) {
    let k = ((n as f64 / 2.0).sqrt().round() as usize).max(2);
    let unit: i64 = 1 << 26; // 1.0 in units of 2^-26
    let base: i64 = 100_000_000 * unit; // 1e8, < 2^53
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let q = 1.0 / unit as f64;
    let mut positions = Vec::with_capacity((k + 1) * (k + 1));
    for i in 0..=k {
        for j in 0..=k {
            let jx = (rnd() % (unit as u64 / 4)) as i64;
            let jy = (rnd() % (unit as u64 / 4)) as i64;
            let x = base + i as i64 * unit + jx;
            let y = base + j as i64 * unit + jy;
            let z = 3 * base - x - y; // exact in i64 and representable: |z|·2^26 < 2^53
            positions.push(DVec3::new(x as f64 * q, y as f64 * q, z as f64 * q));
        }
    }
    let id = |i: usize, j: usize| (i * (k + 1) + j) as u32;
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for i in 0..k {
        for j in 0..k {
            let (p00, p10, p11, p01) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            ta.push([p00, p10, p11]);
            ta.push([p00, p11, p01]);
            tb.push([p00, p10, p01]);
            tb.push([p10, p11, p01]);
        }
    }
    (one_object(positions.clone(), ta, "grid-a"), one_object(positions, tb, "grid-b"))
}

/// The mesh as OBJ text (`v` lines with 17 significant digits, then `f` lines).
pub fn to_obj(m: &Mesh) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(m.positions.len() * 60 + m.triangles.len() * 24);
    for p in &m.positions {
        let _ = writeln!(s, "v {:.17e} {:.17e} {:.17e}", p.x, p.y, p.z);
    }
    for t in &m.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_exact_plane() {
        assert_eq!(torus(10_000).triangles.len(), 2 * 100 * 50);
        let (a, b) = coplanar_grids(2_000);
        assert_eq!(a.triangles.len(), b.triangles.len());
        for p in &a.positions {
            // x + y + z == 3e8 exactly (checked in integers of 2^-26).
            let f = |v: f64| (v * (1u64 << 26) as f64) as i64;
            assert_eq!(f(p.x) + f(p.y) + f(p.z), 3 * 100_000_000i64 * (1 << 26));
        }
    }
}
