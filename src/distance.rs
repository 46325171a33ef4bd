//! Closed-form distance kernels between points, segments and triangles (all `f64`).
//!
//! - Point–triangle: the Voronoi-region classification of Ericson, *Real-Time Collision
//!   Detection* (2005), §5.1.5.
//! - Segment–segment: the clamped parametric method of Ericson (2005), §5.1.9. The line–line
//!   parameter `(b·f − c·e) / (a·e − b²)` is evaluated through the Lagrange identities
//!   `a·e − b² = |d1×d2|²` and `b·f − c·e = (d1×d2)·(d2×r)`: cross products keep their accuracy
//!   for nearly parallel segments, where the dot-product form cancels catastrophically.
//! - Triangle–triangle: the minimum over 6 vertex–triangle and 9 edge–edge candidates, the
//!   decomposition of Larsen, Gottschalk, Lin & Manocha, *Fast proximity queries with swept
//!   sphere volumes* (1999), as implemented in PQP (`TriDist`).
//!
//! No tolerance is used: zero-length and parallel cases are detected with exact `<= 0.0`
//! tests on squared lengths, each with a well-defined branch. Every candidate is an actual
//! pair of points on the two inputs, so every reported distance is (up to rounding) attained.
//! Everything is deterministic: no allocation, parallelism or hashing, and ties go to the first
//! candidate in a documented order. Inputs must be finite.

use glam::DVec3;

/// Closest point on segment `[a, b]` to `p`; `a` when the segment has zero length.
#[inline]
fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    if len2 <= 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// Closest point to `p` over the edges `ab`, `bc`, `ca` (first in that order on ties).
fn closest_on_edges(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let mut best = closest_on_segment(p, a, b);
    let mut best_d2 = (p - best).length_squared();
    for (s, e) in [(b, c), (c, a)] {
        let q = closest_on_segment(p, s, e);
        let d2 = (p - q).length_squared();
        if d2 < best_d2 {
            best = q;
            best_d2 = d2;
        }
    }
    best
}

/// `num / den` when `den > 0`, else `0` (the caller's branch guarantees `0 <= num <= den`).
#[inline]
fn ratio(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// Closest point on triangle (a,b,c) to p. Works for degenerate triangles (collinear or repeated
/// vertices): then it is the closest point on the segment / the point.
///
/// Ericson §5.1.5: vertex regions, then edge regions, then the face. A triangle whose normal
/// `(b−a)×(c−a)` is exactly zero is handled as the union of its three edges. If rounding makes
/// the face weights inconsistent (a negative weight or a non-positive sum, possible only for a
/// triangle whose area is at rounding level), the edges are used as well. The result is always a
/// point of the triangle, up to rounding.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    if ab.cross(ac) == DVec3::ZERO {
        return closest_on_edges(p, a, b, c);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * ratio(d1, d1 - d3);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * ratio(d2, d2 - d6);
    }
    let va = d3 * d6 - d5 * d4;
    let (e4, e5) = (d4 - d3, d5 - d6);
    if va <= 0.0 && e4 >= 0.0 && e5 >= 0.0 {
        return b + (c - b) * ratio(e4, e4 + e5);
    }
    let sum = va + vb + vc;
    if va >= 0.0 && vb >= 0.0 && vc >= 0.0 && sum > 0.0 {
        return a + ab * (vb / sum) + ac * (vc / sum);
    }
    closest_on_edges(p, a, b, c)
}

/// Ericson §5.1.9 without canonical ordering; see [`closest_points_segments`].
#[inline]
fn segments_raw(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> (DVec3, DVec3) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let (s, t);
    if a <= 0.0 {
        if e <= 0.0 {
            return (p1, p2);
        }
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 0.0 {
            s = (-c / a).clamp(0.0, 1.0);
            t = 0.0;
        } else {
            let b = d1.dot(d2);
            let n = d1.cross(d2);
            let denom = n.dot(n); // = a·e − b², exactly 0 only for parallel segments
            let s0 = if denom > 0.0 {
                (n.dot(d2.cross(r)) / denom).clamp(0.0, 1.0)
            } else {
                0.0 // parallel: any s works as a start, the clamping below fixes t and then s
            };
            let t_num = b * s0 + f;
            if t_num < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t_num > e {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t_num / e;
                s = s0;
            }
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}

/// `true` when segment `x` precedes segment `y` in the lexicographic order of their coordinates
/// (`f64::total_cmp`), used to make the segment query exactly symmetric.
#[inline]
fn seg_precedes(x: [DVec3; 2], y: [DVec3; 2]) -> bool {
    for k in 0..2 {
        for (u, v) in x[k].to_array().into_iter().zip(y[k].to_array()) {
            match u.total_cmp(&v) {
                std::cmp::Ordering::Less => return true,
                std::cmp::Ordering::Greater => return false,
                std::cmp::Ordering::Equal => {}
            }
        }
    }
    false
}

/// Closest points between segments [p1,q1] and [p2,q2] (either may have zero length).
/// Returns (point on first, point on second).
///
/// Ericson §5.1.9: the closest points of the two lines, clamped to the first segment, the
/// second parameter recomputed and clamped, and the first recomputed if that clamp was active.
/// Zero-length segments are detected by `|d|² <= 0`; parallel ones by `|d1×d2|² <= 0`, in which
/// case the search starts from `p1` (any start gives a correct closest pair for parallel
/// segments). The pair is computed with the lexicographically smaller segment first, so
/// swapping the arguments swaps the result bit for bit.
pub fn closest_points_segments(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> (DVec3, DVec3) {
    if seg_precedes([p2, q2], [p1, q1]) {
        let (y, x) = segments_raw(p2, q2, p1, q1);
        (x, y)
    } else {
        segments_raw(p1, q1, p2, q2)
    }
}

/// Result of a triangle–triangle distance query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriDistance {
    /// Euclidean distance `|on_a − on_b|` between the witness points.
    pub distance: f64,
    /// Witness point on the first triangle.
    pub on_a: DVec3,
    /// Witness point on the second triangle.
    pub on_b: DVec3,
}

/// In-plane edge normals `n×e_i` of triangle `t`, with `e_i = t[i+1] − t[i]` and
/// `n = e_0 × (t[2] − t[0])`; all zero for a triangle whose normal is exactly zero.
#[inline]
fn edge_normals(t: &[DVec3; 3]) -> [DVec3; 3] {
    let e = [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
    let n = e[0].cross(t[2] - t[0]);
    [n.cross(e[0]), n.cross(e[1]), n.cross(e[2])]
}

/// Orthogonal projection of `p` onto the plane of `t` if it falls inside `t` (boundary
/// included), as the convex combination of the vertices with the projection's barycentric
/// weights, so the returned point is a point of `t`. `None` otherwise or when the weights sum to
/// `<= 0` (zero-area triangle, whose candidates the edge–edge pairs already cover).
#[inline]
fn face_candidate(t: &[DVec3; 3], m: &[DVec3; 3], p: DVec3) -> Option<DVec3> {
    // u_i = n·(e_{i+1} × (p − t_{i+1})): twice the area opposite t_i, times |n|.
    let u0 = m[1].dot(p - t[1]);
    if u0 < 0.0 {
        return None;
    }
    let u1 = m[2].dot(p - t[2]);
    if u1 < 0.0 {
        return None;
    }
    let u2 = m[0].dot(p - t[0]);
    if u2 < 0.0 {
        return None;
    }
    let sum = u0 + u1 + u2;
    if sum <= 0.0 {
        return None;
    }
    Some((t[0] * u0 + t[1] * u1 + t[2] * u2) / sum)
}

/// Distance between two triangles that do NOT intersect (the caller decides intersection exactly
/// elsewhere and uses 0 then), with witness points on each triangle: the minimum over the 6
/// vertex–triangle and 9 edge–edge candidates. Degenerate triangles (segments, points) work.
///
/// Candidates, in tie-breaking order (the first minimum wins):
/// 1. the 9 edge pairs, `a`'s edges outer and `b`'s inner, edge `i` being `[t[i], t[(i+1)%3]]`
///    ([`closest_points_segments`]);
/// 2. `b[0]`, `b[1]`, `b[2]` against the face of `a`, then `a[0]`, `a[1]`, `a[2]` against the face
///    of `b`, each only when the vertex projects inside that face.
///
/// A vertex whose closest point on the other triangle lies on an edge is covered by the edge
/// pairs, so vertex–triangle candidates need only the face interior; for a zero-area triangle
/// the edge pairs alone cover everything. Squared distances are compared and one `sqrt` taken,
/// so `distance == |on_a − on_b|`. `distance` is bitwise symmetric:
/// `triangle_distance(b, a).distance == triangle_distance(a, b).distance` (the witnesses swap,
/// except that exact ties may resolve to a different pair).
///
/// If the triangles do intersect, the true distance is 0 but the result is still the minimum of
/// these same 15 candidates: `distance >= 0`, `on_a` is a point of `a` and `on_b` a point of
/// `b`, and `distance == |on_a − on_b|`, so it is a valid (if useless) upper bound. It is 0 when
/// the boundaries touch (edges crossing, a vertex on the other triangle) and in general positive
/// when an edge pierces the other triangle's interior, which no candidate measures.
pub fn triangle_distance(a: &[DVec3; 3], b: &[DVec3; 3]) -> TriDistance {
    let mut best = f64::INFINITY;
    let (mut on_a, mut on_b) = (a[0], b[0]);
    let mut consider = |x: DVec3, y: DVec3| {
        let d2 = (x - y).length_squared();
        if d2 < best {
            best = d2;
            on_a = x;
            on_b = y;
        }
    };
    for i in 0..3 {
        let (p1, q1) = (a[i], a[(i + 1) % 3]);
        for j in 0..3 {
            let (x, y) = closest_points_segments(p1, q1, b[j], b[(j + 1) % 3]);
            consider(x, y);
        }
    }
    let ma = edge_normals(a);
    for &p in b {
        if let Some(q) = face_candidate(a, &ma, p) {
            consider(q, p);
        }
    }
    let mb = edge_normals(b);
    for &p in a {
        if let Some(q) = face_candidate(b, &mb, p) {
            consider(p, q);
        }
    }
    TriDistance {
        distance: best.sqrt(),
        on_a,
        on_b,
    }
}
