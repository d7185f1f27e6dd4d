#!/usr/bin/python3
"""Conditional time models on held-out worlds (docs/learning.md, "Held-out evaluation").

A family of generated worlds per domain (buildings for navigation, table scenes for the kitchen),
each world's options drawn from its seed. Training worlds are collected with features (buildings
move by move, kitchens along their skeletons); held-out worlds (other seeds, used for nothing but
this evaluation) are collected on their skeletons with many trials, which gives each its oracle (the
world's own fit) and the attempts to score. Then, for each model (hazard, boosted, pooled
Kaplan-Meier) and the oracle:

- per attempt: planning NLL, integrated Brier score and execution NLL of the prediction
  (`ontime score`);
- decision quality: the exact success probability, in the oracle instance, of dp-rerun (and the
  optimal allocator where its state cap allows) planning with each instance (`ontime evaluate
  --belief --exact`);
- online update: repeated episodes in each held-out world, dp-rerun planning with the prediction
  updated by every attempt made there (`ontime adapt`: the success rate of each episode over many
  independent sequences), the prior's strength fitted on
  validation worlds (`ontime fit-strength`: models fitted on the first 80% of the training worlds,
  strengths scored on the rest);
- navigation only, the whole TAMP loop (`ontime tamp`, the real planner, skeletons streamed by the
  task planner) in each held-out building with a library of every doorway move: collected there
  (the oracle), predicted by each model, each prediction updated across episodes
  (`--adapt-strength`), and first-found. scripts/tamp-learning.py measures the update there on
  paired episodes, in buildings of its own.

`--seeds FIRST-LAST --decisions-only` measures other worlds (a spent round, again with new
features) on the scores and dp-rerun alone.

Writes OUT/results.json, OUT/table.md and OUT/heldout.png. Every step is an `ontime` command; the
same settings give the same numbers (collections count collision checks, not seconds; the TAMP
loop runs on the modelled clock).
"""

import argparse
import json
import os
import random
import statistics
import subprocess
import sys

TRAIN_SEEDS = range(1001, 1051)
# The held-out worlds of each domain. Three earlier rounds of kitchens are held out no more: the
# analysis of 2001-2020 led to the kitchen's reach feature, 3001-3020 were seen with its first,
# linear form before the training worlds chose the log scale, and the failures of 4001-4020 led
# to the reach share's drawn layouts and finer floor. The kitchen's are 5001-5020.
HELD_OUT_SEEDS = {"navigation": range(2001, 2021), "manipulation": range(5001, 5021)}
LEARNED = ("hazard", "boosted", "pooled")
BELIEFS = (*LEARNED, "oracle")
NAMES = {"hazard": "hazard model", "boosted": "boosted model", "pooled": "pooled Kaplan-Meier",
         "oracle": "oracle (own fit)", "first-found": "first-found (no model)"}


def building(seed):
    """Options of one generated building. Chosen on training buildings 1001-1012 (docs/learning.md):
    3-4 x 3-4 rooms, many doors, a third to a half of them narrow in every building, so that
    paths of the same length differ in how hard their doors are."""
    draw = random.Random(seed)
    narrow_min = round(draw.uniform(0.74, 0.80), 3)
    wide_min = round(draw.uniform(1.0, 1.4), 3)
    empty = round(draw.uniform(0.0, 0.5), 2)
    return [
        "--rows", str(draw.choice((3, 3, 4))),
        "--cols", str(draw.choice((3, 3, 4))),
        "--door-density", str(round(draw.uniform(0.7, 1.0), 2)),
        "--narrow-doors", str(round(draw.uniform(0.25, 0.6), 2)),
        "--narrow-min", str(narrow_min),
        "--narrow-max", str(round(narrow_min + draw.uniform(0.01, 0.06), 3)),
        "--wide-min", str(wide_min),
        "--wide-max", str(round(wide_min + draw.uniform(0.0, 0.3), 3)),
        "--empty-rooms", str(empty),
        "--cluttered-rooms", str(round(draw.uniform(0.0, 1.0 - empty), 2)),
        "--min-boxes", "2",
        "--max-boxes", str(draw.choice((4, 6, 8, 10))),
        "--seed", str(seed),
    ]


def kitchen(seed):
    """Options of one generated kitchen. Chosen on training kitchens 1001-1012 (docs/learning.md):
    one target with two or three neighbours, or two with one or two each, at least one neighbour
    each, so that every kitchen has a choice of what to clear first; at most one region more than
    tables (more may leave no room on a table: two of the held-out seeds would draw no feasible
    scene)."""
    draw = random.Random(seed)
    targets = draw.choice((1, 2))
    max_clutter = draw.choice((2, 3)) if targets == 1 else draw.choice((1, 2))
    min_clutter = draw.randint(1, max_clutter)
    min_objects = targets * (1 + max_clutter) + draw.randint(0, 2)
    tables = draw.choice((2, 3)) if targets == 2 else draw.choice((1, 2, 3))
    return [
        "--domain", "manipulation",
        "--tables", str(tables),
        "--regions", str(draw.randint(2, min(4, 1 + tables))),  # (more regions than that may not fit)
        "--targets", str(targets),
        "--min-clutter", str(min_clutter),
        "--max-clutter", str(max_clutter),
        "--min-objects", str(min_objects),
        "--max-objects", str(min(16, min_objects + draw.randint(0, 2))),
        "--seed", str(seed),
    ]


DOMAINS = {
    # family, the prefix of its files, whether the training worlds are collected move by move
    "navigation": {"family": building, "stem": "building", "every_action": True},
    "manipulation": {"family": kitchen, "stem": "kitchen", "every_action": False},
}


class Runner:
    def __init__(self, args, mpi):
        self.args, self.ontime, self.out, self.mpi = args, args.ontime, args.out, mpi
        self.domain = DOMAINS[args.domain]

    def path(self, *parts):
        return os.path.join(self.out, *parts)

    def run(self, args, parallel=False, may_exceed=False):
        command = ([*self.mpi, self.ontime] if parallel and self.mpi else [self.ontime]) + [str(a) for a in args]
        result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=False)
        if may_exceed and result.returncode == 2 and "resource limit" in result.stderr:
            return None
        if result.returncode != 0:
            sys.exit(f"heldout: {' '.join(command)} failed ({result.returncode}): {result.stderr.strip()}")
        return result.stdout

    def json(self, args, may_exceed=False, parallel=False):
        text = self.run([*args, "--json"], may_exceed=may_exceed, parallel=parallel)
        return None if text is None else json.loads(text)

    def world(self, seed, held_out):
        world = self.path("worlds", f"{self.domain['stem']}-{seed}.json")
        if not os.path.exists(world):
            extra = ["--skeletons", str(self.args.skeletons)] if held_out and self.args.domain == "navigation" else []
            self.run(["generate-world", *self.domain["family"](seed), *extra, "-o", world])
        return world

    def deadline(self, world):
        """A held-out world's deadline: for a building, 4.5 steps per move of its shortest room path
        (time for its executions and quick refinements, not for slow narrow doors); for a kitchen,
        the generator's (20 steps per target)."""
        with open(world, encoding="utf-8") as text:
            data = json.load(text)
        if self.args.domain == "navigation":
            return round(self.args.steps_per_move * min(len(skeleton) for skeleton in data["skeletons"]))
        return data["collection"]["deadline"]

    def collect(self, world, trials, suffix, every_action, deadline=None):
        stem = os.path.splitext(os.path.basename(world))[0] + suffix
        log, instance = self.path("logs", stem + ".jsonl"), self.path("oracles", stem + ".json")
        if not os.path.exists(instance):
            extra = ["--every-action"] if every_action else []
            if deadline is not None:
                extra += ["--deadline", deadline]
            self.run(["collect", "--domain", self.args.domain, "--world", world, "--features", "--trials", trials,
                      "--log", log, "-o", instance, *extra], parallel=True)
        return log, instance

    def fit(self, logs, kind, name, step):
        model = self.path("models", name + ".json")
        if not os.path.exists(model):
            self.run(["fit", *logs, "--conditional", kind, "--domain", self.args.domain, "--step", step, "-o", model])
        return model


def train(args, runner):
    """Collects the first args.train training worlds, fits the three models on them and the online
    update's strength of each. Returns (training logs, models, strengths, step seconds)."""
    train_logs = []
    for i, seed in enumerate(TRAIN_SEEDS[: args.train]):
        print(f"training world {i + 1}/{args.train} (seed {seed})", file=sys.stderr)
        world = runner.world(seed, held_out=False)
        train_logs.append(runner.collect(world, args.train_trials, "", runner.domain["every_action"])[0])
    with open(runner.path("worlds", os.path.basename(runner.world(TRAIN_SEEDS[0], False))), encoding="utf-8") as text:
        step = json.load(text)["collection"]["step_seconds"]
    models = {kind: runner.fit(train_logs, kind, kind, step) for kind in LEARNED}

    # The prior's strength, on worlds the model was not fitted on: models of the first 80% of the
    # training worlds, strengths scored on the rest.
    split = max(1, (4 * len(train_logs)) // 5)
    strengths = {}
    for kind in LEARNED:
        model = runner.fit(train_logs[:split], kind, f"{kind}-validation", step)
        scored = runner.json(["fit-strength", *train_logs[split:], "--model", model, "--strengths",
                              "0.5,1,2,5,10,20,50,100,200,500"])
        strengths[kind] = scored["best"]
    return train_logs, models, strengths, step


def mean(values):
    values = [v for v in values if v is not None]
    return statistics.fmean(values) if values else None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--domain", choices=sorted(DOMAINS), default="navigation")
    parser.add_argument("--ontime", default="build/ontime")
    parser.add_argument("--out", help="output folder (default: heldout-DOMAIN)")
    parser.add_argument("--train", type=int, default=len(TRAIN_SEEDS), help="training worlds (first N seeds)")
    parser.add_argument("--held-out", type=int, default=20, help="held-out worlds (at most 20)")
    parser.add_argument("--train-trials", type=int, default=30, help="attempts per action of a training world")
    parser.add_argument("--oracle-trials", type=int, default=300, help="attempts per action of a held-out world")
    parser.add_argument("--skeletons", type=int, default=6, help="room paths of a held-out building")
    parser.add_argument("--steps-per-move", type=float, default=4.5, help="a held-out building's deadline per move")
    parser.add_argument("--optimal-states", type=int, default=3_000_000, help="state cap of the optimal allocator")
    parser.add_argument("--max-states", type=int, default=20_000_000, help="state cap of the exact evaluations")
    parser.add_argument("--sampled-episodes", type=int, default=20_000,
                        help="episodes of dp-rerun where its exact evaluation passes the cap")
    parser.add_argument("--adapt-episodes", type=int, default=10, help="episodes of the online update per world")
    parser.add_argument("--adapt-sequences", type=int, default=1000, help="independent sequences of them")
    parser.add_argument("--tamp-episodes", type=int, default=200, help="TAMP episodes per library and building")
    parser.add_argument("--tamp-sequences", type=int, default=20, help="TAMP sequences that learn, per building")
    parser.add_argument("--no-tamp", action="store_true", help="leave out the TAMP loop")
    parser.add_argument("--mpi", type=int, default=0, help="collect over this many MPI ranks (mpirun -np N)")
    parser.add_argument("--seeds", help="held-out worlds FIRST-LAST instead of the domain's (e.g. a spent round "
                        "measured again with new features); none may be a training seed")
    parser.add_argument("--decisions-only", action="store_true",
                        help="scores and dp-rerun only: no optimal allocator, online update or TAMP loop")
    args = parser.parse_args()
    held_out_seeds = HELD_OUT_SEEDS[args.domain]
    if args.seeds is not None:
        first, _, last = args.seeds.partition("-")
        if not (first.isdigit() and last.isdigit() and int(first) <= int(last)):
            parser.error(f"--seeds {args.seeds}: FIRST-LAST, two whole numbers, FIRST <= LAST")
        held_out_seeds = range(int(first), int(last) + 1)
        if set(held_out_seeds) & set(TRAIN_SEEDS):
            parser.error(f"--seeds {args.seeds}: overlaps the training worlds {TRAIN_SEEDS[0]}-{TRAIN_SEEDS[-1]}")
    args.out = args.out or f"heldout-{args.domain}"
    tamp = args.domain == "navigation" and not args.no_tamp and not args.decisions_only
    for folder in ("worlds", "logs", "oracles", "models", "predicted", "libraries"):
        os.makedirs(os.path.join(args.out, folder), exist_ok=True)
    mpi = ["mpirun", "--oversubscribe", "-np", str(args.mpi)] if args.mpi > 0 else []
    if mpi and os.geteuid() == 0:
        mpi.insert(1, "--allow-run-as-root")
    runner = Runner(args, mpi)

    train_logs, models, strengths, step = train(args, runner)

    # A run that was stopped continues: the worlds results.json already holds under the same
    # settings are kept, not measured again.
    worlds = []
    done = {}
    if os.path.exists(runner.path("results.json")):
        with open(runner.path("results.json"), encoding="utf-8") as text:
            previous = json.load(text)
        if previous.get("settings") == vars(args) and previous.get("strengths") == strengths:
            done = {w["seed"]: w for w in previous["worlds"]}
    for i, seed in enumerate(held_out_seeds[: args.held_out]):
        print(f"held-out world {i + 1}/{args.held_out} (seed {seed})", file=sys.stderr)
        if seed in done:
            worlds.append(done[seed])
            continue
        world = runner.world(seed, held_out=True)
        deadline = runner.deadline(world)
        log, oracle = runner.collect(world, args.oracle_trials, "", False, deadline)
        stem = os.path.splitext(os.path.basename(world))[0]
        instances = {"oracle": oracle}
        for kind in LEARNED:
            instances[kind] = runner.path("predicted", f"{stem}-{kind}.json")
            runner.run(["predict", "--domain", args.domain, "--world", world, "--model", models[kind],
                        "--deadline", deadline, "-o", instances[kind]])
        result = {"seed": seed, "family": runner.domain["family"](seed), "deadline": deadline, "scores": {},
                  "dp-rerun": {}, "optimal": {}, "adapt": {}, "tamp": {}, "tamp_adapt": {}}
        result["sampled"] = []
        for kind, instance in instances.items():
            result["scores"][kind] = runner.json(["score", instance, log])
            # The optimal allocator only where its state cap allows (None otherwise).
            evaluation = None if args.decisions_only else runner.json(
                ["evaluate", oracle, "--belief", instance, "--solver", "optimal", "--exact", "--episodes", 100,
                 "--no-timing", "--max-states", args.optimal_states], may_exceed=True)
            result["optimal"][kind] = None if evaluation is None else evaluation["exact_success_probability"]
            # dp-rerun exactly where the states its plan reaches fit under the cap; elsewhere (a
            # belief that spreads effort over many skeletons reaches many states) its success rate
            # over --sampled-episodes episodes, and the world is listed as sampled.
            evaluation = runner.json(["evaluate", oracle, "--belief", instance, "--solver", "dp-rerun", "--exact",
                                      "--episodes", 100, "--no-timing", "--max-states", args.max_states],
                                     may_exceed=True)
            if evaluation is not None:
                result["dp-rerun"][kind] = evaluation["exact_success_probability"]
            else:
                result["sampled"].append(f"dp-rerun {kind}")
                evaluation = runner.json(["evaluate", oracle, "--belief", instance, "--solver", "dp-rerun",
                                          "--episodes", args.sampled_episodes, "--no-timing"])
                result["dp-rerun"][kind] = evaluation["success_rate"]
            if kind != "oracle" and not args.decisions_only:
                # The success rate by episode over many sequences (an exact value per sequence and
                # episode would cost an exact evaluation of each posterior's plan).
                adapted = runner.json(["adapt", oracle, "--belief", instance, "--solver", "dp-rerun", "--strength",
                                       strengths[kind], "--episodes", args.adapt_episodes, "--sequences",
                                       args.adapt_sequences, "--no-exact"])
                result["adapt"][kind] = [s / args.adapt_sequences for s in adapted["successes"]]
        if tamp:
            _, library = runner.collect(world, args.oracle_trials, "-moves", True, deadline)
            libraries = {"oracle": library}
            for kind in LEARNED:
                libraries[kind] = runner.path("libraries", f"{stem}-{kind}.json")
                runner.run(["predict", "--domain", args.domain, "--world", world, "--model", models[kind],
                            "--deadline", deadline, "--library", "-o", libraries[kind]])
            common = ["tamp", "--world", world, "--deadline", step * deadline, "--clock", "model", "--seed", 1]
            for kind, library in libraries.items():
                done = runner.json([*common, "--library", library, "--solver", "dp-rerun",
                                    "--episodes", args.tamp_episodes])
                result["tamp"][kind] = done["success_rate"]
                if kind != "oracle":
                    done = runner.json([*common, "--library", library, "--solver", "dp-rerun",
                                        "--episodes", args.adapt_episodes, "--sequences", args.tamp_sequences,
                                        "--adapt-strength", strengths[kind]])
                    result["tamp_adapt"][kind] = [e["success_rate"] for e in done["adaptation"]["by_episode"]]
            done = runner.json([*common, "--library", libraries["oracle"], "--solver", "first-found",
                                "--episodes", args.tamp_episodes])
            result["tamp"]["first-found"] = done["success_rate"]
        worlds.append(result)
        with open(runner.path("results.json"), "w", encoding="utf-8") as out:
            json.dump({"settings": vars(args), "strengths": strengths, "worlds": worlds}, out, indent=1)

    summarise(args, runner, strengths, worlds, tamp)


def summarise(args, runner, strengths, worlds, tamp):
    solved = [w for w in worlds if all(w["optimal"][kind] is not None for kind in BELIEFS)]
    summary = {}
    for kind in BELIEFS:
        attempts = sum(w["scores"][kind]["attempts"] for w in worlds)
        executions = sum(w["scores"][kind]["executions"] for w in worlds)
        summary[kind] = {
            # Per attempt over every held-out attempt; success probabilities averaged over worlds.
            "planning_nll": sum(w["scores"][kind]["planning_nll"] * w["scores"][kind]["attempts"]
                                for w in worlds) / attempts,
            "integrated_brier": sum(w["scores"][kind]["integrated_brier"] * w["scores"][kind]["attempts"]
                                    for w in worlds) / attempts,
            "execution_nll": sum(w["scores"][kind]["execution_nll"] * w["scores"][kind]["executions"]
                                 for w in worlds) / executions,
            "dp-rerun": mean(w["dp-rerun"][kind] for w in worlds),
            # Over the worlds where the optimum was reached for all of them.
            "optimal": mean(w["optimal"][kind] for w in solved),
            "optimal_worlds": len(solved),
        }
        if kind != "oracle":
            summary[kind]["strength"] = strengths[kind]
        if kind != "oracle" and not args.decisions_only:
            summary[kind]["adapt"] = [mean(w["adapt"][kind][e] for w in worlds) for e in range(args.adapt_episodes)]
        if tamp:
            summary[kind]["tamp"] = mean(w["tamp"][kind] for w in worlds)
            if kind != "oracle":
                summary[kind]["tamp_adapt"] = [mean(w["tamp_adapt"][kind][e] for w in worlds)
                                               for e in range(args.adapt_episodes)]
    if tamp:
        summary["first-found"] = {"tamp": mean(w["tamp"]["first-found"] for w in worlds)}
    with open(runner.path("results.json"), "w", encoding="utf-8") as out:
        json.dump({"settings": vars(args), "strengths": strengths, "summary": summary, "worlds": worlds}, out, indent=1)

    lines = ["| distributions | planning NLL | integrated Brier | execution NLL | dp-rerun success | "
             f"optimal success ({len(solved)} of {len(worlds)} worlds) |",
             "|---|---|---|---|---|---|"]
    for kind in BELIEFS:
        s = summary[kind]
        lines.append(f"| {NAMES[kind]} | {s['planning_nll']:.4f} | {s['integrated_brier']:.4f} | "
                     f"{s['execution_nll']:.4f} | {s['dp-rerun']:.4f} | "
                     + (f"{s['optimal']:.4f} |" if s["optimal"] is not None else "- |"))
    sampled = [f"{w['seed']} ({', '.join(w['sampled'])})" for w in worlds if w.get("sampled")]
    lines.append("")
    lines.append("Sampled where the exact evaluation passed its state cap: "
                 + ("; ".join(sampled) if sampled else "none") + ".")
    oracle = summary["oracle"]["dp-rerun"]
    if not args.decisions_only:
        lines += ["", f"| prior (strength) | episode 1 | episode {args.adapt_episodes} | oracle | gap closed |",
                  "|---|---|---|---|---|"]
        for kind in LEARNED:
            s = summary[kind]
            first, last = s["adapt"][0], s["adapt"][-1]
            closed = f"{(last - first) / (oracle - first):.0%}" if oracle - first > 1e-9 else "-"
            lines.append(f"| {NAMES[kind]} ({s['strength']:g}) | {first:.4f} | {last:.4f} | {oracle:.4f} | {closed} |")
    if tamp:
        tail = max(1, args.adapt_episodes // 2)
        lines += ["", f"| library | TAMP success ({args.tamp_episodes} episodes per building) | learning: episode 1 | "
                      f"episodes {args.adapt_episodes - tail + 1}-{args.adapt_episodes} | gap closed |",
                  "|---|---|---|---|---|"]
        for kind in (*BELIEFS, "first-found"):
            s = summary[kind]
            if kind in LEARNED:
                curve = s["tamp_adapt"]
                late = statistics.fmean(curve[-tail:])
                gap = summary["oracle"]["tamp"] - curve[0]
                closed = f"{(late - curve[0]) / gap:.0%}" if gap > 0 else "-"
                lines.append(f"| {NAMES[kind]} | {s['tamp']:.4f} | {curve[0]:.4f} | {late:.4f} | {closed} |")
            else:
                lines.append(f"| {NAMES[kind]} | {s['tamp']:.4f} | | | |")
    table = "\n".join(lines) + "\n"
    with open(runner.path("table.md"), "w", encoding="utf-8") as out:
        out.write(table)
    print(table, end="")
    plot(args, runner, summary, worlds, tamp)


def plot(args, runner, summary, worlds, tamp):
    import matplotlib  # pylint: disable=import-outside-toplevel

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # pylint: disable=import-outside-toplevel

    panels = 1 if args.decisions_only else 3 if tamp else 2
    figure, axes = plt.subplots(1, panels, figsize=(5 * panels + 1, 3.6), squeeze=False,
                                gridspec_kw={"width_ratios": [3] + [2] * (panels - 1)})
    axes = axes[0]
    axis = axes[0]
    order = sorted(range(len(worlds)), key=lambda i: worlds[i]["dp-rerun"]["oracle"])
    for kind, marker in zip(BELIEFS, ("o", "D", "s", "^")):
        axis.plot(range(len(order)), [worlds[i]["dp-rerun"][kind] for i in order], marker=marker, linestyle="",
                  label=NAMES[kind])
    axis.set_xlabel("held-out world (by the oracle's success)")
    axis.set_ylabel("dp-rerun success (exact)")
    axis.set_title(args.domain)
    axis.legend(fontsize="small")
    episodes = range(1, args.adapt_episodes + 1)
    curves = [("adapt", "dp-rerun", "success, mean over worlds"), ("tamp_adapt", "tamp", "TAMP loop success, mean")]
    for axis, (key, reference, label) in zip(axes[1:], curves[: panels - 1]):
        for kind, marker in zip(LEARNED, ("o", "D", "s")):
            axis.plot(episodes, summary[kind][key], marker=marker, label=f"{NAMES[kind]}, updated")
        axis.axhline(summary["oracle"][reference], color="tab:red", linestyle="--", label=NAMES["oracle"])
        axis.set_xlabel("episode in the world")
        axis.set_ylabel(label)
        axis.legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(runner.path("heldout.png"), dpi=120)


if __name__ == "__main__":
    main()
