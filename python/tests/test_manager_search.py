"""The manager's searches against scans of every pair: the best-first distance search, the
persistent broad phase, and rotated parts (their bounding balls and topology come from the
prepared mesh, without a pass over the vertices, where rounding cannot change them)."""

import numpy as np

import meshclash
from conftest import box, l_prism


def placement(rng, spread):
    """A random rotation (scaled by up to 1.5) and a translation in [0, spread)^3."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    t = np.eye(4)
    t[:3, :3] = q * rng.uniform(0.5, 1.5)
    t[:3, 3] = rng.uniform(0, spread, size=3)
    return t


def scene(seed, n, spread):
    rng = np.random.default_rng(seed)
    shapes = [l_prism(), box()]
    return {f"o{i}": (meshclash.Mesh(*shapes[i % 2]), placement(rng, spread)) for i in range(n)}


def manager(objs):
    m = meshclash.CollisionManager()
    for name, (mesh, t) in objs.items():
        m.add_object(name, mesh, transform=t)
    return m


def pairs(objs):
    keys = list(objs)
    return [(a, b) for i, a in enumerate(keys) for b in keys[i + 1:]]


def test_min_distance_is_the_smallest_over_every_pair():
    for seed in range(3):
        objs = scene(seed, 40, 60.0)
        m = manager(objs)
        colliding = {p for p in pairs(objs) if objs[p[0]][0].collides(objs[p[1]][0], objs[p[0]][1], objs[p[1]][1])}
        if colliding:
            continue  # a signed distance; this test is about the search among separated parts
        scan = min(
            (objs[a][0].distance(objs[b][0], objs[a][1], objs[b][1])[0], a, b) for a, b in pairs(objs)
        )
        d, names = m.min_distance_internal(return_names=True)
        assert (d, names) == (scan[0], (scan[1], scan[2]))
        # The same with every object moved (the tree is built again) and by name.
        for name, (mesh, t) in objs.items():
            m.set_transform(name, t)
        assert m.min_distance_internal(return_names=True) == (d, names)
        want = min(
            (objs["o3"][0].distance(objs[b][0], objs["o3"][1], objs[b][1])[0], b) for b in objs if b != "o3"
        )
        assert m.min_distance_internal(name="o3", return_names=True) == (want[0], tuple(sorted(("o3", want[1]))))
        # Against another manager and a single mesh.
        half = dict(list(objs.items())[:20])
        rest = dict(list(objs.items())[20:])
        ma, mb = manager(half), manager(rest)
        across = min(
            (objs[a][0].distance(objs[b][0], objs[a][1], objs[b][1])[0], a, b) for a in half for b in rest
        )
        assert ma.min_distance_other(mb, return_names=True) == (across[0], (across[1], across[2]))
        probe, t = objs["o0"]
        single = min((probe.distance(rest[b][0], t, rest[b][1])[0], b) for b in rest)
        assert mb.min_distance_single(probe, transform=t, return_name=True) == (single[0], single[1])
        return
    raise AssertionError("every seed gave a colliding scene")


def test_collisions_of_rotated_parts_match_pairwise_checks():
    objs = scene(11, 30, 6.0)
    m = manager(objs)
    want = {
        tuple(sorted(p)) for p in pairs(objs) if objs[p[0]][0].collides(objs[p[1]][0], objs[p[0]][1], objs[p[1]][1])
    }
    assert 0 < len(want) < len(pairs(objs))
    assert m.in_collision_internal(return_names=True) == (True, want)
    # Moved elsewhere and back: the broad phase follows.
    for k, (name, (_, t)) in enumerate(objs.items()):
        far = t.copy()
        far[0, 3] += 100.0 * k
        m.set_transform(name, far)
    assert m.in_collision_internal() is False
    for name, (_, t) in objs.items():
        m.set_transform(name, t)
    assert m.in_collision_internal(return_names=True) == (True, want)


def test_a_rotated_part_inside_a_rotated_container_collides_and_has_no_gap():
    rng = np.random.default_rng(5)
    outer = meshclash.Mesh(*box((-4, -4, -4), (4, 4, 4)))
    inner = meshclash.Mesh(*box((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5)))
    for _ in range(10):
        r = placement(rng, 0.0)
        r[:3, :3] /= np.cbrt(abs(np.linalg.det(r[:3, :3])))  # keep the unit scale
        t = placement(rng, 0.0)
        t[:3, :3] /= np.cbrt(abs(np.linalg.det(t[:3, :3])))
        m = meshclash.CollisionManager()
        m.add_object("outer", outer, transform=r)
        m.add_object("inner", inner, transform=t)
        assert m.in_collision_internal(return_names=True) == (True, {("inner", "outer")})
        d = m.min_distance_internal()
        assert d <= 0.0
