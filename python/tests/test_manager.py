"""meshclash.CollisionManager: trimesh's interface and return shapes, exact answers."""

import numpy as np
import pytest

import meshclash
from conftest import box, l_prism


def at(x, y=0.0, z=0.0):
    t = np.eye(4)
    t[:3, 3] = [x, y, z]
    return t


def manager(**objs):
    m = meshclash.CollisionManager()
    for name, (mesh, t) in objs.items():
        m.add_object(name, mesh, transform=t)
    return m


CUBE = box()


def test_internal_collisions_names_and_data():
    m = manager(a=(CUBE, None), b=(CUBE, at(0.5, 0.5, 0.5)), c=(CUBE, at(5)), d=(CUBE, at(6)))
    assert m.in_collision_internal() is True
    hit, names = m.in_collision_internal(return_names=True)
    assert hit and names == {("a", "b"), ("c", "d")}  # c and d touch face to face: a collision
    hit, names, data = m.in_collision_internal(return_names=True, return_data=True)
    assert {tuple(sorted(c.names)) for c in data} == names
    for c in data:
        (x, y) = sorted(c.names)
        assert 0 <= c.index(x) < 12 and 0 <= c.index(y) < 12
        assert c.point.shape == (3,) and abs(np.linalg.norm(c.normal) - 1) < 1e-12
    # Convex pairs: one contact each, with the exact depth (a and b overlap by 0.5 along every
    # axis; c and d touch).
    assert sorted(c.depth for c in data) == [0.0, 0.5]
    hit, data = m.in_collision_internal(return_data=True)
    assert hit and len(data) == 2
    m.set_transform("d", at(np.nextafter(6.0, 7.0)))
    assert m.in_collision_internal(return_names=True)[1] == {("a", "b")}
    m.remove_object("b")
    assert m.in_collision_internal() is False
    assert m.in_collision_internal(return_names=True, return_data=True) == (False, set(), [])


def test_containment_is_a_collision():
    big = box((-5, -5, -5), (5, 5, 5))
    m = manager(big=(big, None), small=(CUBE, None))
    hit, names, data = m.in_collision_internal(return_names=True, return_data=True)
    assert hit and names == {("big", "small")}
    # Both convex: the contact is the exact penetration (out through x, y or z = 5: depth 5),
    # with no meeting triangles (face -1).
    assert len(data) == 1 and data[0].depth == 5.0 and data[0].index("big") == -1
    assert data[0].kind == "a_in_b" or data[0].kind == "b_in_a"
    assert m.min_distance_internal() == -5.0
    # Non-convex container: the contact has no point, the distance is 0 (never the gap).
    m.add_object("big", l_prism(scale=10.0, at=(-1.0, -1.0, -1.0)))
    hit, data = m.in_collision_internal(return_data=True)
    assert hit and len(data) == 1 and data[0].point is None and data[0].depth == 0.0
    assert m.min_distance_internal() == 0.0


def test_single_and_other():
    m = manager(a=(CUBE, None), b=(CUBE, at(2)))
    assert m.in_collision_single(CUBE, transform=at(0.5)) is True
    assert m.in_collision_single(CUBE, transform=at(0.5), return_names=True) == (True, {"a"})
    # Touching both: x in [1, 2] meets a at x = 1 and b at x = 2.
    assert m.in_collision_single(CUBE, transform=at(1.0), return_names=True) == (True, {"a", "b"})
    hit, data = m.in_collision_single(CUBE, transform=at(1.0), return_data=True)
    assert hit and {n for c in data for n in c.names} == {"a", "b", "__external"}
    assert m.in_collision_single(CUBE, transform=at(-1.5)) is False
    other = manager(x=(CUBE, at(0, 0.9)), y=(CUBE, at(10)))
    assert m.in_collision_other(other, return_names=True) == (True, {("a", "x")})
    assert other.in_collision_other(m, return_names=True) == (True, {("x", "a")})


def test_distances():
    m = manager(a=(CUBE, None), b=(CUBE, at(3)), c=(CUBE, at(0, 4.5)))
    assert m.min_distance_internal() == 2.0
    d, names = m.min_distance_internal(return_names=True)
    assert (d, names) == (2.0, ("a", "b"))
    d, names, data = m.min_distance_internal(return_names=True, return_data=True)
    assert data.distance == 2.0 and data.point("a")[0] == 1.0 and data.point("b")[0] == 3.0
    assert m.min_distance_internal(name="c", return_names=True) == (3.5, ("a", "c"))
    d, name = m.min_distance_single(CUBE, transform=at(0, -1.25), return_name=True)
    assert (d, name) == (0.25, "a")
    d, name, data = m.min_distance_single(CUBE, transform=at(0, -1.25), return_name=True, return_data=True)
    assert data.index("a") >= 0 and np.isclose(data.point("__external")[1], -0.25)
    other = manager(z=(CUBE, at(3, 0, 1.5)))
    assert m.min_distance_other(other, return_names=True) == (0.5, ("b", "z"))
    m.set_transform("b", at(1.0))
    assert m.min_distance_internal() == 0.0  # touching
    empty = meshclash.CollisionManager()
    assert empty.min_distance_internal() == float("inf")
    assert empty.in_collision_internal() is False


def test_add_object_accepts_tuples_meshes_and_trimesh_likes():
    class Like:
        vertices, faces = l_prism()

    m = meshclash.CollisionManager()
    m.add_object("tuple", CUBE)
    m.add_object("mesh", meshclash.Mesh(*CUBE), transform=at(0.5))
    m.add_object("like", Like(), transform=at(10))
    assert m.in_collision_internal(return_names=True) == (True, {("mesh", "tuple")})
    m.add_object("mesh", CUBE, transform=at(1.5))  # replaces
    assert m.in_collision_internal() is False


def test_transforms_are_applied_in_f64():
    """trimesh casts transforms to float32; here 0.1 stays the f64 0.1."""
    m = manager(a=(CUBE, None), b=(CUBE, at(1.0 + 1e-12)))
    assert m.in_collision_internal() is False
    assert 0 < m.min_distance_internal() < 2e-12


def test_many_objects_match_pairwise_checks():
    rng = np.random.default_rng(7)
    objs = {f"o{i}": (l_prism(), at(*rng.uniform(0, 6, size=3))) for i in range(25)}
    m = manager(**objs)
    _, names = m.in_collision_internal(return_names=True)
    want = set()
    keys = sorted(objs)
    for i, a in enumerate(keys):
        for b in keys[i + 1:]:
            r = meshclash.check(objs[a][0], objs[b][0], transform_a=objs[a][1], transform_b=objs[b][1])
            if r["verdict"] in ("touching", "clash"):
                want.add((a, b))
    assert names == want and len(want) > 0
