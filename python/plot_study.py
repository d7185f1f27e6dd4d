#!/usr/bin/python3
"""Draws the computation-time studies of `ontime study` from their CSV files.

    plot_study.py compute-time|equal-time|anytime CSV PNG

compute-time (Fig. 4): total decision time per episode of mcts and dp-rerun, log scale.
equal-time   (Fig. 5): success of dp-rerun and of mcts held to dp-rerun's time per decision.
anytime      (Fig. 6): mcts success against log10 of the time multiplier, one panel per
                        instance, the exact optimum and dp-rerun as horizontal lines.

Instance labels are shortened for drawing. Exit statuses: see ontime_plotting.
"""

import sys

# Sets the Agg backend: import it first.
from ontime_plotting import BadInput, bad_input, label, number, read_csv_rows, run, save_atomically, shorten

import matplotlib.pyplot as plt  # noqa: E402

COLORS = {"mcts": "#c0504d", "dp-rerun": "#4f81bd", "optimum": "#333333"}


COLUMNS = {
    "compute-time": ["instance", "solver", "mean_episode_seconds", "success_rate"],
    "equal-time": ["instance", "dp_rerun_success_rate", "dp_rerun_ci95", "mcts_success_rate", "mcts_ci95",
                   "dp_rerun_decision_seconds"],
    "anytime": ["instance", "log10_multiplier", "success_rate", "ci95", "optimum", "dp_rerun_success_rate",
                "dp_rerun_decision_seconds"],
}


def read_rows(path, kind):
    """The rows, every number column checked."""
    rows = read_csv_rows(path, COLUMNS[kind])
    for row_number, row in enumerate(rows, 1):
        for column in COLUMNS[kind]:
            if column not in ("instance", "solver"):
                number(path, row_number, column, row[column])
    return rows


def instances_in_order(rows):
    seen = []
    for row in rows:
        if row["instance"] not in seen:
            seen.append(row["instance"])
    return seen


def compute_time(rows, png):
    instances = instances_in_order(rows)
    fig, ax = plt.subplots(figsize=(1.6 * len(instances) + 3, 4.2))
    width = 0.38
    for offset, solver in ((-width / 2, "mcts"), (width / 2, "dp-rerun")):
        values, labels = [], []
        for instance in instances:
            row = next((r for r in rows if r["instance"] == instance and r["solver"] == solver), None)
            if row is None:
                raise BadInput(f"no {solver} row for instance {shorten(instance)}")
            values.append(float(row["mean_episode_seconds"]))
            labels.append(f'{float(row["success_rate"]):.2f}')
        positions = [i + offset for i in range(len(instances))]
        bars = ax.bar(positions, values, width, label=solver, color=COLORS[solver])
        for bar, rate in zip(bars, labels):
            ax.annotate(rate, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center",
                        va="bottom", fontsize=8)
    ax.set_yscale("log")
    ax.set_xticks(range(len(instances)), [label(instance, 30) for instance in instances])
    ax.set_ylabel("decision time per episode (s, log scale)")
    ax.set_title("Meta-level computation per episode (labels: success rate)")
    ax.legend()
    fig.tight_layout()
    save_atomically(fig, png, dpi=130)


def equal_time(rows, png):
    instances = [row["instance"] for row in rows]
    fig, ax = plt.subplots(figsize=(1.6 * len(instances) + 3, 4.2))
    width = 0.38
    for offset, solver, prefix in ((-width / 2, "dp-rerun", "dp_rerun"), (width / 2, "mcts", "mcts")):
        rates = [float(row[f"{prefix}_success_rate"]) for row in rows]
        errors = [float(row[f"{prefix}_ci95"]) for row in rows]
        positions = [i + offset for i in range(len(instances))]
        ax.bar(positions, rates, width, yerr=errors, capsize=3, label=solver, color=COLORS[solver])
    labels = [f'{label(row["instance"], 30)}\n{float(row["dp_rerun_decision_seconds"]) * 1e9:.0f} ns' for row in rows]
    ax.set_xticks(range(len(instances)), labels)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("success rate (95% interval)")
    ax.set_title("Same time per decision as dp-rerun (below each instance)")
    ax.legend()
    fig.tight_layout()
    save_atomically(fig, png, dpi=130)


def anytime(rows, png):
    instances = instances_in_order(rows)
    columns = min(3, len(instances))
    lines = (len(instances) + columns - 1) // columns
    fig, axes = plt.subplots(lines, columns, figsize=(4.2 * columns, 3.3 * lines), squeeze=False)
    for index, instance in enumerate(instances):
        ax = axes[index // columns][index % columns]
        points = sorted((r for r in rows if r["instance"] == instance), key=lambda r: float(r["log10_multiplier"]))
        x = [float(r["log10_multiplier"]) for r in points]
        y = [float(r["success_rate"]) for r in points]
        e = [float(r["ci95"]) for r in points]
        ax.fill_between(x, [a - b for a, b in zip(y, e)], [a + b for a, b in zip(y, e)], color=COLORS["mcts"],
                        alpha=0.2, linewidth=0)
        ax.plot(x, y, marker="o", color=COLORS["mcts"], label="mcts")
        ax.axhline(float(points[0]["optimum"]), color=COLORS["optimum"], linestyle="--", label="exact optimum")
        ax.axhline(float(points[0]["dp_rerun_success_rate"]), color=COLORS["dp-rerun"], linestyle=":",
                   label="dp-rerun")
        base = float(points[0]["dp_rerun_decision_seconds"])
        ax.set_title(f"{label(instance, 30)} (base {base * 1e9:.0f} ns)", fontsize=10)
        ax.set_xlabel("log10 time multiplier")
        ax.set_ylabel("success rate")
        ax.set_ylim(0, 1.05)
        if index == 0:
            ax.legend(fontsize=8, loc="lower right")
    for index in range(len(instances), lines * columns):
        axes[index // columns][index % columns].axis("off")
    fig.suptitle("mcts with 10^m times dp-rerun's time per decision")
    fig.tight_layout()
    save_atomically(fig, png, dpi=130)


def main():
    argv = sys.argv
    if len(argv) != 4 or argv[1] not in COLUMNS:
        raise BadInput("usage: plot_study.py compute-time|equal-time|anytime CSV PNG")
    rows = read_rows(argv[2], argv[1])
    if not rows:
        raise bad_input(argv[2], "no rows to plot")
    {"compute-time": compute_time, "equal-time": equal_time, "anytime": anytime}[argv[1]](rows, argv[3])


if __name__ == "__main__":
    run(main)
