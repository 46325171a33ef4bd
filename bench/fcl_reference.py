#!/usr/bin/env python3
"""python-fcl (FCL's OBBRSS trees) on the benchmark tori, as an outside reference for meshclash.

Setup (once):   python3 -m venv /tmp/fcl-venv
                /tmp/fcl-venv/bin/pip install python-fcl trimesh numpy
Inputs:         cargo run --release -p meshclash-bench -- gen /tmp/cases
Run:            /tmp/fcl-venv/bin/python bench/fcl_reference.py /tmp/cases [--repeat 3]

For torus A against B linked and B crossing (and B apart) it times, separately: building each
BVHModel (OBBRSS), one `fcl.collide` (stop at the first contact) and one `fcl.distance` (with
nearest points). Query times are the best of --repeat runs; builds are timed once each. FCL's
distance is an f64 GJK/closed-form distance on the f32 input (rounded exactly to f64), so it
should agree with meshclash's exact minimum to about 1e-12 on these well-shaped triangles.
"""

import argparse
import sys
import time

import fcl
import numpy as np
import trimesh


def load(path):
    m = trimesh.load(path, force="mesh", process=False)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int32)


def build(vertices, faces):
    t = time.perf_counter()
    model = fcl.BVHModel()
    model.beginModel(len(vertices), len(faces))
    model.addSubModel(vertices, faces)
    model.endModel()
    obj = fcl.CollisionObject(model, fcl.Transform())
    return obj, (time.perf_counter() - t) * 1e3


def best(repeat, f):
    out, ms = None, float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        ms = min(ms, (time.perf_counter() - t) * 1e3)
    return out, ms


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", help="directory written by `meshclash-bench gen`")
    ap.add_argument("--repeat", type=int, default=3, help="query runs, best kept (default 3)")
    args = ap.parse_args()

    va, fa = load(f"{args.dir}/torus_a.glb")
    print(f"python-fcl {getattr(fcl, '__version__', '?')}, trimesh {trimesh.__version__}, "
          f"numpy {np.__version__}; torus A: {len(fa)} triangles")
    print("| case | build A ms | build B ms | collide ms | distance ms | collides | distance |")
    print("|---|---|---|---|---|---|---|")
    for name in ["linked", "crossing", "apart"]:
        vb, fb = load(f"{args.dir}/torus_b_{name}.glb")
        a, build_a = build(va, fa)
        b, build_b = build(vb, fb)
        creq = fcl.CollisionRequest(num_max_contacts=1, enable_contact=False)
        hit, collide_ms = best(args.repeat, lambda: fcl.collide(a, b, creq, fcl.CollisionResult()))
        dreq = fcl.DistanceRequest(enable_nearest_points=True)
        d, distance_ms = best(args.repeat, lambda: fcl.distance(a, b, dreq, fcl.DistanceResult()))
        print(f"| tori {name} | {build_a:.0f} | {build_b:.0f} | {collide_ms:.1f} | "
              f"{distance_ms:.1f} | {bool(hit)} | {d:.12f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
