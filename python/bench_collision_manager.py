#!/usr/bin/env python3
"""Benchmark (not a test): CollisionManager.in_collision_internal and min_distance_internal on
2CylinderEngine's parts, meshclash against trimesh + python-fcl, in the same run.

    python python/bench_collision_manager.py [path/to/2CylinderEngine.glb] [--repeat N]

Both managers get the same parts, in world coordinates (float64 vertices; identity
transforms, so trimesh's float32 cast of transforms plays no part). Prints the median time of
each query for both, and the ratio. The verdicts are printed too: on this assembly they may
differ where parts only touch or one lies inside another (see meshclash.collision's docstring).
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

import meshclash  # noqa: E402
import trimesh  # noqa: E402
from trimesh.collision import CollisionManager as FclManager  # noqa: E402
DEFAULT = HERE.parent.parent / "shared" / "meshes" / "2CylinderEngine.glb"


def parts(path):
    scene = trimesh.load(path, force="scene", process=False)
    out = {}
    for node in scene.graph.nodes_geometry:
        t, geom = scene.graph[node]
        m = scene.geometry[geom].copy()
        m.apply_transform(t)
        out[node] = m
    return out


def timed(f, repeat):
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("path", nargs="?", default=str(DEFAULT))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument(
        "--explode",
        type=float,
        default=0.0,
        help="move each part away from the assembly's centre by this factor times its offset "
        "(parts of the engine touch, so min_distance_internal is 0 without it)",
    )
    args = ap.parse_args()
    meshes = parts(args.path)
    if args.explode:
        centre = sum(m.bounds.mean(axis=0) for m in meshes.values()) / len(meshes)
        for m in meshes.values():
            m.apply_translation((m.bounds.mean(axis=0) - centre) * args.explode)
    tris = sum(len(m.faces) for m in meshes.values())
    print(f"{args.path}: {len(meshes)} parts, {tris} triangles; median of {args.repeat} runs")

    rows = []
    for label, make in [("meshclash", meshclash.CollisionManager), ("trimesh+fcl", FclManager)]:
        t0 = time.perf_counter()
        m = make()
        for name, mesh in meshes.items():
            m.add_object(name, mesh)
        add = time.perf_counter() - t0
        t_any, hit = timed(m.in_collision_internal, args.repeat)
        t_names, (_, names) = timed(lambda: m.in_collision_internal(return_names=True), args.repeat)
        t_dist, d = timed(m.min_distance_internal, args.repeat)
        rows.append((label, add, t_any, t_names, t_dist, hit, len(names), d))

    print(f"{'':12} {'add_object':>11} {'in_collision':>13} {'  +names':>10} {'min_distance':>13}   answers")
    for label, add, t_any, t_names, t_dist, hit, n, d in rows:
        print(
            f"{label:12} {add * 1e3:9.1f}ms {t_any * 1e3:11.2f}ms {t_names * 1e3:8.2f}ms {t_dist * 1e3:11.2f}ms"
            f"   collision={hit} pairs={n} min_distance={d:.6g}"
        )
    (_, add_m, any_m, names_m, dist_m, *_), (_, add_f, any_f, names_f, dist_f, *_) = rows
    print(
        f"speed-up (trimesh+fcl time / meshclash time): in_collision_internal {any_f / any_m:.1f}x, "
        f"with return_names {names_f / names_m:.1f}x, min_distance_internal {dist_f / dist_m:.1f}x, "
        f"add_object (all parts) {add_f / add_m:.1f}x"
    )


if __name__ == "__main__":
    main()
