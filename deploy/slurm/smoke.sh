#!/usr/bin/env bash
# A one-node Slurm on this machine, from Debian's slurm-wlm and munge packages, running
# deploy/slurm/precompute.sbatch for real: munged, slurmctld -D and slurmd -D are started by hand
# (no systemd) with their state under a temporary directory and stopped by their PIDs; the array
# job of SHARDS shards and its afterok merge job are submitted, waited for, and the merged cache
# is compared byte for byte with an unsharded run. Prints what it did; the output committed is
# results/scale/slurm-smoke.txt:
#   apt-get install slurm-wlm munge   # once, as root
#   bash deploy/slurm/smoke.sh > results/scale/slurm-smoke.txt
# HAARSHIFT names the binary (default: target/release/haarshift, built if missing);
# WAIT_SECONDS (default 600) how long the jobs may take before the run counts as failed.
# Without Slurm it says so in one line and exits 0 (skipped), unless HAARSHIFT_REQUIRE lists
# `slurm` (as .ci/run sets it): then it fails.
set -euo pipefail
cd "$(dirname "$0")/../.."
for program in slurmctld slurmd sbatch munged; do
    command -v "$program" >/dev/null && continue
    why="no $program on the PATH (apt-get install slurm-wlm munge)"
    if [[ ",${HAARSHIFT_REQUIRE:-}," == *,slurm,* ]]; then
        echo "deploy/slurm/smoke.sh: slurm is required (HAARSHIFT_REQUIRE) but missing: $why" >&2
        exit 1
    fi
    echo "skipped: deploy/slurm/smoke.sh: $why"
    exit 0
done
shards=${SHARDS:-3}
wait_seconds=${WAIT_SECONDS:-600}
haarshift=$(realpath "${HAARSHIFT:-target/release/haarshift}")
[ -x "$haarshift" ] || cargo build --release -p haarshift-cli >&2
work=$(mktemp -d)
pids=()
stop() {
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
    rm -rf "$work"
}
trap stop EXIT
host=$(hostname -s)
mkdir -p "$work"/{munge,state,spool,out}
chmod 700 "$work/munge"

# munge: a fresh key; --force because the key and socket live in a temporary directory.
mungekey --create --keyfile="$work/munge/munge.key" >/dev/null 2>&1 \
    || dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge/munge.key"
munged --force --foreground --key-file="$work/munge/munge.key" \
    --socket="$work/munge/munge.socket" --pid-file="$work/munge/munged.pid" \
    --log-file="$work/munge/munged.log" --seed-file="$work/munge/munged.seed" &
pids+=($!)
for _ in $(seq 50); do [ -S "$work/munge/munge.socket" ] && break; sleep 0.1; done

cat >"$work/slurm.conf" <<CONF
ClusterName=smoke
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$work/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=smoke Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
slurmctld -D -f "$SLURM_CONF" &
pids+=($!)
slurmd -D -f "$SLURM_CONF" &
pids+=($!)
for _ in $(seq 100); do
    sinfo -h -o %t 2>/dev/null | grep -qx idle && break
    sleep 0.2
done
echo "one-node Slurm: $(sinfo --version), node $host: $(sinfo -h -o '%t, %c CPUs')"

scene=$work/balls.json
cat >"$scene" <<'SCENE'
{"objects": [{"generator": {"sphere": {"cells": 6}}},
             {"generator": {"sphere": {"cells": 6}}, "transform": {"translate": [2.5, 0, 0]}}],
 "ground_plane": true}
SCENE
options=(--param cube --resolution 16 --visibility-samples 2)
start=$SECONDS
submitted=$(HAARSHIFT=$haarshift bash deploy/slurm/precompute.sbatch "$scene" "$work/out" \
    "$shards" "${options[@]}")
echo "$submitted" | sed "s|$work/||g"
merge=$(echo "$submitted" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')
while [ -n "$(squeue -h 2>/dev/null)" ]; do
    if squeue -h -o %r | grep -q DependencyNeverSatisfied || ((SECONDS - start > wait_seconds)); then
        echo "a shard failed (or $wait_seconds s passed); the queue:"
        squeue
        cat "$work"/out/*.out
        exit 1
    fi
    sleep 0.5
done
echo "every job left the queue after $((SECONDS - start)) s; OUT_DIR holds:"
ls "$work/out" | sed 's/^/  /'
for log in "$work"/out/*.out; do
    echo "$(basename "$log"):"
    sed "s|$work/||g; s/^/  /" "$log"
done
[ -f "$work/out/scene.hsr" ] || { echo "no merged cache: the merge job $merge did not run"; exit 1; }
"$haarshift" relight precompute "$scene" "${options[@]}" -o "$work/whole.hsr" >/dev/null
if cmp "$work/out/scene.hsr" "$work/whole.hsr"; then
    echo "merged cache == unsharded cache, byte for byte ($(stat -c %s "$work/whole.hsr") bytes)"
else
    exit 1
fi
