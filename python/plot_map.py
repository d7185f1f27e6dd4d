"""A domain's world seen from above, with refined motions.

Reads the JSON that `ontime map` writes: {"title", "polygons": [{"kind", "label", "points"}],
"paths": [{"label", "points", "end"}]}, with kinds "room" (drawn light, labelled in its
top-left corner), "wall", "obstacle" and "robot" (the start footprint); each path is drawn in its own
colour with the robot's footprint where it ends. Writes the PNG through a temporary file.
"""

import argparse
import json
from ontime_plotting import save_atomically  # sets the Agg backend: import it first

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

STYLE = {
    "room": dict(facecolor="#f4f1ea", edgecolor="none", zorder=0),
    "wall": dict(facecolor="#333333", edgecolor="#333333", linewidth=0.3, zorder=2),
    "obstacle": dict(facecolor="#a67c52", edgecolor="#5b4027", linewidth=0.6, zorder=2),
    "robot": dict(facecolor="#4c9a4c", edgecolor="#2d5e2d", linewidth=0.8, alpha=0.8, zorder=4),
}
PATH_COLOURS = ["#1f77b4", "#d62728", "#9467bd", "#ff7f0e", "#17becf", "#8c564b"]


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--data", required=True)
    parser.add_argument("--output", required=True)
    arguments = parser.parse_args()
    with open(arguments.data, encoding="utf-8") as handle:
        drawing = json.load(handle)

    xs = [point[0] for polygon in drawing["polygons"] for point in polygon["points"]]
    ys = [point[1] for polygon in drawing["polygons"] for point in polygon["points"]]
    width, height = max(xs) - min(xs), max(ys) - min(ys)
    figure, axes = plt.subplots(figsize=(11, 11 * height / width + 1.2))
    for polygon in drawing["polygons"]:
        axes.add_patch(Polygon(polygon["points"], closed=True, **STYLE.get(polygon["kind"], STYLE["obstacle"])))
        if polygon["label"]:
            # Rooms are labelled in their top-left corner, clear of furniture in the middle.
            left = min(point[0] for point in polygon["points"])
            top = max(point[1] for point in polygon["points"])
            axes.text(left + 0.15, top - 0.15, polygon["label"], ha="left", va="top", fontsize=12, color="#7a7a7a",
                      fontweight="bold", zorder=5)
    for index, path in enumerate(drawing["paths"]):
        colour = PATH_COLOURS[index % len(PATH_COLOURS)]
        axes.plot([point[0] for point in path["points"]], [point[1] for point in path["points"]], color=colour,
                  linewidth=1.8, label=path["label"], zorder=3)
        axes.add_patch(Polygon(path["end"], closed=True, facecolor=colour, edgecolor=colour, alpha=0.35, zorder=3))
    axes.set_xlim(min(xs) - 0.2, max(xs) + 0.2)
    axes.set_ylim(min(ys) - 0.2, max(ys) + 0.2)
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_title(drawing["title"])
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2, fontsize=8, frameon=False)
    figure.tight_layout()

    save_atomically(figure, arguments.output)

if __name__ == "__main__":
    main()
