#!/usr/bin/env python3
"""Same-run peers for `meshclash-bench cases`: trueform (C++/TBB, f64) and python-fcl (FCL's
OBBRSS trees) on the two-file cases of a directory written by `meshclash-bench gen`.

    python3 bench/peers.py DIR [--only spheres,tori-crossing,...] [--reps 3] [--json]

Each peer runs only when it is importable (`pip install trueform python-fcl trimesh numpy`);
a missing one is reported, not an error. Per case and peer (wall clock, ms, best of --reps for
the queries; loads and builds once): **load** (trueform's own OBJ reader; GLB through trimesh,
which both peers then share), **build** (trueform: `Mesh` construction and its lazy tree, forced
by the first query; FCL: both `BVHModel`s), **pairs** (trueform: `gather_intersecting_ids`, every
intersecting triangle pair; FCL: `collide` with every contact), **intersects** (the yes/no
query), **distance** (0 when they meet). `meshclash-bench cases --peers PYTHON` runs this with
`--json` and checks each peer's answers against its own.
"""
import argparse
import json
import sys
import time

CASES = {
    "spheres": ("spheres_a.obj", "spheres_b.obj"),
    "tori-crossing": ("torus_a.glb", "torus_b_crossing.glb"),
    "tori-apart": ("torus_a.glb", "torus_b_apart.glb"),
    "tori-linked": ("torus_a.glb", "torus_b_linked.glb"),
}


def timed(reps, f):
    out, best = None, float("inf")
    for _ in range(reps):
        t = time.perf_counter()
        out = f()
        best = min(best, (time.perf_counter() - t) * 1e3)
    return out, best


def load_arrays(path):
    """(faces int32 (N, 3), points float64 (P, 3)), ms."""
    import numpy as np

    t = time.perf_counter()
    if path.endswith(".obj"):
        try:
            import trueform as tf

            faces, points = tf.read_obj(path, ngon=3, dtype=np.float64)
            return (np.asarray(faces, dtype=np.int32), np.asarray(points)), (time.perf_counter() - t) * 1e3
        except ImportError:
            pass
    import trimesh

    m = trimesh.load(path, force="mesh", process=False)
    arrays = (np.asarray(m.faces, dtype=np.int32), np.asarray(m.vertices, dtype=np.float64))
    return arrays, (time.perf_counter() - t) * 1e3


def run_trueform(a, b, load_ms, reps):
    import trueform as tf

    def fresh():
        return tf.Mesh(*a), tf.Mesh(*b)

    # Build: construction plus the lazy trees the first query makes.
    t = time.perf_counter()
    ma, mb = fresh()
    hit = bool(tf.intersects(ma, mb))
    first_ms = (time.perf_counter() - t) * 1e3
    hit, intersects_ms = timed(reps, lambda: bool(tf.intersects(ma, mb)))
    ids, pairs_ms = timed(reps, lambda: tf.gather_intersecting_ids(ma, mb))
    d, distance_ms = timed(reps, lambda: float(tf.distance(ma, mb)))
    return {
        "tool": f"trueform {tf.__version__}",
        "load_ms": load_ms,
        "build_ms": max(first_ms - intersects_ms, 0.0),
        "intersects_ms": intersects_ms,
        "pairs_ms": pairs_ms,
        "distance_ms": distance_ms,
        "intersects": hit,
        "pairs": int(len(ids)),
        "distance": d,
    }


def run_fcl(a, b, load_ms, reps):
    import fcl

    def model(faces, points):
        m = fcl.BVHModel()
        m.beginModel(len(points), len(faces))
        m.addSubModel(points, faces)
        m.endModel()
        return fcl.CollisionObject(m, fcl.Transform())

    t = time.perf_counter()
    oa, ob = model(*a), model(*b)
    build_ms = (time.perf_counter() - t) * 1e3
    one = fcl.CollisionRequest(num_max_contacts=1, enable_contact=False)
    hit, intersects_ms = timed(reps, lambda: fcl.collide(oa, ob, one, fcl.CollisionResult()) > 0)
    every = fcl.CollisionRequest(num_max_contacts=1 << 30, enable_contact=True)
    n, pairs_ms = timed(reps, lambda: fcl.collide(oa, ob, every, fcl.CollisionResult()))
    dreq = fcl.DistanceRequest(enable_nearest_points=True)
    d, distance_ms = timed(reps, lambda: fcl.distance(oa, ob, dreq, fcl.DistanceResult()))
    return {
        "tool": f"python-fcl {getattr(fcl, '__version__', '?')}",
        "load_ms": load_ms,
        "build_ms": build_ms,
        "intersects_ms": intersects_ms,
        "pairs_ms": pairs_ms,
        "distance_ms": distance_ms,
        "intersects": bool(hit),
        "pairs": int(n),
        "distance": max(float(d), 0.0),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", help="directory written by `meshclash-bench gen`")
    ap.add_argument("--only", help="comma-separated cases (default: every case whose files exist)")
    ap.add_argument("--reps", type=int, default=3, help="query runs, best kept (default 3)")
    ap.add_argument("--json", action="store_true", help="one JSON document instead of a table")
    args = ap.parse_args()
    import os

    names = [c.strip() for c in args.only.split(",")] if args.only else list(CASES)
    names = [c for c in names if c in CASES]
    peers = []
    for module, runner in [("trueform", run_trueform), ("fcl", run_fcl)]:
        try:
            __import__(module)
            peers.append(runner)
        except ImportError:
            print(f"peers.py: {module} is not importable; skipped", file=sys.stderr)
    results = []
    for name in names:
        paths = [os.path.join(args.dir, f) for f in CASES[name]]
        if not all(os.path.isfile(p) for p in paths):
            continue
        (a, la), (b, lb) = load_arrays(paths[0]), load_arrays(paths[1])
        for run in peers:
            try:
                r = run(a, b, la + lb, args.reps)
            except Exception as e:  # a peer that fails is reported, not fatal
                r = {"tool": run.__name__[4:], "error": str(e)}
            r["case"] = name
            results.append(r)
    if args.json:
        json.dump({"results": results}, sys.stdout, indent=1)
        print()
        return 0
    print("| case | tool | load ms | build ms | intersects ms | pairs ms | distance ms | pairs | distance |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        if "error" in r:
            print(f"| {r['case']} | {r['tool']} | error: {r['error']} |||||||")
            continue
        print(f"| {r['case']} | {r['tool']} | {r['load_ms']:.0f} | {r['build_ms']:.0f} | "
              f"{r['intersects_ms']:.1f} | {r['pairs_ms']:.1f} | {r['distance_ms']:.1f} | "
              f"{r['pairs']} | {r['distance']:.12g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
