#!/usr/bin/env bash
# Python tests of the meshclash package, on a fresh machine:
#   1. builds the release CLI (the tests compare the package's documents with its output),
#   2. creates a venv (python/.venv, or $MESHCLASH_VENV) and installs maturin, numpy, pytest,
#      trimesh, python-fcl, scipy, networkx, lxml and pillow (trimesh's .3DXML loader, for its
#      own collision tests in tests/trimesh_compat) and mypy (the stubs' check) from the
#      package registry,
#   3. installs the package with the one install command, `pip install ./python`,
#   4. runs pytest on python/tests. Exits non-zero on any failure.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/.." && pwd)"
py="${PYTHON:-python3}"
venv="${MESHCLASH_VENV:-$here/.venv}"

(cd "$repo" && cargo build --release --quiet --bin meshclash)
target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in /*) ;; *) target="$repo/$target" ;; esac
export MESHCLASH_BIN="$target/release/meshclash"

if [ ! -x "$venv/bin/python" ]; then
    "$py" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet maturin numpy pytest trimesh python-fcl scipy networkx lxml pillow mypy
# The one install command (from the repository root). The extension builds in the CLI's target
# directory by default, so the library and its dependencies compiled for the CLI above are
# reused ($MESHCLASH_PY_TARGET to build elsewhere).
cd "$repo"
CARGO_TARGET_DIR="${MESHCLASH_PY_TARGET:-$target}" "$venv/bin/python" -m pip install --quiet --force-reinstall --no-deps ./python
cd "$here"
# -p no:cacheprovider: leave no .pytest_cache in the tree.
"$venv/bin/pytest" -p no:cacheprovider -q tests "$@"
