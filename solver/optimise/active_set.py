"""The active-set loop: solve on the waypoints that can bind, check the whole path, add, repeat.

Only a few waypoints bind a path's optimum, but IPOPT's problem (and SLSQP's constraints)
grow with every waypoint: a 1,000-waypoint NLP took 22 s (issue 23). So a local solve starts on
the waypoints that bind at its start (the FIRST_ROWS lowest speed bounds of the whole path
there, with their neighbours and, with acceleration limits, their blend stencils), solved as a
problem of their own (:func:`solver.path.subset.on_waypoints`, a relaxation: its rows are the
whole path's at those waypoints); then the whole path is evaluated at the answer on the same
branch, and the waypoints whose bound is below the subset's (with those within NEAR_RTOL
above it), or where the whole path fails (every failing step and unsolved pose at once), are
added, until the answer's bottleneck is in the set (a cutting-plane loop). The optimum of the
set is then the whole path's: every row left out holds there.

On the NX-like pocket program of ``bench/active_set.py`` (10,487 moves) a start's first set is
about 90 waypoints and its final one 150 to 220, after two solves.

Whatever the loop returns is still only a candidate: the front door judges it by the whole
path's evaluation (:func:`solver.optimise.optimize.optimize_placement`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from solver.core.family import Branch
from solver.optimise.search_space import PlacementBounds
from solver.path.limits import JointAccelerationLimit
from solver.path.pipeline import run_chunk
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem
from solver.path.subset import on_waypoints

FIRST_ROWS = 32  # the lowest speed bounds at the start that make the first set
ADDED_ROWS = 64  # the lowest bounds below the set's least that one round adds, at most
MAX_ROUNDS = 10  # solves from one start, at most (the last set is then returned as it is)
MAX_ACTIVE_ROWS = 800  # the largest set solved (a solve on a larger one is not made)
NEAR_RTOL = 0.01
"""A round that adds rows also adds those within this (relative) above the set's least: the
waypoints nearly binding at one answer are the likeliest to bind at the next."""
ACTIVE_SET_RTOL = 1e-9
"""A waypoint outside the set binds when its bound is below the set's least by more than this
(relative): the NLP holds its rows to 1e-10, so the set's least is the optimum to about that."""

T = TypeVar("T")


@dataclass(frozen=True)
class ActiveSetResult(Generic[T]):
    """What the solve on the final set returned, the set, and how many solves it took.

    Attributes:
        solved: the last solve's own result.
        rows: the final set, whole-path waypoint indices (ascending).
        rounds: the solves made (1: the first set held).
    """

    solved: T
    rows: np.ndarray
    rounds: int


def closure(problem: PathProblem, rows: np.ndarray, *, neighbours: bool = True) -> np.ndarray:
    """The waypoints with their neighbours, and with the blend stencil of each (ascending).

    The neighbours bring the joint step rows around a binding waypoint; with acceleration
    limits, a waypoint's acceleration row needs its five stencil waypoints.
    """
    n = problem.prepared.n_waypoints
    kept = np.unique(np.concatenate([rows - 1, rows, rows + 1]) if neighbours else rows)
    kept = kept[(kept >= 0) & (kept < n)]
    for limit in problem.final_path_limits:
        if isinstance(limit, JointAccelerationLimit) and limit.stencil.waypoints.size:
            centre = np.isin(limit.stencil.waypoints, kept)
            kept = np.union1d(kept, limit.stencil.index[centre].ravel())
    return kept


def lowest(bounds_per_waypoint: np.ndarray, count: int) -> np.ndarray:
    """The ``count`` waypoints of the lowest finite bounds (NaN last; ties by index)."""
    order = np.argsort(np.nan_to_num(bounds_per_waypoint, nan=np.inf), kind="stable")
    return order[:count]


def whole_path_bounds(
    problem: PathProblem, bounds: PlacementBounds, vector: np.ndarray, branch: Branch
) -> tuple[np.ndarray, np.ndarray]:
    """The whole path's speed bound at every waypoint at ``vector`` on ``branch``.

    Returns:
        the bounds (N,), m/s (V_max, or with acceleration limits the least of V_max and
        V_acc), NaN everywhere where the branch fails; and where it fails, ascending (empty
        where it runs): its first failing waypoint, and every waypoint without a regular IK
        solution on the branch or whose step from the one before is over the bound (each of
        those fails the path, so a solve that sees one sees them all).
    """
    placement = bounds.rows(bounds.clamp(vector)[None])
    on_branch = problem.with_options(branch=branch)
    result = evaluate_placements(on_branch, placement, with_speeds=True)
    speeds = result.feed_bounds
    if speeds is None:  # not reached: asked for with_speeds
        raise RuntimeError("evaluate_placements returned no speeds")
    failed = int(result.failed_waypoint[0])
    if failed < 0:
        return speeds[0], np.zeros(0, dtype=np.int64)
    q = run_chunk(on_branch, placement).tracked.q[:, 0, 0]  # (n, N), NaN where no solution
    step = np.abs(np.diff(q, axis=-1))
    step = np.minimum(step, 2 * np.pi - step)  # a turn of 2 pi is no step
    with np.errstate(invalid="ignore"):
        jumps = np.flatnonzero(
            np.any(step > problem.options.max_joint_step, axis=0) & problem.prepared.segment_in_pass
        )
    unsolved = np.flatnonzero(np.isnan(q).any(axis=0))
    failing = np.unique(np.concatenate([[failed], jumps, jumps + 1, unsolved]))
    return speeds[0], failing.astype(np.int64)


def first_rows(problem: PathProblem, speeds: np.ndarray, failing: np.ndarray) -> np.ndarray:
    """The first set of a start: its FIRST_ROWS slowest waypoints, where it fails, and theirs.

    ``speeds`` and ``failing`` are the whole path's at the start (:func:`whole_path_bounds`).
    """
    return closure(problem, np.union1d(lowest(speeds, FIRST_ROWS), failing))


def binding_outside(
    problem: PathProblem, speeds: np.ndarray, failing: np.ndarray, rows: np.ndarray
) -> np.ndarray:
    """The waypoints outside ``rows`` that bind the whole path (none: the set holds).

    Where the whole path fails, its failing waypoints (:func:`whole_path_bounds`) and the one
    before and after each (the steps into and out of it), those outside, the first 3
    ADDED_ROWS along the path. Else, where some
    bound outside is below the set's least by more than ACTIVE_SET_RTOL, the ADDED_ROWS
    lowest of those below the least + NEAR_RTOL.
    """
    outside = np.ones(problem.prepared.n_waypoints, dtype=bool)
    outside[rows] = False
    if failing.size or np.isnan(speeds).all():
        around = np.unique(np.concatenate([failing - 1, failing, failing + 1]))
        around = around[(around >= 0) & (around < len(outside))]
        kept: np.ndarray = around[outside[around]][: 3 * ADDED_ROWS]  # the first along the path
        return kept
    least = float(np.nanmin(speeds[rows]))
    finite = np.nan_to_num(speeds, nan=np.inf)
    if not np.any(outside & (finite < least * (1.0 - ACTIVE_SET_RTOL))):
        return np.zeros(0, dtype=np.int64)
    candidates = np.flatnonzero(outside & (finite < least * (1.0 + NEAR_RTOL)))
    added: np.ndarray = candidates[lowest(speeds[candidates], ADDED_ROWS)]
    return added


def solve_on_active_set(
    problem: PathProblem,
    bounds: PlacementBounds,
    branch: Branch,
    rows: np.ndarray,
    solve: Callable[[PathProblem, np.ndarray], tuple[np.ndarray, T]],
) -> ActiveSetResult[T]:
    """The cutting-plane loop: ``solve`` on the set, the whole path checked, rows added.

    Args:
        problem: the whole problem.
        bounds: the placement box (the answers are checked clamped into it).
        branch: the IK branch the solves follow (the whole path is checked on it).
        rows: the first set, whole-path waypoint indices.
        solve: from the problem on the set and the set's indices, the answer's decision
            vector and the solve's own result.

    Returns:
        the last solve's result, on the first set where the answer's bottleneck is in the set,
        or on the last set after MAX_ROUNDS solves or before one over MAX_ACTIVE_ROWS
        waypoints (the front door judges it either way): at most MAX_ROUNDS solves of at
        most MAX_ACTIVE_ROWS waypoints (or the whole path, where it is no longer).
    """
    n = problem.prepared.n_waypoints
    for round_ in range(1, MAX_ROUNDS + 1):
        whole = len(rows) == n
        vector, solved = solve(problem if whole else on_waypoints(problem, rows), rows)
        if whole:
            break
        speeds, failing = whole_path_bounds(problem, bounds, vector, branch)
        added = binding_outside(problem, speeds, failing, rows)
        grown = closure(problem, np.union1d(rows, added), neighbours=False)
        if not added.size or round_ == MAX_ROUNDS or len(grown) > MAX_ACTIVE_ROWS:
            break
        rows = grown
    return ActiveSetResult(solved, rows, round_)
