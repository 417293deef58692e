"""Following branches in fixed spin: the per-waypoint tests of the map kernel, with a bar.

:func:`solver.kernels.fixed_spin.map_cells` follows a placement's branches in phases
(:mod:`solver.kernels.cell`, "pruning"): the branch the previous placement chose, then every
other branch at a few probe waypoints, then the branches left, each left as soon as its running
minimum of the speed bound falls below the bar. A phase's branches are marked in ``todo``;
everything a branch computes here (its failure, mu_path, bottleneck, position-limit test) is
what the one loop over all branches computed, as a branch's tests never read another branch.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import (
    OK,
    REASON_DISCONTINUOUS,
    REASON_JOINT_LIMITS,
    REASON_SINGULAR,
    REASON_UNREACHABLE,
    SINGULAR,
    TAKES_OVER,
    UNREACHABLE,
)
from solver.families.kernels import N_JOINTS, pose_block
from solver.kernels.cell import BLOCK, fail, prune
from solver.kernels.limits import joint_speed_bound
from solver.kernels.positions import NARROW, WIDE, first_outside_pairs

OUTSIDE = 1e-9
"""A waypoint whose joint is outside a narrow range's arc by more than this (cos of the angle
from the range's middle below cos of its half width) has no 2 pi copy within the limits (the
exact test's slack is EDGE, 1e-12 rad): its branch fails the position limits there or before.
Where the cell has a feasible branch (a finite ``limit``), the branch is then left, its bound
-inf, as an unreachable one is: an OPW arm's branches out of their joint ranges were followed
to the end, where their limits are tested, for nothing."""


@njit(cache=True, error_model="numpy", nogil=True)
def follow_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, limit, family, par, poses, branches, pure_rotation, segment_checked, lower, upper,
    modes, arc, inverse_qdot, max_joint_step, scratch, cq, sq, qd, status, need, alive, why,
    where, slowest, slowest_at, slowest_joint, speeds, chords2, largest2, inside, crossed, hint,
):  # fmt: skip
    """Follow the branch rows marked in ``todo`` along the whole path, in blocks of waypoints.

    Each row: unreachable, then singular, then the step test cos(dq) >= cos(max_joint_step)
    against the previous waypoint, with the sums of the fast position tests; then its DTF and
    running minimum (``slowest``, ``slowest_at``, ``slowest_joint``, where a tie in the last
    bits stays with the earlier waypoint: :data:`solver.core.codes.TAKES_OVER`; V_max in
    ``speeds``); after the path the position limits (:func:`first_outside_pairs`). A row
    whose running minimum falls below its ``limit`` is pruned
    (:func:`solver.kernels.cell.prune`); ``hint`` keeps where each row's minimum was. Arrays
    as :func:`solver.kernels.fixed_spin.map_cells` makes them.
    """
    n_waypoints = poses.shape[1]
    check_steps = max_joint_step < math.pi
    cos_step = math.cos(max_joint_step)
    n_live = 0
    for i in range(branches.shape[0]):
        if todo[i] and alive[i]:
            chords2[i, :] = 0.0
            largest2[i, :] = 0.0
            inside[i, :] = np.inf
            crossed[i, :] = False
            n_live += 1
    for w0 in range(0, n_waypoints, BLOCK):
        if n_live == 0:
            break
        w1 = min(w0 + BLOCK, n_waypoints)
        need[:] = False
        for i in range(branches.shape[0]):
            need[branches[i]] = need[branches[i]] or (todo[i] and alive[i])
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
                elif w > 0:
                    checked = check_steps and segment_checked[w - 1]
                    for j in range(N_JOINTS):
                        c0, s0 = cq[b, j, w - 1], sq[b, j, w - 1]
                        c1, s1 = cq[b, j, w], sq[b, j, w]
                        if checked and c0 * c1 + s0 * s1 < cos_step:
                            code = REASON_DISCONTINUOUS
                            break
                        if modes[j] == WIDE:
                            chord2 = (c1 - c0) * (c1 - c0) + (s1 - s0) * (s1 - s0)
                            chords2[i, j] += chord2
                            largest2[i, j] = max(largest2[i, j], chord2)
                        elif modes[j] == NARROW and not crossed[i, j]:
                            # Does the step's short arc pass the middle of the gap, the angle
                            # opposite the range's middle? Where both ends lie on the middle's
                            # side (u > 0) and the sign of v changes, it passes the middle
                            # instead; otherwise it may (so: the exact test).
                            u0 = c0 * arc[j, 0] + s0 * arc[j, 1]
                            v0 = s0 * arc[j, 0] - c0 * arc[j, 1]
                            u1 = c1 * arc[j, 0] + s1 * arc[j, 1]
                            v1 = s1 * arc[j, 0] - c1 * arc[j, 1]
                            crossed[i, j] = v0 * v1 <= 0.0 and (u0 <= 0.0 or u1 <= 0.0)
                if code >= 0:
                    fail(i, code, w, alive, why, where)
                    n_live -= 1
                    break
                outside = False
                for j in range(N_JOINTS):
                    if modes[j] == NARROW:
                        margin = cq[b, j, w] * arc[j, 0] + sq[b, j, w] * arc[j, 1] - arc[j, 2]
                        inside[i, j] = min(inside[i, j], margin)
                        outside = outside or margin < -OUTSIDE
                if outside and limit[i] > -np.inf:  # out of a narrow range: infeasible
                    prune(i, w, -np.inf, alive, why, where, slowest, hint)
                    n_live -= 1
                    break
                speed, limiting = joint_speed_bound(qd, b, w, inverse_qdot)
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
        if not (todo[i] and alive[i]):
            continue
        hint[i] = slowest_at[i]
        first = first_outside_pairs(
            cq, sq, branches[i], i, lower, upper, modes, chords2, largest2, inside, crossed
        )
        if first < n_waypoints:
            fail(i, REASON_JOINT_LIMITS, first, alive, why, where)


@njit(cache=True, error_model="numpy", nogil=True)
def fail_first_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, family, par, poses, branches, scratch, cq, sq, qd, status, need, alive, why, where,
):  # fmt: skip
    """The rows marked in ``todo`` without a regular solution at the first waypoint fail there.

    :func:`follow_rows`' first tests (unreachable, then singular) at waypoint 0, for all the
    rows at once: one pose kernel call of one waypoint, where following them one by one solves
    a block of BLOCK waypoints each. A placement whose first branch fails at its first
    waypoint is mostly out of reach on every branch (the KUKA KR6's ERK grid: 116 of its 546
    cells, each of whose eight branches solved a block).
    """
    need[:] = False
    for i in range(branches.shape[0]):
        need[branches[i]] = need[branches[i]] or (todo[i] and alive[i])
    pose_block(family, par, poses, 0, 1, need, scratch, cq, sq, status, qd)
    for i in range(branches.shape[0]):
        if not (todo[i] and alive[i]):
            continue
        if status[branches[i], 0] == UNREACHABLE:
            fail(i, REASON_UNREACHABLE, 0, alive, why, where)
        elif status[branches[i], 0] == SINGULAR:
            fail(i, REASON_SINGULAR, 0, alive, why, where)


@njit(cache=True, error_model="numpy", nogil=True)
def probe_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, limit, w, family, par, poses, branches, pure_rotation, inverse_qdot, scratch, cq, sq,
    qd, status, need, alive, why, where, slowest, hint, bound,
):  # fmt: skip
    """Prune the rows marked in ``todo`` whose speed bound at waypoint w is below their ``limit``.

    A row that is not OK at w fails there or before (its bound -inf); one whose bound there is
    below its limit (:func:`solver.kernels.cell.set_limits`) has its mu_path below it. The
    others keep in ``bound`` the least bound seen (:func:`solver.kernels.cell.next_row`).
    """
    need[:] = False
    for i in range(branches.shape[0]):
        need[branches[i]] = need[branches[i]] or (todo[i] and alive[i])
    pose_block(family, par, poses, w, w + 1, need, scratch, cq, sq, status, qd)
    for i in range(branches.shape[0]):
        if not (todo[i] and alive[i]):
            continue
        b = branches[i]
        if status[b, w] != OK:
            prune(i, w, -np.inf, alive, why, where, slowest, hint)
            continue
        speed, _ = joint_speed_bound(qd, b, w, inverse_qdot)
        v = 0.0 if pure_rotation[w] else speed
        if v < limit[i]:
            prune(i, w, v, alive, why, where, slowest, hint)
        else:
            bound[i] = min(bound[i], v)
