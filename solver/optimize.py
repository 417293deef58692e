"""The best placement of a path: maximise mu_path over (x, y, yaw) in a box (spec section 6).

Two methods, each checked by the evaluator:

- ``casadi``: a coarse map finds the local maxima (over (r, psi) where the first joint turns
  about the base z axis, over (x, y, yaw) otherwise); from the best few, each on its own IK
  branch, IPOPT solves the epigraph NLP of :mod:`solver.placement_nlp`.
- ``scipy``: differential evolution over (x, y, yaw), every generation one batch through
  :mod:`solver.placements`, then SLSQP on the epigraph form with finite-difference gradients
  (:mod:`solver.placement_scipy`).

Whatever a solver returns is only a candidate: the answer is the candidate (or the best coarse
cell, so never less than the map) with the highest mu_path by :func:`solver.evaluate.evaluate_path`,
and the reported placement and mu_path are the evaluator's. Where the symmetry holds, every
candidate is first moved along its arc to the point nearest the start (inside the bounds), so
the reported (x, y, yaw) is deterministic.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from solver.evaluate import DEFAULT_MAX_JOINT_STEP, PathEvaluation, evaluate_path
from solver.exceptions import InvalidInputError
from solver.ik.ur_analytic import BRANCHES
from solver.placement_nlp import PlacementNlp
from solver.placement_scipy import global_search, polish
from solver.placements import PreparedPath, evaluate_placements, prepare_path
from solver.robots import Robot
from solver.spatial import MAX_COORDINATE, Placement
from solver.symmetry import PlacementBounds, arc_coordinates, arc_point, turns_about_base_z

Method = Literal["casadi", "scipy"]
COARSE_STEP = 0.02  # m, of the coarse map (r or x, y)
COARSE_YAW_STEP = math.radians(15)  # rad, of the coarse map (psi or yaw)
N_STARTS = 4  # IPOPT solves, from the best local maxima of the coarse map
MAX_COARSE_CELLS = 50_000  # default limit on the coarse map (a box larger is an input error)


@dataclass(frozen=True)
class SolverReport:
    """What the optimiser did: its name, the status of the winning solve, iterations, seconds."""

    name: str
    status: str
    iterations: int
    seconds: float


@dataclass(frozen=True)
class PlacementOptimum:
    """The best placement found, as the evaluator sees it.

    Attributes:
        placement: the optimum (inside the bounds).
        mu_path: m/s, the evaluator's mu_path there.
        evaluation: the evaluator's whole answer there.
        start: the start placement; start_mu_path its mu_path (None when infeasible).
        improvement_percent: 100 (mu_path / start_mu_path - 1); None without a feasible start.
        solver: what the optimiser did.
        symmetric: whether the search used the (r, psi) symmetry.
    """

    placement: Placement
    mu_path: float
    evaluation: PathEvaluation
    start: Placement
    start_mu_path: float | None
    improvement_percent: float | None
    solver: SolverReport
    symmetric: bool


Point = tuple[float, float, float]  # x (m), y (m), yaw (rad)


@dataclass(frozen=True)
class Cell:
    """A placement (x, y, yaw) with its mu_path and IK branch index."""

    placement: Point
    mu_path: float
    branch: int


def check_bounds(bounds: PlacementBounds) -> None:
    """Raise InvalidInputError naming the range that is not finite, reversed or too far."""
    for name, (low, high) in (("x", bounds.x), ("y", bounds.y), ("yaw", bounds.yaw)):
        if not (math.isfinite(low) and math.isfinite(high) and low <= high):
            raise InvalidInputError(f"bounds.{name}", f"needs finite [min, max], got {[low, high]}")
        if name != "yaw" and max(abs(low), abs(high)) > MAX_COORDINATE:
            raise InvalidInputError(f"bounds.{name}", f"beyond +-{MAX_COORDINATE} m")
    if not math.isfinite(bounds.z) or abs(bounds.z) > MAX_COORDINATE:
        raise InvalidInputError("z", f"{bounds.z!r} m is not a finite height within the cell")


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
        result = evaluate_placements(robot, path, placements, max_joint_step=max_joint_step)
        mu[inside], branch[inside] = result.mu_path, result.branch
    flat = np.ravel_multi_index
    cells = []
    for index in _local_maxima(mu.reshape(shape), periodic):
        k = int(flat(index, shape))
        point = points[k]
        if point is not None:
            cells.append(Cell(point, float(mu[k]), int(branch[k])))
    return cells


def _place_on_arc(
    placement: tuple[float, float, float], bounds: PlacementBounds, near: float, symmetric: bool
) -> Placement:
    """The candidate, clamped into the box, moved along its arc to the point nearest ``near``.

    Solvers may end a hair outside their bounds (IPOPT by its bound relaxation, 1e-8): the
    clamp is what makes every reported placement inside them; the evaluator then judges it.
    """
    x, y, yaw = (
        min(max(value, low), high)
        for value, (low, high) in zip(placement, (bounds.x, bounds.y, bounds.yaw), strict=True)
    )
    if symmetric:
        moved = arc_point(*arc_coordinates(x, y, yaw), bounds, near=near)
        if moved is not None:
            x, y, yaw = moved
    return Placement(x, y, bounds.z, yaw)


def optimize_placement(
    robot: Robot,
    waypoints_in_workpiece: np.ndarray,
    *,
    bounds: PlacementBounds,
    start: Placement | None = None,
    method: Method = "casadi",
    max_joint_step: float = DEFAULT_MAX_JOINT_STEP,
    max_coarse_cells: int = MAX_COARSE_CELLS,
) -> PlacementOptimum | None:
    """The placement inside ``bounds`` where the path runs fastest.

    Args:
        robot: a UR arm of the catalogue, with its speed limits and TCP.
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i (metres).
        bounds: x, y, yaw ranges and the height z.
        start: the start placement (default: the centre of the bounds), reported with its
            mu_path and used to choose the point of the optimal arc.
        method: ``"casadi"`` (IPOPT from the coarse map's maxima) or ``"scipy"``.
        max_joint_step: rad, as for :func:`solver.evaluate.evaluate_path`.
        max_coarse_cells: the largest coarse map the casadi method may make.

    Returns:
        The optimum (never below the start), or None when neither the start nor any placement
        the search tried is feasible.

    Raises:
        InvalidInputError: bad bounds, a start outside them, an unknown method, or a box whose
            coarse map is over ``max_coarse_cells``.
    """
    began = time.perf_counter()
    check_bounds(bounds)
    if method not in ("casadi", "scipy"):
        raise InvalidInputError("method", f"unknown method {method!r}; use casadi or scipy")
    if start is None:
        start = Placement(*bounds.centre()[:2], bounds.z, bounds.centre()[2])
    if not bounds.contains(start.x, start.y, start.yaw) or start.z != bounds.z:
        raise InvalidInputError("start", f"{start} is outside the bounds {bounds}")
    path = np.asarray(waypoints_in_workpiece, dtype=float)
    prepared = prepare_path(robot, path)
    start_evaluation = evaluate_path(robot, path, start, max_joint_step=max_joint_step)
    symmetric = turns_about_base_z(robot)
    near = math.atan2(start.y, start.x)
    if method == "casadi":
        cells = coarse_cells(
            robot,
            prepared,
            bounds,
            symmetric=symmetric,
            near=near,
            max_joint_step=max_joint_step,
            max_cells=max_coarse_cells,
        )
        candidates, statuses, iterations = _casadi(
            robot, path, prepared, bounds, cells, max_joint_step
        )
        name = "ipopt (casadi), from the coarse map's maxima"
    else:
        candidates, statuses, iterations = _scipy(
            robot, prepared, bounds, max_joint_step, symmetric
        )
        name = "differential_evolution + SLSQP (scipy)"
    # The start last: it is the answer only when nothing the solver found is better.
    candidates = [*candidates, (start.x, start.y, start.yaw)]
    statuses = [*statuses, "no better placement found than the start"]
    best: tuple[float, Placement, PathEvaluation, str] | None = None
    for candidate, status in zip(candidates, statuses, strict=True):
        placement = _place_on_arc(candidate, bounds, near, symmetric)
        evaluation = evaluate_path(robot, path, placement, max_joint_step=max_joint_step)
        if evaluation.mu_path is not None and (best is None or evaluation.mu_path > best[0]):
            best = (evaluation.mu_path, placement, evaluation, status)
    if best is None:
        return None
    mu_path, placement, evaluation, status = best
    start_mu = start_evaluation.mu_path
    return PlacementOptimum(
        placement=placement,
        mu_path=mu_path,
        evaluation=evaluation,
        start=start,
        start_mu_path=start_mu,
        improvement_percent=None if not start_mu else 100.0 * (mu_path / start_mu - 1.0),
        solver=SolverReport(name, status, iterations, time.perf_counter() - began),
        symmetric=symmetric,
    )


def _casadi(
    robot: Robot,
    path: np.ndarray,
    prepared: PreparedPath,
    bounds: PlacementBounds,
    cells: list[Cell],
    max_joint_step: float,
) -> tuple[list[tuple[float, float, float]], list[str], int]:
    """Candidates: the best coarse cell, then IPOPT's optimum from each of the best cells."""
    if not cells:
        return [], [], 0
    candidates, statuses = [cells[0].placement], ["best cell of the coarse map"]
    if prepared.pure_rotation.any() or cells[0].mu_path <= 0.0:
        return candidates, ["mu_path is 0 everywhere: the path turns on the spot"], 0
    nlp = PlacementNlp(robot, prepared, path[:, :3, :3], bounds, max_joint_step=max_joint_step)
    iterations = 0
    for cell in cells[:N_STARTS]:
        x, y, yaw = cell.placement
        at_start = evaluate_path(
            robot,
            path,
            Placement(x, y, bounds.z, yaw),
            branch=BRANCHES[cell.branch],
            max_joint_step=max_joint_step,
        )
        if at_start.q is None or at_start.qdot is None or at_start.v_max is None:
            continue
        joint_speeds = at_start.qdot * (cell.mu_path / at_start.v_max)[:, None]
        result = nlp.solve(cell.placement, cell.mu_path, at_start.q, joint_speeds)
        iterations += result.iterations
        candidates.append(result.placement)
        statuses.append(result.status)
    return candidates, statuses, iterations


def _scipy(
    robot: Robot,
    prepared: PreparedPath,
    bounds: PlacementBounds,
    max_joint_step: float,
    symmetric: bool,
) -> tuple[list[tuple[float, float, float]], list[str], int]:
    """Candidates: the best placement of each basin DE saw, and SLSQP's polish of each."""
    basins, iterations = global_search(
        robot, prepared, bounds, max_joint_step=max_joint_step, symmetric=symmetric
    )
    if not basins:
        return [], [], iterations
    candidates, statuses = [basins[0][0]], ["best placement of differential evolution"]
    if prepared.pure_rotation.any() or basins[0][1] <= 0.0:
        return candidates, ["mu_path is 0 everywhere: the path turns on the spot"], iterations
    for placement, mu_path, branch in basins:
        polished, status, steps = polish(
            robot,
            prepared,
            bounds,
            placement,
            mu_path,
            BRANCHES[branch],
            max_joint_step=max_joint_step,
        )
        candidates.append(polished)
        statuses.append(f"SLSQP: {status}")
        iterations += steps
    return candidates, statuses, iterations
