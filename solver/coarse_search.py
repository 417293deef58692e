"""The coarse search of the optimiser: a map over the bounds and its local maxima.

Where joint 1 turns about the base z axis the map is over (r, psi) (:mod:`solver.symmetry`),
each cell placed on its arc inside the bounds; otherwise over (x, y, yaw). Its local maxima,
best first, are the starts of the IPOPT solves, each with its IK branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.exceptions import InvalidInputError
from solver.pipeline import PreparedPath, SpinMode
from solver.placements import evaluate_placements
from solver.robots import Robot
from solver.spatial import MAX_COORDINATE
from solver.symmetry import PlacementBounds, arc_point

COARSE_STEP = 0.02  # m, of the coarse map (r or x, y)
COARSE_YAW_STEP = math.radians(15)  # rad, of the coarse map (psi or yaw)
MAX_COARSE_CELLS = 50_000  # default limit on the coarse map (a box larger is an input error)

Point = tuple[float, float, float]  # x (m), y (m), yaw (rad)


@dataclass(frozen=True)
class Cell:
    """A placement (x, y, yaw) with its mu_path and IK branch index."""

    placement: Point
    mu_path: float
    branch: int


def _local_maxima(values: np.ndarray, periodic: tuple[bool, ...]) -> list[tuple[int, ...]]:
    """Indices of cells not below any neighbour (NaN never is one), best first."""
    padded = np.where(np.isnan(values), -np.inf, values)
    is_max = np.isfinite(padded)
    for axis, wraps in enumerate(periodic):
        for shift in (1, -1):
            neighbour = np.roll(padded, shift, axis=axis)
            if not wraps:
                edge = [slice(None)] * values.ndim
                edge[axis] = slice(0, 1) if shift == 1 else slice(-1, None)
                neighbour[tuple(edge)] = -np.inf
            is_max &= padded >= neighbour
    order = np.argsort(-padded[is_max], kind="stable")
    return [tuple(int(i) for i in idx) for idx in np.argwhere(is_max)[order]]


def coarse_cells(
    robot: Robot,
    path: PreparedPath,
    bounds: PlacementBounds,
    *,
    symmetric: bool,
    near: float,
    max_joint_step: float,
    spin_mode: SpinMode = "fixed",
    max_cells: int = MAX_COARSE_CELLS,
) -> list[Cell]:
    """Local maxima of a coarse map over the bounds, best first.

    Over (r, psi) at COARSE_STEP x COARSE_YAW_STEP when ``symmetric`` (each cell placed on its
    arc nearest the polar angle ``near``), else over (x, y, yaw).

    Raises:
        InvalidInputError: the map would have more than ``max_cells`` cells (on ``bounds``).
    """
    n_psi = round(2 * math.pi / COARSE_YAW_STEP)
    if symmetric:
        corners = [math.hypot(x, y) for x in bounds.x for y in bounds.y]
        inside_x = min(max(0.0, bounds.x[0]), bounds.x[1])
        inside_y = min(max(0.0, bounds.y[0]), bounds.y[1])
        r_low, r_high = math.hypot(inside_x, inside_y), max(corners)
        sizes = [math.floor((r_high - r_low) / COARSE_STEP) + 1, n_psi]
    else:
        sizes = [
            math.floor((high - low) / step + 1e-9) + 1
            for (low, high), step in (
                (bounds.x, COARSE_STEP),
                (bounds.y, COARSE_STEP),
                (bounds.yaw, COARSE_YAW_STEP),
            )
        ]
    if math.prod(sizes) > max_cells:
        raise InvalidInputError(
            "bounds",
            f"the search box needs a coarse map of {math.prod(sizes)} cells "
            f"({' x '.join(map(str, sizes))} at {COARSE_STEP * 1000:.0f} mm, "
            f"{math.degrees(COARSE_YAW_STEP):.0f} deg); the limit is {max_cells}",
        )
    if symmetric:
        radii = r_low + COARSE_STEP * np.arange(sizes[0])
        psis = -math.pi + COARSE_YAW_STEP * np.arange(n_psi)
        shape: tuple[int, ...] = (len(psis), len(radii))
        points: list[Point | None] = [
            arc_point(float(r), float(p), bounds, near=near) for p in psis for r in radii
        ]
        # mu_path is the same all along an arc: evaluate every cell at the polar angle `near`,
        # so that the cells of one psi share a yaw (the cheap case of evaluate_placements),
        # unless that is farther than any placement may be.
        evaluated: list[Point | None] = [
            (float(r * math.cos(near)), float(r * math.sin(near)), float(p + near))
            if r <= MAX_COORDINATE
            else None
            for p in psis
            for r in radii
        ]
        periodic: tuple[bool, ...] = (True, False)
    else:
        axes = [
            low + step * np.arange(size)
            for (low, _), step, size in zip(
                (bounds.x, bounds.y, bounds.yaw),
                (COARSE_STEP, COARSE_STEP, COARSE_YAW_STEP),
                sizes,
                strict=True,
            )
        ]
        shape = (len(axes[2]), len(axes[1]), len(axes[0]))
        points = [(float(x), float(y), float(w)) for w in axes[2] for y in axes[1] for x in axes[0]]
        evaluated = [None] * len(points)
        periodic = (bounds.yaw[1] - bounds.yaw[0] >= 2 * math.pi - 1e-9, False, False)
    inside, rows = [], []
    for i, point in enumerate(points):
        at = evaluated[i] or point
        if point is not None and at is not None:
            inside.append(i)
            rows.append([at[0], at[1], bounds.z, at[2]])
    mu = np.full(len(points), np.nan)
    branch = np.zeros(len(points), dtype=int)
    if inside:
        placements = np.array(rows)
        result = evaluate_placements(
            robot, path, placements, max_joint_step=max_joint_step, spin_mode=spin_mode
        )
        mu[inside], branch[inside] = result.mu_path, result.branch
    flat = np.ravel_multi_index
    cells = []
    for index in _local_maxima(mu.reshape(shape), periodic):
        k = int(flat(index, shape))
        point = points[k]
        if point is not None:
            cells.append(Cell(point, float(mu[k]), int(branch[k])))
    return cells
