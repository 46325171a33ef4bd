//! Closed solids written as OBJ parts, and the check run on two of them in both modes (two
//! files, and one scene of two parts), for the suites that compare a per-part-pair figure with
//! an exact oracle (the overlap box, the exact convex depth).

use meshclash::pipeline::{self, Request};
use meshclash::report::Report;
use std::path::Path;

pub type V = [f64; 3];

/// A closed triangle mesh with outward winding.
#[derive(Clone)]
pub struct Solid {
    pub points: Vec<V>,
    pub tris: Vec<[usize; 3]>,
}

impl Solid {
    /// The same solid with every triangle's winding (and the triangle order) reversed.
    pub fn flipped(&self) -> Solid {
        Solid {
            points: self.points.clone(),
            tris: self.tris.iter().rev().map(|t| [t[0], t[2], t[1]]).collect(),
        }
    }

    /// Every point moved by `f`.
    pub fn map(&self, f: impl Fn(V) -> V) -> Solid {
        Solid { points: self.points.iter().map(|&p| f(p)).collect(), tris: self.tris.clone() }
    }

    /// The solid as an OBJ object `name`, its vertex numbers after `offset` earlier vertices.
    pub fn obj(&self, name: &str, offset: usize) -> String {
        let mut s = format!("o {name}\n");
        for p in &self.points {
            s += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
        }
        for t in &self.tris {
            s += &format!("f {} {} {}\n", t[0] + 1 + offset, t[1] + 1 + offset, t[2] + 1 + offset);
        }
        s
    }
}

/// The deterministic report of `req`.
pub fn run(req: Request) -> Report {
    let o = pipeline::run(&Request { deterministic: true, ..req }, &|_| {}).expect("check runs");
    pipeline::report::build(&o)
}

/// `a` (part A) against `b` (part B) as two files and as one scene, in `dir`, each request
/// adjusted by `with`: the two-file report, then the scene report.
pub fn both_modes(dir: &Path, a: &Solid, b: &Solid, with: impl Fn(Request) -> Request) -> (Report, Report) {
    let (pa, pb, ps) = (dir.join("a.obj"), dir.join("b.obj"), dir.join("scene.obj"));
    std::fs::write(&pa, a.obj("A", 0)).unwrap();
    std::fs::write(&pb, b.obj("B", 0)).unwrap();
    std::fs::write(&ps, a.obj("A", 0) + &b.obj("B", a.points.len())).unwrap();
    (run(with(Request::files(&pa, &pb))), run(with(Request::scene(&ps))))
}
