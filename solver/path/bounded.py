"""A six-joint numeric map cell's IK: the candidate first, the others dropped once hopeless.

:mod:`solver.path.pruning` follows a seven-joint arm's branches in pieces, best bound first,
from Python; a six-joint arm's following is too cheap for that (the bounds cost more than they
save). Here the whole choice runs compiled, one placement after the other
(:meth:`solver.core.follows_in_steps.FollowsInSteps.follow_bounded`): the slot the previous
placement ended with is followed first to the end (the candidate), then each other slot in
order, with V_max at every waypoint; a slot is dropped once its least V_max so far shows that it can
neither tie with the candidate nor beat it. The other slots are scouted: followed with a few
rough steps a stride of waypoints, solved exactly (and their V_max taken) at the candidate's
slowest waypoint and wherever the rough V_max comes near dropping them; only exact V_max
bound a slot, and a slot that is not dropped (or whose stride is not trusted to stay on its
branch) is followed exactly from its first waypoint, so every row handed on is
``follow_paths``' to the bit. That is the argument of the analytic map kernels'
pruning (:mod:`solver.kernels.fixed_spin`): mu_path is the least V_max along the branch, and
:func:`solver.path.tracking.choose_branch` takes the highest, the first in order of a tie.

The kernel only guesses the candidate's feasibility (tracking's joint limits and steps are
judged by the pipeline), and its V_max round otherwise than the pipeline's. So the pipeline
checks every placement afterwards (:func:`pick_stands`) with its own mu_path of the slots
followed to the end: where a dropped slot could change a placement's choice, the chunk is run
again following every slot (none of 546 placements of the UR5's ERK map). A dropped slot
comes back unreachable from its first waypoint, as in :mod:`solver.path.pruning`, so no
reported field of the cell changes (tested cell by cell against following every slot).

Seven-joint (redundant) chains take the same seam with their own pass
(:mod:`solver.families.numeric.bounded_redundant_kernel`): no scouting (a redundant branch's
solutions depend on every waypoint before), the slots followed best bound first.
"""

from __future__ import annotations

import numpy as np

from solver.core.codes import TIE_RTOL, UNREACHABLE
from solver.core.family import PathSolutions
from solver.core.follows_in_steps import FollowsInSteps
from solver.path.chunk import Chunk
from solver.path.problem import PathProblem
from solver.path.pruning import can_prune

MARGIN = 1e-13
"""Relative slack on a dropped slot's bound: the kernel's V_max come from the unwrapped
solutions, the pipeline's from the tracked ones (2 pi apart), equal to rounding (about 1e-15
on the UR5 and OPW arms); it must stay well under TIE_RTOL, or slots that tie to rounding (a
UR's shoulder branches) could never be dropped."""

ROUGH = 3
"""Damped least-squares steps a stride when a slot other than the candidate is scouted
(without a convergence test). From one waypoint to the next (UR5 on the ERK path), one step
leaves |e|_inf about 1e-4, two about 1e-9 (90th percentile); over a stride of 8 two leave
about 1e-5, so three (kept with the stride of 12 below, measured with it)."""
STRIDE = 12
"""Waypoints a scouted slot goes at a time (stopping at the candidate's slowest waypoint).
The UR5-as-URDF ERK map's compiled following took 0.56 times as long as following every slot
other than the candidate exactly (with drops), with the lead alone 0.35 (the same slots
dropped; loaded machine, best of 5, same run); strides of 4 and 12 about the same as 8 then.
Measured again on an idle machine (2026-12-07, six alternations, best of 3 each): the whole map
294-310 ms with 12 against 303-362 with 8 (best 0.97x, median 0.95x), 4, 16 and 24 slower
(1.04-1.14x); the IRB 2400 as a URDF the same with either (333 and 334 ms). The same answers
with any stride (a slot handed on is followed exactly)."""
RESIDUAL = 1e-6
"""A stride whose rough steps leave |e|_inf (m, rad) above this is not trusted to have stayed
on the slot's branch: the slot is followed exactly instead."""
MOTION = 0.35
"""Nor one that moves a joint more than this (rad, m): the joint step tracking calls a jump
between two waypoints (``PathOptions.max_joint_step``'s default)."""
SLACK = 1e-5
"""Where a scouted slot's rough V_max is within this (relative) of dropping it, it is solved
exactly there and its exact V_max enters its bound (the rough ones only say where to look)."""


ONE_PASS_WAYPOINTS = 4 * 32 * 133
"""Placement-waypoints a six-joint numeric map runs through the pipeline at once: a thread's
task of the ERK path (four chunks of 32 placements, 133 waypoints; :func:`one_pass_chunk`)."""


def in_one_pass(problem: PathProblem) -> bool:
    """Whether the problem's family is pruned in this module's one compiled pass.

    Six and seven joints (:attr:`FollowsInSteps.follows_bounded`); other families that follow
    in steps are pruned in steps (:mod:`solver.path.pruning`).
    """
    family = problem.family
    return isinstance(family, FollowsInSteps) and family.follows_bounded


def one_pass_chunk(problem: PathProblem, chunk: int) -> int:
    """Placements a map's chunk takes: ``chunk``, more where this module follows them.

    The pass and the pipeline's Python work around it run once a chunk, so larger chunks
    share that work: the UR5-as-URDF ERK map (serial) took 0.976 times the CPU time in chunks
    of 128 placements against 32 (2026-12-02, load 2-4, best of 4, alternating in one
    process; 0.94 with chunks of 96 at load 6), the same answers
    (each placement's slots are followed, tracked and bounded alone; the candidate carried
    from one placement to the next only orders the work). Up to :data:`ONE_PASS_WAYPOINTS`
    placement-waypoints, at least ``chunk`` placements.
    """
    if not (in_one_pass(problem) and problem.robot.dof == 6 and can_prune(problem)):
        return chunk
    return max(chunk, ONE_PASS_WAYPOINTS // problem.prepared.n_waypoints)


def bounded_solutions(
    problem: PathProblem,
    rotation: np.ndarray,
    flange_position: np.ndarray,
    twist: np.ndarray,
    tool_position: np.ndarray,
    *,
    excluded: np.ndarray | None = None,
    first: tuple[np.ndarray, np.ndarray] | None = None,
) -> PathSolutions:
    """The family's solutions along a chunk's paths, slots that cannot be the pick dropped.

    Args and returns as :func:`solver.path.pruning.pruned_solutions`; ``excluded``: shape
    (C, K), bool, slots left out at each placement (the path checks refused them: their
    following is not started, their rows come back unreachable, and the pick is the best of
    the others, :func:`solver.path.path_checks.refuse_colliding`); ``first``: the seeding of
    these paths' first waypoints from an earlier run of them (:attr:`PathSolutions.first`
    and ``branches_found``: the same arrays ``seed_first`` gives), else they are seeded.
    """
    chunk = Chunk(problem, rotation, flange_position, twist, tool_position)
    family = chunk.family
    if first is None:
        first = family.seed_first(chunk.rotations[:, 0], chunk.positions[:, 0])
    seeded, count = first
    n_seeds = seeded.shape[1]
    current = np.array(seeded[:, : max(int(count.max()), 1)], order="C")
    if excluded is not None:
        current[excluded[:, : current.shape[1]]] = np.nan  # a slot without a start: not followed
    speeds = (
        np.moveaxis(chunk.twist, 0, -1),
        np.moveaxis(chunk.tool, 0, -1),
        problem.robot.qdot_max,
        problem.prepared.pure_rotation,
        problem.options.max_joint_step,
    )
    q, status, bound, dropped = family.follow_bounded(
        current,
        (chunk.rotations, chunk.positions),
        speeds,
        (TIE_RTOL, MARGIN, ROUGH, SLACK, STRIDE, RESIDUAL, MOTION),
    )
    kept = ~dropped & (status[..., 0] != UNREACHABLE)
    order = np.argsort(~kept, axis=0, kind="stable")[: max(int(kept.sum(axis=0).max()), 1)]
    every = np.arange(len(count))
    q, status = q[:, order, every], status[order, every]
    gone = dropped[order, every]
    q[:, gone] = np.nan
    status[gone] = UNREACHABLE
    return PathSolutions(
        q=q,
        status=status,
        seeds=n_seeds,
        branches_found=count,
        slots=order,
        bound=bound,
        dropped=dropped,
        first=seeded,
    )


def pick_stands(solutions: PathSolutions, rows: np.ndarray, mu_path: np.ndarray) -> bool:
    """Whether every placement's pick stands whatever its dropped slots (:func:`choice_holds`).

    Args:
        solutions: :func:`bounded_solutions`' answer.
        rows: the rows of ``solutions.q`` the pipeline followed (a prefix).
        mu_path: shape (len(rows), C), the pipeline's mu_path of those rows, -inf infeasible.
    """
    assert solutions.slots is not None and solutions.bound is not None
    assert solutions.dropped is not None
    mu = np.full(solutions.bound.shape, -np.inf)
    cells = np.arange(solutions.bound.shape[1])
    mu[solutions.slots[rows], cells] = mu_path  # a dropped slot's row is unreachable: -inf
    return bool(choice_holds(mu, solutions.bound, solutions.dropped).all())


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
