"""The distance query of colliding convex parts against a scan of every pair in floats: the
answer is the first pair in insertion order whose triangles meet, at minus its penetration depth
(the separating-axis minimum over every face normal and every cross product of two edges), and
the same after every object is moved (placed anew) and after moves by exact translations."""

import itertools

import numpy as np
import pytest

import meshclash

trimesh = pytest.importorskip("trimesh")


def spheres(seed, n):
    """n small icospheres (80 faces) of random radii packed so that some pairs overlap."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        m = trimesh.creation.icosphere(subdivisions=1, radius=rng.uniform(0.3, 1.0))
        out.append((np.array(m.vertices), np.array(m.faces), rng.uniform(0.0, 4.0, size=3)))
    return out


def depth(va, ea, vb, eb, fa, fb):
    """Penetration depth of two convex polytopes in floats: the smallest overlap over the face
    normals of both and the cross products of every edge pair (every axis bounds the depth from
    above; the facet normals of the Minkowski difference are among these)."""

    def normals(v, f):
        n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        return n / np.linalg.norm(n, axis=1)[:, None]

    da = va[ea[:, 1]] - va[ea[:, 0]]
    db = vb[eb[:, 1]] - vb[eb[:, 0]]
    cross = np.cross(da[:, None, :], db[None, :, :]).reshape(-1, 3)
    length = np.linalg.norm(cross, axis=1)
    cross = cross[length > 1e-12 * length.max()] / length[length > 1e-12 * length.max()][:, None]
    axes = np.concatenate([normals(va, fa), normals(vb, fb), cross])
    pa, pb = va @ axes.T, vb @ axes.T
    overlap = np.minimum(pa.max(0) - pb.min(0), pb.max(0) - pa.min(0))
    return overlap.min()


def inside(va, vb, fb):
    """Every vertex of A strictly inside convex B (below every face plane of B)."""
    n = np.cross(vb[fb[:, 1]] - vb[fb[:, 0]], vb[fb[:, 2]] - vb[fb[:, 0]])
    return bool(np.all(np.einsum("fk,vfk->vf", n, va[:, None, :] - vb[fb[:, 0]][None, :, :]) < 0))


def expected(world, faces):
    """(signed distance, pair) the query must give: the first pair in insertion order whose
    surfaces meet (overlapping solids, neither strictly inside the other), else the first with
    one inside the other; None when nothing collides."""
    edges = [trimesh.Trimesh(v, f, process=False).edges_unique for v, f in zip(world, faces)]
    meeting, contained = None, None
    centers = [(v.min(0) + v.max(0)) / 2 for v in world]
    radii = [np.linalg.norm(v - c, axis=1).max() for v, c in zip(world, centers)]
    for i, j in itertools.combinations(range(len(world)), 2):
        if np.linalg.norm(centers[i] - centers[j]) > 1.01 * (radii[i] + radii[j]):
            continue  # bounding balls apart: no overlap
        d = depth(world[i], edges[i], world[j], edges[j], faces[i], faces[j])
        if d <= 0:
            continue
        if inside(world[i], world[j], faces[j]) or inside(world[j], world[i], faces[i]):
            contained = contained or (-d, (i, j))
        else:
            meeting = (-d, (i, j))
            break
    return meeting or contained


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_colliding_convex_parts_answer_the_first_meeting_pair_at_minus_its_depth(seed):
    objs = spheres(seed, 14)
    names = [f"s{k}" for k in range(len(objs))]
    faces = [f for _, f, _ in objs]

    def check(m, world):
        want = expected(world, faces)
        assert want is not None, "the scene must collide"
        d, pair = m.min_distance_internal(return_names=True)
        assert pair == tuple(sorted((names[want[1][0]], names[want[1][1]])))
        assert d <= 0
        assert abs(d - want[0]) <= 1e-9 * (1 + abs(want[0]))

    # Vertices placed in the mesh (identity placement: the prepared mesh's own coordinates).
    m = meshclash.CollisionManager()
    for name, (v, f, at) in zip(names, objs):
        m.add_object(name, trimesh.Trimesh(v + at, f, process=False))
    check(m, [v + at for v, _, at in objs])
    # Every object placed anew where it is (each pair decided again).
    for name in names:
        m.set_transform(name, np.eye(4))
    check(m, [v + at for v, _, at in objs])

    # Placed by translations: shifted by whole units, exact in f64 for these coordinates
    # (the placement reuses the prepared mesh's face frames), then moved by other whole units.
    m = meshclash.CollisionManager()
    for name, (v, f, at) in zip(names, objs):
        t = np.eye(4)
        t[:3, 3] = [3.0, -2.0, 5.0]
        m.add_object(name, trimesh.Trimesh(v + at, f, process=False), transform=t)
    check(m, [v + at + [3.0, -2.0, 5.0] for v, _, at in objs])
    for k, name in enumerate(names):
        t = np.eye(4)
        t[:3, 3] = [float(k % 3), 1.0, -1.0]
        m.set_transform(name, t)
    check(m, [v + at + [float(k % 3), 1.0, -1.0] for k, (v, _, at) in enumerate(objs)])
