"""The timeline of one live episode: a lane per skeleton, time in seconds left to right.

Reads the CSV that `ontime run --effort wall --timeline` writes (one row per step: skeleton,
action, start, outside_seconds, decision_seconds, planning_seconds, overrun_seconds,
observe_seconds, refined, execution_seconds, and optionally lane, execution_start,
execution_end) and draws, for each step, the allocator's thinking
(grey: its choice before the call, taking in the outcome after), the planner's slice
(the skeleton's colour) with its overrun beyond the slice hatched in red, a star where a motion
was found, and the execution of the plan that succeeded (dark, thin) after the last step. Rows of
lane "execution" (the robot's motions, from start to end) are drawn in a lane of their own, the
robot's, below the skeletons, on the same time axis; rows of lane "start" (the robot starting a
motion while the planner works, SPEC §10) draw their decision there. Dotted lines mark the step
boundaries of the model, a solid line the deadline. Exit statuses: see ontime_plotting.
"""

import argparse

# Sets the Agg backend: import it first.
from ontime_plotting import TITLE_CHARACTERS, bad_input, label, number, read_csv_rows, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

THINKING_COLOUR = "#8c8c8c"
OVERRUN_COLOUR = "#c0392b"
EXECUTION_COLOUR = "#303030"
MAX_LANES = 24  # skeletons drawn as lanes; steps of others share the last lane


def read_steps(path):
    columns = [
        "skeleton",
        "action",
        "start",
        "outside_seconds",
        "decision_seconds",
        "planning_seconds",
        "overrun_seconds",
        "observe_seconds",
        "refined",
        "execution_seconds",
    ]
    steps = []
    for row_number, row in enumerate(read_csv_rows(path, columns), 1):
        step = {"action": row["action"]}
        step["skeleton"] = number(path, row_number, "skeleton", row["skeleton"], int)
        for column in columns[2:8] + ["execution_seconds"]:
            step[column] = number(path, row_number, column, row[column])
            if step[column] < 0:
                raise bad_input(path, f"row {row_number}: {column} must be >= 0")
        step["refined"] = number(path, row_number, "refined", row["refined"], int) == 1
        step["lane"] = row.get("lane") or "planning"
        if step["lane"] not in ("planning", "start", "execution"):
            raise bad_input(path, f"row {row_number}: lane must be planning, start or execution")
        if step["lane"] != "planning":
            for column in ("execution_start", "execution_end"):
                step[column] = number(path, row_number, column, row.get(column) or "")
        steps.append(step)
    return steps


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--title", default="")
    parser.add_argument("--deadline", type=float, required=True)
    parser.add_argument("--step", type=float, required=True)
    parser.add_argument("--skeletons", type=int, required=True)
    parser.add_argument("--solution", type=int, default=-1, help="the skeleton executed, -1: none")
    parser.add_argument("--execution", type=float, default=0.0, help="its execution seconds")
    arguments = parser.parse_args()
    steps = read_steps(arguments.data)
    executions = [step for step in steps if step["lane"] == "execution"]
    acting = any(step["lane"] == "start" for step in steps)  # the robot acted while planning
    lanes = min(arguments.skeletons, MAX_LANES)
    robot = lanes if executions else None  # the robot's lane, below the skeletons'
    colours = plt.get_cmap("tab10")

    figure, axes = plt.subplots(figsize=(9.0, 1.2 + 0.42 * (lanes + (1 if executions else 0))))
    end = 0.0
    reported = 0.0  # the last planner call's end
    for execution in executions:
        axes.broken_barh(
            [(execution["execution_start"], execution["execution_end"] - execution["execution_start"])],
            (robot - 0.3, 0.6),
            color=EXECUTION_COLOUR,
            edgecolor="white",
        )
        axes.annotate(
            label(execution["action"], 24),
            (execution["execution_start"], robot + 0.42),
            fontsize=6,
            ha="left",
            va="top",
            rotation=20,
        )
    for step in steps:
        if step["lane"] == "execution":
            continue
        if step["lane"] == "start" or step["skeleton"] < 0:
            # A start (or a step in which the planner idled): only the decision, in the robot's lane.
            if robot is not None:
                thinking_start = step["start"] + step["outside_seconds"]
                axes.broken_barh(
                    [(thinking_start, step["decision_seconds"])], (robot - 0.4, 0.8), color=THINKING_COLOUR
                )
            continue
        lane = min(step["skeleton"], lanes - 1)
        thinking_start = step["start"] + step["outside_seconds"]
        planning_start = thinking_start + step["decision_seconds"]
        slice_seconds = step["planning_seconds"] - step["overrun_seconds"]
        axes.broken_barh([(thinking_start, step["decision_seconds"])], (lane - 0.4, 0.8), color=THINKING_COLOUR)
        axes.broken_barh(
            [(planning_start, slice_seconds)], (lane - 0.35, 0.7), color=colours(lane % 10), edgecolor="white"
        )
        if step["overrun_seconds"] > 0:
            axes.broken_barh(
                [(planning_start + slice_seconds, step["overrun_seconds"])],
                (lane - 0.35, 0.7),
                facecolor="none",
                edgecolor=OVERRUN_COLOUR,
                hatch="////",
            )
        finish = planning_start + step["planning_seconds"]
        axes.broken_barh([(finish, step["observe_seconds"])], (lane - 0.4, 0.8), color=THINKING_COLOUR)
        if step["refined"]:
            axes.plot([finish], [lane], marker="*", color="black", markersize=9)
            axes.annotate(
                label(step["action"], 24), (finish, lane - 0.42), fontsize=6, ha="left", va="bottom", rotation=20
            )
        end = max(end, finish + step["observe_seconds"])
        reported = max(reported, finish)
    if arguments.solution >= 0 and not acting:
        lane = min(arguments.solution, lanes - 1)
        axes.broken_barh([(reported, arguments.execution)], (lane - 0.12, 0.24), color=EXECUTION_COLOUR)
    boundary = arguments.step
    while boundary < arguments.deadline - 1e-9:
        axes.axvline(boundary, color="#cccccc", linestyle=":", linewidth=0.8, zorder=0)
        boundary += arguments.step
    axes.axvline(arguments.deadline, color="black", linewidth=1.2)
    axes.set_xlim(0, arguments.deadline * 1.02)
    shown = lanes + (1 if executions else 0)
    axes.set_ylim(-1.0, shown - 0.3)
    axes.set_yticks(range(shown))
    axes.set_yticklabels([f"skeleton {k}" for k in range(lanes)] + (["robot"] if executions else []), fontsize=7)
    axes.invert_yaxis()
    axes.set_xlabel("seconds since the episode began (deadline: solid line; model steps: dotted)")
    axes.legend(
        handles=[
            Patch(color=THINKING_COLOUR, label="allocator thinking"),
            Patch(color=colours(0), label="planner slice"),
            Patch(facecolor="none", edgecolor=OVERRUN_COLOUR, hatch="////", label="overrun"),
            Patch(color=EXECUTION_COLOUR, label="execution"),
        ],
        fontsize=7,
        loc="upper right",
        ncol=4,
    )
    axes.set_title(label(arguments.title, TITLE_CHARACTERS), fontsize=9)
    figure.tight_layout()
    save_atomically(figure, arguments.output, dpi=130)


if __name__ == "__main__":
    run(main)
