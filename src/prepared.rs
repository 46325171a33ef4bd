//! Prepared meshes: a mesh whose tree is built once, then placed under any number of affine
//! transforms for the yes/no and distance queries a collision manager makes.
//!
//! A placed mesh ([`Placed`]) reads its own world coordinates — every vertex transformed in f64,
//! exactly as `--transform` does — and walks the prepared tree through a conservative box map
//! ([`BoxMap`], the one instances of a glTF mesh share trees with), so every verdict and distance
//! is exactly what a tree built on the world coordinates would give; only the tree statistics
//! differ (they describe the prepared tree).

pub mod broad;
pub mod topology;

use crate::bvh::traverse::{MappedTree, Tree};
use crate::bvh::{BuildOptions, Bvh, Node};
use crate::check::containment::{self, Containment, Topology};
use crate::check::query::{self, Closest, DistanceError, PairFinding, PairKind, Settings};
use crate::error::{Error, InputProblem, Location, Result};
use crate::geom::predicates::{self, BoxMap, PlacementRounding, Tolerances};
use crate::geom::{Aabb, DVec3};
use crate::narrow::convex::{self, Penetration, Polytope, Surface};
use crate::narrow::tri_tri;
use crate::scene::mesh::{Mesh, TriMesh};
use glam::DMat4;
use smallvec::SmallVec;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};
use topology::Fragile;

/// A mesh with its tree built once, to be placed under many transforms ([`Prepared::place`]).
#[derive(Debug)]
pub struct Prepared {
    /// The mesh in its own coordinates.
    pub mesh: Mesh,
    /// Its tree.
    pub tree: Bvh,
    /// Its name in error messages and reports.
    pub label: PathBuf,
    surface: OnceLock<Option<Surface>>,
    convex: OnceLock<bool>,
    /// The face frames of the mesh's own coordinates ([`convex::Frames`]), for the convex
    /// depth of placements that are exact translations.
    frames: OnceLock<convex::Frames>,
    topology: OnceLock<Arc<Topology>>,
    /// The ball of the mesh's own vertices, and whether their box lies in the tree's root box
    /// (where a box map's slack covers every vertex).
    ball: OnceLock<(Ball, bool)>,
    /// The vertex pairs and triangles whose coincidence or collinearity rounding under a
    /// placement could change ([`Fragile`]).
    fragile: OnceLock<Option<Fragile>>,
    /// The exact box of every vertex in the mesh's own coordinates (used or not).
    root: Aabb,
    /// Does every vertex belong to some triangle?
    all_used: bool,
}

impl Prepared {
    /// Build the tree of `mesh` (validated by [`mesh_from_arrays`] or a loader).
    pub fn new(label: &Path, mesh: Mesh, opts: BuildOptions) -> Result<Prepared> {
        query::check_range(&mesh, label)?;
        let tree = Bvh::build(&mesh, opts);
        let root = Aabb::of_points(&mesh.positions);
        let mut used = vec![false; mesh.positions.len()];
        mesh.triangles.iter().flatten().for_each(|&v| used[v as usize] = true);
        let all_used = used.iter().all(|&u| u);
        Ok(Prepared {
            mesh,
            tree,
            label: label.to_path_buf(),
            surface: OnceLock::new(),
            convex: OnceLock::new(),
            frames: OnceLock::new(),
            topology: OnceLock::new(),
            ball: OnceLock::new(),
            fragile: OnceLock::new(),
            root,
            all_used,
        })
    }

    /// The vertex pairs and triangles a placement's rounding could change ([`Fragile`]), found
    /// once.
    fn fragile(&self) -> Option<&Fragile> {
        self.fragile
            .get_or_init(|| Fragile::of(&self.mesh.positions, &self.mesh.triangles, self.topology()))
            .as_ref()
    }

    /// The bounding ball of the mesh in its own coordinates ([`Ball::of_points`]), found once;
    /// a placement by a box map derives its ball from it ([`Ball::mapped`]).
    pub fn ball(&self) -> Ball {
        self.own_ball().0
    }

    fn own_ball(&self) -> &(Ball, bool) {
        self.ball.get_or_init(|| {
            let root = &self.root;
            (Ball::of_points(&self.mesh.positions, root), self.tree.bounds().contains(root))
        })
    }

    /// The closed surface's edges (`None` unless closed and consistently oriented), found once.
    pub fn surface(&self) -> Option<&Surface> {
        self.surface.get_or_init(|| Surface::of(&self.mesh.triangles)).as_ref()
    }

    /// Exact: is the mesh, in its own coordinates, a convex polytope facing out
    /// ([`convex::is_convex`])? Decided once, when first asked.
    pub fn is_convex(&self) -> bool {
        *self.convex.get_or_init(|| {
            self.surface().is_some_and(|s| convex::is_convex(&self.mesh.positions, &self.mesh.triangles, s))
        })
    }

    /// The closedness and components of the mesh in its own coordinates, found once.
    fn topology(&self) -> &Arc<Topology> {
        self.topology.get_or_init(|| Arc::new(containment::topology(&self.mesh)))
    }

    /// Place the mesh under `m`. Nothing is computed on the vertices yet: the placement keeps
    /// the transform and a box that holds every world vertex ([`Coarse`]), enough for a broad
    /// phase; the world coordinates (every vertex transformed in f64, as `--transform` does;
    /// identity keeps the coordinates as they are), the tree mapped onto them and their exact
    /// box are computed when a query first reads them ([`Placed::positions`]). The errors of
    /// the world coordinates (a vertex not finite or beyond the exact range) are raised here:
    /// when the box does not show every vertex clear of them, the vertices are placed now.
    pub fn place(self: &Arc<Self>, m: DMat4) -> Result<Placed> {
        if m == DMat4::IDENTITY {
            let laid = Laid { world: None, tree: Mapping::Own, root: self.root };
            return Ok(self.placed(m, self.root, OnceLock::from(laid)));
        }
        let rows = rows_of(&m);
        if let Some((coarse, map)) =
            Coarse::of(&rows, &self.root).zip(BoxMap::fit(rows, &self.tree.bounds(), std::iter::empty()))
        {
            let reach = coarse.map_box(&self.root);
            let bound = reach.min.abs().max(reach.max.abs()).max_element();
            if bound.is_finite() && bound <= predicates::MAX_EXACT_MAGNITUDE {
                let mut p = self.placed(m, reach, OnceLock::new());
                p.coarse = Some((coarse, map));
                // When every vertex is a triangle's, the outline's boxes hold them all: their
                // union is a tighter box for a rotated mesh.
                let outline = p.outline();
                if self.all_used && !outline.is_empty() {
                    let u = outline.iter().fold(Aabb::EMPTY, |b, x| b.union(*x));
                    p.reach = Aabb { min: u.min.max(reach.min), max: u.max.min(reach.max) };
                }
                return Ok(p);
            }
        }
        self.place_now(m)
    }

    /// Place the mesh under `m` (not the identity) with its world coordinates computed at once:
    /// the first vertex that is not finite or beyond the exact range after the transform is the
    /// error.
    fn place_now(self: &Arc<Self>, m: DMat4) -> Result<Placed> {
        let local = &self.mesh.positions;
        let mut world = Vec::with_capacity(local.len());
        for (i, p) in local.iter().enumerate() {
            let w = m.transform_point3(*p);
            if !w.is_finite() {
                let problem = InputProblem::NonFiniteAfterTransform { value: None };
                return Err(Error::at(&self.label, Location::Vertex(i), problem));
            }
            if w.abs().max_element() > predicates::MAX_EXACT_MAGNITUDE {
                return Err(Error::at(&self.label, Location::Vertex(i), InputProblem::BeyondExactRange));
            }
            world.push(w);
        }
        let laid = self.lay(&m, world);
        Ok(self.placed(m, laid.root, OnceLock::from(laid)))
    }

    /// A fresh placement under `m` with box `reach` and what is computed of it (`laid`):
    /// nothing else found yet.
    fn placed(self: &Arc<Self>, m: DMat4, reach: Aabb, laid: OnceLock<Laid>) -> Placed {
        Placed {
            prepared: self.clone(),
            transform: m,
            reach,
            coarse: None,
            outline: OnceLock::new(),
            laid,
            reads: AtomicUsize::new(0),
            topology: OnceLock::new(),
            convex: OnceLock::new(),
            translated: OnceLock::new(),
            ball: OnceLock::new(),
            id: next_id(),
        }
    }

    /// The tree mapped onto the world coordinates `world` (placed by `m`, not the identity) and
    /// their exact box.
    fn lay(&self, m: &DMat4, world: Vec<DVec3>) -> Laid {
        let local = &self.mesh.positions;
        let pairs = local.iter().copied().zip(world.iter().copied());
        let tree = match BoxMap::fit(rows_of(m), &self.tree.bounds(), pairs) {
            Some(map) => Mapping::Mapped(map),
            None => Mapping::Refit(refit(&self.tree, &world, &self.mesh.triangles)),
        };
        let root = Aabb::of_points(&world);
        Laid { world: Some(world), tree, root }
    }
}

/// The rows `[r_i0, r_i1, r_i2, t_i]` of the affine part of `m`.
fn rows_of(m: &DMat4) -> [[f64; 4]; 3] {
    [0, 1, 2].map(|k| [m.x_axis[k], m.y_axis[k], m.z_axis[k], m.w_axis[k]])
}

/// A conservative map of boxes under a placement, found from the transform alone: the box it
/// gives for a box of the prepared mesh's own coordinates holds the f64 image
/// (`DMat4::transform_point3`, whatever the order of its products and sums) of every point of
/// that box. It is the affine map with no measured deviation ([`BoxMap::fit`] over no vertex
/// pair, the source root the mesh's own box: it holds every point whose image is `fl(R x + t)`
/// evaluated in the map's order), its boxes widened by the search margin of the map's scale
/// `S = max_i (|t_i| + Σ_j |r_ij| max(|root.min_j|, |root.max_j|))`
/// ([`predicates::distance_rounding_slack`], 128 units of rounding of `S`). That covers the
/// rest: an image computed in another order is, like `fl(R x + t)`, within `γ_4 S` of the exact
/// image (Higham, §3.1; `γ_4 ≈ 4u`), so within `8.1u S` of `fl(R x + t)`, and the widening itself
/// rounds by at most `u (|box| + margin)`, about `u S`.
#[derive(Debug, Clone, Copy)]
pub struct Coarse {
    map: BoxMap,
    margin: f64,
}

impl Coarse {
    /// The coarse map of `rows` for boxes inside `root`; `None` when the map is not finite.
    pub fn of(rows: &[[f64; 4]; 3], root: &Aabb) -> Option<Coarse> {
        let map = BoxMap::fit(*rows, root, std::iter::empty())?;
        let big = root.min.abs().max(root.max.abs()).to_array();
        let scale = rows
            .iter()
            .map(|r| r[3].abs() + (0..3).map(|j| r[j].abs() * big[j]).sum::<f64>())
            .fold(0.0f64, f64::max);
        Some(Coarse { map, margin: predicates::distance_rounding_slack(scale) })
    }

    /// A box holding the image of every point of `b` (inside the root given to [`Coarse::of`]).
    pub fn map_box(&self, b: &Aabb) -> Aabb {
        let m = DVec3::splat(self.margin);
        let b = self.map.map_box(b);
        Aabb { min: b.min - m, max: b.max + m }
    }
}

/// Down to this depth, the nodes of a placed mesh's tree give its outline
/// ([`Placed::outline`]): at most 2^6 boxes (a speed threshold, no answer depends on it).
const OUTLINE_DEPTH: u32 = 6;

/// A fresh placement id (never reused in the process).
fn next_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// How a placed mesh sees the prepared tree.
#[derive(Debug)]
enum Mapping {
    /// Identity placement: the tree as built.
    Own,
    /// Boxes mapped by the placement (conservatively widened).
    Mapped(BoxMap),
    /// The fallback when no box map fits: same topology, exact boxes.
    Refit(Bvh),
}

fn refit(template: &Bvh, world: &[DVec3], tris: &[[u32; 3]]) -> Bvh {
    let mut nodes: Vec<Node> = template.nodes.clone();
    for i in (0..nodes.len()).rev() {
        let n = nodes[i];
        nodes[i].bounds = if n.is_leaf() {
            template.leaf_prims(&n).iter().fold(Aabb::EMPTY, |b, &t| {
                b.union(Aabb::of_triangle(&tris[t as usize].map(|v| world[v as usize])))
            })
        } else {
            nodes[i + 1].bounds.union(nodes[n.a as usize].bounds)
        };
    }
    Bvh { nodes, prims: template.prims.clone() }
}

/// What a placement computes on the vertices: the world coordinates (`None`: the prepared
/// mesh's own), the view of the prepared tree, the exact world box.
#[derive(Debug)]
struct Laid {
    world: Option<Vec<DVec3>>,
    tree: Mapping,
    root: Aabb,
}

/// A prepared mesh under one placement: its world coordinates and a view of the prepared tree,
/// computed when first read.
#[derive(Debug)]
pub struct Placed {
    /// The prepared mesh.
    pub prepared: Arc<Prepared>,
    /// The placement.
    pub transform: DMat4,
    /// A box holding every world vertex of the triangles, known without them
    /// ([`Placed::reach`]).
    reach: Aabb,
    /// When the world coordinates were not computed at once: the map of boxes known without
    /// them, and the tree's box map, by whose evaluation ([`BoxMap::image`]) they are computed.
    coarse: Option<(Coarse, BoxMap)>,
    outline: OnceLock<Vec<Aabb>>,
    laid: OnceLock<Laid>,
    /// How many vertices were computed one by one before the world coordinates
    /// ([`Placed::vertex`]; approximate under concurrent reads: only speed depends on it).
    reads: AtomicUsize,
    topology: OnceLock<Arc<Topology>>,
    convex: OnceLock<bool>,
    translated: OnceLock<bool>,
    ball: OnceLock<Ball>,
    id: u64,
}

/// A ball that holds every vertex of a placed mesh (so its convex hull, and everything the
/// collision and distance queries look at): center and radius, the radius rounded up by the
/// search margin of the coordinates' scale ([`predicates::distance_rounding_slack`]), so that
/// `|v - center| <= radius` holds exactly for every vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ball {
    /// The center (the box center).
    pub center: DVec3,
    /// The radius, rounded up.
    pub radius: f64,
    /// The search margin of the coordinates' scale.
    pub slack: f64,
}

impl Ball {
    /// The ball of `pos` around the center of their box `root`: the largest f64 distance to
    /// the center, rounded up by the search margin of the coordinates' scale.
    pub fn of_points(pos: &[DVec3], root: &Aabb) -> Ball {
        let center = root.center();
        let slack = predicates::distance_rounding_slack(root.max_abs());
        let r = pos.iter().map(|v| (*v - center).length_squared()).fold(0.0f64, f64::max).sqrt();
        Ball { center, radius: r + slack, slack }
    }

    /// A ball holding every target vertex of `map` whose source vertex lies in `self` (a ball of
    /// the source coordinates), `root` the targets' exact box (its scale gives the slack), with
    /// no pass over the vertices. The center is the f64 image of the source center. Every
    /// target `w` of a source `p` lies within `map.slack` (per axis) of the exact image
    /// `R p + t`, and so does the center's f64 image of the exact image of the source center
    /// (`map.slack` covers that rounding too, see [`BoxMap`]); so
    /// `|w - center| <= |R (p - c)| + 2 |slack| <= σ(R) r + 2 |slack|`, with `σ(R)` the largest
    /// singular value of `R`, bounded above by [`predicates::singular_value_bounds`]. The sum is rounded up by the
    /// search margin of the targets' scale (its f64 rounding is a few ulps of it).
    pub fn mapped(&self, map: &BoxMap, root: &Aabb) -> Ball {
        let center = map.image(self.center);
        let slack = predicates::distance_rounding_slack(root.max_abs());
        let radius =
            predicates::singular_value_bounds(&map.rows).1 * self.radius + 2.0 * map.slack.length() + slack;
        Ball { center, radius, slack }
    }

    /// A lower bound of the distance between any point of `self` and any point of `o`
    /// (negative when the balls overlap): the f64 distance of the centers less both radii and
    /// the rounding of that distance.
    pub fn gap(&self, o: &Ball) -> f64 {
        (self.center - o.center).length() - self.radius - o.radius - self.slack.max(o.slack)
    }

    /// Certainly apart: no point of one ball within the other.
    pub fn apart(&self, o: &Ball) -> bool {
        self.gap(o) > 0.0
    }
}

/// A placed mesh read vertex by vertex ([`Placed::corners`]): from the world coordinates when
/// they were computed when the view was made, else each vertex alone ([`Placed::vertex`]).
#[derive(Debug, Clone, Copy)]
pub struct Corners<'a> {
    placed: &'a Placed,
    world: Option<&'a [DVec3]>,
}

impl TriMesh for Corners<'_> {
    #[inline]
    fn vertex_count(&self) -> usize {
        self.placed.prepared.mesh.positions.len()
    }
    #[inline]
    fn vertex(&self, v: u32) -> DVec3 {
        match self.world {
            Some(w) => w[v as usize],
            None => self.placed.vertex(v),
        }
    }
    #[inline]
    fn triangle_count(&self) -> usize {
        self.placed.prepared.mesh.triangles.len()
    }
    #[inline]
    fn indices(&self, t: u32) -> [u32; 3] {
        self.placed.prepared.mesh.triangles[t as usize]
    }
    fn positions(&self) -> std::borrow::Cow<'_, [DVec3]> {
        std::borrow::Cow::Borrowed(self.placed.positions())
    }
}

/// A placed mesh as the checks read it (world coordinates; nothing copied).
#[derive(Debug, Clone, Copy)]
pub struct PlacedMesh<'a> {
    positions: &'a [DVec3],
    triangles: &'a [[u32; 3]],
}

impl TriMesh for PlacedMesh<'_> {
    #[inline]
    fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    #[inline]
    fn vertex(&self, v: u32) -> DVec3 {
        self.positions[v as usize]
    }
    #[inline]
    fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
    #[inline]
    fn indices(&self, t: u32) -> [u32; 3] {
        self.triangles[t as usize]
    }
    fn positions(&self) -> std::borrow::Cow<'_, [DVec3]> {
        std::borrow::Cow::Borrowed(self.positions)
    }
}

impl Placed {
    /// The world coordinates, tree view and exact box, computed on first use (`place` checked
    /// the range already). Each vertex is the tree's box map's image of it ([`BoxMap::image`]:
    /// the products and sums of `DMat4::transform_point3`, in its order, so the same bits as
    /// placing at once), so that map, fitted over no vertex, is the map a fit over every vertex
    /// gives (each deviation is zero), with no pass to measure it.
    fn laid(&self) -> &Laid {
        self.laid.get_or_init(|| {
            let Some((_, map)) = &self.coarse else { unreachable!("placed at once") };
            let mut root = Aabb::EMPTY;
            let world: Vec<DVec3> = self
                .prepared
                .mesh
                .positions
                .iter()
                .map(|p| {
                    let w = map.image(*p);
                    root = root.grow(w);
                    w
                })
                .collect();
            Laid { world: Some(world), tree: Mapping::Mapped(*map), root }
        })
    }

    /// The world coordinates.
    pub fn positions(&self) -> &[DVec3] {
        self.laid().world.as_deref().unwrap_or(&self.prepared.mesh.positions)
    }

    /// The world coordinates of vertex `v`: the very value [`Placed::positions`] holds, found
    /// alone (when the world coordinates are not computed yet, by transforming that vertex
    /// as they would be). Once half as many vertices as the mesh has were found alone, the
    /// world coordinates are computed (a walk that reads that many reads more).
    pub fn vertex(&self, v: u32) -> DVec3 {
        let local = self.prepared.mesh.positions[v as usize];
        let laid = match (self.laid.get(), &self.coarse) {
            (Some(l), _) => l,
            (None, Some((_, map))) => {
                // A plain load and store: a lost count under concurrent reads only delays
                // the switch.
                let n = self.reads.load(Ordering::Relaxed);
                if n < self.prepared.mesh.positions.len() / 2 {
                    self.reads.store(n + 1, Ordering::Relaxed);
                    return map.image(local);
                }
                self.laid()
            }
            (None, None) => self.laid(),
        };
        laid.world.as_ref().map_or(local, |w| w[v as usize])
    }

    /// The world corners of triangle `t` ([`Placed::vertex`]).
    pub fn triangle(&self, t: u32) -> [DVec3; 3] {
        self.prepared.mesh.triangles[t as usize].map(|v| self.vertex(v))
    }

    /// Are the world coordinates computed (a query has read them)?
    pub fn is_laid(&self) -> bool {
        self.laid.get().is_some()
    }

    /// The mesh view (the world coordinates, computed now if they are not yet).
    pub fn mesh(&self) -> PlacedMesh<'_> {
        PlacedMesh { positions: self.positions(), triangles: &self.prepared.mesh.triangles }
    }

    /// The mesh view for a walk that reads few triangles (the search for a first meeting
    /// pair, a witness): each vertex read alone ([`Placed::vertex`]) until the world
    /// coordinates are computed. Same values as [`Placed::mesh`].
    pub fn corners(&self) -> Corners<'_> {
        let world = self.laid.get().map(|l| l.world.as_deref().unwrap_or(&self.prepared.mesh.positions));
        Corners { placed: self, world }
    }

    /// The tree view: the prepared tree through the placement's box map, or a tree refitted on
    /// the world coordinates when no box map fits them. When the world coordinates were not
    /// computed at once, the root's box is [`Placed::reach`] (known from the transform: a walk
    /// needs no world coordinate to start, and starts the same whenever they are computed);
    /// else it is the exact box.
    pub fn tree(&self) -> MappedTree<'_> {
        if let Some((_, map)) = &self.coarse {
            return MappedTree { bvh: &self.prepared.tree, map: Some(*map), root: self.reach };
        }
        let laid = self.laid();
        let (bvh, map) = match &laid.tree {
            Mapping::Own => (&self.prepared.tree, None),
            Mapping::Mapped(m) => (&self.prepared.tree, Some(*m)),
            Mapping::Refit(t) => (t, None),
        };
        MappedTree { bvh, map, root: laid.root }
    }

    /// The exact world box.
    pub fn bounds(&self) -> Aabb {
        self.laid().root
    }

    /// A box holding every world vertex of the mesh's triangles (every world vertex when some
    /// vertex is in no triangle), known from the placement alone ([`Coarse`], and the union of
    /// [`Placed::outline`]); the exact box when the placement computed the world coordinates at
    /// once. It never changes.
    pub fn reach(&self) -> Aabb {
        self.reach
    }

    /// Exact: are the world coordinates a convex polytope facing out? The prepared mesh's
    /// answer when they are its own coordinates or an exact translation of them (orientation
    /// signs unchanged); otherwise decided on the world coordinates, once (a rotated convex
    /// mesh whose coplanar triangles rounding bent apart is not convex).
    pub fn is_convex(&self) -> bool {
        *self.convex.get_or_init(|| {
            let p = &self.prepared;
            if !p.is_convex() {
                return false;
            }
            match &self.laid().world {
                _ if self.translated() => true,
                None => true,
                Some(w) => p.surface().is_some_and(|s| convex::is_convex(w, &p.mesh.triangles, s)),
            }
        })
    }

    /// The convex polytope the depth computation reads, when [`Placed::is_convex`].
    pub fn polytope(&self) -> Option<Polytope<'_>> {
        if !self.is_convex() {
            return None;
        }
        let p = &self.prepared;
        let surface = p.surface()?;
        // Own coordinates or an exact translation of them: the prepared mesh's face frames.
        let frames = (self.laid().world.is_none() || self.translated())
            .then(|| p.frames.get_or_init(|| convex::Frames::of(&p.mesh.positions, &p.mesh.triangles)));
        Some(Polytope { positions: self.positions(), triangles: &p.mesh.triangles, surface, frames })
    }

    /// This placement's id, unique in the process: answers about a pair of placements can be
    /// kept under the pair of ids (a placed mesh never changes; moving an object places it anew).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Give this placement a fresh id, as placing the mesh again under the same transform
    /// would, without redoing the work: a placement is a function of the prepared mesh and the
    /// transform, so its world coordinates, tree and the facts found about them (ball,
    /// convexity, topology) stay true; only answers kept under the old id stop applying.
    pub fn renew_id(&mut self) {
        self.id = next_id();
    }

    /// The bounding ball of the world vertices ([`Ball`]), found once: the prepared mesh's own
    /// ball for the identity placement, its image ([`Ball::mapped`], no pass over the vertices)
    /// when the tree is mapped, else the ball of the world vertices.
    pub fn ball(&self) -> Ball {
        *self.ball.get_or_init(|| {
            let laid = self.laid();
            match &laid.tree {
                Mapping::Own => self.prepared.ball(),
                Mapping::Mapped(map) if self.prepared.own_ball().1 => {
                    self.prepared.ball().mapped(map, &laid.root)
                }
                Mapping::Mapped(_) | Mapping::Refit(_) => Ball::of_points(self.positions(), &laid.root),
            }
        })
    }

    /// Certainly apart (by their boxes or their balls): the two can neither collide nor be
    /// nearer than [`Placed::gap`]. Boxes that hold them ([`Placed::reach`]) and miss settle
    /// it without the world coordinates.
    pub fn apart(&self, o: &Placed) -> bool {
        !self.reach.overlaps(&o.reach) || !self.bounds().overlaps(&o.bounds()) || self.ball().apart(&o.ball())
    }

    /// Boxes that together hold every triangle of the placed mesh: the boxes of the prepared
    /// tree's nodes at depth [`OUTLINE_DEPTH`] (and of leaves above it), mapped by the
    /// placement's [`Coarse`] map when the world coordinates were not computed at once (none
    /// are read), else the tree view's boxes. Found once.
    pub fn outline(&self) -> &[Aabb] {
        self.outline.get_or_init(|| {
            let own = &self.prepared.tree;
            if own.is_empty() {
                return Vec::new();
            }
            let mut out = Vec::new();
            let mut stack = vec![(0u32, 0u32)];
            while let Some((n, depth)) = stack.pop() {
                if depth < OUTLINE_DEPTH && !own.is_leaf(n) {
                    stack.extend(own.children(n).map(|c| (c, depth + 1)));
                    continue;
                }
                out.push(match &self.coarse {
                    Some((c, _)) => c.map_box(&own.node_box(n)),
                    None => self.tree().node_box(n),
                });
            }
            out
        })
    }

    /// A lower bound of [`Placed::gap`] (so of the distance between the two meshes) from the
    /// boxes that hold them ([`Placed::reach`]) alone: their distance less the search margin
    /// of their coordinates' scale (0 when they overlap). The boxes hold the exact ones, and
    /// their scale is at least theirs: the f64 box distance only shrinks and the margin grows.
    pub fn reach_gap(&self, o: &Placed) -> f64 {
        (self.reach.distance_sq(&o.reach).sqrt() - self.reach_margin().max(o.reach_margin())).max(0.0)
    }

    /// The search margin of the scale of [`Placed::reach`]: at least the margin of the world
    /// coordinates' scale ([`Ball::slack`]).
    pub fn reach_margin(&self) -> f64 {
        predicates::distance_rounding_slack(self.reach.max_abs())
    }

    /// A lower bound of the distance between the two meshes: the larger of their boxes' and
    /// their balls' gaps (0 when both overlap).
    pub fn gap(&self, o: &Placed) -> f64 {
        let (ba, bb) = (self.ball(), o.ball());
        let boxes = self.bounds().distance_sq(&o.bounds()).sqrt() - ba.slack.max(bb.slack);
        boxes.max(ba.gap(&bb)).max(0.0)
    }

    /// Exact: are the world coordinates the prepared mesh's own, or an exact translation of
    /// them ([`predicates::exact_translation`])? Then every orientation sign, every exactly
    /// coincident vertex pair and every degenerate triangle is the same as in the prepared
    /// mesh, so its placement-free answers (convexity, topology) hold here. Decided once.
    fn translated(&self) -> bool {
        *self.translated.get_or_init(|| match &self.laid().world {
            None => true,
            Some(w) => predicates::exact_translation(&self.prepared.mesh.positions, w).is_some(),
        })
    }

    /// Closedness and components ([`containment::topology`]): the prepared mesh's for the
    /// identity placement and when [`Placed::translated`]; for a box-mapped placement, the
    /// prepared mesh's corrected where its rounding merged vertices or changed a triangle's
    /// collinearity ([`Fragile::placed`]); else found on the world coordinates. Found once.
    fn topology(&self) -> &Topology {
        self.topology.get_or_init(|| {
            let p = &self.prepared;
            let laid = self.laid();
            let from_prepared = match (&laid.tree, &laid.world) {
                (Mapping::Own, _) | (_, None) => Some(p.topology().clone()),
                (Mapping::Mapped(map), Some(world)) if p.own_ball().1 => p.fragile().and_then(|f| {
                    f.placed(p.topology(), world, &p.mesh.triangles, &PlacementRounding::of(map))
                }),
                _ => None,
            };
            from_prepared
                .or_else(|| self.translated().then(|| p.topology().clone()))
                .unwrap_or_else(|| Arc::new(containment::topology(&self.mesh())))
        })
    }
}

/// What [`collide`] finds between two placed meshes.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// Triangle pairs that meet (crossing or touching exactly), sorted; with `all` false, at
    /// least one when they meet (the first crossing pair found stops the walk).
    pub contacts: Vec<PairFinding>,
    /// Containment, decided when no triangles meet.
    pub containment: Containment,
}

impl Collision {
    /// Do the two meshes collide: triangles meet (crossing or touching), or one lies inside the
    /// other (containment, including the partial kinds and face-to-face volume overlap).
    pub fn collides(&self) -> bool {
        !self.contacts.is_empty() || self.containment.is_clash()
    }
}

/// Certainly no triangle of `a` meets one of `b`, from their outlines ([`Placed::outline`]) and
/// boxes ([`Placed::reach`]) alone: no box of one's outline may meet one of the other's (a
/// point shared by two triangles lies in a box of each). True says what a tree walk for
/// meeting triangles would find (none) without the world coordinates.
pub fn no_meeting_triangles(a: &Placed, b: &Placed) -> bool {
    let tol = Tolerances::default();
    if !tol.boxes_may_meet(&a.reach(), &b.reach()) {
        return true;
    }
    let (ra, rb) = (a.reach(), b.reach());
    // At most 2^OUTLINE_DEPTH boxes each: kept on the stack (this runs for every candidate pair
    // of a query).
    let near = |o: &[Aabb], r: &Aabb| {
        o.iter().filter(|x| tol.boxes_may_meet(x, r)).copied().collect::<SmallVec<[Aabb; 64]>>()
    };
    let (oa, ob) = (near(a.outline(), &rb), near(b.outline(), &ra));
    !oa.iter().any(|x| ob.iter().any(|y| tol.boxes_may_meet(x, y)))
}

/// Certainly the two do not collide, from their outlines and boxes alone: no triangles meet
/// ([`no_meeting_triangles`]) and no box of either's outline meets the other's box (so no
/// vertex of either's triangles lies in the other's box: nothing is contained). [`collide`]
/// finds no collision then.
pub fn surely_clear(a: &Placed, b: &Placed) -> bool {
    let (ra, rb) = (a.reach(), b.reach());
    !ra.overlaps(&rb)
        || (no_meeting_triangles(a, b)
            && !a.outline().iter().any(|x| x.overlaps(&rb))
            && !b.outline().iter().any(|y| y.overlaps(&ra)))
}

/// Every triangle pair of `a` and `b` that meets exactly (crossing or touching), sorted; with
/// `first`, the walk stops at the first one found (which one depends on timing).
pub fn meeting_pairs<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB, first: bool) -> Vec<PairFinding>
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    if !first {
        return query::find_pairs(a, ta, b, tb, &Settings::default()).0;
    }
    if a.triangle_count() + b.triangle_count() <= SEQUENTIAL_FIRST_CONTACT {
        return first_contact_sequential(a, ta, b, tb).into_iter().collect();
    }
    let tol = Tolerances::default();
    let stop = AtomicBool::new(false);
    let mut found = crate::bvh::traverse::collect_pairs(
        ta,
        tb,
        |x, y| !stop.load(Ordering::Relaxed) && tol.boxes_may_meet(x, y),
        |la, lb, out| {
            let mut room = LeafRoom::default();
            let everywhere = Aabb { min: DVec3::NEG_INFINITY, max: DVec3::INFINITY };
            let leaves = (a, la, &everywhere, b, lb, &everywhere);
            if let Some(p) = first_in_leaves(leaves, &mut room, &|| stop.load(Ordering::Relaxed)) {
                out.push(p);
                stop.store(true, Ordering::Relaxed);
            }
        },
    );
    found.sort_unstable_by_key(|p| (p.a, p.b));
    found
}

/// Up to this many triangles in both meshes together, the first-contact search walks the two
/// trees on one thread: a collision manager runs many small pairs at once, and splitting each
/// into parallel sub-walks cost more than the walk itself (a speed threshold, no verdict
/// depends on it).
const SEQUENTIAL_FIRST_CONTACT: usize = 50_000;

/// The first meeting triangle pair of a depth-first dual walk on this thread. The walk opens
/// the node with the larger box (as the parallel walks do), keeps only the children whose boxes
/// meet the other node's, and walks first the child whose box shares more with it (the larger
/// surface of the two boxes' intersection: where a contact is likelier), so a meeting pair is
/// usually reached without a detour; which pair is found depends only on the trees. At a leaf
/// pair each triangle's box is computed once and compared with the other leaf's box before any
/// pair of triangles: a box that misses a node's box misses every triangle box inside it.
fn first_contact_sequential<A, TA, B, TB>(a: &A, ta: &TA, b: &B, tb: &TB) -> Option<PairFinding>
where
    A: TriMesh + ?Sized,
    TA: Tree + ?Sized,
    B: TriMesh + ?Sized,
    TB: Tree + ?Sized,
{
    let tol = Tolerances::default();
    if ta.is_empty() || tb.is_empty() {
        return None;
    }
    let (root_a, root_b) = (ta.node_box(0), tb.node_box(0));
    if !tol.boxes_may_meet(&root_a, &root_b) {
        return None;
    }
    // Room for the usual depth at once (the stack holds at most one entry per level of the two
    // trees, plus one).
    let mut stack = Vec::with_capacity(64);
    stack.push((0u32, 0u32, root_a, root_b));
    let mut room = LeafRoom::default();
    while let Some((i, j, bi, bj)) = stack.pop() {
        let open_a = match (ta.is_leaf(i), tb.is_leaf(j)) {
            (true, true) => {
                let leaves = (a, ta.leaf_prims(i), &bi, b, tb.leaf_prims(j), &bj);
                if let Some(p) = first_in_leaves(leaves, &mut room, &|| false) {
                    return Some(p);
                }
                continue;
            }
            (false, true) => true,
            (true, false) => false,
            (false, false) => bi.half_area() >= bj.half_area(),
        };
        let (kids, other) = if open_a { (ta.children(i), bj) } else { (tb.children(j), bi) };
        let boxes = kids.map(|c| if open_a { ta.node_box(c) } else { tb.node_box(c) });
        let shared = boxes.map(|k| tol.boxes_may_meet(&k, &other).then(|| shared_surface(&k, &other)));
        // Pushed in reverse order of preference: the last pushed is walked first.
        let order = match shared {
            [Some(x), Some(y)] if y > x => [0, 1],
            _ => [1, 0],
        };
        for k in order {
            if shared[k].is_some() {
                let (c, bc) = (kids[k], boxes[k]);
                stack.push(if open_a { (c, j, bc, bj) } else { (i, c, bi, bc) });
            }
        }
    }
    None
}

/// Two leaves of a first-contact walk: (mesh A, its leaf's triangles, a box holding them; the
/// same of B).
type Leaves<'a, A, B> = (&'a A, &'a [u32], &'a Aabb, &'a B, &'a [u32], &'a Aabb);

/// A triangle of a leaf near the other leaf: its index, corners and box.
type Near = (u32, [DVec3; 3], Aabb);

/// Room for [`first_in_leaves`]: the near triangles of each leaf, and the classifier facts of
/// B's, prepared when some pair needs them (on the stack for leaves of up to 8 triangles; the
/// default leaves hold 4).
type LeafRoom = (SmallVec<[Near; 8]>, SmallVec<[Near; 8]>, SmallVec<[Option<tri_tri::Prepared>; 8]>);

/// The first triangle pair of two leaves that meets, in leaf order (A's triangles outside,
/// B's inside): a triangle of one leaf is tried only when its box meets the other leaf's box;
/// none when those triangles are apart along the normal of the first of them on either side
/// ([`predicates::apart_along`]); each triangle is read, boxed and prepared
/// ([`tri_tri::Prepared`]) once. The pair found is classified again with its segment, as
/// [`tri_tri::classify`] gives it. `room` is room for the near triangles of each side; `stop`
/// is asked before each pair.
fn first_in_leaves<A, B>(
    (a, la, box_a, b, lb, box_b): Leaves<'_, A, B>,
    room: &mut LeafRoom,
    stop: &dyn Fn() -> bool,
) -> Option<PairFinding>
where
    A: TriMesh + ?Sized,
    B: TriMesh + ?Sized,
{
    let tol = Tolerances::default();
    let (near_a, near_b, facts_b) = (&mut room.0, &mut room.1, &mut room.2);
    let near = |m: &dyn Fn(u32) -> [DVec3; 3], leaf: &[u32], other: &Aabb, out: &mut SmallVec<[Near; 8]>| {
        out.clear();
        for &t in leaf {
            let tt = m(t);
            let bt = Aabb::of_triangle(&tt);
            if tol.boxes_may_meet(other, &bt) {
                out.push((t, tt, bt));
            }
        }
    };
    near(&|t| b.triangle(t), lb, box_a, near_b);
    if near_b.is_empty() {
        return None;
    }
    near(&|t| a.triangle(t), la, box_b, near_a);
    // Two patches of surface near each other without meeting (a part in a bore, a face over
    // another) are often apart along the normal of one of their triangles: no pair needs
    // classifying then.
    fn corners(l: &[Near]) -> impl Iterator<Item = &DVec3> {
        l.iter().flat_map(|x| x.1.iter())
    }
    let normal = |l: &[Near]| l.first().map(|x| (x.1[1] - x.1[0]).cross(x.1[2] - x.1[0]));
    if [normal(near_a), normal(near_b)]
        .into_iter()
        .flatten()
        .any(|n| predicates::apart_along(n, corners(near_a), corners(near_b)))
    {
        return None;
    }
    facts_b.clear();
    facts_b.resize_with(near_b.len(), || None);
    for (s, ts, bs) in near_a.iter() {
        let mut ps = None;
        for ((t, tt, bt), pt) in near_b.iter().zip(facts_b.iter_mut()) {
            if !tol.boxes_may_meet(bs, bt) {
                continue;
            }
            if stop() {
                return None;
            }
            let ps = &*ps.get_or_insert_with(|| tri_tri::Prepared::new(*ts));
            let pt = &*pt.get_or_insert_with(|| tri_tri::Prepared::new(*tt));
            if tri_tri::classify_prepared(ps, pt, false).is_some() {
                let h = tri_tri::classify_prepared(ps, pt, true).expect("the same pair meets");
                let kind = if h.crossing { PairKind::Crossing } else { PairKind::Touching };
                return Some(PairFinding {
                    a: *s,
                    b: *t,
                    kind,
                    contact: Some(h.contact),
                    distance: 0.0,
                    segment: h.segment,
                });
            }
        }
    }
    None
}

/// The surface (half area) of the intersection of two boxes, 0 when they only touch or miss:
/// the walk's measure of how much two node boxes share.
#[inline]
fn shared_surface(x: &Aabb, y: &Aabb) -> f64 {
    let e = (x.max.min(y.max) - x.min.max(y.min)).max(DVec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// Exact collision test of two placed meshes: every meeting triangle pair (`all`), or stop at
/// the first meeting pair; when none meet, containment decides (left at `None`, not decided,
/// when no vertex of either mesh lies in the other's box: nothing can be contained then).
/// Without `all` (a yes/no question) containment is decided only as far as a clash
/// ([`containment::OpenInside::Skip`]: the undefined inside of an open surface is not looked
/// into).
pub fn collide(a: &Placed, b: &Placed, all: bool) -> Collision {
    let none = Collision { contacts: Vec::new(), containment: Containment::None };
    if surely_clear(a, b) || !a.bounds().overlaps(&b.bounds()) {
        return none;
    }
    let (ta, tb) = (a.tree(), b.tree());
    let contacts = match (no_meeting_triangles(a, b), all) {
        (true, _) => Vec::new(),
        (false, true) => meeting_pairs(&a.mesh(), &ta, &b.mesh(), &tb, false),
        (false, false) => meeting_pairs(&a.corners(), &ta, &b.corners(), &tb, true),
    };
    if !contacts.is_empty() {
        return Collision { contacts, containment: Containment::None };
    }
    // Every vertex of a contained component lies in the other mesh's box: with no vertex of
    // either mesh's triangles in the other's box, no containment is possible (exact test), and
    // the topology and ray casts are skipped. (A vertex no triangle uses belongs to no
    // component.) The walk visits only the triangles in tree nodes that meet the other box.
    let any_inside = |p: &Placed, q: &Placed| {
        let (bq, pos, tris) = (q.bounds(), p.positions(), &p.prepared.mesh.triangles);
        crate::bvh::traverse::any_in_box(&p.tree(), &bq, |t| {
            tris[t as usize]
                .iter()
                .any(|&v| bq.contains(&Aabb { min: pos[v as usize], max: pos[v as usize] }))
        })
    };
    if !any_inside(a, b) && !any_inside(b, a) {
        return none;
    }
    let (ma, mb) = (a.mesh(), b.mesh());
    let open = if all { containment::OpenInside::Explain } else { containment::OpenInside::Skip };
    let containment = containment::decide(&ma, &ta, a.topology(), &mb, &tb, b.topology(), open);
    Collision { contacts, containment }
}

/// The minimum distance between two placed meshes (their surfaces) with a closest pair of
/// points: 0 at a shared point when triangles meet; `None` beyond `bound` (pass infinity for
/// no bound).
pub fn distance(a: &Placed, b: &Placed, bound: f64) -> Option<Closest> {
    if a.bounds().distance_sq(&b.bounds()).sqrt() > bound {
        return None;
    }
    let (ta, tb) = (a.tree(), b.tree());
    if a.bounds().overlaps(&b.bounds()) {
        // Stops at the first meeting pair: the distance is 0 either way, the witness is a
        // shared point of some meeting pair.
        let (ca, cb) = (a.corners(), b.corners());
        if let Some(p) = meeting_pairs(&ca, &ta, &cb, &tb, true).first() {
            return Some(query::pair_witness(&ca, &cb, p));
        }
    }
    query::closest_pair(&a.mesh(), &ta, &b.mesh(), &tb, DistanceError::default())
        .filter(|c| c.distance <= bound)
}

/// The exact penetration of two placed convex meshes ([`convex::penetration`]): `None` unless
/// both are convex ([`Placed::is_convex`]) and they meet (depth 0 when they only touch).
pub fn penetration(a: &Placed, b: &Placed) -> Option<Penetration> {
    if !a.bounds().overlaps(&b.bounds()) {
        return None;
    }
    convex::penetration(&a.polytope()?, &b.polytope()?)
}

/// The signed distance a collision manager reports between two placed meshes, with a witness
/// on each: see [`signed_distance`].
#[derive(Debug, Clone, PartialEq)]
pub struct Signed {
    /// The gap between the surfaces when the meshes do not collide; `-depth` when they collide
    /// and both are convex (the exact penetration depth); 0 when they collide otherwise (0 is
    /// then an upper bound: the depth of non-convex parts is not computed).
    pub distance: f64,
    /// Triangle of A (-1 when none applies: a contained part with no meeting triangles) and a
    /// point of A.
    pub a: (i64, DVec3),
    /// Triangle of B (or -1) and a point of B.
    pub b: (i64, DVec3),
    /// The penetration when both are convex and they collide.
    pub penetration: Option<Penetration>,
}

/// The signed distance of two placed meshes: positive (the surfaces' minimum distance, as
/// [`distance`]) when they do not collide ([`collide`]: no triangles meet, neither inside the
/// other); never positive when they collide — `-depth` for convex meshes, 0 otherwise, so a part
/// inside another never reports a gap. `None` when they do not collide and are farther apart
/// than `bound`.
pub fn signed_distance(a: &Placed, b: &Placed, bound: f64) -> Option<Signed> {
    if a.bounds().overlaps(&b.bounds()) {
        let c = collide(a, b, false);
        if c.collides() {
            return Some(colliding(a, b, &c));
        }
    }
    distance(a, b, bound).map(|c| Signed {
        distance: c.distance,
        a: (c.a.0 as i64, c.a.1),
        b: (c.b.0 as i64, c.b.1),
        penetration: None,
    })
}

/// The signed distance of two placed meshes known to collide through `contact`, a meeting
/// triangle pair (found by [`meeting_pairs`] with `first`): what [`signed_distance`] answers
/// when its own search finds that pair, without searching again.
pub fn signed_meeting(a: &Placed, b: &Placed, contact: &PairFinding) -> Signed {
    colliding(a, b, &Collision { contacts: vec![*contact], containment: Containment::None })
}

fn colliding(a: &Placed, b: &Placed, c: &Collision) -> Signed {
    let contact = c
        .contacts
        .first()
        .map(|p| (p.a as i64, p.b as i64, query::pair_witness(&a.corners(), &b.corners(), p)));
    if let Some(p) = a.polytope().zip(b.polytope()).and_then(|(pa, pb)| convex::penetration(&pa, &pb)) {
        let half = p.normal * (p.depth * 0.5);
        let (fa, fb) = contact.as_ref().map_or((-1, -1), |c| (c.0, c.1));
        return Signed {
            distance: 0.0 - p.depth,
            a: (fa, p.point + half),
            b: (fb, p.point - half),
            penetration: Some(p),
        };
    }
    match contact {
        Some((fa, fb, w)) => Signed { distance: 0.0, a: (fa, w.a.1), b: (fb, w.b.1), penetration: None },
        None => {
            // Containment: no triangles meet; the witness is the first vertex of the mesh
            // (some of) whose components lie inside the other.
            let inner = match c.containment {
                Containment::BInA | Containment::BPartlyInA => b.positions()[0],
                _ => a.positions()[0],
            };
            Signed { distance: 0.0, a: (-1, inner), b: (-1, inner), penetration: None }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(at: DVec3) -> Mesh {
        let v = crate::testing::gen::box_corners(at, at + DVec3::ONE).to_vec();
        let t = crate::testing::gen::BOX_TRIANGLES.to_vec();
        one_object(v, t, "cube")
    }

    /// A mesh of one object named `name`.
    fn one_object(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>, name: &str) -> Mesh {
        Mesh {
            positions,
            tri_object: vec![0; triangles.len()],
            triangles,
            objects: vec![crate::scene::mesh::Object { name: name.into(), ..Default::default() }],
        }
    }

    fn prepared(m: Mesh) -> Arc<Prepared> {
        Arc::new(Prepared::new(Path::new("<cube>"), m, BuildOptions::default()).unwrap())
    }

    #[test]
    fn placed_queries_match_a_fresh_check() {
        let a = prepared(cube(DVec3::ZERO));
        let pa = a.place(DMat4::IDENTITY).unwrap();
        for (shift, meets) in [(0.5, true), (1.0, true), (1.25, false)] {
            let rot = DMat4::from_translation(DVec3::new(shift, 0.2, 0.1)) * DMat4::from_rotation_z(0.0);
            let pb = a.place(rot).unwrap();
            let mut world = cube(DVec3::ZERO);
            query::place(&mut world, &rot, Path::new("x")).unwrap();
            let fresh = query::check(&cube(DVec3::ZERO), &world, &Settings::default());
            let c = collide(&pa, &pb, true);
            assert_eq!(c.collides(), meets, "shift {shift}");
            assert_eq!(c.contacts, fresh.pairs);
            // The first-contact searches (one thread for small pairs, parallel otherwise) find
            // one of those pairs, or none.
            let (ma, mb, ta, tb) = (pa.mesh(), pb.mesh(), pa.tree(), pb.tree());
            let seq = first_contact_sequential(&ma, &ta, &mb, &tb);
            assert_eq!(seq.is_some(), meets);
            assert!(seq.is_none_or(|p| fresh.pairs.contains(&p)));
            assert_eq!(collide(&pa, &pb, false).collides(), meets);
            let d = distance(&pa, &pb, f64::INFINITY).unwrap();
            assert_eq!(d.distance, fresh.closest.unwrap().distance);
        }
        // A small cube inside a big one: no triangles meet, yet they collide (containment).
        let big = prepared(cube(DVec3::ZERO));
        let pbig = big.place(DMat4::from_scale(DVec3::splat(4.0))).unwrap();
        let small = a.place(DMat4::from_translation(DVec3::splat(1.0))).unwrap();
        let c = collide(&pbig, &small, false);
        assert!(c.contacts.is_empty());
        assert_eq!(c.containment, Containment::BInA);
        assert_eq!(distance(&pbig, &small, f64::INFINITY).unwrap().distance, 1.0);
    }

    /// A triangle soup of `n` small triangles with coordinates on a 1/8 grid in [0, 8]^3 (so
    /// exactly touching triangles, shared planes and shared vertices are common), from `seed`.
    fn soup(n: usize, seed: u64) -> Mesh {
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move |k: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % k
        };
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for t in 0..n as u32 {
            let corner = DVec3::new(next(61) as f64, next(61) as f64, next(61) as f64) / 8.0;
            for _ in 0..3 {
                positions.push(corner + DVec3::new(next(5) as f64, next(5) as f64, next(5) as f64) / 8.0);
            }
            triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        one_object(positions, triangles, "soup")
    }

    /// The one-thread first-contact search on `pa` and `pb` finds a pair exactly when some pair
    /// of their triangles meets (every pair classified), and the pair it finds is the finding
    /// [`tri_tri::classify`] gives for it. Whether some pair meets.
    fn first_contact_matches_every_pair(pa: &Placed, pb: &Placed, case: &str) -> bool {
        let (ma, mb, ta, tb) = (pa.mesh(), pb.mesh(), pa.tree(), pb.tree());
        let any = (0..ma.triangle_count() as u32).any(|s| {
            (0..mb.triangle_count() as u32)
                .any(|t| tri_tri::classify(&ma.triangle(s), &mb.triangle(t)).is_some())
        });
        let found = first_contact_sequential(&ma, &ta, &mb, &tb);
        assert_eq!(found.is_some(), any, "{case}");
        if let Some(f) = found {
            let h = tri_tri::classify(&ma.triangle(f.a), &mb.triangle(f.b)).expect(case);
            let got = (f.kind == PairKind::Crossing, f.contact, f.segment);
            assert_eq!(got, (h.crossing, Some(h.contact), h.segment), "{case}");
        }
        any
    }

    /// The first-contact walk (ordered by box overlap, children culled before they are walked,
    /// triangles culled by the other leaf's box) finds a pair exactly when some triangle pair
    /// meets, compared with classifying every pair, under grid translations (exact touching),
    /// exact quarter turns and general rotations (boxes mapped with slack).
    #[test]
    fn first_contact_finds_a_pair_exactly_when_some_pair_meets() {
        let (mut met, mut missed) = (0, 0);
        for seed in 0..24u64 {
            let a = prepared(soup(120, 2 * seed + 1));
            let b = prepared(soup(40 + 4 * seed as usize, 2 * seed + 2));
            let shift = DVec3::new((seed % 5) as f64 * 1.5, (seed % 3) as f64, (seed % 4) as f64) * 0.5;
            let quarter = DMat4::from_cols(
                glam::DVec4::new(0.0, 1.0, 0.0, 0.0),
                glam::DVec4::new(-1.0, 0.0, 0.0, 0.0),
                glam::DVec4::new(0.0, 0.0, 1.0, 0.0),
                glam::DVec4::new(8.0, 0.0, 0.0, 1.0),
            );
            let placements = [
                DMat4::from_translation(shift),
                quarter * DMat4::from_translation(shift * 0.5),
                DMat4::from_translation(shift) * DMat4::from_rotation_y(0.1 + seed as f64 * 0.05),
            ];
            let pa = a.place(DMat4::from_translation(DVec3::new(0.25, 0.0, 0.0))).unwrap();
            for m in placements {
                let pb = b.place(m).unwrap();
                let any = first_contact_matches_every_pair(&pa, &pb, &format!("seed {seed}"));
                if any {
                    met += 1;
                } else {
                    missed += 1;
                }
                assert_eq!(collide(&pa, &pb, false).contacts.is_empty(), !any);
            }
        }
        assert!(met > 10 && missed > 5, "{met} met, {missed} missed");
    }

    /// An open tube of radius `r` around the z axis, `n` sides, `rings` rings from z = 0 to 4.
    fn tube(r: f64, n: u32, rings: u32) -> Mesh {
        let angle = |k: u32| std::f64::consts::TAU * k as f64 / n as f64;
        let positions = (0..=rings)
            .flat_map(|j| {
                (0..n).map(move |k| {
                    DVec3::new(r * angle(k).cos(), r * angle(k).sin(), 4.0 * j as f64 / rings as f64)
                })
            })
            .collect();
        let mut triangles = Vec::new();
        for j in 0..rings {
            for k in 0..n {
                let (a, b) = (j * n + k, j * n + (k + 1) % n);
                triangles.push([a, b, b + n]);
                triangles.push([a, b + n, a + n]);
            }
        }
        one_object(positions, triangles, "tube")
    }

    /// Near misses, where leaves are set apart along a triangle's normal: a tube inside
    /// another with clearances from 1e-9 to 1e-2, coincident, shifted sideways into it, and
    /// turned about z (facets crossing). The first-contact search finds a pair exactly when
    /// some pair meets (every pair classified), and it is a meeting pair.
    #[test]
    fn first_contact_on_near_misses_matches_every_pair() {
        let outer = prepared(tube(1.0, 48, 12));
        let (mut met, mut missed) = (0, 0);
        for (gap, shift, turn) in [
            (1.0e-9, 0.0, 0.0),
            (1.0e-3, 0.0, 0.0),
            (1.0e-2, 0.0, 0.3),
            (0.0, 0.0, 0.0),
            (1.0e-3, 2.0e-3, 0.0),
            (1.0e-9, 0.0, 0.01),
        ] {
            let inner = prepared(tube(1.0 - gap, 48, 12));
            let m = DMat4::from_translation(DVec3::new(shift, 0.0, 0.1)) * DMat4::from_rotation_z(turn);
            let (pa, pb) = (outer.place(DMat4::IDENTITY).unwrap(), inner.place(m).unwrap());
            if first_contact_matches_every_pair(&pa, &pb, &format!("gap {gap} shift {shift} turn {turn}")) {
                met += 1;
            } else {
                missed += 1;
            }
        }
        assert!(met >= 2 && missed >= 2, "{met} met, {missed} missed");
    }

    /// Above [`SEQUENTIAL_FIRST_CONTACT`] triangles the first-contact search runs in parallel:
    /// it finds a meeting pair, as classified alone, exactly when the full search finds some.
    #[test]
    fn parallel_first_contact_finds_a_meeting_pair() {
        let (a, b) = (prepared(soup(26_000, 3)), prepared(soup(26_000, 4)));
        for shift in [0.3, 9.0] {
            let (pa, pb) = (
                a.place(DMat4::IDENTITY).unwrap(),
                b.place(DMat4::from_translation(DVec3::splat(shift))).unwrap(),
            );
            let (ma, mb, ta, tb) = (pa.mesh(), pb.mesh(), pa.tree(), pb.tree());
            assert!(ma.triangle_count() + mb.triangle_count() > SEQUENTIAL_FIRST_CONTACT);
            let first = meeting_pairs(&ma, &ta, &mb, &tb, true);
            let all = meeting_pairs(&ma, &ta, &mb, &tb, false);
            assert_eq!(first.is_empty(), all.is_empty(), "shift {shift}");
            assert_eq!(all.is_empty(), shift > 8.0);
            for f in &first {
                let h = crate::narrow::tri_tri::classify(&ma.triangle(f.a), &mb.triangle(f.b)).unwrap();
                assert_eq!(
                    (f.kind == PairKind::Crossing, f.contact, f.segment),
                    (h.crossing, Some(h.contact), h.segment)
                );
            }
        }
    }

    /// Random affine maps: rotations, uneven scales, reflections, shears, large translations,
    /// zeros of either sign, from `seed`.
    fn random_transforms(seed: u64, n: usize) -> Vec<DMat4> {
        let mut next = crate::load::test_rng(seed);
        let mut unit = move || next(1 << 30) as f64 / (1u64 << 30) as f64;
        (0..n)
            .map(|k| {
                let axis = DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5).normalize_or(DVec3::Z);
                let rot = DMat4::from_axis_angle(axis, unit() * 6.3);
                let scale = DVec3::new(0.1 + unit() * 3.0, 0.1 + unit() * 3.0, 0.1 + unit() * 3.0);
                let shift = DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * [8.0, 1.0e6, 0.5][k % 3];
                let mut m = match k % 5 {
                    0 => DMat4::from_translation(shift),
                    1 => DMat4::from_translation(shift) * rot,
                    2 => DMat4::from_translation(shift) * rot * DMat4::from_scale(scale),
                    3 => DMat4::from_translation(shift) * DMat4::from_scale(scale * -1.0),
                    _ => {
                        let mut m = DMat4::from_translation(shift) * rot;
                        m.y_axis.x += unit();
                        m
                    }
                };
                if k % 2 == 1 {
                    let flip = |x: f64| if x == 0.0 { -x } else { x };
                    m = DMat4::from_cols_array(&m.to_cols_array().map(flip));
                }
                m
            })
            .collect()
    }

    /// A placement's world coordinates computed when first read are bit for bit those computed
    /// at once, and so are its exact box, tree boxes below the root, ball and every verdict and
    /// distance; its box from the transform alone holds every world vertex (it is the tree
    /// view's root), and reading single vertices or a pair lower bound computes nothing. Every
    /// answer, witnesses included, is the same whether a query finds the world coordinates
    /// computed or computes them (or reads only the vertices it needs), and a first-contact
    /// search reads few vertices and computes none of them all.
    #[test]
    fn lazy_placements_answer_as_eager_ones() {
        let mut compared = 0;
        let mut outcomes = [0; 3];
        for seed in 0..6u64 {
            let a = prepared(soup(60 + 10 * seed as usize, 2 * seed + 11));
            let b = prepared(if seed % 2 == 0 { cube(DVec3::splat(2.0)) } else { soup(50, 2 * seed + 12) });
            let ms = random_transforms(seed + 1, 10);
            for (k, &ma) in ms.iter().enumerate() {
                let mb = ms[(k + 3) % ms.len()] * DMat4::from_translation(DVec3::splat(k as f64 * 0.3));
                let (la, lb) = (a.place(ma).unwrap(), b.place(mb).unwrap());
                let (ea, eb) = (a.place_now(ma).unwrap(), b.place_now(mb).unwrap());
                assert!(!la.is_laid() && !lb.is_laid(), "placing computes nothing");
                // Single vertices and the box bound, before the world coordinates exist.
                assert_eq!(la.triangle(1), ea.triangle(1));
                assert!(!la.is_laid(), "reading a few vertices computes no other");
                // Reading every vertex alone gives the same values, and past half of them the
                // world coordinates are computed.
                let sa = a.place(ma).unwrap();
                let singles: Vec<DVec3> = (0..a.mesh.positions.len() as u32).map(|v| sa.vertex(v)).collect();
                assert!(sa.is_laid());
                assert!(la.reach_gap(&lb) <= ea.gap(&eb));
                if !la.reach().overlaps(&lb.reach()) {
                    assert!(la.apart(&lb) && !la.is_laid() && !lb.is_laid());
                    assert!(!collide(&la, &lb, false).collides() && !la.is_laid());
                }
                // The outlines' verdicts, read without the world coordinates, against the
                // exact ones.
                let (quiet, clear) = (no_meeting_triangles(&la, &lb), surely_clear(&la, &lb));
                assert!(!la.is_laid() && !lb.is_laid());
                let full = collide(&ea, &eb, true);
                assert!(!quiet || full.contacts.is_empty());
                assert!(!clear || !full.collides());
                outcomes[quiet as usize + clear as usize] += 1;
                let bits =
                    |p: &[DVec3]| p.iter().flat_map(|v| v.to_array().map(f64::to_bits)).collect::<Vec<_>>();
                assert_eq!(bits(&singles), bits(ea.positions()));
                // The same placements with their world coordinates computed before any query.
                let (fa, fb) = (a.place(ma).unwrap(), b.place(mb).unwrap());
                let _ = (fa.positions(), fb.positions());
                for (l, e, f) in [(&la, &ea, &fa), (&lb, &eb, &fb)] {
                    assert_eq!(bits(l.positions()), bits(e.positions()));
                    assert_eq!(l.bounds(), e.bounds());
                    assert!(l.reach().contains(&l.bounds()), "{:?} {:?}", l.reach(), l.bounds());
                    assert!(e.reach() == e.bounds());
                    let (tl, te, tf) = (l.tree(), e.tree(), f.tree());
                    assert_eq!(tl.node_box(0), l.reach());
                    for n in 0..l.prepared.tree.nodes.len() as u32 {
                        assert_eq!(tl.node_box(n), tf.node_box(n));
                        assert!(n == 0 || tl.node_box(n) == te.node_box(n));
                    }
                    assert_eq!(l.ball(), e.ball());
                    assert_eq!(l.is_convex(), e.is_convex());
                }
                assert_eq!(la.apart(&lb), ea.apart(&eb));
                assert_eq!(la.gap(&lb), ea.gap(&eb));
                assert_eq!(collide(&la, &lb, true), collide(&ea, &eb, true));
                let d = distance(&la, &lb, f64::INFINITY);
                assert_eq!(d, distance(&fa, &fb, f64::INFINITY));
                assert_eq!(d.map(|c| c.distance), distance(&ea, &eb, f64::INFINITY).map(|c| c.distance));
                // Fresh lazy placements (nothing computed yet) for the first contact and the
                // signed distance.
                let (la, lb) = (a.place(ma).unwrap(), b.place(mb).unwrap());
                let first = meeting_pairs(&la.corners(), &la.tree(), &lb.corners(), &lb.tree(), true);
                assert_eq!(first, meeting_pairs(&fa.mesh(), &fa.tree(), &fb.mesh(), &fb.tree(), true));
                let s = signed_distance(&la, &lb, f64::INFINITY);
                assert_eq!(s, signed_distance(&fa, &fb, f64::INFINITY));
                let e = signed_distance(&ea, &eb, f64::INFINITY);
                assert_eq!(s.map(|s| s.distance), e.map(|s| s.distance));
                compared += 1;
            }
        }
        assert_eq!(compared, 60);
        assert!(outcomes.iter().all(|&n| n >= 3), "{outcomes:?}");
    }

    /// Two dense soups placed across each other: the first-contact search on vertices read
    /// one by one finds the pair the search on computed world coordinates finds, and the signed
    /// distance from it is the same, without computing the world coordinates of either (soups
    /// are not convex: no depth is computed).
    #[test]
    fn first_contact_reads_few_vertices() {
        let (a, b) = (prepared(soup(3000, 5)), prepared(soup(3000, 6)));
        let mut found = 0;
        for (k, m) in random_transforms(9, 20).into_iter().enumerate() {
            let m =
                DMat4::from_translation(DVec3::splat(4.0)) * m * DMat4::from_translation(DVec3::splat(-4.0));
            let mb = DMat4::from_rotation_z(0.3 + k as f64) * DMat4::from_translation(DVec3::splat(0.01));
            let (la, lb) = (a.place(m).unwrap(), b.place(mb).unwrap());
            let (fa, fb) = (a.place(m).unwrap(), b.place(mb).unwrap());
            let _ = (fa.positions(), fb.positions());
            let first = meeting_pairs(&la.corners(), &la.tree(), &lb.corners(), &lb.tree(), true);
            assert_eq!(first, meeting_pairs(&fa.mesh(), &fa.tree(), &fb.mesh(), &fb.tree(), true));
            if let Some(p) = first.first() {
                found += 1;
                assert!(!la.is_laid() && !lb.is_laid(), "{k}: a first contact computed every vertex");
                assert_eq!(signed_meeting(&la, &lb, p), signed_meeting(&fa, &fb, p));
                assert!(!la.is_laid() && !lb.is_laid(), "{k}: a witness computed every vertex");
            }
            assert_eq!(signed_distance(&la, &lb, f64::INFINITY), signed_distance(&fa, &fb, f64::INFINITY));
        }
        assert!(found >= 10, "{found}");
    }

    /// A transform that takes some vertex out of the finite or exact range fails at placing,
    /// with the error placing every vertex at once gives; one whose box bound leaves the range
    /// while every vertex stays in it places (at once).
    #[test]
    fn placing_out_of_range_fails_at_place() {
        let a = prepared(cube(DVec3::ZERO));
        let big = predicates::MAX_EXACT_MAGNITUDE;
        let cases = [
            (DMat4::from_scale(DVec3::splat(big * 2.0)), false),
            (DMat4::from_translation(DVec3::new(0.0, big * 1.5, 0.0)), false),
            (DMat4::from_scale(DVec3::new(1.0, f64::INFINITY, 1.0)), false),
            (DMat4::from_scale(DVec3::new(1.0, 1.0, f64::NAN)), false),
            (
                DMat4::from_translation(DVec3::new(f64::MAX, 0.0, 0.0))
                    * DMat4::from_scale(DVec3::splat(2.0)),
                false,
            ),
            // The corner (1, 1, 1) lands exactly on the range's end: fine, placed at once.
            (DMat4::from_scale(DVec3::splat(big)), true),
            (DMat4::from_translation(DVec3::splat(big - 1.0e60)), true),
        ];
        for (m, fine) in cases {
            let (lazy, eager) = (a.place(m), a.place_now(m));
            match (lazy, eager) {
                (Ok(l), Ok(e)) => {
                    assert!(fine, "{m}");
                    assert!(l.is_laid());
                    assert_eq!(l.positions(), e.positions());
                }
                (Err(l), Err(e)) => {
                    assert!(!fine, "{m}");
                    assert_eq!(l.to_string(), e.to_string());
                }
                (l, e) => panic!("{m}: {:?} / {:?}", l.map(|_| ()), e.map(|_| ())),
            }
        }
    }

    /// The box from the transform alone holds the f64 image of every point of the source box,
    /// at scales from 2^-200 to 2^200 and with translations that cancel the linear part.
    #[test]
    fn reach_holds_every_image() {
        let mut next = crate::load::test_rng(0x5DEE_CE66_D1CE_4E5B);
        let mut unit = move || next(1 << 40) as f64 / (1u64 << 40) as f64 - 0.5;
        for k in 0..4000 {
            let scale = 2f64.powi((k % 41) * 10 - 200);
            let pts: Vec<DVec3> =
                (0..6).map(|_| DVec3::new(unit(), unit(), unit()) * scale + scale).collect();
            let mut pts = pts;
            let root = Aabb::of_points(&pts);
            pts.extend((0..8).map(|c| {
                DVec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), root.max, root.min)
            }));
            let mut m = DMat4::from_cols_array(&std::array::from_fn(|_| unit() * 4.0));
            // Half the time the translation nearly cancels the image of the first point.
            if k % 2 == 0 {
                let w = m.transform_point3(pts[0]) - m.w_axis.truncate();
                m.w_axis = (-w).extend(1.0);
            }
            let r = Coarse::of(&rows_of(&m), &root).unwrap().map_box(&root);
            for p in &pts {
                let w = m.transform_point3(*p);
                assert!(r.contains(&Aabb { min: w, max: w }), "{k}: {w} outside {r:?}");
            }
        }
    }

    /// Balls hold every vertex, their gap is a lower bound of the true distance, and apart
    /// pairs never collide; a translated placement's topology (taken from the prepared mesh) is
    /// the one found on its world coordinates.
    #[test]
    fn balls_bound_and_translated_topology_matches() {
        let a = prepared(cube(DVec3::ZERO));
        let placements = [
            DMat4::IDENTITY,
            DMat4::from_translation(DVec3::new(1.5, 0.25, -0.5)),
            DMat4::from_translation(DVec3::new(0.1, 0.2, 0.3)),
            DMat4::from_translation(DVec3::new(2.0, 2.0, 0.0)) * DMat4::from_rotation_z(0.7),
            DMat4::from_translation(DVec3::new(0.9, 0.9, 0.9)) * DMat4::from_rotation_x(0.3),
        ];
        let placed: Vec<Placed> = placements.iter().map(|&m| a.place(m).unwrap()).collect();
        for p in &placed {
            let b = p.ball();
            assert!(p.positions().iter().all(|v| (*v - b.center).length() <= b.radius));
            // The same closedness, components and coincidences (merged ids are numbered by the
            // coordinates' order, which a translation may change).
            let (t, fresh) = (p.topology(), containment::topology(&p.mesh()));
            assert_eq!(
                (t.closed, &t.component_seeds, &t.component_of),
                (fresh.closed, &fresh.component_seeds, &fresh.component_of)
            );
            let n = t.merged.len();
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(t.merged[i] == t.merged[j], fresh.merged[i] == fresh.merged[j]);
                }
            }
        }
        assert!(placed[0].translated() && placed[1].translated() && !placed[3].translated());
        for x in &placed {
            for y in &placed {
                let gap = x.gap(y);
                let d = distance(x, y, f64::INFINITY).unwrap().distance;
                let c = collide(x, y, false).collides();
                assert!(gap <= d, "{gap} > {d}");
                if x.apart(y) {
                    assert!(!c && d > 0.0);
                }
            }
        }
    }

    /// The signed distance from a meeting pair found beforehand is the one the full query
    /// finds (convex and non-convex pairs, crossing and touching).
    #[test]
    fn signed_from_a_meeting_pair_equals_the_full_query() {
        let a = prepared(cube(DVec3::ZERO));
        let mut two = cube(DVec3::ZERO);
        let far = cube(DVec3::splat(3.0));
        two.triangles.extend(far.triangles.iter().map(|t| t.map(|v| v + 8)));
        two.positions.extend(far.positions);
        two.tri_object = vec![0; two.triangles.len()];
        let two = prepared(two);
        let origin = a.place(DMat4::IDENTITY).unwrap();
        let mut met = 0;
        for k in 0..24 {
            let t = k as f64 * 0.125;
            let m = DMat4::from_translation(DVec3::new(t, 0.5 - t * 0.25, 0.25)) * DMat4::from_rotation_z(t);
            for other in [a.place(m).unwrap(), two.place(m).unwrap()] {
                let (ma, mb, ta, tb) = (origin.mesh(), other.mesh(), origin.tree(), other.tree());
                let Some(first) = meeting_pairs(&ma, &ta, &mb, &tb, true).into_iter().next() else {
                    continue;
                };
                met += 1;
                let full = signed_distance(&origin, &other, f64::INFINITY).unwrap();
                assert_eq!(signed_meeting(&origin, &other, &first), full, "step {k}");
                assert!(full.distance <= 0.0);
            }
        }
        assert!(met > 10, "{met}");
    }

    #[test]
    fn signed_distance_is_never_positive_for_colliding_parts() {
        let a = prepared(cube(DVec3::ZERO));
        let at = |x: f64, y: f64, z: f64| a.place(DMat4::from_translation(DVec3::new(x, y, z))).unwrap();
        let origin = at(0.0, 0.0, 0.0);
        assert!(origin.is_convex());
        // Coincident unit cubes: depth 1; overlapping by 0.25 along x: -0.25; apart: the gap.
        let s = signed_distance(&origin, &at(0.0, 0.0, 0.0), f64::INFINITY).unwrap();
        assert_eq!(s.distance, -1.0);
        let s = signed_distance(&origin, &at(0.75, 0.0, 0.0), f64::INFINITY).unwrap();
        assert_eq!(s.distance, -0.25);
        assert_eq!((s.a.1 - s.b.1).length(), 0.25);
        assert_eq!(signed_distance(&origin, &at(3.0, 0.0, 0.0), f64::INFINITY).unwrap().distance, 2.0);
        assert_eq!(signed_distance(&origin, &at(1.0, 0.5, 0.0), f64::INFINITY).unwrap().distance, 0.0);
        assert!(signed_distance(&origin, &at(3.0, 0.0, 0.0), 1.5).is_none());
        // A unit cube inside a cube of side 4 (scaled: convexity decided on the world
        // coordinates): the shortest way out is 1.5, through x = 0.
        let big = a.place(DMat4::from_scale(DVec3::splat(4.0))).unwrap();
        assert!(big.is_convex());
        let s = signed_distance(&big, &at(0.5, 1.5, 1.25), f64::INFINITY).unwrap();
        assert_eq!(s.distance, -1.5);
        assert_eq!(penetration(&big, &at(0.5, 1.5, 1.25)).unwrap().normal, DVec3::new(-1.0, 0.0, 0.0));
        // The same inside a non-convex part (the big cube and a far one in one mesh): no depth,
        // but never the positive gap between the surfaces.
        let mut two = cube(DVec3::ZERO);
        two.positions.iter_mut().for_each(|p| *p *= 4.0);
        let far = cube(DVec3::splat(10.0));
        two.triangles.extend(far.triangles.iter().map(|t| t.map(|v| v + 8)));
        two.positions.extend(far.positions);
        two.tri_object = vec![0; two.triangles.len()];
        let two = prepared(two).place(DMat4::IDENTITY).unwrap();
        assert!(!two.is_convex());
        let s = signed_distance(&two, &at(0.5, 1.5, 1.25), f64::INFINITY).unwrap();
        assert_eq!((s.distance, s.penetration), (0.0, None));
        assert!(penetration(&two, &at(0.5, 1.5, 1.25)).is_none());
    }
}
