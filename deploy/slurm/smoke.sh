#!/usr/bin/env bash
# Slurm smoke test: bring up a one-node Slurm cluster on this machine (munge,
# slurmctld, slurmd; Debian's `slurm-wlm`, run as root), submit the plan's shards as a job
# array (deploy/slurm/meshclash-array.sbatch), merge after the array with a dependent job,
# and compare the merged report with the single-machine run byte for byte.
#
#   sudo apt-get install slurm-wlm            # once
#   sudo deploy/slurm/smoke.sh [MESHCLASH] [SCENE.glb] [N]
#
# Everything (config, state, logs, outputs) lives in a temporary directory; the daemons it
# started are stopped on exit.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exe=$(realpath "${1:-$here/../../target/release/meshclash}")
scene=$(realpath "${2:-$here/../../../shared/meshes/2CylinderEngine.glb}")
n=${3:-4}
[ "$(id -u)" = 0 ] || { echo "smoke.sh: run as root (slurmd and munged)" >&2; exit 2; }
for t in munged slurmctld slurmd sbatch squeue; do
    command -v $t >/dev/null || { echo "smoke.sh: $t missing: apt-get install slurm-wlm" >&2; exit 2; }
done
work=$(mktemp -d /tmp/meshclash-slurm.XXXXXX)
chmod 755 "$work"
host=$(hostname -s)
cpus=$(nproc)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    [ -f "$work/slurmctld.pid" ] && kill "$(cat "$work/slurmctld.pid")" 2>/dev/null || true
    [ -f "$work/slurmd.pid" ] && kill "$(cat "$work/slurmd.pid")" 2>/dev/null || true
    [ -f "$work/munged.pid" ] && kill "$(cat "$work/munged.pid")" 2>/dev/null || true
}
trap cleanup EXIT

# munge: its own socket and key in $work (an already running munged is left alone).
dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge.key"
mkdir -p "$work/munge"
munged --force --key-file="$work/munge.key" --socket="$work/munge/munge.socket" \
    --pid-file="$work/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munge.seed"

mkdir -p "$work/state" "$work/spool" "$work/out"
cat > "$work/slurm.conf" <<CONF
ClusterName=meshclash-smoke
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/munge.socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=smoke Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
    sinfo -h -o '%T' 2>/dev/null | grep -q idle && break
    sleep 1
done
sinfo

# The plan, on the shared directory every array task reads.
cp "$scene" "$work/site.glb"
cd "$work"
t0=$(date +%s.%N)
"$exe" plan scene site.glb --no-timings -o plan.json
t1=$(date +%s.%N)
array=$(sbatch --parsable --array=1-"$n" --chdir="$work" --output="$work/out/shard-%a.log" \
    --export=ALL,MESHCLASH="$exe" "$here/meshclash-array.sbatch")
merge=$(sbatch --parsable --dependency=afterok:"$array" --chdir="$work" --output="$work/out/merge.log" \
    --wrap="\"$exe\" merge out/shard-*.json --junit report.xml -o report.json; echo exit=\$? > out/merge.code")
echo "submitted array $array (1-$n) and merge $merge"
while squeue -h -j "$array,$merge" 2>/dev/null | grep -q .; do sleep 1; done
t2=$(date +%s.%N)
for i in $(seq "$n"); do
    echo "--- array task $i: $(tr -s ' \t\n' ' ' < "$work/out/shard-$i.log")"
done
merged_code=$(sed 's/exit=//' out/merge.code)
set +e
"$exe" scene site.glb --no-timings --junit single.xml -o single.json
single_code=$?
set -e
t3=$(date +%s.%N)
cmp report.json single.json
cmp report.xml single.xml
[ "$merged_code" = "$single_code" ] || { echo "exit codes differ: merge $merged_code, single $single_code" >&2; exit 1; }
echo "plan $(echo "$t1 - $t0" | bc) s, array of $n + merge $(echo "$t2 - $t1" | bc) s (submit to merged), single run $(echo "$t3 - $t2" | bc) s"
echo "slurm smoke: merged report and JUnit byte-identical to the single run ($(wc -c < report.json) bytes), exit code $merged_code both"
