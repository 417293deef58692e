"""A map cell's IK, following only the branches that can still be its best (robots.md section 4).

A map cell reports the branch that :func:`solver.path.tracking.choose_branch` takes: the
highest mu_path, the first in order among those within ``TIE_RTOL`` of it. mu_path is the least
V_max along the branch, so the least V_max over the waypoints followed so far bounds it from
above: once that bound is below the best complete, feasible branch's mu_path less its tie
tolerance, the branch can neither be the best nor tie with it, and following it further is
wasted. A numeric family's work is that following
(:class:`solver.core.follows_in_steps.FollowsInSteps`); the analytic acceleration kernel drops
branches by the same argument (:mod:`solver.kernels.accelerations`).

So, for a chunk of placements, best first: every branch is followed along the first
:data:`PIECE` waypoints; then, at each placement, the branch with the highest bound (with those
level with it, :data:`EVEN`) is followed a piece further, again and again, until branches reach
the last waypoint; a feasible one sets the placement's best (its mu_path, tracked as the
pipeline tracks). A branch is dropped once its bound is below the best less the tie tolerance,
or once tracking already refuses what was followed of it (a singular waypoint, a step over
``max_joint_step``, no joint copy within the limits); the ones still above are followed to the
end. Where no branch is feasible, every branch is followed to the end (the reason of an
infeasible cell is the furthest failure of all branches). A dropped branch is handed to the
pipeline as unreachable at its first waypoint: it is not the chosen branch, so no reported
field of the cell changes (tested cell by cell against following every branch).

Only where that argument holds: the map's ``auto`` branch, fixed spin, limits that bound each
waypoint by its own configuration (the joint speeds) and no final-path limit (mu_acc ranks the
branches). A path check (the cell) judges the pick's joint path, which is followed to the end;
where it refuses the pick, the refused placements run again without their refused branches
(:func:`solver.path.path_checks.refuse_colliding`).
Evaluations follow every branch: their answer reports the whole joint paths. A family that
follows bounded (six and seven joints, :attr:`FollowsInSteps.follows_bounded`) is pruned under
the same conditions in one compiled pass instead (:mod:`solver.path.bounded`); this serves arms
of more joints.
"""

from __future__ import annotations

import math

import numpy as np

from solver.core.codes import SINGULAR, TIE_RTOL, UNREACHABLE
from solver.core.family import PathSolutions
from solver.core.follows_in_steps import FollowsInSteps
from solver.path.chunk import Chunk
from solver.path.limits import JointSpeedLimit
from solver.path.problem import PathProblem

PIECE = 32
"""Waypoints a slot is followed at a time, between two looks at the bounds (32 against 8, 16
and 24: the fastest Panda map of 99 ERK placements, same run)."""
PROBE = 8
"""V_max is computed at every PROBE-th waypoint of a piece (its last among them): a bound from
fewer waypoints is still a bound, and for seven joints V_max (an LP) costs about as much as
following."""
EVEN = 1e-9
"""Slots whose bound is within this (relative) of a placement's highest are followed together
(the branches of a UR shoulder tie to rounding all along)."""
MARGIN = 1e-12
"""Relative margin below the tie threshold: the bounds here and the pipeline's V_max come from
angles 2 pi apart (wrapped here, tracked there), equal only to rounding."""
LIMIT_MARGIN = 1e-9
"""Turns of slack when the joint limits refuse a path so far (tracking's own is EDGE, 1e-12):
the path is unwrapped here piece by piece, its sums rounded otherwise."""
_TWO_PI = 2.0 * math.pi


def can_prune(problem: PathProblem) -> bool:
    """Whether a map of ``problem`` may drop branches (see the module's conditions)."""
    family = problem.family
    n_branches = len(family.branches)
    return (
        isinstance(family, FollowsInSteps)
        and (family.follows_in_steps or family.follows_bounded)
        and problem.options.spin_mode == "fixed"
        and not problem.final_path_limits
        and all(type(limit) is JointSpeedLimit for limit in problem.waypoint_limits)
        and n_branches > 1
        and problem.prepared.n_waypoints > 1
        and np.array_equal(problem.branches, np.arange(n_branches))
    )


class _State:
    """The slots' following so far: solutions, bounds, and what tracking already refuses.

    Attributes:
        current: shape (C, K, n), each slot's solution at the last waypoint followed; NaN
            where it has none (lost, or no solution at the first waypoint).
        position: shape (K, C), the next waypoint to follow.
        q: shape (n, K, C, W), rad, wrapped; status: shape (K, C, W).
        bound: shape (K, C), the least V_max followed so far (inf before any).
        settled: shape (K, C), a singular waypoint or a step over the bound was followed: the
            branch's reason and failing waypoint are known (nothing later comes first).
        broken: shape (K, C), tracking refuses the waypoints followed so far (singular, a step
            over the bound, or no joint copy within the limits): the branch is infeasible.
        last, unwrapped, low, high: shape (n, K, C): the last solution followed, the unwrapped
            joint path there and its least and greatest value so far (as tracking unwraps).
        best: shape (C,), the highest mu_path of a feasible branch followed to the end.
    """

    def __init__(self, current: np.ndarray, n_waypoints: int) -> None:
        """Nothing followed yet from the first waypoints' solutions ``current`` (C, K, n)."""
        n_cells, n_slots, dof = current.shape
        self.current = current
        self.position = np.zeros((n_slots, n_cells), dtype=np.int64)
        self.q = np.full((dof, n_slots, n_cells, n_waypoints), np.nan)
        self.status = np.full((n_slots, n_cells, n_waypoints), UNREACHABLE, dtype=np.int64)
        self.bound = np.full((n_slots, n_cells), np.inf)
        self.broken = np.zeros((n_slots, n_cells), dtype=bool)
        self.settled = np.zeros((n_slots, n_cells), dtype=bool)
        self.last = np.full((dof, n_slots, n_cells), np.nan)
        self.unwrapped, self.low, self.high = self.last.copy(), self.last.copy(), self.last.copy()
        self.best = np.full(n_cells, -np.inf)

    @property
    def live(self) -> np.ndarray:
        """(K, C): slots with a solution at the last waypoint followed, not at the end yet."""
        live: np.ndarray = np.isfinite(self.current[..., 0]).T
        return live & (self.position < self.q.shape[-1])


def pruned_solutions(
    problem: PathProblem,
    rotation: np.ndarray,
    flange_position: np.ndarray,
    twist: np.ndarray,
    tool_position: np.ndarray,
) -> PathSolutions:
    """The family's solutions along a chunk's paths, branches that cannot be best dropped.

    Best first: at each placement the slots with the highest bound (and those within
    :data:`EVEN` of it) are followed a piece further, until the best slot is followed to the
    end; a slot followed to the end and feasible sets the placement's best, and the slots
    whose bound falls below it, or whose tracking is refused so far, are dropped. A placement
    without any feasible slot follows all of them to the end.

    Args:
        problem: a problem :func:`can_prune` admits.
        rotation: shape (3, 3, C or 1, W), R_B_F* of the flange.
        flange_position: shape (3, C, W), m in {B}.
        twist: shape (6, C or 1, W), t_hat in {B}.
        tool_position: shape (3, C, W), m in {B}.

    Returns:
        As :meth:`KinematicsFamily.solve_path`, but each placement's rows are only its kept
        slots, in order (``PathSolutions.slots`` names them), then unreachable rows; a row
        after the kept ones at a placement is unreachable (NaN) at every waypoint.
    """
    chunk = Chunk(problem, rotation, flange_position, twist, tool_position)
    n_cells, n_waypoints = flange_position.shape[1:]
    current, count = chunk.family.seed_first(chunk.rotations[:, 0], chunk.positions[:, 0])
    n_seeds = current.shape[1]
    current = np.ascontiguousarray(current[:, : max(int(count.max()), 1)])  # the slots found
    state = _State(current, n_waypoints)
    _advance(chunk, state, state.live)  # every slot's first piece
    while True:
        threshold = _threshold(state.best)
        hopeful = state.live & ~state.broken & (state.bound >= threshold)
        top = np.where(hopeful, state.bound, -np.inf).max(axis=0)
        chosen = hopeful & (state.bound >= top * (1.0 - EVEN))
        if not chosen.any():
            break
        _advance(chunk, state, chosen)
    found = state.best > -np.inf
    # Where none is feasible, the furthest failure is the cell's: every branch to the end,
    # except those whose failure is settled (they come back unreachable after it).
    _advance(chunk, state, state.live & ~found & ~state.settled, to_end=True)
    threshold = _threshold(state.best)
    complete = state.position >= n_waypoints
    hopeless = found & (~complete | (state.bound < threshold))
    # Each placement's kept slots first, in the family's order (so ties go as before); the
    # dropped ones and those without a solution after them, as many rows as the most kept.
    kept = ~hopeless & (state.status[..., 0] != UNREACHABLE)
    slots = np.argsort(~kept, axis=0, kind="stable")[: max(int(kept.sum(axis=0).max()), 1)]
    cells = np.arange(n_cells)
    q, status = state.q[:, slots, cells], state.status[slots, cells]
    dropped = hopeless[slots, cells]
    q[:, dropped] = np.nan
    status[dropped] = UNREACHABLE
    return PathSolutions(q=q, status=status, seeds=n_seeds, branches_found=count, slots=slots)


def _threshold(best: np.ndarray) -> np.ndarray:
    """The bound below which a branch is dropped: the best less its tie tolerance, and margin.

    -inf (nothing dropped) where no branch is feasible yet, or the best is infinite.
    """
    with np.errstate(invalid="ignore"):
        below = best - (TIE_RTOL + MARGIN) * np.abs(best)
    threshold: np.ndarray = np.where(np.isfinite(best), below, -np.inf)
    return threshold


def _advance(chunk: Chunk, state: _State, chosen: np.ndarray, to_end: bool = False) -> None:
    """Follow the ``chosen`` slots (K, C) a piece (or to the end) further, and what it shows.

    Their solutions and statuses, bounds and tracking so far; a slot that reaches the end
    and is feasible raises its placement's best.
    """
    n_waypoints = state.q.shape[-1]
    slots, cells = np.nonzero(chosen)
    if not slots.size:
        return
    begin = state.position[slots, cells]
    end = np.full_like(begin, n_waypoints) if to_end else np.minimum(begin + PIECE, n_waypoints)
    start, stop = np.zeros_like(state.position), np.zeros_like(state.position)
    start[slots, cells], stop[slots, cells] = begin, end
    chunk.family.follow_ranges(
        state.current, chunk.rotations, chunk.positions, start, stop, (state.q, state.status)
    )
    state.position[slots, cells] = end
    if to_end:
        return
    waypoints = begin[:, None] + np.arange(PIECE)
    inside = waypoints < n_waypoints
    waypoints = np.minimum(waypoints, n_waypoints - 1)
    q = np.where(inside, state.q[:, slots[:, None], cells[:, None], waypoints], np.nan)
    probed = slice(PROBE - 1, None, PROBE)
    v_max = chunk.v_max(q[..., probed], cells, waypoints[:, probed])
    state.bound[slots, cells] = np.fmin(state.bound[slots, cells], np.fmin.reduce(v_max, axis=-1))
    singular = inside & (state.status[slots[:, None], cells[:, None], waypoints] == SINGULAR)
    jump, limits = _tracked_so_far(chunk.problem, state, slots, cells, q, begin)
    state.settled[slots, cells] |= singular.any(axis=-1) | jump
    state.broken[slots, cells] |= state.settled[slots, cells] | limits
    complete = (end >= n_waypoints) & np.isfinite(state.current[cells, slots, 0])
    done, at = slots[complete], cells[complete]
    if done.size:
        mu = chunk.mu_path(state.q[:, done, at], state.status[done, at], at)
        np.maximum.at(state.best, at, mu)


def _tracked_so_far(
    problem: PathProblem,
    state: _State,
    slots: np.ndarray,
    cells: np.ndarray,
    q: np.ndarray,
    begin: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Whether tracking refuses the slots' paths up to their pieces' ends: a step, the limits.

    :func:`solver.path.tracking.track`'s unwrapping, carried from piece to piece (q: (n, M, w),
    the pieces from waypoints ``begin``, NaN past the path's end); the steps are tracking's to
    the bit, the limits are judged with a margin (the running sums round otherwise than
    tracking's), so a path refused here is refused there.

    Returns:
        jump: shape (M,), a step over ``max_joint_step``; limits: shape (M,), no joint copy
        holds the path so far within the limits.
    """
    first = begin == 0
    before = np.where(first, q[..., 0], state.last[:, slots, cells])
    steps = np.diff(np.concatenate([before[..., None], q], axis=-1), axis=-1)
    base = np.where(first, q[..., 0], state.unwrapped[:, slots, cells])
    segment = begin[:, None] - 1 + np.arange(q.shape[-1])  # the segment into each waypoint
    in_pass = problem.prepared.segment_in_pass
    checked = (segment >= 0) & in_pass[np.clip(segment, 0, max(len(in_pass) - 1, 0))]
    steps -= np.where(steps > math.pi, _TWO_PI, np.where(steps < -math.pi, -_TWO_PI, 0.0))
    with np.errstate(invalid="ignore"):
        jump = (np.any(np.abs(steps) > problem.options.max_joint_step, axis=0) & checked).any(-1)
    path = base[..., None] + np.cumsum(steps, axis=-1)
    low = np.fmin(np.fmin(state.low[:, slots, cells], base), np.fmin.reduce(path, axis=-1))
    high = np.fmax(np.fmax(state.high[:, slots, cells], base), np.fmax.reduce(path, axis=-1))
    state.low[:, slots, cells], state.high[:, slots, cells] = low, high
    finite = np.isfinite(q)
    last = np.where(finite.any(axis=-1), q.shape[-1] - 1 - np.argmax(finite[..., ::-1], axis=-1), 0)
    state.last[:, slots, cells] = np.take_along_axis(q, last[..., None], axis=-1)[..., 0]
    state.unwrapped[:, slots, cells] = np.take_along_axis(path, last[..., None], axis=-1)[..., 0]
    robot = problem.robot
    k_low = np.ceil((robot.q_lower[:, None] - low) / _TWO_PI - LIMIT_MARGIN)
    k_high = np.floor((robot.q_upper[:, None] - high) / _TWO_PI + LIMIT_MARGIN)
    limits: np.ndarray = np.any(k_low > k_high, axis=0)
    return jump, limits
