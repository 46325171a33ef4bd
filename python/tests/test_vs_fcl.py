"""meshclash.CollisionManager against trimesh.collision.CollisionManager (python-fcl).

Clear cases (crossings, comfortable gaps) must agree: verdicts, names, distances to 1e-9. Where
they differ (exact touching, 1-ulp gaps or overlaps, containment), the difference is FCL's: the
exact check (meshclash.check) is shown to side with meshclash.
"""

import numpy as np
import pytest

import meshclash
from conftest import l_prism, shared

fcl = pytest.importorskip("fcl", reason="python-fcl is not installed (run-tests.sh installs it from PyPI)")
trimesh = pytest.importorskip("trimesh", reason="trimesh is not installed (run-tests.sh installs it from PyPI)")
from trimesh.collision import CollisionManager as FclManager  # noqa: E402


def rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def scattered_prisms(seed, n=14, spread=7.0):
    """n non-convex L prisms at random poses (world coordinates in f64, so FCL's float32
    transforms play no part)."""
    rng = np.random.default_rng(seed)
    v, f = l_prism()
    out = {}
    for i in range(n):
        w = v @ rotation(rng).T + rng.uniform(0, spread, size=3)
        out[f"p{i:02d}"] = trimesh.Trimesh(vertices=w, faces=f, process=False)
    return out


def both(meshes):
    a, b = meshclash.CollisionManager(), FclManager()
    for name, m in meshes.items():
        a.add_object(name, m)
        b.add_object(name, m)
    return a, b


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_collision_names_agree_on_clear_cases(seed):
    meshes = scattered_prisms(seed)
    ours, theirs = both(meshes)
    hit, names = ours.in_collision_internal(return_names=True)
    fhit, fnames = theirs.in_collision_internal(return_names=True)
    assert names == fnames and hit == fhit
    assert ours.in_collision_internal() == hit
    assert len(names) > 0  # the layouts do cross somewhere
    # Each colliding pair really crosses (exact check), each other pair is clear.
    for i, a in enumerate(sorted(meshes)):
        for b in sorted(meshes)[i + 1:]:
            r = meshclash.check(meshes[a], meshes[b])
            assert (r["summary"]["crossing_pairs"] > 0) == ((a, b) in names), (a, b)
    # in_collision_single / _other against FCL's.
    probe = meshes["p00"]
    rest_ours, rest_theirs = both({k: m for k, m in meshes.items() if k != "p00"})
    assert rest_ours.in_collision_single(probe, return_names=True) == rest_theirs.in_collision_single(
        probe, return_names=True
    )
    one_ours, one_theirs = both({"p00": probe})
    assert rest_ours.in_collision_other(one_ours, return_names=True) == rest_theirs.in_collision_other(
        one_theirs, return_names=True
    )


@pytest.mark.parametrize("seed", [5, 6])
def test_min_distance_agrees_on_separated_pairs(seed):
    meshes = scattered_prisms(seed, n=8, spread=14.0)
    names = sorted(meshes)
    compared = 0
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            ours, theirs = both({a: meshes[a]})
            if ours.in_collision_single(meshes[b]):
                continue
            d, data = ours.min_distance_single(meshes[b], return_data=True)
            fd = theirs.min_distance_single(meshes[b])
            assert abs(d - fd) <= 1e-9, (a, b, d, fd)
            assert d > 0
            # The witness points are on the surfaces and d apart.
            assert abs(np.linalg.norm(data.point(a) - data.point("__external")) - d) <= 1e-12 * max(1.0, d)
            compared += 1
    assert compared >= 10
    ours, theirs = both(meshes)
    d, n = ours.min_distance_internal(return_names=True)
    fd, fn = theirs.min_distance_internal(return_names=True)
    if not ours.in_collision_internal():
        assert abs(d - fd) <= 1e-9 and n == fn


def test_engine_parts_differ_from_fcl_only_where_fcl_is_inexact():
    """2CylinderEngine's parts as placed in the file: every pair whose triangles cross is a
    collision for both; any pair on which they disagree is shown by the exact check to be
    touching-only or containment (meshclash yes, FCL no) or clear (FCL yes, meshclash no)."""
    scene = trimesh.load(shared("2CylinderEngine.glb"), force="scene", process=False)
    meshes = {}
    for node in scene.graph.nodes_geometry:
        t, geom = scene.graph[node]
        m = scene.geometry[geom].copy()
        m.apply_transform(t)
        meshes[node] = m
    ours, theirs = both(meshes)
    _, names = ours.in_collision_internal(return_names=True)
    _, fnames = theirs.in_collision_internal(return_names=True)
    for a, b in names ^ fnames:
        r = meshclash.check(meshes[a], meshes[b])
        if (a, b) in names:
            assert r["summary"]["crossing_pairs"] == 0, (a, b)
            assert r["verdict"] in ("touching", "clash") and (
                r["verdict"] == "touching" or r["summary"]["contained"] is not None
            ), (a, b, r["summary"])
        else:
            assert r["verdict"] in ("clear", "clearance"), (a, b, r["summary"])
    crossing = set()
    for a, b in names:
        if meshclash.check(meshes[a], meshes[b], first_hit=True)["summary"]["crossing_pairs"] > 0:
            crossing.add((a, b))
    assert crossing and crossing <= fnames


def exact_collides(a, b):
    r = meshclash.check(a, b)
    return r["verdict"] == "touching" or r["verdict"] == "clash"


def test_touching_and_one_ulp_cases_show_fcls_differences():
    """Exactly touching, 1 ulp apart, 1 ulp into each other, and containment: meshclash's
    manager equals the exact check every time; FCL's answer is printed beside it, and it is
    wrong in at least one of them."""
    v, f = l_prism()
    a = trimesh.Trimesh(vertices=v, faces=f, process=False)

    def shifted(x, y=0.0):
        return trimesh.Trimesh(vertices=v + [x, y, 0.0], faces=f, process=False)

    big_v, big_f = l_prism(scale=10.0, at=(-1.0, -1.0, -1.0))
    cases = {
        "faces touch (x = 2)": shifted(2.0),
        "1 ulp apart": shifted(np.nextafter(2.0, 3.0)),
        "1 ulp into": shifted(np.nextafter(2.0, 1.0)),
        "edge touches (x = 2, y = 1)": shifted(2.0, 1.0),
        "corner 1e-12 apart": shifted(2.0 + 1e-12, 2.0),
        "inside a larger L": trimesh.Trimesh(vertices=big_v, faces=big_f, process=False),
    }
    rows, fcl_wrong = [], []
    for name, b in cases.items():
        ours, theirs = both({"a": a})
        got, fgot, exact = ours.in_collision_single(b), theirs.in_collision_single(b), exact_collides(a, b)
        assert got == exact, name
        rows.append(f"{name:28} exact={exact!s:5} meshclash={got!s:5} fcl={fgot!s:5}")
        if fgot != exact:
            fcl_wrong.append(name)
    print("\n".join(rows))
    assert "inside a larger L" in fcl_wrong  # containment: FCL's meshes are surfaces
    assert exact_collides(a, cases["faces touch (x = 2)"]) and not exact_collides(a, cases["1 ulp apart"])


def test_tiny_gaps_fcl_reports_distance_zero():
    """A tilted L and a copy moved along a face normal by 2 + gap: for gaps of 1e-12 to 1e-9,
    FCL says 'no collision' yet 'distance 0'; meshclash's manager gives the exact check's
    distance (about the gap) and its verdict."""
    v, f = l_prism()
    axis = np.array([1.0, 2.0, 3.0]) / np.linalg.norm([1.0, 2.0, 3.0])
    r = trimesh.transformations.rotation_matrix(0.7, axis)[:3, :3]
    a = trimesh.Trimesh(vertices=v @ r.T, faces=f, process=False)
    normal = r @ np.array([1.0, 0.0, 0.0])
    rows, fcl_zero = [], []
    for gap in [1e-12, 1e-9, 1e-6, -1e-9]:
        b = trimesh.Trimesh(vertices=v @ r.T + normal * (2.0 + gap), faces=f, process=False)
        ours, theirs = both({"a": a})
        exact = meshclash.check(a, b)
        d, fd = ours.min_distance_single(b), theirs.min_distance_single(b)
        assert d == exact["summary"]["min_distance"]
        assert ours.in_collision_single(b) == (exact["verdict"] == "clash") == (gap < 0)
        assert theirs.in_collision_single(b) == (gap < 0)  # FCL's verdicts agree here
        if gap > 0:
            assert abs(d - gap) < 1e-14 + 1e-6 * gap
            if fd == 0.0:
                fcl_zero.append(gap)
        rows.append(f"gap {gap:8g}: meshclash d={d:.3g}, fcl d={fd:.3g}")
    print("\n".join(rows))
    assert 1e-9 in fcl_zero and 1e-12 in fcl_zero
