"""Pictures (PNG): the capability map, one panel per yaw and spin; joint use along a path."""

from __future__ import annotations

import io
import math
import textwrap

import matplotlib

matplotlib.use("Agg")  # no display: render to memory

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from solver.path.capability_map import CapabilityMap  # noqa: E402
from solver.path.evaluate import PathEvaluation  # noqa: E402
from solver.path.feed import FeedCheck  # noqa: E402

PANEL_INCHES = (4.0, 3.6)
COLOUR_BAR_INCHES = 1.2
DPI = 100
MAX_COLUMNS = 3
TITLE_INCHES = 0.3  # the figure's title, above the panels
LEGEND_INCHES = 0.3  # the legend, below them
PANEL_MARGINS_INCHES = (0.75, 0.2, 0.5, 0.3)  # left, right, bottom, top of each panel's axes
JOINT_USE_WIDTH_INCHES = 8.0
JOINT_USE_MARGINS_INCHES = (0.75, 0.5, 0.4)  # left, bottom, top of the panels' axes
PANEL_GAP_INCHES = 0.25
"""Fixed margins, not matplotlib's constrained layout (half the picture's rendering time)."""
LEGEND_POINTS = 8
LEGEND_LABEL_CHARACTERS = 32
"""A legend label's longest text: a longer joint name is cut, its end marked (the picture only)."""


def figure_pixels(n_panels: int) -> tuple[int, int]:
    """Width and height (pixels) of the PNG of a map with ``n_panels`` (yaw, spin) pairs."""
    columns = min(n_panels, MAX_COLUMNS)
    rows = math.ceil(n_panels / MAX_COLUMNS)
    width = PANEL_INCHES[0] * columns + COLOUR_BAR_INCHES
    height = PANEL_INCHES[1] * rows
    return round(width * DPI), round(height * DPI)


Box = tuple[float, float, float, float]
"""An axes box: left, bottom, width, height, as fractions of the figure."""


def _layout(rows: int, columns: int, width: float, height: float) -> tuple[list[Box], Box]:
    """Each panel's axes box, row by row, and the colour bar's, in a figure of width x height in.

    Fixed margins in inches, not matplotlib's constrained layout: that layout measured every
    tick label of every panel and was half the rendering time (0.8 of 1.6 s for six panels).
    """
    cell_height = (height - TITLE_INCHES - LEGEND_INCHES) / rows
    left, right, bottom, top = PANEL_MARGINS_INCHES
    boxes = []
    for row in range(rows):
        for column in range(columns):
            x0 = PANEL_INCHES[0] * column + left
            y0 = LEGEND_INCHES + cell_height * (rows - 1 - row) + bottom
            boxes.append(
                (
                    x0 / width,
                    y0 / height,
                    (PANEL_INCHES[0] - left - right) / width,
                    (cell_height - bottom - top) / height,
                )
            )
    bar_bottom = LEGEND_INCHES + bottom
    bar = (
        (PANEL_INCHES[0] * columns + 0.15) / width,
        bar_bottom / height,
        0.2 / width,
        (height - TITLE_INCHES - top - bar_bottom) / height,
    )
    return boxes, bar


def render_png(cmap: CapabilityMap, *, title: str) -> bytes:
    """The map as PNG bytes: colour bar in m/s, infeasible cells blank, best and worst marked."""
    n_panels = len(cmap.spins) * len(cmap.yaws)
    columns = min(n_panels, MAX_COLUMNS)
    rows = math.ceil(n_panels / MAX_COLUMNS)
    width_px, height_px = figure_pixels(n_panels)
    width_in, height_in = width_px / DPI, height_px / DPI
    figure = plt.figure(figsize=(width_in, height_in), dpi=DPI)
    boxes, bar = _layout(rows, columns, width_in, height_in)
    colour_of = cmap.feed_index  # mu_acc with acceleration limits, else mu_path
    feasible = ~np.isnan(colour_of)
    low = float(np.nanmin(colour_of)) if feasible.any() else 0.0
    high = float(np.nanmax(colour_of)) if feasible.any() else 1.0
    colours = matplotlib.colormaps["viridis"].with_extremes(bad="white")
    best, worst = cmap.extreme(best=True), cmap.extreme(best=False)
    half_x = (cmap.xs[1] - cmap.xs[0]) / 2 if len(cmap.xs) > 1 else 0.005
    half_y = (cmap.ys[1] - cmap.ys[0]) / 2 if len(cmap.ys) > 1 else 0.005
    extent = (cmap.xs[0] - half_x, cmap.xs[-1] + half_x, cmap.ys[0] - half_y, cmap.ys[-1] + half_y)
    images = []
    for panel, (s, k) in enumerate(np.ndindex(len(cmap.spins), len(cmap.yaws))):
        axes = figure.add_axes(boxes[panel])
        image = axes.imshow(
            np.ma.masked_invalid(colour_of[s, k]),
            origin="lower",
            extent=extent,
            cmap=colours,
            vmin=low,
            vmax=high if high > low else low + 1e-9,
            interpolation="nearest",
            aspect="equal",
        )
        images.append(image)
        for index, marker, colour in ((best, "*", "red"), (worst, "X", "black")):
            if index is not None and index[:2] == (s, k):
                axes.plot(cmap.xs[index[3]], cmap.ys[index[2]], marker, color=colour, ms=12)
        spin = f", spin {math.degrees(float(cmap.spins[s])):.1f} deg" if cmap.spins[s] else ""
        axes.set_title(
            f"yaw {math.degrees(float(cmap.yaws[k])):.1f} deg{spin}, z = {cmap.z:.3f} m",
            fontsize=9,
        )
        axes.set_xlabel("x (m)")
        axes.set_ylabel("y (m)")
    label = "mu_path (m/s)" if cmap.mu_acc is None else "mu_acc (m/s)"
    figure.colorbar(images[0], cax=figure.add_axes(bar), label=label)
    figure.legend(
        handles=[
            Line2D([], [], marker="*", color="red", ls="", ms=10, label="best"),
            Line2D([], [], marker="X", color="black", ls="", ms=8, label="worst"),
            Patch(facecolor="white", edgecolor="grey", label="infeasible"),
        ],
        loc="lower right",
        ncols=3,
        fontsize=8,
        frameon=False,
        borderaxespad=0.1,
    )
    figure.suptitle(title, fontsize=10, y=1.0 - 0.08 / height_in, va="top")
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI)
    plt.close(figure)
    return buffer.getvalue()


def _acceleration_panel(axes: Axes, use: np.ndarray, evaluation: PathEvaluation) -> None:
    """Each joint's |qdd| / qddot_max along the path (NaN gaps at the pass ends)."""
    waypoints = np.arange(len(use))
    for j in range(use.shape[1]):
        axes.plot(waypoints, use[:, j], lw=1.2)
    axes.axhline(1.0, color="red", ls="--", lw=1.0)
    acc = evaluation.acceleration
    if acc is not None and acc.limited_by == "acceleration":
        axes.plot(acc.waypoint, use[acc.waypoint, acc.joint], "s", color="black", ms=7)
    axes.set_xlabel("waypoint")
    axes.set_ylabel("|qdd| / qddot_max")
    axes.set_ylim(bottom=0.0)


def render_message(text: str) -> bytes:
    """A PNG that says ``text`` where there is nothing to plot (a path that does not run)."""
    figure = plt.figure(figsize=(8.0, 1.5), dpi=DPI)
    figure.text(0.5, 0.5, textwrap.fill(text, 90), ha="center", va="center", fontsize=10)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI)
    plt.close(figure)
    return buffer.getvalue()


def render_joint_use(
    check: FeedCheck, evaluation: PathEvaluation, joint_names: tuple[str, ...], *, title: str
) -> bytes:
    """Each joint's use of its speed limit along the path at the feed, as a PNG (cam.md 7).

    One line per joint, the limit at 1, the bottleneck waypoint and joint marked: the picture
    the ERK 2021 paper checked in URSim (figs. 3-4). With acceleration limits a second panel
    below shows each joint's use of its acceleration limit at that constant feed
    (motion.md section 2), the waypoint where mu_acc binds marked.
    """
    use = np.abs(check.use) if check.use is not None else np.zeros((0, len(joint_names)))
    labels = [_legend_label(name) for name in joint_names]
    w, b = evaluation.bottleneck_waypoint, evaluation.bottleneck_joint
    if w is not None and b is not None:
        labels.append(_legend_label(f"bottleneck: {joint_names[b]}"))
    height = 7.0 if check.acceleration_use is not None else 4.0
    figure = plt.figure(figsize=(JOINT_USE_WIDTH_INCHES, height), dpi=DPI)
    panels = _joint_use_layout(2 if check.acceleration_use is not None else 1, height, labels)
    axes = figure.add_axes(panels[0])
    if check.acceleration_use is not None:
        below = figure.add_axes(panels[1], sharex=axes)
        _acceleration_panel(below, check.acceleration_use, evaluation)
        axes.tick_params(labelbottom=False)
    else:
        axes.set_xlabel("waypoint")
    waypoints = np.arange(len(use))
    for j, label in enumerate(labels[: len(joint_names)]):
        axes.plot(waypoints, use[:, j], label=label, lw=1.2)
    axes.axhline(1.0, color="red", ls="--", lw=1.0, label="limit")
    if w is not None and b is not None:
        axes.plot(w, use[w, b], "o", color="black", ms=8, label=labels[-1])
    state = "runs" if check.feasible else "does NOT run"
    axes.set_title(
        f"{title}: feed {check.feed:.4g} m/s {state} (margin {check.margin:.3g})", fontsize=10
    )
    axes.set_ylabel("|qdot| / qdot_max")
    axes.set_ylim(bottom=0.0)
    figure.legend(
        loc="upper right",
        bbox_to_anchor=(1.0, 1.0 - JOINT_USE_MARGINS_INCHES[2] / height),
        fontsize=LEGEND_POINTS,
        frameon=False,
    )
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI)
    plt.close(figure)
    return buffer.getvalue()


def _legend_label(text: str) -> str:
    """``text`` cut to LEGEND_LABEL_CHARACTERS, an ellipsis where it was cut."""
    if len(text) <= LEGEND_LABEL_CHARACTERS:
        return text
    return text[: LEGEND_LABEL_CHARACTERS - 1] + "\N{HORIZONTAL ELLIPSIS}"


def _joint_use_layout(panels: int, height: float, labels: list[str]) -> list[Box]:
    """The axes boxes of the joint-use panels, top first; the legend's room at the right.

    The legend's width is estimated from its longest label (about half an em a character, the
    line's handle and padding 0.6 in), so no text is measured before the figure is drawn. Only
    the top panel has a title and only the bottom one tick labels under it.
    """
    longest = max((len(label) for label in labels), default=0)
    legend = 0.6 + 0.5 * LEGEND_POINTS / 72 * longest
    left, bottom, top = JOINT_USE_MARGINS_INCHES
    width = JOINT_USE_WIDTH_INCHES
    inner = (height - bottom - top - PANEL_GAP_INCHES * (panels - 1)) / panels
    return [
        (
            left / width,
            (bottom + (inner + PANEL_GAP_INCHES) * (panels - 1 - k)) / height,
            (width - left - legend) / width,
            inner / height,
        )
        for k in range(panels)
    ]
