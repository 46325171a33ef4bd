#!/bin/sh
# Browser test of the HTML report: generate reports from the shipped meshes with the
# meshclash binary, load each from disk in headless Chromium (Debian package `chromium`; Node.js
# runs the driver, no npm package needed), screenshot the overview and the first clash, and
# assert the clash colours are in the frame, no network request was made and the console has no
# error. Exit non-zero on the first failure.
#
#   tests/browser/run.sh                 # screenshots in a temporary directory
#   tests/browser/run.sh --update-docs   # also copy the screenshots README shows to docs/img/
#
# Environment: CHROMIUM (default /usr/bin/chromium), CARGO_TARGET_DIR (default target),
# MESHCLASH or MESHCLASH_BIN (a binary to use instead of building one; .ci/test passes the one its
# Rust tests built). Without either, target/debug/meshclash is built (the dev and test profiles
# build it alike, so after a `cargo test` nothing compiles).
set -eu
cd "$(dirname "$0")/../.."
update_docs=0
[ "${1:-}" = "--update-docs" ] && update_docs=1

command -v node >/dev/null || { echo "tests/browser/run.sh: node not found (apt-get install nodejs)" >&2; exit 2; }
[ -x "${CHROMIUM:-/usr/bin/chromium}" ] || { echo "tests/browser/run.sh: chromium not found (apt-get install chromium)" >&2; exit 2; }
MESHCLASH="${MESHCLASH:-${MESHCLASH_BIN:-}}"
if [ -z "$MESHCLASH" ]; then
  cargo build --quiet --bin meshclash
  MESHCLASH="${CARGO_TARGET_DIR:-target}/debug/meshclash"
fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
shots="$out/shots"
mkdir -p "$shots"

# check NAME ROWS -- meshclash arguments...   (ROWS: expected table rows, or - for any; when TEXT
# is set, the clash table must show it)
pages=0
TEXT=
check() {
  name=$1; rows=$2; shift 3
  pages=$((pages + 1))
  set +e
  "$MESHCLASH" "$@" -q --no-timings --html "$out/$name.html" -o "$out/$name.json"
  code=$?
  set -e
  [ "$code" -le 1 ] || { echo "meshclash failed on $name (exit $code)" >&2; exit 1; }
  if [ "$rows" = "-" ]; then
    node tests/browser/driver.mjs "$out/$name.html" "$shots/$name-overview.png" "$shots/$name-clash.png" ${TEXT:+--text} ${TEXT:+"$TEXT"}
  else
    node tests/browser/driver.mjs "$out/$name.html" "$shots/$name-overview.png" "$shots/$name-clash.png" --rows "$rows" ${TEXT:+--text} ${TEXT:+"$TEXT"}
  fi
}

check fcl 1 -- meshes/fcl_env.obj meshes/fcl_rob.obj
check pins 6 -- scene meshes/pins.glb
check pins-apart 1 -- meshes/pins.glb meshes/pins.glb --translate-b 300,0,0
# Two unit cubes overlapping by 0.75: an exact convex depth, labelled so.
TEXT='depth 0.75 (exact)'
check cubes-exact 1 -- meshes/Box.glb meshes/Box.glb --translate-b 0.25,0,0 --penetration
TEXT=
if [ -f ../shared/meshes/2CylinderEngine.glb ]; then
  # No engine part is convex: its depths are sampled lower bounds.
  TEXT='depth ≥'
  check engine - -- scene ../shared/meshes/2CylinderEngine.glb --penetration
  TEXT=
fi
# `meshclash self` pages: a strip folded back through itself (tests/glb.rs: 2 crossing and 2
# touching pairs, inconsistent winding, open), and the robot (self-touching, non-manifold, open).
printf 'o strip\nv 0 0 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 1 0 1\nv 1 1 1\nv 1 0 -1\nv 1 1 -1\nf 1 3 4\nf 1 4 2\nf 3 5 6\nf 3 6 4\nf 5 6 8\nf 5 8 7\n' >"$out/strip.obj"
check self-strip 3 -- self "$out/strip.obj"
check self-rob 3 -- self meshes/fcl_rob.obj --fail-on never

# --export-glb: each GLB drawn through its own cameras by a viewer of our own
# (tests/browser/glb_viewer.html): both tints on white and on dark, the first clash in view.
glb() {
  name=$1; shift 2
  pages=$((pages + 1))
  set +e
  "$MESHCLASH" "$@" -q --no-timings --export-glb "$out/$name.glb" -o "$out/$name-glb.json"
  code=$?
  set -e
  [ "$code" -le 1 ] || { echo "meshclash failed on $name (exit $code)" >&2; exit 1; }
  node tests/browser/driver.mjs --glb "$out/$name.glb" "$shots/$name-glb-overview.png" "$shots/$name-glb-clash.png"
}
glb fcl -- meshes/fcl_env.obj meshes/fcl_rob.obj
glb pins -- scene meshes/pins.glb
glb self-strip -- self "$out/strip.obj"
if [ -f ../shared/meshes/2CylinderEngine.glb ]; then
  glb engine -- scene ../shared/meshes/2CylinderEngine.glb
fi

if [ "$update_docs" = 1 ]; then
  mkdir -p docs/img
  for f in fcl-clash pins-clash engine-clash self-strip-clash self-rob-clash engine-glb-overview-dark engine-glb-clash; do
    case $f in *-glb-*) dest=docs/img/$f.png ;; *) dest=docs/img/html-$f.png ;; esac
    [ -f "$shots/$f.png" ] && cp "$shots/$f.png" "$dest"
  done
  echo "screenshots copied to docs/img/"
fi
echo "browser: $pages passed, 0 failed"
