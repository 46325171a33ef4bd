//! Assemblies: which parts clash with which.
//!
//! A *part* is an object of a loaded file (OBJ `o`/`g`, STL `solid`, glTF mesh instance).
//! Part pairs are found by a broad phase over the parts' world boxes (a BVH over part boxes,
//! walked against itself or the other set with the same dual walk as triangles); only parts that
//! take part in some candidate pair get a triangle BVH, built lazily and in parallel, and each
//! candidate pair is checked exactly with [`crate::check::query::check_built`]. Parts whose boxes never
//! come within the search margin of another cost nothing beyond their box.
//!
//! Nothing is copied per part: a part is a view of the loaded mesh (its world coordinates, as
//! the loader computed them) through a *layout* — its triangles re-indexed to its own vertices,
//! numbered in order of first use — and instances of one glTF mesh share one layout and one tree
//! (one SAH build per distinct mesh). The first needed instance (the *leader*) owns the tree,
//! built over its own world coordinates (exact boxes). Every other instance walks the same tree
//! through the relative transform `world(instance) · world(leader)⁻¹`: node boxes are mapped
//! into its world coordinates and widened by a bound on rounding and on the measured deviation
//! of its vertices from the mapped leader's ([`BoxMap`], proved in
//! [`crate::geom::predicates`]), so culling stays conservative for mirrored, rotated and
//! non-uniformly scaled instances; the root box is the part's exact world box. Triangles at the
//! leaves, containment and distances all read the instance's own world coordinates, so every
//! verdict is exactly what a copied sub-mesh would give. An instance whose coordinates are not
//! an affine image of the leader's (to rounding), or without node matrices, falls back to a
//! refitted copy of the leader's tree (exact boxes, a copy of the nodes).

use crate::bvh::traverse::AtomicU64;
use crate::bvh::traverse::{self, MappedTree};
use crate::bvh::{BuildOptions, Bvh, Node};
use crate::check::containment;
use crate::check::containment::Containment;
use crate::check::containment::Topology;
use crate::check::query::{
    closest_pair_within, find_pairs, pair_walk, tally_walk, ClashResult, Detail, PairFinding, PairPhase,
    Settings, Tally, Verdict,
};
use crate::geom::predicates::BoxMap;
use crate::geom::{Aabb, DVec3};
use crate::load::InstancedScene;
use crate::scene::mesh::{Mesh, TriMesh};
use rayon::prelude::*;
use std::borrow::Cow;
use std::collections::HashMap;
use std::time::Instant;

/// One part of one input.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Which input (0 = A, 1 = B).
    pub input: u8,
    /// Object index in that input.
    pub object: u32,
    /// Object name (glTF node path, OBJ group, STL solid).
    pub name: String,
    /// Its triangles, as indices into the input mesh, in file order.
    pub triangles: Vec<u32>,
    /// World box.
    pub bounds: Aabb,
    /// glTF mesh it instances, if any.
    pub gltf_mesh: Option<u32>,
}

/// Split a mesh into its parts (objects with at least one triangle), in object order.
pub fn parts_of(mesh: &Mesh, input: u8) -> Vec<Part> {
    // Count first, so that each list is allocated once at its size (pushing would leave up to
    // half of each list's capacity unused, a third more memory over a large scene).
    let mut count = vec![0usize; mesh.objects.len()];
    for &o in &mesh.tri_object {
        count[o as usize] += 1;
    }
    let mut tris: Vec<Vec<u32>> = count.into_iter().map(Vec::with_capacity).collect();
    for (t, &o) in mesh.tri_object.iter().enumerate() {
        tris[o as usize].push(t as u32);
    }
    tris.into_iter()
        .enumerate()
        .filter(|(_, t)| !t.is_empty())
        .map(|(o, triangles)| {
            let bounds = triangles
                .iter()
                .fold(Aabb::EMPTY, |b, &t| b.union(Aabb::of_triangle(&crate::bvh::triangle(mesh, t))));
            Part {
                input,
                object: o as u32,
                name: mesh.objects[o].name.clone(),
                triangles,
                bounds,
                gltf_mesh: mesh.objects[o].gltf_mesh,
            }
        })
        .collect()
}

/// Match a part name against a glob: `*` any run of characters (including `/`), `?` one
/// character; everything else literal.
pub fn glob_match(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    let (mut i, mut j, mut star, mut mark) = (0usize, 0usize, None::<usize>, 0usize);
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// The triangles of one part re-indexed to its own vertices, numbered in order of first use (as
/// a copied sub-mesh would number them): built once per distinct glTF mesh and shared by every
/// instance whose triangles index the loaded mesh in the same pattern.
#[derive(Debug)]
struct Layout {
    /// Triangles in part-local vertex indices, in the part's (file) order.
    tris: Vec<[u32; 3]>,
    /// For each part-local vertex, its index in the loaded mesh for the part the layout was
    /// made from; another instance adds its `shift`. Empty when `run` says it counts up.
    vmap: Vec<u32>,
    /// Number of part-local vertices.
    vertices: usize,
    /// `Some(vmap[0])` when `vmap` counts up by one from there (the usual glTF case): the
    /// part's vertices are then a slice of the loaded mesh's, borrowed as they are.
    run: Option<u32>,
}

impl Layout {
    fn of(mesh: &Mesh, tris: &[u32]) -> Layout {
        let (tris, mut vmap) = mesh.reindex(tris);
        let run = vmap.first().copied().filter(|&s| vmap.iter().zip(s..).all(|(&v, w)| v == w));
        let vertices = vmap.len();
        if run.is_some() {
            vmap = Vec::new();
        }
        Layout { tris, vmap, vertices, run }
    }

    fn bytes(&self) -> usize {
        self.tris.len() * 12 + self.vmap.len() * 4
    }
}

/// The vertex-index offset that makes `inst` read like `leader` (same triangle count, and each
/// corner of each triangle the leader's corner plus one common offset), if there is one.
pub(crate) fn shift_of(mesh: &Mesh, leader: &Part, inst: &Part) -> Option<i64> {
    if leader.triangles.len() != inst.triangles.len() || leader.triangles.is_empty() {
        return None;
    }
    let first = |p: &Part| mesh.triangles[p.triangles[0] as usize][0] as i64;
    let shift = first(inst) - first(leader);
    let same = leader.triangles.iter().zip(&inst.triangles).all(|(&l, &i)| {
        let (l, i) = (mesh.triangles[l as usize], mesh.triangles[i as usize]);
        (0..3).all(|k| i[k] as i64 == l[k] as i64 + shift)
    });
    same.then_some(shift)
}

/// Where the check reads the parts of one input: the loaded mesh in world coordinates, or an
/// instanced glTF scene whose parts are placed when they are read (by the loader's own
/// arithmetic, so the coordinates are the loaded mesh's, bit for bit) and dropped after.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    /// The loaded mesh, in world coordinates.
    Loaded(&'a Mesh),
    /// An instanced glTF scene (scene mode: one input).
    Placed(&'a InstancedScene),
}

impl<'a> Source<'a> {
    /// The mesh `part` is read from and its triangles there: the loaded mesh and the part's
    /// triangle numbers (borrowed), or the part placed alone ([`placed_part`]) and all of its
    /// triangles.
    pub(crate) fn part_mesh<'p>(self, part: &'p Part) -> (Cow<'a, Mesh>, Cow<'p, [u32]>) {
        match self {
            Source::Loaded(m) => (Cow::Borrowed(m), Cow::Borrowed(&part.triangles)),
            Source::Placed(s) => {
                let one = placed_part(s, part.object as usize);
                let all = (0..one.triangles.len() as u32).collect();
                (Cow::Owned(one), Cow::Owned(all))
            }
        }
    }

    /// The layout of `part` (see [`Layout`]).
    fn layout(self, part: &Part) -> Layout {
        let (mesh, triangles) = self.part_mesh(part);
        Layout::of(&mesh, &triangles)
    }

    /// The vertex offset that makes `inst` read like `leader` (see [`shift_of`]). Placed, the
    /// instances of one glTF mesh index their own vertices alike.
    pub(crate) fn shift(self, leader: &Part, inst: &Part) -> Option<i64> {
        match self {
            Source::Loaded(m) => shift_of(m, leader, inst),
            Source::Placed(_) => (leader.gltf_mesh == inst.gltf_mesh
                && leader.triangles.len() == inst.triangles.len()
                && !leader.triangles.is_empty())
            .then_some(0),
        }
    }

    /// The world coordinates `part`'s layout indexes: the loaded mesh's (borrowed), or the part
    /// placed.
    pub(crate) fn world(self, part: &Part) -> Cow<'a, [DVec3]> {
        match self {
            Source::Loaded(m) => Cow::Borrowed(&m.positions),
            Source::Placed(s) => Cow::Owned(s.place_positions(part.object as usize)),
        }
    }

    /// The glTF world matrix of `part`, if known.
    pub(crate) fn matrix(self, part: &Part) -> Option<glam::DMat4> {
        match self {
            Source::Loaded(m) => m.objects[part.object as usize].world,
            Source::Placed(s) => Some(s.parts[part.object as usize].world),
        }
    }
}

/// Part `k` of `scene` placed, as a mesh of its positions and triangles. The loader placed
/// every part by the same arithmetic and found all coordinates finite, so placing cannot fail
/// here (an empty mesh stands in if it ever did).
pub(crate) fn placed_part(scene: &InstancedScene, k: usize) -> Mesh {
    let (positions, triangles) = scene.place(k).unwrap_or_default();
    Mesh { positions, triangles, ..Mesh::default() }
}

/// The parts of an instanced scene (see [`parts_of`]): the same list the expanded mesh gives,
/// `bounds[k]` the box of part `k`'s triangles (found when the scene was summarised:
/// [`crate::check::query::scene_info`]).
pub fn parts_of_scene(scene: &InstancedScene, bounds: &[Aabb]) -> Vec<Part> {
    let mut t0 = 0u32;
    scene
        .parts
        .iter()
        .zip(bounds)
        .enumerate()
        .map(|(k, (p, &bounds))| {
            let first = t0;
            t0 = t0.saturating_add(scene.part_counts(k).1 as u32);
            Part {
                input: 0,
                object: k as u32,
                name: p.name.clone(),
                triangles: (first..t0).collect(),
                bounds,
                gltf_mesh: Some(p.mesh),
            }
        })
        .collect()
}

/// One part seen through its layout: vertex `v` is `world[vmap[v] + shift]`. Nothing is copied.
#[derive(Debug, Clone, Copy)]
struct PartMesh<'a> {
    world: &'a [DVec3],
    layout: &'a Layout,
    shift: i64,
}

impl TriMesh for PartMesh<'_> {
    #[inline]
    fn vertex_count(&self) -> usize {
        self.layout.vertices
    }
    #[inline]
    fn vertex(&self, v: u32) -> DVec3 {
        let at = match self.layout.run {
            Some(s) => s as i64 + v as i64,
            None => self.layout.vmap[v as usize] as i64,
        };
        self.world[(at + self.shift) as usize]
    }
    #[inline]
    fn triangle_count(&self) -> usize {
        self.layout.tris.len()
    }
    #[inline]
    fn indices(&self, t: u32) -> [u32; 3] {
        self.layout.tris[t as usize]
    }
    fn positions(&self) -> std::borrow::Cow<'_, [DVec3]> {
        match self.layout.run {
            Some(s) => {
                let at = (s as i64 + self.shift) as usize;
                std::borrow::Cow::Borrowed(&self.world[at..at + self.layout.vertices])
            }
            None => (0..self.vertex_count() as u32).map(|v| self.vertex(v)).collect::<Vec<_>>().into(),
        }
    }
}

/// The parts' views: a part's layout over coordinates given when it is read.
struct Views<'l> {
    plan: &'l [Option<Plan>],
    layouts: &'l [Layout],
}

impl<'l> Views<'l> {
    fn of<'w>(&self, i: usize, world: &'w [DVec3]) -> PartMesh<'w>
    where
        'l: 'w,
    {
        let p = self.plan[i].expect("needed part has a plan");
        PartMesh { world, layout: &self.layouts[p.layout], shift: p.shift }
    }
}

/// The affine map from `leader`'s world coordinates to `inst`'s: `world(inst) · world(leader)⁻¹`
/// from the glTF node matrices, as [`BoxMap`] rows. `None` without matrices or for a singular
/// leader matrix.
pub(crate) fn relative_rows(leader: Option<glam::DMat4>, inst: Option<glam::DMat4>) -> Option<[[f64; 4]; 3]> {
    let (l, i) = (leader?, inst?);
    let det = l.determinant();
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let r = i * l.inverse();
    Some([0, 1, 2].map(|k| [r.x_axis[k], r.y_axis[k], r.z_axis[k], r.w_axis[k]]))
}

/// Refit a tree built for another instance of the same mesh to this instance's coordinates:
/// same topology and leaf order, exact boxes (the fallback when no box map fits).
fn refit(template: &Bvh, mesh: &PartMesh) -> Bvh {
    let mut nodes: Vec<Node> = template.nodes.clone();
    for i in (0..nodes.len()).rev() {
        let n = nodes[i];
        nodes[i].bounds = if n.is_leaf() {
            template
                .leaf_prims(&n)
                .iter()
                .fold(Aabb::EMPTY, |b, &t| b.union(Aabb::of_triangle(&mesh.triangle(t))))
        } else {
            nodes[i + 1].bounds.union(nodes[n.a as usize].bounds)
        };
    }
    Bvh { nodes, prims: template.prims.clone() }
}

fn tree_bytes(t: &Bvh) -> usize {
    t.nodes.len() * std::mem::size_of::<Node>() + t.prims.len() * 4
}

/// How a needed part gets its triangles and its tree.
#[derive(Debug, Clone, Copy)]
struct Plan {
    /// Index into the layouts.
    layout: usize,
    /// Vertex offset against the layout's part.
    shift: i64,
    /// The part whose tree this part uses (itself for a leader).
    leader: usize,
}

/// The result for one part pair.
#[derive(Debug, Clone, PartialEq)]
pub struct PartPair {
    /// Index into [`AssemblyResult::parts`] (the A side).
    pub a: usize,
    /// Index into [`AssemblyResult::parts`] (the B side).
    pub b: usize,
    /// The check of the two parts; triangle indices are those of the input meshes. A pair with
    /// a finding (listed in the report) has its closest points; a clear pair has them only if
    /// it could be the scene's closest (its `closest` is `None` when a pair at least as close
    /// was known: see [`check_parts`]).
    pub result: ClashResult,
}

/// Everything an assembly check finds.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyResult {
    /// All parts of both inputs (selected or not), A's first.
    pub parts: Vec<Part>,
    /// Part pairs whose boxes came within the search margin, sorted by (a, b), with findings
    /// or not.
    pub part_pairs: Vec<PartPair>,
    /// Parts for which a triangle tree was needed (the others were skipped).
    pub built: Vec<bool>,
    /// Distinct SAH builds (instances of one glTF mesh share one build).
    pub sah_builds: usize,
    /// How the instances shared trees.
    pub sharing: Sharing,
    /// Time to build the part trees, ms.
    pub build_ms: f64,
    /// Time for the broad phase and all part-pair checks, ms.
    pub query_ms: f64,
}

/// How instances of one glTF mesh shared one tree (see [`check_parts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Sharing {
    /// Trees used by more than one part (a leader and at least one mapped instance).
    pub shared_trees: usize,
    /// Parts that walked another part's tree through a box map instead of owning one.
    pub mapped_instances: usize,
    /// Bytes not allocated compared with copying every needed part into its own sub-mesh
    /// (positions, triangles, object ids) with its own tree: the copies' total minus the
    /// shared layouts, trees, refitted fallbacks and box maps.
    pub memory_saved_bytes: usize,
}

/// Which part pairs to check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pairing {
    /// Every selected part of A against every selected part of B (two files, or two selections
    /// of one file).
    Cross,
    /// Every selected part against every other selected part of the same input (all-vs-all);
    /// each unordered pair once.
    AllVsAll,
}

/// Check parts `sel_a` against `sel_b` (indices into `parts`) of `meshes[input]`.
pub fn check_parts(
    meshes: [&Mesh; 2],
    parts: Vec<Part>,
    sel_a: &[usize],
    sel_b: &[usize],
    pairing: Pairing,
    settings: &Settings,
) -> AssemblyResult {
    check_parts_kept(meshes, parts, sel_a, sel_b, pairing, settings, &|_, _| true)
}

/// [`check_parts`], of the candidate part pairs only those `keep` accepts: the others are
/// dropped before any tree is built (a shard's pairs: [`PartsHook`]).
pub fn check_parts_kept(
    meshes: [&Mesh; 2],
    parts: Vec<Part>,
    sel_a: &[usize],
    sel_b: &[usize],
    pairing: Pairing,
    settings: &Settings,
    keep: &(dyn Fn(usize, usize) -> bool + Sync),
) -> AssemblyResult {
    check_parts_from(
        [Source::Loaded(meshes[0]), Source::Loaded(meshes[1])],
        parts,
        sel_a,
        sel_b,
        pairing,
        settings,
        keep,
    )
}

/// [`check_parts_kept`] on parts read from `sources` (by input).
pub fn check_parts_from(
    sources: [Source<'_>; 2],
    parts: Vec<Part>,
    sel_a: &[usize],
    sel_b: &[usize],
    pairing: Pairing,
    settings: &Settings,
    keep: &(dyn Fn(usize, usize) -> bool + Sync),
) -> AssemblyResult {
    let t0 = Instant::now();
    // Broad phase: a tree over the selected parts' boxes on each side, walked together.
    let mut candidates: Vec<(usize, usize)> =
        part_box_walk(&parts, sel_a, sel_b, pairing, settings, &|| true, |pa, pb, out| out.push((pa, pb)));
    candidates.sort_unstable();
    candidates.dedup();
    candidates.retain(|&(a, b)| keep(a, b));
    // Lazy trees: only parts in some candidate pair.
    let mut built = vec![false; parts.len()];
    for &(a, b) in &candidates {
        built[a] = true;
        built[b] = true;
    }
    let needed: Vec<usize> = (0..parts.len()).filter(|&i| built[i]).collect();
    let source = |i: usize| sources[parts[i].input as usize];
    // Group instances: the first needed part of each (input, glTF mesh) leads; another instance
    // shares its layout and tree when its triangles index the mesh in the same pattern.
    let mut leader_of_mesh: HashMap<(u8, u32), usize> = HashMap::new();
    let mut leaders: Vec<usize> = Vec::new();
    let mut plan: Vec<Option<Plan>> = vec![None; parts.len()];
    for &i in &needed {
        let shared = parts[i].gltf_mesh.and_then(|m| {
            let l = *leader_of_mesh.entry((parts[i].input, m)).or_insert(i);
            let shift = if l == i { None } else { source(i).shift(&parts[l], &parts[i]) }?;
            Some(Plan { leader: l, shift, ..plan[l]? })
        });
        plan[i] = Some(shared.unwrap_or_else(|| {
            leaders.push(i);
            Plan { layout: leaders.len() - 1, shift: 0, leader: i }
        }));
    }
    let layouts: Vec<Layout> = leaders.par_iter().map(|&i| source(i).layout(&parts[i])).collect();
    // A part's coordinates (borrowed from the loaded mesh, or placed for the moment) and its
    // view through its layout.
    let world = |i: usize| source(i).world(&parts[i]);
    let views = Views { plan: &plan, layouts: &layouts };
    let own: Vec<Bvh> = leaders
        .par_iter()
        .map(|&i| {
            let w = world(i);
            let v = views.of(i, &w);
            let boxes: Vec<Aabb> =
                (0..v.triangle_count() as u32).map(|t| Aabb::of_triangle(&v.triangle(t))).collect();
            Bvh::build_from_boxes(&boxes, settings.bvh)
        })
        .collect();
    let sah_builds = own.len();
    // Every other instance maps its leader's boxes by the relative transform; when no map fits
    // (no matrices, or coordinates that are not an affine image to rounding), it refits a copy.
    enum Shared {
        Map(BoxMap),
        Refit(Bvh),
    }
    let shared: Vec<(usize, Shared)> = needed
        .par_iter()
        .filter(|&&i| plan[i].is_some_and(|p| p.leader != i))
        .map(|&i| {
            let p = plan[i].expect("planned");
            let (wl, wi) = (world(p.leader), world(i));
            let (vl, vi) = (views.of(p.leader, &wl), views.of(i, &wi));
            let template = &own[p.layout];
            let rows = relative_rows(source(i).matrix(&parts[p.leader]), source(i).matrix(&parts[i]));
            let map = rows.and_then(|r| {
                let pairs = (0..vl.vertex_count() as u32).map(|v| (vl.vertex(v), vi.vertex(v)));
                BoxMap::fit(r, &template.bounds(), pairs)
            });
            (i, map.map_or_else(|| Shared::Refit(refit(template, &vi)), Shared::Map))
        })
        .collect();
    let mut maps: Vec<Option<BoxMap>> = vec![None; parts.len()];
    let mut refits: Vec<Option<Bvh>> = (0..parts.len()).map(|_| None).collect();
    let mut users = vec![0usize; leaders.len()];
    for (i, s) in shared {
        match s {
            Shared::Map(m) => {
                maps[i] = Some(m);
                users[plan[i].expect("planned").layout] += 1;
            }
            Shared::Refit(t) => refits[i] = Some(t),
        }
    }
    let tree = |i: usize| {
        let p = plan[i].expect("needed part has a plan");
        match &refits[i] {
            Some(t) => MappedTree { bvh: t, map: None, root: parts[i].bounds },
            None => MappedTree { bvh: &own[p.layout], map: maps[i], root: parts[i].bounds },
        }
    };
    // Memory: what copying each needed part into its own sub-mesh (f64 positions, triangles,
    // object ids) with its own tree would take, against the shared layouts and trees.
    let copied: usize = needed
        .iter()
        .map(|&i| {
            let p = plan[i].expect("planned");
            let (v, t) = (layouts[p.layout].vertices, layouts[p.layout].tris.len());
            v * 24 + t * 16 + tree_bytes(&own[p.layout])
        })
        .sum();
    let kept: usize = layouts.iter().map(Layout::bytes).sum::<usize>()
        + own.iter().map(tree_bytes).sum::<usize>()
        + refits.iter().flatten().map(tree_bytes).sum::<usize>()
        + maps.iter().flatten().count() * std::mem::size_of::<BoxMap>();
    let sharing = Sharing {
        shared_trees: users.iter().filter(|&&u| u > 0).count(),
        mapped_instances: users.iter().sum(),
        memory_saved_bytes: copied.saturating_sub(kept),
    };
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t1 = Instant::now();
    // Three phases, so that no rayon worker ever blocks on another's lazy value: every pair's
    // pairs and closest points; then the topology of each part some verdict needs (containment
    // or volumes overlap), each part once; then containment and the verdicts.
    let phases: Vec<(PairPhase, bool)> = candidates
        .par_iter()
        .map(|&(a, b)| {
            let (wa, wb) = (world(a), world(b));
            let (va, vb, ta, tb) = (views.of(a, &wa), views.of(b, &wb), tree(a), tree(b));
            // Without the lists (`--detail parts`) the walk keeps only a tally: memory does not
            // grow with the pairs of a part pair.
            let phase = match settings.detail {
                Detail::Parts => tally_walk(&va, &ta, &vb, &tb, settings),
                Detail::Pairs => pair_walk(&va, &ta, &vb, &tb, settings),
            };
            let needs = phase.needs_topology(&va, &ta, &vb, &tb);
            (phase, needs)
        })
        .collect();
    let mut wanted = vec![false; parts.len()];
    for (&(a, b), (_, needs)) in candidates.iter().zip(&phases) {
        if *needs {
            wanted[a] = true;
            wanted[b] = true;
        }
    }
    let topology: Vec<Option<Topology>> = (0..parts.len())
        .into_par_iter()
        .map(|i| wanted[i].then(|| containment::topology(&views.of(i, &world(i)))))
        .collect();
    let mut finished: Vec<(ClashResult, bool)> = candidates
        .par_iter()
        .zip(phases.into_par_iter())
        .map(|(&(a, b), (phase, needs))| {
            let topo =
                needs.then(|| (topology[a].as_ref().expect("wanted"), topology[b].as_ref().expect("wanted")));
            let pending = phase.closest_pending();
            let mut phase = phase;
            let (wa, wb) = (world(a), world(b));
            let (va, vb) = (views.of(a, &wa), views.of(b, &wb));
            if topo.is_some_and(|(x, y)| phase.needs_pairs(x, y)) {
                // Touching closed parts: containment reads their contacts.
                phase.set_pairs(find_pairs(&va, &tree(a), &vb, &tree(b), settings).0);
            }
            let mut r = phase.finish(&va, &tree(a), &vb, &tree(b), topo);
            if settings.detail == Detail::Parts {
                r.pairs = Vec::new();
            }
            r.closed = [topology[a].as_ref().map(|t| t.closed), topology[b].as_ref().map(|t| t.closed)];
            r.timings = Default::default();
            (r, pending)
        })
        .collect();
    // Distances. A part pair with a finding is listed with its closest points: searched in full.
    // A clear pair's distance shows only through the scene's minimum, so it is searched only as
    // far as it could be that minimum: all clear pairs share one bound, starting at the least
    // distance already known (0 as soon as any pair touches or crosses: then no clear pair,
    // whose exact distance is positive, can be the minimum and none is searched).
    let listed = |r: &ClashResult| r.verdict != Verdict::Clear || r.containment != Containment::None;
    let closest_of = |&(a, b): &(usize, usize), best: &AtomicU64| {
        let (wa, wb) = (world(a), world(b));
        let (va, vb, ta, tb) = (views.of(a, &wa), views.of(b, &wb), tree(a), tree(b));
        closest_pair_within(&va, &ta, &vb, &tb, settings.distance_error, best)
    };
    finished.par_iter_mut().zip(candidates.par_iter()).filter(|((r, p), _)| *p && listed(r)).for_each(
        |((r, pending), pair)| {
            r.closest = closest_of(pair, &AtomicU64::new(f64::INFINITY.to_bits()));
            *pending = false;
        },
    );
    let known =
        finished.iter().filter_map(|(r, _)| r.closest.map(|c| c.distance)).fold(f64::INFINITY, f64::min);
    if known > 0.0 {
        let shared = AtomicU64::new(known.to_bits());
        finished.par_iter_mut().zip(candidates.par_iter()).filter(|((_, p), _)| *p).for_each(
            |((r, _), pair)| {
                r.closest = closest_of(pair, &shared);
            },
        );
    }
    let part_pairs: Vec<PartPair> = finished
        .into_iter()
        .zip(&candidates)
        .map(|((mut r, _), &(a, b))| {
            to_input_indices(&mut r, &parts[a], &parts[b]);
            PartPair { a, b, result: r }
        })
        .collect();
    AssemblyResult {
        parts,
        part_pairs,
        built,
        sah_builds,
        sharing,
        build_ms,
        query_ms: t1.elapsed().as_secs_f64() * 1e3,
    }
}

/// Map triangle indices of the part sub-meshes back to the input meshes' indices (order is
/// preserved: a part's triangles are in file order, so sorted pairs stay sorted).
fn to_input_indices(r: &mut ClashResult, pa: &Part, pb: &Part) {
    let (ta, tb) = (&pa.triangles, &pb.triangles);
    for p in &mut r.pairs {
        *p = PairFinding { a: ta[p.a as usize], b: tb[p.b as usize], ..*p };
    }
    if let Some(c) = &mut r.closest {
        c.a.0 = ta[c.a.0 as usize];
        c.b.0 = tb[c.b.0 as usize];
    }
}

impl AssemblyResult {
    /// The worst verdict over all part pairs.
    pub fn verdict(&self) -> Verdict {
        self.part_pairs.iter().map(|p| p.result.verdict).max().unwrap_or(Verdict::Clear)
    }

    /// Part pairs with a finding (verdict other than clear, or containment).
    pub fn findings(&self) -> impl Iterator<Item = &PartPair> {
        self.part_pairs
            .iter()
            .filter(|p| p.result.verdict != Verdict::Clear || p.result.containment != Containment::None)
    }
}

/// The centre of a set of points (used for region markers).
pub fn centroid(points: &[DVec3]) -> DVec3 {
    if points.is_empty() {
        return DVec3::ZERO;
    }
    points.iter().fold(DVec3::ZERO, |s, p| s + *p) / points.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::Object;

    /// Each part lists exactly its object's triangles, in file order, in a list allocated at
    /// its size; objects without triangles give no part.
    #[test]
    fn parts_list_their_triangles_in_lists_of_their_size() {
        let mut next = crate::load::test_rng(11);
        let objects = 9;
        let n = 500;
        let mesh = Mesh {
            positions: (0..3 * n).map(|i| DVec3::new(i as f64, (i % 7) as f64, (i % 3) as f64)).collect(),
            triangles: (0..n as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
            // Object 4 is never used.
            tri_object: (0..n).map(|_| next(objects) as u32).map(|o| if o == 4 { 5 } else { o }).collect(),
            objects: (0..objects).map(|o| Object { name: format!("o{o}"), ..Object::default() }).collect(),
        };
        let parts = parts_of(&mesh, 1);
        let objects_used: Vec<u32> = parts.iter().map(|p| p.object).collect();
        assert_eq!(objects_used, vec![0, 1, 2, 3, 5, 6, 7, 8]);
        for p in &parts {
            let expected: Vec<u32> =
                (0..n as u32).filter(|&t| mesh.tri_object[t as usize] == p.object).collect();
            assert_eq!(p.triangles, expected, "{}", p.name);
            assert_eq!(p.triangles.capacity(), p.triangles.len(), "{}", p.name);
            assert_eq!(p.input, 1);
            let boxes = expected.iter().map(|&t| Aabb::of_triangle(&crate::bvh::triangle(&mesh, t)));
            assert_eq!(p.bounds, boxes.fold(Aabb::EMPTY, Aabb::union));
        }
    }

    #[test]
    fn glob_matches_like_a_shell() {
        assert!(glob_match("Engine/*", "Engine/Piston_2"));
        assert!(glob_match("*Piston*", "Engine/Piston_2"));
        assert!(glob_match("Piston_?", "Piston_2"));
        assert!(!glob_match("Piston_?", "Piston_12"));
        assert!(glob_match("*", ""));
        assert!(!glob_match("a*b", "acbd"));
        assert!(glob_match("a*b*", "acbd"));
    }

    /// Points on a bumpy sphere (f32 values, like a glTF accessor) and a fan of triangles.
    fn blob() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let (n, m) = (24u32, 16u32);
        let mut pos = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (i as f64 / n as f64 * 6.0, j as f64 / m as f64 * 3.0 + 0.05);
                let r = 1.0 + 0.1 * (5.0 * u).sin();
                let p = [r * u.cos() * v.sin(), r * u.sin() * v.sin(), r * v.cos()];
                pos.push(DVec3::from_array(p.map(|x| x as f32 as f64)));
            }
        }
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..m - 1 {
                let (a, b) = (i * m + j, ((i + 1) % n) * m + j);
                tris.push([a, b, b + 1]);
                tris.push([a, b + 1, a + 1]);
            }
        }
        (pos, tris)
    }

    #[test]
    fn mapped_boxes_contain_every_instance_triangle() {
        use glam::{DMat4, DQuat};
        let (local, tris) = blob();
        let leaders = [
            DMat4::IDENTITY,
            DMat4::from_scale_rotation_translation(
                DVec3::splat(10.0),
                DQuat::IDENTITY,
                DVec3::new(-3.0, 0.5, 7.0),
            ),
            DMat4::from_scale_rotation_translation(
                DVec3::new(0.1, 3.0, -0.7),
                DQuat::from_xyzw(0.3, -0.2, 0.6, 0.7).normalize(),
                DVec3::new(1e8, -2e7, 3.0),
            ),
        ];
        let instances = [
            DMat4::from_scale_rotation_translation(
                DVec3::new(-1.0, 1.0, 1.0),
                DQuat::IDENTITY,
                DVec3::new(5.0, 2.0, 2.0),
            ),
            DMat4::from_scale_rotation_translation(
                DVec3::new(3.0, 0.5, 7.0),
                DQuat::from_xyzw(-0.1, 0.8, 0.2, 0.4).normalize(),
                DVec3::new(1.0, 1.0, 1.0),
            ),
            DMat4::from_scale_rotation_translation(
                DVec3::new(1e-3, 1e3, -1.0),
                DQuat::from_xyzw(0.5, 0.5, -0.5, 0.5),
                DVec3::new(-1e8, 1e-9, 0.0),
            ),
        ];
        for l in leaders {
            for i in instances {
                let world =
                    |m: DMat4| -> Vec<DVec3> { local.iter().map(|&p| m.transform_point3(p)).collect() };
                let (wl, wi) = (world(l), world(i));
                let boxes: Vec<Aabb> =
                    tris.iter().map(|t| Aabb::of_triangle(&t.map(|v| wl[v as usize]))).collect();
                let tree = Bvh::build_from_boxes(&boxes, BuildOptions::default());
                let rows = relative_rows(Some(l), Some(i)).unwrap();
                let map = BoxMap::fit(rows, &tree.bounds(), wl.iter().copied().zip(wi.iter().copied()))
                    .expect("an instance maps");
                // Every node's mapped box holds the instance's triangles below it.
                let mut below: Vec<Aabb> = vec![Aabb::EMPTY; tree.nodes.len()];
                for k in (0..tree.nodes.len()).rev() {
                    let n = tree.nodes[k];
                    below[k] = if n.is_leaf() {
                        tree.leaf_prims(&n).iter().fold(Aabb::EMPTY, |b, &t| {
                            b.union(Aabb::of_triangle(&tris[t as usize].map(|v| wi[v as usize])))
                        })
                    } else {
                        below[k + 1].union(below[n.a as usize])
                    };
                    assert!(map.map_box(&n.bounds).contains(&below[k]), "node {k} of {l:?} -> {i:?}");
                }
                // A coordinate that is not the image of its source (one vertex moved by 1e-3 of
                // the size) is refused.
                let mut bent = wi.clone();
                bent[7] += DVec3::splat(below[0].extent().max_element() * 1e-3);
                assert!(BoxMap::fit(rows, &tree.bounds(), wl.iter().copied().zip(bent)).is_none());
            }
        }
    }
}

/// What to check in an assembly run.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Selection {
    /// `meshclash scene FILE`: parts of one file against each other.
    pub scene: bool,
    /// Globs selecting the A side (empty = all parts of A; in scene mode, all parts).
    pub select_a: Vec<String>,
    /// Globs selecting the B side (empty = all parts of B; in scene mode: all-vs-all).
    pub select_b: Vec<String>,
    /// Globs removing parts from both sides.
    pub exclude: Vec<String>,
    /// Sharding (`crate::shard`): restrict or stand in for the part-pair check.
    pub hook: Option<Hook>,
}

/// The sharding hook of [`run`]: a shard checks only its candidate part pairs, and
/// a merge stands in the shards' combined outcome for the check; everything around [`run`]
/// (loading, report, regions, baseline, JUnit) stays the single-machine code path.
pub trait PartsHook: Send + Sync + std::fmt::Debug {
    /// Check candidate part pair (`a`, `b`) (indices into the parts)? Parts mode only.
    fn keep(&self, a: usize, b: usize) -> bool;
    /// An outcome to return instead of checking anything (called once the parts and the
    /// selection sizes are known, in both modes).
    fn stand_in(
        &self,
        meshes: [&Mesh; 2],
        parts: &[Part],
        selected: [usize; 2],
    ) -> Option<Result<Outcome, String>>;
    /// Sees the outcome [`run`] returns.
    fn seen(&self, meshes: [&Mesh; 2], outcome: &Outcome);
}

/// A shared [`PartsHook`] (equal when it is the same hook).
#[derive(Debug, Clone)]
pub struct Hook(pub std::sync::Arc<dyn PartsHook>);

impl PartialEq for Hook {
    fn eq(&self, o: &Hook) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &o.0)
    }
}
impl Eq for Hook {}

impl Selection {
    /// True when parts must be checked pair by pair (scene mode or a selection).
    pub fn by_parts(&self) -> bool {
        self.scene || !self.select_a.is_empty() || !self.select_b.is_empty() || !self.exclude.is_empty()
    }
}

/// One part pair in the report.
#[derive(Debug, Clone, PartialEq)]
pub struct PartPairSummary {
    /// Index into the parts list (A side).
    pub a: usize,
    /// Index into the parts list (B side).
    pub b: usize,
    /// The pair's verdict.
    pub verdict: Verdict,
    /// Counts by kind.
    pub counts: crate::check::query::Counts,
    /// Minimum distance, when known (checked pairs; or 0 for meeting pairs in file mode).
    pub min_distance: Option<f64>,
    /// Containment between the two parts.
    pub containment: Containment,
    /// The witness of `min_distance`: triangles (input indices) and points, when known.
    pub closest: Option<crate::check::query::Closest>,
    /// The pair's triangle pairs (input triangle indices), sorted; the report lists a capped
    /// number of them.
    pub pairs: Vec<(u32, u32)>,
}

/// Facts about the assembly run.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyInfo {
    /// `files` (A against B, pairs grouped by part) or `parts` (part pairs checked one by one:
    /// scene mode or a selection).
    pub mode: &'static str,
    /// Selected parts on each side.
    pub selected: [usize; 2],
    /// Part pairs whose boxes came within the search margin.
    pub candidate_part_pairs: usize,
    /// Parts that needed a triangle tree (parts mode only).
    pub built_parts: Option<usize>,
    /// Distinct SAH builds (parts mode only; instances share one).
    pub sah_builds: Option<usize>,
    /// How instances shared trees (parts mode only).
    pub sharing: Option<Sharing>,
}

/// The whole outcome: a merged [`ClashResult`] (pairs in input triangle indices) plus the
/// per-part view.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// All findings merged, as for a two-file check.
    pub result: ClashResult,
    /// All parts (A's, then B's; in scene mode only the file's).
    pub parts: Vec<Part>,
    /// Part pairs with their verdicts, sorted; clear pairs omitted.
    pub part_pairs: Vec<PartPairSummary>,
    /// Run facts.
    pub info: AssemblyInfo,
}

fn select(parts: &[Part], input: u8, globs: &[String], exclude: &[String]) -> Vec<usize> {
    (0..parts.len())
        .filter(|&i| parts[i].input == input)
        .filter(|&i| globs.is_empty() || globs.iter().any(|g| glob_match(g, &parts[i].name)))
        .filter(|&i| !exclude.iter().any(|g| glob_match(g, &parts[i].name)))
        .collect()
}

/// Check `a` against `b` (in scene mode, `a` against itself) part by part or as whole files.
/// Errors (a selection that matches nothing) are one line.
pub fn run(a: &Mesh, b: &Mesh, sel: &Selection, settings: &Settings) -> Result<Outcome, String> {
    let o = run_checked(a, b, sel, settings)?;
    if let Some(h) = &sel.hook {
        h.0.seen([a, if sel.scene { a } else { b }], &o);
    }
    Ok(o)
}

fn run_checked(a: &Mesh, b: &Mesh, sel: &Selection, settings: &Settings) -> Result<Outcome, String> {
    let mut parts = parts_of(a, 0);
    if !sel.scene {
        parts.extend(parts_of(b, 1));
    }
    let (sa, sb) = selected(&parts, sel)?;
    let meshes = [a, if sel.scene { a } else { b }];
    if let Some(o) = sel.hook.as_ref().and_then(|h| h.0.stand_in(meshes, &parts, [sa.len(), sb.len()])) {
        return o;
    }
    if !sel.by_parts() {
        let (mut result, mut part_pairs) = match settings.detail {
            Detail::Pairs => {
                let result = crate::check::query::check(a, b, settings);
                let part_pairs = group_by_part(&parts, a, b, &result);
                (result, part_pairs)
            }
            // Without the lists, each part pair's pairs are tallied as they are found.
            Detail::Parts => {
                let (result, tallies) = crate::check::query::check_tallied(a, b, settings, |i, j| {
                    (a.tri_object[i as usize], b.tri_object[j as usize])
                });
                (result, group_tallies(&parts, a, b, tallies))
            }
        };
        per_part_containment(&parts, a, b, &mut result, &mut part_pairs, settings);
        let info = AssemblyInfo {
            mode: "files",
            selected: [sa.len(), sb.len()],
            candidate_part_pairs: part_pairs.len(),
            built_parts: None,
            sah_builds: None,
            sharing: None,
        };
        return Ok(Outcome { result, parts, part_pairs, info });
    }
    by_parts([Source::Loaded(a), Source::Loaded(meshes[1])], parts, &sa, &sb, sel, settings)
}

/// [`run`] in scene mode on an instanced glTF scene: the same outcome as [`run`] on the
/// scene's expanded mesh, each part placed when the check reads it (never all at once);
/// `bounds[k]` is the box of part `k`'s triangles. The selection must be a scene's without a
/// sharding hook.
pub fn run_instanced(
    scene: &InstancedScene,
    bounds: &[Aabb],
    sel: &Selection,
    settings: &Settings,
) -> Result<Outcome, String> {
    run_instanced_with(scene, bounds, sel, settings, |_| None)
}

/// [`run_instanced`], where `stand_in(parts)` (called once the parts are known and each side
/// of the selection holds one) may give the outcome instead of the check: the result cache's
/// per-part-pair reuse over the scene's parts, placed as they are read.
pub fn run_instanced_with(
    scene: &InstancedScene,
    bounds: &[Aabb],
    sel: &Selection,
    settings: &Settings,
    stand_in: impl FnOnce(&[Part]) -> Option<Outcome>,
) -> Result<Outcome, String> {
    if !sel.scene || sel.hook.is_some() {
        return Err("an instanced scene is checked in scene mode without a sharding hook".to_string());
    }
    let parts = parts_of_scene(scene, bounds);
    let (sa, sb) = selected(&parts, sel)?;
    if let Some(o) = stand_in(&parts) {
        return Ok(o);
    }
    by_parts([Source::Placed(scene); 2], parts, &sa, &sb, sel, settings)
}

/// The selected parts of each side (indices into `parts`); an error when a side has none.
fn selected(parts: &[Part], sel: &Selection) -> Result<(Vec<usize>, Vec<usize>), String> {
    let b_input = if sel.scene { 0 } else { 1 };
    let sa = select(parts, 0, &sel.select_a, &sel.exclude);
    let sb = select(parts, b_input, &sel.select_b, &sel.exclude);
    for (s, globs, side) in [(&sa, &sel.select_a, "a"), (&sb, &sel.select_b, "b")] {
        if s.is_empty() {
            return Err(if globs.is_empty() {
                format!("no part left to check on side {side} after --exclude")
            } else {
                format!("--select-{side} {} matches no part", globs.join(","))
            });
        }
    }
    Ok((sa, sb))
}

/// The part-by-part check of the selected parts `sa` against `sb` (scene mode or a selection).
fn by_parts(
    sources: [Source<'_>; 2],
    parts: Vec<Part>,
    sa: &[usize],
    sb: &[usize],
    sel: &Selection,
    settings: &Settings,
) -> Result<Outcome, String> {
    let pairing = if sel.scene && sel.select_b.is_empty() { Pairing::AllVsAll } else { Pairing::Cross };
    if candidates_exceed(&parts, sa, sb, pairing, settings, MAX_CANDIDATE_PART_PAIRS) {
        return Err(format!(
            "more than {MAX_CANDIDATE_PART_PAIRS} candidate part pairs (parts whose boxes come within the search \
             margin of each other), the most meshclash checks in one run: narrow it with \
             --select-a/--select-b/--exclude, or shard it (meshclash plan)"
        ));
    }
    let keep = |x, y| sel.hook.as_ref().is_none_or(|h| h.0.keep(x, y));
    let ar = check_parts_from(sources, parts, sa, sb, pairing, settings, &keep);
    let mut pairs_seen = std::collections::HashSet::new();
    let AssemblyResult {
        parts: ar_parts,
        part_pairs: ar_pairs,
        built,
        sah_builds,
        sharing,
        build_ms,
        query_ms,
    } = ar;
    let candidate_part_pairs = ar_pairs.len();
    let mut reduction = PartPairReduction::new(settings.detail);
    reduction.merged.reserve_exact(ar_pairs.iter().map(|pp| pp.result.pairs.len()).sum());
    for pp in ar_pairs {
        let (x, y) = (pp.a.min(pp.b), pp.a.max(pp.b));
        if x == y || !pairs_seen.insert((x, y)) {
            continue; // a part selected on both sides, or the mirror of a pair already done
        }
        reduction.add(pp.a, pp.b, pp.result);
    }
    let info = AssemblyInfo {
        mode: "parts",
        selected: [sa.len(), sb.len()],
        candidate_part_pairs,
        built_parts: Some(built.iter().filter(|b| **b).count()),
        sah_builds: Some(sah_builds),
        sharing: Some(sharing),
    };
    let (result, part_pairs) = reduction.finish(crate::check::query::Timings { build_ms, query_ms });
    Ok(Outcome { result, parts: ar_parts, part_pairs, info })
}

/// The reduction of a parts-mode check over its part pairs, in the order they are added: the
/// merged findings (sorted at the end), the counts, the scene's closest pair (smallest distance,
/// then triangle indices), the first containment clash, and a [`PartPairSummary`] for every pair
/// that is not clear. Used by the check itself and by the result cache, which adds stored and
/// checked pairs alike, so both give the same outcome.
#[derive(Debug)]
pub struct PartPairReduction {
    detail: Detail,
    /// The findings so far (reserve on it when their number is known).
    pub merged: Vec<PairFinding>,
    part_pairs: Vec<PartPairSummary>,
    closest: Option<crate::check::query::Closest>,
    containment: Containment,
    counts: crate::check::query::Counts,
}

impl PartPairReduction {
    /// An empty reduction; with [`Detail::Parts`] the pairs' triangle-pair lists are dropped.
    pub fn new(detail: Detail) -> PartPairReduction {
        PartPairReduction {
            detail,
            merged: Vec::new(),
            part_pairs: Vec::new(),
            closest: None,
            containment: Containment::None,
            counts: Default::default(),
        }
    }

    /// Adds part pair `(a, b)`'s result.
    pub fn add(&mut self, a: usize, b: usize, mut r: ClashResult) {
        if self.detail == Detail::Parts {
            r.pairs = Vec::new();
        }
        self.merged.extend(r.pairs.iter().copied());
        self.counts.merge(&r.counts);
        if let Some(c) = r.closest {
            if self.closest.is_none_or(|m| (c.distance, c.a.0, c.b.0) < (m.distance, m.a.0, m.b.0)) {
                self.closest = Some(c);
            }
        }
        if self.containment == Containment::None && r.containment.is_clash() {
            self.containment = r.containment.clone();
        }
        if r.verdict != Verdict::Clear || r.containment != Containment::None {
            self.part_pairs.push(PartPairSummary {
                a,
                b,
                verdict: r.verdict,
                counts: r.counts,
                min_distance: r.closest.map(|c| c.distance),
                containment: r.containment.clone(),
                closest: r.closest,
                pairs: r.pairs.iter().map(|p| (p.a, p.b)).collect(),
            });
        }
        // r (and its pair list) is dropped here: each list is held once, in `merged`.
    }

    /// The merged result (findings sorted by triangle pair, verdict the worst part pair's) and
    /// the part pairs that are not clear.
    pub fn finish(mut self, timings: crate::check::query::Timings) -> (ClashResult, Vec<PartPairSummary>) {
        // Each triangle pair is found in one part pair only, so the keys are distinct and any
        // sort gives one order: sorted in parallel.
        self.merged.par_sort_unstable_by_key(|p| (p.a, p.b));
        let verdict = self.part_pairs.iter().map(|p| p.verdict).max().unwrap_or(Verdict::Clear);
        let result = ClashResult {
            pairs: self.merged,
            counts: self.counts,
            closest: self.closest,
            verdict,
            containment: self.containment,
            closed: [None, None],
            trees: Default::default(),
            timings,
        };
        (result, self.part_pairs)
    }
}

/// The most candidate part pairs (part boxes within the search margin of each other) one run
/// checks. Each costs its result (a few hundred bytes, more with findings) until the report is
/// written, so 2^23 pairs keep a scene within a few GB; a scene beyond it (a million parts
/// stacked in one place, say) is refused with exit 2 before any pair is collected, instead of
/// exhausting memory.
pub const MAX_CANDIDATE_PART_PAIRS: usize = 1 << 23;

/// The broad phase over part boxes: a tree over each side's selected part boxes, walked together;
/// `each(a, b, out)` gets every candidate part pair (boxes within the search margin; in
/// all-vs-all pairing each unordered pair once, `a < b`). The walk stops descending once
/// `go_on` says no.
fn part_box_walk<T: Send>(
    parts: &[Part],
    sel_a: &[usize],
    sel_b: &[usize],
    pairing: Pairing,
    settings: &Settings,
    go_on: &(dyn Fn() -> bool + Sync),
    each: impl Fn(usize, usize, &mut Vec<T>) + Sync,
) -> Vec<T> {
    let tol = settings.tolerances;
    let boxes = |sel: &[usize]| sel.iter().map(|&i| parts[i].bounds).collect::<Vec<_>>();
    let opts = BuildOptions { leaf_size: 1, ..settings.bvh };
    let (ba, bb) = (Bvh::build_from_boxes(&boxes(sel_a), opts), Bvh::build_from_boxes(&boxes(sel_b), opts));
    traverse::collect_pairs(
        &ba,
        &bb,
        |x, y| go_on() && tol.boxes_may_meet(x, y),
        |la, lb, out| {
            for &i in la {
                for &j in lb {
                    let (pa, pb) = (sel_a[i as usize], sel_b[j as usize]);
                    let wanted = match pairing {
                        Pairing::Cross => true,
                        Pairing::AllVsAll => pa < pb,
                    };
                    if wanted && tol.boxes_may_meet(&parts[pa].bounds, &parts[pb].bounds) {
                        each(pa, pb, out);
                    }
                }
            }
        },
    )
}

/// Would the broad phase of `sel_a` against `sel_b` find more than `cap` candidate part pairs?
/// A counting walk over the part boxes that stops as soon as the count passes `cap` and keeps
/// nothing.
fn candidates_exceed(
    parts: &[Part],
    sel_a: &[usize],
    sel_b: &[usize],
    pairing: Pairing,
    settings: &Settings,
    cap: usize,
) -> bool {
    use std::sync::atomic::{AtomicUsize, Ordering};
    // Cheap bound first: fewer possible pairs than the cap cannot exceed it.
    if sel_a.len().saturating_mul(sel_b.len()) <= cap {
        return false;
    }
    let count = AtomicUsize::new(0);
    let _: Vec<()> = part_box_walk(
        parts,
        sel_a,
        sel_b,
        pairing,
        settings,
        &|| count.load(Ordering::Relaxed) <= cap,
        |_, _, _| {
            count.fetch_add(1, Ordering::Relaxed);
        },
    );
    count.load(Ordering::Relaxed) > cap
}

/// File mode with a file of several parts (objects, or bodies with `--split-bodies`), when no
/// pair crosses: closedness, outward winding, containment and face-to-face volume overlap are
/// decided per part pair, as scene mode decides them, not per file. A part duplicated inside a
/// multi-part file (its faces coinciding with the other file's part, outward normals agreeing)
/// or hidden inside one closed part of a file whose other parts are open is a clash like the
/// same part alone; such a pair is listed in `part_pairs` even when no triangles meet. The
/// file-level containment stands when it already is a clash.
fn per_part_containment(
    parts: &[Part],
    a: &Mesh,
    b: &Mesh,
    result: &mut ClashResult,
    part_pairs: &mut Vec<PartPairSummary>,
    settings: &Settings,
) {
    let side = |input: u8| (0..parts.len()).filter(|&i| parts[i].input == input).collect::<Vec<_>>();
    let (sa, sb) = (side(0), side(1));
    if (sa.len() <= 1 && sb.len() <= 1) || result.counts.crossing > 0 {
        return;
    }
    let ar = check_parts([a, b], parts.to_vec(), &sa, &sb, Pairing::Cross, settings);
    let mut first: Option<Containment> = None;
    for pp in ar.part_pairs.iter().filter(|pp| pp.result.containment.is_clash()) {
        let c = pp.result.containment.clone();
        first.get_or_insert_with(|| c.clone());
        match part_pairs.iter_mut().find(|s| (s.a, s.b) == (pp.a, pp.b)) {
            Some(s) => {
                s.containment = c;
                s.verdict = Verdict::Clash;
            }
            None => part_pairs.push(PartPairSummary {
                a: pp.a,
                b: pp.b,
                verdict: Verdict::Clash,
                counts: pp.result.counts,
                min_distance: pp.result.closest.map(|c| c.distance),
                containment: c,
                closest: pp.result.closest,
                pairs: Vec::new(),
            }),
        }
    }
    part_pairs.sort_by_key(|s| (s.a, s.b));
    if let Some(c) = first {
        if !result.containment.is_clash() {
            result.containment = c;
        }
        result.verdict = Verdict::Clash;
    }
}

/// File mode without the lists: [`group_by_part`] from the tally of each part pair's pairs
/// (keyed by the objects of A and B), giving the same summaries with empty pair lists.
fn group_tallies(
    parts: &[Part],
    a: &Mesh,
    b: &Mesh,
    tallies: std::collections::BTreeMap<(u32, u32), Tally>,
) -> Vec<PartPairSummary> {
    let index: HashMap<(u8, u32), usize> =
        parts.iter().enumerate().map(|(i, p)| ((p.input, p.object), i)).collect();
    let mut out: Vec<PartPairSummary> = tallies
        .into_iter()
        .map(|((oa, ob), t)| {
            let mut closest = t.best.map(|p| crate::check::query::pair_witness(a, b, &p));
            if let Some(c) = closest.as_mut().filter(|c| c.distance > 0.0) {
                let (ta, tb) = (crate::bvh::triangle(a, c.a.0), crate::bvh::triangle(b, c.b.0));
                c.distance = crate::narrow::exact_distance::exact_distance_sq(&ta, &tb).rounded();
            }
            PartPairSummary {
                a: index[&(0, oa)],
                b: index[&(1, ob)],
                verdict: t.verdict(),
                counts: t.counts,
                min_distance: closest.map(|c| c.distance),
                containment: Containment::None,
                closest,
                pairs: Vec::new(),
            }
        })
        .collect();
    out.sort_by_key(|s| (s.a, s.b));
    out
}

/// File mode: group the pairs of a whole-file check by the parts they belong to (also used by
/// [`crate::api`], so both report files mode the same way).
pub fn group_by_part(parts: &[Part], a: &Mesh, b: &Mesh, r: &ClashResult) -> Vec<PartPairSummary> {
    let index: HashMap<(u8, u32), usize> =
        parts.iter().enumerate().map(|(i, p)| ((p.input, p.object), i)).collect();
    let mut by: std::collections::BTreeMap<(usize, usize), PartPairSummary> = Default::default();
    for p in &r.pairs {
        let pa = index[&(0, a.tri_object[p.a as usize])];
        let pb = index[&(1, b.tri_object[p.b as usize])];
        let e = by.entry((pa, pb)).or_insert_with(|| PartPairSummary {
            a: pa,
            b: pb,
            verdict: Verdict::Clear,
            counts: Default::default(),
            min_distance: None,
            containment: Containment::None,
            closest: None,
            pairs: Vec::new(),
        });
        let v = e.counts.record(p);
        e.verdict = e.verdict.max(v);
        e.pairs.push((p.a, p.b));
        // Pairs come sorted by (a, b): the first of the smallest distance is the witness.
        if e.closest.is_none_or(|c| p.distance < c.distance) {
            e.closest = Some(crate::check::query::pair_witness(a, b, p));
        }
        e.min_distance = e.closest.map(|c| c.distance);
    }
    // A positive minimum is reported as the exact distance of its pair, correctly rounded.
    by.into_values()
        .map(|mut e| {
            if let Some(c) = e.closest.as_mut().filter(|c| c.distance > 0.0) {
                let (ta, tb) = (crate::bvh::triangle(a, c.a.0), crate::bvh::triangle(b, c.b.0));
                c.distance = crate::narrow::exact_distance::exact_distance_sq(&ta, &tb).rounded();
                e.min_distance = Some(c.distance);
            }
            e
        })
        .collect()
}
