#!/usr/bin/env bash
# End-to-end test of the Slurm scripts on a one-node cluster started on this machine:
# munged, slurmctld and slurmd run as root from a private directory (their own key, socket,
# config, state and ports: nothing of the system's is touched), submit.sh renders SCENE as an
# array of 4 sample ranges plus the merge job, and the merged image must equal a single-process
# render of the same spp. The daemons are stopped at the end, whatever happened.
#
#   scripts/slurm/ci-test.sh CANOPY SCENE SPP
#
# Exit 0: passed; 1: failed; 77: could not run (not root, Slurm or munge missing, or the daemons
# would not start), with the reason printed loudly (ctest shows the test as skipped).
set -uo pipefail
if [ $# -ne 3 ]; then
  echo "usage: $0 CANOPY SCENE SPP" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
CANOPY=$(realpath "$1") SCENE=$(realpath "$2") SPP=$3
TASKS=4

skip() {
  echo "==================================================================" >&2
  echo "SLURM TEST SKIPPED: $*" >&2
  echo "==================================================================" >&2
  exit 77
}
fail() {
  echo "slurm test FAILED: $*" >&2
  for f in "$tmp"/*.log "$tmp"/out/parts/*.log; do
    [ -f "$f" ] && { echo "---- $f" >&2; tail -n 20 "$f" >&2; }
  done
  exit 1
}

[ "$(id -u)" -eq 0 ] || skip "needs root to run slurmctld/slurmd (running as $(id -un))"
for c in munged slurmctld slurmd sbatch squeue scancel; do
  command -v "$c" >/dev/null || skip "$c not found (scripts/install-deps.sh installs slurm-wlm and munge)"
done

tmp=$(mktemp -d /tmp/canopy-slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  scancel --quiet --full --signal=KILL --user=root >/dev/null 2>&1 || true
  for f in "$tmp/slurmd.pid" "$tmp/slurmctld.pid" "$tmp/munged.pid"; do
    [ -f "$f" ] && kill "$(cat "$f")" 2>/dev/null
  done
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  sleep 1
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done
  [ -n "${KEEP_TMP:-}" ] || rm -rf "$tmp"
}
trap cleanup EXIT

# munge: a private key and socket.
mkdir -p "$tmp/munge" && chmod 700 "$tmp/munge"
dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge/munge.key"
munged --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.socket" \
  --pid-file="$tmp/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge/seed" \
  --force >"$tmp/munged.out" 2>&1 || skip "munged would not start: $(tail -n 3 "$tmp/munged.log" "$tmp/munged.out" 2>/dev/null | tr '\n' ' ')"

# Slurm: one node (this machine), one partition, root as the Slurm user, non-default ports.
node=$(hostname -s)
cpus=$(nproc)
mkdir -p "$tmp/state" "$tmp/spool" "$tmp/out"
cat >"$tmp/slurm.conf" <<EOF
ClusterName=canopyci
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.socket
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SlurmdTimeout=60
NodeName=$node CPUs=$cpus State=UNKNOWN
PartitionName=ci Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
# The node is up when sinfo shows it idle.
up=
for _ in $(seq 1 60); do
  if sinfo -h -o '%t' 2>/dev/null | grep -q idle; then up=1; break; fi
  for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null || break 2; done
  sleep 1
done
[ -n "$up" ] || skip "the one-node cluster did not come up: slurmctld: $(tail -n 2 "$tmp/slurmctld.log" "$tmp/slurmctld.out" 2>/dev/null | tr '\n' ' ') slurmd: $(tail -n 2 "$tmp/slurmd.log" "$tmp/slurmd.out" 2>/dev/null | tr '\n' ' ')"
echo "slurm test: cluster up ($node, $cpus CPUs); submitting $TASKS ranges of $SPP spp"

out="$tmp/out/merged.exr"
export CANOPY
sub=$("$here/submit.sh" "$SCENE" "$SPP" "$TASKS" "$out" --seed 3 --quiet) || fail "submit.sh: $sub"
echo "$sub"
merge=$(echo "$sub" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')
[ -n "$merge" ] || fail "no merge job id in: $sub"
for _ in $(seq 1 300); do
  [ -z "$(squeue -h -j "$merge" 2>/dev/null)" ] && break
  sleep 1
done
[ -z "$(squeue -h -j "$merge" 2>/dev/null)" ] || fail "the merge job did not finish in 300 s"
parts="$tmp/out/merged-parts"
[ -f "$out" ] || fail "the merge job wrote no $out"
n=$(ls "$parts"/part-*.exr 2>/dev/null | wc -l)
[ "$n" -eq "$TASKS" ] || fail "$n partial images, expected $TASKS"
grep -q "$SPP samples per pixel (samples 0:$SPP of seed 3)" "$parts/merge.txt" ||
  fail "merge output: $(cat "$parts/merge.txt")"
for i in $(seq 0 $((TASKS - 1))); do
  grep -q "samples $((i * SPP / TASKS)):$(((i + 1) * SPP / TASKS))" "$parts/range-$i.log" ||
    fail "task $i's log does not name its range"
  if grep -q $'\r' "$parts/range-$i.log"; then fail "task $i's log holds carriage returns"; fi
done

# The same render in one process: equal up to float rounding.
"$CANOPY" render "$SCENE" --spp "$SPP" --seed 3 --quiet --out "$tmp/single.exr" >/dev/null 2>&1 ||
  fail "the single-process render failed"
cmp=$("$CANOPY" compare "$out" "$tmp/single.exr" --json) || fail "compare failed"
rmse=$(echo "$cmp" | sed -n 's/.*"rmse": *\([-0-9.eE+]*\).*/\1/p')
awk -v r="$rmse" 'BEGIN { exit !(r != "" && r + 0 <= 1e-6) }' ||
  fail "merged vs single-process render: rmse $rmse > 1e-6"
echo "slurm test passed: $TASKS array tasks + merge equal the single-process render (rmse $rmse)"
