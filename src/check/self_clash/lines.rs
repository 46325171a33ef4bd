//! Groups of zero-area triangles on one line, counted instead of walked.
//!
//! A *line group* is a set of at least [`GROUP_MIN`] triangles of one part that are zero-area
//! segments (two or three distinct vertices, all on one line `L`: exact [`pr::collinear`]),
//! all on the same line `L`, and *isolated*: no merged vertex of a member is used by any other
//! triangle of the part. Two members share nothing, so by the rule of the module above they are a
//! self-clash pair iff the closed segments meet, and two closed segments on one line meet iff
//! their intervals along an axis on which `L` is not constant overlap: every point of `L` is
//! ordered along such an axis exactly as on `L`, so plain comparisons of the stored
//! coordinates decide it. Such a pair never crosses (segments have no interior to cross,
//! [`crate::narrow::tri_tri`]): it touches.
//!
//! So the pairs inside a group are counted by sorting the intervals (`m` members: the `m(m−1)/2`
//! pairs minus those whose intervals lie apart, `O(m log m)`), and only the first ones (by
//! triangle index) are listed, found with an interval query; the walk skips every pair of two
//! members (and every node pair whose triangles all belong to one group). Pairs of a member
//! with any other triangle are walked and tested as usual.
//!
//! Candidates are bucketed by a rounded key of their line (direction and foot point) only to
//! find groups quickly; membership is decided exactly (collinear with the group's first
//! member), so rounding can at worst split one line into several groups, whose pairs across
//! groups are then walked.

use crate::check::fans::Fans;
use crate::geom::predicates as pr;
use crate::geom::DVec3;
use crate::scene::mesh::Mesh;
use rayon::prelude::*;

/// Fewer candidates on one line than this are left to the walk.
pub const GROUP_MIN: usize = 16;

/// No group.
pub const NONE: u32 = u32::MAX;

/// One group: its members (local triangle numbers, ascending) and their intervals along `axis`.
struct Group {
    members: Vec<u32>,
    /// Per member (same order): the lowest and highest coordinate of its corners along the
    /// group's axis.
    spans: Vec<(f64, f64)>,
}

/// The line groups of one part.
pub struct LineGroups {
    /// Per local triangle: its group, or [`NONE`].
    group: Vec<u32>,
    groups: Vec<Group>,
}

/// The two extreme corners of a zero-area triangle with at least two distinct corners, along
/// the axis of the largest extent of its box (on which its line is not constant).
fn extremes(p: &[DVec3; 3]) -> (DVec3, DVec3, usize) {
    let lo = p[0].min(p[1]).min(p[2]);
    let hi = p[0].max(p[1]).max(p[2]);
    let axis = pr::line_axis(lo, hi);
    let mut a = p[0];
    let mut b = p[0];
    for &q in &p[1..] {
        if q[axis] < a[axis] {
            a = q;
        }
        if q[axis] > b[axis] {
            b = q;
        }
    }
    (a, b, axis)
}

impl LineGroups {
    /// The groups of the part made of triangles `tris` of `mesh` (with their fans), or `None`
    /// when there is none.
    pub fn new(mesh: &Mesh, tris: &[u32], fans: &Fans) -> Option<LineGroups> {
        let n = tris.len();
        if n < GROUP_MIN {
            return None;
        }
        let corners = |k: usize| crate::bvh::triangle(mesh, tris[k]);
        // Every corner at each of its vertices is its own (at most three).
        let isolated = |k: usize| {
            let ids = fans.ids[k];
            ids.iter().all(|&v| {
                let g = fans.group(v as usize);
                g.len() <= 3 && g.iter().all(|&e| e as usize / 3 == k)
            })
        };
        // One scale for rounding every foot point of the part.
        let scale = (0..n)
            .into_par_iter()
            .map(|k| corners(k).iter().map(|p| p.abs().max_element()).fold(1.0f64, f64::max))
            .reduce(|| 1.0, f64::max);
        let mut keyed: Vec<([i64; 7], u32)> = (0..n)
            .into_par_iter()
            .filter_map(|k| {
                let ids = fans.ids[k];
                if fans.proper(k) || (ids[0] == ids[1] && ids[1] == ids[2]) || !isolated(k) {
                    return None;
                }
                let (a, b, axis) = extremes(&corners(k));
                let d = (b - a).normalize();
                let foot = a - a.dot(d) * d;
                let q = |x: f64, unit: f64| (x / unit * 1048576.0).round() as i64;
                let key = [
                    axis as i64,
                    q(d.x, 1.0),
                    q(d.y, 1.0),
                    q(d.z, 1.0),
                    q(foot.x, scale),
                    q(foot.y, scale),
                    q(foot.z, scale),
                ];
                Some((key, k as u32))
            })
            .collect();
        if keyed.len() < GROUP_MIN {
            return None;
        }
        keyed.par_sort_unstable();
        let mut group = vec![NONE; n];
        let mut groups = Vec::new();
        let mut start = 0;
        while start < keyed.len() {
            let end = start + keyed[start..].iter().take_while(|e| e.0 == keyed[start].0).count();
            let run = &keyed[start..end];
            start = end;
            if run.len() < GROUP_MIN {
                continue;
            }
            // The run is sorted by index: its first member fixes the line.
            let (p0, q0, axis) = extremes(&corners(run[0].1 as usize));
            let members: Vec<u32> = run
                .par_iter()
                .filter(|&&(_, k)| {
                    let (p, q, _) = extremes(&corners(k as usize));
                    pr::collinear(p0, q0, p) && pr::collinear(p0, q0, q)
                })
                .map(|&(_, k)| k)
                .collect();
            if members.len() < GROUP_MIN {
                continue;
            }
            // In mesh order (the order pairs are listed in).
            let mut members = members;
            members.sort_unstable_by_key(|&k| tris[k as usize]);
            let spans = members
                .iter()
                .map(|&k| {
                    let p = corners(k as usize);
                    let (lo, hi) = (
                        p[0][axis].min(p[1][axis]).min(p[2][axis]),
                        p[0][axis].max(p[1][axis]).max(p[2][axis]),
                    );
                    (lo, hi)
                })
                .collect();
            for &k in &members {
                group[k as usize] = groups.len() as u32;
            }
            groups.push(Group { members, spans });
        }
        (!groups.is_empty()).then_some(LineGroups { group, groups })
    }

    /// The group of local triangle `k`, or [`NONE`].
    #[inline]
    pub fn of(&self, k: u32) -> u32 {
        self.group[k as usize]
    }

    /// Are local triangles `x` and `y` in one group (a pair counted here, not walked)?
    #[inline]
    pub fn same(&self, x: u32, y: u32) -> bool {
        let g = self.group[x as usize];
        g != NONE && g == self.group[y as usize]
    }

    /// The number of groups.
    pub fn len(&self) -> usize {
        self.groups.len()
    }

    /// The number of self-clash pairs inside group `g` (all touching).
    pub fn count(&self, g: usize) -> u64 {
        let spans = &self.groups[g].spans;
        let m = spans.len() as u64;
        let mut his: Vec<f64> = spans.iter().map(|s| s.1).collect();
        his.sort_unstable_by(f64::total_cmp);
        // A pair lies apart iff one interval ends strictly before the other begins; each such
        // pair is counted once, at the later one.
        let apart: u64 = spans.iter().map(|&(lo, _)| his.partition_point(|&h| h < lo) as u64).sum();
        m * (m - 1) / 2 - apart
    }

    /// The first self-clash pairs inside group `g` (local triangle numbers, lower mesh index
    /// first) in the order of their mesh indices: every pair whose lower member is among the
    /// first lower members, until at least `cap` are listed (or all of them).
    pub fn first_pairs(&self, g: usize, cap: usize) -> Vec<(u32, u32)> {
        let grp = &self.groups[g];
        let mut out = Vec::new();
        if cap == 0 {
            return out;
        }
        // Members by interval start; a max tree over their ends answers "every interval
        // starting at or before x whose end is at or after y" in time linear in the answer.
        let mut by_lo: Vec<usize> = (0..grp.members.len()).collect();
        by_lo.sort_unstable_by(|&i, &j| grp.spans[i].0.total_cmp(&grp.spans[j].0).then(i.cmp(&j)));
        let size = by_lo.len().next_power_of_two();
        let mut tree = vec![f64::NEG_INFINITY; 2 * size];
        for (x, &i) in by_lo.iter().enumerate() {
            tree[size + x] = grp.spans[i].1;
        }
        for x in (1..size).rev() {
            tree[x] = tree[2 * x].max(tree[2 * x + 1]);
        }
        let mut found = Vec::new();
        // Members are in mesh order, so `j > i` is the higher triangle.
        for (i, &a) in grp.members.iter().enumerate() {
            let (lo, hi) = grp.spans[i];
            let end = by_lo.partition_point(|&j| grp.spans[j].0 <= hi);
            found.clear();
            collect(&tree, 1, 0, size, end, lo, &mut found);
            let mut partners: Vec<u32> =
                found.iter().map(|&x| by_lo[x]).filter(|&j| j > i).map(|j| grp.members[j]).collect();
            partners.sort_unstable();
            out.extend(partners.into_iter().map(|b| (a, b)));
            if out.len() >= cap {
                break;
            }
        }
        out
    }
}

/// The positions `x < end` under tree node `node` (covering `lo..hi`) whose value is `>= at_least`.
fn collect(tree: &[f64], node: usize, lo: usize, hi: usize, end: usize, at_least: f64, out: &mut Vec<usize>) {
    if lo >= end || tree[node] < at_least {
        return;
    }
    if hi - lo == 1 {
        out.push(lo);
        return;
    }
    let mid = (lo + hi) / 2;
    collect(tree, 2 * node, lo, mid, end, at_least, out);
    collect(tree, 2 * node + 1, mid, hi, end, at_least, out);
}
