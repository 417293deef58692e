"""The path checks (:class:`solver.path.limits.PathCheck`, the cell) applied after the speed limits.

The speed limits choose, at each placement, the branch with the highest index; a path check
then runs on that branch's joint path only where it is feasible (a collision check costs far
more than the speed limits). Where it refuses the path and the branch is ``auto``, the next
feasible branch by index is checked, and so on; where every feasible branch is refused the
placement is infeasible with the check's reason, at the best branch's refused waypoint.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from solver.core.codes import FEASIBLE
from solver.path.limits import PathVerdict
from solver.path.pipeline import ChunkResult, run_chunk
from solver.path.problem import PathProblem

# The columns of one placement from a pipeline run whose ``pick`` is the branch to report.
Columns = Callable[[ChunkResult], tuple[np.ndarray, ...]]


def check_path(
    problem: PathProblem, q: np.ndarray, placement: np.ndarray, *, thorough: bool
) -> PathVerdict | None:
    """The first check that refuses ``q`` (W, n) at ``placement`` (5,); else the last verdict.

    None when the problem has no path checks.
    """
    verdict = None
    for check in problem.path_checks:
        verdict = check.check(q, placement, thorough=thorough)
        if verdict.failed_waypoint is not None:
            return verdict
    return verdict


def branch_order(run: ChunkResult, cell: int) -> list[int]:
    """The feasible branches of placement ``cell`` (indices on axis B), best index first.

    The pipeline's pick first (its tie rule), then the others by falling index.
    """
    index = run.mu_path if run.mu_acc is None else run.mu_acc
    feasible = np.flatnonzero(run.tracked.reason[:, cell] == FEASIBLE)
    pick = int(run.pick[cell])
    others = sorted((b for b in feasible if b != pick), key=lambda b: -index[b, cell])
    return ([pick] if pick in feasible else []) + [int(b) for b in others]


def clear_pick(
    problem: PathProblem, run: ChunkResult, placements: np.ndarray, cell: int, *, thorough: bool
) -> tuple[int | None, PathVerdict | None, PathVerdict | None]:
    """The branch placement ``cell`` takes with the path checks: the best that passes them.

    With a fixed branch only the pipeline's pick is checked.

    Returns:
        the branch (axis B) or None when every feasible branch is refused; the verdict of the
        branch taken; the verdict that refused the pipeline's pick (None if it passed).
    """
    order = branch_order(run, cell)
    first_refusal = None
    for b in order if problem.options.branch is None else order[:1]:
        q = run.tracked.q[:, b, cell].T
        verdict = check_path(problem, q, placements[cell], thorough=thorough)
        if verdict is None or verdict.failed_waypoint is None:
            return b, verdict, first_refusal
        first_refusal = first_refusal or verdict
    return None, None, first_refusal


def refuse_colliding(
    problem: PathProblem,
    placements: np.ndarray,
    columns: tuple[np.ndarray, ...],
    columns_of: Columns,
) -> tuple[np.ndarray, ...]:
    """The placements' columns with the path checks applied (cell.md section 3).

    Args:
        problem: the robot, the path, the options (with the cell).
        placements: shape (C, 5), one spin, as the columns were computed.
        columns: mu, reason, failed waypoint, branch (family index), ... as
            :func:`solver.path.placements._chunk` gives them.
        columns_of: the columns of a one-placement pipeline run at its ``pick``.
    """
    if not problem.path_checks:
        return columns
    out = [np.array(c, copy=True) for c in columns]
    reason, branch = out[1], out[3]
    family = problem.family
    feasible = np.flatnonzero(reason == FEASIBLE)
    for b in np.unique(branch[feasible]):
        cells = feasible[branch[feasible] == b]
        taken = problem.with_options(branch=family.branches[int(b)])
        single = run_chunk(taken, placements[cells])
        for k, c in enumerate(cells):
            q = single.tracked.q[:, 0, k].T
            verdict = check_path(problem, q, placements[c], thorough=False)
            if verdict is not None and verdict.failed_waypoint is not None:
                _next_branch(problem, placements[c : c + 1], out, int(c), verdict, columns_of)
    return tuple(out)


def _next_branch(
    problem: PathProblem,
    row: np.ndarray,
    out: list[np.ndarray],
    c: int,
    refusal: PathVerdict,
    columns_of: Columns,
) -> None:
    """Placement ``c``'s columns from its best branch that passes (auto), else refused."""
    if problem.options.branch is None:
        run = run_chunk(problem, row)
        chosen, _, _ = clear_pick(problem, run, row, 0, thorough=False)
        if chosen is not None:
            picked = columns_of(dataclasses.replace(run, pick=np.array([chosen])))
            for column, value in zip(out, picked, strict=True):
                column[c] = value[0]
            return
    _refuse(out, c, problem.path_checks[0].reason, int(refusal.failed_waypoint or 0))


def _refuse(columns: list[np.ndarray], c: int, reason: int, waypoint: int) -> None:
    """Mark placement ``c`` infeasible with ``reason`` at ``waypoint`` (its branch kept)."""
    columns[0][c] = np.nan  # mu_path
    columns[1][c] = reason
    columns[2][c] = waypoint
    columns[4][c] = columns[5][c] = -1  # bottleneck waypoint and joint
    columns[6][c] = np.nan  # V_max (if kept)
    columns[7][c] = np.nan  # mu_acc
    columns[8][c] = columns[9][c] = columns[10][c] = -1
    columns[11][c] = np.nan  # V_acc (if kept)
