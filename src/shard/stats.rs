//! The tree-sharing facts of an assembly report (`sah_builds`, `shared_trees`,
//! `memory_saved_bytes`) for the whole plan, which no single shard sees: which needed part
//! leads which glTF mesh, which instance maps its leader's tree and which refits a copy, and the
//! memory a copy per part would have taken.
//!
//! **Mirrors the private accounting of [`crate::check::assembly::check_parts`]** (grouping by
//! `(input, glTF mesh)` in part order, the shift test, the box map fit, the byte counts): the
//! byte-identity tests of `tests/shard.rs` fail when the two drift apart. Only the size of each
//! own tree needs the tree; a shard builds the trees of the own-tree parts it is the owner of
//! (see [`owned_tree_bytes`]) and the merge adds them up.

use crate::bvh::{BuildOptions, Bvh, Node};
use crate::check::assembly::{relative_rows, Part, Sharing, Source};
use crate::geom::predicates::BoxMap;
use crate::geom::{Aabb, DVec3};
use crate::scene::mesh::Mesh;
use std::collections::{BTreeMap, HashMap};

/// How each needed part gets its tree: its own (`leader == part`) or its leader's.
#[derive(Debug, Clone)]
pub struct Grouping {
    /// Own-tree parts, in the order the check builds them (a layout each).
    pub own: Vec<usize>,
    /// Per needed part: (index into `own`, vertex shift, leader part).
    plan: BTreeMap<usize, (usize, i64, usize)>,
}

/// Group the `needed` parts (ascending) as the check does.
pub fn group(meshes: [&Mesh; 2], parts: &[Part], needed: &[usize]) -> Grouping {
    group_from([Source::Loaded(meshes[0]), Source::Loaded(meshes[1])], parts, needed)
}

/// [`group`] over parts read from `sources` (by input), with the check's shift test
/// ([`Source::shift`]).
fn group_from(sources: [Source<'_>; 2], parts: &[Part], needed: &[usize]) -> Grouping {
    let mut leader_of_mesh: HashMap<(u8, u32), usize> = HashMap::new();
    let mut own = Vec::new();
    let mut plan: BTreeMap<usize, (usize, i64, usize)> = BTreeMap::new();
    for &i in needed {
        let src = sources[parts[i].input as usize];
        let shared = parts[i].gltf_mesh.and_then(|m| {
            let l = *leader_of_mesh.entry((parts[i].input, m)).or_insert(i);
            let shift = if l == i { None } else { src.shift(&parts[l], &parts[i]) }?;
            let (layout, _, _) = *plan.get(&l)?;
            Some((layout, shift, l))
        });
        let p = shared.unwrap_or_else(|| {
            own.push(i);
            (own.len() - 1, 0, i)
        });
        plan.insert(i, p);
    }
    Grouping { own, plan }
}

/// Bytes of a tree as the check counts them.
pub fn tree_bytes(t: &Bvh) -> usize {
    t.nodes.len() * std::mem::size_of::<Node>() + t.prims.len() * 4
}

/// The tree the check builds for an own-tree part, whose triangles in `mesh` are `triangles`
/// (over their world boxes).
fn build_tree(mesh: &Mesh, triangles: &[u32], opts: BuildOptions) -> Bvh {
    let boxes: Vec<Aabb> =
        triangles.iter().map(|&t| Aabb::of_triangle(&crate::bvh::triangle(mesh, t))).collect();
    Bvh::build_from_boxes(&boxes, opts)
}

/// Tree sizes of the own-tree parts in `owned` (built here, in parallel).
pub fn owned_tree_bytes(
    meshes: [&Mesh; 2],
    parts: &[Part],
    owned: &[usize],
    opts: BuildOptions,
) -> Vec<(usize, u64)> {
    owned_tree_bytes_from([Source::Loaded(meshes[0]), Source::Loaded(meshes[1])], parts, owned, opts)
}

/// [`owned_tree_bytes`] over parts read from `sources` (an instanced scene's placed one at a
/// time, as the check builds their trees).
pub fn owned_tree_bytes_from(
    sources: [Source<'_>; 2],
    parts: &[Part],
    owned: &[usize],
    opts: BuildOptions,
) -> Vec<(usize, u64)> {
    use rayon::prelude::*;
    owned
        .par_iter()
        .map(|&i| {
            let (mesh, triangles) = sources[parts[i].input as usize].part_mesh(&parts[i]);
            (i, tree_bytes(&build_tree(&mesh, &triangles, opts)) as u64)
        })
        .collect()
}

/// The layout of one own-tree part: (part-local vertices, bytes kept, vertex map or a run start).
struct Layout {
    tris: usize,
    vertices: usize,
    bytes: usize,
    vmap: Vec<u32>,
    run: Option<u32>,
}

impl Layout {
    fn of(mesh: &Mesh, triangles: &[u32]) -> Layout {
        let (tris, vmap) = mesh.reindex(triangles);
        let run = vmap.first().copied().filter(|&s| vmap.iter().zip(s..).all(|(&v, w)| v == w));
        let kept_map = if run.is_some() { 0 } else { vmap.len() };
        Layout { tris: tris.len(), vertices: vmap.len(), bytes: tris.len() * 12 + kept_map * 4, vmap, run }
    }

    fn vertex(&self, world: &[DVec3], v: u32, shift: i64) -> DVec3 {
        let at = match self.run {
            Some(s) => s as i64 + v as i64,
            None => self.vmap[v as usize] as i64,
        };
        world[(at + shift) as usize]
    }
}

/// `sah_builds` and the [`Sharing`] of a check whose needed parts are `needed`, given the size
/// of every own tree (`tree_bytes[part]`). `None` names a missing tree size.
pub fn sharing(
    meshes: [&Mesh; 2],
    parts: &[Part],
    needed: &[usize],
    tree_bytes: &HashMap<usize, u64>,
) -> Result<(usize, Sharing), usize> {
    sharing_lazy(meshes, parts, needed, |_, own| match own.iter().find(|p| !tree_bytes.contains_key(p)) {
        Some(&p) => Err(p),
        None => Ok(tree_bytes.clone()),
    })
}

/// [`sharing`], asking `sizes(wanted, own)` for the tree sizes it needs: `wanted` are the own
/// trees some instance walks through a box map (the only ones the figures depend on), `own`
/// every own-tree part; both ascending. The answer must hold every part of `wanted`.
///
/// The figures: a copy per needed part costs its vertices (24 bytes), triangles (16 bytes)
/// and the tree of its layout; what is kept is each layout, each own tree, each refitted copy
/// (as large as its leader's tree) and each box map. The difference is the layouts' copies
/// less the kept layouts and maps, plus the tree of every mapped instance's leader.
pub fn sharing_lazy(
    meshes: [&Mesh; 2],
    parts: &[Part],
    needed: &[usize],
    sizes: impl FnOnce(&[usize], &[usize]) -> Result<HashMap<usize, u64>, usize>,
) -> Result<(usize, Sharing), usize> {
    sharing_lazy_from([Source::Loaded(meshes[0]), Source::Loaded(meshes[1])], parts, needed, sizes)
}

/// [`sharing_lazy`] over parts read from `sources`: an instanced scene's parts are placed one
/// at a time, as the check places them, and give the figures the expanded mesh gives.
pub fn sharing_lazy_from(
    sources: [Source<'_>; 2],
    parts: &[Part],
    needed: &[usize],
    sizes: impl FnOnce(&[usize], &[usize]) -> Result<HashMap<usize, u64>, usize>,
) -> Result<(usize, Sharing), usize> {
    use rayon::prelude::*;
    let g = group_from(sources, parts, needed);
    let src_of = |i: usize| sources[parts[i].input as usize];
    let layouts: Vec<Layout> = g
        .own
        .par_iter()
        .map(|&i| {
            let (mesh, triangles) = src_of(i).part_mesh(&parts[i]);
            Layout::of(&mesh, &triangles)
        })
        .collect();
    // Instances: a box map when one fits, else a refitted copy (same size as the leader's tree).
    let instances: Vec<(usize, usize, i64, usize)> = g
        .plan
        .iter()
        .filter(|(&i, &(_, _, l))| l != i)
        .map(|(&i, &(layout, shift, l))| (i, layout, shift, l))
        .collect();
    let mapped: Vec<(usize, bool)> = instances
        .par_iter()
        .map(|&(i, layout, shift, l)| {
            let (lay, src) = (&layouts[layout], src_of(i));
            let rows = relative_rows(src.matrix(&parts[l]), src.matrix(&parts[i]));
            let fits = rows.is_some_and(|r| {
                // Loaded, both read the one mesh's vertices (the instance `shift` apart); placed,
                // each its own.
                let (wl, wi) = (src.world(&parts[l]), src.world(&parts[i]));
                let pairs =
                    (0..lay.vertices as u32).map(|v| (lay.vertex(&wl, v, 0), lay.vertex(&wi, v, shift)));
                BoxMap::fit(r, &parts[l].bounds, pairs).is_some()
            });
            (layout, fits)
        })
        .collect();
    let mut users = vec![0usize; g.own.len()];
    for &(layout, fits) in &mapped {
        if fits {
            users[layout] += 1;
        }
    }
    let wanted: Vec<usize> = {
        let mut w: Vec<usize> = (0..g.own.len()).filter(|&l| users[l] > 0).map(|l| g.own[l]).collect();
        w.sort_unstable();
        w
    };
    let mut own_sorted = g.own.clone();
    own_sorted.sort_unstable();
    let tb = sizes(&wanted, &own_sorted)?;
    let mut copied: i128 = 0;
    for &(layout, _, _) in g.plan.values() {
        let l = &layouts[layout];
        copied += (l.vertices * 24 + l.tris * 16) as i128;
    }
    let mut kept: i128 = layouts.iter().map(|l| l.bytes as i128).sum();
    let maps: usize = users.iter().sum();
    kept += (maps * std::mem::size_of::<BoxMap>()) as i128;
    for (layout, &u) in users.iter().enumerate() {
        if u > 0 {
            let b = *tb.get(&g.own[layout]).ok_or(g.own[layout])?;
            copied += u as i128 * b as i128;
        }
    }
    Ok((
        g.own.len(),
        Sharing {
            shared_trees: users.iter().filter(|&&u| u > 0).count(),
            mapped_instances: maps,
            memory_saved_bytes: (copied - kept).max(0) as usize,
        },
    ))
}
