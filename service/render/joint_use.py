"""The joint-use picture of a path at its feed (PNG), and a picture that only says why not."""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from service.render.kept import KeptFigures, new_figure, png_of
from service.render.map_picture import Box
from solver.path.evaluate import PathEvaluation
from solver.path.feed import FeedCheck

JOINT_USE_WIDTH_INCHES = 8.0
JOINT_USE_MARGINS_INCHES = (0.75, 0.5, 0.4)  # left, bottom, top of the panels' axes
PANEL_GAP_INCHES = 0.25
LEGEND_POINTS = 8
LEGEND_LABEL_CHARACTERS = 32
"""A legend label's longest text: a longer joint name is cut, its end marked (the picture only)."""


def render_message(text: str) -> bytes:
    """A PNG that says ``text`` where there is nothing to plot (a path that does not run)."""
    figure = new_figure(8.0, 1.5)
    figure.text(0.5, 0.5, textwrap.fill(text, 90), ha="center", va="center", fontsize=10)
    return png_of(figure)


class JointUseFigure:
    """A joint-use figure for one set of legend labels, with or without the acceleration panel.

    Made once per layout (:mod:`service.render.kept`): each path's lines, markers and title are
    set on it, its panels' limits scaled to them as a new figure's are, and it is drawn again.
    """

    def __init__(self, labels: tuple[str, ...], n_joints: int, accelerations: bool) -> None:
        """The panels, one line a joint (and the bottleneck's marker where labelled), the legend."""
        self.height = 7.0 if accelerations else 4.0
        self.figure = new_figure(JOINT_USE_WIDTH_INCHES, self.height)
        panels = _joint_use_layout(2 if accelerations else 1, self.height, list(labels))
        self.axes = self.figure.add_axes(panels[0])
        self.below: Axes | None = None
        self.acc_lines: list[Line2D] = []
        self.acc_marker: Line2D | None = None
        if accelerations:
            self.below = below = self.figure.add_axes(panels[1], sharex=self.axes)
            self.acc_lines = [below.plot([], [], lw=1.2)[0] for _ in range(n_joints)]
            below.axhline(1.0, color="red", ls="--", lw=1.0)
            self.acc_marker = below.plot([], [], "s", color="black", ms=7, visible=False)[0]
            below.set_xlabel("waypoint")
            below.set_ylabel("|qdd| / qddot_max")
            self.axes.tick_params(labelbottom=False)
        else:
            self.axes.set_xlabel("waypoint")
        self.lines = [self.axes.plot([], [], label=label, lw=1.2)[0] for label in labels[:n_joints]]
        self.axes.axhline(1.0, color="red", ls="--", lw=1.0, label="limit")
        self.marker = (
            self.axes.plot([], [], "o", color="black", ms=8, label=labels[-1])[0]
            if len(labels) > n_joints
            else None
        )
        self.axes.set_ylabel("|qdot| / qdot_max")
        self.figure.legend(
            loc="upper right",
            bbox_to_anchor=(1.0, 1.0 - JOINT_USE_MARGINS_INCHES[2] / self.height),
            fontsize=LEGEND_POINTS,
            frameon=False,
        )

    def png(self, check: FeedCheck, evaluation: PathEvaluation, *, title: str) -> bytes:
        """This path's joint use drawn on the figure (whatever it showed before), as PNG."""
        use = np.abs(check.use) if check.use is not None else np.zeros((0, len(self.lines)))
        waypoints = np.arange(len(use))
        for j, line in enumerate(self.lines):
            line.set_data(waypoints, use[:, j])
        w, b = evaluation.bottleneck_waypoint, evaluation.bottleneck_joint
        if self.marker is not None and w is not None and b is not None:
            self.marker.set_data([w], [use[w, b]])
        state = "runs" if check.feasible else "does NOT run"
        self.axes.set_title(
            f"{title}: feed {check.feed:.4g} m/s {state} (margin {check.margin:.3g})", fontsize=10
        )
        scaled = [self.axes]
        acc_use = check.acceleration_use  # given when the figure has the panel (its layout key)
        if self.below is not None and self.acc_marker is not None and acc_use is not None:
            for j, line in enumerate(self.acc_lines):
                line.set_data(np.arange(len(acc_use)), acc_use[:, j])
            acc = evaluation.acceleration
            marked = acc is not None and acc.limited_by == "acceleration"
            self.acc_marker.set_visible(marked)
            if acc is not None and marked:
                self.acc_marker.set_data([acc.waypoint], [acc_use[acc.waypoint, acc.joint]])
            scaled.append(self.below)
        for axes in scaled:  # the limits a new figure's autoscaling gives, from 0 up
            axes.relim(visible_only=True)
            axes.set_autoscale_on(True)
        for axes in scaled:
            axes.autoscale_view()
            axes.set_ylim(bottom=0.0)
        return png_of(self.figure)


KEPT: KeptFigures[JointUseFigure] = KeptFigures(4, 16 * 2**20)
"""The joint-use figures kept, by legend labels and panels."""


def render_joint_use(
    check: FeedCheck, evaluation: PathEvaluation, joint_names: tuple[str, ...], *, title: str
) -> bytes:
    """Each joint's use of its speed limit along the path at the feed, as a PNG (cam.md 7).

    One line per joint, the limit at 1, the bottleneck waypoint and joint marked: the picture
    the ERK 2021 paper checked in URSim (figs. 3-4). With acceleration limits a second panel
    below shows each joint's use of its acceleration limit at that constant feed
    (motion.md section 2), the waypoint where mu_acc binds marked.
    """
    labels = [_legend_label(name) for name in joint_names]
    w, b = evaluation.bottleneck_waypoint, evaluation.bottleneck_joint
    if w is not None and b is not None:
        labels.append(_legend_label(f"bottleneck: {joint_names[b]}"))
    accelerations = check.acceleration_use is not None
    key = (tuple(labels), len(joint_names), accelerations)
    return KEPT.drawn(
        key,
        lambda: JointUseFigure(*key),
        lambda figure: figure.png(check, evaluation, title=title),
    )


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
