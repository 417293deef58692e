"""The best placement of a path: maximise mu_path over (x, y, yaw) in a box (spec section 6).

Two methods, each checked by the evaluator:

- ``casadi``: a coarse map finds the local maxima (over (r, psi) where the first joint turns
  about the base z axis, over (x, y, yaw) otherwise); from the best few, each on its own IK
  branch, IPOPT solves the epigraph NLP of :mod:`solver.optimise.methods.placement_nlp`.
- ``scipy``: differential evolution over (x, y, yaw), every generation one batch through
  :mod:`solver.path.placements`, then SLSQP on the epigraph form with finite-difference gradients
  (:mod:`solver.optimise.methods.placement_scipy`).

Whatever a solver returns is only a candidate: the answer is the candidate (or the best coarse
cell, so never less than the map) with the highest mu_path by
:func:`solver.path.evaluate.evaluate_path`, and the reported placement and mu_path are the
evaluator's. Where the symmetry holds, every
candidate is first moved along its arc to the point nearest the start (inside the bounds), so
the reported (x, y, yaw) is deterministic.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import partial
from typing import Literal

import numpy as np

from solver.core.exceptions import InvalidInputError, quoted
from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress, span
from solver.core.robots import Robot
from solver.core.spatial import Placement, spun_waypoints
from solver.optimise.coarse_search import MAX_COARSE_CELLS, Cell, coarse_cells
from solver.optimise.local_search import climb, refine_cells
from solver.optimise.methods.placement_nlp import PlacementNlp
from solver.optimise.methods.placement_scipy import (
    SearchSize,
    global_search,
    polish,
    search_placements,
    search_size,
)
from solver.optimise.search_space import PlacementBounds, vector_of
from solver.optimise.symmetry import arc_coordinates, arc_point, turns_about_base_z
from solver.path.evaluate import DEFAULT_MAX_JOINT_STEP, PathEvaluation, evaluate_path
from solver.path.joint_path import EXACT_POSE_TOLERANCE, evaluate_joint_path
from solver.path.pipeline import PreparedPath, SpinMode, prepare_path, require_family

Method = Literal["casadi", "scipy"]
N_STARTS = 4  # IPOPT solves, from the coarse maxima that refine best
N_CLIMBS = (
    2  # Nelder-Mead climbs on mu_path (solver.optimise.local_search), from the best refined cells
)
CLIMB_STATUS = "Nelder-Mead on mu_path, from a refined cell"  # a climb's candidate status


@dataclass(frozen=True)
class Candidate:
    """What a solver proposes, for the evaluator to judge.

    Attributes:
        vector: the decision vector [x, y, yaw, spin, z] (m, m, rad, rad, m).
        status: what the solver said of it.
        spins: shape (N,), rad, each waypoint's spin on top of the placement's (spin path).
        joint_path: shape (N, n), rad, the NLP's own joint path for a redundant arm (dof > 6),
            judged as it is (:mod:`solver.path.joint_path`) beside the tracked one.
    """

    vector: np.ndarray
    status: str
    spins: np.ndarray | None = None
    joint_path: np.ndarray | None = None


@dataclass(frozen=True)
class SolverReport:
    """What the optimiser did: its name, the status of the winning solve, iterations, seconds."""

    name: str
    status: str
    iterations: int
    seconds: float


@dataclass(frozen=True)
class PlacementOptimum:
    """The best placement found, as the evaluator sees it (qpsolvers' ``Solution``).

    Attributes:
        found: whether any placement the search tried (the start included) is feasible; when
            not, placement, mu_path and evaluation are None.
        placement: the optimum (inside the bounds).
        mu_path: m/s, the evaluator's mu_path there.
        evaluation: the evaluator's whole answer there.
        start: the start placement; start_mu_path its mu_path (None when infeasible).
        improvement_percent: 100 (mu_path / start_mu_path - 1); None without a feasible start.
        solver: what the optimiser did.
        symmetric: whether the search used the (r, psi) symmetry.
        spins: shape (N,), rad, each waypoint's spin on top of the placement's, when the
            answer came from the spin-path NLP (cam.md section 4); else None.
        joint_path: shape (N, n), rad, for a redundant arm (dof > 6) the joint path mu_path is
            at (the NLP's own, or the tracked one where that is faster); None for dof <= 6.
    """

    found: bool
    placement: Placement | None
    mu_path: float | None
    evaluation: PathEvaluation | None
    start: Placement
    start_mu_path: float | None
    improvement_percent: float | None
    solver: SolverReport
    symmetric: bool
    spins: np.ndarray | None = None
    joint_path: np.ndarray | None = None


def _place_on_arc(
    vector: np.ndarray, bounds: PlacementBounds, near: float, symmetric: bool
) -> tuple[Placement, float]:
    """The candidate, clamped into the box, moved along its arc to the point nearest ``near``.

    Solvers may end a hair outside their bounds (IPOPT by its bound relaxation, 1e-8): the
    clamp is what makes every reported placement inside them; the evaluator then judges it.
    The spin and the height ride along: turning the placement about the base axis leaves them.

    Returns:
        the placement, and the turn (rad) about the base z axis that moved it along its arc
        (joint 1 of a joint path moves by as much).
    """
    clamped = bounds.clamp(vector)
    x, y, yaw, spin, z = clamped
    if symmetric:
        moved = arc_point(*arc_coordinates(x, y, yaw), bounds, near=near)
        if moved is not None:
            x, y, yaw = moved
    turn = math.atan2(y, x) - math.atan2(clamped[1], clamped[0]) if symmetric else 0.0
    placement = Placement(float(x), float(y), float(z), float(yaw), spin=float(spin))
    return placement, (turn + math.pi) % (2 * math.pi) - math.pi


def _turned_joint_path(robot: Robot, joint_path: np.ndarray, turn: float) -> np.ndarray:
    """The joint path with joint 1 turned by ``turn`` (the copy 2 pi k that fits its limits).

    Where joint 1 turns about the base z axis (the symmetry), turning the placement by ``turn``
    about that axis is reached by the same joint path with q1 + turn.
    """
    turned = np.array(joint_path, dtype=float)
    if turn == 0.0:
        return turned
    first = turned[:, 0] + turn
    for copy in (0.0, -2 * math.pi, 2 * math.pi):
        if robot.q_lower[0] <= (first + copy).min() and (first + copy).max() <= robot.q_upper[0]:
            first = first + copy
            break
    turned[:, 0] = first
    return turned


def optimize_placement(
    robot: Robot,
    waypoints_in_workpiece: np.ndarray,
    *,
    bounds: PlacementBounds,
    start: Placement | None = None,
    method: Method = "casadi",
    max_joint_step: float = DEFAULT_MAX_JOINT_STEP,
    spin_mode: SpinMode = "fixed",
    max_spin_step: float | None = None,
    max_coarse_cells: int = MAX_COARSE_CELLS,
    max_coarse_poses: int | None = None,
    max_search_poses: int | None = None,
    max_solver_seconds: float | None = None,
    progress: Progress | None = None,
    passes: Sequence[tuple[int, int]] | None = None,
    runner: TaskRunner = SERIAL,
) -> PlacementOptimum:
    """The placement inside ``bounds`` where the path runs fastest.

    Args:
        robot: an arm with a kinematics family, with its speed limits and TCP.
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i (metres).
        bounds: x, y, yaw and spin ranges and the height z (the decision vector).
        start: the start placement (default: the centre of the bounds), reported with its
            mu_path and used to choose the point of the optimal arc.
        method: ``"casadi"`` (IPOPT from the coarse map's maxima) or ``"scipy"``.
        max_joint_step: rad, as for :func:`solver.path.evaluate.evaluate_path`.
        spin_mode: ``fixed`` or ``free`` (the tool spin rate free, cam.md section 2), as for
            :func:`solver.path.evaluate.evaluate_path`; every method searches in that mode.
        max_spin_step: rad, > 0: the casadi method also gives each waypoint its own spin, with
            steps at most this (cam.md section 4, ``spin_path``); None keeps one spin.
        max_coarse_cells: the largest coarse map the casadi method may make.
        max_coarse_poses: the most placement-waypoint pairs of that map (None: no limit), each
            weighed by the family's cost (:meth:`KinematicsFamily.path_cost`).
        max_search_poses: the same for the placements the scipy method's differential
            evolution evaluates (None: no limit).
        max_solver_seconds: the longest one IPOPT solve may take (None: IPOPT's default).
        progress: called with the fraction done (coarse map or DE, then each solve's
            iterations); a :class:`solver.core.progress.Cancelled` it raises stops the search.
        passes: index ranges [start, stop) of the passes of a CAM program (cam.md section 5);
            None: one pass. A spin path (``max_spin_step``) needs one pass.
        runner: where the coarse map's and differential evolution's placements run
            (:mod:`solver.core.parallel`); the same optimum on any.

    Returns:
        The optimum (never below the start); ``found`` is False when neither the start nor any
        placement the search tried is feasible.

    Raises:
        InvalidInputError: bad bounds, a start outside them, an unknown method, or a box whose
            coarse map is over ``max_coarse_cells`` or ``max_coarse_poses``, or whose search
            is over ``max_search_poses`` (on ``bounds``).
    """
    began = time.perf_counter()
    bounds.check()
    if method not in ("casadi", "scipy"):
        raise InvalidInputError(
            "method", f"unknown method {quoted(str(method))}; use casadi or scipy"
        )
    if max_spin_step is not None:
        if method != "casadi" or spin_mode != "fixed":
            raise InvalidInputError(
                "spin_path", "a spin path needs method casadi and spin_mode fixed"
            )
        if not (math.isfinite(max_spin_step) and max_spin_step > 0.0):
            raise InvalidInputError(
                "spin_path.max_spin_step", f"{max_spin_step:.6g} rad must be finite and > 0"
            )
    if start is None:
        start = bounds.placement(bounds.centre())
    if not bounds.contains(vector_of(start)):
        raise InvalidInputError(
            "start",
            f"x {start.x:g} m, y {start.y:g} m, z {start.z:g} m, yaw {start.yaw:g} rad, spin "
            f"{start.spin:g} rad is outside the bounds",
        )
    path = np.asarray(waypoints_in_workpiece, dtype=float)
    if method == "scipy":
        cost = require_family(robot).path_cost(len(path))
        size = search_size(bounds, path_cost=cost, n_waypoints=len(path))
        if max_search_poses is not None:
            _check_search_size(robot, bounds, size, len(path), max_search_poses)
    prepared = prepare_path(robot, path, passes=passes)
    if max_spin_step is not None and not prepared.segment_in_pass.all():
        raise InvalidInputError("spin_path", "a spin path needs a program of one pass")
    start_evaluation = evaluate_path(
        robot, path, start, max_joint_step=max_joint_step, spin_mode=spin_mode, passes=passes
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
            max_poses=max_coarse_poses,
            progress=span(progress, 0.0, 0.25),
            runner=runner,
        )
        cells = refine_cells(
            robot,
            prepared,
            bounds,
            cells,
            max_joint_step=max_joint_step,
            spin_mode=spin_mode,
            progress=span(progress, 0.25, 0.3),
            runner=runner,
        )
        candidates, iterations = _casadi(
            robot,
            path,
            prepared,
            bounds,
            cells,
            max_joint_step,
            spin_mode,
            max_spin_step,
            max_solver_seconds,
            span(progress, 0.3, 0.95),
            passes,
            runner,
        )
        name = "ipopt (casadi), from the coarse map's maxima"
    else:
        candidates, iterations = _scipy(
            robot, prepared, bounds, max_joint_step, symmetric, spin_mode, size, progress, runner
        )
        name = "differential_evolution + SLSQP (scipy)"
    # The start last: it is the answer only when nothing the solver found is better.
    candidates = [
        *candidates,
        Candidate(vector_of(start), "no better placement found than the start"),
    ]
    best: tuple[float, Placement, PathEvaluation, Candidate] | None = None
    for candidate in candidates:
        placement, turn = _place_on_arc(candidate.vector, bounds, near, symmetric)
        waypoints = path if candidate.spins is None else spun_waypoints(path, candidate.spins)
        judged = []
        if candidate.joint_path is not None:
            try:
                judged.append(
                    evaluate_joint_path(
                        robot,
                        waypoints,
                        placement,
                        _turned_joint_path(robot, candidate.joint_path, turn),
                        max_joint_step=max_joint_step,
                        passes=passes,
                        tolerance=EXACT_POSE_TOLERANCE,
                    )
                )
            except InvalidInputError:  # off its poses, limits or steps: only tracking counts
                pass
        judged.append(
            evaluate_path(
                robot,
                waypoints,
                placement,
                max_joint_step=max_joint_step,
                spin_mode=spin_mode,
                passes=passes,
            )
        )
        for evaluation in judged:
            if evaluation.mu_path is not None and (best is None or evaluation.mu_path > best[0]):
                best = (evaluation.mu_path, placement, evaluation, candidate)
    report = SolverReport(name, "", iterations, time.perf_counter() - began)
    if best is None:
        return PlacementOptimum(
            found=False,
            placement=None,
            mu_path=None,
            evaluation=None,
            start=start,
            start_mu_path=None,
            improvement_percent=None,
            solver=dataclasses.replace(report, status="no feasible placement inside the bounds"),
            symmetric=symmetric,
        )
    mu_path, placement, evaluation, chosen = best
    status = chosen.status
    if chosen.joint_path is not None and evaluation.branch is not None:
        status += " (at the placement its tracked joint path is faster than its own)"
    start_mu = start_evaluation.mu_path
    return PlacementOptimum(
        found=True,
        placement=placement,
        mu_path=mu_path,
        evaluation=evaluation,
        start=start,
        start_mu_path=start_mu,
        improvement_percent=None if not start_mu else 100.0 * (mu_path / start_mu - 1.0),
        solver=dataclasses.replace(report, status=status),
        symmetric=symmetric,
        spins=chosen.spins,
        joint_path=evaluation.q if robot.dof > 6 else None,
    )


def _check_search_size(
    robot: Robot, bounds: PlacementBounds, size: SearchSize, n_waypoints: int, max_poses: int
) -> None:
    """Refuse a differential evolution whose weighed work is over ``max_poses``.

    Raises:
        InvalidInputError: on ``bounds``, saying the size asked for and the limit.
    """
    family = require_family(robot)
    placements = search_placements(bounds, size)
    work = placements * family.path_cost(n_waypoints)
    if work > max_poses:
        raise InvalidInputError(
            "bounds",
            f"the scipy search of {int(bounds.free.sum())} free variables evaluates "
            f"{placements} placements * {n_waypoints} waypoints = {placements * n_waypoints} "
            f"poses, as work {work:.4g} closed-form poses ({family.name} IK); the limit is "
            f"{max_poses}; fix a variable, shorten the path, or use method casadi",
        )


def _casadi(
    robot: Robot,
    path: np.ndarray,
    prepared: PreparedPath,
    bounds: PlacementBounds,
    cells: list[Cell],
    max_joint_step: float,
    spin_mode: SpinMode,
    max_spin_step: float | None,
    max_solver_seconds: float | None,
    progress: Progress | None,
    passes: Sequence[tuple[int, int]] | None,
    runner: TaskRunner,
) -> tuple[list[Candidate], int]:
    """Candidates: the best refined cell, IPOPT's optima, Nelder-Mead climbs.

    IPOPT starts from the coarse cells whose basins refine best
    (:func:`solver.optimise.local_search.refine_cells`); the climbs on mu_path start from the best
    refined cells and may cross to another branch, where IPOPT cannot. They need nothing from
    IPOPT, so where the runner lets the caller use a second thread they run beside the solves
    (the map kernel releases the GIL); either way the candidates come in the same order.

    For a redundant arm (dof > 6) each optimum carries the NLP's joint path: IPOPT chose the
    redundancy too, and the evaluator's tracked joint path would lose that.

    In free spin mode each solve starts from the cell's joint path at the given spin with the
    spin rate 0 (a feasible start at the fixed-spin mu_path), and IPOPT frees the rate.
    """
    if not cells:
        return [], 0
    if prepared.pure_rotation.any() or cells[0].mu_path <= 0.0:
        zero = "mu_path is 0 everywhere: the path turns on the spot"
        return [Candidate(cells[0].vector, zero)], 0
    candidates = [Candidate(cells[0].vector, "best cell of the coarse map, refined")]
    nlp = PlacementNlp(
        robot,
        prepared,
        path[:, :3, :3],
        bounds,
        max_joint_step=max_joint_step,
        free_spin=spin_mode == "free",
        max_spin_step=max_spin_step,
        ipopt_options=None if max_solver_seconds is None else {"max_cpu_time": max_solver_seconds},
    )
    iterations = 0
    climbs: Callable[[], list[Candidate]] = partial(
        _climbs, robot, prepared, bounds, cells, max_joint_step, spin_mode
    )
    with ThreadPoolExecutor(1, thread_name_prefix="dtf-climbs") as beside:
        if runner.threads > 1:  # the climbs need nothing from IPOPT: beside its solves
            climbs = beside.submit(climbs).result
        # IPOPT starts from the coarse cells whose basins climbed highest. (The other refined
        # cells are below cells[0] and below the climbs: no candidates.)
        starts = [cell.coarse or cell for cell in cells[:N_STARTS]]
        for k, cell in enumerate(starts):
            solved = _solve_from(
                robot, path, nlp, bounds, cell, max_joint_step, passes,
                span(progress, k / len(starts), (k + 1) / len(starts)),
            )  # fmt: skip
            if solved is not None:
                candidates.append(solved[0])
                iterations += solved[1]
        candidates += climbs()
    return candidates, iterations


def _solve_from(
    robot: Robot,
    path: np.ndarray,
    nlp: PlacementNlp,
    bounds: PlacementBounds,
    cell: Cell,
    max_joint_step: float,
    passes: Sequence[tuple[int, int]] | None,
    progress: Progress | None,
) -> tuple[Candidate, int] | None:
    """IPOPT's optimum from the cell's joint path, with its iterations; None where none starts.

    A start IPOPT refuses is a candidate at the cell, with IPOPT's message and no iterations.
    """
    at_start = evaluate_path(
        robot,
        path,
        bounds.placement(cell.vector),
        branch=require_family(robot).branches[cell.branch],
        max_joint_step=max_joint_step,
        passes=passes,
    )
    q, qdot, v_max, speed = at_start.q, at_start.qdot, at_start.v_max, at_start.mu_path
    if q is None or qdot is None or v_max is None or speed is None:
        return None
    joint_speeds = qdot * (speed / v_max)[:, None]
    try:
        result = nlp.solve(cell.vector, speed, q, joint_speeds, progress=progress)
    except RuntimeError as error:  # IPOPT refused this start: the others still count
        failure = f"IPOPT failed from a start: {str(error).splitlines()[-1][:200]}"
        return Candidate(cell.vector, failure), 0
    candidate = Candidate(
        result.vector,
        result.status,
        spins=result.spins,
        joint_path=result.joint_path if robot.dof > 6 else None,
    )
    return candidate, result.iterations


def _climbs(
    robot: Robot,
    prepared: PreparedPath,
    bounds: PlacementBounds,
    cells: list[Cell],
    max_joint_step: float,
    spin_mode: SpinMode,
) -> list[Candidate]:
    """Nelder-Mead on mu_path from the best N_CLIMBS cells: across branches, to their tops."""
    candidates = []
    for cell in cells[:N_CLIMBS]:
        top = climb(
            robot, prepared, bounds, cell, max_joint_step=max_joint_step, spin_mode=spin_mode
        )
        if top is not None:
            candidates.append(Candidate(top.vector, CLIMB_STATUS))
    return candidates


def _scipy(
    robot: Robot,
    prepared: PreparedPath,
    bounds: PlacementBounds,
    max_joint_step: float,
    symmetric: bool,
    spin_mode: SpinMode,
    size: SearchSize,
    progress: Progress | None,
    runner: TaskRunner,
) -> tuple[list[Candidate], int]:
    """Candidates: DE's best placement, SLSQP's polishes, Nelder-Mead climbs on mu_path.

    Each basin DE saw is climbed first by the compass search, then polished by SLSQP on the
    branch it ends on.

    The search is ``size`` (smaller for a family whose placement costs more).
    """
    basins, iterations = global_search(
        robot,
        prepared,
        bounds,
        max_joint_step=max_joint_step,
        symmetric=symmetric,
        spin_mode=spin_mode,
        size=size,
        progress=span(progress, 0.0, 0.6),
        runner=runner,
    )
    if not basins:
        return [], iterations
    if prepared.pure_rotation.any() or basins[0][1] <= 0.0:
        zero = "mu_path is 0 everywhere: the path turns on the spot"
        return [Candidate(basins[0][0], zero)], iterations
    candidates = [Candidate(basins[0][0], "best placement of differential evolution")]
    # Each basin's best point climbed by the compass search (which may change the branch),
    # then polished on the branch it ends on.
    refined = refine_cells(
        robot,
        prepared,
        bounds,
        [Cell(vector, mu, branch) for vector, mu, branch in basins],
        max_joint_step=max_joint_step,
        spin_mode=spin_mode,
        runner=runner,
    )
    if refined:
        basins = [(cell.vector, cell.mu_path, cell.branch) for cell in refined]
    for k, (placement, mu_path, branch) in enumerate(basins):
        polished, status, steps = polish(
            robot,
            prepared,
            bounds,
            placement,
            mu_path,
            require_family(robot).branches[branch],
            max_joint_step=max_joint_step,
            spin_mode=spin_mode,
            size=size,
            progress=span(
                progress, 0.6 + 0.35 * k / len(basins), 0.6 + 0.35 * (k + 1) / len(basins)
            ),
        )
        candidates.append(Candidate(polished, f"SLSQP: {status}"))
        iterations += steps
    candidates += _climbs(robot, prepared, bounds, refined, max_joint_step, spin_mode)
    return candidates, iterations
