"""Shared fixtures: where the repository, its meshes, the shared corpus and the CLI binary are."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
MESHES = REPO / "meshes"
SHARED = REPO.parent / "shared" / "meshes"


def cli_binary() -> Path:
    """The meshclash CLI built from this repository, in any profile (the tests compare documents,
    not speed): $MESHCLASH_BIN (run-tests.sh sets it; .ci/test passes the test-profile binary its
    Rust tests built), else target/debug/meshclash or target/release/meshclash under
    $CARGO_TARGET_DIR or target/."""
    env = os.environ.get("MESHCLASH_BIN")
    if env:
        return Path(env)
    tgt = os.environ.get("CARGO_TARGET_DIR")
    for base in ([Path(tgt)] if tgt else []) + [REPO / "target"]:
        for profile in ("debug", "release"):
            p = base / profile / "meshclash"
            if p.exists():
                return p
    pytest.fail(
        "the meshclash CLI is missing: set MESHCLASH_BIN to a meshclash binary built from this "
        "repository, or run python/run-tests.sh (it builds one)"
    )


def run_cli(*args, expect=(0, 1)):
    """Run the CLI; return (exit code, parsed JSON stdout or None, stderr)."""
    p = subprocess.run([str(cli_binary()), *map(str, args)], capture_output=True, text=True)
    assert p.returncode in expect, (p.returncode, p.stderr)
    doc = json.loads(p.stdout) if p.returncode in (0, 1) and p.stdout.strip() else None
    return p.returncode, doc, p.stderr


def shared(name: str) -> Path:
    """A test mesh: the repository's own copy first (meshes/, tests/data/meshes/), then the corpus
    ($MESHCLASH_SHARED_MESHES or ../shared/meshes). Skips, saying why, when it is nowhere; with CI
    set and the corpus present, a missing file fails instead."""
    repo = Path(__file__).resolve().parents[2]
    corpus = Path(os.environ.get("MESHCLASH_SHARED_MESHES", SHARED))
    for d in (repo / "meshes", repo / "tests" / "data" / "meshes", corpus):
        if (d / name).exists():
            return d / name
    if os.environ.get("CI") and corpus.is_dir():
        pytest.fail(f"{name} is missing from the corpus at {corpus}")
    pytest.skip(f"test mesh {name} not found (set MESHCLASH_SHARED_MESHES to the corpus)")


def write_obj(path: Path, vertices, faces, name: str):
    """An OBJ with one object `name` holding exactly these coordinates (repr round-trips f64)."""
    lines = [f"o {name}"]
    lines += [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in np.asarray(vertices, dtype=np.float64)]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces, dtype=np.int64)]
    path.write_text("\n".join(lines) + "\n")
    return path


def box(lo=(0.0, 0.0, 0.0), hi=(1.0, 1.0, 1.0)):
    """An axis-aligned closed box, outward-facing triangles."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    v = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]] for i in range(8)])
    f = np.array(
        [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
         [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]],
        dtype=np.int64,
    )
    return v, f


def l_prism(scale=1.0, at=(0.0, 0.0, 0.0)):
    """A closed L-shaped prism (non-convex, so trimesh hands it to FCL as a BVH mesh, not as a
    convex solid): the L (0,0)-(2,0)-(2,1)-(1,1)-(1,2)-(0,2) extruded over z in [0, 1]."""
    outline = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=np.float64)
    n = len(outline)
    v = np.vstack([np.c_[outline, np.zeros(n)], np.c_[outline, np.ones(n)]]) * scale + np.asarray(at, dtype=np.float64)
    # Caps: fan triangulation of the L is valid from vertex 3 (the reflex corner).
    cap = [[3, 4, 5], [3, 5, 0], [3, 0, 1], [3, 1, 2]]
    f = [[c, b, a] for a, b, c in cap] + [[a + n, b + n, c + n] for a, b, c in cap]
    for i in range(n):
        j = (i + 1) % n
        f += [[i, j, j + n], [i, j + n, i + n]]
    return v, np.array(f, dtype=np.int64)


def manager_of(parts, transforms):
    """A new meshclash manager holding `parts` ((name, mesh, transform) triples) placed by
    `transforms` (name -> 4x4): the reference that decides every pair from scratch."""
    import meshclash

    m = meshclash.CollisionManager()
    for name, mesh, _ in parts:
        m.add_object(name, mesh, transforms[name])
    return m


def flipped(t):
    """`t` with every zero of the other sign: the same placement under other bits."""
    return np.where(t == 0.0, np.where(np.signbit(t), 0.0, -0.0), t)
