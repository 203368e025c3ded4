#!/bin/sh
# A throwaway one-node Slurm cluster for the tests (tests/deploy/slurm_test.py), from Debian's
# packages (slurmctld, slurmd, slurm-client, munge):
#   slurm_cluster.sh start DIR   a munge key and munged, a test-owned slurm.conf (one node with
#                                this machine's CPUs, ReturnToService=2, free ports), slurmctld
#                                and slurmd, all with their files in DIR; waits for the node to
#                                be idle and prints the slurm.conf path (export it as SLURM_CONF).
#   slurm_cluster.sh stop DIR    stops the daemons and removes DIR.
# Needs root (slurmd starts jobs as their submitting user), as in CI. Exit status 3 and a message
# when Slurm or munge is not installed: the tests fail on that, they do not skip.
set -eu
cmd=${1:?start|stop}
dir=${2:?DIR}

need() {
  for b in "$@"; do
    command -v "$b" >/dev/null 2>&1 || [ -x "/usr/sbin/$b" ] || {
      echo "slurm_cluster.sh: $b is not installed: install slurmctld, slurmd, slurm-client and munge as the README's setup does (scripts/install-deps.sh)" >&2
      exit 3
    }
  done
}

free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

stop_pidfile() {
  if [ -f "$1" ]; then
    pid=$(cat "$1")
    kill "$pid" 2>/dev/null || true
    i=0
    while kill -0 "$pid" 2>/dev/null && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
    kill -9 "$pid" 2>/dev/null || true
  fi
}

case "$cmd" in
start)
  need munged mungekey slurmctld slurmd sinfo sbatch
  [ "$(id -u)" = 0 ] || { echo "slurm_cluster.sh: slurmd must run as root (it starts jobs as their user)" >&2; exit 1; }
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
  chmod 755 "$dir"
  mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
  chmod 700 "$dir/munge"
  PATH="$PATH:/usr/sbin"
  mungekey --create --keyfile="$dir/munge/munge.key" >/dev/null
  chmod 400 "$dir/munge/munge.key"
  munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/seed" ||
    { cat "$dir/log/munged.log" >&2; exit 1; }
  node=$(hostname -s)
  cpus=$(nproc)
  cat >"$dir/slurm.conf" <<CONF
ClusterName=synbench-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
KillWait=5
SchedulerParameters=sched_interval=1
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -f "$SLURM_CONF" ||
    { cat "$dir/log/slurmctld.log" >&2; exit 1; }
  slurmd -f "$SLURM_CONF" ||
    { cat "$dir/log/slurmd.log" >&2; exit 1; }
  i=0
  until sinfo -h -N -o %t 2>/dev/null | grep -qx idle; do
    i=$((i + 1))
    if [ $i -gt 300 ]; then
      echo "slurm_cluster.sh: the node did not become idle in 30 s:" >&2
      sinfo -N -l >&2 || true
      tail -20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2
      exit 1
    fi
    sleep 0.1
  done
  echo "$dir/slurm.conf"
  ;;
stop)
  stop_pidfile "$dir/slurmd.pid"
  stop_pidfile "$dir/slurmctld.pid"
  stop_pidfile "$dir/munge/munged.pid"
  rm -rf "$dir"
  ;;
*)
  echo "usage: slurm_cluster.sh start|stop DIR" >&2
  exit 2
  ;;
esac
