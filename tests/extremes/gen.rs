//! Small exact mesh generators and the frames (placements) every case is built in.
//!
//! A case is written in abstract coordinates (small dyadic numbers). A [`Frame`] maps an
//! abstract point to world coordinates in f64 (`scale`, then `rotation`, then `shift`, each
//! operation rounded once). The map is a deterministic function of the abstract point, so two
//! vertices that are the same abstract point are the same world point bit for bit: every
//! contact made by shared vertices survives any frame. Offsets that must stay exact (ulp-scale
//! gaps and penetrations) are applied in world coordinates with [`Frame::offset`].

use meshclash::geom::DVec3;
use meshclash::scene::mesh::{Mesh, Object};

/// How faithfully a frame carries a construction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Class {
    /// Every abstract coordinate used by the cases maps exactly (a similarity in exact
    /// arithmetic): every incidence (also a vertex on a slanted face) is kept.
    Exact,
    /// A per-axis monotone map (rounded): equal coordinates stay equal and well separated ones
    /// keep their order, so incidences built from coordinate equalities (axis-aligned
    /// contacts) are kept; slanted incidences are not.
    Monotone,
    /// A rotation: only contacts through bit-identical shared vertices are kept; everything
    /// else is whatever the rounded coordinates say (decided by the exact oracle).
    Rotated,
}

#[derive(Debug, Clone)]
pub struct Frame {
    pub name: String,
    pub class: Class,
    pub scale: f64,
    pub rot: Option<[[f64; 3]; 3]>,
    pub shift: [f64; 3],
}

impl Frame {
    fn new(name: &str, class: Class, scale: f64, rot: Option<[[f64; 3]; 3]>, shift: [f64; 3]) -> Frame {
        Frame { name: name.to_string(), class, scale, rot, shift }
    }

    pub fn p(&self, v: [f64; 3]) -> DVec3 {
        let s = v.map(|x| x * self.scale);
        let r = match self.rot {
            None => s,
            Some(m) => [0, 1, 2].map(|i| m[i][0] * s[0] + m[i][1] * s[1] + m[i][2] * s[2]),
        };
        DVec3::new(r[0] + self.shift[0], r[1] + self.shift[1], r[2] + self.shift[2])
    }

    /// `v` moved along abstract axis `axis` by `off`. Without a rotation the move is made in
    /// world coordinates on the already placed point and rounded away from zero to at least one
    /// ulp, so its sign is never lost; the exact world offset is returned with the point.
    /// With a rotation the move is made in abstract coordinates before placing (the oracle
    /// decides what survives the rounding) and the offset is `None`.
    pub fn offset(&self, v: [f64; 3], axis: usize, off: Off) -> (DVec3, Option<f64>) {
        if self.rot.is_some() {
            let mut w = v;
            w[axis] += match off {
                Off::Rel(d) => d,
                Off::Ulps(n) => n as f64 * f64::EPSILON * v[axis].abs().max(1.0),
            };
            return (self.p(w), None);
        }
        let mut w = self.p(v);
        let x = w[axis];
        let moved = match off {
            Off::Rel(d) => {
                let y = x + d * self.scale;
                if y != x {
                    y
                } else if d > 0.0 {
                    x.next_up()
                } else {
                    x.next_down()
                }
            }
            Off::Ulps(n) => {
                let mut y = x;
                for _ in 0..n.unsigned_abs() {
                    y = if n > 0 { y.next_up() } else { y.next_down() };
                }
                y
            }
        };
        w[axis] = moved;
        (w, Some(moved - x))
    }
}

/// A displacement: relative to the (abstract) size 1, or a number of world ulps.
#[derive(Debug, Clone, Copy)]
pub enum Off {
    Rel(f64),
    Ulps(i32),
}

fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = axis.map(|c| c / l);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

pub fn identity() -> Frame {
    Frame::new("identity", Class::Exact, 1.0, None, [0.0; 3])
}

/// Every frame of bullet 3: powers of two and literal decimals, scalings, rotations.
pub fn all_frames() -> Vec<Frame> {
    use Class::*;
    let p = |e: i32| 2f64.powi(e);
    let r1 = rotation([1.0, 2.0, 3.0], 0.7);
    let r2 = rotation([-0.3, 0.9, 0.2], 2.1);
    vec![
        identity(),
        Frame::new("translate 2^10", Exact, 1.0, None, [p(10), -p(10), p(10)]),
        Frame::new("translate 2^20", Exact, 1.0, None, [p(20), p(20), -p(20)]),
        Frame::new("translate 2^23", Exact, 1.0, None, [-p(23), p(23), p(23)]),
        Frame::new("translate 2^27", Exact, 1.0, None, [p(27), p(27), p(27)]),
        Frame::new("translate 1e3", Exact, 1.0, None, [1e3, 1e3, -1e3]),
        Frame::new("translate 1e6", Exact, 1.0, None, [1e6, -1e6, 1e6]),
        Frame::new("translate 1e7", Exact, 1.0, None, [1e7, 1e7, 1e7]),
        Frame::new("translate 1e8", Exact, 1.0, None, [1e8, 1e8, 1e8]),
        Frame::new("scale 2^20", Exact, p(20), None, [0.0; 3]),
        Frame::new("scale 2^-20", Exact, p(-20), None, [0.0; 3]),
        Frame::new("scale 1e6", Monotone, 1e6, None, [0.0; 3]),
        Frame::new("scale 1e-6", Monotone, 1e-6, None, [0.0; 3]),
        Frame::new("scale 1e-6, translate 1e-3", Monotone, 1e-6, None, [1e-3, -1e-3, 1e-3]),
        Frame::new(
            "translate (1e8+0.1, -1e8/3, 1e8·π)",
            Monotone,
            1.0,
            None,
            [1e8 + 0.1, -1e8 / 3.0, 1e8 * std::f64::consts::PI],
        ),
        Frame::new("scale 0.1, translate 1e7/3", Monotone, 0.1, None, [1e7 / 3.0; 3]),
        Frame::new("rotate (1,2,3) 0.7", Rotated, 1.0, Some(r1), [0.0; 3]),
        Frame::new("rotate (-0.3,0.9,0.2) 2.1", Rotated, 1.0, Some(r2), [0.0; 3]),
        Frame::new("rotate (1,2,3) 0.7, translate 1e8", Rotated, 1.0, Some(r1), [1e8, -1e8, 1e8]),
        Frame::new("rotate (-0.3,0.9,0.2) 2.1, scale 1e-6", Rotated, 1e-6, Some(r2), [0.0; 3]),
        Frame::new("rotate (1,2,3) 0.7, scale 1e6, translate 2^20", Rotated, 1e6, Some(r1), [p(20); 3]),
    ]
}

/// The frames of the tolerance bands: no translation (the tolerance margins of 1e-7 relative
/// must stay far above the distance rounding), absolute scales 1e-6 and 1e6.
pub fn small_frames() -> Vec<Frame> {
    use Class::*;
    let r1 = rotation([1.0, 2.0, 3.0], 0.7);
    vec![
        identity(),
        Frame::new("scale 1e-6", Monotone, 1e-6, None, [0.0; 3]),
        Frame::new("scale 1e6", Monotone, 1e6, None, [0.0; 3]),
        Frame::new("scale 2^20", Exact, 2f64.powi(20), None, [0.0; 3]),
        Frame::new("scale 2^-20", Exact, 2f64.powi(-20), None, [0.0; 3]),
        Frame::new("translate 2^10", Exact, 1.0, None, [1024.0; 3]),
        Frame::new("rotate (1,2,3) 0.7", Rotated, 1.0, Some(r1), [0.0; 3]),
        Frame::new("rotate (1,2,3) 0.7, scale 1e-6", Rotated, 1e-6, Some(r1), [0.0; 3]),
    ]
}

/// Collects vertices and triangles (vertices are not merged: shared corners are pushed once
/// per use, which is how the loaders see them too, and the check must not care).
#[derive(Default, Clone)]
pub struct Mb {
    pub pos: Vec<DVec3>,
    pub tris: Vec<[u32; 3]>,
}

impl Mb {
    pub fn tri(&mut self, a: DVec3, b: DVec3, c: DVec3) -> &mut Self {
        let n = self.pos.len() as u32;
        self.pos.extend([a, b, c]);
        self.tris.push([n, n + 1, n + 2]);
        self
    }

    /// Triangle by indices into `pos` (for repeated-index triangles).
    pub fn tri_idx(&mut self, t: [u32; 3]) -> &mut Self {
        self.tris.push(t);
        self
    }

    /// Quad `a b c d` (in order around it) split along the diagonal `a c`.
    pub fn quad(&mut self, a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> &mut Self {
        self.tri(a, b, c).tri(a, c, d)
    }

    /// A box from its 8 corners (`c[i]`: bit 0 = high x, bit 1 = high y, bit 2 = high z).
    /// Each face is split along the diagonal from its (low, low) corner to its (high, high)
    /// corner, in the face's two free axes, unless `flip` names that face (`2·axis + high`),
    /// then along the other diagonal. 12 triangles, in the order: x-low, x-high, y-low,
    /// y-high, z-low, z-high faces, two each.
    pub fn boxed(&mut self, c: [DVec3; 8], flip: &[usize]) -> &mut Self {
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for high in 0..2 {
                let at = |iu: usize, iv: usize| c[(high << axis) | (iu << u) | (iv << v)];
                let (q00, q10, q11, q01) = (at(0, 0), at(1, 0), at(1, 1), at(0, 1));
                if flip.contains(&(2 * axis + high)) {
                    self.quad(q10, q11, q01, q00);
                } else {
                    self.quad(q00, q10, q11, q01);
                }
            }
        }
        self
    }

    pub fn tet(&mut self, p: [DVec3; 4]) -> &mut Self {
        self.tri(p[0], p[1], p[2]).tri(p[0], p[1], p[3]).tri(p[0], p[2], p[3]).tri(p[1], p[2], p[3])
    }

    pub fn mesh(&self) -> Mesh {
        Mesh {
            positions: self.pos.clone(),
            triangles: self.tris.clone(),
            tri_object: vec![0; self.tris.len()],
            objects: vec![Object { name: "part".into(), ..Default::default() }],
        }
    }
}

/// The 8 corners of the abstract box `[lo, hi]`, placed.
pub fn corners(f: &Frame, lo: [f64; 3], hi: [f64; 3]) -> [DVec3; 8] {
    std::array::from_fn(|i| f.p([0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] })))
}

pub fn boxed(f: &Frame, lo: [f64; 3], hi: [f64; 3]) -> Mb {
    let mut m = Mb::default();
    m.boxed(corners(f, lo, hi), &[]);
    m
}

/// An open `n × n` plate in the plane `z = z0` over `[x0, x1] × [y0, y1]`.
pub fn plate(f: &Frame, x: [f64; 2], y: [f64; 2], z0: f64, n: usize) -> Mb {
    let mut m = Mb::default();
    let at = |i: usize, j: usize| {
        let t = |a: [f64; 2], k: usize| a[0] + (a[1] - a[0]) * k as f64 / n as f64;
        f.p([t(x, i), t(y, j), z0])
    };
    for i in 0..n {
        for j in 0..n {
            m.quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
        }
    }
    m
}
