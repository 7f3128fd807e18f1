#!/usr/bin/env bash
# A one-node Slurm on this machine for the dispersion tool's real back end (tests and demos):
# munged + slurmctld + slurmd as root, non-default ports, every file (key, sockets, state, logs,
# pid files) under a scratch folder, stopped by pid.
#
#   scripts/slurm-local.sh start [DIR]   # DIR, or $ROCKSTEADY_SLURM_DIR; prints `export SLURM_CONF=...`
#   scripts/slurm-local.sh stop  [DIR]
#
# Then `SLURM_CONF=DIR/slurm.conf sinfo`, or `rocksteady-campaign dispersion FILE --backend slurm`
# with SLURM_CONF exported. Needs root (munged runs as user munge, slurmd as root), slurm-wlm and
# munge (scripts/setup.sh). Ports: ROCKSTEADY_SLURM_PORT (controller, default 16817) and the next one.
set -euo pipefail

cmd=${1:-}
dir=${2:-${ROCKSTEADY_SLURM_DIR:-}}
if [[ -z "$cmd" || -z "$dir" ]]; then
  echo "usage: $0 start|stop DIR   (or set ROCKSTEADY_SLURM_DIR)" >&2
  exit 2
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
port=${ROCKSTEADY_SLURM_PORT:-16817}
conf="$dir/slurm.conf"

stop_pid() {  # pid file, name
  local f=$1 pid
  [[ -f "$f" ]] || return 0
  pid=$(cat "$f" 2>/dev/null || true)
  if [[ -n "$pid" ]] && kill -0 "$pid" 2>/dev/null; then
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null || true
  fi
  rm -f "$f"
}

case "$cmd" in
  stop)
    stop_pid "$dir/slurmd.pid"
    stop_pid "$dir/slurmctld.pid"
    stop_pid "$dir/munge/munged.pid"
    echo "slurm-local: stopped ($dir)"
    ;;
  start)
    if [[ $(id -u) -ne 0 ]]; then
      echo "slurm-local: needs root (munged and slurmd)" >&2
      exit 77
    fi
    for p in munged slurmctld slurmd sbatch; do
      command -v "$p" >/dev/null || { echo "slurm-local: $p not found (scripts/setup.sh installs slurm-wlm munge)" >&2; exit 1; }
    done
    "$0" stop "$dir" >/dev/null
    host=$(hostname -s)
    # munge: a private key and socket, owned by the munge user.
    install -d -m 0700 -o munge -g munge "$dir/munge"
    if [[ ! -f "$dir/munge/munge.key" ]]; then
      dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
    fi
    chown munge:munge "$dir/munge/munge.key"
    chmod 0400 "$dir/munge/munge.key"
    runuser -u munge -- munged --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
      --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
      --seed-file="$dir/munge/munged.seed" --force
    mkdir -p "$dir/state" "$dir/spool" "$dir/log"
    cat > "$conf" <<CONF
# One-node Slurm written by scripts/slurm-local.sh.
ClusterName=rocksteady
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
MaxArraySize=10001
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$conf"
    slurmctld
    slurmd
    for _ in $(seq 100); do
      state=$(sinfo -h -o %T 2>/dev/null | head -1 || true)
      if [[ "$state" == idle* ]]; then
        echo "slurm-local: up on $host ($dir)"
        echo "export SLURM_CONF=$conf"
        exit 0
      fi
      sleep 0.2
    done
    echo "slurm-local: the node did not come up; logs in $dir/log" >&2
    sinfo >&2 || true
    exit 1
    ;;
  *)
    echo "usage: $0 start|stop DIR" >&2
    exit 2
    ;;
esac
