#!/usr/bin/python3
"""Draws PPO learning curves written by `ontime train`.

    plot_learning_curve.py CURVE.csv [CURVE.csv ...] OUT.png

Success rate of each epoch's training episodes (sampled choices) against the episodes seen,
one line per curve file, labelled by the file's name.
"""

import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def label_of(path):
    name = os.path.basename(path)
    return name[: -len(".curve.csv")] if name.endswith(".curve.csv") else os.path.splitext(name)[0]


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    fig, ax = plt.subplots(figsize=(6.8, 4.0))
    for path in argv[1:-1]:
        with open(path, newline="") as handle:
            rows = list(csv.DictReader(handle))
        if not rows:
            sys.stderr.write(f"{path}: no epochs to plot\n")
            return 2
        episodes = [int(row["episodes"]) for row in rows]
        success = [float(row["success_rate"]) for row in rows]
        ax.plot(episodes, success, marker=".", label=label_of(path))
    ax.set_xlabel("training episodes")
    ax.set_ylabel("success rate of the epoch's episodes")
    ax.set_ylim(0, 1.05)
    ax.grid(alpha=0.3)
    if len(argv) > 3:
        ax.legend(fontsize=8, loc="lower right")
    ax.set_title("PPO learning curves")
    fig.tight_layout()
    fig.savefig(argv[-1], dpi=130)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
