"""A six-joint numeric map cell's IK: the candidate first, the others dropped once hopeless.

:mod:`solver.path.pruning` follows a seven-joint arm's branches in pieces, best bound first,
from Python; a six-joint arm's following is too cheap for that (the bounds cost more than they
save). Here the whole choice runs compiled, one placement after the other
(:meth:`solver.core.family.FollowsInSteps.follow_bounded`): the slot the previous placement
ended with is followed first to the end (the candidate), then each other slot in order, with
V_max at every waypoint; a slot is dropped once its least V_max so far shows that it can
neither tie with the candidate nor beat it. That is the argument of the analytic map kernels'
pruning (:mod:`solver.kernels.fixed_spin`): mu_path is the least V_max along the branch, and
:func:`solver.path.tracking.choose_branch` takes the highest, the first in order of a tie.

The kernel only guesses the candidate's feasibility (tracking's joint limits and steps are
judged here), and its V_max round otherwise than the pipeline's. So every placement is
checked afterwards (:func:`choice_holds`) with the pipeline's mu_path of the slots followed to
the end: where a dropped slot could change the choice, the placement's dropped slots are
followed to the end after all. A dropped slot comes back unreachable from its first waypoint,
as in :mod:`solver.path.pruning`, so no reported field of the cell changes (tested cell by
cell against following every slot).
"""

from __future__ import annotations

import numpy as np

from solver.core.codes import TIE_RTOL, UNREACHABLE
from solver.core.family import PathSolutions
from solver.path.problem import PathProblem
from solver.path.pruning import Chunk

MARGIN = 1e-13
"""Relative slack on a dropped slot's bound: the kernel's V_max come from the unwrapped
solutions, the pipeline's from the tracked ones (2 pi apart), equal to rounding (about 1e-15
on the UR5 and OPW arms); it must stay well under TIE_RTOL, or slots that tie to rounding (a
UR's shoulder branches) could never be dropped."""


def bounded_solutions(
    problem: PathProblem,
    rotation: np.ndarray,
    flange_position: np.ndarray,
    twist: np.ndarray,
    tool_position: np.ndarray,
) -> PathSolutions:
    """The family's solutions along a chunk's paths, slots that cannot be the pick dropped.

    Args and returns as :func:`solver.path.pruning.pruned_solutions`.
    """
    chunk = Chunk(problem, rotation, flange_position, twist, tool_position)
    family = chunk.family
    n_waypoints = chunk.positions.shape[1]
    current, count = family.seed_first(chunk.rotations[:, 0], chunk.positions[:, 0])
    n_seeds = current.shape[1]
    current = np.ascontiguousarray(current[:, : max(int(count.max()), 1)])
    speeds = (
        np.moveaxis(chunk.twist, 0, -1),
        np.moveaxis(chunk.tool, 0, -1),
        problem.robot.qdot_max,
        problem.prepared.pure_rotation,
    )
    q, status, bound, dropped = family.follow_bounded(
        current, (chunk.rotations, chunk.positions), speeds, (TIE_RTOL, MARGIN)
    )
    complete = ~dropped & np.isfinite(current[..., 0]).T
    slots, cells = np.nonzero(complete)
    mu = np.full(bound.shape, -np.inf)
    mu[slots, cells] = chunk.mu_path(q[:, slots, cells], status[slots, cells], cells)
    redo = dropped & ~choice_holds(mu, bound, dropped)
    if redo.any():  # followed to the end after all, from the first waypoint
        start = np.zeros(redo.shape, dtype=np.int64)
        stop = np.where(redo, n_waypoints, 0)
        family.follow_ranges(
            current.copy(), chunk.rotations, chunk.positions, start, stop, (q, status)
        )
        dropped &= ~redo
    kept = ~dropped & (status[..., 0] != UNREACHABLE)
    order = np.argsort(~kept, axis=0, kind="stable")[: max(int(kept.sum(axis=0).max()), 1)]
    every = np.arange(len(count))
    q, status = q[:, order, every], status[order, every]
    gone = dropped[order, every]
    q[:, gone] = np.nan
    status[gone] = UNREACHABLE
    return PathSolutions(q=q, status=status, seeds=n_seeds, branches_found=count, slots=order)


def choice_holds(mu: np.ndarray, bound: np.ndarray, dropped: np.ndarray) -> np.ndarray:
    """Whether each placement's pick stands whatever its dropped slots' mu_path (K, C) -> (C,).

    The pick is :func:`solver.path.tracking.choose_branch`'s among the slots followed to the
    end (``mu``: their mu_path, -inf where infeasible or dropped). A dropped slot's mu_path is
    at most its ``bound`` (1 + MARGIN), or it is infeasible: one after the pick cannot change it
    while that bound less its tie tolerance is at most the pick's mu_path (it could raise the
    highest only so far that the pick still ties with it); one before it while the bound is
    below the highest less the tie tolerance (it cannot tie). A placement without a feasible
    slot followed holds only if nothing was dropped (its answer is the furthest failure).
    """
    feasible = mu > -np.inf
    top = mu.max(axis=0)
    tied = feasible & (mu >= top - TIE_RTOL * np.abs(top))
    pick = tied.argmax(axis=0)
    chosen = np.take_along_axis(mu, pick[None], axis=0)[0]
    high = bound * (1.0 + MARGIN)
    with np.errstate(invalid="ignore"):
        after = high - TIE_RTOL * np.abs(high) <= chosen
        before = high < top - TIE_RTOL * np.abs(top)
    later = np.arange(len(mu))[:, None] > pick
    harmless = ~dropped | np.where(later, after, before)
    holds: np.ndarray = ~dropped.any(axis=0) | (feasible.any(axis=0) & harmless.all(axis=0))
    return holds
