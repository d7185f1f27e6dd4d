"""Histograms of every action's planning and execution PMF, "never" as a bar of its own.

A dotted line marks the deadline; steps an instance lists beyond it are drawn too.

Reads the CSV that `ontime plot` writes (action,distribution,step,probability; step "never"
for the mass beyond every deadline) and draws one panel per action and distribution, planning
and execution side by side, into one PNG (written to a temporary file, then renamed). Labels
are shortened; at most MAX_ACTIONS_DRAWN actions are drawn (the title says so), and long step
ranges are drawn as one line per step with mass instead of a bar per step, so that any valid instance gives a
figure of bounded size. Exit statuses: see ontime_plotting.
"""

import argparse
import collections
import math

# Sets the Agg backend: import it first.
from ontime_plotting import TITLE_CHARACTERS, bad_input, label, number, read_csv_rows, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

PLANNING_COLOUR = "#3b6ea8"
EXECUTION_COLOUR = "#d08a2c"
NEVER_COLOUR = "#9b2f2f"
MAX_ACTIONS_DRAWN = 32  # 16 rows of 4 panels
MAX_BARS = 120  # steps drawn as separate bars; more are drawn as lines


def read_histograms(path):
    """action -> distribution -> ({step: probability}, never)."""
    data = collections.OrderedDict()
    for row_number, row in enumerate(read_csv_rows(path, ["action", "distribution", "step", "probability"]), 1):
        if row["distribution"] not in ("planning", "execution"):
            raise bad_input(path, f"row {row_number}: distribution must be planning or execution")
        entry = data.setdefault(row["action"], {}).setdefault(row["distribution"], [{}, 0.0])
        probability = number(path, row_number, "probability", row["probability"])
        if row["step"] == "never":
            entry[1] = probability
        else:
            step = number(path, row_number, "step", row["step"], int)
            if step < 0:
                raise bad_input(path, f"row {row_number}: step {step} is negative")
            entry[0][step] = probability
    return data


def draw_panel(axes, masses, never, deadline, colour, title, first_step):
    last = max([deadline] + list(masses))
    steps = list(range(first_step, last + 1))
    heights = [masses.get(step, 0.0) for step in steps]
    margin = len(steps) // 50  # keeps the first and last steps clear of the frame at any scale
    never_position = last + 2 + margin
    if len(steps) <= MAX_BARS:
        axes.bar(steps, heights, width=0.85, color=colour)
        ticks = [step for step in steps if step % 5 == 0 or step == first_step]
    else:
        # One line per step with mass: a single artist, and a lone spike stays visible at any width.
        spikes = [step for step in steps if masses.get(step, 0.0) > 0]
        axes.vlines(spikes, 0, [masses[step] for step in spikes], color=colour, linewidth=1)
        locator = MaxNLocator(nbins=5, integer=True)
        ticks = [int(tick) for tick in locator.tick_values(first_step, last) if first_step <= tick <= 0.9 * last]
    axes.bar([never_position], [never], width=max(0.85, len(steps) / 60), color=NEVER_COLOUR)
    if never > 0:
        axes.annotate(f"{never:.2f}", (never_position, never), ha="center", va="bottom", fontsize=6)
    axes.axvline(deadline + 0.5, color="grey", linestyle=":", linewidth=0.8)
    ticks.append(never_position)
    axes.set_xticks(ticks)
    axes.set_xticklabels([str(step) for step in ticks[:-1]] + ["never"], fontsize=7)
    axes.set_xlim(first_step - 1 - margin, never_position + 1 + margin)
    axes.set_ylim(0, 1.15 * max([never] + list(masses.values()) + [1e-9]))
    axes.tick_params(axis="y", labelsize=7)
    axes.set_title(title, fontsize=8)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--data", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--title", default="")
    parser.add_argument("--deadline", type=int, required=True)
    arguments = parser.parse_args()

    histograms = read_histograms(arguments.data)
    title = label(arguments.title, TITLE_CHARACTERS)
    if len(histograms) > MAX_ACTIONS_DRAWN:
        title += f" (first {MAX_ACTIONS_DRAWN} of {len(histograms)} actions; all are in the CSV)"
        histograms = collections.OrderedDict(list(histograms.items())[:MAX_ACTIONS_DRAWN])
    pairs_per_row = 2
    rows = max(1, math.ceil(len(histograms) / pairs_per_row))
    figure, grid = plt.subplots(rows, 2 * pairs_per_row, figsize=(4 * pairs_per_row * 2, 1.9 * rows + 0.8),
                                squeeze=False)
    for axes in grid.flat:
        axes.set_visible(False)
    for index, (action, distributions) in enumerate(histograms.items()):
        row, pair = divmod(index, pairs_per_row)
        for column, (kind, colour, first_step) in enumerate(
                [("planning", PLANNING_COLOUR, 1), ("execution", EXECUTION_COLOUR, 0)]):
            axes = grid[row][2 * pair + column]
            axes.set_visible(True)
            masses, never = distributions.get(kind, [{}, 1.0])
            draw_panel(axes, masses, never, arguments.deadline, colour, f"{label(action, 32)}: {kind}", first_step)
            if row == rows - 1 or index + pairs_per_row >= len(histograms):
                axes.set_xlabel("steps", fontsize=7)
    figure.suptitle(title, fontsize=11)
    figure.tight_layout(rect=(0, 0, 1, 0.97))

    save_atomically(figure, arguments.output)


if __name__ == "__main__":
    run(main)
