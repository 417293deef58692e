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

from solver.coarse_search import MAX_COARSE_CELLS, Cell, coarse_cells
from solver.evaluate import DEFAULT_MAX_JOINT_STEP, PathEvaluation, evaluate_path
from solver.exceptions import InvalidInputError
from solver.pipeline import PreparedPath, SpinMode, prepare_path, require_family
from solver.placement_nlp import PlacementNlp
from solver.placement_scipy import global_search, polish
from solver.robots import Robot
from solver.spatial import MAX_COORDINATE, Placement
from solver.symmetry import PlacementBounds, arc_coordinates, arc_point, turns_about_base_z

Method = Literal["casadi", "scipy"]
N_STARTS = 4  # IPOPT solves, from the best local maxima of the coarse map


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


def check_bounds(bounds: PlacementBounds) -> None:
    """Raise InvalidInputError naming the range that is not finite, reversed or too far."""
    for name, (low, high) in (("x", bounds.x), ("y", bounds.y), ("yaw", bounds.yaw)):
        if not (math.isfinite(low) and math.isfinite(high) and low <= high):
            raise InvalidInputError(f"bounds.{name}", f"needs finite [min, max], got {[low, high]}")
        if name != "yaw" and max(abs(low), abs(high)) > MAX_COORDINATE:
            raise InvalidInputError(f"bounds.{name}", f"beyond +-{MAX_COORDINATE} m")
    if not math.isfinite(bounds.z) or abs(bounds.z) > MAX_COORDINATE:
        raise InvalidInputError("z", f"{bounds.z!r} m is not a finite height within the cell")


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
    spin_mode: SpinMode = "fixed",
    max_coarse_cells: int = MAX_COARSE_CELLS,
) -> PlacementOptimum | None:
    """The placement inside ``bounds`` where the path runs fastest.

    Args:
        robot: an arm with a kinematics family, with its speed limits and TCP.
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i (metres).
        bounds: x, y, yaw ranges and the height z.
        start: the start placement (default: the centre of the bounds), reported with its
            mu_path and used to choose the point of the optimal arc.
        method: ``"casadi"`` (IPOPT from the coarse map's maxima) or ``"scipy"``.
        max_joint_step: rad, as for :func:`solver.evaluate.evaluate_path`.
        spin_mode: ``fixed`` or ``free`` (the tool spin rate free, cam.md section 2), as for
            :func:`solver.evaluate.evaluate_path`; every method searches in that mode.
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
    start_evaluation = evaluate_path(
        robot, path, start, max_joint_step=max_joint_step, spin_mode=spin_mode
    )
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
            spin_mode=spin_mode,
            max_cells=max_coarse_cells,
        )
        candidates, statuses, iterations = _casadi(
            robot, path, prepared, bounds, cells, max_joint_step, spin_mode
        )
        name = "ipopt (casadi), from the coarse map's maxima"
    else:
        candidates, statuses, iterations = _scipy(
            robot, prepared, bounds, max_joint_step, symmetric, spin_mode
        )
        name = "differential_evolution + SLSQP (scipy)"
    # The start last: it is the answer only when nothing the solver found is better.
    candidates = [*candidates, (start.x, start.y, start.yaw)]
    statuses = [*statuses, "no better placement found than the start"]
    best: tuple[float, Placement, PathEvaluation, str] | None = None
    for candidate, status in zip(candidates, statuses, strict=True):
        placement = _place_on_arc(candidate, bounds, near, symmetric)
        evaluation = evaluate_path(
            robot, path, placement, max_joint_step=max_joint_step, spin_mode=spin_mode
        )
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
    spin_mode: SpinMode,
) -> tuple[list[tuple[float, float, float]], list[str], int]:
    """Candidates: the best coarse cell, then IPOPT's optimum from each of the best cells.

    In free spin mode each solve starts from the cell's joint path at the given spin with the
    spin rate 0 (a feasible start at the fixed-spin mu_path), and IPOPT frees the rate.
    """
    if not cells:
        return [], [], 0
    candidates, statuses = [cells[0].placement], ["best cell of the coarse map"]
    if prepared.pure_rotation.any() or cells[0].mu_path <= 0.0:
        return candidates, ["mu_path is 0 everywhere: the path turns on the spot"], 0
    nlp = PlacementNlp(
        robot,
        prepared,
        path[:, :3, :3],
        bounds,
        max_joint_step=max_joint_step,
        free_spin=spin_mode == "free",
    )
    iterations = 0
    for cell in cells[:N_STARTS]:
        x, y, yaw = cell.placement
        at_start = evaluate_path(
            robot,
            path,
            Placement(x, y, bounds.z, yaw),
            branch=require_family(robot).branches[cell.branch],
            max_joint_step=max_joint_step,
        )
        q, qdot, v_max, speed = at_start.q, at_start.qdot, at_start.v_max, at_start.mu_path
        if q is None or qdot is None or v_max is None or speed is None:
            continue
        joint_speeds = qdot * (speed / v_max)[:, None]
        result = nlp.solve(cell.placement, speed, q, joint_speeds)
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
    spin_mode: SpinMode,
) -> tuple[list[tuple[float, float, float]], list[str], int]:
    """Candidates: the best placement of each basin DE saw, and SLSQP's polish of each."""
    basins, iterations = global_search(
        robot,
        prepared,
        bounds,
        max_joint_step=max_joint_step,
        symmetric=symmetric,
        spin_mode=spin_mode,
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
            require_family(robot).branches[branch],
            max_joint_step=max_joint_step,
            spin_mode=spin_mode,
        )
        candidates.append(polished)
        statuses.append(f"SLSQP: {status}")
        iterations += steps
    return candidates, statuses, iterations
