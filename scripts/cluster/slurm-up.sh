#!/usr/bin/env bash
# Brings up a single-node SLURM cluster on this machine, for the heavy `ontime` jobs
# (the *.sbatch scripts beside this one). Works without systemd: the daemons are started
# directly and keep all their state, logs and pid files in one directory.
#
# Usage:
#   eval "$(scripts/cluster/slurm-up.sh DIR)"    # e.g. DIR=/tmp/ontime-slurm
#   sinfo; sbatch scripts/cluster/collect.sbatch --domain navigation
#   scripts/cluster/slurm-down.sh DIR
#
# The only line on stdout is `export SLURM_CONF=DIR/slurm.conf`, which the client
# commands (sinfo, sbatch, srun, squeue, scancel) need to find this cluster; every other
# message goes to stderr.
#
# What it does, each step skipped when already done (running it twice is harmless):
#   1. installs what is missing through scripts/setup.sh (munge, slurmctld, slurmd,
#      slurm-client and libpmix-dev among OnTime's packages; with sudo when not root);
#   2. starts munged (SLURM's authentication) unless it already runs, and records in
#      DIR/munged.pid that it did, so that slurm-down.sh stops only a munged started here;
#   3. unless slurmctld and slurmd already run from DIR/slurm.conf: stops whichever of the
#      two still runs from DIR, clears DIR's controller state and slurmd spool (an earlier
#      run's node state, job numbers or revoked job credentials would otherwise get in the
#      way of the new run), writes DIR/slurm.conf and starts both daemons;
#   4. waits until `sinfo` shows the node idle, or busy with jobs if the cluster was already
#      up (SLURM_UP_TIMEOUT seconds, default 90), else stops with the tails of the daemons'
#      logs.
#
# One such cluster at a time: the daemons listen on SLURM's standard ports 6817 and 6818.
set -euo pipefail

if [ $# -ne 1 ]; then
  echo "usage: $0 DIR" >&2
  exit 2
fi

log() { echo "slurm-up: $*" >&2; }


# Prints the pids of the live processes called NAME (exited ones not yet reaped left out).
live_pids() {
  local pid
  for pid in $(pgrep -x "$1"); do
    if alive "$pid"; then echo "$pid"; fi
  done
}

mkdir -p "$1"
dir=$(cd "$1" && pwd -P)
conf="$dir/slurm.conf"
timeout_seconds=${SLURM_UP_TIMEOUT:-90}

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
# shellcheck source=scripts/cluster/slurm-common.sh
source "$(dirname "$0")/slurm-common.sh"

# 1. Packages: OnTime's installer (idempotent) has munge, SLURM and PMIx among its packages.
"$(dirname "$0")/../setup.sh" >&2

# The daemons run as root (SlurmUser and SlurmdUser below), so starting them needs root.
run_root() { "${sudo_cmd[@]}" "$@"; }

# 2. munged. The package creates the key; a key is made here only if it is missing.
if [ ! -s /etc/munge/munge.key ]; then
  log "creating /etc/munge/munge.key"
  if command -v mungekey >/dev/null; then
    run_root runuser -u munge -- mungekey --create
  else
    run_root runuser -u munge -- /usr/sbin/create-munge-key
  fi
fi
munged_pids=$(live_pids munged)
if [ -n "$munged_pids" ]; then
  # Still ours if the munged recorded by an earlier run is the one running now.
  if [ -f "$dir/munged.pid" ] && ! grep -qx -- "$(cat "$dir/munged.pid")" <<<"$munged_pids"; then
    rm -f "$dir/munged.pid"
  fi
else
  log "starting munged"
  # /run/munge (its socket and pid file) does not survive a reboot; without systemd nothing
  # else creates it. munged runs as the munge user, who owns the key it checks.
  run_root install -d -o munge -g munge -m 0755 /run/munge
  run_root runuser -u munge -- /usr/sbin/munged
  for _ in $(seq 50); do
    munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1 && break
    sleep 0.1
  done
  live_pids munged | head -n 1 >"$dir/munged.pid"
fi
if ! munge -n </dev/null | unmunge >/dev/null 2>&1; then
  log "munge does not work: 'munge -n | unmunge' failed (see /var/log/munge/munged.log)"
  exit 1
fi

# 3. slurmctld and slurmd.
mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/run"


stop_daemon() {
  local pid
  pid=$(running_here "$1") || return 0
  stop_pid "$1" "$pid"
}

# Stops with MESSAGE and the tails of the daemons' logs.
fail() {
  log "$*"
  for daemon in slurmctld slurmd; do
    echo "--- tail of $dir/log/$daemon.log" >&2
    tail -n 20 "$dir/log/$daemon.log" >&2 2>/dev/null || echo "(no log)" >&2
  done
  log "scripts/cluster/slurm-down.sh $dir stops whatever did start"
  exit 1
}

if running_here slurmctld >/dev/null && running_here slurmd >/dev/null; then
  log "slurmctld and slurmd already run from $conf"
else
  for daemon in slurmctld slurmd; do
    others=$(live_pids "$daemon" | grep -vx -- "$(running_here "$daemon" || echo none)" || true)
    if [ -n "$others" ]; then
      log "a $daemon of another configuration runs (pid ${others//$'\n'/ }); stop it first:" \
        "it holds SLURM's ports"
      exit 1
    fi
  done
  stop_daemon slurmd
  stop_daemon slurmctld
  rm -rf "${dir:?}/state" "${dir:?}/spool" "${dir:?}/run"
  mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/run"
  for daemon in slurmctld slurmd; do
    if [ -f "$dir/log/$daemon.log" ]; then mv "$dir/log/$daemon.log" "$dir/log/$daemon.log.old"; fi
  done

  host=$(hostname -s)
  # Explicit topology and memory: slurmd drains a node whose configuration claims more than
  # it finds, and falls back to one CPU when slurm.conf says nothing.
  lscpu_field() { lscpu | sed -n "s/^$1:[[:space:]]*//p" | head -n 1; }
  sockets=$(lscpu_field 'Socket(s)')
  cores=$(lscpu_field 'Core(s) per socket')
  threads=$(lscpu_field 'Thread(s) per core')
  if ! [[ "$sockets$cores$threads" =~ ^[0-9]+$ ]]; then
    sockets=1 cores=$(nproc) threads=1
  fi
  memory=$(awk '/^MemTotal:/ { print int($2 / 1024) }' /proc/meminfo)

  cat >"$conf" <<EOF
# Single-node cluster written by scripts/cluster/slurm-up.sh; rewritten at every fresh start.
ClusterName=ontime
# Controller and node both on this machine, reached over loopback whatever the host name
# resolves to.
SlurmctldHost=$host(127.0.0.1)
# Both daemons as root: slurmd must be root to start jobs as their users, and with slurmctld
# as root too the files under $dir need no ownership change for a slurm account.
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CryptoType=crypto/munge
# Everything the daemons keep lives under $dir.
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# No cgroups (they need systemd or a delegated cgroup tree): processes are tracked through
# /proc and tasks are not bound to CPUs.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
# No mail server here: jobs asking for mail get none, and slurmctld does not complain at start.
MailProg=/bin/true
# ontime's MPI ranks get their rank and size from PMIx (srun --mpi=pmix).
MpiDefault=pmix
# A node that went down with an earlier run returns to service as soon as slurmd registers.
ReturnToService=2
# Cores are the scheduled resource; memory is not, so jobs need not state --mem.
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
NodeName=$host NodeAddr=127.0.0.1 Sockets=$sockets CoresPerSocket=$cores ThreadsPerCore=$threads RealMemory=$memory State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

  log "starting slurmctld and slurmd from $conf"
  run_root slurmctld -f "$conf" || fail "slurmctld did not start"
  run_root slurmd -f "$conf" || fail "slurmd did not start"
fi

# 4. Wait for the node.
export SLURM_CONF="$conf"
start=$SECONDS
state=""
while true; do
  state=$(sinfo -h -N -o '%T' 2>/dev/null | head -n 1 || true)
  case "$state" in
    idle | mixed | allocated | completing) break ;;
  esac
  for daemon in slurmctld slurmd; do
    running_here "$daemon" >/dev/null || fail "$daemon is not running"
  done
  if [ $((SECONDS - start)) -ge "$timeout_seconds" ]; then
    fail "the node is not idle after ${timeout_seconds} s (state: '${state:-no answer}')"
  fi
  sleep 1
done
log "node $(hostname -s) is $state after $((SECONDS - start)) s"
echo "export SLURM_CONF=$conf"
