//! The exact overlap boxes a report carries: for each clashing pair of closed parts, the box of
//! their common volume, and in two-file mode the box for two nested single-part files.

use super::*;

/// The exact overlap box of every clashing part pair of two closed parts (None for the other
/// pairs, and for the pairs `need` declines, by their index in `o.part_pairs`). Each part involved is copied and gets a tree once, however many pairs it is in; parts
/// and pairs run in parallel, and the answer does not depend on the thread count.
pub fn overlaps(
    o: &assembly::Outcome,
    a: &Mesh,
    b: &Mesh,
    scene: bool,
    opts: BuildOptions,
    need: impl Fn(usize) -> bool + Sync,
) -> Vec<Option<crate::check::overlap::Overlap>> {
    use rayon::prelude::*;
    let clashing =
        |(k, pp): &(usize, &assembly::PartPairSummary)| pp.verdict == query::Verdict::Clash && need(*k);
    let mut wanted: Vec<usize> = o
        .part_pairs
        .iter()
        .enumerate()
        .filter(clashing)
        .map(|(_, pp)| pp)
        .flat_map(|pp| [pp.a, pp.b])
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let solids: std::collections::HashMap<usize, Option<(Mesh, crate::bvh::Bvh)>> = wanted
        .par_iter()
        .map(|&i| {
            let part = &o.parts[i];
            let m = if part.input == 0 || scene { a } else { b };
            let mesh = m.sub_mesh(&part.triangles);
            let closed = crate::check::containment::topology(&mesh).closed;
            (
                i,
                closed.then(|| {
                    let tree = crate::bvh::Bvh::build(&mesh, opts);
                    (mesh, tree)
                }),
            )
        })
        .collect();
    o.part_pairs
        .par_iter()
        .enumerate()
        .map(|(k, pp)| {
            if pp.verdict != query::Verdict::Clash || !need(k) {
                return None;
            }
            let (Some(Some((ma, ta))), Some(Some((mb, tb)))) = (solids.get(&pp.a), solids.get(&pp.b)) else {
                return None;
            };
            crate::check::overlap::overlap_box(ma, ta, mb, tb)
        })
        .collect()
}

/// The exact box of A ∩ B in two-file mode when each file is one part, both closed, and they
/// clash by containment (one inside the other, or volumes overlapping through coincident faces)
/// while no part pair is a clash to carry the box (a single part per file gets no part pair
/// for a containment without meeting triangles); None otherwise.
pub fn files_overlap(
    o: &assembly::Outcome,
    a: &Mesh,
    b: &Mesh,
    scene: bool,
    opts: BuildOptions,
) -> Option<crate::check::overlap::Overlap> {
    let clashing_pair = o.part_pairs.iter().any(|pp| pp.verdict == query::Verdict::Clash);
    if scene || clashing_pair || !o.result.containment.is_clash() {
        return None;
    }
    let [pa, pb] = o.parts.as_slice() else { return None };
    if (pa.input, pb.input) != (0, 1) {
        return None;
    }
    let solid = |m: &Mesh, part: &assembly::Part| {
        let mesh = m.sub_mesh(&part.triangles);
        crate::check::containment::topology(&mesh).closed.then(|| {
            let tree = crate::bvh::Bvh::build(&mesh, opts);
            (mesh, tree)
        })
    };
    let (sa, sb) = rayon::join(|| solid(a, pa), || solid(b, pb));
    let ((ma, ta), (mb, tb)) = (sa?, sb?);
    crate::check::overlap::overlap_box(&ma, &ta, &mb, &tb)
}
