"""The map's picture on a new figure against a kept one (``service/render``), printed by run.py.

Each panel count: the ERK-size map with 1, 2 and 6 (yaw) panels drawn on a new figure (what
every picture cost before the figures were kept) and through ``render_png`` (a kept figure,
two maps alternated so each draw changes what the figure shows), best of a few, alternated
in the same run.
"""

from __future__ import annotations

import numpy as np
from timing import best_time  # bench/timing.py, beside it

from service.render.map_picture import MapFigure, render_png
from solver.core.robots import Robot
from solver.path.capability_map import capability_map
from solver.path.problem import PathProblem


def picture_lines(
    robot: Robot, path: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float, *, smoke: bool
) -> None:
    """Print the time of the map's PNG on a new figure and on a kept one, per panel count."""
    problem = PathProblem.of(robot, path)
    repeats = 2 if smoke else 5
    figures = []
    for panels in (1, 2) if smoke else (1, 2, 6):
        maps = [
            capability_map(problem, xs=xs, ys=ys, z=z, yaws=np.linspace(0.0, turn, panels))
            for turn in (0.5, 1.0)
        ]
        render_png(maps[0], title="warm-up")  # a figure of this panel count kept
        new = kept = float("inf")
        for k in range(repeats):
            cmap, n = maps[k % 2], panels
            new = min(new, best_time(lambda c=cmap, n=n: MapFigure(n).png(c, title="map"), 1))
            kept = min(kept, best_time(lambda c=cmap: render_png(c, title="map"), 1))
        figures.append(
            f"{panels} panel{'s' if panels > 1 else ''} {new * 1e3:.0f} -> {kept * 1e3:.0f} ms "
            f"({new / kept:.2f}x)"
        )
    print(f"map PNG, a new figure -> a kept one (best of {repeats}): " + "; ".join(figures))
