"""The map kernels' final-path step: mu_acc per branch, and its answer columns (motion.md s. 2).

With joint acceleration limits the numpy pipeline (:func:`solver.path.pipeline.run_chunk`)
bounds a constant feed along each feasible branch's final tracked joint path (in free spin,
the path along the spin schedule): mu_acc = min(mu_path, min_i V_acc,i), and the ``auto``
branch is the one with the highest mu_acc (:func:`solver.path.tracking.choose_branch`, ties
within ``ACC_TIE_RTOL`` to the first). The kernels do the same here, with the limit's hooks
(:mod:`solver.kernels.limits`).

The branches (:func:`cell_mu_acc`) are taken in their order, and a branch is
left as soon as a bound of its mu_acc (its mu_path, or one waypoint's V_acc) is at most
``top``, the highest index of the branches before it: an earlier branch then has an index at
least as high, so whatever the tie, the choice takes that one (or one before it) and never this
one. Each branch is first probed at the waypoints where the branches before it bound, then
scanned along its path until such a waypoint. Branches of one shoulder share joints (a UR's
wrist_3 differs between them by pi, which no second difference sees): their V_acc there is
equal to the bit, as D is formed from the steps (:func:`solver.kernels.limits.step_stencil`),
and most branches are left at their first probe. In free spin a branch is tracked along its
spin schedule only when no probe leaves it.

Without acceleration limits the free-spin kernel tracks the spin schedule fastest first
(:func:`next_fastest`) and stops at the first branch that holds, ties apart.

Without acceleration limits the kernels get ``qddot_max`` of shape (0,) and skip all of this.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import FEASIBLE
from solver.families.kernels import N_JOINTS
from solver.kernels.cell import fail
from solver.kernels.limits import acceleration_at
from solver.kernels.positions import pair_step, relative_path, wrapped_step
from solver.kernels.spin_schedule import spin_rate, spun_failure


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def acc_work(n_branches, n_waypoints, keep_speeds):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Per branch: its index for the choice, where mu_acc binds, and V_acc per waypoint.

    The index is mu_acc, or mu_path where it was not computed; ``taken`` marks the branches
    whose mu_acc was.

    Returns:
        feed, acc_at, acc_joint, taken: shape (B,); acc_speeds: shape (B, W), or (B, 0) when
        not ``keep_speeds``; probes: shape (B + 1,), the stencil rows where branches bound,
        their count last (:func:`cell_mu_acc`); steps: shape (W, 6), one branch's joint steps.
    """
    feed = np.empty(n_branches)
    acc_at = np.empty(n_branches, dtype=np.int64)
    acc_joint = np.empty(n_branches, dtype=np.int64)
    taken = np.empty(n_branches, dtype=np.bool_)
    acc_speeds = np.empty((n_branches, n_waypoints if keep_speeds else 0))
    probes = np.zeros(n_branches + 1, dtype=np.int64)
    steps = np.empty((n_waypoints, N_JOINTS))
    return feed, acc_at, acc_joint, taken, acc_speeds, probes, steps


@njit(cache=True, error_model="numpy", nogil=True)
def next_fastest(alive, taken, slowest, top, tie):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The alive branch not yet taken with the highest mu_path (the first at a tie), or -1.

    -1 too where that mu_path is below ``top`` (the highest index found so far) and not tied
    with it (relative ``tie``): no branch left can then be chosen. The branch returned is
    marked taken.
    """
    i = -1
    for k in range(alive.shape[0]):
        if alive[k] and not taken[k] and (i < 0 or slowest[k] > slowest[i]):
            i = k
    if i < 0 or slowest[i] < top - tie * abs(top):
        return -1
    taken[i] = True
    return i


@njit(cache=True, error_model="numpy", nogil=True)
def write_acc(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    c, pick, reason, slowest, slowest_at, slowest_joint, feed, acc_at, acc_joint, acc_speeds,
    mu_acc, limited_by, acc_waypoint, acc_joint_out, v_acc,
):  # fmt: skip
    """Placement c's acceleration columns from its chosen branch row ``pick``.

    As :func:`solver.path.placements._chunk`: mu_acc; what binds it (0 the speed limits, 1 the
    acceleration limits, -1 infeasible); its waypoint and joint (those of mu_path where the
    speed limits bind); V_acc along the path (NaN where infeasible).
    """
    if reason[c] != FEASIBLE:
        mu_acc[c] = np.nan
        limited_by[c] = -1
        acc_waypoint[c] = -1
        acc_joint_out[c] = -1
        for w in range(v_acc.shape[1]):
            v_acc[c, w] = np.nan
        return
    mu_acc[c] = feed[pick]
    accelerated = acc_at[pick] >= 0 and feed[pick] < slowest[pick]
    limited_by[c] = 1 if accelerated else 0
    acc_waypoint[c] = acc_at[pick] if accelerated else slowest_at[pick]
    acc_joint_out[c] = acc_joint[pick] if accelerated else slowest_joint[pick]
    for w in range(v_acc.shape[1]):
        v_acc[c, w] = acc_speeds[pick, w]


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def pair_steps(cq, sq, b, lo, hi, steps):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch b's joint steps q_w - q_(w-1) for lo < w <= hi into ``steps`` (W, 6).

    The angle between neighbouring (cos, sin) pairs (:func:`solver.kernels.positions.pair_step`):
    the same bits wherever and however often a step is made.
    """
    for w in range(lo + 1, hi + 1):
        for j in range(N_JOINTS):
            steps[w, j] = pair_step(cq[b, j, w - 1], sq[b, j, w - 1], cq[b, j, w], sq[b, j, w])


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def spun_steps(cq, sq, qd, qs, b, lo, hi, rate, length, qdot_max, steps):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch b's steps along the spin schedule at the feed ``rate`` (m/s), lo < w <= hi.

    :func:`pair_steps` plus the spin's move over the segment, sigma dt J^-1 [0; z_tool], as
    :func:`solver.kernels.spin_schedule.spun_failure` adds it within a pass (``qd``, ``qs``:
    shape (8, 6, W); ``length``: shape (W - 1,), m), brought into [-pi, pi] as its tracking
    does. Without a feed (0) no spin moves.
    """
    pair_steps(cq, sq, b, lo, hi, steps)
    if rate <= 0.0:
        return
    for w in range(lo + 1, hi + 1):
        spin = spin_rate(qd, qs, b, w - 1, qdot_max, rate) * length[w - 1] / rate
        for j in range(N_JOINTS):
            steps[w, j] = wrapped_step(steps[w, j] + spin * qs[b, j, w - 1])


@njit(cache=True, error_model="numpy", nogil=True)
def cell_mu_acc(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    alive, why, where, slowest, branches, cq, sq, qd, qs, free, length, segment_checked, lower,
    upper, qdot_max, max_joint_step, spun, index, c, waypoints, qddot_max, feed, acc_at,
    acc_joint, acc_speeds, probes, steps,
):  # fmt: skip
    """mu_acc in ``feed`` of the branches the choice can take; below the best, the others.

    Branch by branch in their order (see the module): skipped where its mu_path is at most
    ``top``, left at the first probe (a waypoint where a branch before it bound) whose V_acc
    is; in free spin then tracked along its spin schedule
    (:func:`solver.kernels.spin_schedule.spun_failure`, which may fail it); then scanned along
    its steps (:func:`solver.kernels.limits.acceleration_at`) until a waypoint whose V_acc is
    at most ``top``. A branch scanned to the end has its mu_acc, the least V_acc (the first
    waypoint and joint at a tie; where it binds goes to ``acc_at``, ``acc_joint``, and V_acc
    per waypoint to ``acc_speeds``); a branch left has such a bound in ``feed``.

    Args:
        alive: shape (B,), the branches that hold (a branch the spin schedule fails: out).
        why: shape (B,), out, why a branch failed.
        where: shape (B,), out, where.
        slowest: shape (B,), m/s, their mu_path.
        branches: shape (B,), their indices in the pairs.
        cq: shape (8, 6, W), the joints' cos per branch.
        sq: shape (8, 6, W), their sin.
        qd: shape (8, 6, W), J^-1 t_hat (free spin).
        qs: shape (8, 6, W), J^-1 [0; z_tool] (free spin).
        free: free spin: the joint paths along the spin schedule.
        length: shape (W - 1,), m, the segments' lengths (free spin).
        segment_checked: shape (W - 1,), bool, where the step bound applies (free spin).
        lower: shape (6,), rad, lower position limits (free spin).
        upper: shape (6,), rad, upper position limits (free spin).
        qdot_max: shape (6,), rad/s (free spin).
        max_joint_step: rad (free spin).
        spun: shape (W, 6), work (free spin).
        index: shape (K, 5), the blend stencil's waypoints.
        c: shape (K, S), its step form (:func:`solver.kernels.limits.step_stencil`).
        waypoints: shape (K,), the constrained waypoints.
        qddot_max: shape (6,), rad/s^2.
        feed: shape (B,), out, m/s.
        acc_at: shape (B,), out.
        acc_joint: shape (B,), out.
        acc_speeds: shape (B, W) or (B, 0), out.
        probes: shape (B + 1,), work.
        steps: shape (W, 6), work.
    """
    feed[:] = slowest
    probes[-1] = 0
    top = -np.inf
    for i in range(branches.shape[0]):
        if not alive[i] or slowest[i] <= top:
            continue
        b = branches[i]
        rate = slowest[i] if free and slowest[i] > 0.0 and math.isfinite(slowest[i]) else 0.0
        left = False
        for p in range(probes[-1]):
            k = probes[p]
            start, span = index[k, 0], index[k, -1] - index[k, 0]
            spun_steps(cq, sq, qd, qs, b, start, start + span, rate, length, qdot_max, steps)
            worst, joint = acceleration_at(steps, start, span, c, k, qddot_max)
            if 1.0 / math.sqrt(worst) <= top:
                feed[i] = 1.0 / math.sqrt(worst)
                acc_at[i] = waypoints[k]
                acc_joint[i] = joint
                left = True
                break
        if left:
            continue
        if free:
            code, at = spun_failure(
                relative_path(cq, sq, b, True), qd, qs, b, rate, length, segment_checked,
                lower, upper, qdot_max, max_joint_step, spun,
            )  # fmt: skip
            if code != FEASIBLE:
                fail(i, code, at, alive, why, where)
                continue
        row = acc_speeds[i] if acc_speeds.shape[1] else acc_speeds[0, :0]
        if row.shape[0]:
            row[:] = np.inf
        largest, at, joint, built = -1.0, -1, -1, 0
        for k in range(waypoints.shape[0]):
            start, span = index[k, 0], index[k, -1] - index[k, 0]
            spun_steps(cq, sq, qd, qs, b, built, start + span, rate, length, qdot_max, steps)
            built = max(built, start + span)
            worst, limiting = acceleration_at(steps, start, span, c, k, qddot_max)
            if row.shape[0]:
                row[waypoints[k]] = 1.0 / math.sqrt(worst)
            if worst > largest:  # V_acc = 1 / sqrt(worst) below the least so far
                largest, at, joint = worst, k, limiting
                if 1.0 / math.sqrt(worst) <= top:
                    break
        least = 1.0 / math.sqrt(largest) if at >= 0 else np.inf
        feed[i] = min(slowest[i], least)
        acc_at[i] = waypoints[at] if at >= 0 else -1
        acc_joint[i] = joint
        top = max(top, feed[i])
        if at >= 0:
            new = True
            for p in range(probes[-1]):
                new = new and probes[p] != at
            if new:
                probes[probes[-1]] = at
                probes[-1] += 1
