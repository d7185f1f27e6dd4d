#!/usr/bin/env bash
# Stops the single-node SLURM cluster that slurm-up.sh started from DIR.
#
# Usage:
#   scripts/cluster/slurm-down.sh DIR
#
# Cancels the jobs of its partition (their steps would otherwise outlive slurmd), stops slurmd
# and then slurmctld through the pid files in DIR/run, waiting for each to exit (SIGKILL after
# 30 s), and stops munged only if slurm-up.sh started it (DIR/munged.pid records that and
# still names the running munged). A munged that ran before slurm-up.sh is left alone, as
# other services may use it. Nothing running is not an error, so running it twice is harmless.
# DIR itself (configuration, logs) is kept; slurm-up.sh clears its stale state at the next start.
set -euo pipefail

if [ $# -ne 1 ]; then
  echo "usage: $0 DIR" >&2
  exit 2
fi

log() { echo "slurm-down: $*" >&2; }

if [ ! -d "$1" ]; then
  log "no directory $1; nothing to stop"
  exit 0
fi
dir=$(cd "$1" && pwd -P)
conf="$dir/slurm.conf"

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
# shellcheck source=scripts/cluster/slurm-common.sh
source "$(dirname "$0")/slurm-common.sh"

if running_here slurmctld >/dev/null; then
  export SLURM_CONF="$conf"
  if [ -n "$(squeue -h -o %i 2>/dev/null | head -n 1)" ]; then
    log "cancelling the remaining jobs"
    scancel --partition=main 2>/dev/null || true
    for _ in $(seq 30); do
      [ -z "$(squeue -h -o %i 2>/dev/null | head -n 1)" ] && break
      sleep 1
    done
  fi
fi

stopped=0
for daemon in slurmd slurmctld; do
  if pid=$(running_here "$daemon"); then
    stop_pid "$daemon" "$pid"
    stopped=$((stopped + 1))
  fi
  rm -f "$dir/run/$daemon.pid"
done

if [ -f "$dir/munged.pid" ]; then
  pid=$(cat "$dir/munged.pid")
  if [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = munged ]; then
    stop_pid munged "$pid"
  fi
  rm -f "$dir/munged.pid"
elif [ -n "$(for pid in $(pgrep -x munged); do alive "$pid" && echo "$pid"; done)" ]; then
  log "munged was running before slurm-up.sh; left running"
fi

[ "$stopped" -gt 0 ] || log "no SLURM daemon of $dir was running"
