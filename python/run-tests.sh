#!/usr/bin/env bash
# Python tests of the meshclash package, on a fresh machine:
#   1. finds the CLI the tests compare the package with: $MESHCLASH_BIN (.ci/test passes the one
#      its Rust tests just built), else builds target/debug/meshclash;
#   2. creates a venv (python/.venv, or $MESHCLASH_VENV) and installs maturin, numpy, pytest,
#      trimesh, python-fcl, scipy, networkx, lxml and pillow (trimesh's .3DXML loader, for its
#      own collision tests in tests/trimesh_compat) and mypy (the stubs' check) from the
#      package registry;
#   3. installs the package with the one install command, `pip install ./python`, its extension
#      built in the dev profile (`cargo rustc --profile test` would build a test harness) in the
#      same target directory as the Rust tests: python/ is a
#      member of the root workspace, so the library and its dependencies compiled for the tests
#      and the CLI are reused, not compiled again ($MESHCLASH_PY_PROFILE=release for a release
#      build);
#   4. runs pytest on python/tests. Exits non-zero on any failure.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/.." && pwd)"
py="${PYTHON:-python3}"
venv="${MESHCLASH_VENV:-$here/.venv}"
profile="${MESHCLASH_PY_PROFILE:-dev}"

target="${CARGO_TARGET_DIR:-$repo/target}"
case "$target" in /*) ;; *) target="$repo/$target" ;; esac
if [ -z "${MESHCLASH_BIN:-}" ]; then
    # target/debug/meshclash: the dev and test profiles build the product crate alike (Cargo.toml),
    # so this is the binary `cargo test` builds for the integration tests; after one, nothing
    # compiles.
    (cd "$repo" && cargo build --quiet --bin meshclash)
    export MESHCLASH_BIN="$target/debug/meshclash"
fi
[ -x "$MESHCLASH_BIN" ] || { echo "python/run-tests.sh: MESHCLASH_BIN=$MESHCLASH_BIN is not an executable" >&2; exit 2; }

if [ ! -x "$venv/bin/python" ]; then
    "$py" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet maturin numpy pytest trimesh python-fcl scipy networkx lxml pillow mypy pyright
# The one install command (from the repository root), without build isolation (the venv's
# maturin, found on PATH), the extension in $profile.
cd "$repo"
PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$target" MATURIN_PEP517_ARGS="--profile $profile" \
    "$venv/bin/python" -m pip install --quiet --no-build-isolation --force-reinstall --no-deps ./python
cd "$here"
# -p no:cacheprovider: leave no .pytest_cache in the tree.
"$venv/bin/pytest" -p no:cacheprovider -q tests "$@"
