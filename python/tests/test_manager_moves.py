"""meshclash.CollisionManager: yes/no answers while objects move, against the exact answer of a
fresh manager at every step (a manager keeps hints from earlier queries; only speed may depend
on them)."""

import numpy as np

import meshclash
from conftest import box


def at(x, y=0.0, z=0.0):
    t = np.eye(4)
    t[:3, 3] = [x, y, z]
    return t


def test_yes_no_answers_follow_the_moves():
    cube = box()
    steps = [0.5, 3.0, 0.25, 1.0, 1.0 + 2.0**-40, 0.75, 5.0, 0.0]
    kept = meshclash.CollisionManager()
    kept.add_object("a", cube, transform=at(0.0))
    kept.add_object("b", cube, transform=at(steps[0]))
    answers = []
    for x in steps:
        kept.set_transform("b", at(x, 0.125))
        fresh = meshclash.CollisionManager()
        fresh.add_object("a", cube, transform=at(0.0))
        fresh.add_object("b", cube, transform=at(x, 0.125))
        # The names query decides every pair (no hints): the reference.
        expected = len(fresh.in_collision_internal(return_names=True)[1]) > 0
        assert kept.in_collision_internal() == expected, x
        assert fresh.in_collision_internal() == expected, x
        answers.append(expected)
    # Both outcomes occur, and a colliding step follows a separated one and vice versa.
    assert answers == [True, False, True, True, False, True, False, True]
