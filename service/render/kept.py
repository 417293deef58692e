"""Figures kept between pictures: making a matplotlib figure costs more than drawing it again.

A picture's figure (its axes, tick objects, colour bar, legend) is made once per layout and
given the next picture of that layout: :class:`KeptFigures` hands a figure to one thread at a
time (taken under a lock, given back after its PNG is written) and keeps at most ``most``, of
``most_bytes`` of pixels in all.
Every picture's figure is made by :func:`new_figure` (no pyplot: its registry of figures is
global, shared by the routes' threads) and written by :func:`png_of`.
"""

from __future__ import annotations

import io
import threading
from collections.abc import Callable, Hashable
from typing import Generic, Protocol, TypeVar

import matplotlib

matplotlib.use("Agg")  # no display: render to memory

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

F = TypeVar("F", bound="Drawing")
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


class Drawing(Protocol):
    """A picture's kept state: its matplotlib figure (and the artists it updates)."""

    figure: Figure


def held_bytes(drawing: Drawing) -> int:
    """The bytes of the pixels a drawn figure holds: its Agg buffer, RGBA at DPI."""
    width, height = drawing.figure.canvas.get_width_height()
    return 4 * width * height


class KeptFigures(Generic[F]):
    """At most ``most`` figures not in use, by layout key, holding at most ``most_bytes``.

    A drawn figure keeps its Agg buffer (4 bytes a pixel): a 24-panel map's is 14.5 MiB, so
    the pool bounds the pixels it holds as well as the figures (four of the largest held 58
    MiB before). A figure that would take the pool past ``most_bytes`` is dropped once drawn.
    """

    def __init__(self, most: int, most_bytes: int) -> None:
        """No figure kept yet."""
        self.most = most
        self.most_bytes = most_bytes
        self._kept: dict[Hashable, list[tuple[F, int]]] = {}
        self._lock = threading.Lock()

    def drawn(self, key: Hashable, make: Callable[[], F], draw: Callable[[F], bytes]) -> bytes:
        """``draw`` on a kept figure of layout ``key`` (or on ``make()``); the figure kept after.

        A figure whose drawing raises is not kept (its state is not known).
        """
        with self._lock:
            figures = self._kept.get(key)
            figure, size = figures.pop() if figures else (None, 0)
        if figure is None:
            figure = make()
            size = held_bytes(figure)
        picture = draw(figure)
        with self._lock:
            if self.count() < self.most and self.held() + size <= self.most_bytes:
                self._kept.setdefault(key, []).append((figure, size))
        return picture

    def count(self) -> int:
        """How many figures are kept (not in use)."""
        return sum(len(figures) for figures in self._kept.values())

    def held(self) -> int:
        """The bytes of pixels the kept figures hold (:func:`held_bytes`)."""
        return sum(size for figures in self._kept.values() for _, size in figures)
