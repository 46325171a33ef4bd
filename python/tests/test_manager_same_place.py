"""meshclash.CollisionManager: set_transform to the transform an object already has keeps its
placement (nothing to compute again) but still drops the answers kept about it; every answer
afterwards is the answer of a fresh manager of the same scene (the reference: it decides every
pair from scratch)."""

import numpy as np
import trimesh

from conftest import manager_of


def scene(seed):
    """Overlapping and separate parts, rotated and translated (placements that are not exact
    translations), some inside others."""
    rng = np.random.default_rng(seed)
    parts = []
    for k in range(8):
        mesh = trimesh.creation.icosphere(subdivisions=1, radius=0.5 + rng.random())
        t = trimesh.transformations.random_rotation_matrix(rng.random(3))
        t[:3, 3] = rng.random(3) * 4.0
        parts.append((f"p{k}", mesh, t))
    # A small part inside the first one: only containment decides that pair.
    parts.append(("inner", trimesh.creation.icosphere(subdivisions=1, radius=0.05), parts[0][2].copy()))
    return parts



def answers(m):
    names_all = m._native.names()
    d, names, data = m.min_distance_internal(return_names=True, return_data=True)
    hit, pairs = m.in_collision_internal(return_names=True)
    return (
        d,
        names,
        data.index(names[0]),
        data.index(names[1]),
        m.in_collision_internal(),
        hit,
        sorted(pairs),
        [m.min_distance_internal(name=n) for n in names_all],
    )


def test_setting_the_same_transform_keeps_the_answers_of_a_fresh_manager():
    for seed in range(3):
        parts = scene(seed)
        transforms = {name: t for name, _, t in parts}
        kept = manager_of(parts, transforms)
        expected = answers(manager_of(parts, transforms))
        assert answers(kept) == expected
        for _ in range(2):
            # The same transform, as a new array each time (the same bits).
            for name, t in transforms.items():
                kept.set_transform(name, np.array(t))
            assert answers(kept) == expected, seed
        # A zero of the other sign is other bits: that object is placed again; same answers.
        flipped = {name: np.where(t == 0.0, -0.0, t) for name, t in transforms.items()}
        for name, t in flipped.items():
            kept.set_transform(name, t)
        assert answers(kept) == answers(manager_of(parts, flipped)) == expected, seed


def test_moving_away_and_back_gives_the_answers_of_a_fresh_manager_at_each_step():
    parts = scene(7)
    transforms = {name: t for name, _, t in parts}
    kept = manager_of(parts, transforms)
    away = dict(transforms)
    shift = np.eye(4)
    shift[:3, 3] = [0.0, 0.0, 40.0]
    away["p0"] = shift @ transforms["p0"]
    for step in [transforms, away, away, transforms, transforms, away, transforms]:
        for name, t in step.items():
            kept.set_transform(name, t)
        assert answers(kept) == answers(manager_of(parts, step))
    # Both kinds of step answer differently (the first object's pairs change).
    assert answers(manager_of(parts, transforms)) != answers(manager_of(parts, away))
