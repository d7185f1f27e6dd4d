"""One episode of `ontime tamp` seen from above: the skeletons the task planner found, coloured by
the planning effort each got, and the motions the planner found.

Reads the JSON that `ontime tamp --picture` writes: {"title", "polygons": [...as plot_map.py...],
"skeletons": [{"index", "label", "planning_seconds", "executed", "points"?}], "motions":
[{"action", "executed", "points"}]}. A skeleton with "points" (a navigation room path) is drawn
through its doors, its colour and width growing with its planning seconds (an action shared by
several skeletons counts for each); the plan executed is drawn black and thick. Found motions are
drawn thin in red, the executed ones bold. Exit statuses: see ontime_plotting.
"""

import argparse

# Sets the Agg backend: import it first.
from ontime_plotting import TITLE_CHARACTERS, bad_input, label, read_json, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import cm, colors  # noqa: E402

from plot_map import draw  # noqa: E402

MAX_LEGEND = 12  # skeletons listed in the legend; the others are drawn unlabelled


def check_drawing(drawing):
    """Raises KeyError, TypeError or ValueError unless `drawing` has the fields described above."""
    str(drawing["title"])
    for polygon in drawing["polygons"]:
        str(polygon["kind"]), str(polygon["label"])
        for x, y in polygon["points"]:
            float(x), float(y)
    for skeleton in drawing["skeletons"]:
        int(skeleton["index"]), str(skeleton["label"]), bool(skeleton["executed"])
        if float(skeleton["planning_seconds"]) < 0:
            raise ValueError("negative planning seconds")
        for x, y in skeleton.get("points", []):
            float(x), float(y)
    for motion in drawing["motions"]:
        str(motion["action"]), bool(motion["executed"])
        for x, y in motion["points"]:
            float(x), float(y)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--data", required=True)
    parser.add_argument("--output", required=True)
    arguments = parser.parse_args()
    drawing = read_json(arguments.data)
    try:
        check_drawing(drawing)
    except (KeyError, TypeError, ValueError, IndexError) as error:
        raise bad_input(arguments.data, f"not an episode drawing ({type(error).__name__}: {error})") from None

    top = [polygon for polygon in drawing["polygons"] if polygon.get("view", "top") == "top"]
    if not top:
        raise bad_input(arguments.data, "no polygon seen from above")
    xs = [point[0] for polygon in top for point in polygon["points"]]
    ys = [point[1] for polygon in top for point in polygon["points"]]
    width, height = max(xs) - min(xs), max(ys) - min(ys)
    figure, axes = plt.subplots(figsize=(11, 11 * height / width + 1.8))
    draw(axes, top)

    skeletons = drawing["skeletons"]
    most = max([skeleton["planning_seconds"] for skeleton in skeletons] + [1e-9])
    scale = colors.Normalize(vmin=0, vmax=most)
    colour_map = plt.get_cmap("viridis_r")
    # Least effort first, so that the skeletons that got the most are drawn on top.
    for skeleton in sorted(skeletons, key=lambda s: s["planning_seconds"]):
        points = skeleton.get("points")
        if not points:
            continue
        # Skeletons sharing doors would hide each other: each is shifted a little.
        shift = 0.08 * (skeleton["index"] % 7 - 3)
        seconds = skeleton["planning_seconds"]
        name = label(skeleton["label"]) + f" ({seconds:.1f} s)" if skeleton["index"] < MAX_LEGEND else None
        axes.plot([x + shift for x, _ in points], [y + shift for _, y in points],
                  color="black" if skeleton["executed"] else colour_map(scale(seconds)),
                  linewidth=4.0 if skeleton["executed"] else 1.2 + 3.0 * seconds / most,
                  alpha=0.9, label=name, zorder=3.2 if skeleton["executed"] else 3)
    for motion in drawing["motions"]:
        points = motion["points"]
        axes.plot([x for x, _ in points], [y for _, y in points], color="#c0392b",
                  linewidth=1.8 if motion["executed"] else 0.7, alpha=1.0 if motion["executed"] else 0.6, zorder=3.5)
    figure.colorbar(cm.ScalarMappable(norm=scale, cmap=colour_map), ax=axes, fraction=0.03, pad=0.01,
                    label="planning seconds on the skeleton's actions")
    axes.set_ylabel("y (m)")
    axes.set_title(label(drawing["title"], TITLE_CHARACTERS))
    if any(skeleton["index"] < MAX_LEGEND for skeleton in skeletons):
        axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2, fontsize=7, frameon=False)
    figure.tight_layout()
    save_atomically(figure, arguments.output)


if __name__ == "__main__":
    run(main)
