#!/usr/bin/env bash
# Throughput of the split commands against the number of MPI ranks on this machine, one thread
# per rank (the figures of docs/cluster.md):
#  - collection: `ontime collect` of the navigation domain, TRIALS trials per action (default 300),
#    as one process without a launcher, then under `mpirun -np 1` and `mpirun -np 2`;
#  - evaluation: `ontime evaluate` of the fitted instance with mcts, EPISODES episodes
#    (default 2000), the same three ways;
#  - the launcher's own cost: `mpirun -np 2` of an evaluation of 1 episode (MPI start-up, one
#    exchange of results, shut-down) against the same command as one process.
# Every run's files are compared with the one-process run's (they must be identical).
# Usage: scripts/cluster/scaling.sh [TRIALS] [EPISODES]   (build/ontime, a Release build)
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
trials=${1:-300}
episodes=${2:-2000}
ontime="$root/build/ontime"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mpirun=(mpirun --oversubscribe --bind-to none)
if [ "$(id -u)" -eq 0 ]; then mpirun+=(--allow-run-as-root); fi
world="$root/data/domains/navigation.json"

seconds() {  # seconds COMMAND...: wall-clock seconds of the command
  local began ended
  began=$(date +%s.%N)
  "$@" > /dev/null
  ended=$(date +%s.%N)
  echo "$ended - $began" | bc
}

echo "| job | one process | mpirun -np 1 | mpirun -np 2 | speed-up, 2 ranks vs one process |"
echo "|---|---:|---:|---:|---:|"
for job in collect evaluate; do
  declare -A took=()
  for how in one np1 np2; do
    mkdir -p "$work/$how"
    launcher=()
    case $how in
      np1) launcher=("${mpirun[@]}" -np 1) ;;
      np2) launcher=("${mpirun[@]}" -np 2) ;;
    esac
    cd "$work/$how"
    if [ "$job" = collect ]; then
      took[$how]=$(seconds "${launcher[@]}" "$ontime" collect --domain navigation --world "$world" \
        --trials "$trials" --seed 1 --threads 1 --log nav.jsonl --instance nav.json)
    else
      took[$how]=$(seconds "${launcher[@]}" "$ontime" evaluate "$work/one/nav.json" --solver mcts \
        --episodes "$episodes" --seed 1 --threads 1 --json --no-timing)
      "${launcher[@]}" "$ontime" evaluate "$work/one/nav.json" --solver mcts --episodes 200 --seed 1 \
        --threads 1 --json --no-timing > evaluate.json
    fi
    cd "$root"
  done
  if [ "$job" = collect ]; then
    cmp "$work/one/nav.jsonl" "$work/np2/nav.jsonl"
    cmp "$work/one/nav.json" "$work/np2/nav.json"
    what="collect, navigation, $trials trials per action"
  else
    cmp "$work/one/evaluate.json" "$work/np2/evaluate.json"
    what="evaluate, navigation model, mcts, $episodes episodes"
  fi
  printf "| %s | %.2f s | %.2f s | %.2f s | %.2f |\n" "$what" "${took[one]}" "${took[np1]}" "${took[np2]}" \
    "$(echo "${took[one]} / ${took[np2]}" | bc -l)"
done

alone=$(seconds "$ontime" evaluate "$work/one/nav.json" --solver dp-rerun --episodes 1 --threads 1 --json)
launched=$(seconds "${mpirun[@]}" -np 2 "$ontime" evaluate "$work/one/nav.json" --solver dp-rerun --episodes 1 \
  --threads 1 --json)
printf "\nLauncher cost (mpirun -np 2: start-up, one exchange, shut-down): %.2f s (the same command alone: %.3f s)\n" \
  "$(echo "$launched - $alone" | bc -l)" "$alone"
