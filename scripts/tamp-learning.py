#!/usr/bin/python3
"""The online update in the TAMP loop, measured on paired episodes (docs/learning.md, "Online update
in the TAMP loop, paired").

In each held-out building (seeds of their own, used for nothing else) the whole TAMP loop (`ontime
tamp --clock model`: the task planner streams room paths, the real planner refines them, everything
on the modelled clock) runs with dp-rerun three ways on the same episode seeds:

- with the building's own library (300 attempts per doorway move: the oracle), without updates;
- with each model's predicted library, without updates;
- with each model's predicted library, updated after every episode by the attempts made in it
  (`--adapt-strength`, the strength fitted on training worlds as in scripts/heldout.py), in
  sequences of --episodes episodes.

Episode i of every run draws its planner and task-planner randomness from the same seed, so an
episode whose decisions the update leaves unchanged ends the same way with and without it: the
difference between the last two runs measures what the update gained, episode by episode, without
the noise of two independent samples. The gap it is measured against, the oracle's success rate
less the prediction's, is paired the same way.

The models come from the training worlds of scripts/heldout.py (collected and fitted in the same
--out folder when they are not there yet). Writes OUT/tamp-learning.json, OUT/tamp-learning.md and
OUT/tamp-learning.png.
"""

import argparse
import json
import math
import os
import statistics
import sys

import heldout

NAMES = heldout.NAMES


def parse_seeds(text):
    """'6001-6020' or '6001,6003': the held-out buildings."""
    seeds = []
    for part in text.split(","):
        first, _, last = part.partition("-")
        seeds += range(int(first), int(last or first) + 1)
    return seeds


def successes(document):
    return "".join("1" if e["status"] == "success" else "0" for e in document["episode_results"])


def measure(args, runner, strengths, models, seed):
    """One building's runs: the success (0/1) of every episode of every run, as strings of bits."""
    world = runner.world(seed, held_out=True)
    deadline = runner.deadline(world)
    stem = os.path.splitext(os.path.basename(world))[0]
    _, oracle = runner.collect(world, args.oracle_trials, "-moves", True, deadline)
    libraries = {}
    for kind in heldout.LEARNED:
        libraries[kind] = runner.path("libraries", f"{stem}-{kind}.json")
        runner.run(["predict", "--domain", "navigation", "--world", world, "--model", models[kind], "--deadline",
                    deadline, "--library", "-o", libraries[kind]])
    with open(oracle, encoding="utf-8") as text:
        step = json.load(text)["step_seconds"]
    total = args.episodes * args.sequences
    common = ["tamp", "--world", world, "--deadline", step * deadline, "--clock", "model", "--seed", args.seed,
              "--solver", "dp-rerun"]
    result = {"seed": seed, "family": heldout.building(seed), "deadline": deadline,
              "oracle": successes(runner.json([*common, "--library", oracle, "--episodes", total])),
              "fixed": {}, "updated": {}}
    for kind, library in libraries.items():
        result["fixed"][kind] = successes(runner.json([*common, "--library", library, "--episodes", total]))
        result["updated"][kind] = successes(runner.json(
            [*common, "--library", library, "--episodes", args.episodes, "--sequences", args.sequences,
             "--adapt-strength", strengths[kind]]))
        # A sequence's first episode plans with the prediction itself: the pairing holds only if it
        # ends as the fixed run's episode of the same seed does.
        fixed, updated = result["fixed"][kind], result["updated"][kind]
        if any(fixed[s * args.episodes] != updated[s * args.episodes] for s in range(args.sequences)):
            sys.exit(f"tamp-learning: building {seed}, {kind}: a sequence's first episode differs from the same "
                     "episode without updates; the runs are not paired")
    return result


def windows(args):
    """Episode windows of the table: 1, 2-5, then blocks of ten (episode numbers from 1)."""
    edges = [1, 2, 6] + list(range(11, args.episodes + 1, 10)) + [args.episodes + 1]
    edges = sorted({e for e in edges if e <= args.episodes + 1})
    return list(zip(edges[:-1], edges[1:]))


def summarise(args, worlds, strengths):
    """Per model: the gap (oracle less prediction, every episode paired) and, per episode window,
    the gain of the update (updated less fixed, paired per sequence), averaged over buildings, with
    standard errors from the spread between sequences (gain) and between episodes (gap)."""
    count, length = len(worlds), args.episodes
    summary = {}
    for kind in heldout.LEARNED:
        gap_means, gap_vars, gains = [], [], []
        for w in worlds:
            paired = [int(o) - int(f) for o, f in zip(w["oracle"], w["fixed"][kind])]
            gap_means.append(statistics.fmean(paired))
            gap_vars.append(statistics.variance(paired) / len(paired))
            # The update's gain in each episode of each sequence: gains[world][sequence][episode].
            fixed, updated = w["fixed"][kind], w["updated"][kind]
            gains.append([[int(updated[s * length + e]) - int(fixed[s * length + e]) for e in range(length)]
                          for s in range(args.sequences)])
        by_episode = [sum(sum(row[e] for row in world) / args.sequences / count for world in gains)
                      for e in range(length)]
        gap = statistics.fmean(gap_means)
        rows = []
        for first, end in windows(args):
            variance = sum(statistics.variance([statistics.fmean(row[first - 1:end - 1]) for row in world])
                           / args.sequences for world in gains)
            gain = statistics.fmean(by_episode[first - 1:end - 1])
            rows.append({"episodes": [first, end - 1], "gain": gain, "gain_se": math.sqrt(variance) / count,
                         "closed": gain / gap if gap > 0 else None})
        summary[kind] = {
            "strength": strengths[kind],
            "fixed": statistics.fmean(statistics.fmean(int(b) for b in w["fixed"][kind]) for w in worlds),
            "oracle": statistics.fmean(statistics.fmean(int(b) for b in w["oracle"]) for w in worlds),
            "gap": gap, "gap_se": math.sqrt(sum(gap_vars)) / count,
            "gain_by_episode": by_episode, "windows": rows,
            "buildings_with_a_gap": sum(1 for g in gap_means if g > 0),
        }
    return summary


def table(args, summary, count):
    spans = [f"episode {a}" if a == b else f"episodes {a}-{b}"
             for a, b in (row["episodes"] for row in summary["hazard"]["windows"])]
    lines = [f"{count} held-out buildings, {args.sequences} sequences of {args.episodes} episodes each, "
             "dp-rerun, every run on the same episode seeds.", "",
             "| prediction (strength) | fixed | oracle | gap | " + " | ".join(f"closed, {s}" for s in spans)
             + " |", "|---|---|---|---|" + "---|" * len(spans)]
    for kind in heldout.LEARNED:
        s = summary[kind]
        cells = [f"{row['closed']:.0%} ({row['gain']:+.4f} ± {1.96 * row['gain_se']:.4f})"
                 if row["closed"] is not None else f"- ({row['gain']:+.4f})" for row in s["windows"]]
        lines.append(f"| {NAMES[kind]} ({s['strength']:g}) | {s['fixed']:.4f} | {s['oracle']:.4f} | "
                     f"{s['gap']:.4f} ± {1.96 * s['gap_se']:.4f} | " + " | ".join(cells) + " |")
    lines += ["", "fixed: the prediction's success rate without updates; gap: the oracle's less that, paired per "
              "episode; closed: the update's gain (updated less fixed, paired) over the gap; ± 95% "
              "(1.96 standard errors)."]
    return "\n".join(lines) + "\n"


def plot(args, summary, path):
    import matplotlib  # pylint: disable=import-outside-toplevel

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # pylint: disable=import-outside-toplevel

    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 3.8))
    episodes = range(1, args.episodes + 1)
    for kind, marker in zip(heldout.LEARNED, ("o", "D", "s")):
        s = summary[kind]
        left.plot(episodes, [s["fixed"] + g for g in s["gain_by_episode"]], marker=marker, markersize=3,
                  label=f"{NAMES[kind]} ({s['strength']:g}), updated")
        if s["gap"] > 0:
            right.plot(episodes, [g / s["gap"] for g in s["gain_by_episode"]], marker=marker, markersize=3,
                       label=f"{NAMES[kind]} (gap {s['gap']:.3f})")
    left.axhline(summary["hazard"]["oracle"], color="tab:red", linestyle="--", label=NAMES["oracle"])
    left.set_xlabel("episode in the building")
    left.set_ylabel("TAMP loop success, mean over buildings")
    left.set_title("dp-rerun, prediction updated after every episode")
    left.legend(fontsize="small")
    right.axhline(0.5, color="tab:gray", linestyle=":", label="half the gap")
    right.axhline(1.0, color="tab:red", linestyle="--", label="oracle")
    right.set_xlabel("episode in the building")
    right.set_ylabel("share of the gap closed (paired)")
    right.set_title("where the prediction has a gap to the oracle")
    right.legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ontime", default="build/ontime")
    parser.add_argument("--out", default="heldout-navigation",
                        help="folder of scripts/heldout.py's navigation run (its training worlds and models)")
    parser.add_argument("--seeds", default="6001-6020", help="held-out buildings (e.g. 6001-6020)")
    parser.add_argument("--episodes", type=int, default=50, help="episodes of one sequence in a building")
    parser.add_argument("--sequences", type=int, default=40, help="independent sequences per building")
    parser.add_argument("--oracle-trials", type=int, default=300, help="attempts per doorway move of the oracle")
    parser.add_argument("--seed", type=int, default=1, help="seed of the episodes")
    parser.add_argument("--train", type=int, default=len(heldout.TRAIN_SEEDS), help="training worlds")
    parser.add_argument("--train-trials", type=int, default=30, help="attempts per move of a training world")
    parser.add_argument("--skeletons", type=int, default=6, help="room paths of a held-out building")
    parser.add_argument("--steps-per-move", type=float, default=4.5, help="a held-out building's deadline per move")
    parser.add_argument("--replace", action="store_true",
                        help="replace the results of a run of other settings in --out (else refused)")
    args = parser.parse_args()
    if args.episodes < 1 or args.sequences < 2:
        parser.error("--episodes must be at least 1 and --sequences at least 2")
    try:
        seeds = parse_seeds(args.seeds)
    except ValueError:
        parser.error(f"--seeds {args.seeds!r}: expected FIRST-LAST or a comma-separated list of seeds")
    overlap = sorted(set(seeds) & (set(heldout.TRAIN_SEEDS) | set(heldout.HELD_OUT_SEEDS["navigation"])))
    if overlap:
        parser.error(f"--seeds: {overlap[0]} is a training or held-out building of scripts/heldout.py")
    args.domain = "navigation"
    for folder in ("worlds", "logs", "oracles", "models", "libraries"):
        os.makedirs(os.path.join(args.out, folder), exist_ok=True)
    runner = heldout.Runner(args, [])
    _, models, strengths, _ = heldout.train(args, runner)

    # A run that was stopped continues with the buildings it measured under the same settings.
    results = os.path.join(args.out, "tamp-learning.json")
    settings = {k: v for k, v in vars(args).items() if k not in ("ontime", "out", "replace")}
    done = {}
    if os.path.exists(results):
        with open(results, encoding="utf-8") as text:
            previous = json.load(text)
        if previous.get("settings") == settings and previous.get("strengths") == strengths:
            done = {w["seed"]: w for w in previous["worlds"]}
        elif not args.replace:
            print(f"tamp-learning: {results} holds a run of other settings or models; pass --replace to "
                  "measure anew there, or another --out", file=sys.stderr)
            sys.exit(2)
    worlds = []
    for i, seed in enumerate(seeds):
        print(f"held-out building {i + 1}/{len(seeds)} (seed {seed})", file=sys.stderr)
        worlds.append(done[seed] if seed in done else measure(args, runner, strengths, models, seed))
        with open(results, "w", encoding="utf-8") as out:
            json.dump({"settings": settings, "strengths": strengths, "worlds": worlds}, out)

    summary = summarise(args, worlds, strengths)
    with open(results, "w", encoding="utf-8") as out:
        json.dump({"settings": settings, "strengths": strengths, "summary": summary, "worlds": worlds}, out)
    text = table(args, summary, len(worlds))
    with open(os.path.join(args.out, "tamp-learning.md"), "w", encoding="utf-8") as out:
        out.write(text)
    print(text, end="")
    plot(args, summary, os.path.join(args.out, "tamp-learning.png"))


if __name__ == "__main__":
    main()
