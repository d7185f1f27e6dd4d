#!/usr/bin/python3
"""Draws PPO learning curves written by `ontime train`.

    plot_learning_curve.py CURVE.csv [CURVE.csv ...] OUT.png

Success rate of each epoch's training episodes (sampled choices) against the episodes seen,
one line per curve file, labelled by the file's name (shortened). Exit statuses: see
ontime_plotting.
"""

import os
import sys

# Sets the Agg backend: import it first.
from ontime_plotting import BadInput, bad_input, label, number, read_csv_rows, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402


def curve_label(path):
    name = os.path.basename(path)
    return label(name[: -len(".curve.csv")] if name.endswith(".curve.csv") else os.path.splitext(name)[0])


def main():
    argv = sys.argv
    if len(argv) < 3:
        raise BadInput("usage: plot_learning_curve.py CURVE.csv [CURVE.csv ...] OUT.png")
    fig, ax = plt.subplots(figsize=(6.8, 4.0))
    for path in argv[1:-1]:
        rows = read_csv_rows(path, ["episodes", "success_rate"])
        if not rows:
            raise bad_input(path, "no epochs to plot")
        episodes = [number(path, i, "episodes", row["episodes"], int) for i, row in enumerate(rows, 1)]
        success = [number(path, i, "success_rate", row["success_rate"]) for i, row in enumerate(rows, 1)]
        ax.plot(episodes, success, marker=".", label=curve_label(path))
    ax.set_xlabel("training episodes")
    ax.set_ylabel("success rate of the epoch's episodes")
    ax.set_ylim(0, 1.05)
    ax.grid(alpha=0.3)
    if len(argv) > 3:
        ax.legend(fontsize=8, loc="lower right")
    ax.set_title("PPO learning curves")
    fig.tight_layout()
    save_atomically(fig, argv[-1], dpi=130)


if __name__ == "__main__":
    run(main)
