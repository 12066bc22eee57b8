#!/usr/bin/env bash
# A one-node Slurm cluster on loopback for tests: munged, slurmctld and slurmd in the
# foreground (as background processes of this script's caller), state and logs under DIR.
#
#   tools/slurm/one-node-cluster.sh start DIR   # prints `export SLURM_CONF=DIR/slurm.conf`
#   tools/slurm/one-node-cluster.sh stop DIR
#
# Needs Debian's slurm-wlm and munge (tools/test installs them) and root (slurmd runs jobs as
# the submitting user; the daemons here run as the caller, SlurmUser = the caller).
set -euo pipefail
export PATH="$PATH:/usr/sbin:/sbin"
cmd=${1:?start or stop}
dir=$(mkdir -p "${2:?a directory for the cluster state}" && cd "$2" && pwd)
case "$cmd" in
stop)
  # TERM, then KILL what is left after 5 s (slurmctld's script helper included)
  pids=()
  for p in slurmd slurmctld munged; do
    if [ -f "$dir/$p.pid" ]; then
      pids+=("$(cat "$dir/$p.pid")")
      rm -f "$dir/$p.pid"
    fi
  done
  if [ ${#pids[@]} -gt 0 ]; then
    kill "${pids[@]}" 2>/dev/null || true
    for _ in $(seq 50); do
      kill -0 "${pids[@]}" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "${pids[@]}" 2>/dev/null || true
  fi
  pkill -9 -f "slurmscriptd.*$dir" 2>/dev/null || true
  exit 0
  ;;
start) ;;
*)
  echo "usage: $0 start|stop DIR" >&2
  exit 2
  ;;
esac
for b in munged slurmctld slurmd sbatch; do
  command -v "$b" >/dev/null || {
    echo "$0: $b is missing: apt-get install slurm-wlm munge (tools/test does)" >&2
    exit 1
  }
done
user=$(id -un)
mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
# munge: its own key, socket and files under DIR
if [ ! -f "$dir/munge/munge.key" ]; then
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
fi
chmod 700 "$dir/munge"
chmod 400 "$dir/munge/munge.key"
munged --foreground --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
  --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
  --seed-file="$dir/munge/munged.seed" >"$dir/munged.out" 2>&1 &
echo $! >"$dir/munged.pid"
mem_mb=$(awk '/MemTotal/ {print int($2 / 1024 * 0.8)}' /proc/meminfo)
cpus=$(nproc)
port=$((20000 + RANDOM % 20000))
cat >"$dir/slurm.conf" <<CONF
ClusterName=sinsmodel-ci
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$user
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.daemon.pid
SlurmdPidFile=$dir/slurmd.daemon.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmdTimeout=30
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=ci Nodes=localhost Default=YES MaxTime=60 State=UP
CONF
export SLURM_CONF=$dir/slurm.conf
# the socket must exist before the daemons authenticate
for _ in $(seq 50); do [ -S "$dir/munge/munge.socket" ] && break; sleep 0.1; done
slurmctld -D -i -f "$SLURM_CONF" >"$dir/slurmctld.out" 2>&1 &
echo $! >"$dir/slurmctld.pid"
slurmd -D -N localhost -f "$SLURM_CONF" >"$dir/slurmd.out" 2>&1 &
echo $! >"$dir/slurmd.pid"
# ready when the node is idle
for _ in $(seq 100); do
  if sinfo -h -N -o '%T' 2>/dev/null | grep -q '^idle'; then
    echo "export SLURM_CONF=$SLURM_CONF"
    exit 0
  fi
  sleep 0.2
done
echo "$0: the cluster did not come up in 20 s; logs in $dir:" >&2
tail -n 20 "$dir"/*.out "$dir"/*.log >&2 || true
exit 1
