"""The ``casadi`` method: IPOPT from the coarse map's maxima, beside Nelder-Mead climbs.

A coarse map finds the local maxima (over (r, psi) where the first joint turns about the base
z axis, over (x, y, yaw) otherwise; :mod:`solver.optimise.coarse_search`); the compass search
ranks their basins (:func:`solver.optimise.local_search.refine_cells`); from the best few, each
on its own IK branch, IPOPT solves the epigraph NLP of
:mod:`solver.optimise.methods.placement_nlp`, and Nelder-Mead climbs mu_path itself from the
best refined cells (which may cross to another branch, where IPOPT cannot). With a cell, an
optimum that is not clear of it is also backed off towards its start
(:mod:`solver.optimise.back_off`).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from functools import partial

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.progress import Progress, span
from solver.optimise.active_set import (
    MAX_ROUNDS,
    first_rows,
    solve_on_active_set,
    whole_path_bounds,
)
from solver.optimise.back_off import back_off
from solver.optimise.candidate import ZERO_SPEED, Candidate, Search
from solver.optimise.coarse_search import Cell, search_cells
from solver.optimise.local_search import climbs, refine_cells
from solver.optimise.methods.placement_nlp import NlpResult, PlacementNlp
from solver.optimise.search_space import PlacementBounds
from solver.path.evaluate import evaluate_path
from solver.path.limits import JointAccelerationLimit, JointSpeedLimit
from solver.path.problem import PathProblem

DESCRIPTION = "ipopt (casadi), from the coarse map's maxima"
N_STARTS = 4  # IPOPT solves, from the coarse maxima that refine best
NLP_LIMITS = (JointSpeedLimit, JointAccelerationLimit)
"""The limits the NLP has rows for (:mod:`solver.optimise.methods.placement_nlp`)."""


def check(problem: PathProblem, bounds: PlacementBounds, settings: Search) -> None:
    """Refuse a problem with a limit the NLP has no rows for, before any work.

    IPOPT would climb to the optimum of the other limits alone, which the evaluator then
    judges: an answer below what the search could find, silently (the seams audit: the NLP
    builds its rows from the robot's speed and acceleration limits by name). The scipy method
    evaluates every limit.

    Raises:
        InvalidInputError: on ``method``, naming the limit.
    """
    for limit in problem.limits:
        if type(limit) not in NLP_LIMITS:
            raise InvalidInputError(
                "method",
                f"the casadi method's NLP has rows for the joint speed and acceleration limits "
                f"only, not for the {limit.name!r} limit: use method scipy",
            )


def search(
    problem: PathProblem, bounds: PlacementBounds, settings: Search
) -> tuple[list[Candidate], int]:
    """Candidates: the best refined cell, IPOPT's optima, Nelder-Mead climbs; IPOPT's iterations.

    IPOPT starts from the coarse cells whose basins refine best; the climbs on mu_path start
    from the best refined cells. They need nothing from IPOPT, so where the runner lets the
    caller use a second thread they run beside the solves (the map kernel releases the GIL);
    either way the candidates come in the same order.

    For a redundant arm (dof > 6) each optimum carries the NLP's joint path: IPOPT chose the
    redundancy too, and the evaluator's tracked joint path would lose that.

    In free spin mode each solve starts from the cell's joint path at the given spin with the
    spin rate 0 (a feasible start at the fixed-spin mu_path), and IPOPT frees the rate.
    """
    progress, runner = settings.progress, settings.runner
    cells = search_cells(
        problem,
        bounds,
        settings,
        progress=span(progress, 0.0, 0.25),
        max_poses=settings.max_coarse_poses,
    )
    cells = refine_cells(problem, bounds, cells, progress=span(progress, 0.25, 0.3), runner=runner)
    if not cells:
        return [], 0
    if problem.prepared.pure_rotation.any() or cells[0].mu_path <= 0.0:
        return [Candidate(cells[0].vector, ZERO_SPEED)], 0
    candidates = [Candidate(cells[0].vector, "best cell of the coarse map, refined")]
    seconds = settings.max_solver_seconds
    options: dict[str, object] | None = None if seconds is None else {"max_wall_time": seconds}

    whole: list[PlacementNlp] = []  # the whole problem's NLP, built once for every start

    def nlp_of(posed: PathProblem) -> PlacementNlp:
        """The NLP of the problem (built once) or of one of its active sets."""
        if posed is problem and whole:
            return whole[0]
        nlp = PlacementNlp(
            posed, bounds, max_spin_step=settings.max_spin_step, ipopt_options=options
        )
        if posed is problem:
            whole.append(nlp)
        return nlp

    iterations = 0
    climbed: Callable[[], list[Candidate]] = partial(climbs, problem, bounds, cells)
    solves = span(progress, 0.3, 0.95)
    with ThreadPoolExecutor(1, thread_name_prefix="dtf-climbs") as beside:
        if runner.threads > 1:  # the climbs need nothing from IPOPT: beside its solves
            climbed = beside.submit(climbed).result
        # IPOPT starts from the coarse cells whose basins climbed highest. (The other refined
        # cells are below cells[0] and below the climbs: no candidates.)
        starts = [cell.coarse or cell for cell in cells[:N_STARTS]]
        for k, cell in enumerate(starts):
            part = span(solves, k / len(starts), (k + 1) / len(starts))
            solved = _solve_from(problem, nlp_of, bounds, cell, part, settings)
            if solved is not None:
                candidates.append(solved[0])
                iterations += solved[1]
                backed = back_off(problem, bounds, cell.vector, solved[0])
                if backed is not None:  # IPOPT, blind to the cell, climbed into it
                    candidates.append(backed)
        candidates += climbed()
    return candidates, iterations


def uses_active_set(problem: PathProblem, settings: Search) -> bool:
    """Whether the solves run on active sets (:mod:`solver.optimise.active_set`).

    Not with a spin path (each segment's twist couples neighbouring waypoints' spins) nor for a
    redundant arm (its answer carries the NLP's joint path along the whole path): those solve
    the whole path.
    """
    return settings.active_set and settings.max_spin_step is None and problem.robot.dof <= 6


def _solve_from(
    problem: PathProblem,
    nlp_of: Callable[[PathProblem], PlacementNlp],
    bounds: PlacementBounds,
    cell: Cell,
    progress: Progress | None,
    settings: Search,
) -> tuple[Candidate, int] | None:
    """IPOPT's optimum from the cell's joint path, with its iterations; None where none starts.

    The start is the cell's joint path on its branch in fixed spin (in free spin the NLP frees
    the rate from 0). A start IPOPT refuses is a candidate at the cell, with IPOPT's message and
    no iterations. Where :func:`uses_active_set`, IPOPT solves on the waypoints that bind, the
    whole path checked after each solve (:func:`solver.optimise.active_set.solve_on_active_set`);
    the candidate carries the final set.
    """
    branch = problem.family.branches[cell.branch]
    at_start = evaluate_path(
        problem.with_options(branch=branch, spin_mode="fixed"),
        bounds.placement(cell.vector),
        thorough=False,  # its joint path and speeds only
    )
    # With acceleration limits the NLP's rows hold at mu_acc, not at mu_path: start there.
    q, qdot, v_max, speed = at_start.q, at_start.qdot, at_start.v_max, at_start.feed_index
    if q is None or qdot is None or v_max is None or speed is None:
        return None
    joint_speeds = qdot * (speed / v_max)[:, None]
    if not uses_active_set(problem, settings):
        try:
            result = nlp_of(problem).solve(cell.vector, speed, q, joint_speeds, progress=progress)
        except RuntimeError as error:  # IPOPT refused this start: the others still count
            return _refused(cell, error), 0
        candidate = Candidate(
            result.vector,
            result.status,
            spins=result.spins,
            joint_path=result.joint_path if problem.robot.dof > 6 else None,
        )
        return candidate, result.iterations
    solves: list[NlpResult] = []

    def solve(subset: PathProblem, rows: np.ndarray) -> tuple[np.ndarray, NlpResult]:
        round_ = span(progress, len(solves) / MAX_ROUNDS, (len(solves) + 1) / MAX_ROUNDS)
        solved = nlp_of(subset).solve(
            cell.vector, speed, q[rows], joint_speeds[rows], progress=round_
        )
        solves.append(solved)
        return solved.vector, solved

    speeds, failing = whole_path_bounds(problem, bounds, cell.vector, branch)
    first = first_rows(problem, speeds, failing)
    try:
        looped = solve_on_active_set(problem, bounds, branch, first, solve)
    except RuntimeError as error:
        return _refused(cell, error), sum(s.iterations for s in solves)
    result = looped.solved
    candidate = Candidate(result.vector, result.status, spins=result.spins, rows=looped.rows)
    return candidate, sum(s.iterations for s in solves)


def _refused(cell: Cell, error: RuntimeError) -> Candidate:
    """The candidate of a start IPOPT refused: the cell, with IPOPT's message."""
    return Candidate(cell.vector, f"IPOPT failed from a start: {str(error).splitlines()[-1][:200]}")
