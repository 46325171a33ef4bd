"""The trimesh drop-in: signed distances and exact convex depth, the objects and helpers trimesh
code uses, the typed overloads, and memory bounds of the array entry points."""

import importlib.util
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshclash
from conftest import box, l_prism


def at(x, y=0.0, z=0.0):
    t = np.eye(4)
    t[:3, 3] = [x, y, z]
    return t


CUBE = box((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))


def test_convex_overlaps_give_the_exact_depth_as_negative_distance():
    m = meshclash.CollisionManager()
    m.add_object("a", CUBE)
    for shift, want in [(0.75, -0.25), (0.0, -1.0), (1.0, 0.0), (3.0, 2.0), (0.5 + 2**-40, -(0.5 - 2**-40))]:
        d, data = m.min_distance_single(CUBE, transform=at(shift), return_data=True)
        assert d == want, shift
        if d < 0:
            assert np.linalg.norm(data.point("a") - data.point("__external")) == pytest.approx(-d)
    hit, data = m.in_collision_single(CUBE, transform=at(0.75), return_data=True)
    assert hit and len(data) == 1
    assert data[0].depth == 0.25 and np.array_equal(data[0].normal, [1.0, 0.0, 0.0])


def test_a_contained_part_never_reports_a_gap():
    big = box((-5, -5, -5), (5, 5, 5))
    small = box((-4, -1, -1), (-3, 1, 1))
    m = meshclash.CollisionManager()
    m.add_object("big", big)
    m.add_object("small", small)
    assert m.in_collision_internal() is True
    # Both convex: minus the exact depth (out through x = -5: 1 + 1 = ... the small box spans
    # x in [-4, -3], so moving it by -2 puts it at [-6, -5]).
    assert m.min_distance_internal() == -2.0
    # A non-convex container (an L-shaped prism) around a small cube: 0, never the gap.
    lv, lf = l_prism(scale=10.0, at=(-10.0, -10.0, -10.0))
    n = meshclash.CollisionManager()
    n.add_object("l", (lv, lf))
    n.add_object("cube", box((-9, -9, -9), (-8, -8, -8)))
    assert n.in_collision_internal() is True
    d, names, data = n.min_distance_internal(return_names=True, return_data=True)
    assert d == 0.0 and names == ("cube", "l") and data.index("l") == -1


def test_distance_stops_at_the_first_colliding_pair_in_order():
    m = meshclash.CollisionManager()
    m.add_object("a", CUBE)
    m.add_object("b", CUBE, at(0.9))  # overlaps a by 0.1
    m.add_object("c", CUBE, at(10.0))
    m.add_object("d", CUBE, at(10.5))  # overlaps c by 0.5: deeper, later
    assert m.min_distance_internal(return_names=True) == (pytest.approx(-0.1), ("a", "b"))
    m.set_transform("b", at(3.0))
    assert m.min_distance_internal(return_names=True) == (-0.5, ("c", "d"))


def test_add_object_returns_an_object_and_set_transform_updates_it():
    m = meshclash.CollisionManager()
    obj = m.add_object("a", CUBE, at(1.0))
    assert isinstance(obj, meshclash.CollisionObject) and obj.name == "a"
    assert np.array_equal(obj.getTranslation(), [1.0, 0.0, 0.0])
    m.set_transform("a", at(2.0))
    assert np.array_equal(obj.transform, at(2.0))


def test_scene_to_collision_and_mesh_to_bvh():
    trimesh = pytest.importorskip("trimesh")
    a = trimesh.creation.box(extents=[1, 1, 1])
    b = trimesh.creation.box(extents=[1, 1, 1])
    b.apply_translation([0.5, 0, 0])
    c = trimesh.creation.box(extents=[1, 1, 1])
    c.apply_translation([5, 0, 0])
    scene = trimesh.Scene([a, b, c])
    manager, objects = meshclash.scene_to_collision(scene)
    assert set(objects) == set(scene.graph.nodes_geometry)
    hit, names = manager.in_collision_internal(return_names=True)
    assert hit and len(names) == 1
    prepared = meshclash.mesh_to_BVH(a)
    assert isinstance(prepared, meshclash.Mesh) and prepared.face_count == 12
    assert manager.in_collision_single(prepared) is True


def test_a_mesh_edited_in_place_is_prepared_again():
    trimesh = pytest.importorskip("trimesh")
    probe = trimesh.creation.box(extents=[1, 1, 1])
    m = meshclash.CollisionManager()
    m.add_object("a", CUBE)
    assert m.in_collision_single(probe) is True
    probe.apply_translation([10, 0, 0])  # edits the vertices in place
    assert m.in_collision_single(probe) is False


SNIPPET = """
from typing import List, Optional, Set, Tuple

import numpy as np
import meshclash

m = meshclash.CollisionManager()
v = np.zeros((3, 3))
f = np.array([[0, 1, 2]])
obj: meshclash.CollisionObject = m.add_object("a", (v, f))
only: bool = m.in_collision_internal()
hit, names = m.in_collision_internal(return_names=True)
pairs: Set[Tuple[str, str]] = names
flag, names2, data = m.in_collision_internal(return_names=True, return_data=True)
contacts: List[meshclash.ContactData] = data
hit1, data1 = m.in_collision_single((v, f), return_data=True)
depth: float = data1[0].depth
dist: float = m.min_distance_internal()
d2, pair = m.min_distance_internal(return_names=True)
maybe: Optional[Tuple[str, str]] = pair
d3, name = m.min_distance_single((v, f), return_name=True)
label: Optional[str] = name
manager, objects = meshclash.scene_to_collision(None)
"""


def test_stubs_type_check_the_common_calls(tmp_path):
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed")
    src = tmp_path / "snippet.py"
    src.write_text(textwrap.dedent(SNIPPET))
    p = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental", "--cache-dir", str(tmp_path / "cache"), str(src)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    # And a wrong use is caught: the tuple is not a bool.
    src.write_text(textwrap.dedent(SNIPPET) + "wrong: bool = m.in_collision_internal(return_names=True)\n")
    p = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental", "--cache-dir", str(tmp_path / "cache"), str(src)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    line = len(textwrap.dedent(SNIPPET).splitlines()) + 1
    assert p.returncode == 1 and f"snippet.py:{line}: error: Incompatible types" in p.stdout, p.stdout


def test_stubs_type_check_under_pyright(tmp_path):
    if importlib.util.find_spec("pyright") is None:
        pytest.skip("pyright is not installed")
    src = tmp_path / "snippet.py"
    src.write_text(textwrap.dedent(SNIPPET))
    run = [sys.executable, "-m", "pyright", "--pythonpath", sys.executable, str(src)]
    p = subprocess.run(run, capture_output=True, text=True, cwd=tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    src.write_text(textwrap.dedent(SNIPPET) + "wrong: bool = m.in_collision_internal(return_names=True)\n")
    p = subprocess.run(run, capture_output=True, text=True, cwd=tmp_path)
    line = len(textwrap.dedent(SNIPPET).splitlines()) + 1
    assert p.returncode == 1 and f"snippet.py:{line}:" in p.stdout, p.stdout


LIMITED = """
import resource, sys
import numpy as np
resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))
import meshclash
{make}
try:
    meshclash.Mesh(v, f)
except MemoryError as e:
    print("MemoryError:", e)
    sys.exit(0)
print("no error")
sys.exit(3)
"""


@pytest.mark.parametrize(
    "make",
    [
        # 10^8 vertices (float32: 1.2 GB): preparing would need about 10 GB.
        "v = np.zeros((10**8, 3), dtype=np.float32); f = np.array([[0, 1, 2]], dtype=np.int32)",
        # 5 * 10^7 copies of one triangle (600 MB of indices).
        "v = np.eye(3); f = np.zeros((5 * 10**7, 3), dtype=np.int32); f[:, 1] = 1; f[:, 2] = 2",
    ],
    ids=["1e8-vertices", "5e7-identical-faces"],
)
def test_huge_arrays_raise_memory_error_under_a_limit(make, tmp_path):
    limit = 3 * 2**30
    p = subprocess.run(
        [sys.executable, "-c", LIMITED.format(limit=limit, make=make)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert p.returncode == 0, (p.returncode, p.stdout, p.stderr[-2000:])
    assert "MemoryError:" in p.stdout and "MB this process may still allocate" in p.stdout
