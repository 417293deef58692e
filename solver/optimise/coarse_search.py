"""The coarse search of the optimiser: a map over the bounds and its local maxima.

Where joint 1 turns about the base z axis the map is over (r, psi)
(:mod:`solver.optimise.symmetry`), each cell placed on its arc inside the bounds; otherwise over
(x, y, yaw). A free tool spin is one more dimension of the map, and so is a free height z. Its
local maxima and the box's corners that run (:func:`box_corners`), best first, are the starts of
the IPOPT solves, each with its IK branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress
from solver.core.spatial import MAX_COORDINATE
from solver.core.written import stepped_as_written
from solver.optimise.candidate import Search
from solver.optimise.coarse_rows import map_values, mapped_waypoints
from solver.optimise.failures import Tried
from solver.optimise.search_space import VARIABLES, PlacementBounds, decision_vector
from solver.optimise.symmetry import arc_point
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem

COARSE_STEP = 0.02  # m, of the coarse map (r or x, y)
COARSE_YAW_STEP = math.radians(15)  # rad, of the coarse map (psi, yaw and spin)
MAX_COARSE_CELLS = 50_000  # default limit on the coarse map (a box larger is an input error)


@dataclass(frozen=True)
class Cell:
    """A decision vector (:mod:`solver.optimise.search_space`), its mu_path and IK branch index.

    ``mu_path`` is the index searched: mu_acc where the robot has acceleration limits.

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
    return stepped_as_written(low, COARSE_STEP, math.floor((high - low) / COARSE_STEP + 1e-9) + 1)


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


def _axis(
    low: float, high: float, step: float, *, ends: bool = False, slack: float = 1e-9
) -> np.ndarray:
    """A coarse axis: ``low`` and every ``step`` after it up to ``high`` (and its end).

    ``slack``: a step that ends within it past ``high`` still counts (the box's axes take
    1e-9 for rounding; the symmetric search's radius axis has always taken none).

    With ``ends`` (the yaw's, unless the range is a whole turn, whose end is its start), the
    range's end is a sample of its own where the last step stops more than half a step short
    of it, so that no yaw of the range is farther than half a step from a sample. An optimum
    often lies on the box's edge, where the bounds stop it, and from a sample up to 15 degrees
    short of it IPOPT may climb to another maximum (the UR5 on a wall,
    tests/solver/families/test_tilted_base.py: 10 % lower). The lengths' 20 mm steps leave
    little to their ends; none is added there (a map's size is its work).

    The values are stepped in the decimals ``low`` and ``step`` are written in
    (:func:`solver.core.written.stepped_as_written`), as a map's grid is: a cell that is itself
    the answer reads x -0.16, not -0.16000000000000003.
    """
    axis = stepped_as_written(low, step, math.floor((high - low) / step + slack) + 1)
    if ends and high - axis[-1] > step / 2:
        axis = np.append(axis, high)
    return axis


def _map_sizes(
    bounds: PlacementBounds, *, symmetric: bool, n_spins: int, n_heights: int
) -> tuple[list[int], tuple[float, float]]:
    """The coarse map's sizes, its largest axes first, and (r_low, r_high) when symmetric."""
    n_psi = round(2 * math.pi / COARSE_YAW_STEP)
    radii = (0.0, 0.0)
    if symmetric:
        corners = [math.hypot(x, y) for x in bounds.x for y in bounds.y]
        inside_x = min(max(0.0, bounds.x[0]), bounds.x[1])
        inside_y = min(max(0.0, bounds.y[0]), bounds.y[1])
        radii = (math.hypot(inside_x, inside_y), max(corners))
        sizes = [len(_axis(*radii, COARSE_STEP, slack=0.0)), n_psi]
    else:
        sizes = [
            len(_axis(*bounds.x, COARSE_STEP)),
            len(_axis(*bounds.y, COARSE_STEP)),
            len(_axis(*bounds.yaw, COARSE_YAW_STEP, ends=not _whole_turn(bounds))),
        ]
    sizes = [n_spins, *sizes] if n_spins > 1 else sizes
    sizes = [n_heights, *sizes] if n_heights > 1 else sizes
    return sizes, radii


def _check_map_size(
    problem: PathProblem, sizes: list[int], *, max_cells: int, max_poses: int | None
) -> None:
    """Refuse a coarse map over ``max_cells`` cells or ``max_poses`` weighed poses (on bounds)."""
    if math.prod(sizes) > max_cells:
        raise InvalidInputError(
            "bounds",
            f"the search box needs a coarse map of {math.prod(sizes)} cells "
            f"({' x '.join(map(str, sizes))} at {COARSE_STEP * 1000:.0f} mm, "
            f"{math.degrees(COARSE_YAW_STEP):.0f} deg); the limit is {max_cells}",
        )
    n_waypoints = mapped_waypoints(problem.prepared.n_waypoints)
    poses = math.prod(sizes) * n_waypoints
    family = problem.family
    work = math.prod(sizes) * problem.path_cost(n_waypoints)
    if max_poses is not None and work > max_poses:
        size = f"the search box's coarse map of {math.prod(sizes)} cells * {n_waypoints} "
        size += f"waypoints = {poses} poses"
        if n_waypoints < problem.prepared.n_waypoints:
            size += f" (a program of {problem.prepared.n_waypoints} waypoints is mapped on "
            size += f"{n_waypoints} at most)"
        if work != poses:
            size += f", as work {work:.4g} closed-form poses ({family.name} IK)"
        raise InvalidInputError("bounds", f"{size}; the limit is {max_poses}")


def coarse_map_cells(bounds: PlacementBounds, *, symmetric: bool) -> int:
    """How many cells the coarse map of ``bounds`` has (what :func:`coarse_cells` evaluates).

    Cells outside the box are not evaluated, so this is an upper bound of its placements.
    """
    sizes, _ = _map_sizes(
        bounds,
        symmetric=symmetric,
        n_spins=len(_spin_values(bounds)[0]),
        n_heights=len(_heights(bounds)),
    )
    return math.prod(sizes)


_Point = tuple[float, float, float] | None  # (x, y, yaw) of a cell, None outside the box


def _one_spin_cells(
    bounds: PlacementBounds, radii: tuple[float, float], *, symmetric: bool, near: float
) -> tuple[list[_Point], list[_Point], tuple[int, ...], tuple[bool, ...]]:
    """One spin's cells, where each is reported and where it is evaluated.

    Returns:
        the cells' (x, y, yaw) inside the box (None: no point of the cell is), where each is
        evaluated (None: there), the cells' shape and which of its axes wrap.
    """
    if symmetric:
        r_low, r_high = radii
        n_psi = round(2 * math.pi / COARSE_YAW_STEP)
        radius = _axis(r_low, r_high, COARSE_STEP, slack=0.0)
        psis = -math.pi + COARSE_YAW_STEP * np.arange(n_psi)
        points = [arc_point(float(r), float(p), bounds, near=near) for p in psis for r in radius]
        # mu_path is the same all along an arc: evaluate every cell at the polar angle `near`,
        # so that the cells of one psi share a yaw (the cheap case of evaluate_placements),
        # unless that is farther than any placement may be.
        evaluated: list[_Point] = [
            (float(r * math.cos(near)), float(r * math.sin(near)), float(p + near))
            if r <= MAX_COORDINATE
            else None
            for p in psis
            for r in radius
        ]
        return points, evaluated, (len(psis), len(radius)), (True, False)
    axes = [
        _axis(*bounds.x, COARSE_STEP),
        _axis(*bounds.y, COARSE_STEP),
        _axis(*bounds.yaw, COARSE_YAW_STEP, ends=not _whole_turn(bounds)),
    ]
    shape = (len(axes[2]), len(axes[1]), len(axes[0]))
    points = [(float(x), float(y), float(w)) for w in axes[2] for y in axes[1] for x in axes[0]]
    periodic = (_whole_turn(bounds), False, False)
    return points, [None] * len(points), shape, periodic


def _whole_turn(bounds: PlacementBounds) -> bool:
    """Whether the box's yaw range is a whole turn (or more): its end is its start."""
    return bounds.yaw[1] - bounds.yaw[0] >= 2 * math.pi - 1e-9


def coarse_cells(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    symmetric: bool,
    near: float,
    max_cells: int = MAX_COARSE_CELLS,
    max_poses: int | None = None,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> list[Cell]:
    """Local maxima of a coarse map over the bounds, best first.

    Over (r, psi) at COARSE_STEP x COARSE_YAW_STEP when ``symmetric`` (each cell placed on its
    arc nearest the polar angle ``near``), else over (x, y, yaw); times the spins when the spin
    is free. Every cell on the problem's branch policy (``auto``, for the optimisers). A
    program longer than :data:`solver.optimise.coarse_rows.MAX_MAP_ROWS` is mapped on the
    waypoints that bind its best cells, and only those cells, verified on the whole path, are
    returned (:mod:`solver.optimise.coarse_rows`). ``tried`` keeps the cells evaluated on the
    whole path (:mod:`solver.optimise.failures`).

    Raises:
        InvalidInputError: the map would have more than ``max_cells`` cells, or more than
            ``max_poses`` placement-waypoint pairs (on ``bounds``), each pair weighed by the
            family's cost (:meth:`KinematicsFamily.path_cost`: 1 for a closed-form family).
    """
    spins, spin_wraps = _spin_values(bounds)
    heights = _heights(bounds)
    sizes, radii = _map_sizes(
        bounds, symmetric=symmetric, n_spins=len(spins), n_heights=len(heights)
    )
    _check_map_size(problem, sizes, max_cells=max_cells, max_poses=max_poses)
    points, evaluated, shape, periodic = _one_spin_cells(
        bounds, radii, symmetric=symmetric, near=near
    )
    vectors: list[np.ndarray | None] = []
    rows = []
    for z in heights:
        for spin in spins:
            for point, where in zip(points, evaluated, strict=True):
                at = where or point
                if point is None or at is None:
                    vectors.append(None)
                    continue
                x, y, yaw = point
                vectors.append(decision_vector(x=x, y=y, yaw=yaw, spin=spin, z=z))
                rows.append([at[0], at[1], z, at[2], spin])  # a placement row
    full_shape = (len(heights), len(spins), *shape)
    mu = np.full(len(vectors), np.nan)
    branch = np.zeros(len(vectors), dtype=int)
    inside_index = [i for i, v in enumerate(vectors) if v is not None]
    periodic_axes = (False, spin_wraps, *periodic)
    if inside_index:
        position = np.full(len(vectors), -1)
        position[inside_index] = np.arange(len(inside_index))

        def maxima(values: np.ndarray) -> list[int]:
            """The local maxima of the map with ``values`` inside, as indices of ``rows``."""
            full = np.full(len(vectors), np.nan)
            full[inside_index] = values
            found = _local_maxima(full.reshape(full_shape), periodic_axes)
            return [int(position[np.ravel_multi_index(i, full_shape)]) for i in found]

        result = map_values(
            problem, np.array(rows), maxima, progress=progress, runner=runner, tried=tried
        )
        mu[inside_index], branch[inside_index] = result.feed_index, result.branch
    cells = []
    for index in _local_maxima(mu.reshape(full_shape), periodic_axes):
        k = int(np.ravel_multi_index(index, full_shape))
        vector = vectors[k]
        if vector is not None:
            cells.append(Cell(vector, float(mu[k]), int(branch[k])))
    for extra in (
        box_corners(problem, bounds, runner=runner, tried=tried),
        box_edges(problem, bounds, symmetric=symmetric, runner=runner, tried=tried),
    ):  # a corner or edge point that is one of the cells already is there once
        cells += [c for c in extra if not any(_same_placement(c.vector, o.vector) for o in cells)]
    return sorted(cells, key=lambda cell: -cell.mu_path)  # stable: the map's first


def search_cells(
    problem: PathProblem,
    bounds: PlacementBounds,
    settings: Search,
    *,
    progress: Progress | None,
    max_poses: int | None = None,
) -> list[Cell]:
    """:func:`coarse_cells` with a search's settings (its symmetry, start, limit, runner, tally)."""
    return coarse_cells(
        problem,
        bounds,
        symmetric=settings.symmetric,
        near=settings.near,
        max_cells=settings.max_coarse_cells,
        max_poses=max_poses,
        progress=progress,
        runner=settings.runner,
        tried=settings.tried,
    )


_ANGLES = [VARIABLES.index("yaw"), VARIABLES.index("spin")]
_TWO_PI = 2.0 * math.pi
SAME_START = 1e-4
"""m and rad: corners and cells closer than this (angles up to whole turns) are one start."""


def _same_placement(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two decision vectors are one start: within SAME_START, angles up to turns."""
    apart = np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))
    turns = apart[_ANGLES] / _TWO_PI
    apart[_ANGLES] = _TWO_PI * np.abs(turns - np.round(turns))
    return bool(np.all(apart <= SAME_START))


def _whole_turns(bounds: PlacementBounds, variable: int) -> bool:
    """Whether ``variable`` is an angle whose two bounds are one start (whole turns apart)."""
    if variable not in _ANGLES:
        return False
    moved = bounds.lower.copy()
    moved[variable] = bounds.upper[variable]
    return _same_placement(moved, bounds.lower)


def corner_vectors(bounds: PlacementBounds) -> np.ndarray:
    """The decision vectors of the box's distinct corners: every free variable at either bound.

    An angle whose range is whole turns (yaw over [-pi, pi], or [-3.1416, 3.1416] as typed)
    has one corner value: its two bounds are one start, and twice the corners filled the
    refinement's starts with pairs of the same placement (the optimiser audit, stop 53).
    """
    lower, upper = bounds.lower, bounds.upper
    free = [int(v) for v in np.flatnonzero(bounds.free) if not _whole_turns(bounds, int(v))]
    vectors = np.tile(lower, (1 << len(free), 1))
    for k in range(len(vectors)):
        for bit, variable in enumerate(free):
            if k >> bit & 1:
                vectors[k, variable] = upper[variable]
    return vectors


def box_corners(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> list[Cell]:
    """The box's corners that run, as cells (their whole path's mu_path and branch).

    The bounds often stop the optimum, and the polar map samples a corner poorly: near the
    box's largest radius an (r, psi) cell exists only at the corner. A UR5 box had two corner
    maxima with a dip between, the map's cells near the worse one: the casadi method answered
    0.33136 m/s where the other corner runs at 0.33379 (the optimiser audits, stops 52 and 53).
    At most 2^5 placements, on the whole path.
    """
    vectors = corner_vectors(bounds)
    rows = bounds.rows(vectors)
    result = evaluate_placements(problem, rows, runner=runner)
    if tried is not None:
        tried.record(rows, result.reason, result.failed_waypoint)
    return [
        Cell(vectors[k], float(result.feed_index[k]), int(result.branch[k]))
        for k in np.flatnonzero(np.isfinite(result.feed_index))
    ]


def _edge_samples(bounds: PlacementBounds, variable: int) -> np.ndarray:
    """A variable's samples along an edge at the coarse map's steps, without the corners."""
    low, high = bounds.lower[variable], bounds.upper[variable]
    if variable in _ANGLES:
        samples = _axis(low, high, COARSE_YAW_STEP, ends=not _whole_turns(bounds, variable))
    else:
        samples = _axis(low, high, COARSE_STEP, ends=True)
    inner: np.ndarray = samples[(samples > low + SAME_START) & (samples < high - SAME_START)]
    return inner


def edge_lines(bounds: PlacementBounds) -> list[np.ndarray]:
    """The box's edges as lines of decision vectors, each without its corners.

    An edge runs along one free variable, the others at a corner (:func:`corner_vectors`);
    its samples are the coarse map's steps (20 mm, 15 degrees). An angle of whole turns has
    one corner value, so its edges are whole circles.
    """
    corners = corner_vectors(bounds)
    lines = []
    for variable in np.flatnonzero(bounds.free):
        samples = _edge_samples(bounds, int(variable))
        if not len(samples):
            continue
        starts = corners[corners[:, variable] == bounds.lower[variable]]
        for start in starts:
            line = np.tile(start, (len(samples), 1))
            line[:, variable] = samples
            lines.append(line)
    return lines


def box_edges(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    symmetric: bool,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> list[Cell]:
    """The local maxima along the box's edges (:func:`edge_lines`) that run, as cells.

    The bounds often stop the optimum on an edge, which the polar map (cells of (r, psi),
    each an arc) samples only where an arc happens to end there: a UR5 box had two maxima along
    its edge at the largest y and yaw, and the casadi method answered the worse one, 0.63 %
    below (the optimiser audit, stop 53). The samples are mapped as the coarse map is
    (:func:`solver.optimise.coarse_rows.map_values`: a long program on a set of waypoints,
    its maxima verified on the whole path); a point not below its neighbours on its line is a
    maximum. Only for the polar map (``symmetric``): the map over (x, y, yaw) has the box's
    edges on its own axes (at the lower bounds and, where the range is whole steps, the upper).
    """
    lines = edge_lines(bounds) if symmetric else []
    if not lines:
        return []
    vectors = np.concatenate(lines)
    ends = np.cumsum([len(line) for line in lines])

    def maxima(values: np.ndarray) -> list[int]:
        found = []
        for start, end in zip([0, *ends[:-1]], ends, strict=True):
            line = values[start:end]
            found += [start + index[0] for index in _local_maxima(line, (False,))]
        return sorted(found, key=lambda k: -values[k])

    result = map_values(problem, bounds.rows(vectors), maxima, runner=runner, tried=tried)
    return [
        Cell(vectors[k], float(result.feed_index[k]), int(result.branch[k]))
        for k in maxima(result.feed_index)
        if np.isfinite(result.feed_index[k])
    ]


def box_edge_points(bounds: PlacementBounds, *, symmetric: bool) -> int:
    """How many placements :func:`box_edges` maps."""
    return sum(len(line) for line in edge_lines(bounds)) if symmetric else 0
