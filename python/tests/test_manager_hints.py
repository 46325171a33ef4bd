"""meshclash.CollisionManager: the names, yes/no and distance queries of a manager whose objects
move (it keeps, per object pair, the triangle pair that met last time and tries it first) give
the answers of a fresh manager at every step, including steps where the kept triangle pair no
longer meets, where the objects separate, and where one part moves inside another."""

import numpy as np

import meshclash
from conftest import box, l_prism


def at(x, y=0.0, z=0.0):
    t = np.eye(4)
    t[:3, 3] = [x, y, z]
    return t


def fresh(objs):
    m = meshclash.CollisionManager()
    for name, (mesh, t) in objs.items():
        m.add_object(name, mesh, transform=t)
    return m


def test_kept_contacts_never_change_an_answer():
    rng = np.random.default_rng(11)
    objs = {f"l{i}": (l_prism(), at(*rng.uniform(0, 4, size=3))) for i in range(10)}
    # A large box and a small one that touches it, crosses its wall, then lies inside it.
    objs["big"] = (box((0.0, 0.0, 0.0), (4.0, 4.0, 4.0)), at(10.0))
    objs["small"] = (box(), at(14.0, 1.0, 1.0))
    kept = fresh(objs)
    inner = 0
    for step in range(12):
        # The L prisms move by small steps (contacts change), one of them far away and back.
        for i in range(10):
            if rng.random() < 0.6:
                objs[f"l{i}"] = (objs[f"l{i}"][0], at(*rng.uniform(0, 4, size=3)))
        objs["l0"] = (objs["l0"][0], at(30.0) if step % 3 == 1 else at(1.0, 1.0, 0.5))
        x = [14.0, 13.5, 12.0, 11.0][step % 4]
        objs["small"] = (objs["small"][0], at(x, 1.0, 1.0))
        for name, (_, t) in objs.items():
            kept.set_transform(name, t)
        ref = fresh(objs)
        _, names = kept.in_collision_internal(return_names=True)
        _, want = ref.in_collision_internal(return_names=True)
        assert names == want, step
        assert kept.in_collision_internal() == (len(want) > 0), step
        assert kept.min_distance_internal(return_names=True) == fresh(objs).min_distance_internal(
            return_names=True
        ), step
        # The same with the kept contacts of this very step (a still scene).
        assert kept.in_collision_internal(return_names=True)[1] == want, step
        inner += ("big", "small") in want and x == 12.0
    # The small box inside the big one (no triangles meet) counts as a collision.
    assert inner == 3
