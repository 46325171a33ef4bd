"""Bad input from Python raises ValueError/OSError with the CLI's one-line message; never a crash."""

import numpy as np
import pytest

import meshclash
from conftest import MESHES, box, run_cli, write_obj

V, F = box()


@pytest.mark.parametrize(
    "vertices,faces,match",
    [
        (V[:, :2], F, r"vertices must have shape \(n, 3\)"),
        (V.ravel(), F, r"vertices must have shape \(n, 3\)"),
        (V, F[:, :2], r"faces must have shape \(m, 3\)"),
        (V, F.ravel(), r"faces must have shape \(m, 3\)"),
        (V.astype(np.float16), F, "vertices must be float64 or float32"),
        (V.astype(bool), F, "vertices must be float64 or float32"),
        (V.astype(object), F, "vertices must be float64 or float32"),
        (V, F.astype(np.float64), "faces must be int32, int64 or uint32"),
        (V, F.astype(np.int16), "faces must be int32, int64 or uint32"),
        (V, np.zeros((0, 3), dtype=np.int64), "no triangles"),
        (np.zeros((0, 3)), F, "triangle 0 refers to vertex 0 but there are 0 vertices"),
        (V, np.where(F == 7, 8, F), "triangle 3 refers to vertex 8 but there are 8 vertices"),
        (V, np.where(F == 7, -1, F), "triangle 3 refers to vertex -1 but there are 8 vertices"),
        (V, np.where(F == 7, 2**40, F), "refers to vertex 1099511627776"),
        (V, np.where(F == 7, 2**32 - 1, F).astype(np.uint32), "refers to vertex 4294967295"),
        (np.where(V == 1.0, np.nan, V), F, r"vertex 1 has a non-finite coordinate \(NaN\)"),
        (np.where(V == 1.0, np.inf, V), F, r"vertex 1 has a non-finite coordinate \(inf\)"),
        (V * 1e76, F, r"beyond ±2\^250"),
    ],
)
def test_bad_arrays_raise_value_error(vertices, faces, match):
    with pytest.raises(ValueError, match=match):
        meshclash.check((vertices, faces), (V, F))
    with pytest.raises(ValueError, match=match):
        meshclash.Mesh(vertices, faces)
    m = meshclash.CollisionManager()
    with pytest.raises(ValueError, match=match):
        m.add_object("x", (vertices, faces))


def test_strided_and_non_contiguous_arrays_are_read_correctly():
    vf = np.asfortranarray(V)
    big = np.zeros((8, 6))
    big[:, ::2] = V
    ff = np.asfortranarray(F.astype(np.int32))
    want = meshclash.check((V, F), (V + 0.5, F), timings=False)
    for v, f in [(vf, F), (big[:, ::2], F), (V, ff), (V[::-1][::-1], F)]:
        assert meshclash.check((v, f), (V + 0.5, F), timings=False) == want


def test_array_errors_read_like_the_cli(tmp_path):
    """The CLI's wording for the same mesh saved as OBJ; arrays number vertices and triangles
    from 0 (as NumPy does) where the OBJ loader gives 1-based OBJ numbers and a line."""
    bad = np.where(V == 1.0, np.nan, V)
    p = write_obj(tmp_path / "bad.obj", bad, F, "a")
    _, _, err = run_cli(p, MESHES / "shared.STL", expect=(2,))
    assert err.strip().endswith("vertex 2 has a non-finite coordinate (NaN)")
    with pytest.raises(ValueError) as e:
        meshclash.check((bad, F), (V, F))
    assert str(e.value) == "<array a>: vertex 1 has a non-finite coordinate (NaN)"
    p = write_obj(tmp_path / "idx.obj", V, np.where(F == 7, 8, F), "a")
    _, _, err = run_cli(p, MESHES / "shared.STL", expect=(2,))
    assert err.strip().endswith("refers to vertex 9 but there are 8 vertices")
    with pytest.raises(ValueError) as e:
        meshclash.check((V, np.where(F == 7, 8, F)), (V, F))
    assert str(e.value) == "<array a>: triangle 3 refers to vertex 8 but there are 8 vertices"


CLI_PREFIX = "meshclash: error: "


def test_file_errors_are_the_cli_line(tmp_path):
    missing = tmp_path / "missing.obj"
    _, _, err = run_cli(missing, MESHES / "shared.STL", expect=(2,))
    with pytest.raises(OSError) as e:
        meshclash.check(missing, MESHES / "shared.STL")
    assert CLI_PREFIX + str(e.value) == err.strip()
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"")
    _, _, err = run_cli(empty, MESHES / "shared.STL", expect=(2,))
    with pytest.raises(ValueError) as e:
        meshclash.check(empty, MESHES / "shared.STL")
    assert CLI_PREFIX + str(e.value) == err.strip()
    with pytest.raises(OSError):
        meshclash.scene(tmp_path)  # a directory
    with pytest.raises(ValueError, match="matches no part"):
        meshclash.scene(MESHES / "pins.glb", select_a=["nothing*"])


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"mode": "sloppy"}, "mode must be"),
        ({"clearance": -1}, "--clearance must be a finite number >= 0"),
        ({"touch_tolerance": "abc"}, "--touch-tolerance must be"),
        ({"touch_tolerance": float("nan")}, "--touch-tolerance must be"),
        ({"transform_b": np.eye(3)}, "transform_b must be a"),
        ({"transform_b": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]}, "last row must be 0,0,0,1"),
        ({"transform_b": np.full((4, 4), np.nan)}, "must be finite"),
        ({"transform_b": [[1e308, 0, 0, 1e308], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}, "not finite after the transform"),
        ({"transform_b": np.diag([1e300, 1e300, 1e300, 1.0])}, r"beyond ±2\^250"),
        ({"leaf_size": 0}, "--leaf-size must be 1..=64"),
        ({"bvh": "octree"}, "bvh must be"),
        ({"distance_rel_err": -0.5}, "--distance-rel-err must be"),
    ],
)
def test_bad_settings_raise_value_error(kwargs, match):
    with pytest.raises(ValueError, match=match):
        meshclash.check((V, F), (V, F), **kwargs)


def test_bad_inputs_of_other_kinds():
    with pytest.raises(ValueError, match="must be a file path"):
        meshclash.check(42, (V, F))
    m = meshclash.CollisionManager()
    with pytest.raises(ValueError, match="not in collision manager"):
        m.remove_object("nope")
    with pytest.raises(ValueError, match="not in collision manager"):
        m.set_transform("nope", np.eye(4))
    with pytest.raises(ValueError, match="not in collision manager"):
        m.min_distance_internal(name="nope")
    m.add_object("a", (V, F))
    with pytest.raises(ValueError, match=r"transform must be \(4,4\)"):
        m.set_transform("a", np.eye(3))
