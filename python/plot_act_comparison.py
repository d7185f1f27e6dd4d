"""Plan-first against acting while planning (SPEC §10): the exact optimum of each instance in both
modes, one pair of bars per instance, and along the deadline for the instances run at several.

Reads the CSV that scripts/act-comparison.sh writes (columns instance, deadline, plan_first,
concurrent, ...). Instances with one deadline are drawn as bars; an instance with several as two
lines against the deadline. Exit statuses: see ontime_plotting.
"""

import argparse

# Sets the Agg backend: import it first.
from ontime_plotting import TITLE_CHARACTERS, bad_input, label, number, read_csv_rows, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402

COLUMNS = ["instance", "deadline", "plan_first", "concurrent"]


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--data", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--title", default="Plan first against acting while planning: the exact optimum")
    arguments = parser.parse_args()
    rows = read_csv_rows(arguments.data, COLUMNS)
    if not rows:
        raise bad_input(arguments.data, "no rows")
    by_instance = {}
    for row_number, row in enumerate(rows, 1):
        point = [number(arguments.data, row_number, column, row[column]) for column in COLUMNS[1:]]
        by_instance.setdefault(row["instance"], []).append(point)
    single = {name: points[0] for name, points in by_instance.items() if len(points) == 1}
    swept = {name: sorted(points) for name, points in by_instance.items() if len(points) > 1}
    panels = (1 if single else 0) + len(swept)
    figure, axes = plt.subplots(1, panels, figsize=(5.5 * panels, 4.5), squeeze=False)
    panel = 0
    if single:
        bars = axes[0][panel]
        names = list(single)
        positions = range(len(names))
        bars.bar([p - 0.2 for p in positions], [single[n][1] for n in names], 0.4, label="plan first")
        bars.bar([p + 0.2 for p in positions], [single[n][2] for n in names], 0.4, label="acting while planning")
        bars.set_xticks(list(positions))
        bars.set_xticklabels([label(n, 20) for n in names], rotation=30, ha="right", fontsize=8)
        bars.set_ylabel("optimal success probability")
        bars.set_ylim(0, 1.05)
        bars.grid(axis="y", alpha=0.3)
        bars.legend(fontsize=8)
        panel += 1
    for name, points in swept.items():
        lines = axes[0][panel]
        deadlines = [point[0] for point in points]
        lines.plot(deadlines, [point[1] for point in points], "--", marker="o", markersize=4, label="plan first")
        lines.plot(deadlines, [point[2] for point in points], "-", marker="o", markersize=4,
                   label="acting while planning")
        lines.set_xlabel("deadline (steps)")
        lines.set_ylabel("optimal success probability")
        lines.set_ylim(-0.02, 1.02)
        lines.grid(alpha=0.3)
        lines.legend(fontsize=8)
        lines.set_title(label(name, 40), fontsize=9)
        panel += 1
    figure.suptitle(label(arguments.title, TITLE_CHARACTERS), fontsize=10)
    figure.tight_layout()
    save_atomically(figure, arguments.output)


if __name__ == "__main__":
    run(main)
