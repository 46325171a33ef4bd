"""meshclash: exact clash and proximity detection between triangle meshes.

NumPy arrays (or mesh files) in, the same JSON report the ``meshclash`` command line writes out,
as a dict. Every verdict is exact for the f64 coordinates as given (touching is its own class,
never a rounding accident); distances are f64 closed forms.

* :func:`check` -- two meshes (``(vertices, faces)`` arrays, file paths or :class:`Mesh`)
  against each other: the report document (schema ``meshclash.report/2``).
* :func:`scene` -- every part of one file against every other part.
* :class:`Mesh` -- a prepared mesh (validated, tree built once) to check again and again under
  different transforms.
* :class:`CollisionManager` -- ``trimesh.collision.CollisionManager``'s interface on exact
  checks: change one import.

The GIL is released while checking. Bad input raises ``ValueError`` (``OSError`` for files that
cannot be read) with the command line's one-line message.
"""

from __future__ import annotations

import json
import os

import numpy as np

from . import _meshclash

__all__ = [
    "check",
    "scene",
    "Mesh",
    "CollisionManager",
    "CollisionObject",
    "scene_to_collision",
    "mesh_to_BVH",
    "mesh_to_convex",
    "ContactData",
    "DistanceData",
    "__version__",
]

__version__ = _meshclash.version()

_VERTEX_DTYPES = (np.float64, np.float32)
_FACE_DTYPES = (np.int32, np.int64, np.uint32)


def _arrays(vertices, faces, what):
    """Validate shapes and dtypes; return arrays the native module reads (float64/float32
    vertices, int32/int64/uint32 faces, as given when they already are)."""
    v = np.asarray(vertices)
    f = np.asarray(faces)
    if v.dtype not in _VERTEX_DTYPES:
        if v.dtype.kind in "iu" and v.size:
            v = v.astype(np.float64)
        else:
            raise ValueError(
                f"{what}: vertices must be float64 or float32 (got dtype {v.dtype})"
            )
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{what}: vertices must have shape (n, 3), got {v.shape}")
    if f.dtype not in _FACE_DTYPES:
        raise ValueError(
            f"{what}: faces must be int32, int64 or uint32 (got dtype {f.dtype})"
        )
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"{what}: faces must have shape (m, 3), got {f.shape}")
    return v, f


def _input(x, side):
    if isinstance(x, Mesh):
        return x._native
    if isinstance(x, _meshclash.Mesh):
        return x
    if isinstance(x, (str, os.PathLike)):
        return os.fspath(x)
    if isinstance(x, tuple) and len(x) == 2:
        return _arrays(x[0], x[1], f"<array {side}>")
    if hasattr(x, "vertices") and hasattr(x, "faces"):
        return _arrays(x.vertices, x.faces, f"<array {side}>")
    raise ValueError(
        f"{side} must be a file path, a (vertices, faces) pair of arrays, a meshclash.Mesh "
        "or an object with vertices and faces"
    )


def _matrix(t, name):
    if t is None:
        return None
    m = np.asarray(t, dtype=np.float64)
    if m.shape == (3, 4):
        m = np.vstack([m, [0.0, 0.0, 0.0, 1.0]])
    if m.shape != (4, 4):
        raise ValueError(f"{name} must be a (4, 4) or (3, 4) matrix, got shape {m.shape}")
    return m.tolist()


def check(
    a,
    b,
    *,
    transform_a=None,
    transform_b=None,
    touch_tolerance=0.0,
    clearance=0.0,
    max_pairs=1000,
    mode="exact",
    first_hit=False,
    detail="pairs",
    threads=0,
    timings=True,
    penetration=False,
    split_bodies=False,
    select_a=(),
    select_b=(),
    exclude=(),
    bvh="sah",
    leaf_size=4,
    distance_rel_err=0.0,
    distance_abs_err=0.0,
    units=None,
    units_a=None,
    units_b=None,
    scale_a=None,
    scale_b=None,
    fail_on="clash",
    baseline=None,
    cache=None,
    cache_max_bytes=None,
) -> dict:
    """Check mesh ``a`` against mesh ``b``; return the report as a dict.

    ``a`` and ``b`` are each a ``(vertices, faces)`` pair of NumPy arrays (vertices float64 or
    float32 of shape (n, 3); faces int32, int64 or uint32 of shape (m, 3), 0-based), an object
    with ``vertices`` and ``faces`` (a ``trimesh.Trimesh``), a file path (OBJ, STL, glTF/GLB),
    or a prepared :class:`Mesh`. The flags are the command line's: ``transform_a``/``_b`` a 4x4
    (or 3x4) affine matrix applied in f64; ``touch_tolerance`` and ``clearance`` a number or a
    string with a ``rel`` suffix (``"1e-6rel"``); ``mode`` ``"exact"`` or ``"fast"``;
    ``detail`` ``"pairs"`` or ``"parts"`` (``--detail``: part-pair verdicts, counts and closest points without triangle-pair lists or regions); ``threads`` 0 for one per core; ``timings=False`` is ``--no-timings`` (the same inputs then
    give the same document as ``meshclash A B --no-timings``).

    The command line's report flags, with its meaning: ``units`` (``--units``: ``"um"``,
    ``"mm"``, ``"cm"``, ``"m"``, ``"in"``, ``"ft"``, ``"yd"``), ``units_a``/``units_b``,
    ``scale_a``/``scale_b``, ``fail_on`` (``"clash"``, ``"touching"``, ``"clearance"``,
    ``"never"``, ``"new"``; the report's ``failed`` says whether the run fails), ``baseline``
    (the path of an earlier report), ``cache`` (a cache directory; ``MESHCLASH_CACHE`` is not
    read: pass it) and ``cache_max_bytes``.

    The result has the report's keys and schema version (``meshclash schema`` prints the
    schema): ``verdict`` (``clear``/``clearance``/``touching``/``clash``), ``summary``,
    ``closest``, ``pairs``, ``regions``, ``part_pairs`` ... In-memory inputs have ``format``
    ``"array"`` and path ``<array a>``/``<array b>`` (a :class:`Mesh`: ``<mesh NAME>``).
    With a :class:`Mesh` the prepared tree is reused: findings are the same, the ``bvh`` block
    describes the prepared tree.
    """
    doc = _meshclash.check_json(
        _input(a, "a"),
        _input(b, "b"),
        transform_a=_matrix(transform_a, "transform_a"),
        transform_b=_matrix(transform_b, "transform_b"),
        touch_tolerance=touch_tolerance,
        clearance=clearance,
        max_pairs=int(max_pairs),
        mode=mode,
        first_hit=bool(first_hit),
        detail=detail,
        threads=int(threads),
        timings=bool(timings),
        penetration=bool(penetration),
        split_bodies=bool(split_bodies),
        bvh=bvh,
        leaf_size=int(leaf_size),
        distance_rel_err=float(distance_rel_err),
        distance_abs_err=float(distance_abs_err),
        select_a=list(select_a),
        select_b=list(select_b),
        exclude=list(exclude),
        **_flags(units, units_a, units_b, scale_a, scale_b, fail_on, baseline, cache, cache_max_bytes),
    )
    return json.loads(doc)


def _flags(units, units_a, units_b, scale_a, scale_b, fail_on, baseline, cache, cache_max_bytes):
    """The units, gate, baseline and cache keywords of the native calls (None: as the command
    line's default)."""
    out = {"fail_on": str(fail_on)}
    for key, value in (("units", units), ("units_a", units_a), ("units_b", units_b)):
        if value is not None:
            out[key] = str(value)
    for key, value in (("scale_a", scale_a), ("scale_b", scale_b)):
        if value is not None:
            out[key] = float(value)
    if baseline is not None:
        out["baseline"] = os.fspath(baseline)
    if cache is not None:
        out["cache"] = os.fspath(cache)
    if cache_max_bytes is not None:
        out["cache_max_bytes"] = int(cache_max_bytes)
    return out


def scene(
    path,
    *,
    touch_tolerance=0.0,
    clearance=0.0,
    max_pairs=1000,
    mode="exact",
    first_hit=False,
    detail="pairs",
    threads=0,
    timings=True,
    penetration=False,
    split_bodies=False,
    select_a=(),
    select_b=(),
    exclude=(),
    bvh="sah",
    leaf_size=4,
    distance_rel_err=0.0,
    distance_abs_err=0.0,
    units=None,
    file_units=None,
    scale=None,
    fail_on="clash",
    baseline=None,
    self_check=False,
    self_fail_on=(),
    cache=None,
    cache_max_bytes=None,
) -> dict:
    """Check every part of the file at ``path`` against every other part (``meshclash scene
    FILE``); the flags are those of :func:`check`. ``file_units`` and ``scale`` are the file's
    units and scale (``--units-a``, ``--scale-a``); ``self_check=True`` is ``--self`` (every
    part against itself too, a ``self`` block), ``self_fail_on`` its ``--self-fail-on``
    conditions (``"open"``, ``"non-manifold"``, ``"duplicates"``, ``"degenerate"``,
    ``"winding"``, ``"touching"``, ``"self-clash"``). Returns the report as a dict."""
    doc = _meshclash.scene_json(
        os.fspath(path),
        touch_tolerance=touch_tolerance,
        clearance=clearance,
        max_pairs=int(max_pairs),
        mode=mode,
        first_hit=bool(first_hit),
        detail=detail,
        threads=int(threads),
        timings=bool(timings),
        penetration=bool(penetration),
        split_bodies=bool(split_bodies),
        bvh=bvh,
        leaf_size=int(leaf_size),
        distance_rel_err=float(distance_rel_err),
        distance_abs_err=float(distance_abs_err),
        select_a=list(select_a),
        select_b=list(select_b),
        exclude=list(exclude),
        self_check=bool(self_check),
        self_fail_on=[str(x) for x in self_fail_on],
        **_flags(units, None, None, None, None, fail_on, baseline, cache, cache_max_bytes),
        **({} if file_units is None else {"file_units": str(file_units)}),
        **({} if scale is None else {"scale": float(scale)}),
    )
    return json.loads(doc)


class Mesh:
    """A prepared triangle mesh: validated once, its bounding volume hierarchy built once.

    Place it under any number of transforms with :meth:`collides`, :meth:`distance`,
    :func:`check` (``transform_a``/``transform_b``) or a :class:`CollisionManager`: each
    placement transforms the vertices in f64 and walks the prepared tree through a conservative
    box map, so results are exactly those of a fresh check on the placed coordinates.
    """

    __slots__ = ("_native",)

    def __init__(self, vertices, faces, name=None):
        v, f = _arrays(vertices, faces, f"<mesh {name or 'mesh'}>")
        self._native = _meshclash.Mesh(v, f, name)

    @classmethod
    def _wrap(cls, native):
        m = cls.__new__(cls)
        m._native = native
        return m

    @classmethod
    def from_mesh(cls, mesh, name=None):
        """A :class:`Mesh` from anything with ``vertices`` and ``faces`` (e.g. trimesh.Trimesh),
        a ``(vertices, faces)`` pair, or a :class:`Mesh` (returned as it is)."""
        if isinstance(mesh, Mesh):
            return mesh
        if isinstance(mesh, tuple) and len(mesh) == 2:
            return cls(mesh[0], mesh[1], name)
        if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
            return cls(mesh.vertices, mesh.faces, name)
        raise ValueError(
            "mesh must be a meshclash.Mesh, a (vertices, faces) pair or have vertices and faces"
        )

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def vertex_count(self) -> int:
        return self._native.vertex_count

    @property
    def face_count(self) -> int:
        return self._native.face_count

    @property
    def bounds(self) -> np.ndarray:
        lo, hi = self._native.bounds()
        return np.array([lo, hi])

    def collides(self, other, transform=None, other_transform=None) -> bool:
        """True when this mesh (placed by ``transform``) and ``other`` (placed by
        ``other_transform``) collide: triangles cross or touch exactly, or one lies inside the
        other (both closed)."""
        return self._native.collides(
            Mesh.from_mesh(other)._native,
            _matrix(transform, "transform"),
            _matrix(other_transform, "other_transform"),
        )

    def distance(self, other, transform=None, other_transform=None):
        """``(distance, point_on_self, point_on_other, face_self, face_other)``: the minimum
        distance between the two surfaces (0 when they meet) and its witness."""
        d, pa, pb, fa, fb = self._native.distance(
            Mesh.from_mesh(other)._native,
            _matrix(transform, "transform"),
            _matrix(other_transform, "other_transform"),
        )
        return d, np.array(pa), np.array(pb), fa, fb

    def __repr__(self):
        return f"meshclash.Mesh(name={self.name!r}, vertices={self.vertex_count}, faces={self.face_count})"


from .collision import (  # noqa: E402
    CollisionManager,
    CollisionObject,
    ContactData,
    DistanceData,
    mesh_to_BVH,
    mesh_to_convex,
    scene_to_collision,
)
