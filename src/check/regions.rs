//! Clash regions: the triangle pairs of one part pair grouped into connected interferences, so a
//! user sees "3 interferences" instead of 5,000 pairs.
//!
//! Two pairs of the same part pair belong to one region when their A triangles share a vertex
//! (exactly coincident positions) or their B triangles do — which also joins pairs that share a
//! triangle. Each region gets a centre, a box and an extent from the pairs' shared segments (or,
//! for coplanar contacts, the triangles' boxes), and a stable id: the smallest finding id
//! ([`crate::check::finding_id`], derived from geometry and part names) among its
//! pairs, so ids do not depend on thread timing or file order.

use crate::bvh::{self, BuildOptions, Bvh};
use crate::check::containment::{self, Inside};
use crate::check::query::{PairFinding, PairKind};
use crate::geom::{Aabb, DVec3};
use crate::scene::bodies::{find, union, vertex_key};
use crate::scene::mesh::{Mesh, WorldTriangles};
use rayon::prelude::*;
use std::collections::HashMap;

/// At most this many vertices (taken at an even stride in a fixed order) are measured per
/// region and side, so the estimate costs a bounded number of point queries.
pub const PENETRATION_SAMPLES: usize = 1024;

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
    /// Diagonal of that box: the size of the interference curve or patch.
    pub extent: f64,
    /// Penetration estimate (see [`estimate_penetration`]); `None` until estimated, or when
    /// neither part is closed.
    pub penetration: Option<Penetration>,
    /// Indices into the pairs the region was made from.
    pub members: Vec<usize>,
}

/// How deep one part reaches into the other at a region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// The largest distance found from a sampled point of one part's surface that lies inside
    /// the other (closed) part, near this region, to the other part's surface; 0 when none is.
    pub depth: f64,
    /// That point (the centre of the region when `depth` is 0).
    pub point: DVec3,
    /// Whose point: 0 = a point of A's surface inside B, 1 = of B's inside A.
    pub side: u8,
    /// Points found inside the other part and measured (sampled: at most about
    /// 2 × [`PENETRATION_SAMPLES`] per region and side).
    pub samples: usize,
}

/// Group `pairs` (triangle indices into `a` and `b`) into regions, sorted by id. `a` and `b`
/// are where the triangles come from ([`WorldTriangles`]): only the pairs' triangles are read.
pub fn regions<A, B>(pairs: &[PairFinding], a: &A, b: &B) -> Vec<Region>
where
    A: WorldTriangles + ?Sized,
    B: WorldTriangles + ?Sized,
{
    regions_with_ids(pairs, a, b, &crate::check::finding_id::finding_hashes(pairs, a, b))
}

/// [`regions`] given every pair's finding id (`ids[i]`, the
/// [`crate::check::finding_id::finding_hash`] of `pairs[i]`).
///
/// Regions never span part pairs, so each part pair's pairs are grouped on their own (in
/// parallel): the (side, vertex) keys of its pairs' triangles are sorted, and pairs with equal
/// keys joined.
pub fn regions_with_ids<A, B>(pairs: &[PairFinding], a: &A, b: &B, ids: &[u64]) -> Vec<Region>
where
    A: WorldTriangles + ?Sized,
    B: WorldTriangles + ?Sized,
{
    assert_eq!(pairs.len(), ids.len(), "one finding id per pair");
    let objects = |p: &PairFinding| (a.object_of(p.a), b.object_of(p.b));
    // The pairs of each part pair, in pair order.
    let mut order: Vec<((u32, u32), u32)> =
        pairs.par_iter().enumerate().map(|(i, p)| (objects(p), i as u32)).collect();
    order.par_sort_unstable();
    let mut spans: Vec<&[((u32, u32), u32)]> = order.chunk_by(|x, y| x.0 == y.0).collect();
    // Large part pairs first, so the parallel split stays even.
    spans.sort_by_key(|s| std::cmp::Reverse(s.len()));
    let mut out: Vec<(u64, Region)> = spans
        .par_iter()
        .flat_map_iter(|span| {
            let members: Vec<usize> = span.iter().map(|&(_, i)| i as usize).collect();
            part_pair_regions(pairs, a, b, ids, &members)
        })
        .collect();
    // Distinct pairs have distinct ids but for a hash collision (or identical triangles and
    // names): the first member settles those ties.
    out.par_sort_unstable_by_key(|(id, r)| (*id, r.members[0]));
    out.into_iter().map(|(_, r)| r).collect()
}

/// Join the nodes of one side (`tris`, distinct triangles of `m`, node `base + k` for
/// `tris[k]`) whose triangles share a vertex position.
fn join_shared_vertices<M: WorldTriangles + ?Sized>(m: &M, tris: &[u32], base: u32, parent: &mut [u32]) {
    let mut keys: Vec<([u64; 3], u32)> = Vec::with_capacity(3 * tris.len());
    for (k, &t) in tris.iter().enumerate() {
        for p in m.corners(t) {
            keys.push((vertex_key(&p), base + k as u32));
        }
    }
    keys.sort_unstable();
    for w in keys.windows(2) {
        if w[0].0 == w[1].0 {
            union(parent, w[0].1, w[1].1);
        }
    }
}

/// The regions of one part pair's pairs (`members`: their indices into `pairs`, ascending),
/// each with its id's number.
fn part_pair_regions<A, B>(
    pairs: &[PairFinding],
    a: &A,
    b: &B,
    ids: &[u64],
    members: &[usize],
) -> Vec<(u64, Region)>
where
    A: WorldTriangles + ?Sized,
    B: WorldTriangles + ?Sized,
{
    // Nodes: the distinct A triangles of these pairs, then the distinct B triangles. Two
    // nodes of one side are joined when their triangles share a vertex position, and a pair
    // joins its two nodes; pairs are in one region exactly when their nodes are joined (pairs
    // with the same triangle share its vertices).
    let mut tris: [Vec<u32>; 2] =
        [members.iter().map(|&i| pairs[i].a).collect(), members.iter().map(|&i| pairs[i].b).collect()];
    for t in &mut tris {
        t.sort_unstable();
        t.dedup();
    }
    let na = tris[0].len();
    let mut parent: Vec<u32> = (0..(na + tris[1].len()) as u32).collect();
    join_shared_vertices(a, &tris[0], 0, &mut parent);
    join_shared_vertices(b, &tris[1], na as u32, &mut parent);
    let node = |side: usize, t: u32| -> u32 {
        let k = tris[side].binary_search(&t).expect("the triangle is a node") as u32;
        if side == 0 {
            k
        } else {
            na as u32 + k
        }
    };
    let nodes: Vec<u32> = members.iter().map(|&i| node(0, pairs[i].a)).collect();
    for (&i, &na_node) in members.iter().zip(&nodes) {
        union(&mut parent, na_node, node(1, pairs[i].b));
    }
    // One set per root, numbered in order of first member; members stay ascending.
    let mut set_of_root = vec![u32::MAX; parent.len()];
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for (&i, &n) in members.iter().zip(&nodes) {
        let r = find(&mut parent, n) as usize;
        if set_of_root[r] == u32::MAX {
            set_of_root[r] = sets.len() as u32;
            sets.push(Vec::new());
        }
        sets[set_of_root[r] as usize].push(i);
    }
    sets.into_iter()
        .map(|members| {
            let mut bounds = Aabb::EMPTY;
            let mut sum = DVec3::ZERO;
            let mut id = u64::MAX;
            let mut crossing = 0;
            for &i in &members {
                let p = &pairs[i];
                let (lo, hi) = match p.segment {
                    Some([s, t]) => (s, t),
                    None => {
                        let tb = Aabb::of_triangle(&a.corners(p.a));
                        (tb.min, tb.max)
                    }
                };
                bounds = bounds.grow(lo).grow(hi);
                sum += lo * 0.5 + hi * 0.5;
                crossing += (p.kind == PairKind::Crossing) as usize;
                id = id.min(ids[i]);
            }
            let p0 = &pairs[members[0]];
            let region = Region {
                id: crate::check::finding_id::format_id(id),
                objects: (a.object_of(p0.a), b.object_of(p0.b)),
                pairs: members.len(),
                crossing,
                center: sum / members.len() as f64,
                bounds,
                extent: bounds.extent().length(),
                penetration: None,
                members,
            };
            (id, region)
        })
        .collect()
}

fn point_distance(p: DVec3, m: &Mesh, t: &Bvh) -> f64 {
    let pb = Aabb { min: p, max: p };
    let mut best = f64::INFINITY;
    let mut stack = vec![0u32];
    while let Some(i) = stack.pop() {
        let n = &t.nodes[i as usize];
        if n.bounds.distance_sq(&pb) >= best * best {
            continue;
        }
        if n.is_leaf() {
            for &tri in t.leaf_prims(n) {
                let [a, b, c] = bvh::triangle(m, tri);
                best =
                    best.min((crate::narrow::distance::closest_point_on_triangle(p, a, b, c) - p).length());
            }
        } else {
            let (l, r) = (i + 1, n.a);
            let dl = t.nodes[l as usize].bounds.distance_sq(&pb);
            let dr = t.nodes[r as usize].bounds.distance_sq(&pb);
            let order = if dl <= dr { [r, l] } else { [l, r] };
            stack.extend(order);
        }
    }
    best
}

/// One part of one input, ready for point queries: its triangles, tree, and whether it is
/// closed (only a closed part has an inside).
struct Solid {
    mesh: Mesh,
    tree: Bvh,
}

/// Estimate each region's penetration depth.
///
/// For each side (A's vertices inside B's part, then B's inside A's), when the *other* part
/// is closed: the inner part's triangles that meet no triangle of the other part ("free"
/// triangles) form connected pieces, each entirely inside or entirely outside the other part
/// (a piece that reached the other surface would have a triangle meeting it), so one exact
/// ray-parity test decides a piece. The candidates are the vertices of the pieces sharing a
/// vertex with the region's triangles, plus the region's own vertices and its triangles'
/// centroids and edge midpoints that are inside (exact parity) and off the other surface; the
/// depth is the largest distance from a candidate to the other part's surface, over both
/// sides. It is a lower bound on how far the surfaces interpenetrate there (the surface
/// between samples is not searched), exact when the deepest point is a sample — a box corner,
/// a pin's end. Distances are f64 (rounded like `min_distance`).
///
/// Needs the complete pair list (not `--first-hit`). Parts are copied and a tree built only
/// for parts that have a region.
pub fn estimate_penetration(
    regs: &mut [Region],
    pairs: &[PairFinding],
    a: &Mesh,
    b: &Mesh,
    opts: BuildOptions,
) {
    if regs.is_empty() {
        return;
    }
    let meshes = [a, b];
    // Solids: the parts that are the "outer" side of some region, built in parallel.
    let mut wanted: Vec<(u8, u32)> =
        regs.iter().flat_map(|r| [(0u8, r.objects.0), (1u8, r.objects.1)]).collect();
    wanted.sort_unstable();
    wanted.dedup();
    let solids: HashMap<(u8, u32), Option<Solid>> = wanted
        .par_iter()
        .map(|&(side, o)| {
            let m = meshes[side as usize];
            let tris: Vec<u32> =
                (0..m.triangles.len() as u32).filter(|&t| m.tri_object[t as usize] == o).collect();
            let mesh = m.sub_mesh(&tris);
            let solid = containment::topology(&mesh).closed.then(|| {
                let tree = Bvh::build(&mesh, opts);
                Solid { mesh, tree }
            });
            ((side, o), solid)
        })
        .collect();
    let merged = [
        crate::scene::bodies::merge_vertices(&a.positions),
        crate::scene::bodies::merge_vertices(&b.positions),
    ];
    // Per part pair: which triangles of each side meet the other part.
    let mut cut: HashMap<(u32, u32), [Vec<u32>; 2]> = HashMap::new();
    for p in pairs {
        let e = cut.entry((a.tri_object[p.a as usize], b.tri_object[p.b as usize])).or_default();
        e[0].push(p.a);
        e[1].push(p.b);
    }
    for c in cut.values_mut() {
        for v in c.iter_mut() {
            v.sort_unstable();
            v.dedup();
        }
    }
    // Regions grouped by part pair: the free pieces of a part pair are found once for all its
    // regions (in parallel over part pairs).
    let mut groups: std::collections::BTreeMap<(u32, u32), Vec<usize>> = Default::default();
    for (i, r) in regs.iter().enumerate() {
        groups.entry(r.objects).or_default().push(i);
    }
    let regs_ro: &[Region] = regs;
    let estimates: Vec<(usize, Option<Penetration>)> = groups
        .par_iter()
        .flat_map_iter(|(objects, members)| {
            let mut best: Vec<Option<Penetration>> = vec![None; members.len()];
            for side in 0..2u8 {
                let (inner, outer_obj, inner_obj) = match side {
                    0 => (a, (1u8, objects.1), objects.0),
                    _ => (b, (0u8, objects.0), objects.1),
                };
                let Some(Some(outer)) = solids.get(&outer_obj) else { continue };
                let (ids, distinct) = &merged[side as usize];
                let pieces = Pieces::new(inner, inner_obj, ids, *distinct, &cut[objects][side as usize]);
                for (k, &ri) in members.iter().enumerate() {
                    let found = side_depth(&regs_ro[ri], pairs, side, inner, ids, &pieces, outer);
                    if best[k].is_none_or(|x| found.depth > x.depth) {
                        best[k] = Some(found);
                    }
                }
            }
            members.iter().copied().zip(best).collect::<Vec<_>>()
        })
        .collect();
    for (i, e) in estimates {
        regs[i].penetration = e;
    }
}

/// The inner part's triangles that meet no triangle of the other part ("free"), joined into
/// pieces through shared (merged) vertices: for each merged vertex id, the root of its piece
/// and one vertex index, or `u32::MAX` for ids on no free triangle.
struct Pieces {
    root: Vec<u32>,
    vertex: Vec<u32>,
}

impl Pieces {
    fn new(inner: &Mesh, inner_obj: u32, merged: &[u32], distinct: usize, cuts: &[u32]) -> Pieces {
        let mut parent: Vec<u32> = (0..distinct as u32).collect();
        let mut vertex = vec![u32::MAX; distinct];
        for (t, tri) in inner.triangles.iter().enumerate() {
            if inner.tri_object[t] != inner_obj || cuts.binary_search(&(t as u32)).is_ok() {
                continue;
            }
            let v = tri.map(|i| merged[i as usize]);
            for k in 0..3 {
                if vertex[v[k] as usize] == u32::MAX {
                    vertex[v[k] as usize] = tri[k];
                }
            }
            for k in 1..3 {
                union(&mut parent, v[0], v[k]);
            }
        }
        let root = (0..distinct as u32)
            .map(|m| if vertex[m as usize] == u32::MAX { u32::MAX } else { find(&mut parent, m) })
            .collect();
        Pieces { root, vertex }
    }
}

fn side_depth(
    r: &Region,
    pairs: &[PairFinding],
    side: u8,
    inner: &Mesh,
    merged: &[u32],
    free: &Pieces,
    outer: &Solid,
) -> Penetration {
    let tri_of = |p: &PairFinding| if side == 0 { p.a } else { p.b };
    // The region's vertices (one per merged id, in a fixed order).
    let mut region_vertices: Vec<(u32, u32)> = r
        .members
        .iter()
        .flat_map(|&i| inner.triangles[tri_of(&pairs[i]) as usize])
        .map(|v| (merged[v as usize], v))
        .collect();
    region_vertices.sort_unstable();
    region_vertices.dedup_by_key(|x| x.0);
    // Pieces touching the region, and the region's vertices that belong to no free triangle.
    let mut pieces: Vec<u32> = Vec::new();
    let mut loose: Vec<u32> = Vec::new();
    for &(m, v) in &region_vertices {
        match free.root[m as usize] {
            u32::MAX => loose.push(v),
            root => pieces.push(root),
        }
    }
    pieces.sort_unstable();
    pieces.dedup();
    // A free vertex is off the other surface, so the parity test applies to a piece's root.
    pieces.retain(|&root| {
        let probe = inner.positions[free.vertex[root as usize] as usize];
        containment::point_in_closed_mesh(probe, &outer.mesh, &outer.tree) == Inside::Yes
    });
    // Vertices of the inside pieces, in merged-id order.
    let candidates: Vec<DVec3> = if pieces.is_empty() {
        Vec::new()
    } else {
        (0..free.root.len())
            .filter(|&m| free.root[m] != u32::MAX && pieces.binary_search(&free.root[m]).is_ok())
            .map(|m| inner.positions[free.vertex[m] as usize])
            .collect()
    };
    // Loose points: the region's vertices on no free triangle, and the centroid and edge
    // midpoints of the region's triangles (a long triangle crossing a thin wall has its
    // deepest points between its vertices), sampled.
    let mut loose: Vec<DVec3> = loose.iter().map(|&v| inner.positions[v as usize]).collect();
    let mut tris: Vec<u32> = r.members.iter().map(|&i| tri_of(&pairs[i])).collect();
    tris.sort_unstable();
    tris.dedup();
    for &t in tris.iter().step_by(tris.len().div_ceil(PENETRATION_SAMPLES / 4).max(1)) {
        let [a, b, c] = bvh::triangle(inner, t);
        loose.extend([(a + b + c) / 3.0, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
    }
    let mut measured: Vec<(DVec3, f64)> = Vec::new();
    for &p in loose.iter().step_by(loose.len().div_ceil(PENETRATION_SAMPLES).max(1)) {
        // A point on the other surface (exactly) is not inside, and the parity test needs it off.
        if !containment::on_surface(p, &outer.mesh, &outer.tree)
            && containment::point_in_closed_mesh(p, &outer.mesh, &outer.tree) == Inside::Yes
        {
            measured.push((p, point_distance(p, &outer.mesh, &outer.tree)));
        }
    }
    let stride = candidates.len().div_ceil(PENETRATION_SAMPLES).max(1);
    let mut best = Penetration { depth: 0.0, point: r.center, side, samples: 0 };
    let inside = candidates.iter().step_by(stride).map(|&p| (p, point_distance(p, &outer.mesh, &outer.tree)));
    for (p, d) in inside.chain(measured) {
        best.samples += 1;
        if d > best.depth {
            best.depth = d;
            best.point = p;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::query::{check, Settings};
    use crate::scene::mesh::Object;

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
        let strip =
            |v: Vec<Region>| v.into_iter().map(|g| Region { members: vec![], ..g }).collect::<Vec<_>>();
        assert_eq!(strip(regions(&rev, &a, &b)), strip(regs));
    }

    /// A closed box from `lo` to `hi` with each face cut into `n`×`n` quads (shared vertices).
    fn grid_box(lo: DVec3, hi: DVec3, n: usize) -> Mesh {
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut m = mesh(&[]);
        let mut vid = |m: &mut Mesh, p: DVec3| {
            *index.entry(vertex_key(&p)).or_insert_with(|| {
                m.positions.push(p);
                (m.positions.len() - 1) as u32
            })
        };
        let at = |axis: usize, side: f64, u: f64, v: f64| {
            let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut p = [0.0; 3];
            p[axis] = lo[axis] + side * (hi[axis] - lo[axis]);
            p[i] = lo[i] + u * (hi[i] - lo[i]);
            p[j] = lo[j] + v * (hi[j] - lo[j]);
            DVec3::from(p)
        };
        for axis in 0..3 {
            for side in [0.0, 1.0] {
                for x in 0..n {
                    for y in 0..n {
                        let f = |dx: usize, dy: usize| {
                            at(axis, side, (x + dx) as f64 / n as f64, (y + dy) as f64 / n as f64)
                        };
                        let q = [f(0, 0), f(1, 0), f(1, 1), f(0, 1)].map(|p| vid(&mut m, p));
                        m.triangles.push([q[0], q[1], q[2]]);
                        m.triangles.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
        m.tri_object = vec![0; m.triangles.len()];
        m
    }

    fn estimated(a: &Mesh, b: &Mesh) -> Vec<Region> {
        let r = check(a, b, &Settings::default());
        let mut regs = regions(&r.pairs, a, b);
        estimate_penetration(&mut regs, &r.pairs, a, b, BuildOptions::default());
        regs
    }

    #[test]
    fn penetration_of_a_box_pushed_into_another_is_the_deepest_vertex() {
        // B pokes 3 units into A through A's face x = 4 and is wider than A's cells: the
        // deepest vertex is A's face vertex (4, 2, 2), 1.5 inside B (its faces y, z = 0.5, 3.5);
        // B's deepest vertices are on its face x = 1, 1 inside A.
        let a = grid_box(DVec3::ZERO, DVec3::splat(4.0), 4);
        let b = grid_box(DVec3::new(1.0, 0.5, 0.5), DVec3::new(6.0, 3.5, 3.5), 3);
        let regs = estimated(&a, &b);
        assert_eq!(regs.len(), 1, "{regs:?}");
        let p = regs[0].penetration.expect("both closed");
        assert_eq!((p.depth, p.point, p.side), (1.5, DVec3::new(4.0, 2.0, 2.0), 0));
        // Swapped inputs: the same vertex, now B's.
        let p = estimated(&b, &a)[0].penetration.unwrap();
        assert_eq!((p.depth, p.point, p.side), (1.5, DVec3::new(4.0, 2.0, 2.0), 1));
    }

    #[test]
    fn penetration_of_coarse_boxes_uses_the_region_vertices() {
        // 12-triangle boxes: B's face x = 1.5 lies inside A, its corners 0.5 from A's walls.
        let a = grid_box(DVec3::ZERO, DVec3::splat(2.0), 1);
        let b = grid_box(DVec3::new(1.5, 0.5, 0.5), DVec3::new(3.5, 1.5, 1.5), 1);
        // A's face x = 2 reaches 0.5 into B too, at its diagonal's midpoint (2, 1, 1): a tie,
        // which A's side wins.
        let p = estimated(&a, &b)[0].penetration.unwrap();
        assert_eq!((p.depth, p.side, p.point), (0.5, 0, DVec3::new(2.0, 1.0, 1.0)));
        // Open outer parts have no inside: no estimate from that side, and none at all when
        // both are open.
        let mut open_a = a.clone();
        open_a.triangles.pop();
        open_a.tri_object.pop();
        let p = estimated(&open_a, &b)[0].penetration;
        assert!(p.is_none_or(|p| p.side == 0), "{p:?}");
        let mut open_b = b.clone();
        open_b.triangles.pop();
        open_b.tri_object.pop();
        assert!(estimated(&open_a, &open_b).iter().all(|g| g.penetration.is_none()));
    }

    #[test]
    fn boxes_that_only_touch_have_zero_penetration() {
        let a = grid_box(DVec3::ZERO, DVec3::splat(2.0), 2);
        let b = grid_box(DVec3::new(2.0, 0.5, 0.5), DVec3::new(3.0, 1.5, 1.5), 2);
        let regs = estimated(&a, &b);
        assert!(!regs.is_empty());
        assert!(regs.iter().all(|g| g.penetration.unwrap().depth == 0.0), "{regs:?}");
    }

    /// A mesh of `n` triangles on a coarse integer grid (so that many share vertex positions,
    /// some with a negative zero), spread over `objects` objects.
    fn grid_mesh(n: usize, objects: u32, seed: u64) -> Mesh {
        let mut r = seed;
        let mut next = move |m: u64| {
            r = r.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (r >> 33) % m
        };
        let mut m = Mesh::default();
        for _ in 0..n {
            let base = m.positions.len() as u32;
            for _ in 0..3 {
                let c = |v: u64| if v == 0 { -0.0 } else { v as f64 * 0.5 };
                m.positions.push(DVec3::new(c(next(6)), c(next(6)), c(next(3))));
            }
            m.triangles.push([base, base + 1, base + 2]);
            m.tri_object.push(next(objects as u64) as u32);
        }
        m.objects = (0..objects).map(|o| Object { name: format!("o{o}"), ..Default::default() }).collect();
        m
    }

    /// Regions as one union-find over every pair, keyed by (side, part pair, vertex): the
    /// definition, written the plain way.
    fn regions_oracle(pairs: &[PairFinding], a: &Mesh, b: &Mesh) -> Vec<Region> {
        let n = pairs.len();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        let mut first: HashMap<(u8, u32, u32, [u64; 3]), u32> = HashMap::new();
        for (i, p) in pairs.iter().enumerate() {
            let objs = (a.tri_object[p.a as usize], b.tri_object[p.b as usize]);
            for (side, m, t) in [(0u8, a, p.a), (1u8, b, p.b)] {
                for v in m.triangles[t as usize] {
                    let k = (side, objs.0, objs.1, vertex_key(&m.positions[v as usize]));
                    let j = *first.entry(k).or_insert(i as u32);
                    union(&mut parent, i as u32, j);
                }
            }
        }
        let mut groups: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
        for i in 0..n {
            let r = find(&mut parent, i as u32);
            groups.entry(r).or_default().push(i);
        }
        let mut out: Vec<Region> = groups
            .into_values()
            .map(|members| {
                let (mut bounds, mut sum, mut crossing) = (Aabb::EMPTY, DVec3::ZERO, 0);
                let mut id = String::from("g");
                for &i in &members {
                    let p = &pairs[i];
                    let [lo, hi] = p.segment.unwrap();
                    bounds = bounds.grow(lo).grow(hi);
                    sum += lo * 0.5 + hi * 0.5;
                    crossing += (p.kind == PairKind::Crossing) as usize;
                    id = id.min(crate::check::finding_id::finding_id(a, p.a, b, p.b));
                }
                let p0 = &pairs[members[0]];
                Region {
                    id,
                    objects: (a.tri_object[p0.a as usize], b.tri_object[p0.b as usize]),
                    pairs: members.len(),
                    crossing,
                    center: sum / members.len() as f64,
                    bounds,
                    extent: bounds.extent().length(),
                    penetration: None,
                    members,
                }
            })
            .collect();
        out.sort_by(|x, y| (&x.id, x.members[0]).cmp(&(&y.id, y.members[0])));
        out
    }

    fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
    }

    #[test]
    fn regions_and_ids_match_the_plain_definition_at_any_thread_count() {
        let (a, b) = (grid_mesh(300, 3, 1), grid_mesh(200, 4, 2));
        let mut r = 7u64;
        let mut next = move |m: u64| {
            r = r.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (r >> 33) % m
        };
        let mut tri_pairs: Vec<(u32, u32)> =
            (0..5000).map(|_| (next(300) as u32, next(200) as u32)).collect();
        tri_pairs.sort_unstable();
        tri_pairs.dedup();
        let kinds = [PairKind::Crossing, PairKind::Touching, PairKind::Clearance];
        let mut pairs: Vec<PairFinding> = tri_pairs
            .iter()
            .map(|&(ta, tb)| {
                let s = DVec3::new(next(100) as f64, next(100) as f64, -(next(100) as f64)) / 7.0;
                PairFinding {
                    a: ta,
                    b: tb,
                    kind: kinds[next(3) as usize],
                    contact: None,
                    distance: 0.0,
                    segment: Some([s, s + DVec3::new(0.1, next(9) as f64, 0.3)]),
                }
            })
            .collect();
        for sorted in [true, false] {
            if !sorted {
                // Not sorted by (a, b): the shared first halves of the hashes must not leak.
                pairs.reverse();
                pairs.swap(1, 40);
            }
            let want_ids: Vec<u64> =
                pairs.iter().map(|p| crate::check::finding_id::finding_hash(&a, p.a, &b, p.b)).collect();
            let want = regions_oracle(&pairs, &a, &b);
            assert!(want.len() > 5 && want.iter().any(|r| r.pairs > 1), "{}", want.len());
            for threads in [1, 2, 3] {
                let ids = in_pool(threads, || crate::check::finding_id::finding_hashes(&pairs, &a, &b));
                assert_eq!(ids, want_ids, "{threads} threads");
                let got = in_pool(threads, || regions_with_ids(&pairs, &a, &b, &ids));
                assert_eq!(got.len(), want.len());
                for (g, w) in got.iter().zip(&want) {
                    assert_eq!(g, w, "{threads} threads");
                    assert_eq!(g.center.to_array().map(f64::to_bits), w.center.to_array().map(f64::to_bits));
                }
            }
        }
    }
}
