#!/usr/bin/env bash
# Shard a check on one machine: plan, N shards as background processes, merge.
# The same three commands any batch engine runs; useful to try a plan out, or to split a
# check over processes with separate memory.
#
#   deploy/local.sh N DIR -- CHECK ARGUMENTS...
#   e.g. deploy/local.sh 4 out -- scene site.glb --clearance 10 --no-timings
#
# Writes DIR/plan.json, DIR/shard-I.json, DIR/report.json and DIR/report.xml (JUnit); exits with
# the merge's code
# (0 clear, 1 findings at or above --fail-on, 2 error). MESHCLASH overrides the binary.
# MESHCLASH_CACHE=DIR gives every shard one shared result cache: a re-run checks only the part
# pairs whose parts or settings changed (entries are written by rename and verified on read, so
# concurrent shards may share the directory).
set -uo pipefail
exe=${MESHCLASH:-meshclash}
n=${1:?usage: local.sh N DIR -- CHECK ARGUMENTS...}
dir=${2:?usage: local.sh N DIR -- CHECK ARGUMENTS...}
shift 2
[ "${1:-}" = "--" ] && shift
mkdir -p "$dir"
"$exe" plan "$@" -o "$dir/plan.json" || exit 2
pids=()
for i in $(seq "$n"); do
    "$exe" run --plan "$dir/plan.json" --shard "$i/$n" -o "$dir/shard-$i.json" -q &
    pids+=($!)
done
failed=0
for p in "${pids[@]}"; do
    wait "$p" || failed=1
done
# A failed shard wrote a report saying so: the merge names it (exit 2).
[ $failed = 0 ] || echo "local.sh: a shard failed; the merge names it" >&2
shards=()
for i in $(seq "$n"); do shards+=("$dir/shard-$i.json"); done
"$exe" merge "${shards[@]}" --junit "$dir/report.xml" -o "$dir/report.json"
