#!/usr/bin/env bash
# Checks that OnTime split over MPI ranks gives the numbers of one process, to the byte, and
# loses no work when a rank dies:
#  1. a navigation collection of 50 trials per action (with features: a corpus's records) and an
#     evaluation of the fitted instance, as one process, under `mpirun -np 2`, and under SLURM (`sbatch` of the scripts here, whose
#     `srun --mpi=pmix` starts 2 tasks) on a single-node cluster brought up for the check
#     (slurm-up.sh); the logs, the fitted instances and the evaluations must be identical;
#  2. a rank killed in the middle of a 2-rank collection, and a 2-task SLURM job cancelled in
#     the middle of one: every rank's checkpoint is there, and `--resume` as one process (one
#     task) completes to the same files;
#  3. a usage error under mpirun and under srun: reported once, exit 2;
#  4. the layered exact solver on a cut of the kitchen (the paper's manipulation instance, its
#     first layers up to 300000 states, then a certified interval) and on navigation's fitted
#     instance: one process, `mpirun -np 2` and a 2-task job give the same output; on the coffee
#     building (exogenous chains, SPEC §9), one process and `mpirun -np 2`.
# Usage: scripts/cluster/check.sh [ONTIME]   (default build/ontime; needs root or sudo for SLURM)
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
ontime=$(realpath "${1:-build/ontime}")
work=$(mktemp -d)
slurm_dir="$work/slurm"
cleanup() {
  if [ -f "$slurm_dir/slurm.conf" ]; then "$root/scripts/cluster/slurm-down.sh" "$slurm_dir" || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

mpirun=(mpirun -np 2 --oversubscribe)
if [ "$(id -u)" -eq 0 ]; then mpirun+=(--allow-run-as-root); fi
world="$root/data/domains/navigation.json"
# With --features: the records of a corpus for conditional models (docs/learning.md) come out of
# the ranks as out of one process.
job_collect=(--domain navigation --world "$world" --trials 50 --seed 1 --features --log nav.jsonl
  --instance nav.json)
collect=(collect "${job_collect[@]}" --threads 1)
evaluate=(evaluate nav.json --solver dp-rerun --episodes 20000 --seed 1 --threads 1 --json --no-timing)
kitchen="$root/data/instances/manipulation.json"
cut=("$kitchen" --max-states 300000 --json --stats --no-timing)
solve_cut=(solve "${cut[@]}" --threads 1)
solve_nav=(solve nav.json --threads 1 --json --no-timing)
solve_chains=(solve "$root/data/instances/chains/coffee-building.json" --threads 1 --json --no-timing)

same() {  # same FILE...: each file of one/ equals the one in the other folders named after it
  local folder=$1
  shift
  for file in "$@"; do
    if ! cmp "$work/one/$file" "$work/$folder/$file"; then
      echo "cluster check: $folder/$file differs from one process's" >&2
      exit 1
    fi
  done
  echo "cluster check: $folder gives one process's $* byte for byte"
}

usage_error_once() {  # usage_error_once NAME LAUNCHER...: a bad --trials gives one message, exit 2
  local name=$1 code messages
  shift
  set +e
  "$@" "$ontime" collect --domain navigation --trials 0 > /dev/null 2> "$work/$name-usage.err"
  code=$?
  set -e
  messages=$(grep -c "^ontime: usage error" "$work/$name-usage.err" || true)
  if [ "$code" -ne 2 ] || [ "$messages" -ne 1 ]; then
    echo "cluster check: a usage error under $name gave exit $code and $messages messages" >&2
    cat "$work/$name-usage.err" >&2
    exit 1
  fi
  echo "cluster check: a usage error under $name is reported once, exit 2"
}
journal_lines() {  # journal_lines DIR: lines in the checkpoint files of DIR's collection
  (cat "$1"/nav.jsonl.checkpoint* 2> /dev/null || true) | wc -l
}
wait_for_journal() {  # wait_for_journal DIR: until its ranks have journaled some 300 trials (60 s at most)
  for _ in $(seq 1200); do
    if [ "$(journal_lines "$1")" -ge 300 ]; then return; fi
    sleep 0.05
  done
}

mkdir -p "$work/one" "$work/mpi" "$work/fault" "$work/slurm-run"
(cd "$work/one" && "$ontime" "${collect[@]}" > collect.txt && "$ontime" "${evaluate[@]}" > evaluate.json)
(cd "$work/one" && "$ontime" "${solve_cut[@]}" > solve-cut.json && "$ontime" "${solve_nav[@]}" > solve-nav.json)
(cd "$work/one" && "$ontime" "${solve_chains[@]}" > solve-chains.json)

# 1a. mpirun -np 2.
started=$(date +%s.%N)
(cd "$work/mpi" && "${mpirun[@]}" "$ontime" "${collect[@]}" > collect.txt)
echo "cluster check: mpirun -np 2 collection took $(echo "$(date +%s.%N) - $started" | bc) s"
(cd "$work/mpi" && "${mpirun[@]}" "$ontime" "${evaluate[@]}" > evaluate.json)
same mpi nav.jsonl nav.json evaluate.json
(cd "$work/mpi" && "${mpirun[@]}" "$ontime" "${solve_cut[@]}" > solve-cut.json)
(cd "$work/mpi" && "${mpirun[@]}" "$ontime" "${solve_nav[@]}" > solve-nav.json)
(cd "$work/mpi" && "${mpirun[@]}" "$ontime" "${solve_chains[@]}" > solve-chains.json)
same mpi solve-cut.json solve-nav.json solve-chains.json

# 2. A rank that dies: killed once the ranks have journaled some 300 trials between them.
(cd "$work/fault" && exec "${mpirun[@]}" "$ontime" "${collect[@]}" > collect.txt 2> collect.err) &
launcher=$!
wait_for_journal "$work/fault"
victim=$(pgrep -P "$launcher" -f "ontime collect" | tail -n 1 || true)
if [ -z "$victim" ]; then victim=$(pgrep -n -f "$ontime collect"); fi
kill -9 "$victim"
if wait "$launcher"; then
  echo "cluster check: the job went on without its killed rank" >&2
  exit 1
fi
parts=$(find "$work/fault" -name 'nav.jsonl.checkpoint*' | wc -l)
done_before=$(cat "$work/fault"/nav.jsonl.checkpoint* | grep -c '"action"' || true)
if [ "$parts" -ne 2 ] || [ -e "$work/fault/nav.jsonl" ]; then
  echo "cluster check: after the killed rank, expected 2 checkpoint files and no log, found: $(ls "$work/fault")" >&2
  exit 1
fi
(cd "$work/fault" && "$ontime" "${collect[@]}" --resume > resumed.txt)
if [ "$(find "$work/fault" -name 'nav.jsonl.checkpoint*' | wc -l)" -ne 0 ]; then
  echo "cluster check: the checkpoint files are left after the resumed collection" >&2
  exit 1
fi
grep -q "attempts were done before" "$work/fault/resumed.txt"
same fault nav.jsonl nav.json
echo "cluster check: a rank killed after $done_before journaled trials; resumed as one process"

# 3. A usage error under mpirun: one message, exit 2.
usage_error_once mpirun "${mpirun[@]}"

# 1b. SLURM: a single-node cluster, the sbatch scripts, srun --mpi=pmix with 2 tasks.
eval "$("$root/scripts/cluster/slurm-up.sh" "$slurm_dir")"
export ONTIME="$ontime"
sbatch --wait --ntasks 2 --chdir "$work/slurm-run" --output "$work/slurm-run/collect.out" \
  "$root/scripts/cluster/collect.sbatch" "${job_collect[@]}" > /dev/null
sbatch --wait --ntasks 2 --chdir "$work/slurm-run" --output "$work/slurm-run/evaluate.json" --error "$work/slurm-run/evaluate.err" \
  "$root/scripts/cluster/evaluate.sbatch" nav.json --solver dp-rerun --episodes 20000 --seed 1 --json \
  --no-timing > /dev/null
same slurm-run nav.jsonl nav.json evaluate.json
sbatch --wait --ntasks 2 --chdir "$work/slurm-run" --output "$work/slurm-run/solve-cut.json" \
  --error "$work/slurm-run/solve-cut.err" "$root/scripts/cluster/solve.sbatch" "${cut[@]}" > /dev/null
same slurm-run solve-cut.json
# A cancelled job: scancel once its ranks have journaled some 300 trials; resubmitted with
# --resume as a job of one task, it completes to the same files.
mkdir -p "$work/slurm-cancel"
job=$(sbatch --parsable --ntasks 2 --chdir "$work/slurm-cancel" --output "$work/slurm-cancel/collect.out" \
  "$root/scripts/cluster/collect.sbatch" "${job_collect[@]}")
wait_for_journal "$work/slurm-cancel"
scancel "$job"
for _ in $(seq 600); do
  if [ -z "$(squeue --noheader --jobs "$job" 2> /dev/null)" ]; then break; fi
  sleep 0.1
done
cancelled_at=$(journal_lines "$work/slurm-cancel")
if [ -e "$work/slurm-cancel/nav.jsonl" ] || [ "$cancelled_at" -eq 0 ]; then
  echo "cluster check: the cancelled job finished or left no checkpoint: $(ls "$work/slurm-cancel")" >&2
  exit 1
fi
sbatch --wait --ntasks 1 --chdir "$work/slurm-cancel" --output "$work/slurm-cancel/resumed.out" \
  "$root/scripts/cluster/collect.sbatch" "${job_collect[@]}" --resume > /dev/null
grep -q "attempts were done before" "$work/slurm-cancel/resumed.out"
same slurm-cancel nav.jsonl nav.json
echo "cluster check: a job cancelled after $cancelled_at journal lines, resumed as a job of one task"
usage_error_once srun srun --mpi=pmix -n 2
echo "cluster check: passed"
