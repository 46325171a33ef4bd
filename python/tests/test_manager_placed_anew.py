"""meshclash.CollisionManager: an object given a new transform (other bits, the same place or
another) computes its world coordinates only when a query reads them; every answer afterwards,
in whatever order the queries come, is the answer of a fresh manager of the same scene, and a
transform that takes a vertex out of range still fails at set_transform / add_object."""

import numpy as np
import pytest
import trimesh

from conftest import flipped, manager_of


def scene(seed):
    """Spheres and boxes rotated, scaled unevenly, sheared and translated (some overlapping,
    some apart, one inside another)."""
    rng = np.random.default_rng(seed)
    parts = []
    for k in range(9):
        if k % 3 == 2:
            mesh = trimesh.creation.box(extents=0.5 + rng.random(3))
        else:
            mesh = trimesh.creation.icosphere(subdivisions=1, radius=0.4 + rng.random())
        t = trimesh.transformations.random_rotation_matrix(rng.random(3))
        if k % 4 == 1:
            t = t @ np.diag([0.5 + rng.random(), 0.5 + rng.random(), 1.5, 1.0])
        if k % 4 == 3:
            t[0, 1] += 0.3
        t[:3, 3] = rng.random(3) * 5.0
        parts.append((f"p{k}", mesh, t))
    parts.append(("inner", trimesh.creation.icosphere(subdivisions=1, radius=0.05), parts[0][2].copy()))
    return parts




def query(m, which, probe):
    """One query of the manager, its answer in comparable form."""
    names = m._native.names()
    if which == "yes":
        return m.in_collision_internal()
    if which == "names":
        hit, pairs = m.in_collision_internal(return_names=True)
        return hit, sorted(pairs)
    if which == "distance":
        d, pair, data = m.min_distance_internal(return_names=True, return_data=True)
        return d, pair, data.point(pair[0]).tolist(), data.point(pair[1]).tolist()
    if which == "named":
        return [m.min_distance_internal(name=n) for n in names]
    if which == "single":
        mesh, t = probe
        hit, hit_names = m.in_collision_single(mesh, t, return_names=True)
        d, name, data = m.min_distance_single(mesh, t, return_name=True, return_data=True)
        return hit, sorted(hit_names), d, name, data.point(name).tolist()
    raise ValueError(which)


QUERIES = ["yes", "names", "distance", "named", "single"]


def test_placed_anew_answers_as_a_fresh_manager_in_any_query_order():
    probe = (trimesh.creation.box(extents=[1.0, 2.0, 0.5]), np.eye(4))
    probe[1][:3, 3] = [1.5, 2.0, 2.5]
    for seed in range(3):
        parts = scene(seed)
        transforms = {name: t for name, _, t in parts}
        kept = manager_of(parts, transforms)
        rng = np.random.default_rng(100 + seed)
        for step in range(6):
            # Every other step the same places under other bits; else some objects really move.
            if step % 2 == 0:
                transforms = {name: flipped(t) for name, t in transforms.items()}
            else:
                for name in rng.choice(sorted(transforms), size=3, replace=False):
                    t = transforms[name].copy()
                    t[:3, 3] += rng.normal(size=3)
                    transforms[name] = t
            for name, t in transforms.items():
                kept.set_transform(name, t)
            reference = manager_of(parts, transforms)
            # The first query after the move reads the fresh placements; the order varies.
            order = [QUERIES[(step + k) % len(QUERIES)] for k in range(len(QUERIES))]
            for which in order:
                assert query(kept, which, probe) == query(reference, which, probe), (seed, step, which)


def test_a_transform_out_of_range_fails_at_the_call_and_changes_nothing():
    parts = scene(5)
    transforms = {name: t for name, _, t in parts}
    m = manager_of(parts, transforms)
    before = [query(m, which, None) for which in QUERIES[:4]]
    huge = np.diag([1e300, 1e300, 1e300, 1.0])
    overflow = np.array([[1e308, 0, 0, 1e308], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    for t, match in [(huge, r"beyond ±2\^250"), (overflow, "after the transform")]:
        with pytest.raises(ValueError, match=match):
            m.set_transform("p1", t)
        with pytest.raises(ValueError, match=match):
            m.add_object("new", parts[1][1], t)
        with pytest.raises(ValueError, match=match):
            m.in_collision_single(parts[1][1], t)
    assert m._native.names() == [name for name, _, _ in parts]
    assert [query(m, which, None) for which in QUERIES[:4]] == before
    # Near the end of the range (the box bound leaves it, every vertex stays in it): placed.
    edge = np.eye(4)
    edge[:3, 3] = np.nextafter(2.0**250, 0.0)
    m.set_transform("p1", edge)
    assert query(m, "names", None) == query(manager_of(parts, {**transforms, "p1": edge}), "names", None)
