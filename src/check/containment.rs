//! Is one part hidden inside the other? A closed part fully inside another touches no triangle
//! of it, so the pair search alone says "clear"; this module decides it.
//!
//! * [`topology`]: exactly coincident vertices are merged; a mesh is *closed* when every edge of
//!   its non-degenerate triangles is shared by exactly two of them; connected components are
//!   found with a union–find over the merged vertices.
//! * [`point_in_closed_mesh`]: parity of the crossings of a segment (a "ray" from the point to
//!   beyond the container's box) with the container's triangles, every crossing decided by exact
//!   `orient3d` signs (a segment–triangle test in the style of Möller–Trumbore, but with exact
//!   predicates instead of floating-point barycentrics). A ray that meets an edge or a vertex
//!   exactly, or lies in a triangle's plane, is discarded and another direction is tried, so the
//!   parity is always taken on a generic ray. For a closed (mod-2) surface the parity is the
//!   "odd" inside rule; for a surface that does not intersect itself it is plain inside.
//!
//! Called only when no pair of triangles meets: then each connected component of one mesh is
//! entirely inside or entirely outside the other, so one vertex per component decides.

use crate::bvh::traverse::Tree;
use crate::geom::exact;
use crate::geom::predicates as pr;
use crate::geom::{Aabb, DVec3};
use crate::narrow::tri_tri::{self, Contact, Shape};
use crate::scene::mesh::TriMesh;
use std::collections::HashMap;

/// Closedness and components of one mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topology {
    /// Every edge of every non-degenerate triangle is shared by exactly two of them (after
    /// merging exactly coincident vertices).
    pub closed: bool,
    /// One vertex index per connected component (the first, in triangle order).
    pub component_seeds: Vec<u32>,
    /// For each vertex of the mesh, its component (index into `component_seeds`), or
    /// `u32::MAX` for a vertex no triangle uses.
    pub component_of: Vec<u32>,
    /// Exactly-coincident-vertex ids (index into the distinct positions), per vertex; used by
    /// [`outward`] when it is needed.
    pub merged: Vec<u32>,
}

/// Merge exactly coincident vertices (+0 and −0 are the same point) and count edge uses.
///
/// Linear passes over the triangles: merged ids numbered in order of first occurrence (one hash
/// table, [`crate::scene::bodies::merge_vertices_in_order`]; ids then follow the file's vertex
/// order, so the union–find and the edge buckets below touch memory mostly in order), edges of
/// the proper triangles bucketed by their lower end (a counting sort), components by a
/// union–find whose roots are flattened in one ascending pass. The merge runs beside the
/// parallel pass that tells proper triangles (one byte each) from zero-area ones; the passes
/// after it read each triangle's merged ids from the mesh again rather than from a copy.
pub fn topology<M: TriMesh + ?Sized>(mesh: &M) -> Topology {
    use crate::scene::bodies::union;
    use rayon::prelude::*;
    let n = mesh.triangle_count();
    let vertices = mesh.vertex_count();
    let ((merged, distinct), proper) = rayon::join(
        || crate::scene::bodies::merge_vertices_in_order(&mesh.positions()),
        || {
            (0..n as u32)
                .into_par_iter()
                .map(|t| !Shape::of(&mesh.triangle(t)).is_degenerate())
                .collect::<Vec<bool>>()
        },
    );
    let ids = |t: u32| mesh.indices(t).map(|i| merged[i as usize]);
    let mut parent: Vec<u32> = (0..distinct as u32).collect();
    // Undirected edges (lo, hi) of the proper triangles, bucketed by lo (a counting sort: two
    // passes over the triangles, 4 bytes per edge).
    let lo_hi = |v: [u32; 3], k: usize| (v[k].min(v[(k + 1) % 3]), v[k].max(v[(k + 1) % 3]));
    let mut start = vec![0u32; distinct + 1];
    let mut used = vec![false; vertices];
    for t in 0..n as u32 {
        let idx = mesh.indices(t);
        for i in idx {
            used[i as usize] = true;
        }
        let v = idx.map(|i| merged[i as usize]);
        // Two unions join all three vertices.
        union(&mut parent, v[0], v[1]);
        union(&mut parent, v[1], v[2]);
        if proper[t as usize] {
            for k in 0..3 {
                start[lo_hi(v, k).0 as usize + 1] += 1;
            }
        }
    }
    for i in 0..distinct {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut hi = vec![0u32; start[distinct] as usize];
    for t in (0..n as u32).filter(|&t| proper[t as usize]) {
        let v = ids(t);
        for k in 0..3 {
            let (a, b) = lo_hi(v, k);
            hi[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
        }
    }
    drop(fill);
    drop(proper);
    // Closed: every undirected edge of the proper triangles used exactly twice.
    let closed = !hi.is_empty()
        && (0..distinct).all(|a| {
            let bucket = &mut hi[start[a] as usize..start[a + 1] as usize];
            bucket.sort_unstable();
            bucket.chunk_by(|x, y| x == y).all(|run| run.len() == 2)
        });
    drop(hi);
    drop(start);
    // Every parent is below its child (a union hangs the larger root under the smaller, path
    // halving only shortens), so one ascending pass turns `parent` into each id's root.
    for x in 0..distinct {
        let p = parent[x] as usize;
        parent[x] = parent[p];
    }
    let root = parent;
    // The first vertex (in triangle order) of each component.
    let mut comp_of_root = vec![u32::MAX; distinct];
    let mut component_seeds = Vec::new();
    for t in 0..n as u32 {
        let first = mesh.indices(t)[0];
        let r = root[merged[first as usize] as usize] as usize;
        if comp_of_root[r] == u32::MAX {
            comp_of_root[r] = component_seeds.len() as u32;
            component_seeds.push(first);
        }
    }
    let component_of = (0..vertices)
        .map(|v| if used[v] { comp_of_root[root[merged[v] as usize] as usize] } else { u32::MAX })
        .collect();
    Topology { closed, component_seeds, component_of, merged }
}

/// For a closed mesh: per triangle, +1 if its normal (right-hand rule) points out of the solid,
/// −1 if in, 0 for zero-area triangles. Found by propagating a consistent winding across shared
/// edges within each component and taking the sign of each component's signed volume, so input
/// winding does not matter. `None` for open meshes, or if some component cannot be oriented
/// consistently. Computed only when a face-to-face contact needs it (it is the costly part).
pub fn outward<M: TriMesh + ?Sized>(mesh: &M, topo: &Topology) -> Option<Vec<i8>> {
    if !topo.closed {
        return None;
    }
    orient(mesh, &topo.merged)
}

/// See [`outward`].
fn orient<M: TriMesh + ?Sized>(mesh: &M, merged: &[u32]) -> Option<Vec<i8>> {
    let n = mesh.triangle_count();
    let proper: Vec<bool> = (0..n).map(|t| !Shape::of(&mesh.triangle(t as u32)).is_degenerate()).collect();
    // Undirected edge -> the (at most two, as the mesh is closed) triangles using it, with the
    // direction each traverses it in (+1 when from the lower merged id to the higher).
    let mut by_edge: HashMap<(u32, u32), Vec<(u32, i8)>> = HashMap::with_capacity(n * 3 / 2);
    for t in (0..n).filter(|&t| proper[t]) {
        let v = mesh.indices(t as u32).map(|i| merged[i as usize]);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push((t as u32, if a < b { 1 } else { -1 }));
        }
    }
    let mut flip = vec![0i8; n];
    let mut comps: Vec<Vec<u32>> = Vec::new();
    for start in (0..n).filter(|&t| proper[t]) {
        if flip[start] != 0 {
            continue;
        }
        flip[start] = 1;
        let mut comp = vec![start as u32];
        let mut queue = vec![start as u32];
        while let Some(t) = queue.pop() {
            let v = mesh.indices(t).map(|i| merged[i as usize]);
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                let here = if a < b { 1 } else { -1 } * flip[t as usize];
                for &(u, dir) in &by_edge[&(a.min(b), a.max(b))] {
                    if u == t {
                        continue;
                    }
                    // The neighbour must traverse the shared edge the other way.
                    let want = -here * dir;
                    match flip[u as usize] {
                        0 => {
                            flip[u as usize] = want;
                            comp.push(u);
                            queue.push(u);
                        }
                        f if f != want => return None, // not orientable consistently
                        _ => {}
                    }
                }
            }
        }
        comps.push(comp);
    }
    for comp in comps {
        // Signed volume of the component with the propagated winding (f64: only its sign is
        // used, and a closed solid's is far from zero unless it is flat).
        // Relative to a vertex of the component: far from the origin (1e8) the plain triple
        // products cancel catastrophically.
        let o = mesh.triangle(comp[0])[0];
        let vol: f64 = comp
            .iter()
            .map(|&t| {
                let [a, b, c] = mesh.triangle(t).map(|p| p - o);
                a.dot(b.cross(c)) * flip[t as usize] as f64
            })
            .sum();
        if vol == 0.0 {
            return None;
        }
        if vol < 0.0 {
            for &t in &comp {
                flip[t as usize] = -flip[t as usize];
            }
        }
    }
    Some(flip)
}

/// Ray directions tried in turn: nearly axis-aligned (so the segment's box stays thin and the
/// exact box test culls well) with irrational-looking tilts so that meeting an edge exactly is
/// unlikely; fixed, so the answer is deterministic.
const DIRECTIONS: [[f64; 3]; 12] = [
    [1.0, 0.013_732_1, 0.029_113_7],
    [-1.0, 0.021_557_3, -0.017_904_1],
    [0.019_364_9, 1.0, 0.011_243_3],
    [-0.027_718_9, -1.0, 0.015_521_7],
    [0.012_659_3, 0.023_401_9, 1.0],
    [-0.018_237_1, 0.016_633_9, -1.0],
    [1.0, -0.031_415_9, 0.027_182_8],
    [0.033_166_2, 1.0, -0.022_360_7],
    [-0.024_494_9, 0.028_284_3, 1.0],
    [1.0, 0.141_421_4, -0.173_205_1],
    [0.223_606_8, -1.0, 0.264_575_1],
    [-0.316_227_8, 0.331_662_5, -1.0],
];

/// The outcome of one point query.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inside {
    /// Inside (odd number of crossings).
    Yes,
    /// Outside.
    No,
    /// Every direction tried met an edge or vertex exactly.
    Undecided,
}

/// Is `p` inside the closed mesh `m` (with tree `t`)? `p` must not lie on `m`'s surface.
pub fn point_in_closed_mesh<M: TriMesh + ?Sized, T: Tree + ?Sized>(p: DVec3, m: &M, t: &T) -> Inside {
    if !t.root_box().contains(&Aabb { min: p, max: p }) {
        return Inside::No;
    }
    parity(&p, Aabb { min: p, max: p }, m, t)
}

/// The parity test of [`point_in_closed_mesh`] from a ray start `p` that lies in `near` (a
/// box the segments' boxes are built from, exact for an f64 point; the triangle's box for a
/// [`Weighted`] point), `p` not on `m`'s surface.
fn parity<P: RayStart, M: TriMesh + ?Sized, T: Tree + ?Sized>(p: &P, near: Aabb, m: &M, t: &T) -> Inside {
    let bounds = t.root_box();
    let from = near.center();
    // Long enough to leave the box from anywhere inside (or near) it along any tried direction.
    let reach = (bounds.extent().length() + (from - bounds.center()).length()) * 2.0 + 1.0;
    'dir: for d in DIRECTIONS {
        let q = from + DVec3::from(d) * reach;
        let seg = near.grow(q);
        let mut crossings = 0usize;
        let mut visit = |tri: u32| {
            let [a, b, c] = m.triangle(tri);
            match segment_crosses(p, &seg, q, a, b, c) {
                Crossing::No => false,
                Crossing::Yes => {
                    crossings += 1;
                    false
                }
                Crossing::Degenerate => true,
            }
        };
        let degenerate = if near.min == near.max {
            crate::bvh::traverse::any_on_segment(t, near.min, q, visit)
        } else {
            crate::bvh::traverse::any_in_box(t, &seg, &mut visit)
        };
        if degenerate {
            continue 'dir;
        }
        return if crossings % 2 == 1 { Inside::Yes } else { Inside::No };
    }
    Inside::Undecided
}

/// Generalized winding number of `m` at `p` (Jacobson, Kavan, Sorkine-Hornung 2013): the sum
/// of the triangles' signed solid angles over 4π (Van Oosterom & Strackee 1983). 1 inside a
/// closed outward-wound surface, 0 outside, in between for open or leaky ones. f64, used only
/// to decide whether to call an open container's containment "undecided".
pub fn winding_number<M: TriMesh + ?Sized>(p: DVec3, m: &M) -> f64 {
    let total: f64 = (0..m.triangle_count() as u32)
        .map(|t| {
            let [a, b, c] = m.triangle(t).map(|q| q - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
            2.0 * num.atan2(den)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

/// Is `p` exactly on a triangle of `m`?
pub fn on_surface<M: TriMesh + ?Sized, T: Tree + ?Sized>(p: DVec3, m: &M, t: &T) -> bool {
    crate::bvh::traverse::any_in_box(t, &Aabb { min: p, max: p }, |tri| {
        crate::narrow::tri_tri::classify(&[p, p, p], &m.triangle(tri)).is_some()
    })
}

/// Do two closed, consistently oriented solids overlap in volume through a face-to-face
/// contact? A coplanar pair whose outward normals point the same way has both interiors on the
/// same side of the shared area (duplicated parts, flush overlaps, a part touching a solid's
/// wall from inside); opposite normals are plain contact. Exact: the normal directions of two
/// coplanar triangles are compared by 2D orientation signs on one projection.
pub fn coplanar_overlap(ta: &[DVec3; 3], orient_a: i8, tb: &[DVec3; 3], orient_b: i8) -> bool {
    if orient_a == 0 || orient_b == 0 {
        return false;
    }
    let Some(k) = pr::projection_axis(ta[0], ta[1], ta[2]) else { return false };
    let sa = pr::orient2d(ta[0], ta[1], ta[2], k) * orient_a;
    let sb = pr::orient2d(tb[0], tb[1], tb[2], k) * orient_b;
    sa != 0 && sa == sb
}

enum Crossing {
    No,
    Yes,
    /// Through an edge or vertex, or in the plane: try another ray.
    Degenerate,
}

/// The start of a parity ray: exact signs of the orientations that involve it.
trait RayStart {
    /// Sign of `orient3d(a, b, c, self)`.
    fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> pr::Sign;
    /// Sign of `orient3d(self, q, a, b)`.
    fn turn(&self, q: DVec3, a: DVec3, b: DVec3) -> pr::Sign;
}

impl RayStart for DVec3 {
    fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> pr::Sign {
        pr::orient3d(a, b, c, *self)
    }
    fn turn(&self, q: DVec3, a: DVec3, b: DVec3) -> pr::Sign {
        pr::orient3d(*self, q, a, b)
    }
}

/// The segment from `p` to `q` (whose box is `seg`) against triangle `abc`.
fn segment_crosses<P: RayStart>(p: &P, seg: &Aabb, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Crossing {
    if pr::collinear(a, b, c) {
        return Crossing::No; // zero area: not part of the surface a ray can cross
    }
    let sp = p.side(a, b, c);
    let sq = pr::orient3d(a, b, c, q);
    if sp == 0 && sq == 0 {
        // The ray lies in the triangle's plane: it may graze it; do not count, retry.
        return if Aabb::of_triangle(&[a, b, c]).overlaps(seg) { Crossing::Degenerate } else { Crossing::No };
    }
    if sp * sq > 0 {
        return Crossing::No;
    }
    // p is not on the surface (no pair meets), and q is outside the box of every triangle, so
    // a zero sign means the segment only touches the plane outside the triangle.
    if sp == 0 || sq == 0 {
        return Crossing::No;
    }
    let s = [p.turn(q, a, b), p.turn(q, b, c), p.turn(q, c, a)];
    if s.iter().all(|&v| v > 0) || s.iter().all(|&v| v < 0) {
        Crossing::Yes
    } else if s.iter().all(|&v| v >= 0) || s.iter().all(|&v| v <= 0) {
        Crossing::Degenerate
    } else {
        Crossing::No
    }
}

/// A point of a proper triangle `t` given by positive integer barycentric weights,
/// `Σ w_k t_k / Σ w_k`: not representable in f64 in general, so every sign that involves it is
/// the sign of the weighted sum of the exact orientation values of the triangle's vertices
/// (orientation determinants are affine in each point, and the weights sum to a positive
/// number).
#[derive(Debug, Clone, Copy)]
struct Weighted {
    t: [DVec3; 3],
    w: [i64; 3],
}

impl Weighted {
    fn sum(&self, others: &[DVec3], value: impl Fn(&exact::Frame, DVec3) -> exact::Int) -> pr::Sign {
        let f = exact::Frame::of_points(self.t.iter().chain(others));
        exact::weighted_sum((0..3).map(|k| (self.w[k], value(&f, self.t[k])))).signum()
    }

    /// Sign of `orient2d(a, b, self)` on projection `axis`.
    fn orient2d(&self, a: DVec3, b: DVec3, axis: usize) -> pr::Sign {
        self.sum(&[a, b], |f, x| exact::orient2d(f, a, b, x, axis))
    }

    /// Exactly on the closed proper triangle `g`?
    fn on_triangle(&self, g: &[DVec3; 3]) -> bool {
        let Some(k) = pr::projection_axis(g[0], g[1], g[2]) else { return false };
        if self.side(g[0], g[1], g[2]) != 0 {
            return false;
        }
        let sigma = pr::orient2d(g[0], g[1], g[2], k);
        (0..3).all(|i| self.orient2d(g[i], g[(i + 1) % 3], k) * sigma >= 0)
    }
}

impl RayStart for Weighted {
    fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> pr::Sign {
        self.sum(&[a, b, c], |f, x| exact::orient3d(f, a, b, c, x))
    }
    fn turn(&self, q: DVec3, a: DVec3, b: DVec3) -> pr::Sign {
        self.sum(&[q, a, b], |f, x| exact::orient3d(f, x, q, a, b))
    }
}

/// Where one mesh sits relative to the other, when no triangles meet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Containment {
    /// Neither inside the other.
    None,
    /// Every component of A lies inside B.
    AInB,
    /// Every component of B lies inside A.
    BInA,
    /// Some components of A lie inside B, others outside.
    APartlyInB,
    /// Some components of B lie inside A, others outside.
    BPartlyInA,
    /// Surfaces only touch, but face-to-face contacts show the two solids share volume
    /// (duplicated parts, flush overlaps, touching a solid's wall from inside).
    VolumesOverlap,
    /// Could not decide, with the reason.
    Undecided(String),
}

impl Containment {
    /// Name in the report (`None` → null).
    pub fn name(&self) -> Option<&'static str> {
        Some(match self {
            Containment::None => return None,
            Containment::AInB => "a_in_b",
            Containment::BInA => "b_in_a",
            Containment::APartlyInB => "a_partly_in_b",
            Containment::BPartlyInA => "b_partly_in_a",
            Containment::VolumesOverlap => "volumes_overlap",
            Containment::Undecided(_) => "undecided",
        })
    }

    /// Is this an interference (a clash)?
    pub fn is_clash(&self) -> bool {
        !matches!(self, Containment::None | Containment::Undecided(_))
    }
}

/// One direction of [`decide`].
enum OneWay {
    /// (components inside, components in all).
    Counts(usize, usize),
    Undecided(String),
}

/// Which components of `inner` lie inside `outer`?
/// Could either input lie (partly) inside the other? Not when neither's tree box meets the
/// box of the other's vertices: then [`decide`] answers [`Containment::None`] whatever the
/// topology, so it need not be computed.
pub fn may_nest<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB) -> bool
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let (ba, bb) = (Aabb::of_points(a.positions().iter()), Aabb::of_points(b.positions().iter()));
    tb.root_box().overlaps(&ba) || ta.root_box().overlaps(&bb)
}

fn one_way<I, O, T>(
    inner: &I,
    it: &Topology,
    outer: &O,
    ot: &T,
    otopo: &Topology,
    name: &str,
    open: OpenInside,
) -> OneWay
where
    I: TriMesh + ?Sized,
    O: TriMesh + ?Sized,
    T: Tree + ?Sized,
{
    let n = it.component_seeds.len();
    if !otopo.closed && open == OpenInside::Skip {
        return OneWay::Counts(0, n);
    }
    let ib = Aabb::of_points(inner.positions().iter());
    if !ot.root_box().overlaps(&ib) {
        return OneWay::Counts(0, n);
    }
    if !otopo.closed {
        // Inside an open surface is undefined. Say so only where it could matter: the box
        // allows it and the generalized winding number (Jacobson et al. 2013) at a vertex of
        // the inner part says "mostly enclosed" (> 1/2; a lone sheet never exceeds 1/2).
        if ot.root_box().contains(&ib) {
            let p = inner.vertex(it.component_seeds[0]);
            let w = winding_number(p, outer);
            if w.abs() > 0.5 {
                return OneWay::Undecided(format!(
                    "{name} is not closed, so whether the other part lies inside it is undefined \
                     (winding number {w:.3} at a vertex of the other part)"
                ));
            }
        }
        return OneWay::Counts(0, n);
    }
    // One vertex per component decides, provided it is not on the other surface (surfaces may
    // touch); a component all of whose vertices lie on the other surface decides nothing here
    // (face-to-face overlaps are caught by orientation, see `coplanar_overlap`).
    let mut state = vec![None::<bool>; n];
    for (v, &c) in it.component_of.iter().enumerate() {
        if c == u32::MAX || state[c as usize].is_some() {
            continue;
        }
        let p = inner.vertex(v as u32);
        if on_surface(p, outer, ot) {
            continue;
        }
        match point_in_closed_mesh(p, outer, ot) {
            Inside::Yes => state[c as usize] = Some(true),
            Inside::No => state[c as usize] = Some(false),
            Inside::Undecided => {
                return OneWay::Undecided(format!("every ray from vertex {v} met an edge of {name} exactly"))
            }
        }
        if state.iter().all(Option::is_some) {
            break;
        }
    }
    OneWay::Counts(state.iter().filter(|s| **s == Some(true)).count(), n)
}

/// Whether [`decide`] looks into the inside of an open surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpenInside {
    /// Say where it is undefined and could matter ([`Containment::Undecided`], from the
    /// generalized winding number at a vertex of the other part).
    Explain,
    /// Not looked into (no winding number is computed): for a yes/no question it could only
    /// turn "no" into "undecided", which is no clash either. Every clash is the same.
    Skip,
}

/// Decide containment both ways for two meshes with no meeting triangles.
pub fn decide<A, TA, B, TB>(
    a: &A,
    ta: &TA,
    topo_a: &Topology,
    b: &B,
    tb: &TB,
    topo_b: &Topology,
    open: OpenInside,
) -> Containment
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let ab = one_way(a, topo_a, b, tb, topo_b, "b", open);
    let ba = one_way(b, topo_b, a, ta, topo_a, "a", open);
    match (ab, ba) {
        (OneWay::Counts(i, n), _) if i > 0 && i == n => Containment::AInB,
        (_, OneWay::Counts(i, n)) if i > 0 && i == n => Containment::BInA,
        (OneWay::Counts(i, _), _) if i > 0 => Containment::APartlyInB,
        (_, OneWay::Counts(i, _)) if i > 0 => Containment::BPartlyInA,
        (OneWay::Undecided(e), _) | (_, OneWay::Undecided(e)) => Containment::Undecided(e),
        _ => Containment::None,
    }
}

/// Does proper triangle `g` (not coplanar with proper triangle `t`, meeting it) lie on one side
/// of `t`'s plane and meet the *relative interior* of `t`? Then `Some(side)`: the sign of
/// `orient3d(t, ·)` at `g`'s vertices off the plane. Exact: the part of `g` in the plane (a
/// vertex or an edge) is tested against the open triangle by separating lines (`t`'s edge
/// lines and the edge's own line), all 2D orientation signs on one projection.
fn touches_interior_from(t: &[DVec3; 3], g: &[DVec3; 3]) -> Option<pr::Sign> {
    let s = g.map(|x| pr::orient3d(t[0], t[1], t[2], x));
    let side = if s.iter().all(|&v| v >= 0) {
        1
    } else if s.iter().all(|&v| v <= 0) {
        -1
    } else {
        return None; // `g` crosses the plane: the contact lies on `t`'s boundary
    };
    let on: Vec<DVec3> = (0..3).filter(|&k| s[k] == 0).map(|k| g[k]).collect();
    if on.is_empty() || on.len() == 3 {
        return None;
    }
    let k = pr::projection_axis(t[0], t[1], t[2])?;
    let sigma = pr::orient2d(t[0], t[1], t[2], k);
    let edge_separates =
        (0..3).any(|i| on.iter().all(|&x| pr::orient2d(t[i], t[(i + 1) % 3], x, k) * sigma <= 0));
    let line_separates = on.len() == 2 && {
        let o = t.map(|x| pr::orient2d(on[0], on[1], x, k));
        o.iter().all(|&v| v >= 0) || o.iter().all(|&v| v <= 0)
    };
    (!edge_separates && !line_separates).then_some(side)
}

/// One side of [`decide_touching`]: per component of `p`, whether some point of its surface off
/// `q`'s surface lies inside `q`, and whether some lies outside. `partners[t]`: the triangles
/// of `q` that share a point with triangle `t` of `p`; `covered[t]`: `t` has a face-to-face
/// contact with opposite interiors (its points off `q` are then outside: see
/// [`decide_touching`]).
fn surface_states<P, Q, TQ>(
    p: &P,
    ptopo: &Topology,
    q: &Q,
    tq: &TQ,
    partners: &[Vec<u32>],
    covered: &[bool],
    name: &str,
) -> Result<Vec<(bool, bool)>, String>
where
    P: TriMesh + ?Sized,
    Q: TriMesh + ?Sized,
    TQ: Tree + ?Sized,
{
    use crate::scene::bodies::{find, union};
    let n = p.triangle_count();
    let proper: Vec<bool> = (0..n).map(|t| !Shape::of(&p.triangle(t as u32)).is_degenerate()).collect();
    // Proper partners only: zero-area triangles are not part of the surface a ray crosses.
    let partners: Vec<Vec<[DVec3; 3]>> = partners
        .iter()
        .map(|g| g.iter().map(|&g| q.triangle(g)).filter(|g| !Shape::of(g).is_degenerate()).collect())
        .collect();
    // Triangles that meet no triangle of `q` are off its surface; any two of them that share a
    // vertex share its status (the vertex is off the surface). One test per such class.
    let distinct = ptopo.merged.iter().max().map_or(0, |&m| m as usize + 1);
    let mut parent: Vec<u32> = (0..distinct as u32).collect();
    for t in (0..n).filter(|&t| proper[t] && partners[t].is_empty()) {
        let v = p.indices(t as u32).map(|i| ptopo.merged[i as usize]);
        union(&mut parent, v[0], v[1]);
        union(&mut parent, v[1], v[2]);
    }
    let mut class_done = vec![false; distinct];
    let mut by_vertex: HashMap<u32, Inside> = HashMap::new();
    let mut states = vec![(false, false); ptopo.component_seeds.len()];
    for t in (0..n).filter(|&t| proper[t]) {
        let idx = p.indices(t as u32);
        let tri = p.triangle(t as u32);
        let status = if partners[t].is_empty() {
            let root = find(&mut parent, ptopo.merged[idx[0] as usize]) as usize;
            if std::mem::replace(&mut class_done[root], true) {
                continue;
            }
            *by_vertex
                .entry(ptopo.merged[idx[0] as usize])
                .or_insert_with(|| point_in_closed_mesh(tri[0], q, tq))
        } else if covered[t] {
            continue;
        } else {
            let on_q = |x: DVec3| partners[t].iter().any(|g| tri_tri::classify(&[x, x, x], g).is_some());
            match (0..3).find(|&k| !on_q(tri[k])) {
                Some(k) => *by_vertex
                    .entry(ptopo.merged[idx[k] as usize])
                    .or_insert_with(|| point_in_closed_mesh(tri[k], q, tq)),
                None => {
                    // Every vertex lies on `q`. Where `q`'s surface meets the triangle's interior
                    // it does so in segments and points (no face-to-face contact here), and no
                    // line holds three points of a parabola: of 2m + 1 points on one, inside
                    // the triangle, one is off the m partners' contacts.
                    let m = partners[t].len() as i64;
                    let steps = 2 * m + 2;
                    let point = (1..steps).map(|i| Weighted {
                        t: tri,
                        w: [(2 * steps - i) * (steps - i), 2 * steps * i, i * (steps - i)],
                    });
                    let Some(w) = point.clone().find(|w| !partners[t].iter().any(|g| w.on_triangle(g)))
                    else {
                        return Err(format!("no point of a triangle of {name} found off the other surface"));
                    };
                    let near = Aabb::of_triangle(&tri);
                    if !tq.root_box().overlaps(&near) {
                        Inside::No
                    } else {
                        parity(&w, near, q, tq)
                    }
                }
            }
        };
        let c = ptopo.component_of[idx[0] as usize] as usize;
        match status {
            Inside::Yes => states[c].0 = true,
            Inside::No => states[c].1 = true,
            Inside::Undecided => {
                return Err(format!("every ray from a point of a triangle of {name} met an edge exactly"))
            }
        }
    }
    Ok(states)
}

/// Containment of two closed parts whose surfaces meet but never cross (`contacts`: every pair
/// of triangles that shares a point, as (triangle of `a`, triangle of `b`, contact)), decided
/// exactly and independently of triangle order: do the interiors overlap?
///
/// They do iff (1) a face-to-face contact has both interiors on the same side
/// ([`coplanar_overlap`]), or (2) a triangle of one part meets the relative interior of a
/// triangle of the other from that triangle's inner side (points of it near the contact are
/// then inside the other solid), or (3) a point of one surface off the other lies strictly
/// inside it. When no pair crosses and (2) does not hold for triangle `t`, all points of `t`'s
/// relative interior off the other surface lie on one side of it: a path between two of them,
/// pushed slightly to the inner side of `t`, meets no triangle of the other part (one would
/// cross `t` or touch its interior from that side). So one point per triangle decides (3): a
/// vertex off the other surface, or an exact interior point found by [`Weighted`]; a triangle
/// that meets no other triangle shares its status with its neighbours, so one test per class of
/// such triangles. A triangle with a face-to-face contact of opposite interiors needs none: at
/// the boundary of the shared area the other surface turns away to the outer side (the inner
/// side is (2)), so its points off the other surface are outside. Conversely, if the interiors
/// overlap and no surface point of either lies inside the other, the overlap is a union of
/// components of both interiors: coinciding solids, which (1) finds.
///
/// `None` when an orientation is needed and cannot be computed (or a part is open): the caller
/// keeps the one-vertex-per-component answer of [`decide`].
#[allow(clippy::too_many_arguments)]
pub fn decide_touching<A, TA, B, TB>(
    a: &A,
    ta: &TA,
    topo_a: &Topology,
    b: &B,
    tb: &TB,
    topo_b: &Topology,
    contacts: &[(u32, u32, Contact)],
) -> Option<Containment>
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    if !topo_a.closed || !topo_b.closed {
        return None;
    }
    let proper = |t: &[DVec3; 3]| !Shape::of(t).is_degenerate();
    // (2)'s candidates: (triangle, side its partner lies on), each way.
    let (mut into_a, mut into_b) = (Vec::new(), Vec::new());
    let mut coplanar = false;
    for &(i, j, c) in contacts {
        match c {
            Contact::CoplanarArea => coplanar = true,
            Contact::CoplanarBoundary => {}
            Contact::Point | Contact::Segment => {
                let (ti, tj) = (a.triangle(i), b.triangle(j));
                if proper(&ti) && proper(&tj) {
                    into_a.extend(touches_interior_from(&ti, &tj).map(|s| (i, s)));
                    into_b.extend(touches_interior_from(&tj, &ti).map(|s| (j, s)));
                }
            }
        }
    }
    let (mut covered_a, mut covered_b) = (vec![false; a.triangle_count()], vec![false; b.triangle_count()]);
    if coplanar || !into_a.is_empty() || !into_b.is_empty() {
        let (oa, ob) = rayon::join(|| outward(a, topo_a), || outward(b, topo_b));
        let (oa, ob) = (oa?, ob?);
        for &(i, j, _) in contacts.iter().filter(|x| x.2 == Contact::CoplanarArea) {
            if coplanar_overlap(&a.triangle(i), oa[i as usize], &b.triangle(j), ob[j as usize]) {
                return Some(Containment::VolumesOverlap);
            }
            covered_a[i as usize] = true;
            covered_b[j as usize] = true;
        }
        // The inner side of a triangle is opposite its outward normal: orient3d sign times
        // the outward flag is negative there.
        let inward = |v: &[(u32, pr::Sign)], o: &[i8]| v.iter().any(|&(t, s)| s * o[t as usize] < 0);
        if inward(&into_a, &oa) || inward(&into_b, &ob) {
            return Some(Containment::VolumesOverlap);
        }
    }
    let mut partners_a = vec![Vec::new(); a.triangle_count()];
    let mut partners_b = vec![Vec::new(); b.triangle_count()];
    for &(i, j, _) in contacts {
        partners_a[i as usize].push(j);
        partners_b[j as usize].push(i);
    }
    let (sa, sb) = rayon::join(
        || surface_states(a, topo_a, b, tb, &partners_a, &covered_a, "a"),
        || surface_states(b, topo_b, a, ta, &partners_b, &covered_b, "b"),
    );
    let (sa, sb) = match (sa, sb) {
        (Ok(x), Ok(y)) => (x, y),
        (Err(e), _) | (_, Err(e)) => return Some(Containment::Undecided(e)),
    };
    // A component with points both inside and outside the other: the surfaces pass through
    // each other along shared edges.
    if sa.iter().chain(&sb).any(|&(i, o)| i && o) {
        return Some(Containment::VolumesOverlap);
    }
    let inside = |s: &[(bool, bool)]| (s.iter().filter(|x| x.0).count(), s.len());
    Some(match (inside(&sa), inside(&sb)) {
        ((i, n), _) if i > 0 && i == n => Containment::AInB,
        (_, (i, n)) if i > 0 && i == n => Containment::BInA,
        ((i, _), _) if i > 0 => Containment::APartlyInB,
        (_, (i, _)) if i > 0 => Containment::BPartlyInA,
        _ => Containment::None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, Bvh};
    use crate::scene::mesh::{Mesh, Object};

    /// An axis-aligned box as 12 triangles, outward-facing.
    pub(crate) fn cube(min: DVec3, max: DVec3) -> Mesh {
        let p = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        };
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut triangles = Vec::new();
        for q in quads {
            triangles.push([q[0], q[1], q[2]]);
            triangles.push([q[0], q[2], q[3]]);
        }
        Mesh {
            positions: (0..8).map(p).collect(),
            triangles,
            tri_object: vec![0; 12],
            objects: vec![Object { name: "cube".into(), ..Default::default() }],
        }
    }

    fn inside(p: DVec3, m: &Mesh) -> Inside {
        point_in_closed_mesh(p, m, &Bvh::build(m, BuildOptions::default()))
    }

    /// [`topology`] against a brute-force reading of its definition on random small meshes
    /// with coincident vertices (±0 included), zero-area triangles (repeated and collinear
    /// vertices) and unused vertices.
    #[test]
    fn topology_equals_a_brute_force_oracle() {
        use std::collections::BTreeMap;
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let grid = [-0.0, 0.0, 1.0, 2.0, 0.5];
        for case in 0..2000 {
            let nv = 3 + next(12) as usize;
            let positions: Vec<DVec3> = (0..nv)
                .map(|_| DVec3::new(grid[next(5) as usize], grid[next(5) as usize], grid[next(3) as usize]))
                .collect();
            let nt = 1 + next(14) as usize;
            let triangles: Vec<[u32; 3]> =
                (0..nt).map(|_| [0; 3].map(|_| next(nv as u64 - (case % 2)) as u32)).collect();
            let mesh = Mesh {
                positions: positions.clone(),
                tri_object: vec![0; nt],
                triangles: triangles.clone(),
                objects: vec![Object { name: "m".into(), ..Default::default() }],
            };
            let got = topology(&mesh);
            // Merged ids in order of first occurrence, by comparing every earlier position.
            let key = |p: DVec3| [p.x + 0.0, p.y + 0.0, p.z + 0.0];
            let mut merged = vec![0u32; nv];
            let mut distinct = 0;
            for i in 0..nv {
                merged[i] = match (0..i).find(|&j| key(positions[j]) == key(positions[i])) {
                    Some(j) => merged[j],
                    None => {
                        distinct += 1;
                        distinct - 1
                    }
                };
            }
            assert_eq!(got.merged, merged);
            let mut uses: BTreeMap<(u32, u32), usize> = BTreeMap::new();
            for t in &triangles {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                if pr::collinear(a, b, c) {
                    continue;
                }
                let v = t.map(|i| merged[i as usize]);
                for k in 0..3 {
                    let (x, y) = (v[k], v[(k + 1) % 3]);
                    *uses.entry((x.min(y), x.max(y))).or_default() += 1;
                }
            }
            assert_eq!(got.closed, !uses.is_empty() && uses.values().all(|&u| u == 2), "case {case}");
            // Components: flood over shared merged ids, numbered by first triangle.
            let mut comp_of_id = vec![u32::MAX; distinct as usize];
            let mut seeds = Vec::new();
            for t in &triangles {
                let v = t.map(|i| merged[i as usize]);
                if comp_of_id[v[0] as usize] != u32::MAX {
                    continue;
                }
                let c = seeds.len() as u32;
                seeds.push(t[0]);
                comp_of_id[v[0] as usize] = c;
                let mut grew = true;
                while grew {
                    grew = false;
                    for u in &triangles {
                        let w = u.map(|i| merged[i as usize]);
                        if w.iter().any(|&x| comp_of_id[x as usize] == c)
                            && w.iter().any(|&x| comp_of_id[x as usize] != c)
                        {
                            w.iter().for_each(|&x| comp_of_id[x as usize] = c);
                            grew = true;
                        }
                    }
                }
            }
            assert_eq!(got.component_seeds, seeds, "case {case}");
            let used = |v: usize| triangles.iter().any(|t| t.contains(&(v as u32)));
            let want: Vec<u32> =
                (0..nv).map(|v| if used(v) { comp_of_id[merged[v] as usize] } else { u32::MAX }).collect();
            assert_eq!(got.component_of, want, "case {case}");
        }
    }

    #[test]
    fn cube_is_closed_and_one_component() {
        let c = cube(DVec3::ZERO, DVec3::ONE);
        let t = topology(&c);
        assert!(t.closed);
        assert_eq!(t.component_seeds.len(), 1);
        let mut open = c.clone();
        open.triangles.pop();
        open.tri_object.pop();
        assert!(!topology(&open).closed);
    }

    #[test]
    fn points_inside_outside_and_on_axis_aligned_edges_lines() {
        let c = cube(DVec3::ZERO, DVec3::ONE);
        assert_eq!(inside(DVec3::splat(0.5), &c), Inside::Yes);
        assert_eq!(inside(DVec3::new(0.5, 0.5, 1.5), &c), Inside::No);
        assert_eq!(inside(DVec3::new(-0.5, 0.5, 0.5), &c), Inside::No);
        // On the line of a face diagonal (rays along +x from here would hit the diagonal edge).
        assert_eq!(inside(DVec3::new(0.25, 0.25, 0.25), &c), Inside::Yes);
        assert_eq!(inside(DVec3::new(0.5, 0.0 + 1e-300, 0.5), &c), Inside::Yes);
        // Far from the origin.
        let f = cube(DVec3::splat(1e8), DVec3::splat(1e8 + 1.0));
        assert_eq!(inside(DVec3::splat(1e8 + 0.5), &f), Inside::Yes);
    }

    /// Weighted points whose value is a short binary fraction (so the f64 point is exact) get
    /// the answers of the f64 point: on a triangle or not, and inside the cube or not.
    #[test]
    fn weighted_points_agree_with_their_exact_f64_value() {
        let c = cube(DVec3::ZERO, DVec3::ONE);
        let tree = Bvh::build(&c, BuildOptions::default());
        let tris = [
            [DVec3::new(-0.5, 0.25, 0.5), DVec3::new(1.5, 0.25, 0.5), DVec3::new(0.5, 0.25, 1.5)],
            [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)],
            [DVec3::new(0.5, -1.0, 0.25), DVec3::new(0.5, 2.0, 0.75), DVec3::new(0.5, 0.5, 3.0)],
        ];
        for t in tris {
            for w in [[1, 1, 2], [2, 1, 1], [1, 2, 1], [5, 2, 1], [1, 1, 6], [3, 4, 1]] {
                let sum = (w[0] + w[1] + w[2]) as f64;
                let p = (t[0] * w[0] as f64 + t[1] * w[1] as f64 + t[2] * w[2] as f64) / sum;
                let x = Weighted { t, w };
                for g in (0..12).map(|k| c.triangle(k)) {
                    let on = crate::narrow::tri_tri::classify(&[p, p, p], &g).is_some();
                    assert_eq!(x.on_triangle(&g), on, "{t:?} {w:?} {g:?}");
                }
                if !on_surface(p, &c, &tree) {
                    assert_eq!(parity(&x, Aabb::of_triangle(&t), &c, &tree), inside(p, &c), "{t:?} {w:?}");
                }
            }
        }
    }

    #[test]
    fn box_in_box_both_ways() {
        let outer = cube(DVec3::ZERO, DVec3::splat(10.0));
        let inner = cube(DVec3::splat(4.0), DVec3::splat(5.0));
        let (to, ti) =
            (Bvh::build(&outer, BuildOptions::default()), Bvh::build(&inner, BuildOptions::default()));
        let (po, pi) = (topology(&outer), topology(&inner));
        let explain = OpenInside::Explain;
        assert_eq!(decide(&inner, &ti, &pi, &outer, &to, &po, explain), Containment::AInB);
        assert_eq!(decide(&outer, &to, &po, &inner, &ti, &pi, explain), Containment::BInA);
        let apart = cube(DVec3::splat(20.0), DVec3::splat(21.0));
        let ta = Bvh::build(&apart, BuildOptions::default());
        assert_eq!(decide(&apart, &ta, &topology(&apart), &outer, &to, &po, explain), Containment::None);
    }

    /// The yes/no containment equals the full one wherever either is a clash; it differs only
    /// where an open surface's inside is undefined (no clash either way): a small cube in a big
    /// one, in a big one with one face removed (open), and apart from both, every order.
    #[test]
    fn clash_only_containment_agrees_with_the_full_one() {
        let mut open = cube(DVec3::ZERO, DVec3::splat(10.0));
        open.triangles.truncate(10);
        open.tri_object.truncate(10);
        let meshes = [
            cube(DVec3::ZERO, DVec3::splat(10.0)),
            open,
            cube(DVec3::splat(4.0), DVec3::splat(5.0)),
            cube(DVec3::splat(20.0), DVec3::splat(21.0)),
        ];
        let built: Vec<_> =
            meshes.iter().map(|m| (m, Bvh::build(m, BuildOptions::default()), topology(m))).collect();
        let mut undefined = 0;
        for (a, ta, pa) in &built {
            for (b, tb, pb) in &built {
                let full = decide(*a, ta, pa, *b, tb, pb, OpenInside::Explain);
                let clash = decide(*a, ta, pa, *b, tb, pb, OpenInside::Skip);
                if full.is_clash() || clash.is_clash() {
                    assert_eq!(full, clash);
                } else if full != clash {
                    assert!(
                        matches!(full, Containment::Undecided(ref e) if e.contains("not closed")),
                        "{full:?}"
                    );
                    assert_eq!(clash, Containment::None);
                    undefined += 1;
                }
            }
        }
        // The small cube in the open box, both orders.
        assert_eq!(undefined, 2);
    }
}
