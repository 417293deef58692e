"""The capability map as a PNG: one panel per yaw and spin, drawn on figures kept between maps.

About a third of a map's picture was matplotlib making its figure (axes, the tick objects its
first drawing makes, the colour bar, the legend), the rest drawing and encoding it
(2026-12-03: 176 ms for two panels on a new figure, 116 ms to draw the same figure again;
on a kept figure with another map's data 100 ms, against 152-162 ms new, in alternated runs).
The figures are kept: a figure drawn for one map is given the next map of the same number of
panels (its images' data, extent and colour range, its markers, titles and colour-bar label)
and drawn again (:mod:`service.render.kept`). The bytes are those of a new figure
(tests/service/test_map_picture.py).

Each infeasible cell takes its reason's colour, the page's (``REASON_COLOURS``: unreachable,
joint limits, singular, discontinuous, and collision with the cell, a reason of its own as
cell.md section 3 has it), from an image above the speeds; the legend names them, as the page
does, in a second row.
"""

from __future__ import annotations

import math

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.image import AxesImage
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import AutoLocator, FixedLocator

from service.render.kept import DPI, KeptFigures, new_figure, png_of
from solver.core.codes import REASONS
from solver.path.capability_map import CapabilityMap

PANEL_INCHES = (4.0, 3.6)
COLOUR_BAR_INCHES = 1.2
MAX_COLUMNS = 3
TITLE_INCHES = 0.3  # the figure's title, above the panels
LEGEND_INCHES = 0.5  # the legend, below them: two rows
PANEL_MARGINS_INCHES = (0.75, 0.2, 0.5, 0.3)  # left, right, bottom, top of each panel's axes
_COLOURS = matplotlib.colormaps["viridis"].with_extremes(bad="white")
TICK_DECIMALS = 9
"""An axis of one value is ticked at it to this many decimals of a metre."""
EVEN_RANGE = 0.05
EVEN_SPAN = 0.01
"""A map of one speed everywhere has a colour bar from it up by EVEN_RANGE of it, EVEN_SPAN
(m/s) at least: its range was 1e-9, labelled ``1e-9`` (a map of mu_path 0 everywhere, a path
that only turns the tool)."""
_MARKERS = (("*", "red"), ("X", "black"))  # the best, the worst
REASON_COLOURS = {  # the page's (service/web/static/app.js, REASON_COLOURS), in REASONS' order
    "unreachable": "#e0e0e0",
    "joint_limits": "#f4a6c0",
    "singular": "#555555",
    "discontinuous": "#ffb74d",
    "collision": "#c62828",
}
_REASONS = ListedColormap([REASON_COLOURS[reason] for reason in REASONS])
_REASON_NORM = BoundaryNorm(np.arange(len(REASONS) + 1) - 0.5, len(REASONS))

Box = tuple[float, float, float, float]
"""An axes box: left, bottom, width, height, as fractions of the figure."""


def _rows_and_columns(n_panels: int) -> tuple[int, int]:
    """The rows and columns of a map's panels: up to MAX_COLUMNS a row."""
    return math.ceil(n_panels / MAX_COLUMNS), min(n_panels, MAX_COLUMNS)


def figure_pixels(n_panels: int) -> tuple[int, int]:
    """Width and height (pixels) of the PNG of a map with ``n_panels`` (yaw, spin) pairs."""
    rows, columns = _rows_and_columns(n_panels)
    width = PANEL_INCHES[0] * columns + COLOUR_BAR_INCHES
    height = PANEL_INCHES[1] * rows
    return round(width * DPI), round(height * DPI)


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


class MapFigure:
    """A figure of ``n_panels`` map panels with its colour bar and legend, drawn map by map."""

    def __init__(self, n_panels: int) -> None:
        """The figure, its panels (an empty image, a best and a worst marker each), bar, legend."""
        rows, columns = _rows_and_columns(n_panels)
        width_px, height_px = figure_pixels(n_panels)
        self.height_in = height_px / DPI
        self.figure = new_figure(width_px / DPI, self.height_in)
        boxes, bar = _layout(rows, columns, width_px / DPI, self.height_in)
        self.panels: list[Axes] = []
        self.images: list[AxesImage] = []
        self.reasons: list[AxesImage] = []
        self.markers: list[tuple[Line2D, Line2D]] = []
        for box in boxes[:n_panels]:
            axes = self.figure.add_axes(box)
            image = axes.imshow(
                np.ma.masked_invalid(np.full((1, 1), np.nan)),
                origin="lower",
                cmap=_COLOURS,
                interpolation="nearest",
                aspect="equal",
            )
            reasons = axes.imshow(
                np.ma.masked_array(np.zeros((1, 1)), mask=True),
                origin="lower",
                cmap=_REASONS,
                norm=_REASON_NORM,
                interpolation="nearest",
                aspect="equal",
            )
            best, worst = (
                axes.plot([], [], marker, color=colour, ms=12, visible=False)[0]
                for marker, colour in _MARKERS
            )
            axes.set_xlabel("x (m)")
            axes.set_ylabel("y (m)")
            self.panels.append(axes)
            self.images.append(image)
            self.reasons.append(reasons)
            self.markers.append((best, worst))
        self.colour_bar = self.figure.colorbar(self.images[0], cax=self.figure.add_axes(bar))
        self.legend = self.figure.legend(
            handles=[
                Line2D([], [], marker="*", color="red", ls="", ms=10, label="best"),
                Line2D([], [], marker="X", color="black", ls="", ms=8, label="worst"),
                *(
                    Patch(facecolor=colour, edgecolor="grey", label=reason.replace("_", " "))
                    for reason, colour in REASON_COLOURS.items()
                ),
            ],
            loc="lower right",
            ncols=4,
            fontsize=8,
            frameon=False,
            borderaxespad=0.1,
        )

    def png(self, cmap: CapabilityMap, *, title: str) -> bytes:
        """The map drawn on this figure (whatever it showed before), as PNG bytes."""
        colour_of = cmap.feed_index  # mu_acc with acceleration limits, else mu_path
        feasible = ~np.isnan(colour_of)
        low = float(np.nanmin(colour_of)) if feasible.any() else 0.0
        high = float(np.nanmax(colour_of)) if feasible.any() else 1.0
        if high <= low:  # one speed everywhere: a bar of EVEN_RANGE from it, not of 1e-9
            high = low + max(EVEN_RANGE * abs(low), EVEN_SPAN)
        best, worst = cmap.extreme(best=True), cmap.extreme(best=False)
        half_x, half_y = _half_steps(cmap.xs, cmap.ys)
        extent = (
            cmap.xs[0] - half_x,
            cmap.xs[-1] + half_x,
            cmap.ys[0] - half_y,
            cmap.ys[-1] + half_y,
        )
        for panel, (s, k) in enumerate(np.ndindex(len(cmap.spins), len(cmap.yaws))):
            axes, image = self.panels[panel], self.images[panel]
            image.set_data(np.ma.masked_invalid(colour_of[s, k]))
            image.set_clim(low, high)
            image.set_extent(extent)  # and the axes' limits to it, a kept figure's too
            for axis, values in ((axes.xaxis, cmap.xs), (axes.yaxis, cmap.ys)):
                # an axis of one value is ticked at it, to the nanometre (a row 2 cm high had
                # three labels on one another; matplotlib's formatter fails on a subnormal
                # tick, -2.2e-311: a 500); the others as matplotlib ticks them, a kept
                # figure's too
                axis.set_major_locator(
                    FixedLocator([round(float(values[0]), TICK_DECIMALS) + 0.0])
                    if len(values) == 1
                    else AutoLocator()
                )
            reason = cmap.reason[s, k]
            self.reasons[panel].set_data(np.ma.masked_array(reason, reason < 0))
            self.reasons[panel].set_extent(extent)
            for index, marker in zip((best, worst), self.markers[panel], strict=True):
                shown = index is not None and index[:2] == (s, k)
                marker.set_visible(shown)
                if index is not None and shown:
                    marker.set_data([cmap.xs[index[3]]], [cmap.ys[index[2]]])
            spin = f", spin {math.degrees(float(cmap.spins[s])):.1f} deg" if cmap.spins[s] else ""
            axes.set_title(
                f"yaw {math.degrees(float(cmap.yaws[k])):.1f} deg{spin}, z = {cmap.z:.3f} m",
                fontsize=9,
            )
        label = "mu_path (m/s)" if cmap.mu_acc is None else "mu_acc (m/s)"
        self.colour_bar.set_label(label)
        self.figure.suptitle(title, fontsize=10, y=1.0 - 0.08 / self.height_in, va="top")
        return png_of(self.figure)


def _half_steps(xs: np.ndarray, ys: np.ndarray) -> tuple[float, float]:
    """Half a cell's width and height (m), from the grid's steps.

    Along an axis of one value the cells are square (the other's step), 5 mm where both have
    one: a row was 1 cm high whatever its cells' width.
    """
    half_x = (xs[1] - xs[0]) / 2 if len(xs) > 1 else None
    half_y = (ys[1] - ys[0]) / 2 if len(ys) > 1 else None
    half_x = half_x if half_x is not None else half_y if half_y is not None else 0.005
    return float(half_x), float(half_y if half_y is not None else half_x)


KEPT: KeptFigures[MapFigure] = KeptFigures(4, 16 * 2**20)
"""The map figures kept, by number of panels: four, of 16 MiB of pixels in all (a figure of six
panels holds 3.6 MiB, of 24 panels 14.5 MiB)."""


def render_png(cmap: CapabilityMap, *, title: str) -> bytes:
    """The map as PNG bytes: colour bar in m/s, infeasible cells in their reason's colour."""
    n_panels = len(cmap.spins) * len(cmap.yaws)
    return KEPT.drawn(
        n_panels, lambda: MapFigure(n_panels), lambda figure: figure.png(cmap, title=title)
    )
