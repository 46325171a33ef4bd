//! Clash regions: the triangle pairs of one part pair grouped into connected interferences, so a
//! user sees "3 interferences" instead of 5,000 pairs.
//!
//! Two pairs of the same part pair belong to one region when their A triangles share a vertex
//! (exactly coincident positions) or their B triangles do — which also joins pairs that share a
//! triangle. Each region gets a centre, a box and an extent from the pairs' shared segments (or,
//! for coplanar contacts, the triangles' boxes), and a stable id: the smallest finding id
//! ([`crate::output::baseline::finding_id`], derived from geometry and part names) among its
//! pairs, so ids do not depend on thread timing or file order.

use crate::geom::{Aabb, DVec3};
use crate::mesh::Mesh;
use crate::query::{PairFinding, PairKind};
use std::collections::HashMap;

/// One connected interference.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Stable id (hex).
    pub id: String,
    /// Object of A and of B.
    pub objects: (u32, u32),
    /// Number of triangle pairs.
    pub pairs: usize,
    /// Of those, crossing pairs.
    pub crossing: usize,
    /// Centre of the contact (mean of the pairs' segment midpoints).
    pub center: DVec3,
    /// Box of the contact set.
    pub bounds: Aabb,
    /// Diagonal of that box: the size of the interference curve or patch (not a penetration
    /// depth, which needs the volumes and is not computed).
    pub extent: f64,
}

fn key(p: DVec3) -> [u64; 3] {
    [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits)
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Group `pairs` (triangle indices into `a` and `b`) into regions, sorted by id.
pub fn regions(pairs: &[PairFinding], a: &Mesh, b: &Mesh) -> Vec<Region> {
    let n = pairs.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut first: HashMap<(u8, u32, u32, [u64; 3]), usize> = HashMap::new();
    for (i, p) in pairs.iter().enumerate() {
        let objs = (a.tri_object[p.a as usize], b.tri_object[p.b as usize]);
        let verts = [(0u8, a, p.a), (1u8, b, p.b)];
        for (side, m, t) in verts {
            for v in m.triangles[t as usize] {
                let k = (side, objs.0, objs.1, key(m.positions[v as usize]));
                let j = *first.entry(k).or_insert(i);
                let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
                if ri != rj {
                    parent[ri.max(rj)] = ri.min(rj);
                }
            }
        }
    }
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..n {
        let r = find(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    let mut out: Vec<Region> = groups
        .into_values()
        .map(|members| {
            let mut bounds = Aabb::EMPTY;
            let mut sum = DVec3::ZERO;
            let mut id: Option<String> = None;
            let mut crossing = 0;
            for &i in &members {
                let p = &pairs[i];
                let (lo, hi) = match p.segment {
                    Some([s, t]) => (s, t),
                    None => {
                        let tb = Aabb::of_triangle(&crate::bvh::triangle(a, p.a));
                        (tb.min, tb.max)
                    }
                };
                bounds = bounds.grow(lo).grow(hi);
                sum += lo * 0.5 + hi * 0.5;
                crossing += (p.kind == PairKind::Crossing) as usize;
                let fid = crate::output::baseline::finding_id(a, p.a, b, p.b);
                if id.as_ref().is_none_or(|m| fid < *m) {
                    id = Some(fid);
                }
            }
            let p0 = &pairs[members[0]];
            Region {
                id: id.unwrap_or_default(),
                objects: (a.tri_object[p0.a as usize], b.tri_object[p0.b as usize]),
                pairs: members.len(),
                crossing,
                center: sum / members.len() as f64,
                bounds,
                extent: bounds.extent().length(),
            }
        })
        .collect();
    out.sort_by(|x, y| x.id.cmp(&y.id));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Object;
    use crate::query::{check, Settings};

    fn plate(z: f64, x0: f64) -> Vec<[DVec3; 3]> {
        // A 4×1 strip of quads in the plane x = const... a vertical fin at x = x0.
        let p = |y: f64, zz: f64| DVec3::new(x0, y, z + zz);
        let mut t = Vec::new();
        for i in 0..4 {
            let y = i as f64;
            t.push([p(y, -1.0), p(y + 1.0, -1.0), p(y + 1.0, 1.0)]);
            t.push([p(y, -1.0), p(y + 1.0, 1.0), p(y, 1.0)]);
        }
        t
    }

    fn mesh(tris: &[[DVec3; 3]]) -> Mesh {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for t in tris {
            let base = positions.len() as u32;
            positions.extend_from_slice(t);
            triangles.push([base, base + 1, base + 2]);
        }
        let n = triangles.len();
        Mesh {
            positions,
            triangles,
            tri_object: vec![0; n],
            objects: vec![Object { name: "m".into(), ..Default::default() }],
        }
    }

    #[test]
    fn two_separate_fins_through_a_floor_are_two_regions() {
        // Floor: a 10×5 grid in z = 0 with shared vertices; two fins cross it at x = 2.5 and 7.5.
        let g = |x: usize, y: usize| DVec3::new(x as f64, y as f64, 0.0);
        let mut floor = Vec::new();
        for x in 0..10 {
            for y in 0..5 {
                floor.push([g(x, y), g(x + 1, y), g(x + 1, y + 1)]);
                floor.push([g(x, y), g(x + 1, y + 1), g(x, y + 1)]);
            }
        }
        let (fa, fb) = (plate(0.0, 2.5), plate(0.0, 7.5));
        let fins: Vec<_> = fa.into_iter().chain(fb).collect();
        let (a, b) = (mesh(&floor), mesh(&fins));
        // Floor triangles do not share vertex *indices* (soup), but positions coincide: regions
        // join on positions.
        let r = check(&a, &b, &Settings::default());
        assert!(r.counts.crossing > 0);
        let regs = regions(&r.pairs, &a, &b);
        assert_eq!(regs.len(), 2, "{regs:?}");
        assert_eq!(regs.iter().map(|g| g.pairs).sum::<usize>(), r.pairs.len());
        let xs: Vec<f64> = regs.iter().map(|g| g.center.x).collect();
        assert!(xs.iter().any(|x| (x - 2.5).abs() < 1e-12) && xs.iter().any(|x| (x - 7.5).abs() < 1e-12));
        // Stable: the same regions from the pairs in another order.
        let mut rev = r.pairs.clone();
        rev.reverse();
        assert_eq!(regions(&rev, &a, &b), regs);
    }
}
