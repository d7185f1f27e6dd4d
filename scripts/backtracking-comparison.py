#!/usr/bin/python3
"""Backtracking-aware against backtracking-ignorant allocation (docs/spec.md §7), exactly.

For each instance (the truth, with backtracking, SPEC §7): a planner log of N attempts per action is
drawn from it (`ontime sample-log`, backtrack records included) and fitted three ways:

- aware: `ontime fit` of the log as it is (backtracks are events of their own, with culprits);
- ignorant, cut off: today's model from the same log with every backtrack read as an attempt cut
  off when it gave up (the `backtrack` key removed);
- ignorant, longer: today's model with every backtracked attempt of an action folded into the
  action's next attempt in the log (its seconds added): one long attempt until a motion.

Then the exact success probability, in the truth, of dp-rerun and of the optimal allocator
planning with each (`ontime evaluate --belief --exact`), beside the truth's own optimum. Writes
OUT/results.json and OUT/table.md; every step is an `ontime` command and the same seed gives the
same numbers.
"""

import argparse
import json
import os
import subprocess
import sys

BELIEFS = ("aware", "cut off", "longer")


def run(ontime, args):
    done = subprocess.run([ontime, *map(str, args)], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"backtracking-comparison: {' '.join(map(str, args))} failed: {done.stderr.strip()}")
    return done.stdout


def ignorant_logs(records):
    """The two backtracking-ignorant readings of a log's records."""
    cut_off, longer, carried = [], [], {}
    for record in records:
        plain = {key: value for key, value in record.items() if key != "backtrack"}
        cut_off.append(plain)
        action = record["action"]
        if "backtrack" in record:
            carried[action] = carried.get(action, 0.0) + record["planning_seconds"]
            continue
        plain = dict(plain)
        plain["planning_seconds"] += carried.pop(action, 0.0)
        longer.append(plain)
    for action, seconds in carried.items():  # backtracks at the end of the log: cut off there
        longer.append({"action": action, "planning_seconds": seconds, "found": False})
    return {"cut off": cut_off, "longer": longer}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instances", nargs="*", default=["data/instances/backtracking/grasp-and-place.json"])
    parser.add_argument("--ontime", default="build/ontime")
    parser.add_argument("--out", default="backtracking-comparison")
    parser.add_argument("--attempts", type=int, default=20_000, help="attempts per action of each log")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for instance in args.instances:
        stem = os.path.splitext(os.path.basename(instance))[0]
        with open(instance, encoding="utf-8") as text:
            truth = json.load(text)
        step, deadline = truth.get("step_seconds", 1.0), truth["deadline"]
        log = os.path.join(args.out, f"{stem}.jsonl")
        run(args.ontime, ["sample-log", instance, "--attempts", args.attempts, "--seed", args.seed, "-o", log])
        with open(log, encoding="utf-8") as text:
            records = [json.loads(line) for line in text if line.strip()]
        logs = {"aware": log}
        for name, kept in ignorant_logs(records).items():
            logs[name] = os.path.join(args.out, f"{stem}-{name.replace(' ', '-')}.jsonl")
            with open(logs[name], "w", encoding="utf-8") as out:
                out.writelines(json.dumps(record) + "\n" for record in kept)
        row = {"instance": instance,
               "optimum": json.loads(run(args.ontime, ["solve", instance, "--json"]))["optimal_success_probability"]}
        for name, path in logs.items():
            fitted = os.path.join(args.out, f"{stem}-{name.replace(' ', '-')}.json")
            run(args.ontime, ["fit", path, "--step", step, "--deadline", deadline, "--skeletons", instance, "-o", fitted])
            for solver in ("dp-rerun", "optimal"):
                evaluation = json.loads(run(args.ontime, ["evaluate", instance, "--belief", fitted, "--solver", solver,
                                                          "--exact", "--episodes", 100, "--no-timing", "--json"]))
                row[f"{solver} {name}"] = evaluation["exact_success_probability"]
        rows.append(row)
    with open(os.path.join(args.out, "results.json"), "w", encoding="utf-8") as out:
        json.dump({"settings": vars(args), "rows": rows}, out, indent=1)
    lines = ["| instance | optimum (truth) | " + " | ".join(f"{s}, {b}" for s in ("dp-rerun", "optimal") for b in BELIEFS)
             + " |", "|---" * 8 + "|"]
    for row in rows:
        lines.append(f"| {os.path.basename(row['instance'])} | {row['optimum']:.4f} | "
                     + " | ".join(f"{row[f'{s} {b}']:.4f}" for s in ("dp-rerun", "optimal") for b in BELIEFS) + " |")
    table = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "table.md"), "w", encoding="utf-8") as out:
        out.write(table)
    print(table, end="")


if __name__ == "__main__":
    main()
