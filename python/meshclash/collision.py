"""``trimesh.collision.CollisionManager``'s interface on meshclash's exact checks.

Switch with one import::

    from meshclash import CollisionManager   # was: from trimesh.collision import CollisionManager

Same methods, arguments and return shapes (``return_names``, ``return_data``, ``return_name``).
Where FCL (python-fcl, behind trimesh) and meshclash disagree, meshclash is exact:

* **Touching counts as collision**, as in FCL, but always: FCL calls two exactly touching
  parts colliding or not depending on rounding (and on float32: trimesh casts transforms to
  float32); meshclash decides it exactly for the f64 coordinates.
* **Containment counts as collision**, unlike FCL's BVH meshes: a closed part entirely inside
  another closed part (no triangles meet) collides here. The contact then has face index -1.
* **Convex parts**: trimesh hands convex meshes to FCL as convex solids (GJK/EPA, in floats);
  meshclash decides convexity exactly (closed, facing out, every vertex on or below every
  face's plane) and computes the exact penetration depth by the separating-axis theorem. A
  colliding convex pair gives one contact: ``depth`` the exact depth, ``normal`` the unit
  direction to move the second object by ``depth`` to separate them, ``point`` halfway along
  the deepest penetration. A convex mesh placed by a rotation whose rounding bends its coplanar
  triangles apart is not exactly convex any more and is treated as non-convex.
* **Non-convex colliding parts**: one contact per meeting triangle pair (every pair, sorted;
  FCL caps them), ``point`` on both triangles (the middle of their common segment), ``normal``
  the unit normal of the second object's triangle, ``depth`` 0.0 (not computed: 0 is a lower
  bound).
* **Distances are signed**: the surfaces' minimum distance (f64, with a witness on each) when
  nothing collides; when a pair collides (triangles meet or a part lies inside another), the
  answer is that pair's signed distance, never positive: ``-depth`` when both are convex (as
  FCL's signed distance), 0 otherwise. Like FCL, a distance query stops at the first colliding
  pair it finds; here that is deterministic, not the deepest: the first pair in insertion order
  whose triangles meet, else (no triangles meet anywhere) the first pair in insertion order
  with one part inside the other.
* **Answers kept until something moves**: the manager keeps each pair's verdict and signed
  distance under the two objects' placements; ``set_transform``, ``add_object`` and
  ``remove_object`` drop those of the object they place. Asking again about a still scene is
  answered from them (the same exact answers).
"""

from __future__ import annotations

import weakref

import numpy as np

from . import _meshclash


class ContactData:
    """One contact of two colliding objects (as ``trimesh.collision.ContactData``)."""

    def __init__(self, names, faces, point, normal, depth=0.0, kind="contact"):
        self.names = set(names)
        self._names = tuple(names)
        self._inds = {names[0]: faces[0], names[1]: faces[1]}
        self._point = None if point is None else np.array(point)
        self._normal = None if normal is None else np.array(normal)
        self._depth = float(depth)
        self.kind = kind

    @property
    def normal(self):
        """Convex pair: the unit direction to move the second named object by ``depth`` to
        separate the two. Otherwise the unit normal of the contact triangle of the second named
        object (None for containment)."""
        return self._normal

    @property
    def point(self):
        """Convex pair: halfway along the deepest penetration. Otherwise a point both triangles
        share (the middle of their common segment), or None for containment."""
        return self._point

    @property
    def depth(self):
        """Convex pair: the exact penetration depth. Otherwise 0.0 (not computed)."""
        return self._depth

    def index(self, name):
        """Index of the face in contact on object ``name`` (-1 where none applies)."""
        return self._inds[name]

    def __repr__(self):
        return (
            f"ContactData(names={self._names}, faces={tuple(self._inds.values())}, "
            f"depth={self._depth!r}, kind={self.kind!r})"
        )


class DistanceData:
    """The closest pair of a distance query (as ``trimesh.collision.DistanceData``)."""

    def __init__(self, names, distance, faces, points):
        self.names = set(names)
        self._names = tuple(names)
        self._inds = {names[0]: faces[0], names[1]: faces[1]}
        self._points = {names[0]: np.array(points[0]), names[1]: np.array(points[1])}
        self._distance = distance

    @property
    def distance(self):
        """The signed distance: the gap between the surfaces, or ``-depth`` (convex) or 0
        when the two collide."""
        return self._distance

    def index(self, name):
        """Index of the closest face on object ``name`` (-1 for a contained part)."""
        return self._inds[name]

    def point(self, name):
        """The closest point on object ``name`` (colliding convex pair: the deepest points)."""
        return self._points[name]


class CollisionObject:
    """What :meth:`CollisionManager.add_object` returns (trimesh returns FCL's
    ``CollisionObject``): the object's name, its prepared geometry and current transform."""

    __slots__ = ("name", "geometry", "_transform")

    def __init__(self, name, geometry, transform):
        self.name = name
        self.geometry = geometry
        self._transform = transform

    @property
    def transform(self):
        """The current 4x4 placement (f64)."""
        return self._transform.copy()

    def getTransform(self):  # noqa: N802 - FCL's spelling
        """The current 4x4 placement, as ``fcl.CollisionObject.getTransform`` would give."""
        return self.transform

    def getTranslation(self):  # noqa: N802
        return self._transform[:3, 3].copy()

    def getRotation(self):  # noqa: N802
        return self._transform[:3, :3].copy()

    def __repr__(self):
        return f"CollisionObject(name={self.name!r})"


def _contacts(names, contacts, containment):
    if not contacts:
        return [ContactData(names, (-1, -1), None, None, 0.0, kind=containment or "containment")]
    kind = containment or "contact"
    return [ContactData(names, (fa, fb), p, n, depth, kind=kind) for fa, fb, p, n, depth in contacts]


def _matrix(transform):
    if transform is None:
        return None
    m = np.asarray(transform, dtype=np.float64)
    if m.shape != (4, 4):
        raise ValueError("transform must be (4,4)!")
    return m.tolist()


# Prepared meshes of the trimesh objects queries were given, so that asking again with the
# same mesh (a motion loop's in_collision_single) converts and prepares it once: id -> (weak
# reference, content hash, native mesh). trimesh's hash(mesh) is a hash of its vertices and
# faces, cached by trimesh until they change, so an edited mesh is prepared again.
_PREPARED = {}
_PREPARED_MAX = 64


def _prepare(mesh):
    from . import Mesh

    if isinstance(mesh, Mesh):
        return mesh._native
    if isinstance(mesh, _meshclash.Mesh):
        return mesh
    try:
        ref, key = weakref.ref(mesh), hash(mesh)
    except TypeError:
        return Mesh.from_mesh(mesh)._native
    hit = _PREPARED.get(id(mesh))
    if hit is not None and hit[0]() is mesh and hit[1] == key:
        return hit[2]
    native = Mesh.from_mesh(mesh)._native
    if len(_PREPARED) >= _PREPARED_MAX:
        _PREPARED.clear()
    _PREPARED[id(mesh)] = (ref, key, native)
    return native


def _pack(result, extra, flags):
    """trimesh's return convention: the result, then each requested extra in order."""
    out = (result,) + tuple(x for x, f in zip(extra, flags) if f)
    return out if len(out) > 1 else result


def mesh_to_BVH(mesh):  # noqa: N802 - trimesh's name
    """trimesh's ``mesh_to_BVH`` equivalent: the mesh prepared once (validated, tree built), a
    :class:`meshclash.Mesh` that ``add_object`` and ``in_collision_single`` accept as is."""
    from . import Mesh

    return Mesh.from_mesh(mesh)


def mesh_to_convex(mesh):
    """trimesh's ``mesh_to_convex`` equivalent: the same prepared mesh as :func:`mesh_to_BVH`
    (convexity is decided exactly, per placement, where a depth needs it)."""
    return mesh_to_BVH(mesh)


def scene_to_collision(scene):
    """trimesh's ``scene_to_collision``: a :class:`CollisionManager` holding every geometry
    node of the trimesh ``scene`` under its world transform, and ``{node: CollisionObject}``."""
    manager = CollisionManager()
    objects = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        objects[node] = manager.add_object(name=node, mesh=scene.geometry[geometry], transform=transform)
    return manager, objects


class CollisionManager:
    """A mesh-mesh collision manager with trimesh's interface and exact answers.

    Objects are prepared once (validated, tree built) when added; ``set_transform`` only
    re-places the vertices. Queries release the GIL and run on all cores.
    """

    def __init__(self):
        self._native = _meshclash.Manager()
        self._meshes = {}

    def add_object(self, name, mesh, transform=None):
        """Add ``mesh`` (a trimesh.Trimesh, anything with ``vertices``/``faces``, a
        ``(vertices, faces)`` pair or a :class:`meshclash.Mesh`) as ``name``, placed by the 4x4
        ``transform`` (identity when None); an object of the same name is replaced. The
        transform is applied in f64 (trimesh casts it to float32). Returns the
        :class:`CollisionObject` (trimesh returns FCL's)."""
        native = _prepare(mesh)
        m = _matrix(transform)
        self._native.add(name, native, m)
        obj = CollisionObject(name, native, np.eye(4) if m is None else np.array(m))
        self._meshes[name] = obj
        return obj

    def remove_object(self, name):
        """Delete object ``name``; ValueError if there is none."""
        if name not in self._meshes:
            raise ValueError(f"{name} not in collision manager!")
        self._native.remove(name)
        del self._meshes[name]

    def set_transform(self, name, transform):
        """Replace the transform of object ``name`` (the very same transform keeps the
        object's placement; the answers kept about it are dropped either way)."""
        if name not in self._meshes:
            raise ValueError(f"{name} not in collision manager!")
        m = _matrix(transform)
        self._native.set_transform(name, m)
        self._meshes[name]._transform = np.array(m)

    def in_collision_single(self, mesh, transform=None, return_names=False, return_data=False):
        """Does ``mesh`` (placed by ``transform``) collide with any object of the manager?

        Returns ``is_collision`` and, as requested, the set of names it collides with and a list
        of :class:`ContactData` (names: the object's and ``"__external"``)."""
        need_all = bool(return_data)
        hits = self._native.collide_single(
            _prepare(mesh), _matrix(transform), need_all, not (return_names or return_data)
        )
        names = {h[0] for h in hits}
        data = []
        if return_data:
            for name, contacts, containment in hits:
                data.extend(_contacts((name, "__external"), contacts, containment))
        return _pack(bool(hits), (names, data), (return_names, return_data))

    def in_collision_internal(self, return_names=False, return_data=False):
        """Does any pair of objects of the manager collide?

        Returns ``is_collision`` and, as requested, the set of colliding name pairs (each
        sorted) and a list of :class:`ContactData`."""
        hits = self._native.collide_internal(
            bool(return_data), not (return_names or return_data)
        )
        names = {tuple(sorted((a, b))) for a, b, _, _ in hits}
        data = []
        if return_data:
            for a, b, contacts, containment in hits:
                data.extend(_contacts((a, b), contacts, containment))
        return _pack(bool(hits), (names, data), (return_names, return_data))

    def in_collision_other(self, other_manager, return_names=False, return_data=False):
        """Does any object of this manager collide with any object of ``other_manager``?

        Names are ``(ours, theirs)`` pairs."""
        hits = self._native.collide_other(
            other_manager._native, bool(return_data), not (return_names or return_data)
        )
        names = {(a, b) for a, b, _, _ in hits}
        data = []
        if return_data:
            for a, b, contacts, containment in hits:
                data.extend(_contacts((a, b), contacts, containment))
        return _pack(bool(hits), (names, data), (return_names, return_data))

    def min_distance_single(self, mesh, transform=None, return_name=False, return_data=False):
        """Minimum distance between ``mesh`` (placed by ``transform``) and any object; with
        ``return_name`` the closest object's name, with ``return_data`` a
        :class:`DistanceData` (names: the object's and ``"__external"``)."""
        r = self._native.distance_single(_prepare(mesh), _matrix(transform))
        if r is None:
            return _pack(float("inf"), (None, None), (return_name, return_data))
        d, name, fa, fb, pa, pb = r
        data = DistanceData((name, "__external"), d, (fa, fb), (pa, pb)) if return_data else None
        return _pack(d, (name, data), (return_name, return_data))

    def min_distance_internal(self, name=None, return_names=False, return_data=False):
        """Minimum distance between any two objects of the manager (or between object
        ``name`` and the others); ``return_names`` gives the sorted name pair."""
        if name is not None and name not in self._meshes:
            raise ValueError(f"{name} not in collision manager!")
        r = self._native.distance_internal(name)
        if r is None:
            return _pack(float("inf"), (None, None), (return_names, return_data))
        d, a, b, fa, fb, pa, pb = r
        data = DistanceData((a, b), d, (fa, fb), (pa, pb)) if return_data else None
        return _pack(d, (tuple(sorted((a, b))), data), (return_names, return_data))

    def min_distance_other(self, other_manager, return_names=False, return_data=False):
        """Minimum distance between an object of this manager and one of ``other_manager``;
        names are ``(ours, theirs)``."""
        r = self._native.distance_other(other_manager._native)
        if r is None:
            return _pack(float("inf"), (None, None), (return_names, return_data))
        d, a, b, fa, fb, pa, pb = r
        data = DistanceData((a, b), d, (fa, fb), (pa, pb)) if return_data else None
        return _pack(d, ((a, b), data), (return_names, return_data))
