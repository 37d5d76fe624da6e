#!/usr/bin/env bash
# A real Slurm in the tests: starts Debian's slurm-wlm as a single-node cluster (munged,
# slurmctld, slurmd, all in a scratch directory, no systemd), submits `subflow plan
# --slurm` of a small synthetic take with its submit.sh, waits for the jobs, and compares
# the merged result with `subflow run-plan` of the same plan (bit for bit: the same
# commands) and with the single-process `subflow reconstruct` (eval figures within 5 %).
# Exits 77 (ctest SKIP) with the reason when Slurm is not installed or cannot start here.
#   tests/cluster/slurm_plan_test.sh SUBFLOW_BINARY SOURCE_DIR
set -uo pipefail
subflow="$1"
source_dir="$2"
skip() { echo "SKIP: $*"; exit 77; }
for command in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$command" > /dev/null || skip "$command not installed (scripts/install_deps.sh installs slurm-wlm and munge)"
done
[ "$(id -u)" -eq 0 ] || skip "slurmd needs root to start here"

work="$(mktemp -d /tmp/subflow_slurm_XXXXXX)"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null; done
  wait 2> /dev/null
  rm -rf "$work"
}
trap cleanup EXIT
mkdir -p "$work"/{munge,state,spool,log}
chmod 700 "$work/munge"

# munge with its own key and socket.
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 2> /dev/null
chmod 400 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/socket" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/log/munged.log" --seed-file="$work/munge/seed" \
  || skip "munged does not start: $(tail -2 "$work/log/munged.log" 2> /dev/null)"
pids+=("$(cat "$work/munge/munged.pid")")

host="$(hostname -s)"
cpus="$(nproc)"
memory_mib=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2 ))
cat > "$work/slurm.conf" << CONF
ClusterName=subflowtest
SlurmctldHost=$host
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host CPUs=$cpus RealMemory=$memory_mib State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -D -f "$SLURM_CONF" > "$work/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" > "$work/log/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 60); do
  sinfo -h -o %T 2> /dev/null | grep -qE '^(idle|mixed)' && break
  sleep 1
done
sinfo -h -o %T 2> /dev/null | grep -qE '^(idle|mixed)' ||
  skip "the single-node cluster does not come up: $(tail -3 "$work/log/slurmctld.log" "$work/log/slurmd.log" 2> /dev/null | tr '\n' ' ')"
echo "slurm: $(sinfo -h -o '%P %D %T %c %m')"

fail() { echo "FAIL: $*"; exit 1; }
small="--base-faces 120 --levels 2 --window 3 --iterations 4"
"$subflow" synth blob --out "$work/blob" --cameras 6 --frames 8 --width 160 --height 120 --subdivisions 4 --gray \
  > /dev/null 2>&1 || fail "synth"
"$subflow" plan "$work/blob" --out "$work/plan" --chunk 4 --overlap 1 --slurm --memory 1024 $small \
  > "$work/log/plan.log" 2>&1 || fail "plan: $(cat "$work/log/plan.log")"
bash "$work/plan/slurm/submit.sh" || fail "submit.sh"
last="$(cat "$work/plan/slurm/last_job")"
for _ in $(seq 1800); do
  [ -z "$(squeue -h 2> /dev/null)" ] && break
  sleep 1
done
[ -f "$work/plan/result/report.json" ] ||
  fail "the jobs ended without a result (last job $last): $(tail -5 "$work"/plan/slurm/*.log 2> /dev/null)"
echo "slurm: every job finished; result in $work/plan/result"

# The same plan run here, and the single-process run.
"$subflow" plan "$work/blob" --out "$work/local" --chunk 4 --overlap 1 $small > /dev/null 2>&1 || fail "plan (local)"
"$subflow" run-plan "$work/local" > "$work/log/local.log" 2>&1 || fail "run-plan: $(tail -3 "$work/log/local.log")"
python3 "$source_dir/scripts/compare_results.py" "$work/local/result" "$work/plan/result" --tolerance 1e-9 ||
  fail "the Slurm result differs from run-plan's"
"$subflow" reconstruct "$work/blob" --out "$work/single" $small > /dev/null 2>&1 || fail "reconstruct"
"$subflow" eval "$work/blob" "$work/single" --json "$work/single.json" > /dev/null 2>&1 || fail "eval"
"$subflow" eval "$work/blob" "$work/plan/result" --json "$work/slurm.json" > /dev/null 2>&1 || fail "eval"
python3 - "$work/single.json" "$work/slurm.json" << 'PY' || fail "the Slurm result is not within 5 % of reconstruct"
import json, sys
single, slurm = (json.load(open(path))["overall"]["observed"] for path in sys.argv[1:3])
for name, a, b in (("accuracy", single["accuracy"], slurm["accuracy"]),
                   ("flow EPE", single["flow"]["epe_mean"], slurm["flow"]["epe_mean"])):
    print(f"{name}: reconstruct {a:.6g}, slurm plan {b:.6g} ({100 * (b / a - 1):+.1f} %)")
    if b > 1.05 * a:
        sys.exit(1)
PY
echo "PASS"
