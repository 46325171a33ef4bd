"""Run trimesh's collision tests against meshclash: trimesh.collision.CollisionManager (which
trimesh's scene_to_collision looks up at call time) becomes meshclash.CollisionManager."""

import pytest

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("fcl")  # the tests skip themselves without python-fcl: require it

import meshclash  # noqa: E402
import trimesh.collision  # noqa: E402

trimesh.collision.CollisionManager = meshclash.CollisionManager
