"""Figures kept between pictures: making a matplotlib figure costs more than drawing it again.

A picture's figure (its axes, tick objects, colour bar, legend) is made once per layout and
given the next picture of that layout: :class:`KeptFigures` hands a figure to one thread at a
time (taken under a lock, given back after its PNG is written) and keeps at most ``most``.
Every picture's figure is made by :func:`new_figure` (no pyplot: its registry of figures is
global, shared by the routes' threads) and written by :func:`png_of`.
"""

from __future__ import annotations

import io
import threading
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

import matplotlib

matplotlib.use("Agg")  # no display: render to memory

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

F = TypeVar("F")
DPI = 100


def new_figure(width: float, height: float) -> Figure:
    """A figure of width x height inches at DPI, on its own Agg canvas."""
    figure = Figure(figsize=(width, height), dpi=DPI)
    FigureCanvasAgg(figure)
    return figure


def png_of(figure: Figure) -> bytes:
    """The figure drawn, as PNG bytes."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


class KeptFigures(Generic[F]):
    """At most ``most`` figures not in use, by layout key."""

    def __init__(self, most: int) -> None:
        """No figure kept yet."""
        self.most = most
        self._kept: dict[Hashable, list[F]] = {}
        self._lock = threading.Lock()

    def drawn(self, key: Hashable, make: Callable[[], F], draw: Callable[[F], bytes]) -> bytes:
        """``draw`` on a kept figure of layout ``key`` (or on ``make()``); the figure kept after.

        A figure whose drawing raises is not kept (its state is not known).
        """
        with self._lock:
            figures = self._kept.get(key)
            figure = figures.pop() if figures else None
        if figure is None:
            figure = make()
        picture = draw(figure)
        with self._lock:
            if self.count() < self.most:
                self._kept.setdefault(key, []).append(figure)
        return picture

    def count(self) -> int:
        """How many figures are kept (not in use)."""
        return sum(len(figures) for figures in self._kept.values())
