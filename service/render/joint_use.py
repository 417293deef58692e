"""The joint-use picture of a path at its feed (PNG), and a picture that only says why not."""

from __future__ import annotations

import io
import textwrap

import matplotlib

matplotlib.use("Agg")  # no display: render to memory

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402

from service.render.map_picture import DPI, Box  # noqa: E402
from solver.path.evaluate import PathEvaluation  # noqa: E402
from solver.path.feed import FeedCheck  # noqa: E402

JOINT_USE_WIDTH_INCHES = 8.0
JOINT_USE_MARGINS_INCHES = (0.75, 0.5, 0.4)  # left, bottom, top of the panels' axes
PANEL_GAP_INCHES = 0.25
LEGEND_POINTS = 8
LEGEND_LABEL_CHARACTERS = 32
"""A legend label's longest text: a longer joint name is cut, its end marked (the picture only)."""


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
