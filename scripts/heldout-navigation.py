#!/usr/bin/python3
"""Conditional time models on held-out buildings (docs/learning.md, "Held-out evaluation").

A family of generated buildings, each with its own door widths, narrow-door share, furniture and
size drawn from its seed. Training buildings are collected move by move with features; held-out
buildings (other seeds, used for nothing but this evaluation) are collected on their skeletons with
many trials, which gives each its oracle (the world's own fit) and the attempts to score. Then:

- per attempt: planning NLL, integrated Brier score and execution NLL of the hazard model's
  prediction, of pooled Kaplan-Meier, and of the oracle (`ontime score`);
- decision quality: the exact success probability, in the oracle instance, of dp-rerun (and the
  optimal allocator) planning with each instance (`ontime evaluate --belief --exact`);
- online update: repeated episodes in each held-out building, dp-rerun planning with the hazard
  model's (and pooled) prediction updated by every attempt made there (`ontime adapt`), the prior's
  strength fitted on validation buildings (`ontime fit-strength`: models fitted on the first 40
  training buildings, strengths scored on the last 10).

Writes OUT/results.json, OUT/table.md and OUT/decision.png. Every step is an `ontime` command; the
same settings give the same numbers (the collections count collision checks, not seconds).
"""

import argparse
import json
import os
import random
import statistics
import subprocess
import sys

TRAIN_SEEDS = range(1001, 1051)
HELD_OUT_SEEDS = range(2001, 2021)
MODELS = ("hazard", "pooled", "oracle")


def family(seed):
    """The building options of one seed: size, doors and furniture, widely varied."""
    draw = random.Random(seed)
    narrow_min = round(draw.uniform(0.72, 0.80), 3)
    wide_min = round(draw.uniform(0.92, 1.4), 3)
    empty = round(draw.uniform(0.0, 0.5), 2)
    return [
        "--rows", str(draw.choice((2, 3, 3, 4))),
        "--cols", str(draw.choice((2, 3, 3, 4))),
        "--door-density", str(round(draw.uniform(0.5, 1.0), 2)),
        "--narrow-doors", str(round(draw.uniform(0.0, 0.9), 2)),
        "--narrow-min", str(narrow_min),
        "--narrow-max", str(round(narrow_min + draw.uniform(0.01, 0.08), 3)),
        "--wide-min", str(wide_min),
        "--wide-max", str(round(wide_min + draw.uniform(0.0, 0.3), 3)),
        "--empty-rooms", str(empty),
        "--cluttered-rooms", str(round(draw.uniform(0.0, 1.0 - empty), 2)),
        "--min-boxes", "2",
        "--max-boxes", str(draw.choice((4, 6, 8, 10))),
        "--seed", str(seed),
    ]


class Runner:
    def __init__(self, ontime, out, mpi):
        self.ontime, self.out, self.mpi = ontime, out, mpi

    def path(self, *parts):
        return os.path.join(self.out, *parts)

    def run(self, args, parallel=False, may_exceed=False):
        command = ([*self.mpi, self.ontime] if parallel and self.mpi else [self.ontime]) + args
        result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=False)
        if may_exceed and result.returncode == 2 and "resource limit" in result.stderr:
            return None
        if result.returncode != 0:
            sys.exit(f"heldout-navigation: {' '.join(command)} failed ({result.returncode}): {result.stderr.strip()}")
        return result.stdout

    def json(self, args, may_exceed=False):
        text = self.run([*args, "--json"], may_exceed=may_exceed)
        return None if text is None else json.loads(text)

    def world(self, seed, skeletons):
        world = self.path("worlds", f"building-{seed}.json")
        if not os.path.exists(world):
            self.run(["generate-world", *family(seed), "--skeletons", str(skeletons), "-o", world])
        return world

    def collect(self, world, trials, every_action):
        stem = os.path.splitext(os.path.basename(world))[0]
        log = self.path("logs", stem + ".jsonl")
        instance = self.path("oracles", stem + ".json")
        if not os.path.exists(log):
            extra = ["--every-action"] if every_action else []
            self.run(["collect", "--domain", "navigation", "--world", world, "--features", "--trials", str(trials),
                      "--log", log, "-o", instance, *extra], parallel=True)
        return log, instance


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ontime", default="build/ontime")
    parser.add_argument("--out", default="heldout-navigation")
    parser.add_argument("--train", type=int, default=len(TRAIN_SEEDS), help="training buildings (first N seeds)")
    parser.add_argument("--held-out", type=int, default=len(HELD_OUT_SEEDS), help="held-out buildings")
    parser.add_argument("--train-trials", type=int, default=30, help="attempts per move of a training building")
    parser.add_argument("--oracle-trials", type=int, default=300, help="attempts per action of a held-out building")
    parser.add_argument("--skeletons", type=int, default=6, help="room paths of a held-out building")
    parser.add_argument("--episodes", type=int, default=2000, help="simulated episodes beside the exact value")
    parser.add_argument("--optimal-states", type=int, default=3_000_000, help="state cap of the optimal allocator")
    parser.add_argument("--adapt-episodes", type=int, default=10, help="episodes of the online update per building")
    parser.add_argument("--adapt-sequences", type=int, default=20, help="independent sequences of them")
    parser.add_argument("--mpi", type=int, default=0, help="collect over this many MPI ranks (mpirun -np N)")
    args = parser.parse_args()
    for folder in ("worlds", "logs", "oracles", "models", "predicted"):
        os.makedirs(os.path.join(args.out, folder), exist_ok=True)
    mpi = ["mpirun", "--oversubscribe", "-np", str(args.mpi)] if args.mpi > 0 else []
    if mpi and os.geteuid() == 0:
        mpi.insert(1, "--allow-run-as-root")
    runner = Runner(args.ontime, args.out, mpi)

    train_logs = []
    for i, seed in enumerate(TRAIN_SEEDS[: args.train]):
        print(f"training building {i + 1}/{args.train} (seed {seed})", file=sys.stderr)
        train_logs.append(runner.collect(runner.world(seed, 0), args.train_trials, every_action=True)[0])
    for kind in ("hazard", "pooled"):
        model = runner.path("models", kind + ".json")
        if not os.path.exists(model):
            runner.run(["fit", *train_logs, "--conditional", kind, "--domain", "navigation", "--step", "3",
                        "-o", model])

    # The prior's strength, on buildings the model was not fitted on: models of the first 80% of
    # the training buildings, strengths scored on the rest.
    split = max(1, (4 * len(train_logs)) // 5)
    strengths = {}
    for kind in ("hazard", "pooled"):
        model = runner.path("models", f"{kind}-validation.json")
        runner.run(["fit", *train_logs[:split], "--conditional", kind, "--domain", "navigation", "--step", "3",
                    "-o", model])
        scored = runner.json(["fit-strength", *train_logs[split:], "--model", model, "--strengths",
                              "0.5,1,2,5,10,20,50,100,200,500"])
        strengths[kind] = scored["best"]

    worlds = []
    for i, seed in enumerate(HELD_OUT_SEEDS[: args.held_out]):
        print(f"held-out building {i + 1}/{args.held_out} (seed {seed})", file=sys.stderr)
        world = runner.world(seed, args.skeletons)
        log, oracle = runner.collect(world, args.oracle_trials, every_action=False)
        instances = {"oracle": oracle}
        for kind in ("hazard", "pooled"):
            instances[kind] = runner.path("predicted", f"building-{seed}-{kind}.json")
            runner.run(["predict", "--domain", "navigation", "--world", world, "--model",
                        runner.path("models", kind + ".json"), "-o", instances[kind]])
        result = {"seed": seed, "family": family(seed), "scores": {}, "dp-rerun": {}, "optimal": {}, "adapt": {}}
        for kind, instance in instances.items():
            result["scores"][kind] = runner.json(["score", instance, log])
            for solver in ("dp-rerun", "optimal"):
                extra = ["--max-states", str(args.optimal_states)] if solver == "optimal" else []
                # The optimal allocator only where its state cap allows (None otherwise).
                evaluation = runner.json(["evaluate", oracle, "--belief", instance, "--solver", solver, "--exact",
                                          "--episodes", str(args.episodes), "--no-timing", *extra],
                                         may_exceed=solver == "optimal")
                result[solver][kind] = None if evaluation is None else evaluation["exact_success_probability"]
            if kind != "oracle":
                adapted = runner.json(["adapt", oracle, "--belief", instance, "--solver", "dp-rerun", "--strength",
                                       str(strengths[kind]), "--episodes", str(args.adapt_episodes), "--sequences",
                                       str(args.adapt_sequences)])
                result["adapt"][kind] = adapted["exact_success_probability"]
        worlds.append(result)

    solved = [w for w in worlds if all(w["optimal"][kind] is not None for kind in MODELS)]
    summary = {}
    for kind in MODELS:
        attempts = sum(w["scores"][kind]["attempts"] for w in worlds)
        summary[kind] = {
            # Per attempt over every held-out attempt; success probabilities averaged over worlds.
            "planning_nll": sum(w["scores"][kind]["planning_nll"] * w["scores"][kind]["attempts"]
                                for w in worlds) / attempts,
            "integrated_brier": sum(w["scores"][kind]["integrated_brier"] * w["scores"][kind]["attempts"]
                                    for w in worlds) / attempts,
            "execution_nll": sum(w["scores"][kind]["execution_nll"] * w["scores"][kind]["executions"]
                                 for w in worlds) / sum(w["scores"][kind]["executions"] for w in worlds),
            "dp-rerun": statistics.fmean(w["dp-rerun"][kind] for w in worlds),
            # Over the worlds where the optimum was reached for all three.
            "optimal": statistics.fmean(w["optimal"][kind] for w in solved) if solved else None,
            "optimal_worlds": len(solved),
        }
    for kind in ("hazard", "pooled"):
        # The exact value of the plan each episode starts with, averaged over the buildings.
        summary[kind]["adapt"] = [statistics.fmean(w["adapt"][kind][e] for w in worlds)
                                  for e in range(args.adapt_episodes)]
        summary[kind]["strength"] = strengths[kind]
    with open(runner.path("results.json"), "w", encoding="utf-8") as out:
        json.dump({"settings": vars(args), "summary": summary, "worlds": worlds}, out, indent=1)

    lines = ["| distributions | planning NLL | integrated Brier | execution NLL | dp-rerun success | "
             f"optimal success ({len(solved)} of {len(worlds)} buildings) |",
             "|---|---|---|---|---|---|"]
    names = {"hazard": "hazard model (predicted)", "pooled": "pooled Kaplan-Meier", "oracle": "oracle (own fit)"}
    for kind in MODELS:
        s = summary[kind]
        lines.append(f"| {names[kind]} | {s['planning_nll']:.4f} | {s['integrated_brier']:.4f} | "
                     f"{s['execution_nll']:.4f} | {s['dp-rerun']:.4f} | "
                     + (f"{s['optimal']:.4f} |" if s["optimal"] is not None else "- |"))
    lines += ["", f"| prior (strength) | episode 1 | episode {args.adapt_episodes} | oracle |", "|---|---|---|---|"]
    for kind in ("hazard", "pooled"):
        s = summary[kind]
        lines.append(f"| {names[kind]} ({s['strength']:g}) | {s['adapt'][0]:.4f} | {s['adapt'][-1]:.4f} | "
                     f"{summary['oracle']['dp-rerun']:.4f} |")
    table = "\n".join(lines) + "\n"
    with open(runner.path("table.md"), "w", encoding="utf-8") as out:
        out.write(table)
    print(table, end="")

    import matplotlib  # pylint: disable=import-outside-toplevel

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # pylint: disable=import-outside-toplevel

    figure, (axis, learning) = plt.subplots(1, 2, figsize=(11, 3.5), gridspec_kw={"width_ratios": [3, 2]})
    order = sorted(range(len(worlds)), key=lambda i: worlds[i]["dp-rerun"]["oracle"])
    for kind, marker in zip(MODELS, ("o", "s", "^")):
        axis.plot(range(len(order)), [worlds[i]["dp-rerun"][kind] for i in order], marker=marker, linestyle="",
                  label=names[kind])
    axis.set_xlabel("held-out building (by the oracle's success)")
    axis.set_ylabel("dp-rerun success (exact)")
    axis.legend()
    episodes = range(1, args.adapt_episodes + 1)
    for kind, marker in (("hazard", "o"), ("pooled", "s")):
        learning.plot(episodes, summary[kind]["adapt"], marker=marker, label=f"{names[kind]}, updated")
    learning.axhline(summary["oracle"]["dp-rerun"], color="tab:green", linestyle="--", label=names["oracle"])
    learning.set_xlabel("episode in the building")
    learning.set_ylabel("dp-rerun success (exact, mean)")
    learning.legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(runner.path("decision.png"), dpi=120)


if __name__ == "__main__":
    main()
