# shellcheck shell=bash disable=SC2154
# Shell functions slurm-up.sh and slurm-down.sh share; sourced by them once `dir` (the
# cluster's directory), `conf` (its slurm.conf), `sudo_cmd` and `log` are set.

# True while PID runs. An exited daemon counts as gone even before its parent reaps it:
# daemons are reparented to PID 1, which need not be an init that reaps promptly.
alive() {
  local state
  state=$(sed 's/.*) //; s/ .*//' "/proc/$1/stat" 2>/dev/null) || return 1
  [ -n "$state" ] && [ "$state" != Z ]
}

# Prints the pid of DAEMON (slurmctld or slurmd) if it runs from this directory's slurm.conf;
# a pid file left by a daemon that died, or whose pid has been reused, names nothing.
running_here() {
  local pidfile="$dir/run/$1.pid" pid
  [ -s "$pidfile" ] || return 1
  pid=$(cat "$pidfile")
  [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$1" ] || return 1
  tr '\0' ' ' <"/proc/$pid/cmdline" | grep -qF -- " -f $conf " || return 1
  echo "$pid"
}

# Sends SIGTERM to PID and waits up to 30 s for it to exit, then SIGKILL. Then gives PID 1 up
# to 10 s to reap it, so that no defunct entry is left in the process table either.
stop_pid() {
  local name=$1 pid=$2
  log "stopping $name ($pid)"
  "${sudo_cmd[@]}" kill -TERM "$pid" 2>/dev/null || true
  for _ in $(seq 300); do
    alive "$pid" || break
    sleep 0.1
  done
  if alive "$pid"; then
    log "$name ($pid) did not stop within 30 s; killing it"
    "${sudo_cmd[@]}" kill -KILL "$pid" 2>/dev/null || true
  fi
  for _ in $(seq 100); do
    [ -d "/proc/$pid" ] || return 0
    sleep 0.1
  done
}
