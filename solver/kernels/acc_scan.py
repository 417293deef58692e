"""The acceleration scan of one branch followed to the end: its mu_acc, or where it is left.

:func:`scan_row` is the exact V_acc of every stencil row (motion.md section 2) along a branch's
final joint path, the bits :func:`solver.kernels.limits.acceleration_at` forms row by row from
:func:`solver.kernels.accelerations.moved_steps`, computed in two passes: the branch's steps
joint by joint along the path (:func:`joint_steps`, the asin series of
:func:`solver.kernels.positions.pair_step` on every step, a loop a compiler vectorises, its
other cases made again one by one where a step needs them), then the stencil rows joint by
joint, each over its own span (:func:`row_ratios`, :func:`solver.kernels.limits.row_second`). The
rows are then read in order as the row-by-row scan reads them, so what it reports (where the
least V_acc is, where a branch is left) is the same.

Where the limits cannot bind, no row is read: a branch followed to the end passed the step
test, so each step of a stencil row is at most ``max_joint_step``, |D_j| at most
sum_t |c_k(t)| times that, and V_acc at least a floor the stencil and the limits give
(:func:`scan_work`). A branch whose mu_path is below the floor has mu_acc = mu_path exactly,
bound by its speeds (what the scan would report: its least V_acc, and where, are read only
where they bind, and the row is never left, as mu_path is at least its bar).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.families.kernels import N_JOINTS
from solver.kernels.cell import prune
from solver.kernels.limits import row_second
from solver.kernels.positions import pair_step, series_holds, small_step, wrapped_step

_TWO_PI = 2 * math.pi
# rad: the floor below is taken only where the step test bounds a step well inside a half turn
# (the scan's step and the tested one are then the same step to rounding).
_FLOOR_STEP = 3.0
# The floor's margins: relative on the step bound and on V_acc, absolute on a step (rad), each
# far above the rounding they cover (1e-15 relative; a step whose cosine rounds to the test's
# bound is within 2.2e-8 rad of it, where the cosine is near 1).
_FLOOR_RTOL = 1e-6
_FLOOR_ATOL = 1e-7
DENSE_WASTE = 2
"""The most a step-by-step table may hold beyond its rows' spans, as a multiple of them."""
DENSE_VALUES = 1_000_000
"""The most values a step-by-step table may hold (8 MB, and as many again for its joint path's
padding columns at most)."""


@njit(cache=True, error_model="numpy", nogil=True)
def scan_work(index, c, n_waypoints, segment_checked, max_joint_step, qddot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The stencil in row form and the scan's arrays, made once per kernel call.

    Args:
        index: shape (K, 5), the blend stencil's waypoints.
        c: shape (K, 4), 1/m^2, its runs' weights, from
            :func:`solver.kernels.limits.step_stencil`.
        n_waypoints: W.
        segment_checked: shape (W - 1,), bool, where the step bound applies.
        max_joint_step: rad, the step bound.
        qddot_max: shape (6,), rad/s^2.

    Returns:
        first: shape (K,), index[k, 0] + 1, each row's first step; contiguous: whether
        first[k] = first[0] + k (one pass, rows on consecutive waypoints); weights: shape
        (S, K), the steps' weights by step t of each row (S the longest span), where that
        table is small (:func:`dense_table`), else (0, K): each row is then summed over its
        own span alone; index; c; joint_path: shape (6, W + S) (dense) or (6, W), rad, a
        branch's steps by joint (the last S columns stay 0: the zero weights of a short row
        read there); sums: shape (K,); worst: shape (K,), max_j |D_j| / a_j per row; floor:
        m/s, a lower bound of V_acc on every row of a branch that passed the step test (0:
        none, where a row reads a step the test does not bound or the bound is a half turn).
    """
    n_rows = index.shape[0]
    first = np.empty(n_rows, dtype=np.int64)
    contiguous, bounded, weight = True, max_joint_step <= _FLOOR_STEP, 0.0
    span, spans = 0, 0
    for k in range(n_rows):
        first[k] = index[k, 0] + 1
        contiguous = contiguous and first[k] == first[0] + k
        span = max(span, index[k, 4] - index[k, 0])
        spans += index[k, 4] - index[k, 0]
        total = 0.0
        t = 0
        for run in range(4):  # the steps' weights in t's order, as the table summed them
            end = index[k, run + 1] - index[k, 0]
            while t < end:
                if c[k, run] != 0.0:
                    total += abs(c[k, run])
                    bounded = bounded and segment_checked[index[k, 0] + t]
                t += 1
        weight = max(weight, total)
    least = np.inf  # the least acceleration limit (none without limits: no floor needed)
    for j in range(qddot_max.shape[0]):
        least = min(least, qddot_max[j])
    step = max_joint_step * (1.0 + _FLOOR_RTOL) + _FLOOR_ATOL
    floor = 0.0
    if bounded and least > 0.0 and least < np.inf:
        floor = (1.0 - _FLOOR_RTOL) / math.sqrt(weight * step / least)
    dense = dense_table(n_rows, span, spans)
    weights = np.zeros((span if dense else 0, n_rows))
    for k in range(n_rows if dense else 0):
        t = 0
        for run in range(4):
            end = index[k, run + 1] - index[k, 0]
            while t < end:
                weights[t, k] = c[k, run]
                t += 1
    joint_path = np.zeros((N_JOINTS, n_waypoints + (span if dense else 0)))
    sums = np.empty(n_rows)
    worst = np.empty(n_rows)
    return first, contiguous, weights, index, c, joint_path, sums, worst, floor


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def dense_table(n_rows, span, spans):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether :func:`row_ratios` sums the rows step by step across them all, from a table.

    Where the rows' spans are short and alike (a path's usual blend: two to a few steps), a
    pass over every row at each step t is a loop the compiler vectorises: the ERK-size map with
    the limits ran 1.5x its time without them that way, 1.75x row by row. The table holds
    n_rows x the longest span: kept where that is at most DENSE_WASTE times the spans' sum and
    DENSE_VALUES values (a path with a dense stretch, or a blend spanning thousands of
    waypoints, is summed row by row over each row's own span).
    """
    return n_rows * span <= DENSE_WASTE * spans + n_rows and n_rows * span <= DENSE_VALUES


@njit(cache=True, error_model="numpy", nogil=True)
def joint_steps(cq, sq, qs, b, moves, joint_path):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch b's steps q_w - q_(w-1) along its spin's moves, by joint: ``joint_path[j, w]``.

    The bits of :func:`solver.kernels.accelerations.moved_steps`: the pair's step plus the
    move times J^-1 [0; z_tool] (``moves``: shape (W,); zeros in fixed spin), brought into
    [-pi, pi]. Every step by the series first; the steps it does not give are made again.
    Without moves (fixed spin) the series alone: adding a zero move changes at most the sign
    of a zero step, which no |D| sees.
    ``cq``, ``sq``, ``qs``: shape (8, 6, W); ``joint_path``: shape (6, >= W), columns 1 to W - 1
    written.
    """
    n_waypoints = cq.shape[2]
    unmoved = True
    for w in range(1, n_waypoints):
        unmoved = unmoved & (moves[w] == 0.0)
    for j in range(N_JOINTS):
        cj, sj, qj, out = cq[b, j], sq[b, j], qs[b, j], joint_path[j]
        others = 0
        plain = unmoved
        if plain:  # no move (fixed spin): a zero move of a finite J^-1 [0; z_tool] adds +-0.0
            for w in range(1, n_waypoints):
                plain = plain & (abs(qj[w - 1]) < np.inf)
        if plain:  # the series alone (a step it gives is within half a turn: no wrap)
            for w in range(1, n_waypoints):
                c0, s0, c1, s1 = cj[w - 1], sj[w - 1], cj[w], sj[w]
                cross = c0 * s1 - s0 * c1
                others += not series_holds(cross, c0 * c1 + s0 * s1)
                out[w] = small_step(cross)
        else:
            for w in range(1, n_waypoints):
                c0, s0, c1, s1 = cj[w - 1], sj[w - 1], cj[w], sj[w]
                cross = c0 * s1 - s0 * c1
                others += not series_holds(cross, c0 * c1 + s0 * s1)
                step = small_step(cross) + moves[w] * qj[w - 1]
                step = step - _TWO_PI if step > math.pi else step
                out[w] = step + _TWO_PI if step < -math.pi else step
        if others == 0:
            continue
        for w in range(1, n_waypoints):
            c0, s0, c1, s1 = cj[w - 1], sj[w - 1], cj[w], sj[w]
            if not series_holds(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1):
                out[w] = wrapped_step(pair_step(c0, s0, c1, s1) + moves[w] * qj[w - 1])


@njit(cache=True, error_model="numpy", nogil=True)
def row_ratios(rows, qddot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Every stencil row's max_j |D_j| / a_j into ``rows``' ``worst``.

    D_j as :func:`solver.kernels.limits.row_second` forms it for every hook: summed in t's
    order from 0.0, row by row over each row's own span, or step by step across the rows from
    the table where :func:`scan_work` made one (a short row's zero weights add zeros: the same
    |D|, to the bit). The maximum is taken without its joint (a select the compiler
    vectorises): the joint is read only where a row binds (:func:`row_joint`). ``rows``: from
    :func:`scan_work`, the joint path filled (:func:`joint_steps`); ``qddot_max``: shape (6,),
    rad/s^2.
    """
    first, contiguous, weights, index, c, joint_path, sums, worst, _ = rows
    n_rows = first.shape[0]
    worst[:] = -1.0
    for j in range(N_JOINTS):
        path = joint_path[j]
        limit = qddot_max[j]
        if weights.shape[0] == 0:  # row by row, each over its own span
            for k in range(n_rows):
                ratio = abs(row_second(path, first[k], index, c, k)) / limit
                worst[k] = ratio if ratio > worst[k] else worst[k]
            continue
        sums[:] = 0.0  # step by step across the rows: the same sums (a short row adds zeros)
        for t in range(weights.shape[0]):
            weight = weights[t]
            if contiguous:
                steps = path[first[0] + t : first[0] + t + n_rows]
                for k in range(n_rows):
                    sums[k] += weight[k] * steps[k]
            else:
                for k in range(n_rows):
                    sums[k] += weight[k] * path[first[k] + t]
        for k in range(n_rows):
            ratio = abs(sums[k]) / limit
            worst[k] = ratio if ratio > worst[k] else worst[k]


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def row_joint(rows, k, qddot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The joint of stencil row k's max_j |D_j| / a_j (the first at a tie).

    Each ratio as :func:`row_ratios` forms it: the same sums, in the same order (the same bits).
    """
    first, _, _, index, c, joint_path, _, _, _ = rows
    largest, joint = -1.0, 0
    for j in range(N_JOINTS):
        ratio = abs(row_second(joint_path[j], first[k], index, c, k)) / qddot_max[j]
        if ratio > largest:
            largest, joint = ratio, j
    return joint


@njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
def scan_row(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    i, limit, b, cq, sq, qs, moves, rows, waypoints, qddot_max, feed, acc_at, acc_joint,
    acc_speeds, acc_hint, alive, why, where, slowest,
):  # fmt: skip
    """Row i's mu_acc, the branch followed to the end; or the row left below ``limit``.

    Its steps (:func:`joint_steps`; ``moves`` from
    :func:`solver.kernels.spin_schedule.spin_moves` in free spin, zeros in fixed spin) and
    every stencil row's ratio (:func:`row_ratios`), then read in order: as soon as the least
    V_acc so far is below ``limit`` the row is left (:func:`solver.kernels.cell.prune`, its
    bound the least of that V_acc and its mu_path). A row read to the end has its mu_acc in
    ``feed``, min(mu_path, least V_acc) (the first waypoint and joint at a tie; where it binds
    in ``acc_at``, ``acc_joint`` and ``acc_hint``, V_acc per waypoint in ``acc_speeds``).
    Arrays as :func:`solver.kernels.accelerations.acc_work` and :func:`scan_work` make them;
    ``waypoints``: the blend stencil's. A row whose mu_path is below the stencil's floor
    (:func:`scan_work`) is not read: its mu_acc is its mu_path (no V_acc kept, and none is
    where it binds). Compiled without numba's reference counting (``_nrt=False``, as the
    numeric families' kernels; it allocates nothing): its loops keep numba from pruning the
    atomic increment and decrement of each array argument at every call.
    """
    keep = acc_speeds.shape[1] > 0
    if slowest[i] < rows[8] and not keep:  # below the floor: the speeds bind, as a scan finds
        feed[i] = slowest[i]
        acc_at[i], acc_joint[i], acc_hint[i] = -1, -1, -1
        return
    joint_steps(cq, sq, qs, b, moves, rows[5])
    row_ratios(rows, qddot_max)
    worst = rows[7]
    if keep:
        acc_speeds[i, :] = np.inf
    largest, at, left = -1.0, -1, False
    for k in range(waypoints.shape[0]):
        if keep:
            acc_speeds[i, waypoints[k]] = 1.0 / math.sqrt(worst[k])
        if worst[k] > largest:  # V_acc = 1 / sqrt(worst) below the least so far
            largest, at = worst[k], k
            if 1.0 / math.sqrt(largest) < limit:
                left = True
                break
    least = 1.0 / math.sqrt(largest) if at >= 0 else np.inf
    if left:
        prune(i, at, min(slowest[i], least), alive, why, where, slowest, acc_hint)
        return
    feed[i] = min(slowest[i], least)
    acc_at[i] = waypoints[at] if at >= 0 else -1
    acc_joint[i] = row_joint(rows, at, qddot_max) if at >= 0 else -1
    acc_hint[i] = at
