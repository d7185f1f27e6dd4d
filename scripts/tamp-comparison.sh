#!/usr/bin/env bash
# Success against deadline of the whole TAMP loop (`ontime tamp`) for the allocators planners use
# today (first-found, found-order-round-robin) and OnTime's (dp-rerun, thompson, mcts): one
# `ontime tamp --json` run per allocator and deadline, gathered into a CSV and drawn into a PNG
# by python/plot_tamp_comparison.py. Settings through the environment (defaults in brackets):
#   WORLD [data/domains/building-6x5.json]   LIBRARY [data/instances/building-6x5-moves.json]
#   DEADLINES [120,150,180,210,240,300]       SOLVERS [first-found,found-order-round-robin,dp-rerun,thompson,mcts]
#   EPISODES [300]   SEED [1]
#   TAMP_OPTIONS [--max-skeletons 16 --task-seconds 0.5 --arrival-period 2 --clock model]
#   OUT [docs/images/tamp-comparison]  (writes OUT.csv and OUT.png)   ONTIME [build/ontime]
# mcts runs with --iterations 1000. The modelled clock charges thinking by its model (10 us per
# decision, 2 us per search iteration) and nothing real, so the figures reproduce to the episode
# on any machine; TAMP_OPTIONS without --clock model charges real thinking (see docs/tamp.md).
set -euo pipefail
cd "$(dirname "$0")/.."
WORLD=${WORLD:-data/domains/building-6x5.json}
LIBRARY=${LIBRARY:-data/instances/building-6x5-moves.json}
DEADLINES=${DEADLINES:-120,150,180,210,240,300}
SOLVERS=${SOLVERS:-first-found,found-order-round-robin,dp-rerun,thompson,mcts}
EPISODES=${EPISODES:-300}
SEED=${SEED:-1}
TAMP_OPTIONS=${TAMP_OPTIONS:---max-skeletons 16 --task-seconds 0.5 --arrival-period 2 --clock model}
OUT=${OUT:-docs/images/tamp-comparison}
ONTIME=${ONTIME:-build/ontime}
if [ ! -x "$ONTIME" ]; then
  ./scripts/setup.sh
  ./scripts/build.sh
fi
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
IFS=, read -r -a deadlines <<< "$DEADLINES"
IFS=, read -r -a solvers <<< "$SOLVERS"
for solver in "${solvers[@]}"; do
  extra=()
  if [ "$solver" = mcts ]; then extra=(--iterations 1000); fi
  for deadline in "${deadlines[@]}"; do
    echo "tamp-comparison: $solver, deadline $deadline s" >&2
    # shellcheck disable=SC2086  # TAMP_OPTIONS is a list of options
    "$ONTIME" tamp --world "$WORLD" --library "$LIBRARY" --deadline "$deadline" --solver "$solver" \
      "${extra[@]}" --episodes "$EPISODES" --seed "$SEED" $TAMP_OPTIONS --json > "$runs/$solver-$deadline.json"
  done
done
/usr/bin/python3 - "$runs" "$OUT.csv" <<'PYTHON'
import glob, json, os, sys
rows = []
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    with open(path) as file:
        run = json.load(file)
    rows.append((run["solver"], run["deadline_seconds"], run["success_rate"], run["ci95"], run["episodes"],
                 run["mean_skeletons_found"], run["mean_decision_seconds"], run["seconds"]))
rows.sort(key=lambda row: (row[0], row[1]))
with open(sys.argv[2] + ".tmp", "w") as file:
    file.write("solver,deadline_seconds,success_rate,ci95,episodes,mean_skeletons_found,mean_decision_seconds,"
               "run_seconds\n")
    for row in rows:
        file.write("{},{},{:.4f},{:.4f},{},{:.3f},{:.4f},{:.1f}\n".format(*row))
os.replace(sys.argv[2] + ".tmp", sys.argv[2])
PYTHON
/usr/bin/python3 python/plot_tamp_comparison.py --data "$OUT.csv" --output "$OUT.png" \
  --title "Whole TAMP loop on $(basename "$WORLD"): success against deadline ($EPISODES episodes each, seed $SEED)"
echo "tamp-comparison: wrote $OUT.csv and $OUT.png" >&2
