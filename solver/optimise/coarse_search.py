"""The coarse search of the optimiser: a map over the bounds and its local maxima.

Where joint 1 turns about the base z axis the map is over (r, psi)
(:mod:`solver.optimise.symmetry`), each cell placed on its arc inside the bounds; otherwise over
(x, y, yaw). A free tool spin is
one more dimension of the map, and so is a free height z. Its local maxima, best first, are
the starts of the IPOPT solves, each with its IK branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress
from solver.core.robots import Robot
from solver.core.spatial import MAX_COORDINATE
from solver.optimise.search_space import PlacementBounds
from solver.optimise.symmetry import arc_point
from solver.path.pipeline import PreparedPath, SpinMode, require_family
from solver.path.placements import evaluate_placements

COARSE_STEP = 0.02  # m, of the coarse map (r or x, y)
COARSE_YAW_STEP = math.radians(15)  # rad, of the coarse map (psi, yaw and spin)
MAX_COARSE_CELLS = 50_000  # default limit on the coarse map (a box larger is an input error)


@dataclass(frozen=True)
class Cell:
    """A decision vector [x, y, yaw, spin, z] with its mu_path and IK branch index.

    ``coarse`` is the coarse map's cell a refined cell climbed from (:func:`refine_cells`),
    with its mu_path and branch; None for a cell of the coarse map itself.
    """

    vector: np.ndarray
    mu_path: float
    branch: int
    coarse: Cell | None = None


def _spin_values(bounds: PlacementBounds) -> tuple[np.ndarray, bool]:
    """The coarse map's spins, and whether they wrap (a whole turn)."""
    low, high = bounds.spin
    if high <= low:
        return np.array([low]), False
    wraps = high - low >= 2 * math.pi - 1e-9
    count = math.floor((high - low) / COARSE_YAW_STEP + 1e-9) + (0 if wraps else 1)
    return low + COARSE_YAW_STEP * np.arange(max(count, 1)), wraps


def _heights(bounds: PlacementBounds) -> np.ndarray:
    """The coarse map's heights: z, or its range at COARSE_STEP when z is free."""
    low, high = bounds.z_range
    return low + COARSE_STEP * np.arange(math.floor((high - low) / COARSE_STEP + 1e-9) + 1)


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
    max_poses: int | None = None,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
) -> list[Cell]:
    """Local maxima of a coarse map over the bounds, best first.

    Over (r, psi) at COARSE_STEP x COARSE_YAW_STEP when ``symmetric`` (each cell placed on its
    arc nearest the polar angle ``near``), else over (x, y, yaw); times the spins when the spin
    is free.

    Raises:
        InvalidInputError: the map would have more than ``max_cells`` cells, or more than
            ``max_poses`` placement-waypoint pairs (on ``bounds``), each pair weighed by the
            family's cost (:meth:`KinematicsFamily.path_cost`: 1 for a closed-form family).
    """
    spins, spin_wraps = _spin_values(bounds)
    heights = _heights(bounds)
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
    sizes = [len(spins), *sizes] if len(spins) > 1 else sizes
    sizes = [len(heights), *sizes] if len(heights) > 1 else sizes
    if math.prod(sizes) > max_cells:
        raise InvalidInputError(
            "bounds",
            f"the search box needs a coarse map of {math.prod(sizes)} cells "
            f"({' x '.join(map(str, sizes))} at {COARSE_STEP * 1000:.0f} mm, "
            f"{math.degrees(COARSE_YAW_STEP):.0f} deg); the limit is {max_cells}",
        )
    poses = math.prod(sizes) * path.n_waypoints
    family = require_family(robot)
    work = math.prod(sizes) * family.path_cost(path.n_waypoints)
    if max_poses is not None and work > max_poses:
        size = f"the search box's coarse map of {math.prod(sizes)} cells * {path.n_waypoints} "
        size += f"waypoints = {poses} poses"
        if work != poses:
            size += f", as work {work:.4g} closed-form poses ({family.name} IK)"
        raise InvalidInputError("bounds", f"{size}; the limit is {max_poses}")
    # One spin's cells: where each is reported (inside the box) and where it is evaluated.
    points: list[tuple[float, float, float] | None]
    evaluated: list[tuple[float, float, float] | None]
    if symmetric:
        radii = r_low + COARSE_STEP * np.arange(math.floor((r_high - r_low) / COARSE_STEP) + 1)
        psis = -math.pi + COARSE_YAW_STEP * np.arange(n_psi)
        shape: tuple[int, ...] = (len(psis), len(radii))
        points = [arc_point(float(r), float(p), bounds, near=near) for p in psis for r in radii]
        # mu_path is the same all along an arc: evaluate every cell at the polar angle `near`,
        # so that the cells of one psi share a yaw (the cheap case of evaluate_placements),
        # unless that is farther than any placement may be.
        evaluated = [
            (float(r * math.cos(near)), float(r * math.sin(near)), float(p + near))
            if r <= MAX_COORDINATE
            else None
            for p in psis
            for r in radii
        ]
        periodic: tuple[bool, ...] = (True, False)
    else:
        axes = [
            low + step * np.arange(math.floor((high - low) / step + 1e-9) + 1)
            for (low, high), step in (
                (bounds.x, COARSE_STEP),
                (bounds.y, COARSE_STEP),
                (bounds.yaw, COARSE_YAW_STEP),
            )
        ]
        shape = (len(axes[2]), len(axes[1]), len(axes[0]))
        points = [(float(x), float(y), float(w)) for w in axes[2] for y in axes[1] for x in axes[0]]
        evaluated = [None] * len(points)
        periodic = (bounds.yaw[1] - bounds.yaw[0] >= 2 * math.pi - 1e-9, False, False)
    vectors: list[np.ndarray | None] = []
    rows = []
    for z in heights:
        for spin in spins:
            for point, where in zip(points, evaluated, strict=True):
                at = where or point
                if point is None or at is None:
                    vectors.append(None)
                    continue
                vectors.append(np.array([*point, spin, z]))
                rows.append([at[0], at[1], z, at[2], spin])
    full_shape = (len(heights), len(spins), *shape)
    mu = np.full(len(vectors), np.nan)
    branch = np.zeros(len(vectors), dtype=int)
    inside_index = [i for i, v in enumerate(vectors) if v is not None]
    if inside_index:
        result = evaluate_placements(
            robot,
            path,
            np.array(rows),
            max_joint_step=max_joint_step,
            spin_mode=spin_mode,
            progress=progress,
            runner=runner,
        )
        mu[inside_index], branch[inside_index] = result.mu_path, result.branch
    cells = []
    for index in _local_maxima(mu.reshape(full_shape), (False, spin_wraps, *periodic)):
        k = int(np.ravel_multi_index(index, full_shape))
        vector = vectors[k]
        if vector is not None:
            cells.append(Cell(vector, float(mu[k]), int(branch[k])))
    return cells
