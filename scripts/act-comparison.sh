#!/usr/bin/env bash
# Plan first against acting while planning (SPEC §10): the exact optimum of every instance in both
# modes (`ontime solve --method memoised`, then `--act concurrent`), gathered into a CSV and drawn
# into a PNG by python/plot_act_comparison.py. Settings through the environment (defaults in
# brackets):
#   INSTANCES [the paper's Fig. 1 and instances 1-5]      SWEPT [data/instances/navigation.json]
#   DEADLINES [10,12,14,16]  (the deadlines at which SWEPT is solved, its own deadline replaced)
#   OUT [docs/images/act-comparison]  (writes OUT.csv and OUT.png)   ONTIME [build/ontime]
#   ALLOCATORS [dp-rerun,dp,greedy,round-robin,first-found,found-order-round-robin]  ALLOCATOR_DEADLINE [14]
#   (each allocator's exact value in both modes, `ontime evaluate --exact`, on INSTANCES but Fig. 1
#   and on SWEPT at ALLOCATOR_DEADLINE, written to OUT-allocators.csv; empty ALLOCATORS: none)
# Exact figures: they reproduce to the bit on any machine. Navigation at 16 steps takes about 40 s
# and 0.8 GB; its own deadline (22) is beyond the memoised solver of this mode.
set -euo pipefail
cd "$(dirname "$0")/.."
paper=data/instances/paper
INSTANCES=${INSTANCES:-$paper/figure1.json,$paper/instance1.json,$paper/instance2.json,$paper/instance3.json,$paper/instance4.json,$paper/instance5.json}
SWEPT=${SWEPT:-data/instances/navigation.json}
DEADLINES=${DEADLINES:-10,12,14,16}
ALLOCATORS=${ALLOCATORS-dp-rerun,dp,greedy,round-robin,first-found,found-order-round-robin}
ALLOCATOR_DEADLINE=${ALLOCATOR_DEADLINE:-14}
OUT=${OUT:-docs/images/act-comparison}
ONTIME=${ONTIME:-build/ontime}
if [ ! -x "$ONTIME" ]; then
  ./scripts/setup.sh
  ./scripts/build.sh
fi
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
IFS=, read -r -a instances <<< "$INSTANCES"
IFS=, read -r -a deadlines <<< "$DEADLINES"
with_deadline() {  # INSTANCE FILE, DEADLINE, COPY: a copy of the instance with its deadline replaced
  /usr/bin/python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); d["deadline"] = int(sys.argv[2]); json.dump(d, open(sys.argv[3], "w"))' \
    "$1" "$2" "$3"
}
solve_both() {  # INSTANCE FILE, LABEL
  echo "act-comparison: $2" >&2
  "$ONTIME" solve "$1" --method memoised --act plan-first --json > "$runs/$2.plan-first.json"
  "$ONTIME" solve "$1" --act concurrent --json > "$runs/$2.concurrent.json"
}
for instance in "${instances[@]}"; do
  solve_both "$instance" "$(basename "$instance" .json)"
done
if [ -n "$SWEPT" ]; then
  for deadline in "${deadlines[@]}"; do
    # The swept instance with its deadline replaced (a temporary copy; the original is untouched).
    with_deadline "$SWEPT" "$deadline" "$runs/swept-$deadline.json"
    solve_both "$runs/swept-$deadline.json" "$(basename "$SWEPT" .json)@$deadline"
  done
fi
/usr/bin/python3 - "$runs" "$OUT.csv" <<'PYTHON'
import glob, json, os, sys
rows = []
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.concurrent.json"))):
    label = os.path.basename(path)[: -len(".concurrent.json")]
    with open(path) as file:
        concurrent = json.load(file)
    with open(path.replace(".concurrent.json", ".plan-first.json")) as file:
        plan_first = json.load(file)
    key = "optimal_expected_reward" if "optimal_expected_reward" in concurrent else "optimal_success_probability"
    name, _, _ = label.partition("@")
    with open(concurrent["instance"]) as file:
        deadline = json.load(file)["deadline"]
    rows.append((name, deadline, plan_first[key], concurrent[key], plan_first["states"], concurrent["states"],
                 concurrent["seconds"]))
rows.sort(key=lambda row: (row[0], row[1]))
with open(sys.argv[2] + ".tmp", "w") as file:
    file.write("instance,deadline,plan_first,concurrent,plan_first_states,concurrent_states,concurrent_seconds\n")
    for row in rows:
        file.write("{},{},{:.6f},{:.6f},{},{},{:.2f}\n".format(*row))
os.replace(sys.argv[2] + ".tmp", sys.argv[2])
PYTHON
/usr/bin/python3 python/plot_act_comparison.py --data "$OUT.csv" --output "$OUT.png"
echo "act-comparison: wrote $OUT.csv and $OUT.png" >&2
[ -n "$ALLOCATORS" ] || exit 0

# Each allocator by its commit rule: the exact value of its policy in both modes (one episode is
# drawn too, as evaluate always runs some; only the exact values are kept).
IFS=, read -r -a allocators <<< "$ALLOCATORS"
valued=()
for instance in "${instances[@]}"; do
  [ "$(basename "$instance")" = figure1.json ] || valued+=("$instance")
done
if [ -n "$SWEPT" ]; then
  with_deadline "$SWEPT" "$ALLOCATOR_DEADLINE" "$runs/$(basename "$SWEPT" .json)-$ALLOCATOR_DEADLINE.json"
  valued+=("$runs/$(basename "$SWEPT" .json)-$ALLOCATOR_DEADLINE.json")
fi
for instance in "${valued[@]}"; do
  for allocator in "${allocators[@]}"; do
    echo "act-comparison: $allocator on $(basename "$instance" .json)" >&2
    for act in plan-first concurrent; do
      "$ONTIME" evaluate "$instance" --solver "$allocator" --act "$act" --episodes 1 --exact --json --no-timing \
        > "$runs/allocator.$(basename "$instance" .json).$allocator.$act.json"
    done
  done
done
/usr/bin/python3 - "$runs" "$OUT-allocators.csv" <<'PYTHON'
import glob, json, os, sys
rows = []
for path in sorted(glob.glob(os.path.join(sys.argv[1], "allocator.*.concurrent.json"))):
    _, instance, allocator, _, _ = os.path.basename(path).split(".")
    with open(path) as file:
        concurrent = json.load(file)
    with open(path.replace(".concurrent.json", ".plan-first.json")) as file:
        plan_first = json.load(file)
    key = "exact_expected_reward" if "exact_expected_reward" in concurrent else "exact_success_probability"
    rows.append((instance, allocator, plan_first[key], concurrent[key], concurrent["commit_rule"].split(":")[0].split()[0]))
with open(sys.argv[2] + ".tmp", "w") as file:
    file.write("instance,allocator,plan_first,concurrent,commit_rule\n")
    for row in rows:
        file.write('{},{},{:.6f},{:.6f},"{}"\n'.format(*row))
os.replace(sys.argv[2] + ".tmp", sys.argv[2])
PYTHON
echo "act-comparison: wrote $OUT-allocators.csv" >&2
