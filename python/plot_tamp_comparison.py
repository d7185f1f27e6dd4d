"""Success against deadline of the whole TAMP loop, one line per allocator with its 95% interval.

Reads the CSV that scripts/tamp-comparison.sh writes (columns solver, deadline_seconds,
success_rate, ci95, ...). The baselines that planners use today are drawn dashed. Exit statuses:
see ontime_plotting.
"""

import argparse

# Sets the Agg backend: import it first.
from ontime_plotting import TITLE_CHARACTERS, bad_input, label, number, read_csv_rows, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402

BASELINES = {"first-found", "found-order-round-robin", "round-robin", "greedy"}
COLUMNS = ["solver", "deadline_seconds", "success_rate", "ci95"]


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--data", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--title", default="Success against deadline")
    arguments = parser.parse_args()
    rows = read_csv_rows(arguments.data, COLUMNS)
    if not rows:
        raise bad_input(arguments.data, "no rows")
    curves = {}
    for row_number, row in enumerate(rows, 1):
        point = [number(arguments.data, row_number, column, row[column]) for column in COLUMNS[1:]]
        curves.setdefault(row["solver"], []).append(point)
    figure, axes = plt.subplots(figsize=(8, 5))
    for solver, points in curves.items():
        points.sort()
        deadlines = [point[0] for point in points]
        rates = [point[1] for point in points]
        half = [point[2] for point in points]
        style = "--" if solver in BASELINES else "-"
        line, = axes.plot(deadlines, rates, style, marker="o", markersize=4, label=solver)
        axes.fill_between(deadlines, [r - h for r, h in zip(rates, half)], [r + h for r, h in zip(rates, half)],
                          color=line.get_color(), alpha=0.15, linewidth=0)
    axes.set_xlabel("deadline (s)")
    axes.set_ylabel("success rate (95% interval shaded)")
    axes.set_ylim(-0.02, 1.02)
    axes.grid(alpha=0.3)
    axes.legend(fontsize=9)
    axes.set_title(label(arguments.title, TITLE_CHARACTERS), fontsize=10)
    figure.tight_layout()
    save_atomically(figure, arguments.output)


if __name__ == "__main__":
    run(main)
