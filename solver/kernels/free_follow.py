"""Following branches in free spin: the per-waypoint tests of the free-spin kernel, with a bar.

:func:`solver.kernels.free_spin.free_cells` prunes branches as the fixed-spin kernel does
(:mod:`solver.kernels.fixed_follow`, :mod:`solver.kernels.cell`): a phase's rows are marked in
``todo``, and a row computes here what the one loop over all rows computed (a row's tests never
read another row), but a row whose running minimum falls below its limit is left.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import (
    FEASIBLE,
    OK,
    REASON_DISCONTINUOUS,
    REASON_SINGULAR,
    REASON_UNREACHABLE,
    SINGULAR,
    TAKES_OVER,
    UNREACHABLE,
)
from solver.families.kernels import N_JOINTS, pose_block
from solver.kernels.cell import BLOCK, fail, prune
from solver.kernels.limits import two_variable_speed
from solver.kernels.positions import relative_path
from solver.kernels.spin_schedule import moved_failure, spun_failure


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def needed(todo, branches, alive, need):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Mark in ``need`` (8,) the branches of the rows in ``todo`` still alive."""
    need[:] = False
    for i in range(branches.shape[0]):
        need[branches[i]] = need[branches[i]] or (todo[i] and alive[i])


@njit(cache=True, error_model="numpy", nogil=True)
def follow_free_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, limit, family, par, poses, spin_poses, branches, pure_rotation, segment_checked,
    qdot_max, max_joint_step, scratch, cq, sq, qd, qs, status, need, alive, why, where, slowest,
    slowest_at, slowest_joint, speeds, hint,
):  # fmt: skip
    """Follow the rows marked in ``todo`` along the whole path, in blocks of waypoints.

    Each row: unreachable, then singular, then the step test against the previous waypoint;
    V_max by the two-variable LP and its running minimum (``slowest``, ``slowest_at``,
    ``slowest_joint``, a tie in the last bits staying with the earlier waypoint:
    :data:`solver.core.codes.TAKES_OVER`; V_max in ``speeds``). A row whose running minimum
    falls below its ``limit`` is pruned; ``hint`` keeps where each row's minimum was. Arrays as
    :func:`solver.kernels.free_spin.free_cells` makes them.
    """
    n_waypoints = poses.shape[1]
    check_steps = max_joint_step < math.pi
    cos_step = math.cos(max_joint_step)
    n_live = 0
    for i in range(branches.shape[0]):
        if todo[i] and alive[i]:
            n_live += 1
    for w0 in range(0, n_waypoints, BLOCK):
        if n_live == 0:
            break
        w1 = min(w0 + BLOCK, n_waypoints)
        needed(todo, branches, alive, need)
        pose_block(family, par, spin_poses, w0, w1, need, scratch, cq, sq, status, qs)
        pose_block(family, par, poses, w0, w1, need, scratch, cq, sq, status, qd)
        for i in range(branches.shape[0]):
            if not (todo[i] and alive[i]):
                continue
            b = branches[i]
            for w in range(w0, w1):
                code = -1
                if status[b, w] == UNREACHABLE:
                    code = REASON_UNREACHABLE
                elif status[b, w] == SINGULAR:
                    code = REASON_SINGULAR
                elif w > 0 and check_steps and segment_checked[w - 1]:
                    for j in range(N_JOINTS):
                        c0, s0 = cq[b, j, w - 1], sq[b, j, w - 1]
                        c1, s1 = cq[b, j, w], sq[b, j, w]
                        if c0 * c1 + s0 * s1 < cos_step:
                            code = REASON_DISCONTINUOUS
                            break
                if code >= 0:
                    fail(i, code, w, alive, why, where)
                    n_live -= 1
                    break
                speed, limiting = two_variable_speed(qd, qs, b, w, qdot_max)
                v = 0.0 if pure_rotation[w] else speed
                if w == 0 or v < slowest[i]:
                    if w == 0 or v < slowest[i] * TAKES_OVER:  # not a tie: takes it over
                        slowest_at[i] = w
                        slowest_joint[i] = limiting
                    slowest[i] = v
                    if v < limit[i]:
                        prune(i, w, v, alive, why, where, slowest, hint)
                        n_live -= 1
                        break
                if speeds.shape[0]:
                    speeds[i, w] = v
    for i in range(branches.shape[0]):
        if todo[i] and alive[i]:
            hint[i] = slowest_at[i]


@njit(cache=True, error_model="numpy", nogil=True)
def probe_free_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, limit, w, family, par, poses, spin_poses, branches, pure_rotation, qdot_max, scratch,
    cq, sq, qd, qs, status, need, alive, why, where, slowest, hint, bound,
):  # fmt: skip
    """Prune the rows in ``todo`` whose V_max at waypoint w is below their ``limit``.

    As :func:`solver.kernels.fixed_follow.probe_rows`: a row not OK at w fails there or before
    (bound -inf); the others keep in ``bound`` the least V_max seen.
    """
    needed(todo, branches, alive, need)
    pose_block(family, par, spin_poses, w, w + 1, need, scratch, cq, sq, status, qs)
    pose_block(family, par, poses, w, w + 1, need, scratch, cq, sq, status, qd)
    for i in range(branches.shape[0]):
        if not (todo[i] and alive[i]):
            continue
        b = branches[i]
        if status[b, w] != OK:
            prune(i, w, -np.inf, alive, why, where, slowest, hint)
            continue
        speed, _ = two_variable_speed(qd, qs, b, w, qdot_max)
        v = 0.0 if pure_rotation[w] else speed
        if v < limit[i]:
            prune(i, w, v, alive, why, where, slowest, hint)
        else:
            bound[i] = min(bound[i], v)


@njit(cache=True, error_model="numpy", nogil=True)
def spun_check(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    i, cq, sq, qd, qs, branches, slowest, length, segment_checked, lower, upper, qdot_max,
    max_joint_step, spun, alive, why, where,
):  # fmt: skip
    """Row i, followed to the end, tracked again along its spin schedule; failed if it fails.

    The spin rate nearest zero at the feed mu_path (``slowest``), the joints moved by the
    spin, and that joint path's position limits and step test
    (:func:`solver.kernels.spin_schedule.spun_failure`).
    """
    rate = slowest[i] if slowest[i] > 0.0 and math.isfinite(slowest[i]) else 0.0
    code, at = spun_failure(
        relative_path(cq, sq, branches[i], True), qd, qs, branches[i], rate, length,
        segment_checked, lower, upper, qdot_max, max_joint_step, spun,
    )  # fmt: skip
    if code != FEASIBLE:
        fail(i, code, at, alive, why, where)


@njit(cache=True, error_model="numpy", nogil=True)
def moved_check(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    i, moves, cq, sq, qd, qs, branches, slowest, length, segment_checked, lower, upper, qdot_max,
    max_joint_step, spun, alive, why, where,
):  # fmt: skip
    """:func:`spun_check` with the spin's moves at the row's mu_path already made.

    ``moves``: shape (W,), from :func:`solver.kernels.spin_schedule.spin_moves`, made once for
    this check and the acceleration scan (:mod:`solver.kernels.acc_free`).
    """
    code, at = moved_failure(
        relative_path(cq, sq, branches[i], True), moves, qs, branches[i], segment_checked, lower,
        upper, max_joint_step, spun,
    )  # fmt: skip
    if code != FEASIBLE:
        fail(i, code, at, alive, why, where)
