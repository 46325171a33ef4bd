//! Self-clash: the triangle pairs of one part that meet anywhere the mesh connectivity does not
//! say they meet.
//!
//! # The rule
//!
//! Vertices are identified by exact position first (bit-identical coordinates, +0 = −0:
//! [`crate::scene::bodies::merge_vertices`]). Two triangles `s` and `t` of one part *share* the merged
//! vertices they both use; connectivity says they meet in `H`, the convex hull of those shared
//! vertices (nothing, a vertex, an edge, or — three shared vertices — the whole face). Since both
//! closed triangles contain `H`, their intersection `I` always contains it; the pair is a
//! **self-clash iff `I ≠ H`**, decided exactly:
//!
//! * **Nothing shared**: any contact at all ([`crate::narrow::tri_tri::classify`]).
//! * **One shared vertex `v`**, `s = conv(v, a, b)`, `t = conv(v, c, d)`: every point `p ≠ v` of
//!   `s` lies on a ray from `v` that leaves `s` through the opposite segment `[a, b]`, and the same
//!   holds for `t` and `[c, d]`. If `p ∈ I`, the nearer of the two exit points lies in both
//!   triangles. Hence `I ≠ {v}` iff `[a, b]` meets `t` or `[c, d]` meets `s` — two exact
//!   segment–triangle tests. (A zero-area `s` whose opposite segment contains `v` in its interior
//!   is the union of the segments `[v, a]` and `[v, b]`, each tested the same way.)
//! * **One shared edge `[u, w]`**, third vertices `a` of `s` and `b` of `t`:
//!   - both proper (non-zero area) and not coplanar: `I` lies on the planes' common line, which
//!     meets `s` only in `[u, w]`: no clash;
//!   - both proper and coplanar: a fold iff `a` and `b` lie on the same side of the line `uw`
//!     in the plane (exact `orient2d` on the plane's projection): the interiors overlap along the
//!     whole edge;
//!   - one proper, one zero-area: the zero-area one lies on the line `uw`, which meets the proper
//!     one only in `[u, w]`: no clash;
//!   - both zero-area (all five points on one line): a clash iff `a` and `b` both extend beyond
//!     the same end of `[u, w]`.
//! * **All three vertices shared** (the same face stored twice, in either winding): never a
//!   self-clash pair; such faces are reported by [`crate::check::health`] as duplicates.
//!
//! A triangle whose indices repeat a merged vertex has fewer distinct vertices (a segment or a
//! point), and the rule applies with those. A pair that is a self-clash is then classified like
//! any pair of a two-mesh check (crossing or touching, and the contact shape) from the two whole
//! triangles, so the vocabulary is the same.
//!
//! # The walk
//!
//! One tree per part is walked against itself: a node is paired with itself once (its two
//! children each with themselves, and the two children with each other), and two different
//! nodes as in a dual-tree walk, so each unordered leaf pair is visited once and each unordered
//! triangle pair is tested once. As in [`crate::bvh::traverse`], the root is expanded
//! breadth-first into a fixed number of independent sub-walks, and the result is sorted, so
//! the answer does not depend on the thread count.
//!
//! The tree ([`tree`]) orders the triangles along a Morton curve and splits at the highest
//! differing bit of their codes: a few linear passes instead of a binned-SAH build, which buys
//! little on a surface walked against itself. Its boxes are f32, rounded outward (they contain
//! the exact boxes), and a leaf's triangles are one run of a 40-byte-per-triangle array (box,
//! vertex numbers, position); corners are read from the mesh only for pairs that get a test.
//!
//! On a surface, almost every pair whose boxes overlap is a pair of neighbours around a vertex.
//! Those are settled a whole vertex fan at a time where one exact argument covers the fan
//! ([`certified_fans`]: projected along an axis, the fan's triangles tile the turn around the
//! vertex once); the walk skips every pair sharing a certified vertex. The other pairs get the
//! pair test ([`classify_adjacent`] behind float filters that only skip work).

use crate::bvh::BuildOptions;
use crate::check::fans::Fans;
use crate::geom::predicates::{self as pr, PlaneFilter};
use crate::geom::{Aabb, DVec3};
use crate::narrow::tri_tri::{self, Hit};
use crate::scene::mesh::Mesh;
use rayon::prelude::*;
use std::ops::Range;
use tree::{FBox, SNode};

/// How many independent sub-walks the root is split into (fixed, for determinism).
const SEED_TASKS: usize = 256;

/// A self-clashing pair of triangles, `a < b` (indices into the mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfPair {
    /// The lower triangle index.
    pub a: u32,
    /// The higher triangle index.
    pub b: u32,
    /// How they meet (from the two whole triangles).
    pub hit: Hit,
}

/// The distinct merged vertices of a triangle, with their positions (1 to 3 of them).
fn distinct(tri: &[DVec3; 3], ids: [u32; 3]) -> ([(u32, DVec3); 3], usize) {
    let mut out = [(ids[0], tri[0]); 3];
    let mut n = 1;
    for k in 1..3 {
        if !out[..n].iter().any(|&(i, _)| i == ids[k]) {
            out[n] = (ids[k], tri[k]);
            n += 1;
        }
    }
    (out, n)
}

/// Exact: is `v` strictly between `a` and `b` on their common line (`a ≠ b`)?
fn strictly_between(v: DVec3, a: DVec3, b: DVec3) -> bool {
    if !pr::collinear(v, a, b) {
        return false;
    }
    // On a line, the order along any axis on which `a` and `b` differ is the order on the line.
    let k = (0..3).find(|&k| a[k] != b[k]).expect("a != b");
    let (lo, hi) = if a[k] < b[k] { (a[k], b[k]) } else { (b[k], a[k]) };
    lo < v[k] && v[k] < hi
}

/// Exact: does the segment `[p, q]` (possibly a point) meet the closed triangle `t`?
fn segment_meets(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> bool {
    tri_tri::classify(&[p, q, q], t).is_some()
}

/// Exact, for `s = conv(v, oa)` and `t = conv(v, ob)` (`oa`, `ob`: the other distinct vertices,
/// 0 to 2 each, all different from `v`): do they meet anywhere but `v`? See the module docs.
fn meets_beyond_vertex(v: DVec3, oa: &[DVec3], ob: &[DVec3]) -> bool {
    if oa.is_empty() || ob.is_empty() {
        return false; // one of them is the point v
    }
    if let [a1, a2] = *oa {
        if strictly_between(v, a1, a2) {
            return meets_beyond_vertex(v, &[a1], ob) || meets_beyond_vertex(v, &[a2], ob);
        }
    }
    if let [b1, b2] = *ob {
        if strictly_between(v, b1, b2) {
            return meets_beyond_vertex(v, oa, &[b1]) || meets_beyond_vertex(v, oa, &[b2]);
        }
    }
    let tri = |o: &[DVec3]| [v, o[0], o[o.len() - 1]];
    segment_meets(oa[0], oa[oa.len() - 1], &tri(ob)) || segment_meets(ob[0], ob[ob.len() - 1], &tri(oa))
}

/// Exact, for `s = conv(u, w, a)` and `t = conv(u, w, b)` with `u, w, a, b` four different
/// points: do they meet anywhere but the segment `[u, w]`? See the module docs.
fn meets_beyond_edge(u: DVec3, w: DVec3, a: DVec3, b: DVec3) -> bool {
    let (pa, pb) = (!pr::collinear(u, w, a), !pr::collinear(u, w, b));
    match (pa, pb) {
        (true, true) => {
            if pr::orient3d(u, w, a, b) != 0 {
                return false;
            }
            let axis = pr::projection_axis(u, w, a).expect("proper triangle");
            pr::orient2d(u, w, a, axis) == pr::orient2d(u, w, b, axis)
        }
        (false, false) => {
            let k = (0..3).find(|&k| u[k] != w[k]).expect("u != w");
            let (lo, hi) = if u[k] < w[k] { (u[k], w[k]) } else { (w[k], u[k]) };
            (a[k] > hi && b[k] > hi) || (a[k] < lo && b[k] < lo)
        }
        _ => false,
    }
}

/// Classify a pair of triangles of one part with its connectivity: `ia`, `ib` are the merged
/// (exact-position) vertex ids of `ta`, `tb`. `None` unless they meet beyond what they share
/// (see the module docs); then the classification of the whole pair.
pub fn classify_adjacent(ta: &[DVec3; 3], ia: [u32; 3], tb: &[DVec3; 3], ib: [u32; 3]) -> Option<Hit> {
    classify_adjacent_with(ta, ia, tb, ib, None)
}

/// [`classify_adjacent`], given the plane filter of one of the two triangles when the caller
/// already has it (`(true, f)`: `f` is `ta`'s; `(false, f)`: `tb`'s), so that a triangle tested
/// against several others builds its filter once.
fn classify_adjacent_with(
    ta: &[DVec3; 3],
    ia: [u32; 3],
    tb: &[DVec3; 3],
    ib: [u32; 3],
    known: Option<(bool, &PlaneFilter)>,
) -> Option<Hit> {
    // Ids first (cheap); positions are gathered only for the pairs the filters cannot settle.
    let distinct_count = |i: [u32; 3]| 1 + (i[1] != i[0]) as usize + (i[2] != i[0] && i[2] != i[1]) as usize;
    let (na, nb) = (distinct_count(ia), distinct_count(ib));
    let shared = (0..3).filter(|&k| ib.contains(&ia[k]) && !ia[..k].contains(&ia[k])).count();
    if shared == 0 {
        return tri_tri::classify(ta, tb);
    }
    if shared == 3 || (shared == 2 && (na < 3 || nb < 3)) {
        // All three shared (a duplicate face), or two shared and one triangle is just that
        // segment: the intersection is exactly what is shared.
        return None;
    }
    // Float filters: a triangle whose unshared vertices the other's plane filter proves strictly
    // on one side meets that plane only in what is shared, so the pair is fine. Proven signs
    // are exact, so this only skips work, never changes an answer.
    let off_plane = |f: &PlaneFilter, t: &[DVec3; 3], own: [u32; 3], other: [u32; 3]| {
        let mut side = 0;
        for k in 0..3 {
            if !other.contains(&own[k]) {
                match f.side(t[k]) {
                    Some(s) if s != 0 && (side == 0 || side == s) => side = s,
                    _ => return false,
                }
            }
        }
        side != 0
    };
    let settled = match known {
        Some((true, fa)) => off_plane(fa, tb, ib, ia) || off_plane(&PlaneFilter::new(tb), ta, ia, ib),
        Some((false, fb)) => off_plane(fb, ta, ia, ib) || off_plane(&PlaneFilter::new(ta), tb, ib, ia),
        None => off_plane(&PlaneFilter::new(ta), tb, ib, ia) || off_plane(&PlaneFilter::new(tb), ta, ia, ib),
    };
    if settled {
        return None;
    }
    let (da, na) = distinct(ta, ia);
    let (db, nb) = distinct(tb, ib);
    let (da, db) = (&da[..na], &db[..nb]);
    let in_b = |id: u32| db.iter().any(|&(j, _)| j == id);
    let beyond = match shared {
        1 => {
            let v = da.iter().find(|&&(i, _)| in_b(i)).unwrap();
            let others = |d: &[(u32, DVec3)]| -> ([DVec3; 2], usize) {
                let mut o = [DVec3::ZERO; 2];
                let mut n = 0;
                for &(i, p) in d {
                    if i != v.0 {
                        o[n] = p;
                        n += 1;
                    }
                }
                (o, n)
            };
            let ((oa, ka), (ob, kb)) = (others(da), others(db));
            meets_beyond_vertex(v.1, &oa[..ka], &ob[..kb])
        }
        _ => {
            let shared: Vec<DVec3> = da.iter().filter(|&&(i, _)| in_b(i)).map(|x| x.1).collect();
            let a = da.iter().find(|&&(i, _)| !in_b(i)).unwrap().1;
            let b = db.iter().find(|&&(j, _)| !da.iter().any(|&(i, _)| i == j)).unwrap().1;
            meets_beyond_edge(shared[0], shared[1], a, b)
        }
    };
    if beyond {
        tri_tri::classify(ta, tb)
    } else {
        None
    }
}

/// One triangle as the walk reads it, in curve order (see [`self_pairs_with`]): 40 bytes.
#[derive(Debug, Clone, Copy)]
struct Slot {
    /// A box around it (f32, rounded outward).
    b: FBox,
    /// Its vertex numbers ([`Fans::ids`]: equal iff the merged ids are).
    ids: [u32; 3],
    /// Its position in the part.
    k: u32,
}

impl tree::Item for Slot {
    #[inline]
    fn bounds(&self) -> FBox {
        self.b
    }
    #[inline]
    fn id(&self) -> u32 {
        self.k
    }
}

/// One triangle as a pair test reads it (gathered from the mesh for the pairs that need one).
#[derive(Debug, Clone, Copy)]
struct Tri {
    /// Its corners.
    p: [DVec3; 3],
    /// Their vertex numbers.
    ids: [u32; 3],
    /// Its index in the mesh.
    t: u32,
}

/// `Some(s)` when `s` is a proven non-zero sign.
#[inline]
fn strict(s: Option<pr::Sign>) -> Option<pr::Sign> {
    s.filter(|&s| s != 0)
}

/// Exact, for a proper triangle `s = (v, a, b)` (in its own winding, rotated so that `v` comes
/// first) and a triangle `t = (v, c, d)` whose `c` and `d` lie strictly on opposite sides of
/// `s`'s plane, `c` on side `side_c` (`orient3d(v, a, b, c)`): do `s` and `t` meet anywhere
/// but `v`?
///
/// `t` meets the plane of `s` in the segment `[v, p]`, `p` the point where `[c, d]` crosses it,
/// so `s ∩ t = s ∩ [v, p]`: more than `v` iff `p - v` points into the angle of `s` at `v`, i.e.
/// `p` lies on the inner side (or on) the lines `va` and `bv` and is not `v` itself. For a
/// segment `cd` crossing the plane, `orient3d(c, d, x, y)` has the sign of `p`'s side of the
/// line `xy` in that plane times `-side_c` (the three signs of the classic segment–triangle
/// test); `p = v` (both zero) only when `t` is a segment through `v`, which meets `s` in `v`
/// alone.
fn meets_beyond_vertex_crossing(v: DVec3, a: DVec3, b: DVec3, c: DVec3, d: DVec3, side_c: pr::Sign) -> bool {
    let inner = -side_c;
    let (o1, o2) = (pr::orient3d(c, d, v, a), pr::orient3d(c, d, b, v));
    o1 != -inner && o2 != -inner && (o1 != 0 || o2 != 0)
}

/// The self-clash test of one pair of slots whose boxes overlap, `fx` the plane filter of `x`
/// (built once per `x` and reused against every `y` it meets) and `mx` the corners of `x` that
/// are corners of `y` ([`shared_mask`]): the pair, lower triangle first, when it is one.
///
/// Fast paths for the pairs a surface is made of (every box overlaps its neighbours'), when
/// both triangles have three distinct ids: sharing two (an edge), they are apart beyond it
/// when the filter proves the unshared vertex of one off the other's plane; sharing one (a
/// vertex `v`), when it proves the two unshared vertices of one strictly on one side of the
/// other's plane, and when it proves them strictly on opposite sides, two exact orientations
/// decide it ([`meets_beyond_vertex_crossing`]). Proven signs are exact, so these give the
/// answer of [`classify_adjacent`]; everything else goes to it.
#[inline(never)]
fn test_pair(x: &Tri, fx: &PlaneFilter, y: &Tri, mx: usize) -> Option<SelfPair> {
    let (xi, yi) = (x.ids, y.ids);
    let distinct = |i: [u32; 3]| (i[0] != i[1]) & (i[1] != i[2]) & (i[0] != i[2]);
    let my = shared_mask(yi, xi);
    let beyond = if !(distinct(xi) & distinct(yi)) {
        None
    } else {
        match mx {
            // Nothing shared: any contact; none when `y` is strictly on one side of `x`'s plane.
            0 => Some(!one_side(fx, &y.p)),
            // The same face twice: a duplicate, not a pair.
            7 => Some(false),
            3 | 5 | 6 => {
                // An edge: the unshared corner of each against the other's plane.
                let (kx, ky) = (UNSHARED[mx], UNSHARED[my]);
                let apart = strict(fx.side(y.p[ky])).is_some()
                    || strict(PlaneFilter::new(&y.p).side(x.p[kx])).is_some();
                apart.then_some(false)
            }
            // A vertex.
            _ => {
                let (kx, ky) = (SHARED[mx], SHARED[my]);
                match vertex_sides(fx, x, kx, y, ky) {
                    Some(r) => Some(r),
                    None => vertex_sides(&PlaneFilter::new(&y.p), y, ky, x, kx),
                }
            }
        }
    };
    let (lo, hi) = if x.t < y.t { (x, y) } else { (y, x) };
    let hit = match beyond {
        Some(false) => return None,
        Some(true) => tri_tri::classify(&lo.p, &hi.p),
        None => classify_adjacent_with(&lo.p, lo.ids, &hi.p, hi.ids, None),
    };
    hit.map(|hit| SelfPair { a: lo.t, b: hi.t, hit })
}

/// Bit `k` set when corner `k` of `i` is a corner of `o` (by vertex number).
#[inline(always)]
fn shared_mask(i: [u32; 3], o: [u32; 3]) -> usize {
    let has = |v: u32| ((v == o[0]) | (v == o[1]) | (v == o[2])) as usize;
    has(i[0]) | has(i[1]) << 1 | has(i[2]) << 2
}

/// For a mask with one bit set: that corner.
const SHARED: [usize; 8] = [0, 0, 1, 0, 2, 0, 0, 0];
/// For a mask with two bits set: the corner not set.
const UNSHARED: [usize; 8] = [0, 0, 0, 2, 0, 1, 0, 0];
/// For a mask with two bits set: those two corners.
const SHARED_PAIR: [(usize, usize); 8] = [(0, 0), (0, 0), (0, 0), (0, 1), (0, 0), (0, 2), (1, 2), (0, 0)];
/// The corner after (in the winding) each corner.
const NEXT: [usize; 3] = [1, 2, 0];

/// True if filter `f` proves the three points strictly on one side of its plane.
#[inline]
fn one_side(f: &PlaneFilter, p: &[DVec3; 3]) -> bool {
    match (f.side(p[0]), f.side(p[1]), f.side(p[2])) {
        (Some(a), Some(b), Some(c)) => a != 0 && a == b && a == c,
        _ => false,
    }
}

/// For `s` (filter `f`) and `t` sharing only their corners `ks` and `kt` (the vertex `v`), `s`
/// and `t` read from `v` in their own winding as `(v, a, b)` and `(v, c, d)`: whether they
/// meet beyond `v`, when the filter's signs for `c` and `d` settle it (both strictly on one
/// side: no; strictly on opposite sides: [`meets_beyond_vertex_crossing`]).
#[inline]
fn vertex_sides(f: &PlaneFilter, s: &Tri, ks: usize, t: &Tri, kt: usize) -> Option<bool> {
    let (c, d) = (t.p[NEXT[kt]], t.p[NEXT[NEXT[kt]]]);
    let (sc, sd) = (strict(f.side(c))?, strict(f.side(d))?);
    if sc == sd {
        return Some(false);
    }
    let (v, a, b) = (s.p[ks], s.p[NEXT[ks]], s.p[NEXT[NEXT[ks]]]);
    Some(meets_beyond_vertex_crossing(v, a, b, c, d, sc))
}

/// The box of a triangle by plain comparisons (coordinates are finite).
#[inline(always)]
fn tri_box(p: &[DVec3; 3]) -> Aabb {
    let lo = |a: f64, b: f64| if b < a { b } else { a };
    let hi = |a: f64, b: f64| if b > a { b } else { a };
    let [a, b, c] = p;
    Aabb {
        min: DVec3::new(lo(lo(a.x, b.x), c.x), lo(lo(a.y, b.y), c.y), lo(lo(a.z, b.z), c.z)),
        max: DVec3::new(hi(hi(a.x, b.x), c.x), hi(hi(a.y, b.y), c.y), hi(hi(a.z, b.z), c.z)),
    }
}

/// Does the closed box of triangle `p` meet the closed box `b`? (It misses it iff all three
/// corners are beyond one face of `b`.)
#[inline(always)]
fn tri_meets_box(p: &[DVec3; 3], b: &Aabb) -> bool {
    let [u, v, w] = p;
    let out = (u.x < b.min.x) & (v.x < b.min.x) & (w.x < b.min.x)
        | (u.x > b.max.x) & (v.x > b.max.x) & (w.x > b.max.x)
        | (u.y < b.min.y) & (v.y < b.min.y) & (w.y < b.min.y)
        | (u.y > b.max.y) & (v.y > b.max.y) & (w.y > b.max.y)
        | (u.z < b.min.z) & (v.z < b.min.z) & (w.z < b.min.z)
        | (u.z > b.max.z) & (v.z > b.max.z) & (w.z > b.max.z);
    !out
}

/// Walk a tree (`nodes` in [`crate::bvh::Bvh`]'s layout) against itself: `leaf_self` gets each
/// leaf once, `leaf_pair` each unordered pair of different leaves whose boxes meet (closed
/// boxes) once, each leaf as its range of positions (`a .. a + count`). Results come back in an order that depends only on the tree.
///
/// `settled(i, j)` (`i == j` for a node with itself) says that no pair of triangles under
/// nodes `i` and `j` is a self-clash: that node pair is not opened.
fn self_walk<Z, S, P>(nodes: &[SNode], cap: usize, settled: Z, leaf_self: S, leaf_pair: P) -> Found
where
    Z: Fn(u32, u32) -> bool + Sync,
    S: Fn(Range<usize>, &mut Found) + Sync,
    P: Fn(Range<usize>, Range<usize>, &mut Found) + Sync,
{
    let range = |n: &SNode| n.a as usize..(n.a + n.count) as usize;
    #[derive(Clone, Copy)]
    enum Job {
        Node(u32),
        Pair(u32, u32),
    }
    if nodes.is_empty() {
        return Found::new(cap);
    }
    let meet = |i: u32, j: u32| nodes[i as usize].b.meets(&nodes[j as usize].b);
    // Expand one job; leaf work goes to `out`, new jobs to `jobs`.
    let step = |job: Job, out: &mut Found, jobs: &mut Vec<Job>| match job {
        Job::Node(i) if settled(i, i) => {}
        Job::Pair(i, j) if settled(i, j) => {}
        Job::Node(i) => {
            let n = &nodes[i as usize];
            if n.is_leaf() {
                leaf_self(range(n), out);
            } else {
                jobs.push(Job::Node(i + 1));
                jobs.push(Job::Node(n.a));
                if meet(i + 1, n.a) {
                    jobs.push(Job::Pair(i + 1, n.a));
                }
            }
        }
        Job::Pair(i, j) => {
            let (a, b) = (&nodes[i as usize], &nodes[j as usize]);
            let open_a = match (a.is_leaf(), b.is_leaf()) {
                (true, true) => {
                    leaf_pair(range(a), range(b), out);
                    return;
                }
                (true, false) => false,
                (false, true) => true,
                (false, false) => a.b.half_area() >= b.b.half_area(),
            };
            let kids = if open_a { [(i + 1, j), (a.a, j)] } else { [(i, j + 1), (i, b.a)] };
            for (x, y) in kids {
                if meet(x, y) {
                    jobs.push(Job::Pair(x, y));
                }
            }
        }
    };
    // Breadth-first seeding: leaf work met on the way is done here, in order.
    let mut early = Found::new(cap);
    let mut level = vec![Job::Node(0)];
    while !level.is_empty() && level.len() < SEED_TASKS {
        let mut next = Vec::with_capacity(level.len() * 3);
        for &job in &level {
            step(job, &mut early, &mut next);
        }
        level = next;
    }
    let parts: Vec<Found> = level
        .par_iter()
        .map(|&seed| {
            let mut out = Found::new(cap);
            let mut stack = vec![seed];
            while let Some(job) = stack.pop() {
                step(job, &mut out, &mut stack);
            }
            out.compact();
            out
        })
        .collect();
    for p in parts {
        early.absorb(p);
    }
    early.compact();
    early
}

/// Self-clash pairs as a walk finds them: every one counted, only the first `cap` in `(a, b)`
/// order kept (the list is cut back to them whenever it grows to twice that, so memory does
/// not grow with the number of pairs).
struct Found {
    pairs: Vec<SelfPair>,
    total: u64,
    crossing: u64,
    cap: usize,
}

impl Found {
    fn new(cap: usize) -> Found {
        Found { pairs: Vec::new(), total: 0, crossing: 0, cap }
    }

    #[inline]
    fn push(&mut self, p: SelfPair) {
        self.total += 1;
        self.crossing += p.hit.crossing as u64;
        self.pairs.push(p);
        if self.pairs.len() >= self.cap.saturating_mul(2).max(4096) {
            self.compact();
        }
    }

    /// Keep the first `cap` pairs in `(a, b)` order.
    fn compact(&mut self) {
        if self.pairs.len() > self.cap {
            self.pairs.par_sort_unstable_by_key(|p| (p.a, p.b));
            self.pairs.truncate(self.cap);
        }
    }

    /// Add another walk's pairs and counts.
    fn absorb(&mut self, o: Found) {
        self.total += o.total;
        self.crossing += o.crossing;
        self.pairs.extend(o.pairs);
        self.compact();
    }
}

/// The self-clash pairs of one part: how many there are, how many of them cross, and the first
/// of them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SelfPairs {
    /// The first pairs in `(a, b)` order (all of them, or as many as were asked for).
    pub pairs: Vec<SelfPair>,
    /// How many pairs there are.
    pub total: u64,
    /// How many of them cross.
    pub crossing: u64,
}

/// Every self-clashing pair among `tris` (triangle indices of `mesh`, one part), sorted by
/// `(a, b)`. `merged` gives each vertex of `mesh` its exact-position id
/// ([`crate::scene::bodies::merge_vertices`]).
pub fn self_pairs(mesh: &Mesh, merged: &[u32], tris: &[u32], opts: BuildOptions) -> Vec<SelfPair> {
    self_pairs_timed(mesh, merged, tris, opts).0
}

/// [`self_pairs`] with at most the first `cap` pairs listed (in `(a, b)` order) and every
/// pair counted: memory does not grow with the number of pairs.
pub fn self_pairs_counted(
    mesh: &Mesh,
    merged: &[u32],
    tris: &[u32],
    opts: BuildOptions,
    cap: usize,
) -> SelfPairs {
    let fans = Fans::new(mesh, merged, tris);
    self_pairs_with(mesh, tris, &fans, opts, cap).0
}

/// Milliseconds spent by one [`self_pairs_timed`] call, by phase.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SelfTimes {
    /// The vertex fans and their certificates, the curve order and the tree.
    pub tree_ms: f64,
    /// The walk with every pair test, and the final sort.
    pub walk_ms: f64,
}

/// [`self_pairs`], with the time of each phase.
pub fn self_pairs_timed(
    mesh: &Mesh,
    merged: &[u32],
    tris: &[u32],
    opts: BuildOptions,
) -> (Vec<SelfPair>, SelfTimes) {
    let t0 = std::time::Instant::now();
    let fans = Fans::new(mesh, merged, tris);
    let (found, mut times) = self_pairs_with(mesh, tris, &fans, opts, usize::MAX);
    times.tree_ms = t0.elapsed().as_secs_f64() * 1e3 - times.walk_ms;
    (found.pairs, times)
}

/// [`self_pairs_counted`] with the time of each phase, given the part's fans ([`Fans::new`]
/// over the same triangles).
///
/// Pairs of two members of one line group ([`lines`]) are counted group by group, not walked.
pub fn self_pairs_with(
    mesh: &Mesh,
    tris: &[u32],
    fans: &Fans,
    opts: BuildOptions,
    cap: usize,
) -> (SelfPairs, SelfTimes) {
    let t0 = std::time::Instant::now();
    let copies = Copies::new(fans);
    let lines = lines::LineGroups::new(mesh, tris, fans);
    let certified = certified_fans(mesh, tris, fans, copies.as_ref().map(|c| c.walked.as_slice()));
    let corners = |k: usize| crate::bvh::triangle(mesh, tris[k]);
    // The triangles walked: all, or the first of each set of copies.
    let walked: Option<Vec<u32>> = copies.as_ref().map(|c| c.firsts());
    let local = |i: usize| walked.as_ref().map_or(i, |w| w[i] as usize);
    let count = walked.as_ref().map_or(tris.len(), Vec::len);
    let (keys, centres) = tree::curve_keys(count, |i| tri_box(&corners(local(i))).center());
    let origin = if centres.center().is_finite() { centres.center() } else { DVec3::ZERO };
    // What the walk reads, in curve order (which the tree keeps), so that a leaf is one run of
    // memory: a box, the vertex numbers and the position in the part. Corners are read from
    // the mesh only for the pairs that need a test.
    let mut slots: Vec<Slot> = keys
        .par_iter()
        .map(|&key| {
            let k = local(key as u32 as usize) as u32;
            let b = FBox::around(&tri_box(&corners(k as usize)), origin);
            Slot { b, ids: fans.ids[k as usize], k }
        })
        .collect();
    let nodes = tree::build(&mut slots, &keys, opts.leaf_size.clamp(1, 255) as usize);
    drop(keys);
    drop(walked);
    let is_certified = |v: u32| certified[v as usize / 64] >> (v % 64) & 1 != 0;
    let shared = common_certified(&nodes, &slots, &is_certified);
    let walked_mask = copies.as_ref().map(|c| c.walked.as_slice());
    let edges = certified_edges(mesh, tris, fans, walked_mask, &is_certified);
    let shared_edges = common_edges(&nodes, &slots, &edges);
    let is_certified_edge = |a: u32, b: u32| edges.binary_search(&edge_key(a, b)).is_ok();
    let line_of_node = lines.as_ref().map_or_else(Vec::new, |l| common_line(&nodes, &slots, l));
    let same_line = |x: &Slot, y: &Slot| lines.as_ref().is_some_and(|l| l.same(x.k, y.k));
    let tree_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t1 = std::time::Instant::now();
    let tri_of = |k: u32| Tri { p: corners(k as usize), ids: fans.ids[k as usize], t: tris[k as usize] };
    let tri = |s: &Slot| tri_of(s.k);
    // `x` against each of `ys`: the box test; then a pair sharing a vertex whose fan is
    // certified is settled; the rest get the exact box test and the pair test (`x`'s corners,
    // box and plane filter read once, on first use).
    let against = |x: &Slot, ys: &[Slot], out: &mut Found| {
        let cx = x.ids.iter().enumerate().fold(0, |m, (k, &v)| m | (is_certified(v) as usize) << k);
        let mut full = None;
        for y in ys {
            if x.b.meets(&y.b) && !same_line(x, y) {
                let mx = shared_mask(x.ids, y.ids);
                if mx & cx != 0 {
                    continue;
                }
                if !edges.is_empty() && mx.count_ones() == 2 {
                    let (p, q) = (x.ids[SHARED_PAIR[mx].0], x.ids[SHARED_PAIR[mx].1]);
                    if p != q && is_certified_edge(p, q) {
                        continue;
                    }
                }
                let (tx, bx, fx) = full.get_or_insert_with(|| {
                    let t = tri(x);
                    (t, tri_box(&t.p), PlaneFilter::new(&t.p))
                });
                let ty = tri(y);
                if !tri_meets_box(&ty.p, bx) {
                    continue;
                }
                if let Some(p) = test_pair(tx, fx, &ty, mx) {
                    match &copies {
                        None => out.push(p),
                        Some(c) => c.every_pair(mesh, tris, fans, x.k, y.k, out),
                    }
                }
            }
        }
    };
    let mut found = self_walk(
        &nodes,
        cap,
        |i, j| {
            certified_in_common(&shared[i as usize], &shared[j as usize])
                || shared_edges
                    .get(i as usize)
                    .is_some_and(|&e| e != u64::MAX && shared_edges[j as usize] == e)
                || line_of_node
                    .get(i as usize)
                    .is_some_and(|&g| g != lines::NONE && line_of_node[j as usize] == g)
        },
        |leaf, out| {
            let leaf = &slots[leaf];
            for (k, x) in leaf.iter().enumerate() {
                against(x, &leaf[k + 1..], out);
            }
        },
        |la, lb, out| {
            let lb = &slots[lb];
            for x in &slots[la] {
                against(x, lb, out);
            }
        },
    );
    if let Some(l) = &lines {
        // The pairs inside each line group: counted, the first listed (all touching).
        for g in 0..l.len() {
            found.total += l.count(g);
            for (x, y) in l.first_pairs(g, cap) {
                let (tx, ty) = (tri_of(x), tri_of(y));
                let (lo, hi) = if tx.t < ty.t { (tx, ty) } else { (ty, tx) };
                if let Some(hit) = classify_adjacent(&lo.p, lo.ids, &hi.p, hi.ids) {
                    found.pairs.push(SelfPair { a: lo.t, b: hi.t, hit });
                }
            }
            found.compact();
        }
    }
    found.compact();
    found.pairs.par_sort_unstable_by_key(|p| (p.a, p.b));
    let walk_ms = t1.elapsed().as_secs_f64() * 1e3;
    (
        SelfPairs { pairs: found.pairs, total: found.total, crossing: found.crossing },
        SelfTimes { tree_ms, walk_ms },
    )
}

/// Per node of the self tree: the line group ([`lines`]) every triangle under it belongs to
/// ([`lines::NONE`]: none). No pair inside such a node, or between two nodes of one group, is
/// walked: those pairs are counted with the group.
fn common_line(nodes: &[SNode], slots: &[Slot], lines: &lines::LineGroups) -> Vec<u32> {
    let mut out = vec![lines::NONE; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        out[i] = if n.is_leaf() {
            let items = &slots[n.a as usize..(n.a + n.count) as usize];
            let g = lines.of(items[0].k);
            if items.iter().all(|s| lines.of(s.k) == g) {
                g
            } else {
                lines::NONE
            }
        } else if out[i + 1] == out[n.a as usize] {
            out[i + 1]
        } else {
            lines::NONE
        };
    }
    out
}

/// Triangles of one part with the same distinct vertices (the same face stored again, in any
/// order or winding; the same segment or point), by vertex number. Two of them are never a
/// self-clash pair (they share every vertex either has), and against any third triangle all of
/// them give the same verdict (the rule reads only the distinct vertices and what is shared).
/// So the walk reads one of each set (its *first*: lowest position), and a pair found with a
/// first stands for every pair of the two sets, each classified on its own.
struct Copies {
    /// Per triangle: is it the first of its set (the one walked)?
    walked: Vec<bool>,
    /// Per triangle: its set, as an index into `starts`.
    set: Vec<u32>,
    /// The sets' members, set after set, each ascending.
    members: Vec<u32>,
    /// Where each set starts in `members` (and the end).
    starts: Vec<u32>,
}

impl Copies {
    /// The sets, or `None` when no two triangles have the same distinct vertices (the walk
    /// then reads every triangle, as it would anyway).
    fn new(fans: &Fans) -> Option<Copies> {
        // Distinct vertices ascending, padded with the last: [a, a, b] and [a, b, b] are one set.
        let key = |k: usize| {
            let mut i = fans.ids[k];
            i.sort_unstable();
            if i[0] == i[1] {
                [i[0], i[2], i[2]]
            } else {
                i
            }
        };
        let n = fans.ids.len();
        let mut order: Vec<([u32; 3], u32)> = (0..n).into_par_iter().map(|k| (key(k), k as u32)).collect();
        order.par_sort_unstable();
        if order.windows(2).all(|w| w[0].0 != w[1].0) {
            return None;
        }
        let mut walked = vec![false; n];
        let mut set = vec![0u32; n];
        let mut starts = Vec::new();
        for (x, &(k, t)) in order.iter().enumerate() {
            if x == 0 || k != order[x - 1].0 {
                starts.push(x as u32);
                walked[t as usize] = true;
            }
            set[t as usize] = starts.len() as u32 - 1;
        }
        starts.push(n as u32);
        let members = order.into_iter().map(|(_, t)| t).collect();
        Some(Copies { walked, set, members, starts })
    }

    /// The first triangle of every set, ascending.
    fn firsts(&self) -> Vec<u32> {
        (0..self.walked.len() as u32).filter(|&k| self.walked[k as usize]).collect()
    }

    /// The members of the set of triangle `k`.
    fn of(&self, k: u32) -> &[u32] {
        let s = self.set[k as usize] as usize;
        &self.members[self.starts[s] as usize..self.starts[s + 1] as usize]
    }

    /// Every pair of the sets of `x` and `y` (two walked triangles found to be a self-clash
    /// pair), each classified by [`classify_adjacent`] on its own triangles.
    fn every_pair(&self, mesh: &Mesh, tris: &[u32], fans: &Fans, x: u32, y: u32, out: &mut Found) {
        for &i in self.of(x) {
            for &j in self.of(y) {
                let (ti, tj) = (tris[i as usize], tris[j as usize]);
                let ((a, ka), (b, kb)) = if ti < tj { ((ti, i), (tj, j)) } else { ((tj, j), (ti, i)) };
                let (pa, pb) = (crate::bvh::triangle(mesh, a), crate::bvh::triangle(mesh, b));
                if let Some(hit) = classify_adjacent(&pa, fans.ids[ka as usize], &pb, fans.ids[kb as usize]) {
                    out.push(SelfPair { a, b, hit });
                }
            }
        }
    }
}

/// Vertices with at least this many triangles whose fan is not certified are searched for
/// edges shared by three or more triangles (books), to certify ([`certified_edges`]).
const BOOK_VERTEX_MIN: usize = 16;

/// The key of the edge between vertex numbers `a` and `b` (either order).
#[inline]
fn edge_key(a: u32, b: u32) -> u64 {
    (a.min(b) as u64) << 32 | a.max(b) as u64
}

/// The edges (keys, ascending) shared by three or more walked triangles around which every
/// pair sharing the edge is proven to meet only in it, so the walk may skip those pairs (and
/// nodes whose triangles all hold one such edge: [`common_edges`]).
///
/// Two triangles sharing exactly the edge `[u, w]` (copies are walked once: [`Copies`]), with
/// third vertices `a` and `b`, clash iff both are proper and `a`, `b` lie in one half-plane
/// bounded by the line `uw`, or both are on that line beyond the same end (the edge rule of
/// the module docs). Sorting the proper pages around the edge (exactly: the side of the plane
/// through `u, w` and a first page, then `orient3d` within each open side) puts pages in one
/// half-plane next to each other: the edge is certified when no two neighbours are in one
/// half-plane and at most one collinear page extends beyond each end. Only edges at
/// vertices with [`BOOK_VERTEX_MIN`] or more triangles and an uncertified fan are searched (a
/// surface has none).
fn certified_edges(
    mesh: &Mesh,
    tris: &[u32],
    fans: &Fans,
    walked: Option<&[bool]>,
    vertex_certified: &impl Fn(u32) -> bool,
) -> Vec<u64> {
    let walks = |k: usize| walked.is_none_or(|w| w[k]);
    let candidates: Vec<u32> = (0..fans.vertices() as u32)
        .filter(|&v| fans.group(v as usize).len() >= BOOK_VERTEX_MIN && !vertex_certified(v))
        .collect();
    let mut out: Vec<u64> = candidates
        .par_iter()
        .flat_map_iter(|&u| {
            // Pages by their other vertex w (each edge once: from its lower end).
            let mut by_w: Vec<(u32, u32)> = Vec::new();
            for &e in fans.group(u as usize) {
                let (k, c) = (e as usize / 3, e as usize % 3);
                if !walks(k) {
                    continue;
                }
                let ids = fans.ids[k];
                for w in [ids[(c + 1) % 3], ids[(c + 2) % 3]] {
                    if w > u {
                        by_w.push((w, e));
                    }
                }
            }
            by_w.sort_unstable();
            by_w.dedup();
            let mut found = Vec::new();
            let mut i = 0;
            while i < by_w.len() {
                let j = i + by_w[i..].iter().take_while(|p| p.0 == by_w[i].0).count();
                if j - i >= 3 && book_is_clean(mesh, tris, fans, u, by_w[i].0, &by_w[i..j]) {
                    found.push(edge_key(u, by_w[i].0));
                }
                i = j;
            }
            found
        })
        .collect();
    out.sort_unstable();
    out
}

/// Exact, for the pages `pages` (corners `3k + c` at `u`, each triangle holding `u` and `w`):
/// does every pair of them meet only in the edge? See [`certified_edges`].
fn book_is_clean(mesh: &Mesh, tris: &[u32], fans: &Fans, u: u32, w: u32, pages: &[(u32, u32)]) -> bool {
    let point = |k: usize, c: usize| mesh.positions[mesh.triangles[tris[k] as usize][c] as usize];
    let (mut pu, mut pw) = (None, None);
    let mut thirds: Vec<DVec3> = Vec::with_capacity(pages.len());
    for &(_, e) in pages {
        let k = e as usize / 3;
        let ids = fans.ids[k];
        let mut third = None;
        for (c, &id) in ids.iter().enumerate() {
            match id {
                x if x == u => pu = Some(point(k, c)),
                x if x == w => pw = Some(point(k, c)),
                _ => third = Some(point(k, c)),
            }
        }
        // No third vertex: the segment uw itself, which meets every page in the edge only.
        thirds.extend(third);
    }
    let (Some(u), Some(w)) = (pu, pw) else { return false };
    let (mut proper, mut beyond_u, mut beyond_w) = (Vec::new(), 0, 0);
    let k = (0..3).find(|&k| u[k] != w[k]).expect("u != w");
    for a in thirds {
        if pr::collinear(u, w, a) {
            // Beyond u: on the far side of u from w along axis k (the order on the line).
            if (a[k] < u[k]) == (u[k] < w[k]) && a[k] != u[k] {
                beyond_u += 1;
            } else if (a[k] > w[k]) == (u[k] < w[k]) && a[k] != w[k] {
                beyond_w += 1;
            }
        } else {
            proper.push(a);
        }
    }
    if beyond_u > 1 || beyond_w > 1 {
        return false;
    }
    let Some(&a0) = proper.first() else { return true };
    let axis = pr::projection_axis(u, w, a0).expect("proper page");
    let side0 = pr::orient2d(u, w, a0, axis);
    // 0: a0's half-plane, 1: one open side, 2: the opposite half-plane, 3: the other side.
    let half = |a: DVec3| match pr::orient3d(u, w, a0, a) {
        1 => 1u8,
        -1 => 3,
        _ if pr::orient2d(u, w, a, axis) == side0 => 0,
        _ => 2,
    };
    let mut keyed: Vec<(u8, DVec3)> = proper.iter().map(|&a| (half(a), a)).collect();
    let cmp = |x: &(u8, DVec3), y: &(u8, DVec3)| {
        x.0.cmp(&y.0).then_with(|| {
            if x.0 % 2 == 1 {
                0.cmp(&pr::orient3d(u, w, x.1, y.1))
            } else {
                std::cmp::Ordering::Equal
            }
        })
    };
    keyed.sort_by(cmp);
    keyed.windows(2).all(|p| cmp(&p[0], &p[1]) != std::cmp::Ordering::Equal)
}

/// Per node of the self tree: a certified edge every triangle under it holds (`u64::MAX`:
/// none), as [`common_certified`] does for vertices.
fn common_edges(nodes: &[SNode], slots: &[Slot], edges: &[u64]) -> Vec<u64> {
    let none = u64::MAX;
    if edges.is_empty() {
        return Vec::new();
    }
    let holds = |s: &Slot, e: u64| {
        let i = s.ids;
        [edge_key(i[0], i[1]), edge_key(i[1], i[2]), edge_key(i[0], i[2])].contains(&e)
    };
    let mut out = vec![none; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        out[i] = if n.is_leaf() {
            let items = &slots[n.a as usize..(n.a + n.count) as usize];
            let i0 = items[0].ids;
            [edge_key(i0[0], i0[1]), edge_key(i0[1], i0[2]), edge_key(i0[0], i0[2])]
                .into_iter()
                .find(|&e| edges.binary_search(&e).is_ok() && items.iter().all(|s| holds(s, e)))
                .unwrap_or(none)
        } else if out[i + 1] == out[n.a as usize] {
            out[i + 1]
        } else {
            none
        };
    }
    out
}

/// Up to three certified vertices that every triangle under a node has (ascending, then
/// `u32::MAX`).
type Common = [u32; 3];

/// Per node of the self tree: the certified vertices all its triangles share. A node whose
/// triangles all lie around one certified vertex has no self-clash pair inside it, and two
/// nodes sharing such a vertex none between them ([`certified_in_common`]): the walk skips
/// them whole instead of skipping their pairs one by one (a fan of `m` triangles is `m²/2`
/// pairs).
fn common_certified(nodes: &[SNode], slots: &[Slot], is_certified: &impl Fn(u32) -> bool) -> Vec<Common> {
    let none = [u32::MAX; 3];
    let meet = |a: &Common, b: &Common| {
        let mut out = none;
        let mut n = 0;
        for &v in a.iter().filter(|&&v| v != u32::MAX) {
            if b.contains(&v) {
                out[n] = v;
                n += 1;
            }
        }
        out
    };
    let of_slot = |s: &Slot| {
        let mut c = none;
        let mut n = 0;
        let mut ids = s.ids;
        ids.sort_unstable();
        for (k, &v) in ids.iter().enumerate() {
            if is_certified(v) && (k == 0 || ids[k - 1] != v) {
                c[n] = v;
                n += 1;
            }
        }
        c
    };
    let mut out = vec![none; nodes.len()];
    // Children come after their parent (pre-order): fill from the end.
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        out[i] = if n.is_leaf() {
            let items = &slots[n.a as usize..(n.a + n.count) as usize];
            items[1..].iter().fold(of_slot(&items[0]), |c, s| meet(&c, &of_slot(s)))
        } else {
            meet(&out[i + 1], &out[n.a as usize])
        };
    }
    out
}

/// Do two nodes' triangles all share a certified vertex?
#[inline]
fn certified_in_common(a: &Common, b: &Common) -> bool {
    a.iter().any(|&v| v != u32::MAX && b.contains(&v))
}

/// Fans with at most this many triangles are certified by the ring argument below (on the
/// stack); larger ones by [`sectors_tile`].
const CERTIFIED_FAN_MAX: usize = 32;

/// One bit per vertex: set when every pair of triangles around the vertex is proven to meet
/// only in what it shares, by one exact argument for the whole fan.
///
/// The fan of `v` is certified when its triangles, read from `v` in their own winding as
/// `(v, w1, w2)`, are all proper, no two have the same `w1` or the same `w2`, the `w1` are the
/// `w2` (a closed ring, every edge at `v` used by two triangles in opposite directions), and
/// there is an axis `a` along which the filter proves every normal's component `a` non-zero
/// with one sign `s`, and, projected along `a`, the ring goes around `v` exactly once.
///
/// Then the projection along `a` is one-to-one on each triangle, and every projected triangle
/// `(v, w1, w2)` turns the same way `s` around `v` by less than π; the ring's winding number
/// around `v` is the sum of those turns over 2π, so winding ±1 means the projected triangles
/// are sectors around `v` that tile the turn once without overlapping. Two sectors then meet
/// only in `v` or in their common edge, and the triangles (one-to-one over them) only in what
/// they share: no pair of the fan is a self-clash. The winding number is counted exactly
/// (Sunday's crossing rule): every ring edge `w1 → w2` has `v` on the side `s` (that is the
/// sign of its triangle), so only the edges crossing the line through `v` upward (`s > 0`) or
/// downward (`s < 0`) count, and those are decided by comparing coordinates. Nothing is
/// rounded, so a certified fan is a proof; a fan that is not certified only costs its pairs
/// the pair test.
///
/// `walked` (when given) says which triangles the walk reads: the fan of `v` is then made of
/// those only (the others repeat one of them: [`Copies`]). A fan of more than
/// [`CERTIFIED_FAN_MAX`] triangles is certified by [`sectors_tile`] instead.
fn certified_fans(mesh: &Mesh, tris: &[u32], fans: &Fans, walked: Option<&[bool]>) -> Vec<u64> {
    let n = fans.vertices();
    let corner = |e: u32, step: usize| {
        let (k, c) = (e as usize / 3, e as usize % 3);
        mesh.positions[mesh.triangles[tris[k] as usize][(c + step) % 3] as usize]
    };
    let certify = |v: usize| -> bool {
        let kept: Vec<u32>;
        let group = match walked {
            None => fans.group(v),
            Some(w) => {
                kept = fans.group(v).iter().copied().filter(|&e| w[e as usize / 3]).collect();
                &kept
            }
        };
        let m = group.len();
        if m > CERTIFIED_FAN_MAX {
            return sectors_tile(group, fans, &corner);
        }
        if m < 3 {
            return false;
        }
        let k0 = group[0] as usize / 3;
        // An axis along which every normal has one proven sign.
        let Some((axis, s)) = (0..3).find_map(|a| {
            let s = fans.normal_sign(k0, a)?;
            group.iter().all(|&e| fans.normal_sign(e as usize / 3, a) == Some(s)).then_some((a, s))
        }) else {
            return false;
        };
        // The ring: each w1 once, each w2 once, and the same set.
        let mut w1 = [0u32; CERTIFIED_FAN_MAX];
        let mut w2 = [0u32; CERTIFIED_FAN_MAX];
        for (i, &e) in group.iter().enumerate() {
            let (k, c) = (e as usize / 3, e as usize % 3);
            let t = fans.ids[k];
            (w1[i], w2[i]) = (t[(c + 1) % 3], t[(c + 2) % 3]);
        }
        let (w1, w2) = (&mut w1[..m], &mut w2[..m]);
        w1.sort_unstable();
        w2.sort_unstable();
        if w1 != w2 || w1.windows(2).any(|p| p[0] == p[1]) {
            return false;
        }
        // Crossings of the line through v along the projection's second coordinate.
        let y = (axis + 2) % 3;
        let yv = corner(group[0], 0)[y];
        let crossings = group
            .iter()
            .filter(|&&e| {
                let (p, q) = (corner(e, 1)[y], corner(e, 2)[y]);
                if s > 0 {
                    p <= yv && yv < q
                } else {
                    q <= yv && yv < p
                }
            })
            .count();
        crossings == 1
    };
    (0..n.div_ceil(64))
        .into_par_iter()
        .map(|w| (w * 64..(w * 64 + 64).min(n)).filter(|&v| certify(v)).fold(0u64, |b, v| b | 1 << (v % 64)))
        .collect()
}

/// Exact, for the fan `group` of a vertex `v` (corners `3k + c`; `corner(e, j)` is the point
/// `j` steps after corner `e` in its triangle's winding, so `corner(e, 0) = v`): do its
/// triangles meet only in what they share? Linear after a sort, for fans of any size.
///
/// Projected along an axis along which every triangle `(v, w1, w2)` has the same non-zero
/// orientation (exact `orient2d`), each triangle is one-to-one onto a sector at `v` of less
/// than a half turn, all turning one way. Read every sector from its first ray to its second
/// in the turning direction and sort them by first ray (exactly: half-plane, then
/// orientation). When each sector ends before the next one (cyclically) begins, or on that
/// one's first ray with the same vertex there (a shared edge), the sectors meet only in `v` or
/// in shared edges; so do the triangles (one-to-one over them): certified. Otherwise (two
/// sectors overlap, or touch along a ray at different vertices) nothing is claimed.
fn sectors_tile(group: &[u32], fans: &Fans, corner: &impl Fn(u32, usize) -> DVec3) -> bool {
    let Some(&e0) = group.first() else { return true };
    let v = corner(e0, 0);
    let Some(axis) = pr::projection_axis(v, corner(e0, 1), corner(e0, 2)) else { return false };
    let turn = pr::orient2d(v, corner(e0, 1), corner(e0, 2), axis);
    // (first ray point, its vertex number, second ray point, its vertex number).
    let mut sectors: Vec<(DVec3, u32, DVec3, u32)> = Vec::with_capacity(group.len());
    for &e in group {
        let (p, q) = (corner(e, 1), corner(e, 2));
        if pr::orient2d(v, p, q, axis) != turn {
            return false;
        }
        let (k, c) = (e as usize / 3, e as usize % 3);
        let ids = fans.ids[k];
        let (ip, iq) = (ids[(c + 1) % 3], ids[(c + 2) % 3]);
        sectors.push(if turn > 0 { (p, ip, q, iq) } else { (q, iq, p, ip) });
    }
    // The angle of the ray v→d from the ray v→base, counter-clockwise in the projection, as
    // (half, …): 0 the base ray itself, 1 the open half turn after it, 2 the opposite ray, 3
    // the open half turn before it. Within 1 or 3, `orient2d` orders two rays exactly.
    let half = |base: DVec3, d: DVec3| -> u8 {
        match pr::orient2d(v, base, d, axis) {
            1 => 1,
            -1 => 3,
            _ => {
                // On the line through v and base: the same ray iff on the same side of v along
                // an axis where base differs from v.
                let j = (0..3).find(|&j| base[j] != v[j]).expect("base != v");
                if (d[j] > v[j]) == (base[j] > v[j]) {
                    0
                } else {
                    2
                }
            }
        }
    };
    let cmp = |base: DVec3, a: DVec3, b: DVec3| -> std::cmp::Ordering {
        let (ha, hb) = (half(base, a), half(base, b));
        ha.cmp(&hb).then_with(|| {
            if ha % 2 == 1 {
                0.cmp(&pr::orient2d(v, a, b, axis))
            } else {
                std::cmp::Ordering::Equal
            }
        })
    };
    let base = sectors[0].0;
    sectors.sort_by(|x, y| cmp(base, x.0, y.0));
    let m = sectors.len();
    (0..m).all(|i| {
        let (first, _, end, end_id) = sectors[i];
        let (next, next_id, _, _) = sectors[(i + 1) % m];
        if m == 1 {
            return true;
        }
        if half(first, next) == 0 {
            return false; // two sectors start on one ray: they overlap
        }
        match cmp(first, end, next) {
            std::cmp::Ordering::Less => true,
            std::cmp::Ordering::Equal => end_id == next_id,
            std::cmp::Ordering::Greater => false,
        }
    })
}

/// The same answer as [`self_pairs`] by testing every pair (quadratic; for tests).
pub fn self_pairs_brute_force(mesh: &Mesh, merged: &[u32], tris: &[u32]) -> Vec<SelfPair> {
    let mut sorted = tris.to_vec();
    sorted.sort_unstable();
    let ids = |t: u32| mesh.triangles[t as usize].map(|v| merged[v as usize]);
    let mut out = Vec::new();
    for (x, &a) in sorted.iter().enumerate() {
        for &b in &sorted[x + 1..] {
            let (ta, tb) = (crate::bvh::triangle(mesh, a), crate::bvh::triangle(mesh, b));
            if let Some(hit) = classify_adjacent(&ta, ids(a), &tb, ids(b)) {
                out.push(SelfPair { a, b, hit });
            }
        }
    }
    out
}

/// The result for one part.
#[derive(Debug, Clone, PartialEq)]
pub struct PartResult {
    /// Object index in the (possibly split) mesh; None for `--whole-file`.
    pub object: Option<u32>,
    /// Its name.
    pub name: String,
    /// Its triangles (indices into the mesh).
    pub triangles: usize,
    /// Its first self-clashing pairs, sorted by (a, b): all of them unless the check was asked
    /// to list fewer ([`check_parts_listing`]).
    pub pairs: Vec<SelfPair>,
    /// How many self-clashing pairs it has (listed or not).
    pub count: u64,
    /// How many of them cross.
    pub crossing: u64,
    /// Its health.
    pub health: crate::check::health::Health,
    /// With instance reuse ([`check_part_list`]): the index (in the result list) of the part
    /// whose check this one's result was derived from, because its placed coordinates are an
    /// exact translate of that part's; None when it was checked itself.
    pub same_as: Option<usize>,
}

/// Which parts [`check_parts`] checks.
pub enum PartChoice<'a> {
    /// Every object (object order) whose name passes the filter.
    Objects(&'a dyn Fn(&str) -> bool),
    /// All triangles as one part with this name.
    Whole(&'a str),
}

/// One part to check: its object (None: the whole file), name and triangles (indices into the
/// mesh, ascending).
pub type PartSpec = (Option<u32>, String, Vec<u32>);

/// Self-clash and health of the chosen parts of `mesh`, with the milliseconds spent on health
/// (with the vertex merge) and on the self-clash walks (the two run at the same time, so their
/// times overlap).
pub fn check_parts(
    mesh: &crate::scene::mesh::Mesh,
    choice: PartChoice,
    opts: BuildOptions,
    first_n: usize,
) -> (Vec<PartResult>, f64, f64) {
    check_parts_listing(mesh, choice, opts, first_n, usize::MAX)
}

/// [`check_parts`], listing at most the first `max_listed` pairs of each part (the counts stay
/// complete): memory does not grow with the number of pairs.
pub fn check_parts_listing(
    mesh: &crate::scene::mesh::Mesh,
    choice: PartChoice,
    opts: BuildOptions,
    first_n: usize,
    max_listed: usize,
) -> (Vec<PartResult>, f64, f64) {
    let parts: Vec<PartSpec> = match choice {
        PartChoice::Objects(keep) => crate::check::assembly::parts_of(mesh, 0)
            .into_iter()
            .filter(|p| keep(&p.name))
            .map(|p| (Some(p.object), p.name, p.triangles))
            .collect(),
        PartChoice::Whole(name) => vec![(None, name.to_string(), (0..mesh.triangles.len() as u32).collect())],
    };
    check_part_list(mesh, parts, opts, first_n, max_listed, false)
}

/// [`check_parts`] for a given list of parts. With `reuse` (scene mode), a part whose triangles
/// index the mesh like an earlier checked part's, shifted by one vertex offset (instances of one
/// glTF mesh), and whose placed coordinates are an *exact* translate of that part's
/// ([`crate::geom::predicates::exact_translation`]) is not walked again: every orientation sign
/// is the same for both, so are the vertex merge, the self-clash verdicts and every health count;
/// its pairs are re-classified on its own coordinates (for its own contact segments) and its
/// health findings renumbered. Any other part (an instance rotated or scaled, whose coordinates
/// were rounded differently) is checked on its own placed coordinates, so the answer is always
/// exactly the one a separate check of each part gives. Each part lists at most its first
/// `max_listed` pairs.
pub fn check_part_list(
    mesh: &crate::scene::mesh::Mesh,
    parts: Vec<PartSpec>,
    opts: BuildOptions,
    first_n: usize,
    max_listed: usize,
    reuse: bool,
) -> (Vec<PartResult>, f64, f64) {
    let t = std::time::Instant::now();
    let (merged, _) = crate::scene::bodies::merge_vertices(&mesh.positions);
    let same_as: Vec<Option<usize>> = if reuse { translates(mesh, &parts) } else { vec![None; parts.len()] };
    let merge_ms = t.elapsed().as_secs_f64() * 1e3;
    let leaders: Vec<usize> = (0..parts.len()).filter(|&i| same_as[i].is_none()).collect();
    let ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
    // The fans of each part serve both passes; health and the self-clash walks then run side
    // by side (the walks' tree builds have sequential stretches the health pass fills).
    let t = std::time::Instant::now();
    let fans: Vec<Fans> = leaders.par_iter().map(|&i| Fans::new(mesh, &merged, &parts[i].2)).collect();
    let fans_ms = ms(t);
    let ((healths, health_ms), (found, query_ms)) = rayon::join(
        || {
            let t = std::time::Instant::now();
            let h: Vec<crate::check::health::Health> = leaders
                .par_iter()
                .zip(&fans)
                .map(|(&i, f)| crate::check::health::health_with(mesh, f, &parts[i].2, first_n))
                .collect();
            (h, ms(t) + fans_ms)
        },
        || {
            let t = std::time::Instant::now();
            let f: Vec<SelfPairs> = leaders
                .par_iter()
                .zip(&fans)
                .map(|(&i, f)| self_pairs_with(mesh, &parts[i].2, f, opts, max_listed).0)
                .collect();
            (f, ms(t))
        },
    );
    drop(fans);
    let mut checked: Vec<Option<(crate::check::health::Health, SelfPairs)>> = vec![None; parts.len()];
    for (&i, r) in leaders.iter().zip(healths.into_iter().zip(found)) {
        checked[i] = Some(r);
    }
    let t = std::time::Instant::now();
    let mut results: Vec<PartResult> = Vec::with_capacity(parts.len());
    for (i, (object, name, tris)) in parts.iter().enumerate() {
        let derived = same_as[i].and_then(|l| {
            let (health, found) = checked[l].as_ref().expect("leaders come first");
            // The counts are the leader's (every verdict is the same); the listed pairs are
            // renumbered and re-classified.
            derive(mesh, &merged, &parts[l].2, tris, health, &found.pairs)
                .map(|(h, pairs)| ((h, SelfPairs { pairs, total: found.total, crossing: found.crossing }), l))
        });
        let ((health, found), from) = match derived {
            Some((r, l)) => (r, Some(l)),
            // Not derivable after all (never expected): check it itself.
            None => match checked[i].clone() {
                Some(r) => (r, None),
                None => (
                    (
                        crate::check::health::health(mesh, &merged, tris, first_n),
                        self_pairs_counted(mesh, &merged, tris, opts, max_listed),
                    ),
                    None,
                ),
            },
        };
        results.push(PartResult {
            object: *object,
            name: name.clone(),
            triangles: tris.len(),
            pairs: found.pairs,
            count: found.total,
            crossing: found.crossing,
            health,
            same_as: from,
        });
    }
    (results, merge_ms + health_ms, query_ms + ms(t))
}

/// For each part, an earlier part (one that is checked itself) whose result it can take over:
/// the same number of triangles, each corner index the other's plus one common offset, and the
/// placed corners an exact translate of the other's. At most [`REUSE_CANDIDATES`] earlier parts
/// with the same glTF mesh are tried per part.
fn translates(mesh: &crate::scene::mesh::Mesh, parts: &[PartSpec]) -> Vec<Option<usize>> {
    let corners = |tris: &[u32]| -> Vec<DVec3> {
        tris.iter().flat_map(|&t| crate::bvh::triangle(mesh, t)).collect::<Vec<DVec3>>()
    };
    let shifted = |l: &[u32], i: &[u32]| {
        let first = |t: &[u32]| mesh.triangles[t[0] as usize][0] as i64;
        let shift = first(i) - first(l);
        l.len() == i.len()
            && l.iter().zip(i).all(|(&a, &b)| {
                let (a, b) = (mesh.triangles[a as usize], mesh.triangles[b as usize]);
                (0..3).all(|k| b[k] as i64 == a[k] as i64 + shift)
            })
    };
    let key = |p: &PartSpec| p.0.and_then(|o| mesh.objects[o as usize].gltf_mesh).map(|m| (m, p.2.len()));
    let mut leaders: std::collections::HashMap<(u32, usize), Vec<usize>> = std::collections::HashMap::new();
    let mut out = vec![None; parts.len()];
    for (i, p) in parts.iter().enumerate() {
        let Some(k) = key(p).filter(|k| k.1 > 0) else { continue };
        let group = leaders.entry(k).or_default();
        let mine = std::cell::OnceCell::new();
        let found = group.iter().take(REUSE_CANDIDATES).copied().find(|&l| {
            shifted(&parts[l].2, &p.2)
                && crate::geom::predicates::exact_translation(
                    &corners(&parts[l].2),
                    mine.get_or_init(|| corners(&p.2)),
                )
                .is_some()
        });
        match found {
            Some(l) => out[i] = Some(l),
            None => group.push(i),
        }
    }
    out
}

/// How many earlier checked parts of the same glTF mesh a part is compared with.
const REUSE_CANDIDATES: usize = 4;

/// The result of part `inst` from that of `leader` (an exact translate with the same index
/// pattern, see [`translates`]): the same pairs and findings, renumbered, the pairs re-classified
/// on `inst`'s own coordinates. None if a pair does not classify the same (never expected).
fn derive(
    mesh: &crate::scene::mesh::Mesh,
    merged: &[u32],
    leader: &[u32],
    inst: &[u32],
    health: &crate::check::health::Health,
    pairs: &[SelfPair],
) -> Option<(crate::check::health::Health, Vec<SelfPair>)> {
    // Both lists ascend, so the map keeps order (and the first N ids stay the first N).
    let map = |t: u32| leader.binary_search(&t).ok().map(|k| inst[k]);
    let ids = |t: u32| mesh.triangles[t as usize].map(|v| merged[v as usize]);
    let mut out = Vec::with_capacity(pairs.len());
    for q in pairs {
        let (a, b) = (map(q.a)?, map(q.b)?);
        let hit = classify_adjacent(
            &crate::bvh::triangle(mesh, a),
            ids(a),
            &crate::bvh::triangle(mesh, b),
            ids(b),
        )?;
        if hit.crossing != q.hit.crossing || hit.contact != q.hit.contact {
            return None;
        }
        out.push(SelfPair { a, b, hit });
    }
    let f = |x: &crate::check::health::Finding| -> Option<crate::check::health::Finding> {
        Some(crate::check::health::Finding {
            count: x.count,
            triangles: x.triangles.iter().map(|&t| map(t)).collect::<Option<Vec<u32>>>()?,
        })
    };
    let h = crate::check::health::Health {
        closed: health.closed,
        duplicate_faces: f(&health.duplicate_faces)?,
        zero_area_triangles: f(&health.zero_area_triangles)?,
        non_manifold_edges: f(&health.non_manifold_edges)?,
        non_manifold_vertices: f(&health.non_manifold_vertices)?,
        boundary_edges: f(&health.boundary_edges)?,
        boundary_loops: health.boundary_loops,
        inconsistent_winding_edges: f(&health.inconsistent_winding_edges)?,
        // Σ (a−o)·((b−o)×(c−o)): each difference is the same real for both parts (an exact
        // translate), so the same f64, and the sum is bit-identical.
        volume: health.volume,
    };
    Some((h, out))
}

mod lines;
mod tree;

#[cfg(test)]
mod tests;

/// Generated inputs for tests and the benchmark (with [`crate::testing`]).
#[cfg(any(test, feature = "testing"))]
pub mod gen {
    use crate::geom::DVec3;
    use crate::scene::mesh::Mesh;

    /// [`crate::testing::gen::torus`] (`≈ n` triangles, closed, major radius 1, minor 0.35) with
    /// one fold: the vertex on the outer equator at angle 0 is pulled through the tube to
    /// `(0.5, 0, 0)`, inside the hole, so its six triangles pierce the inner wall.
    pub fn folded_torus(n: usize) -> Mesh {
        let mut m = crate::testing::gen::torus(n);
        m.positions[0] = DVec3::new(0.5, 0.0, 0.0);
        m
    }

    /// A closed tube of radius `small` swept along the figure eight `(cos t, sin 2t / 2, 0)`:
    /// the path crosses itself at the origin (at `t = π/2` and `t = 3π/2`, at right angles), so
    /// the tube overlaps itself there. `u` rings of `v` vertices, two triangles per quad.
    pub fn figure_eight_tube(u: usize, v: usize, small: f64) -> Mesh {
        let mut positions = Vec::with_capacity(u * v);
        for i in 0..u {
            let t = i as f64 / u as f64 * std::f64::consts::TAU;
            let c = DVec3::new(t.cos(), (2.0 * t).sin() / 2.0, 0.0);
            let tangent = DVec3::new(-t.sin(), (2.0 * t).cos(), 0.0).normalize();
            let side = tangent.cross(DVec3::Z);
            for j in 0..v {
                let ph = j as f64 / v as f64 * std::f64::consts::TAU;
                positions.push(c + small * (ph.cos() * side + ph.sin() * DVec3::Z));
            }
        }
        let id = |i: usize, j: usize| ((i % u) * v + (j % v)) as u32;
        let mut triangles = Vec::with_capacity(2 * u * v);
        for i in 0..u {
            for j in 0..v {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Mesh {
            positions,
            tri_object: vec![0; triangles.len()],
            triangles,
            objects: vec![crate::scene::mesh::Object { name: "figure8".into(), ..Default::default() }],
        }
    }
}
