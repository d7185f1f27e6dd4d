"""A domain's world seen from above (and from the front), with refined motions.

Reads the JSON that `ontime map` writes: {"title", "polygons": [{"kind", "label", "view",
"points"}], "paths": [{"label", "points", "end"}]}. Kinds: "room" (drawn light; labelled in its
top-left corner), "wall", "obstacle", "region" (a placement region), "object" (a movable object),
"caption" (a label only) and "robot". Polygons of view "top" (the default) are drawn seen from
above, those of view "front" in a second panel seen from the front (x and z). Each path is drawn
in its own colour in the top view, with the robot's footprint where it ends. Writes the PNG
through a temporary file. Labels and the title are shortened for drawing. Exit statuses: see
ontime_plotting.
"""

import argparse

# Sets the Agg backend: import it first.
from ontime_plotting import TITLE_CHARACTERS, bad_input, label, read_json, run, save_atomically

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

STYLE = {
    "room": dict(facecolor="#f4f1ea", edgecolor="none", zorder=0),
    "wall": dict(facecolor="#333333", edgecolor="#333333", linewidth=0.3, zorder=2),
    "obstacle": dict(facecolor="#a67c52", edgecolor="#5b4027", linewidth=0.6, zorder=2),
    "region": dict(facecolor="#9fd69f", edgecolor="#2d7a2d", linewidth=0.8, alpha=0.6, zorder=2.5),
    "object": dict(facecolor="#e8a33d", edgecolor="#7a4e10", linewidth=0.8, zorder=3.5),
    "caption": dict(facecolor="none", edgecolor="none", zorder=5),
    "robot": dict(facecolor="#4c9a4c", edgecolor="#2d5e2d", linewidth=0.8, alpha=0.8, zorder=4),
}
PATH_COLOURS = ["#1f77b4", "#d62728", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#7f7f7f"]


def draw_label(axes, polygon):
    xs = [point[0] for point in polygon["points"]]
    ys = [point[1] for point in polygon["points"]]
    kind = polygon["kind"]
    text = label(polygon["label"], 30)
    if kind == "room":
        # Rooms are labelled in their top-left corner, clear of furniture in the middle.
        axes.text(min(xs) + 0.15, max(ys) - 0.15, text, ha="left", va="top", fontsize=12, color="#7a7a7a",
                  fontweight="bold", zorder=5)
    elif kind == "region":
        axes.text(max(xs), max(ys), text, ha="right", va="bottom", fontsize=8, color="#1f5a1f",
                  fontweight="bold", zorder=5)
    else:
        axes.text((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2, text, ha="center", va="center",
                  fontsize=7 if kind == "object" else 9, color="#222222", zorder=6)


def draw(axes, polygons):
    for polygon in polygons:
        axes.add_patch(Polygon(polygon["points"], closed=True, **STYLE.get(polygon["kind"], STYLE["obstacle"])))
        if polygon["label"]:
            draw_label(axes, polygon)
    xs = [point[0] for polygon in polygons for point in polygon["points"]]
    ys = [point[1] for polygon in polygons for point in polygon["points"]]
    axes.set_xlim(min(xs) - 0.2, max(xs) + 0.2)
    axes.set_ylim(min(ys) - 0.2, max(ys) + 0.2)
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    return max(xs) - min(xs), max(ys) - min(ys)


def check_drawing(drawing):
    """Raises KeyError, TypeError or ValueError unless `drawing` has the fields described above."""
    str(drawing["title"])
    if not any(polygon.get("view", "top") == "top" for polygon in drawing["polygons"]):
        raise ValueError("no polygon seen from above")
    for polygon in drawing["polygons"]:
        str(polygon["kind"]), str(polygon["label"])
        if not polygon["points"]:
            raise ValueError("a polygon without points")
        for x, y in polygon["points"]:
            float(x), float(y)
    for path in drawing["paths"]:
        str(path["label"])
        for x, y in path["points"] + path["end"]:
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
        raise bad_input(arguments.data, f"not a drawing ({type(error).__name__}: {error})") from None

    top = [polygon for polygon in drawing["polygons"] if polygon.get("view", "top") == "top"]
    front = [polygon for polygon in drawing["polygons"] if polygon.get("view", "top") == "front"]
    xs = [point[0] for polygon in top for point in polygon["points"]]
    ys = [point[1] for polygon in top for point in polygon["points"]]
    width, height = max(xs) - min(xs), max(ys) - min(ys)
    if front:
        zs = [point[1] for polygon in front for point in polygon["points"]]
        front_height = max(zs) - min(zs)
        figure, (axes, front_axes) = plt.subplots(
            2, 1, figsize=(11, 11 * (height + front_height) / width + 2.0),
            gridspec_kw={"height_ratios": [height + 0.4, front_height + 0.4]})
    else:
        figure, axes = plt.subplots(figsize=(11, 11 * height / width + 1.2))
    draw(axes, top)
    for index, path in enumerate(drawing["paths"]):
        colour = PATH_COLOURS[index % len(PATH_COLOURS)]
        axes.plot([point[0] for point in path["points"]], [point[1] for point in path["points"]], color=colour,
                  linewidth=1.8, label=label(path["label"]), zorder=3)
        if path["end"]:  # (none for a skeleton that could not be refined)
            axes.add_patch(Polygon(path["end"], closed=True, facecolor=colour, edgecolor=colour, alpha=0.35,
                                   zorder=3))
    axes.set_ylabel("y (m)")
    axes.set_title(label(drawing["title"], TITLE_CHARACTERS) + (" — seen from above" if front else ""))
    if drawing["paths"]:
        axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07 if not front else -0.12), ncol=2, fontsize=8,
                    frameon=False)
    if front:
        draw(front_axes, front)
        front_axes.set_ylabel("z (m)")
        front_axes.set_title("seen from the front (from y = 0)")
    figure.tight_layout()

    save_atomically(figure, arguments.output)


if __name__ == "__main__":
    run(main)
