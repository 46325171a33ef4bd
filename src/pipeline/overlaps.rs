//! The exact overlap boxes a report carries: for each clashing pair of closed parts, the box of
//! their common volume, and in two-file mode the box for two nested single-part files.

use super::*;
use crate::bvh::lazy::LazyBvh;
use crate::bvh::traverse::Tree;
use std::borrow::Cow;
use std::sync::Arc;

/// The exact overlap box of every clashing part pair of two closed parts (None for the other
/// pairs, and for the pairs `need` declines, by their index in `o.part_pairs`). Each part involved gets a lazy tree once, however many pairs it is in (a part that is a whole
/// input is used in place, others are copied); parts
/// and pairs run in parallel, and the answer does not depend on the thread count.
pub fn overlaps(
    o: &assembly::Outcome,
    inputs: [&LoadedInput; 2],
    scene: bool,
    opts: BuildOptions,
    need: impl Fn(usize) -> bool + Sync,
) -> Vec<Option<crate::check::overlap::Overlap>> {
    use rayon::prelude::*;
    if inputs.iter().any(|i| i.instanced.is_some()) {
        return overlaps_placed(o, inputs, scene, opts, need);
    }
    let meshes: Vec<(usize, Cow<'_, Mesh>)> = clashing_parts(o, &need)
        .par_iter()
        .map(|&i| (i, input_part_mesh(inputs, scene, &o.parts[i])))
        .collect();
    let solids: std::collections::HashMap<usize, (&Mesh, PartTree<'_>)> = meshes
        .par_iter()
        .filter(|(_, mesh)| crate::check::containment::topology(mesh.as_ref()).closed)
        .map(|(i, mesh)| (*i, (mesh.as_ref(), PartTree::new(mesh.as_ref(), opts))))
        .collect();
    o.part_pairs
        .par_iter()
        .enumerate()
        .map(|(k, pp)| {
            if !clashing(k, pp, &need) {
                return None;
            }
            let (Some((ma, ta)), Some((mb, tb))) = (solids.get(&pp.a), solids.get(&pp.b)) else {
                return None;
            };
            crate::check::overlap::overlap_box(*ma, ta, *mb, tb)
        })
        .collect()
}

/// [`overlaps`] when a side is an instanced scene: whether each part is closed is decided once
/// per part (placed, then dropped); then each pair of closed parts has its two parts placed (a
/// worker keeps the last three it placed), builds their trees and drops them, so memory holds a
/// few parts per thread instead of every clashing part at once. The boxes are the same: a box
/// is a function of the two solids alone.
fn overlaps_placed(
    o: &assembly::Outcome,
    inputs: [&LoadedInput; 2],
    scene: bool,
    opts: BuildOptions,
    need: impl Fn(usize) -> bool + Sync,
) -> Vec<Option<crate::check::overlap::Overlap>> {
    use rayon::prelude::*;
    let copy = |i: usize| input_part_mesh(inputs, scene, &o.parts[i]);
    // Whether each part of a clashing pair is closed, each part placed once for it.
    let closed: std::collections::HashSet<usize> = clashing_parts(o, &need)
        .par_iter()
        .filter(|&&i| crate::check::containment::topology(copy(i).as_ref()).closed)
        .copied()
        .collect();
    // The part pairs are sorted by part, so a worker's consecutive pairs mostly share a part:
    // the last few placed are kept.
    let memo = WorkerMemo::new(3);
    let solid = |i: usize| memo.get(i, || Arc::new(copy(i).into_owned()));
    o.part_pairs
        .par_iter()
        .enumerate()
        .map(|(k, pp)| {
            if !clashing(k, pp, &need) || !closed.contains(&pp.a) || !closed.contains(&pp.b) {
                return None;
            }
            let (ma, mb) = (solid(pp.a), solid(pp.b));
            let (ma, mb): (&Mesh, &Mesh) = (&ma, &mb);
            let (ta, tb) = (PartTree::new(ma, opts), PartTree::new(mb, opts));
            crate::check::overlap::overlap_box(ma, &ta, mb, &tb)
        })
        .collect()
}

/// The values made last by each rayon worker, a few per worker, for work whose consecutive
/// items share keys. It lives for one computation, and a value is a function of its key alone,
/// so what it hands back is what making it again would give.
struct WorkerMemo<V> {
    keep: usize,
    slots: Vec<std::sync::Mutex<Kept<V>>>,
}

/// One worker's kept values, least recently used first.
type Kept<V> = Vec<(usize, Arc<V>)>;

impl<V> WorkerMemo<V> {
    fn new(keep: usize) -> Self {
        let workers = rayon::current_num_threads() + 1;
        WorkerMemo { keep, slots: (0..workers).map(|_| Default::default()).collect() }
    }

    /// The value of `key`, kept or made by `make` (outside the lock, so making may itself run in
    /// parallel).
    fn get(&self, key: usize, make: impl FnOnce() -> Arc<V>) -> Arc<V> {
        let last = self.slots.len() - 1;
        let worker = rayon::current_thread_index().map_or(last, |w| w.min(last));
        let slot = || self.slots[worker].lock().unwrap_or_else(|e| e.into_inner());
        {
            let mut kept = slot();
            if let Some(at) = kept.iter().position(|(k, _)| *k == key) {
                // The most recently used goes last: the first is the one to drop.
                let hit = kept.remove(at);
                let v = hit.1.clone();
                kept.push(hit);
                return v;
            }
        }
        let v = make();
        let mut kept = slot();
        if kept.len() == self.keep {
            kept.remove(0);
        }
        kept.push((key, v.clone()));
        v
    }
}

/// The exact box of A ∩ B in two-file mode when each file is one part, both closed, and they
/// clash by containment (one inside the other, or volumes overlapping through coincident faces)
/// while no part pair is a clash to carry the box (a single part per file gets no part pair
/// for a containment without meeting triangles); None otherwise.
pub fn files_overlap<'m>(
    o: &assembly::Outcome,
    a: &'m Mesh,
    b: &'m Mesh,
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
    let solid = |m: &'m Mesh, part: &assembly::Part| -> Option<Cow<'m, Mesh>> {
        let mesh = part_mesh(m, part);
        crate::check::containment::topology(mesh.as_ref()).closed.then_some(mesh)
    };
    let (sa, sb) = rayon::join(|| solid(a, pa), || solid(b, pb));
    let (ma, mb) = (sa?, sb?);
    let (ta, tb) = rayon::join(|| PartTree::new(ma.as_ref(), opts), || PartTree::new(mb.as_ref(), opts));
    crate::check::overlap::overlap_box(ma.as_ref(), &ta, mb.as_ref(), &tb)
}

/// Whether part pair `k` gets an overlap box: a clash that `need` asks for.
fn clashing(k: usize, pp: &assembly::PartPairSummary, need: &impl Fn(usize) -> bool) -> bool {
    pp.verdict == query::Verdict::Clash && need(k)
}

/// The parts of the pairs that get an overlap box ([`clashing`]), sorted, each once.
fn clashing_parts(o: &assembly::Outcome, need: &impl Fn(usize) -> bool) -> Vec<usize> {
    let mut parts: Vec<usize> = o
        .part_pairs
        .iter()
        .enumerate()
        .filter(|&(k, pp)| clashing(k, pp, need))
        .flat_map(|(_, pp)| [pp.a, pp.b])
        .collect();
    parts.sort_unstable();
    parts.dedup();
    parts
}

/// The part's triangles as a mesh of their own ([`part_mesh`]), from its input (in scene mode
/// the one input); a part of an instanced scene placed, as the same copy of the expanded mesh
/// would be.
fn input_part_mesh<'m>(inputs: [&'m LoadedInput; 2], scene: bool, part: &assembly::Part) -> Cow<'m, Mesh> {
    let input = inputs[if part.input == 0 || scene { 0 } else { 1 }];
    let Some(i) = &input.instanced else { return part_mesh(&input.input.mesh, part) };
    let (positions, triangles) = i.scene.place(part.object as usize).unwrap_or_default();
    let placed = Mesh {
        tri_object: vec![0; triangles.len()],
        objects: vec![crate::scene::mesh::Object {
            name: part.name.clone(),
            gltf_mesh: part.gltf_mesh,
            world: Some(i.scene.parts[part.object as usize].world),
        }],
        positions,
        triangles,
    };
    Cow::Owned(placed.sub_mesh(&(0..placed.triangles.len() as u32).collect::<Vec<_>>()))
}

/// The part's triangles as a mesh of their own: the input itself when the part is all of it
/// (its triangles in file order are then `0..n`), a copy otherwise. The overlap box is a
/// function of the solid alone, so it is the same either way.
fn part_mesh<'m>(m: &'m Mesh, part: &assembly::Part) -> Cow<'m, Mesh> {
    let whole = part.triangles.len() == m.triangles.len()
        && part.triangles.iter().enumerate().all(|(k, &t)| t as usize == k);
    if whole {
        Cow::Borrowed(m)
    } else {
        Cow::Owned(m.sub_mesh(&part.triangles))
    }
}

/// Parts with fewer triangles get an eager tree: for them the lazy tree's passes cost more than
/// building the whole tree. A cost knob only (the box does not depend on the tree).
const EAGER_BELOW: usize = 4096;

/// A part's tree for its overlap boxes: eager when small, lazy otherwise (only the cells the
/// edge and point queries open get built).
enum PartTree<'m> {
    Eager(crate::bvh::Bvh),
    Lazy(LazyBvh<'m, Mesh>),
}

impl<'m> PartTree<'m> {
    fn new(m: &'m Mesh, opts: BuildOptions) -> PartTree<'m> {
        if m.triangles.len() < EAGER_BELOW {
            PartTree::Eager(crate::bvh::Bvh::build(m, opts))
        } else {
            PartTree::Lazy(LazyBvh::new(m, opts))
        }
    }

    fn tree(&self) -> &dyn Tree {
        match self {
            PartTree::Eager(t) => t,
            PartTree::Lazy(t) => t,
        }
    }
}

impl Tree for PartTree<'_> {
    fn is_empty(&self) -> bool {
        self.tree().is_empty()
    }
    fn is_leaf(&self, i: u32) -> bool {
        self.tree().is_leaf(i)
    }
    fn children(&self, i: u32) -> [u32; 2] {
        self.tree().children(i)
    }
    fn node_box(&self, i: u32) -> Aabb {
        self.tree().node_box(i)
    }
    fn leaf_prims(&self, i: u32) -> &[u32] {
        self.tree().leaf_prims(i)
    }
    fn subtree_prims(&self, i: u32) -> &[u32] {
        self.tree().subtree_prims(i)
    }
    fn id_bound(&self) -> usize {
        self.tree().id_bound()
    }
    fn stats(&self) -> crate::bvh::Stats {
        self.tree().stats()
    }
}

#[cfg(test)]
mod tests {
    use super::WorkerMemo;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;

    #[test]
    fn a_worker_memo_gives_what_making_gives_and_keeps_only_the_last_few() {
        let made = AtomicUsize::new(0);
        let memo = WorkerMemo::new(2);
        let get = |k: usize| {
            *memo.get(k, || {
                made.fetch_add(1, Ordering::Relaxed);
                Arc::new(k * 10)
            })
        };
        // Outside a pool every call shares one slot: 1, 2 are kept; 1 again is kept (and now the
        // most recent), so 3 drops 2; 1 is still kept; 2 is made again.
        assert_eq!([get(1), get(2), get(1), get(3), get(1), get(2)], [10, 20, 10, 30, 10, 20]);
        assert_eq!(made.load(Ordering::Relaxed), 4);
        assert!(memo.slots.iter().all(|s| s.lock().unwrap().len() <= 2));
    }
}
