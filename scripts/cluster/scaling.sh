#!/usr/bin/env bash
# Throughput of the split commands against the number of MPI ranks on this machine, one thread
# per rank (the figures of docs/cluster.md); build/ontime should be a Release build.
#  1. collection: `ontime collect` of the navigation domain, TRIALS trials per action (default
#     300), as one process without a launcher, under `mpirun -np 1` and under `mpirun -np 2`:
#     wall-clock time, and the collection's own time as the command reports it (from the first
#     trial to the last exchange of results, without MPI's start-up, the fit and the writing);
#  2. evaluation: `ontime evaluate` of the fitted instance with mcts, EPISODES episodes
#     (default 600), the same three ways;
#  3. the overhead on a collection of 100 trials per action: `mpirun -np 2` wall-clock time
#     minus half the one-process time (MPI start-up and shut-down, the exchanges, waiting for
#     the slower rank, and the serial fit and writing), and the launcher's own cost (`mpirun
#     -np 2` of a one-episode evaluation against the same command alone).
# Every split run's files are compared with the one-process run's (they must be identical).
# Usage: scripts/cluster/scaling.sh [TRIALS] [EPISODES]
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
trials=${1:-300}
episodes=${2:-600}
ontime="$root/build/ontime"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mpirun=(mpirun --oversubscribe --bind-to none)
if [ "$(id -u)" -eq 0 ]; then mpirun+=(--allow-run-as-root); fi
world="$root/data/domains/navigation.json"

# run FOLDER HOW COMMAND...: runs the command in FOLDER as one process (HOW=one) or under
# mpirun -np 1 or 2 (HOW=np1, np2), its output in FOLDER/out.txt; prints its wall-clock seconds.
run() {
  local folder=$1 how=$2 began ended
  shift 2
  local launcher=()
  case $how in
    np1) launcher=("${mpirun[@]}" -np 1) ;;
    np2) launcher=("${mpirun[@]}" -np 2) ;;
  esac
  mkdir -p "$folder"
  began=$(date +%s.%N)
  (cd "$folder" && "${launcher[@]}" "$@" > out.txt)
  ended=$(date +%s.%N)
  echo "$ended - $began" | bc
}
collected_in() { sed -n 's/^Collected .* in \([0-9.]*\) s:.*/\1/p' "$1/out.txt"; }

collect=("$ontime" collect --domain navigation --world "$world" --seed 1 --threads 1 --log nav.jsonl
  --instance nav.json)
declare -A wall=() own=()
for how in one np1 np2; do
  wall[$how]=$(run "$work/collect-$how" "$how" "${collect[@]}" --trials "$trials")
  own[$how]=$(collected_in "$work/collect-$how")
done
cmp "$work/collect-one/nav.jsonl" "$work/collect-np2/nav.jsonl"
cmp "$work/collect-one/nav.json" "$work/collect-np2/nav.json"
instance="$work/collect-one/nav.json"
evaluate=("$ontime" evaluate "$instance" --solver mcts --episodes "$episodes" --seed 1 --threads 1 --json --no-timing)
declare -A evaluation=()
for how in one np1 np2; do evaluation[$how]=$(run "$work/evaluate-$how" "$how" "${evaluate[@]}"); done
cmp "$work/evaluate-one/out.txt" "$work/evaluate-np2/out.txt"

echo "| job | one process | mpirun -np 1 | mpirun -np 2 | speed-up, 2 ranks vs one process |"
echo "|---|---:|---:|---:|---:|"
printf "| collect, navigation, %s trials per action: wall-clock | %.2f s | %.2f s | %.2f s | %.2f |\n" "$trials" \
  "${wall[one]}" "${wall[np1]}" "${wall[np2]}" "$(echo "${wall[one]} / ${wall[np2]}" | bc -l)"
printf "| the same: the collection's own time | %.2f s | %.2f s | %.2f s | %.2f |\n" \
  "${own[one]}" "${own[np1]}" "${own[np2]}" "$(echo "${own[one]} / ${own[np2]}" | bc -l)"
printf "| evaluate, mcts on the fitted instance, %s episodes: wall-clock | %.2f s | %.2f s | %.2f s | %.2f |\n" \
  "$episodes" "${evaluation[one]}" "${evaluation[np1]}" "${evaluation[np2]}" \
  "$(echo "${evaluation[one]} / ${evaluation[np2]}" | bc -l)"

small_one=$(run "$work/small-one" one "${collect[@]}" --trials 100)
small_two=$(run "$work/small-np2" np2 "${collect[@]}" --trials 100)
cmp "$work/small-one/nav.jsonl" "$work/small-np2/nav.jsonl"
alone=$(run "$work/tiny-one" one "$ontime" evaluate "$instance" --solver dp-rerun --episodes 1 --threads 1 --json)
launched=$(run "$work/tiny-np2" np2 "$ontime" evaluate "$instance" --solver dp-rerun --episodes 1 --threads 1 --json)
printf "\nCollection of 100 trials per action: one process %.2f s, mpirun -np 2 %.2f s: overhead %.2f s\n" \
  "$small_one" "$small_two" "$(echo "$small_two - $small_one / 2" | bc -l)"
printf "Launcher's own cost (mpirun -np 2 of a one-episode evaluation minus the same alone): %.2f s\n" \
  "$(echo "$launched - $alone" | bc -l)"
