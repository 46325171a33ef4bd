"""Time trueform's self-intersection on an OBJ (the same file `meshclash self` reads), for a
same-run ratio with `meshclash-bench self`.

    python3 bench/trueform_self.py FILE.obj [--reps 3]

Needs `pip install trueform numpy`. Times (wall clock, best of the runs, ms): reading the OBJ
(trueform's reader, f64, not in the ratios), then on a fresh `Mesh(...)` each (so its lazy
tree and topology builds are counted, as meshclash's tree and merge are) `has_self_intersections` (stops at the first contact) and
`self_intersection_curves` (every self-intersection curve, exact, the full answer), then
`self_intersection_curves` again on a warm mesh (its tree and topology already built), and the CPU
time of the process over each timed call (user + system, all threads).
"""
import argparse
import resource
import time


def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def timed(reps, f):
    best_wall, best_cpu, out = float("inf"), float("inf"), None
    for _ in range(reps):
        c, t = cpu(), time.perf_counter()
        out = f()
        best_wall = min(best_wall, time.perf_counter() - t)
        best_cpu = min(best_cpu, cpu() - c)
    return out, best_wall * 1e3, best_cpu * 1e3


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("file")
    ap.add_argument("--reps", type=int, default=3)
    a = ap.parse_args()
    import numpy as np
    import trueform as tf

    (faces, points), load_ms, _ = timed(1, lambda: tf.read_obj(a.file, ngon=3, dtype=np.float64))
    print(f"trueform {tf.__version__}: {len(faces)} triangles, read {load_ms:.1f} ms")

    def fresh():
        return tf.Mesh(faces, points)

    # Each timed call gets a fresh Mesh, so its lazy tree/topology builds are counted.
    def has():
        return tf.has_self_intersections(fresh())

    def curves():
        return tf.self_intersection_curves(fresh())

    v, has_ms, has_cpu = timed(a.reps, has)
    c, cur_ms, cur_cpu = timed(a.reps, curves)
    paths = c[0] if isinstance(c, tuple) else c
    try:
        n_paths = len(paths)
    except TypeError:
        n_paths = "?"
    print(f"has_self_intersections (fresh mesh, stops at the first contact): {v}, "
          f"{has_ms:.1f} ms wall, {has_cpu:.0f} ms CPU")
    print(f"self_intersection_curves (fresh mesh, every curve): {n_paths} paths, "
          f"{cur_ms:.1f} ms wall, {cur_cpu:.0f} ms CPU")
    # The same calls on one mesh whose lazy structures the first call built (query only).
    warm = fresh()
    tf.self_intersection_curves(warm)
    _, wcur_ms, wcur_cpu = timed(a.reps, lambda: tf.self_intersection_curves(warm))
    print(f"self_intersection_curves (warm mesh: tree and topology already built): "
          f"{wcur_ms:.1f} ms wall, {wcur_cpu:.0f} ms CPU")


if __name__ == "__main__":
    main()
