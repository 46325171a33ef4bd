"""Type stub of meshclash (see the docstrings in meshclash/__init__.py)."""

from os import PathLike
from typing import Any, Iterable, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from .collision import CollisionManager as CollisionManager
from .collision import CollisionObject as CollisionObject
from .collision import mesh_to_BVH as mesh_to_BVH
from .collision import mesh_to_convex as mesh_to_convex
from .collision import scene_to_collision as scene_to_collision
from .collision import ContactData as ContactData
from .collision import DistanceData as DistanceData

__version__: str

Vertices = npt.NDArray[Union[np.float64, np.float32]]
Faces = npt.NDArray[Union[np.int32, np.int64, np.uint32]]
Matrix = Union[npt.ArrayLike, Sequence[Sequence[float]]]
Tolerance = Union[float, str]
MeshInput = Union[str, "PathLike[str]", Tuple[Vertices, Faces], "Mesh", Any]

def check(
    a: MeshInput,
    b: MeshInput,
    *,
    transform_a: Optional[Matrix] = ...,
    transform_b: Optional[Matrix] = ...,
    touch_tolerance: Tolerance = ...,
    clearance: Tolerance = ...,
    max_pairs: int = ...,
    mode: Literal["exact", "fast"] = ...,
    first_hit: bool = ...,
    detail: Literal["pairs", "parts"] = ...,
    threads: int = ...,
    timings: bool = ...,
    penetration: bool = ...,
    split_bodies: bool = ...,
    select_a: Iterable[str] = ...,
    select_b: Iterable[str] = ...,
    exclude: Iterable[str] = ...,
    bvh: Literal["sah", "median", "equal"] = ...,
    leaf_size: int = ...,
    distance_rel_err: float = ...,
    distance_abs_err: float = ...,
    units: Optional[str] = ...,
    units_a: Optional[str] = ...,
    units_b: Optional[str] = ...,
    scale_a: Optional[float] = ...,
    scale_b: Optional[float] = ...,
    fail_on: str = ...,
    baseline: Optional[Union[str, PathLike[str]]] = ...,
    cache: Optional[Union[str, PathLike[str]]] = ...,
    cache_max_bytes: Optional[int] = ...,
) -> dict[str, Any]:
    """Check a against b; the report document (schema meshclash.report/2) as a dict."""

def scene(
    path: Union[str, "PathLike[str]"],
    *,
    touch_tolerance: Tolerance = ...,
    clearance: Tolerance = ...,
    max_pairs: int = ...,
    mode: Literal["exact", "fast"] = ...,
    first_hit: bool = ...,
    detail: Literal["pairs", "parts"] = ...,
    threads: int = ...,
    timings: bool = ...,
    penetration: bool = ...,
    split_bodies: bool = ...,
    select_a: Iterable[str] = ...,
    select_b: Iterable[str] = ...,
    exclude: Iterable[str] = ...,
    bvh: Literal["sah", "median", "equal"] = ...,
    leaf_size: int = ...,
    distance_rel_err: float = ...,
    distance_abs_err: float = ...,
    units: Optional[str] = ...,
    file_units: Optional[str] = ...,
    scale: Optional[float] = ...,
    fail_on: str = ...,
    baseline: Optional[Union[str, PathLike[str]]] = ...,
    self_check: bool = ...,
    self_fail_on: Sequence[str] = ...,
    cache: Optional[Union[str, PathLike[str]]] = ...,
    cache_max_bytes: Optional[int] = ...,
) -> dict[str, Any]:
    """Every part of the file against every other part; the report as a dict."""

class Mesh:
    """A prepared mesh: validated, its tree built once; place it under many transforms."""

    def __init__(self, vertices: Vertices, faces: Faces, name: Optional[str] = ...) -> None: ...
    @classmethod
    def from_mesh(cls, mesh: Any, name: Optional[str] = ...) -> "Mesh": ...
    @property
    def name(self) -> str: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    @property
    def bounds(self) -> npt.NDArray[np.float64]: ...
    def collides(
        self, other: Any, transform: Optional[Matrix] = ..., other_transform: Optional[Matrix] = ...
    ) -> bool:
        """Exact: triangles cross or touch, or one closed mesh lies inside the other."""
    def distance(
        self, other: Any, transform: Optional[Matrix] = ..., other_transform: Optional[Matrix] = ...
    ) -> Tuple[float, npt.NDArray[np.float64], npt.NDArray[np.float64], int, int]:
        """(distance, point on self, point on other, face of self, face of other)."""
