#!/usr/bin/env python3
"""Benchmark (not a test): trimesh's CollisionManager scenes, meshclash against trimesh +
python-fcl in the same process, with same-run ratios.

    python python/bench_collision_manager.py [--repeat N] [--only spheres,cycloidal,engine,motion] [--cpu]

Scenes:
  spheres    1000 random icospheres (trimesh's test_random_spheres, seeded), via
             scene_to_collision: in_collision_internal, min_distance_internal.
  cycloidal  the cycloidal gearbox (trimesh's models/cycloidal.3DXML, from
             ../shared/trimesh-collision-tests/models), via scene_to_collision.
  engine     2CylinderEngine's parts (../shared/meshes/2CylinderEngine.glb) in world coordinates.
  motion     one icosphere moved by set_transform, then in_collision_single of a second mesh,
             1,000 steps (the time of the whole loop).
Each query: the median of --repeat runs. add_object: adding every object once. meshclash's
manager keeps pair answers until an object moves, so repeated queries on a still scene are
answered from them ("warm"); the "cold" rows first move every object to where it is
(set_transform with its own transform, not timed), so that every pair is decided again (meshclash
keeps an object's placement when its transform is the very same); the "cold, placed anew" rows
give each object its transform with the zeros' signs flipped every other run (the same place,
other bits), so that every object is placed again too.
--cpu times each run by the process's CPU time (all threads) instead of the wall clock: on a
loaded machine it is distorted less by waiting for a core.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
# This script sits beside the package's sources (python/meshclash, without the compiled
# module): import the installed package instead.
sys.path = [p for p in sys.path if Path(p or ".").resolve() != HERE]

import numpy as np  # noqa: E402
import trimesh  # noqa: E402
import trimesh.collision as tc  # noqa: E402

import meshclash  # noqa: E402

SHARED = HERE.parent.parent / "shared"
FCL = tc.CollisionManager
# The clock of every timed run (--cpu: process CPU time).
clock = time.perf_counter


def timed(f, repeat):
    times, result = [], None
    for _ in range(repeat):
        t0 = clock()
        result = f()
        times.append(clock() - t0)
    return statistics.median(times), result


def flipped(t):
    """`t` with every zero of the other sign: the same placement, other bits."""
    return np.where(t == 0.0, np.where(np.signbit(t), 0.0, -0.0), t)


def timed_cold(f, m, transforms, repeat, anew=False):
    """As timed, but before each run every object is moved to where it is (not timed). With
    `anew`, each run's transforms are the previous run's with every zero's sign flipped: the
    same places under other bits, so meshclash places every object again (given the very same
    transform, it keeps the placement and drops only the kept answers)."""
    times, result = [], None
    for k in range(repeat):
        for name, t in transforms.items():
            m.set_transform(name, flipped(t) if anew and k % 2 == 0 else t)
        t0 = clock()
        result = f()
        times.append(clock() - t0)
    return statistics.median(times), result


def from_scene(make, scene):
    """Every geometry node of the scene into a fresh manager (as scene_to_collision)."""
    t0 = clock()
    m = make()
    for node in scene.graph.nodes_geometry:
        t, geom = scene.graph[node]
        m.add_object(node, scene.geometry[geom], t)
    return m, clock() - t0


def spheres_scene():
    rng = np.random.default_rng(0)
    spheres = [trimesh.creation.icosphere(radius=r[0]).apply_translation(r[1:] * 100) for r in rng.random((1000, 4))]
    return trimesh.Scene(spheres)


def cycloidal_scene():
    path = SHARED / "trimesh-collision-tests" / "models" / "cycloidal.3DXML"
    if not path.exists():
        print(f"cycloidal: {path} is missing, skipped")
        return None
    return trimesh.load(str(path), force="scene")


def engine_scene():
    path = SHARED / "meshes" / "2CylinderEngine.glb"
    if not path.exists():
        print(f"engine: {path} is missing, skipped")
        return None
    scene = trimesh.load(str(path), force="scene", process=False)
    out = trimesh.Scene()
    for node in scene.graph.nodes_geometry:
        t, geom = scene.graph[node]
        m = scene.geometry[geom].copy()
        m.apply_transform(t)
        out.add_geometry(m, node_name=node, geom_name=node)
    return out


def describe(d):
    return f"{d:.6g}" if isinstance(d, float) else repr(d)


def scene_rows(label, scene, repeat):
    rows = []
    managers = {}
    for name, make in [("meshclash", meshclash.CollisionManager), ("fcl", FCL)]:
        managers[name], add = from_scene(make, scene)
        rows.append((label, "add_object (all)", name, add, None))
    queries = [
        ("in_collision_internal()", lambda m: m.in_collision_internal()),
        ("in_collision_internal(names)", lambda m: len(m.in_collision_internal(return_names=True)[1])),
        ("min_distance_internal()", lambda m: m.min_distance_internal()),
    ]
    transforms = {node: scene.graph[node][0] for node in scene.graph.nodes_geometry}
    for q, f in queries:
        for name, m in managers.items():
            t, r = timed_cold(lambda: f(m), m, transforms, repeat)
            rows.append((label, q + " cold", name, t, r))
            t, r = timed_cold(lambda: f(m), m, transforms, repeat, anew=True)
            rows.append((label, q + " cold, placed anew", name, t, r))
            t, r = timed(lambda: f(m), repeat)
            rows.append((label, q, name, t, r))
    return rows


def motion_rows(repeat, steps=1000):
    mover = trimesh.creation.icosphere(radius=1.0)
    probe = trimesh.creation.icosphere(radius=1.0)
    rng = np.random.default_rng(1)
    paths = rng.random((steps, 3)) * 6.0 - 3.0
    rows = []
    for name, make in [("meshclash", meshclash.CollisionManager), ("fcl", FCL)]:
        m = make()
        m.add_object("mover", mover)
        for k in range(20):
            m.add_object(f"fixed{k}", trimesh.creation.icosphere(radius=0.5).apply_translation([k * 3.0 - 30, 4, 0]))

        def loop():
            hits = 0
            for p in paths:
                t = np.eye(4)
                t[:3, 3] = p
                m.set_transform("mover", t)
                hits += m.in_collision_single(probe)
            return hits

        t, r = timed(loop, repeat)
        rows.append(("motion", f"{steps} x (set_transform + in_collision_single)", name, t, r))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--only", default="spheres,cycloidal,engine,motion")
    ap.add_argument("--cpu", action="store_true", help="time by process CPU time, not wall-clock time")
    args = ap.parse_args()
    if args.cpu:
        global clock
        clock = time.process_time
    only = set(args.only.split(","))
    rows = []
    for label, make in [("spheres", spheres_scene), ("cycloidal", cycloidal_scene), ("engine", engine_scene)]:
        if label in only:
            scene = make()
            if scene is not None:
                print(f"{label}: {len(scene.graph.nodes_geometry)} objects", flush=True)
                rows += scene_rows(label, scene, args.repeat)
    if "motion" in only:
        rows += motion_rows(max(1, args.repeat // 2))
    kind = "process CPU time" if args.cpu else "wall-clock time"
    print(f"\n{kind}, median of {args.repeat} runs; ratio = trimesh+FCL time / meshclash time (same run)\n")
    print(f"| scene | query | meshclash | trimesh + FCL | ratio | answers (meshclash / FCL) |")
    print("|---|---|---|---|---|---|")
    by = {}
    for label, q, name, t, r in rows:
        by.setdefault((label, q), {})[name] = (t, r)
    for (label, q), v in by.items():
        (tm, rm), (tf, rf) = v["meshclash"], v["fcl"]
        print(
            f"| {label} | {q} | {tm * 1e3:.3f} ms | {tf * 1e3:.3f} ms | {tf / tm:.1f}x | "
            f"{describe(rm)} / {describe(rf)} |"
        )


if __name__ == "__main__":
    main()
