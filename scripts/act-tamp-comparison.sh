#!/usr/bin/env bash
# Plan first against acting while planning (SPEC §10) in the whole TAMP loop (`ontime tamp`, docs/tamp.md):
# every allocator in both modes at every deadline, on the modelled clock, gathered into a CSV with one
# row per deadline, allocator and mode, and a summary of the best allocator of each mode per deadline.
# Settings through the environment (defaults in brackets):
#   WORLD [data/domains/building-6x5.json]  LIBRARY [data/instances/building-6x5-moves.json]
#   DEADLINES [120,150,180,240,300] (seconds)  EPISODES [300]  SEED [1]  THREADS [2]
#   ALLOCATORS [dp-rerun,greedy,round-robin,first-found]  OUT [docs/images/act-tamp-comparison] (writes OUT.csv)
#   ONTIME [build/ontime]
# On the modelled clock (`--clock model`) the figures reproduce to the episode on any machine and for
# any thread count.
set -euo pipefail
cd "$(dirname "$0")/.."
: "${WORLD:=data/domains/building-6x5.json}" "${LIBRARY:=data/instances/building-6x5-moves.json}"
: "${DEADLINES:=120,150,180,240,300}" "${EPISODES:=300}" "${SEED:=1}" "${THREADS:=2}"
: "${ALLOCATORS:=dp-rerun,greedy,round-robin,first-found}" "${OUT:=docs/images/act-tamp-comparison}"
: "${ONTIME:=build/ontime}"
[ -x "$ONTIME" ] || { ./scripts/setup.sh && ./scripts/build.sh; }
IFS=, read -r -a deadlines <<< "$DEADLINES"
IFS=, read -r -a allocators <<< "$ALLOCATORS"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
for deadline in "${deadlines[@]}"; do
  for allocator in "${allocators[@]}"; do
    for act in plan-first concurrent; do
      echo "act-tamp-comparison: $deadline s, $allocator, $act" >&2
      "$ONTIME" tamp --world "$WORLD" --library "$LIBRARY" --deadline "$deadline" --solver "$allocator" \
        --episodes "$EPISODES" --seed "$SEED" --threads "$THREADS" --clock model --act "$act" --json \
        > "$runs/$deadline.$allocator.$act.json"
    done
  done
done
/usr/bin/python3 - "$runs" "$OUT.csv" <<'PYTHON'
import glob, json, os, sys
rows = []
for path in glob.glob(os.path.join(sys.argv[1], "*.json")):
    deadline, allocator, act = os.path.basename(path)[: -len(".json")].split(".")
    with open(path) as file:
        run = json.load(file)
    rows.append((float(deadline), allocator, act, run["successes"], run["episodes"], run["success_rate"], run["ci95"]))
rows.sort()
with open(sys.argv[2], "w") as out:
    out.write("deadline_seconds,allocator,act,successes,episodes,success_rate,ci95\n")
    for row in rows:
        out.write("{:g},{},{},{},{},{:.4f},{:.4f}\n".format(*row))
print("deadline  best plan-first              best concurrent              gain")
for deadline in sorted({row[0] for row in rows}):
    best = {}
    for act in ("plan-first", "concurrent"):
        best[act] = max((row for row in rows if row[0] == deadline and row[2] == act), key=lambda row: row[5])
    plan, concurrent = best["plan-first"], best["concurrent"]
    print("{:>6g} s  {:<12} {:.4f} ± {:.4f}  {:<12} {:.4f} ± {:.4f}  {:+.4f}".format(
        deadline, plan[1], plan[5], plan[6], concurrent[1], concurrent[5], concurrent[6], concurrent[5] - plan[5]))
PYTHON
echo "act-tamp-comparison: wrote $OUT.csv" >&2
