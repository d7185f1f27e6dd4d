#!/usr/bin/python3
"""Backtracking-aware against backtracking-ignorant allocation (docs/spec.md §7).

A planner log with backtrack records is fitted three ways:

- aware: `ontime fit` of the log as it is (backtracks are events of their own, with culprits);
- ignorant, cut off: today's model from the same log with every backtrack read as an attempt cut
  off when it gave up (the `backtrack` key removed);
- ignorant, longer: today's model with every backtracked attempt of an action folded into the
  action's next attempt in the log (its seconds added): one long attempt until a motion.

The log comes either from an instance with backtracking (INSTANCE ..., the truth: `ontime
sample-log` draws N attempts per action) or from a domain's real refiner that backtracks (`--world
FILE`: `ontime collect --domain manipulation`, N trials per action; the truth is then the aware fit,
and `ontime run` also drives the real refiner). For each belief and allocator (dp-rerun with its
three aggregations, optimal): the exact success probability in the truth of the allocator planning
with the belief (`ontime evaluate --belief --exact`), beside the truth's own optimum, and with
`--world` the success rate of the same allocator with the real refiner (`ontime run --belief`).
Writes OUT/results.json and OUT/table.md; every step is an `ontime` command, and the same seed
gives the same numbers.
"""

import argparse
import json
import os
import subprocess
import sys

BELIEFS = ("aware", "cut off", "longer")
SOLVERS = (("dp-rerun", "sum"), ("dp-rerun", "max"), ("dp-rerun", "self"), ("optimal", None))


def run(ontime, args):
    done = subprocess.run([ontime, *map(str, args)], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"backtracking-comparison: {' '.join(map(str, args))} failed: {done.stderr.strip()}")
    return done.stdout


def solver_args(solver, aggregation):
    return ["--solver", solver] + ([] if aggregation is None else ["--aggregation", aggregation])


def solver_name(solver, aggregation):
    return solver if aggregation is None else f"{solver} ({aggregation})"


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


def fit_beliefs(args, stem, log, skeletons, step, deadline, aware=None):
    """The three fits of `log` (`aware`: an existing aware fit to reuse); returns belief -> path."""
    with open(log, encoding="utf-8") as text:
        records = [json.loads(line) for line in text if line.strip()]
    logs = {"aware": log}
    for name, kept in ignorant_logs(records).items():
        logs[name] = os.path.join(args.out, f"{stem}-{name.replace(' ', '-')}.jsonl")
        with open(logs[name], "w", encoding="utf-8") as out:
            out.writelines(json.dumps(record) + "\n" for record in kept)
    fitted = {}
    for name, path in logs.items():
        if name == "aware" and aware is not None:
            fitted[name] = aware
            continue
        fitted[name] = os.path.join(args.out, f"{stem}-{name.replace(' ', '-')}.json")
        run(args.ontime, ["fit", path, "--step", step, "--deadline", deadline, "--skeletons", skeletons,
                          "-o", fitted[name]])
    return fitted


def exact_values(args, truth, fitted, row):
    row["optimum"] = json.loads(run(args.ontime, ["solve", truth, "--json"]))["optimal_success_probability"]
    for name, belief in fitted.items():
        for solver, aggregation in SOLVERS:
            evaluation = json.loads(run(args.ontime, ["evaluate", truth, "--belief", belief,
                                                      *solver_args(solver, aggregation), "--exact",
                                                      "--episodes", 100, "--no-timing", "--json"]))
            row[f"{solver_name(solver, aggregation)}, {name}"] = evaluation["exact_success_probability"]


def sampled_row(args, instance):
    stem = os.path.splitext(os.path.basename(instance))[0]
    with open(instance, encoding="utf-8") as text:
        truth = json.load(text)
    log = os.path.join(args.out, f"{stem}.jsonl")
    run(args.ontime, ["sample-log", instance, "--attempts", args.attempts, "--seed", args.seed, "-o", log])
    fitted = fit_beliefs(args, stem, log, instance, truth.get("step_seconds", 1.0), truth["deadline"])
    row = {"source": instance, "truth": instance}
    exact_values(args, instance, fitted, row)
    return row


def refiner_row(args, world):
    stem = os.path.splitext(os.path.basename(world))[0]
    log = os.path.join(args.out, f"{stem}.jsonl")
    aware = os.path.join(args.out, f"{stem}-aware.json")
    run(args.ontime, ["collect", "--domain", args.domain, "--world", world, "--trials", args.attempts,
                      "--seed", args.seed, "--log", log, "-o", aware])
    with open(aware, encoding="utf-8") as text:
        fit = json.load(text)
    fitted = fit_beliefs(args, stem, log, aware, fit["step_seconds"], fit["deadline"], aware=aware)
    row = {"source": world, "truth": aware, "episodes": args.episodes}
    exact_values(args, aware, fitted, row)
    for name, belief in fitted.items():
        for solver, aggregation in SOLVERS:
            result = json.loads(run(args.ontime, ["run", "--domain", args.domain, "--world", world,
                                                  "--instance", aware, "--belief", belief,
                                                  *solver_args(solver, aggregation), "--episodes", args.episodes,
                                                  "--seed", args.seed, "--json"]))
            key = f"{solver_name(solver, aggregation)}, {name}"
            row[f"{key}, real"] = result["success_rate"]
            row[f"{key}, real ci95"] = result["ci95"]
            row[f"{key}, backtracks"] = result["backtracks"]
    return row


def table(rows):
    solvers = [solver_name(solver, aggregation) for solver, aggregation in SOLVERS]
    lines = ["| source | allocator | optimum (truth) | " + " | ".join(BELIEFS) + " |", "|---" * (3 + len(BELIEFS)) + "|"]
    for row in rows:
        for solver in solvers:
            cells = []
            for belief in BELIEFS:
                cell = f"{row[f'{solver}, {belief}']:.4f}"
                if f"{solver}, {belief}, real" in row:
                    cell += f" (real {row[f'{solver}, {belief}, real']:.3f} ± {row[f'{solver}, {belief}, real ci95']:.3f})"
                cells.append(cell)
            lines.append(f"| {os.path.basename(row['source'])} | {solver} | {row['optimum']:.4f} | "
                         + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instances", nargs="*", help="instances with backtracking, the truth of sampled logs")
    parser.add_argument("--world", action="append", default=[],
                        help="a world whose real refiner backtracks (repeatable), e.g. data/domains/kitchen-grasps.json")
    parser.add_argument("--domain", default="manipulation", help="the domain of --world")
    parser.add_argument("--ontime", default="build/ontime")
    parser.add_argument("--out", default="backtracking-comparison")
    parser.add_argument("--attempts", type=int, default=20_000,
                        help="attempts per action of each sampled log; trials per action of each collection")
    parser.add_argument("--episodes", type=int, default=1000, help="--world: episodes of each run with the real refiner")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if not args.instances and not args.world:
        args.instances = ["data/instances/backtracking/grasp-and-place.json"]
    os.makedirs(args.out, exist_ok=True)
    rows = [sampled_row(args, instance) for instance in args.instances]
    rows += [refiner_row(args, world) for world in args.world]
    with open(os.path.join(args.out, "results.json"), "w", encoding="utf-8") as out:
        json.dump({"settings": vars(args), "rows": rows}, out, indent=1)
    text = table(rows)
    with open(os.path.join(args.out, "table.md"), "w", encoding="utf-8") as out:
        out.write(text)
    print(text, end="")


if __name__ == "__main__":
    main()
