//! The exact overlap box of two clashing closed parts: the axis-aligned box of the solid
//! intersection A ∩ B.
//!
//! A ∩ B of two closed polyhedral solids is a closed polyhedral set; each extreme of it along
//! an axis is reached at one of its vertices, and every vertex of A ∩ B is
//!
//! * a vertex of A inside (or on) B, or a vertex of B inside (or on) A, or
//! * a point where an edge of one part meets a face (triangle) of the other: a crossing point,
//!   or — for an edge lying in the face's plane — an end of the piece of the edge inside the
//!   triangle (where the edge meets the other part's edges, or its own ends).
//!
//! The box of those points is therefore the box of A ∩ B. Each point is computed exactly: f64
//! coordinates are integers in a common [`Frame`], an edge `p q` meets the plane of a triangle
//! at `p + t (q - p)` with `t` a ratio of two orientation determinants (for an edge in the
//! plane, `t` is a ratio of two 2D determinants), so every coordinate is a [`Ratio`] of
//! integers. Extremes are compared exactly and each bound is rounded once, to the nearest f64
//! ([`Ratio::round`]). The box depends only on the two solids, not on how they are tessellated.
//!
//! Edge–face candidates come from the other part's tree (triangles whose boxes meet the edge's
//! box), so the cost follows the contact, not the product of the sizes. A vertex strictly
//! inside the box found so far cannot move it and costs no point query. Only closed parts have
//! an inside: [`overlap_box`] is for closed parts (the pipeline asks only for those). When the
//! exact point-in-solid test cannot decide a vertex (every ray direction it tries meets an edge
//! exactly), there is no box rather than a doubtful one.

use crate::bvh::traverse::{self, Tree};
use crate::check::containment::{self, Inside};
use crate::geom::exact::{self, Frame, Int, Ratio};
use crate::geom::predicates as pr;
use crate::geom::{Aabb, DVec3};
use crate::narrow::tri_tri::Shape;
use crate::scene::bodies::{find, union};
use crate::scene::mesh::TriMesh;

/// The box of A ∩ B, each bound correctly rounded to f64.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overlap {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

impl Overlap {
    /// `max - min` per axis (f64 differences of the rounded bounds).
    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    /// As an [`Aabb`].
    pub fn aabb(&self) -> Aabb {
        Aabb { min: self.min, max: self.max }
    }
}

/// A point with exact rational coordinates in the frame (all three over one denominator).
struct Point {
    num: [Int; 3],
    den: Int,
}

/// The exact box of the candidate points seen so far, with f64 bounds that let most vertices
/// be skipped without exact arithmetic.
#[derive(Clone)]
struct ExactBox {
    frame: Frame,
    lo: [Option<Ratio>; 3],
    hi: [Option<Ratio>; 3],
    /// Per axis, a value at or above `lo` and one at or below `hi` (the rounded bounds moved
    /// one step inwards): a vertex strictly between them is strictly inside the box.
    inner: [(f64, f64); 3],
}

impl ExactBox {
    fn new(frame: Frame) -> ExactBox {
        ExactBox {
            frame,
            lo: [None, None, None],
            hi: [None, None, None],
            inner: [(f64::INFINITY, f64::NEG_INFINITY); 3],
        }
    }

    /// Add point `p` on the axes of `axes` (an axis left out must be one the point cannot
    /// move: see [`ExactBox::may_move`]; its coordinate is not read).
    fn add(&mut self, p: Point, axes: [bool; 3]) {
        let Point { num, den } = p;
        for (k, n) in num.into_iter().enumerate() {
            if axes[k] {
                let r = Ratio::new(n, den.clone());
                self.extend(k, &r, &r);
            }
        }
    }

    /// Per axis, whether a point known to lie in `b` may move that axis's bounds: false when
    /// `b` lies strictly inside the box along it (the point then cannot move it).
    fn may_move(&self, b: &Aabb) -> [bool; 3] {
        [0, 1, 2].map(|k| !(self.inner[k].0 <= b.min[k] && b.max[k] <= self.inner[k].1))
    }

    /// Widen axis `k` to take in `[lo, hi]`.
    fn extend(&mut self, k: usize, lo: &Ratio, hi: &Ratio) {
        let mut changed = false;
        if self.lo[k].as_ref().is_none_or(|cur| lo.cmp_value(cur).is_lt()) {
            self.lo[k] = Some(lo.clone());
            changed = true;
        }
        if self.hi[k].as_ref().is_none_or(|cur| hi.cmp_value(cur).is_gt()) {
            self.hi[k] = Some(hi.clone());
            changed = true;
        }
        if changed {
            let base = self.frame.base();
            let lo = self.lo[k].as_ref().map_or(f64::INFINITY, |r| r.round(base).next_up());
            let hi = self.hi[k].as_ref().map_or(f64::NEG_INFINITY, |r| r.round(base).next_down());
            self.inner[k] = (lo, hi);
        }
    }

    /// The box of both boxes' points (same frame).
    fn merge(mut self, other: ExactBox) -> ExactBox {
        for k in 0..3 {
            if let (Some(lo), Some(hi)) = (&other.lo[k], &other.hi[k]) {
                self.extend(k, lo, hi);
            }
        }
        self
    }

    fn add_vertex(&mut self, v: DVec3) {
        let num = self.frame.point(v);
        self.add(Point { num, den: Int::from_i64(1) }, [true; 3]);
    }

    /// True if `v` is strictly inside the box (so it cannot move it).
    fn strictly_inside(&self, v: DVec3) -> bool {
        (0..3).all(|k| self.inner[k].0 <= v[k] && v[k] <= self.inner[k].1)
    }

    /// True if every point of `b` is strictly inside the box: no point known to lie in `b`
    /// can move a bound, so its exact coordinates are not needed. `b` holds f64 bounds that
    /// enclose the candidate points exactly (no rounding is involved: the boxes of a segment
    /// and of a triangle, both of which contain their crossing point).
    fn strictly_contains(&self, b: &Aabb) -> bool {
        (0..3).all(|k| self.inner[k].0 <= b.min[k] && b.max[k] <= self.inner[k].1)
    }

    fn finish(&self) -> Option<Overlap> {
        let base = self.frame.base();
        let bound = |r: &Option<Ratio>| r.as_ref().map(|r| r.round(base));
        let mut min = DVec3::ZERO;
        let mut max = DVec3::ZERO;
        for k in 0..3 {
            min[k] = bound(&self.lo[k])?;
            max[k] = bound(&self.hi[k])?;
        }
        Some(Overlap { min, max })
    }
}

/// Is triangle `t` of `m` proper (not degenerate)? Asked only of the triangles an edge or a
/// vertex of the box needs.
fn proper<M: TriMesh + ?Sized>(m: &M, t: u32) -> bool {
    !Shape::of(&m.triangle(t)).is_degenerate()
}

/// The point `p + t (q - p)` for `t = n / d` (`d != 0`), its coordinates on the axes of `axes`
/// (the others are left zero: see [`ExactBox::add`]).
fn along(f: &Frame, p: DVec3, q: DVec3, n: &Int, d: &Int, axes: [bool; 3]) -> Point {
    let num = [0, 1, 2].map(|k| {
        if !axes[k] {
            return Int::default();
        }
        let (ip, iq) = (f.int(p[k]), f.int(q[k]));
        ip.mul(d).add(&n.mul(&iq.sub(&ip)))
    });
    Point { num, den: d.clone() }
}

/// The vertex `v` as a point, its coordinates on the axes of `axes` (see [`along`]).
fn vertex_point(f: &Frame, v: DVec3, axes: [bool; 3]) -> Point {
    let num = [0, 1, 2].map(|k| if axes[k] { f.int(v[k]) } else { Int::default() });
    Point { num, den: Int::from_i64(1) }
}

/// Add to `acc` the points of segment `p q` ∩ closed triangle `tri` that can be vertices of
/// the intersection: the crossing point, or the ends of the piece inside a coplanar triangle.
/// `within` encloses segment ∩ triangle (exact f64 bounds): only the axes along which it is
/// not strictly inside the box found so far are computed and compared.
fn edge_face(acc: &mut ExactBox, p: DVec3, q: DVec3, tri: [DVec3; 3], within: &Aabb) {
    let [a, b, c] = tri;
    let (sp, sq) = (pr::orient3d(a, b, c, p), pr::orient3d(a, b, c, q));
    if sp * sq > 0 {
        return;
    }
    let f = acc.frame;
    let axes = acc.may_move(within);
    if sp == 0 && sq == 0 {
        coplanar(acc, p, q, tri, axes);
        return;
    }
    // The line crosses the plane once: inside the closed triangle iff the three orientations
    // of the line against the triangle's edges have no two opposite signs.
    let s = [pr::orient3d(p, q, a, b), pr::orient3d(p, q, b, c), pr::orient3d(p, q, c, a)];
    if s.contains(&1) && s.contains(&-1) {
        return;
    }
    let point = match (sp, sq) {
        (0, _) => vertex_point(&f, p, axes),
        (_, 0) => vertex_point(&f, q, axes),
        _ => {
            let (vp, vq) = exact::orient3d_two(&f, a, b, c, p, q);
            let d = vp.sub(&vq);
            along(&f, p, q, &vp, &d, axes)
        }
    };
    acc.add(point, axes);
}

/// Segment `p q` in the plane of the proper triangle `tri`: clip it to the triangle in the
/// projection that drops an axis the triangle is not parallel to, and add the ends.
/// Only the axes of `axes` are computed (see [`ExactBox::add`]).
fn coplanar(acc: &mut ExactBox, p: DVec3, q: DVec3, tri: [DVec3; 3], axes: [bool; 3]) {
    let f = acc.frame;
    let Some(axis) = (0..3).find(|&k| pr::orient2d(tri[0], tri[1], tri[2], k) != 0) else {
        return;
    };
    let s = pr::orient2d(tri[0], tri[1], tri[2], axis);
    // t in [lo, hi], as ratios n / d with d > 0.
    let (zero, one) = (Int::default(), Int::from_i64(1));
    let mut lo = Ratio::new(zero.clone(), one.clone());
    let mut hi = Ratio::new(one.clone(), one.clone());
    for k in 0..3 {
        let (u, v) = (tri[k], tri[(k + 1) % 3]);
        // g(t) = s · orient2d(u, v, p + t (q - p)) = gp + t (gq - gp) must be >= 0.
        let sign = Int::from_i64(s as i64);
        let gp = exact::orient2d(&f, u, v, p, axis).mul(&sign);
        let gq = exact::orient2d(&f, u, v, q, axis).mul(&sign);
        let slope = gq.sub(&gp);
        match slope.signum() {
            0 => {
                if gp.signum() < 0 {
                    return;
                }
            }
            1 => {
                // t >= -gp / slope
                let t = Ratio::new(gp.neg(), slope);
                if t.cmp_value(&lo).is_gt() {
                    lo = t;
                }
            }
            _ => {
                let t = Ratio::new(gp.neg(), slope);
                if t.cmp_value(&hi).is_lt() {
                    hi = t;
                }
            }
        }
    }
    if lo.cmp_value(&hi).is_gt() {
        return;
    }
    for t in [lo, hi] {
        acc.add(along(&f, p, q, &t.num, &t.den, axes), axes);
    }
}

/// Is `v` inside or on the closed part `m` (tree `t`)? None when undecided.
fn inside_or_on<M: TriMesh + ?Sized, T: Tree + ?Sized>(v: DVec3, m: &M, t: &T) -> Option<bool> {
    if !t.root_box().contains(&Aabb { min: v, max: v }) {
        return Some(false);
    }
    if containment::on_surface(v, m, t) {
        return Some(true);
    }
    match containment::point_in_closed_mesh(v, m, t) {
        Inside::Yes => Some(true),
        Inside::No => Some(false),
        Inside::Undecided => None,
    }
}

/// The exact box of A ∩ B for two closed parts `a` and `b` with trees `ta` and `tb` over their
/// triangles; None when they do not overlap (not even touch), or when a vertex's inside test
/// cannot be decided. See the module docs.
pub fn overlap_box<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB) -> Option<Overlap>
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    if !ta.root_box().overlaps(&tb.root_box()) {
        return None;
    }
    let frame = Frame::of_points(a.positions().iter().chain(b.positions().iter()));
    // Every 8th run of triangles first, from nothing; then the rest from the box they found,
    // so most edges of the rest lie strictly inside it and need no tree walk.
    let empty = ExactBox::new(frame);
    let mut acc = if a.triangle_count() <= EDGE_RUN as usize && b.triangle_count() <= EDGE_RUN as usize {
        // One run each: nothing to spread over threads, and B's edges start from the box A's
        // found (more of them are skipped than from nothing).
        let from_a = edges_against(&empty, a, (b, tb), |_| true);
        edges_against(&from_a, b, (a, ta), |_| true)
    } else {
        let seed = |r: u32| r.is_multiple_of(8);
        let rest = |r: u32| !r.is_multiple_of(8);
        let (sa, sb) = rayon::join(
            || edges_against(&empty, a, (b, tb), seed),
            || edges_against(&empty, b, (a, ta), seed),
        );
        let seeded = sa.merge(sb);
        let (ra, rb) = rayon::join(
            || edges_against(&seeded, a, (b, tb), rest),
            || edges_against(&seeded, b, (a, ta), rest),
        );
        ra.merge(rb)
    };
    let mut cand = Vec::new();
    candidates(&acc, 0, a, &tb.root_box(), &mut cand);
    candidates(&acc, 1, b, &ta.root_box(), &mut cand);
    if cand.is_empty() {
        return acc.finish();
    }
    let (meet_a, meet_b) = meeting(a, ta, b, tb);
    let (sides_a, sides_b) = rayon::join(|| Sides::new(a, &meet_a), || Sides::new(b, &meet_b));
    let inside_a = |v: u32| sides_a.inside(a, v, |p| inside_or_on(p, b, tb));
    let inside_b = |v: u32| sides_b.inside(b, v, |p| inside_or_on(p, a, ta));
    vertices_inside(&mut acc, &cand, [&sides_a, &sides_b], [&inside_a, &inside_b])?;
    acc.finish()
}

/// Which triangles of A and of B may meet the other part's surface: those whose box meets the
/// box of a triangle of the other part's tree (a superset of the crossing and touching ones).
/// A triangle left out has no point on the other part's surface.
fn meeting<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB) -> (Vec<bool>, Vec<bool>)
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let found = traverse::fold_pairs(
        ta,
        tb,
        |x, y| x.overlaps(y),
        || (Vec::new(), Vec::new()),
        |la, lb, (ma, mb): &mut (Vec<u32>, Vec<u32>)| {
            let boxes_b: Vec<Aabb> = lb.iter().map(|&u| Aabb::of_triangle(&b.triangle(u))).collect();
            let mut hit_b = vec![false; lb.len()];
            for &t in la {
                let bt = Aabb::of_triangle(&a.triangle(t));
                let mut hit = false;
                for (k, bu) in boxes_b.iter().enumerate() {
                    if bt.overlaps(bu) {
                        hit = true;
                        hit_b[k] = true;
                    }
                }
                if hit {
                    ma.push(t);
                }
            }
            mb.extend(lb.iter().zip(&hit_b).filter(|(_, &h)| h).map(|(&u, _)| u));
        },
        |(mut a0, mut b0), (a1, b1)| {
            a0.extend(a1);
            b0.extend(b1);
            (a0, b0)
        },
    );
    let mark = |n: usize, ts: Vec<u32>| {
        let mut m = vec![false; n];
        ts.into_iter().for_each(|t| m[t as usize] = true);
        m
    };
    (mark(a.triangle_count(), found.0), mark(b.triangle_count(), found.1))
}

/// The vertices of a closed part grouped by the side of the other part's surface they lie on.
///
/// A triangle with no point on the other part's surface is connected, so all its points lie on
/// one side: inside, or outside. The vertices of the triangles that do not meet the other part
/// ([`meeting`]) are joined through those triangles into classes that share the answer of the
/// exact point-in-solid test, asked once per class. A vertex of meeting triangles only is a
/// class of its own (it may lie on the other part's surface) and gets its own test. The
/// answers are the exact ones, so the box is the one every vertex tested on its own would give.
struct Sides {
    /// Per vertex, the representative of its class.
    class: Vec<u32>,
    /// Per representative, the answer once asked (None: undecided for every member).
    answer: Vec<std::sync::OnceLock<Option<bool>>>,
}

impl Sides {
    fn new<M: TriMesh + ?Sized>(m: &M, meets: &[bool]) -> Sides {
        let n = m.vertex_count();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        for t in 0..m.triangle_count() as u32 {
            if meets[t as usize] {
                continue;
            }
            let [x, y, z] = m.indices(t);
            union(&mut parent, x, y);
            union(&mut parent, x, z);
        }
        let class: Vec<u32> = (0..n as u32).map(|v| find(&mut parent, v)).collect();
        Sides { class, answer: (0..n).map(|_| std::sync::OnceLock::new()).collect() }
    }

    /// Is vertex `v` inside or on the other part? `test` is the exact point test; it is asked
    /// of `v` first and, when it cannot decide, of the other members of the class in vertex
    /// order, so the answer is the same whichever member asks first. Members asking at once
    /// wait for the first (a lock per class): `test` must not wait for other rayon tasks (the
    /// point test and the lazy tree's cells run on the calling thread alone).
    fn inside<M: TriMesh + ?Sized>(
        &self,
        m: &M,
        v: u32,
        test: impl Fn(DVec3) -> Option<bool>,
    ) -> Option<bool> {
        let c = self.class[v as usize];
        *self.answer[c as usize].get_or_init(|| {
            test(m.vertex(v)).or_else(|| {
                (0..self.class.len() as u32)
                    .filter(|&w| w != v && self.class[w as usize] == c)
                    .find_map(|w| test(m.vertex(w)))
            })
        })
    }

    /// The answer of `v`'s class if it was asked already.
    fn known(&self, v: u32) -> Option<Option<bool>> {
        self.answer[self.class[v as usize] as usize].get().copied()
    }
}

/// Triangles per run of [`edges_against`] (a cost setting only: the box is the same for any).
const EDGE_RUN: u32 = 4096;

/// The points where the edges of `m` meet the faces of `other` (tree `tree`), added to a copy
/// of `start`.
///
/// Every such point lies on its edge and in its triangle, so inside the f64 boxes of both: an
/// edge (or an edge–triangle pair) whose box lies strictly inside the box found so far cannot
/// move it and is skipped without a tree walk (or without exact arithmetic). The skipped
/// points would not have changed any bound, so the box is the same; only work is saved. Runs
/// of triangles go in parallel, each into its own box, and the boxes are merged: the exact box
/// of all the points whatever the split. An edge shared by two triangles is visited from both
/// (the same points twice change nothing).
fn edges_against<M, O, T>(
    start: &ExactBox,
    m: &M,
    (other, tree): (&O, &T),
    runs: impl Fn(u32) -> bool + Sync,
) -> ExactBox
where
    M: TriMesh + ?Sized,
    O: TriMesh + ?Sized,
    T: Tree + ?Sized,
{
    use rayon::prelude::*;
    const RUN: u32 = EDGE_RUN;
    let other_box = tree.root_box();
    let n = m.triangle_count() as u32;
    let run = |first: u32| {
        let mut acc = start.clone();
        for t in first..(first + RUN).min(n) {
            let v = m.indices(t);
            let mut is_proper = None;
            for k in 0..3 {
                let (p, q) = (m.vertex(v[k]), m.vertex(v[(k + 1) % 3]));
                let seg = Aabb { min: p.min(q), max: p.max(q) };
                if !seg.overlaps(&other_box) || acc.strictly_contains(&seg) {
                    continue;
                }
                if !*is_proper.get_or_insert_with(|| proper(m, t)) {
                    break;
                }
                traverse::any_in_box(tree, &seg, |t| {
                    let tri = other.triangle(t);
                    let tb = Aabb::of_triangle(&tri);
                    let common = Aabb { min: seg.min.max(tb.min), max: seg.max.min(tb.max) };
                    if !acc.strictly_contains(&common) && proper(other, t) {
                        edge_face(&mut acc, p, q, tri, &common);
                    }
                    false
                });
            }
        }
        acc
    };
    (0..n.div_ceil(RUN))
        .into_par_iter()
        .filter(|&r| runs(r))
        .map(|r| run(r * RUN))
        .reduce(|| start.clone(), ExactBox::merge)
}

/// Into `out`: the vertices of `m` (part `s`; of its proper triangles) outside the box so far
/// and inside the other part's box `other_box`, as (part, vertex, point). Only the triangles
/// at such vertices are asked whether they are proper.
fn candidates<M: TriMesh + ?Sized>(
    acc: &ExactBox,
    s: usize,
    m: &M,
    other_box: &Aabb,
    out: &mut Vec<(usize, u32, DVec3)>,
) {
    // 0: unused or cannot move the box, 1: a candidate if a proper triangle uses it, 2: one does.
    let mut state = vec![0u8; m.vertex_count()];
    for t in 0..m.triangle_count() as u32 {
        m.indices(t).iter().for_each(|&v| state[v as usize] = 1);
    }
    for (v, st) in state.iter_mut().enumerate() {
        let p = m.vertex(v as u32);
        if *st == 1 && (acc.strictly_inside(p) || !other_box.contains(&Aabb { min: p, max: p })) {
            *st = 0;
        }
    }
    for t in 0..m.triangle_count() as u32 {
        let v = m.indices(t);
        if v.iter().any(|&v| state[v as usize] == 1) && proper(m, t) {
            for &v in &v {
                if state[v as usize] == 1 {
                    state[v as usize] = 2;
                }
            }
        }
    }
    out.extend((0..state.len()).filter(|&v| state[v] == 2).map(|v| (s, v as u32, m.vertex(v as u32))));
}

/// Add the vertices of A inside or on B and of B inside or on A that can move a bound; None
/// when one of those cannot be decided.
///
/// `cand` is from [`candidates`] (only those vertices can move the box) and `inside_other[s]`
/// tests a vertex of part `s` against the other part, once per class of `sides[s]` ([`Sides`]):
/// a vertex whose class was answered already costs no query. For each side of each axis, those beyond
/// that side are taken from the most extreme inwards: the first one inside fixes the side
/// (every later one lies at or inside it), and an undecided one met before it leaves no box.
/// They are tested in batches, each batch's queries in parallel: one vertex first (a side
/// whose extreme vertex is inside costs one point query), then twice as many each time up to
/// [`INSIDE_BATCH`]; vertices that cannot move any side cost none. Each answer is kept, so no
/// vertex is tested twice, and the answers are read in the order above: the first inside
/// vertex and the first undecided one are those a one-by-one pass would meet, whatever the
/// batches. The box is the box of all inside vertices, as if every vertex were tested.
fn vertices_inside(
    acc: &mut ExactBox,
    cand: &[(usize, u32, DVec3)],
    sides: [&Sides; 2],
    inside_other: [&(dyn Fn(u32) -> Option<bool> + Sync); 2],
) -> Option<()> {
    use rayon::prelude::*;
    const UNTESTED: u8 = 0;
    const INSIDE: u8 = 1;
    const UNDECIDED: u8 = 3;
    let mut state = vec![UNTESTED; cand.len()];
    for k in 0..3 {
        for upper in [false, true] {
            // Beyond the side now (the side only moves outwards, so this is a superset of the
            // candidates beyond it later), most extreme first; ties by part and vertex.
            let beyond =
                |p: DVec3, acc: &ExactBox| if upper { p[k] > acc.inner[k].1 } else { p[k] < acc.inner[k].0 };
            let mut order: Vec<usize> = (0..cand.len()).filter(|&i| beyond(cand[i].2, acc)).collect();
            order.sort_unstable_by(|&i, &j| {
                let (x, y) = (cand[i].2[k], cand[j].2[k]);
                let by = if upper { y.total_cmp(&x) } else { x.total_cmp(&y) };
                by.then((cand[i].0, cand[i].1).cmp(&(cand[j].0, cand[j].1)))
            });
            let (mut at, mut size) = (0, 1);
            'side: while at < order.len() {
                let batch = &order[at..(at + size).min(order.len())];
                let code = |a: Option<bool>| match a {
                    Some(true) => INSIDE,
                    Some(false) => 2,
                    None => UNDECIDED,
                };
                let mut todo = Vec::new();
                for &i in batch {
                    if state[i] != UNTESTED {
                        continue;
                    }
                    match sides[cand[i].0].known(cand[i].1) {
                        Some(a) => state[i] = code(a),
                        None => todo.push(i),
                    }
                }
                let answers: Vec<u8> = if todo.len() > 1 {
                    todo.par_iter().map(|&i| code(inside_other[cand[i].0](cand[i].1))).collect()
                } else {
                    todo.iter().map(|&i| code(inside_other[cand[i].0](cand[i].1))).collect()
                };
                for (&i, answer) in todo.iter().zip(answers) {
                    state[i] = answer;
                }
                for &i in batch {
                    match state[i] {
                        INSIDE => {
                            acc.add_vertex(cand[i].2);
                            break 'side;
                        }
                        UNDECIDED => return None,
                        _ => {}
                    }
                }
                at += batch.len();
                size = (size * 2).min(INSIDE_BATCH);
            }
        }
    }
    Some(())
}

/// The most candidate vertices [`vertices_inside`] tests at once (a cost setting only: the box
/// is the same for any).
const INSIDE_BATCH: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildOptions, Bvh};
    use crate::scene::mesh::{Mesh, Object};

    /// An axis-aligned box with each face cut into `n × n` squares of two triangles, outward.
    fn grid_box(min: DVec3, max: DVec3, n: usize) -> Mesh {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for axis in 0..3 {
            for side in 0..2 {
                let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
                let at = |u: usize, v: usize| {
                    let mut p = DVec3::ZERO;
                    p[axis] = if side == 0 { min[axis] } else { max[axis] };
                    // Ends exact; inner points rounded within the face's plane (same solid).
                    let lerp = |k: usize, w: usize| {
                        if w == n {
                            max[k]
                        } else {
                            min[k] + (max[k] - min[k]) * w as f64 / n as f64
                        }
                    };
                    p[i] = lerp(i, u);
                    p[j] = lerp(j, v);
                    p
                };
                let start = positions.len() as u32;
                for u in 0..=n {
                    for v in 0..=n {
                        positions.push(at(u, v));
                    }
                }
                let id = |u: usize, v: usize| start + (u * (n + 1) + v) as u32;
                for u in 0..n {
                    for v in 0..n {
                        let (a, b, c, d) = (id(u, v), id(u + 1, v), id(u + 1, v + 1), id(u, v + 1));
                        if side == 1 {
                            triangles.extend([[a, b, c], [a, c, d]]);
                        } else {
                            triangles.extend([[a, c, b], [a, d, c]]);
                        }
                    }
                }
            }
        }
        let t = triangles.len();
        Mesh { positions, triangles, tri_object: vec![0; t], objects: vec![Object::default()] }
    }

    fn boxed(a: &Mesh, b: &Mesh) -> Option<Overlap> {
        let (ta, tb) = (Bvh::build(a, BuildOptions::default()), Bvh::build(b, BuildOptions::default()));
        overlap_box(a, &ta, b, &tb)
    }

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// The box with nothing skipped: every edge against every face, every vertex tested.
    fn brute(a: &Mesh, b: &Mesh) -> Option<Overlap> {
        let (ta, tb) = (Bvh::build(a, BuildOptions::default()), Bvh::build(b, BuildOptions::default()));
        let mut acc = ExactBox::new(Frame::of_points(a.positions.iter().chain(b.positions.iter())));
        for (m, o, to) in [(a, b, &tb), (b, a, &ta)] {
            for t in 0..m.triangles.len() as u32 {
                let v = m.indices(t);
                for k in 0..3 {
                    for u in 0..o.triangles.len() as u32 {
                        let all = Aabb { min: DVec3::NEG_INFINITY, max: DVec3::INFINITY };
                        edge_face(&mut acc, m.vertex(v[k]), m.vertex(v[(k + 1) % 3]), o.triangle(u), &all);
                    }
                }
            }
            for &p in &m.positions {
                if inside_or_on(p, o, to)? {
                    acc.add_vertex(p);
                }
            }
        }
        acc.finish()
    }

    #[test]
    fn skipping_edges_and_vertices_gives_the_brute_force_box() {
        let a = grid_box(v(0.0, 0.0, 0.0), v(2.0, 1.0, 1.0), 3);
        for (i, off) in [v(0.5, 0.25, -0.5), v(-1.0, 0.5, 0.5), v(1.5, -0.5, 0.25), v(0.25, 0.25, 0.25)]
            .into_iter()
            .enumerate()
        {
            // A tilted tetrahedron moved to each offset.
            let t = Mesh {
                positions: [v(0.0, 0.0, 0.0), v(1.5, 0.25, 0.0), v(0.25, 1.25, 0.1), v(0.3, 0.2, 1.1)]
                    .map(|p| p + off)
                    .to_vec(),
                triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
                tri_object: vec![0; 4],
                objects: vec![Object::default()],
            };
            assert!(brute(&a, &t).is_some(), "offset {i}: they overlap");
            assert_eq!(boxed(&a, &t), brute(&a, &t), "offset {i}");
            assert_eq!(boxed(&t, &a), brute(&a, &t), "offset {i}");
        }
    }

    #[test]
    fn boxes_overlap_in_their_common_box_at_every_tessellation() {
        for n in [1, 2, 3, 5] {
            for m in [1, 4] {
                let a = grid_box(v(0.0, 0.0, 0.0), v(2.0, 1.0, 1.0), n);
                let b = grid_box(v(0.5, 0.4, -1.0), v(3.0, 0.7, 0.6), m);
                let want = Overlap { min: v(0.5, 0.4, 0.0), max: v(2.0, 0.7, 0.6) };
                assert_eq!(boxed(&a, &b), Some(want), "n={n} m={m}");
                assert_eq!(boxed(&b, &a), Some(want), "n={n} m={m}");
            }
        }
    }

    #[test]
    fn nested_touching_and_apart() {
        let outer = grid_box(v(0.0, 0.0, 0.0), v(4.0, 4.0, 4.0), 2);
        let inner = grid_box(v(1.0, 1.5, 1.0), v(2.0, 2.0, 3.0), 3);
        let want = Overlap { min: v(1.0, 1.5, 1.0), max: v(2.0, 2.0, 3.0) };
        assert_eq!(boxed(&outer, &inner), Some(want));
        assert_eq!(boxed(&inner, &outer), Some(want));
        // Face to face: A ∩ B is the shared square (flat).
        let side = grid_box(v(4.0, 1.0, 1.0), v(5.0, 2.0, 2.0), 1);
        assert_eq!(boxed(&outer, &side), Some(Overlap { min: v(4.0, 1.0, 1.0), max: v(4.0, 2.0, 2.0) }));
        let apart = grid_box(v(5.0, 1.0, 1.0), v(6.0, 2.0, 2.0), 1);
        assert_eq!(boxed(&outer, &apart), None);
    }

    #[test]
    fn tilted_crossing_points_are_rounded_once() {
        // A box against a tetrahedron whose edges cross the box's faces at thirds.
        let a = grid_box(v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0), 1);
        let b = Mesh {
            positions: vec![v(0.5, 0.5, 0.5), v(3.5, 0.5, 0.5), v(0.5, 2.0, 0.5), v(0.5, 0.5, 1.25)],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            tri_object: vec![0; 4],
            objects: vec![Object::default()],
        };
        // The tetrahedron has its right-angle corner at (0.5, 0.5, 0.5) and reaches past the
        // box on every axis there, so A ∩ B spans [0.5, 1]³.
        let o = boxed(&a, &b).unwrap();
        assert_eq!(o, Overlap { min: v(0.5, 0.5, 0.5), max: v(1.0, 1.0, 1.0) });
        let inv = Mesh { triangles: b.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(), ..b.clone() };
        assert_eq!(boxed(&inv, &a), Some(o));
        // A tetrahedron sliced by a slab 1 <= x <= 2: the y extremes are crossings at thirds.
        let t = Mesh {
            positions: vec![v(0.0, 0.0, 0.0), v(3.0, 1.0, 0.0), v(3.0, -1.0, 0.0), v(0.0, 0.0, 3.0)],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            tri_object: vec![0; 4],
            objects: vec![Object::default()],
        };
        let slab = grid_box(v(1.0, -5.0, -5.0), v(2.0, 5.0, 5.0), 2);
        let want = Overlap { min: v(1.0, -2.0 / 3.0, 0.0), max: v(2.0, 2.0 / 3.0, 2.0) };
        assert_eq!(boxed(&t, &slab), Some(want));
        assert_eq!(boxed(&slab, &t), Some(want));
    }

    /// A closed solid of kind `kind` (a box cut into a grid, a torus, or a tilted tetrahedron)
    /// scaled by `scale`, turned by `turn` about z and moved by `at`; with `snap` (boxes and
    /// tetrahedra), every coordinate is rounded to a multiple of 1/8, so vertices land exactly
    /// on the other part's faces, edges and vertices, and faces coincide.
    fn solid(kind: u8, scale: f64, turn: f64, at: [f64; 3], snap: bool) -> Mesh {
        let mut m = match kind {
            0 => grid_box(v(-0.5, -0.5, -0.5), v(0.5, 0.5, 0.5), 2),
            1 => crate::testing::gen::torus(96),
            _ => Mesh {
                positions: vec![
                    v(-0.5, -0.5, -0.5),
                    v(0.75, -0.25, -0.5),
                    v(-0.25, 0.75, -0.4),
                    v(-0.3, -0.2, 0.6),
                ],
                triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
                tri_object: vec![0; 4],
                objects: vec![Object::default()],
            },
        };
        let (s, c) = turn.sin_cos();
        for p in &mut m.positions {
            let q = *p * scale;
            *p = v(c * q.x - s * q.y + at[0], s * q.x + c * q.y + at[1], q.z + at[2]);
            if snap && kind != 1 {
                *p = (*p * 8.0).round() / 8.0;
            }
        }
        m
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// Deciding vertices a class at a time gives the box of every edge against every face
        /// and every vertex tested on its own, bit for bit, in both part orders.
        #[test]
        fn random_closed_parts_give_the_brute_force_box(
            kinds in (0u8..3, 0u8..3),
            scales in (0.5f64..2.0, 0.5f64..2.0),
            turns in (0.0f64..3.2, 0.0f64..3.2),
            at in [-1.0f64..1.0, -1.0f64..1.0, -0.6f64..0.6],
            snap in proptest::bool::ANY,
        ) {
            let a = solid(kinds.0, scales.0, turns.0, [0.0; 3], snap);
            let b = solid(kinds.1, scales.1, turns.1, at, snap);
            let want = brute(&a, &b);
            proptest::prop_assert_eq!(boxed(&a, &b), want);
            proptest::prop_assert_eq!(boxed(&b, &a), want);
        }
    }
}
