"""``trimesh.collision.CollisionManager``'s interface on meshclash's exact checks.

Switch with one import::

    from meshclash import CollisionManager   # was: from trimesh.collision import CollisionManager

Same methods, arguments and return shapes (``return_names``, ``return_data``, ``return_name``).
Where FCL (python-fcl, behind trimesh) and meshclash disagree, meshclash is exact:

* **Touching counts as collision**, as in FCL, but always: FCL calls two exactly touching
  parts colliding or not depending on rounding (and on float32: trimesh casts transforms to
  float32); meshclash decides it exactly for the f64 coordinates.
* **Containment counts as collision**, unlike FCL: a closed part entirely inside another closed
  part (no triangles meet) collides here; FCL's BVH meshes are surfaces and say no. The contact
  then has face index -1 and no point (``ContactData.point`` is None).
* **Convex meshes are meshes**: trimesh hands convex meshes to FCL as convex solids (GJK), which
  makes containment in a convex part a collision there; meshclash treats every mesh the same way
  (surfaces, plus exact containment for closed ones).
* **Distances** are between surfaces, in f64, with a witness on each: 0 with a shared point when
  they meet; for a part inside another, the positive gap between their surfaces (FCL's distance
  between overlapping meshes is 0 or negative with no witness).
* ``ContactData.depth`` is 0.0 (no penetration depth is computed) and ``normal`` is the unit
  normal of the contact's triangle on the second named object. With ``return_data`` every
  meeting triangle pair of every colliding object pair is listed (sorted); FCL caps them.
"""

from __future__ import annotations

import numpy as np

from . import _meshclash


class ContactData:
    """One contact of two colliding objects (as ``trimesh.collision.ContactData``)."""

    def __init__(self, names, faces, point, normal, kind="contact"):
        self.names = set(names)
        self._names = tuple(names)
        self._inds = {names[0]: faces[0], names[1]: faces[1]}
        self._point = None if point is None else np.array(point)
        self._normal = None if normal is None else np.array(normal)
        self.kind = kind

    @property
    def normal(self):
        """Unit normal of the contact triangle of the second named object (None for
        containment)."""
        return self._normal

    @property
    def point(self):
        """A point both triangles share (the middle of their common segment), or None for
        containment."""
        return self._point

    @property
    def depth(self):
        """Always 0.0: no penetration depth is computed."""
        return 0.0

    def index(self, name):
        """Index of the face in contact on object ``name`` (-1 for containment)."""
        return self._inds[name]

    def __repr__(self):
        return f"ContactData(names={self._names}, faces={tuple(self._inds.values())}, kind={self.kind!r})"


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
        """The distance between the two objects' surfaces."""
        return self._distance

    def index(self, name):
        """Index of the closest face on object ``name``."""
        return self._inds[name]

    def point(self, name):
        """The closest point on object ``name``."""
        return self._points[name]


def _contacts(names, contacts, containment):
    if not contacts:
        return [ContactData(names, (-1, -1), None, None, kind=containment or "containment")]
    return [ContactData(names, (fa, fb), p, n) for fa, fb, p, n in contacts]


def _matrix(transform):
    if transform is None:
        return None
    m = np.asarray(transform, dtype=np.float64)
    if m.shape != (4, 4):
        raise ValueError("transform must be (4,4)!")
    return m.tolist()


def _prepare(mesh):
    from . import Mesh

    return Mesh.from_mesh(mesh)._native


def _pack(result, extra, flags):
    """trimesh's return convention: the result, then each requested extra in order."""
    out = (result,) + tuple(x for x, f in zip(extra, flags) if f)
    return out if len(out) > 1 else result


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
        transform is applied in f64 (trimesh casts it to float32)."""
        native = _prepare(mesh)
        self._native.add(name, native, _matrix(transform))
        self._meshes[name] = native

    def remove_object(self, name):
        """Delete object ``name``; ValueError if there is none."""
        if name not in self._meshes:
            raise ValueError(f"{name} not in collision manager!")
        self._native.remove(name)
        del self._meshes[name]

    def set_transform(self, name, transform):
        """Replace the transform of object ``name``."""
        if name not in self._meshes:
            raise ValueError(f"{name} not in collision manager!")
        self._native.set_transform(name, _matrix(transform))

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
