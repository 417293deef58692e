"""The compiled hooks of the limits on the path index: a speed bound and its binding joint.

The kernels' side of the limits seam (``spec/architecture.md`` section 3): at one waypoint of
one branch, the largest feed speed a limit allows and the joint that binds it. The map kernels
take every waypoint's bound from here and never compute one themselves. A final-path limit
(joint accelerations, ``motion.md`` section 2) has its hook here too: the bound at one waypoint
of a branch's final joint path, from the path's steps (:func:`step_stencil`,
:func:`acceleration_at`, called through :mod:`solver.kernels.accelerations`). The numpy
pipeline's limits are :mod:`solver.path.limits`; a hook equals its numpy limit number for
number (tests/solver/test_map_kernel.py, test_free_spin_kernel.py,
test_acceleration_hook.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.families.kernels import N_JOINTS


@njit(cache=True, error_model="numpy", nogil=True)
def joint_speed_bound(qd, b, w, inverse_qdot):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint speeds in fixed spin, the DTF: 1 / max_j |qd_j| / qdot_max_j, and its joint j.

    Sensors 2022 eq. (30) at waypoint w of branch b, qd = J^-1 t_hat (``qd``: shape (8, 6, W),
    rad per m; ``inverse_qdot``: shape (6,), s/rad, 1 / qdot_max). The first joint at a tie.
    """
    largest = -1.0
    limiting = 0
    for j in range(N_JOINTS):
        ratio = abs(qd[b, j, w]) * inverse_qdot[j]
        if ratio > largest:
            largest = ratio
            limiting = j
    return 1.0 / largest, limiting


@njit(cache=True, error_model="numpy", nogil=True)
def two_variable_speed(qd, qs, b, w, qdot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint speeds in free spin: the largest s with |s a_j + sigma b_j| <= qdot_max_j, and j.

    :func:`solver.core.two_variable_lp.two_variable_speed` at waypoint w of branch b
    (a = qd[b, :, w], J^-1 t_hat; b = qs[b, :, w], J^-1 [0; z_tool]; both shape (8, 6, W);
    ``qdot_max`` shape (6,), rad/s): the least pair bound, the first pair at a tie, of the pair
    the joint sigma helps less.
    """
    best = np.inf
    first, second = 0, 1
    for j in range(N_JOINTS):
        for k in range(j + 1, N_JOINTS):
            bound = (qdot_max[j] * abs(qs[b, k, w]) + qdot_max[k] * abs(qs[b, j, w])) / abs(
                qd[b, j, w] * qs[b, k, w] - qd[b, k, w] * qs[b, j, w]
            )
            if bound < best:  # a NaN bound (0 / 0) is no bound
                best = bound
                first, second = j, k
    help_first = abs(qs[b, first, w]) / qdot_max[first]
    help_second = abs(qs[b, second, w]) / qdot_max[second]
    return best, first if help_first <= help_second else second


@njit(cache=True, error_model="numpy", nogil=True)
def step_stencil(index, weight):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The blend stencil on the joint path's steps, by runs: D_k = sum_t c_k(t) steps[w0 + 1 + t].

    The weights of a row sum to 0, so D_k = sum_m weight[k, m] (q[index[k, m]] -
    q[index[k, 0]]), and each difference is a sum of the steps between: the step w has the
    weight of every stencil waypoint at or after it. D so formed sees neither the angles' size
    nor the weights' rounding (the steps are small), and two joint paths whose steps are equal
    or opposite have equal |D|, to the bit. The steps' weight is constant on four runs: run m
    (1 to 4) holds the steps t (from w0 = index[k, 0]) with index[k, m - 1] - w0 <= t <
    index[k, m] - w0, of weight weight[k, m] + ... + weight[k, 4] (summed in that order from
    0.0: the bits the steps' weights had when they were a (K, S) table, S the longest row's
    span; that table was two of 1.6 GB each for 20,000 waypoints whose blend spanned half the
    path, and a row's sum ran over S steps whatever its own span).

    Args:
        index: shape (K, 5), the stencil's waypoints (ascending along a row).
        weight: shape (K, 5), 1/m^2, their weights.

    Returns:
        c: shape (K, 4), 1/m^2, each row's runs' weights (:func:`row_second`).
    """
    c = np.zeros((index.shape[0], 4))
    for k in range(index.shape[0]):
        for run in range(1, 5):
            total = 0.0
            for m in range(run, 5):
                total += weight[k, m]
            c[k, run - 1] = total
    return c


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def row_second(steps, first, index, c, k):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """D of stencil row k on one joint: sum_t c_k(t) steps[first + t], t from 0 in order.

    ``steps``: one joint's steps, from ``first`` (the row's first step, the one after its
    waypoint index[k, 0]) on; ``index``, ``c``: the stencil and its runs
    (:func:`step_stencil`). Every hook forms D here: the same sums in the same order, the
    same bits.
    """
    second = 0.0
    base = index[k, 0]
    t = 0
    for run in range(4):
        end = index[k, run + 1] - base
        weight = c[k, run]
        while t < end:
            second += weight * steps[first + t]
            t += 1
    return second


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def acceleration_at(steps, start, index, c, k, qddot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint accelerations at a constant feed at stencil row k: max_j |D_j| / qddot_max_j, and j.

    :class:`solver.path.limits.JointAccelerationLimit` at one waypoint, from the joint path's
    steps (:func:`step_stencil`, :func:`row_second`); V_acc = 1 / sqrt of the ratio; the first
    joint at a tie.

    Args:
        steps: shape (W, 6), rad, steps[w] = q_w - q_(w-1), read from start + 1 to
            index[k, 4].
        start: index[k, 0] of the stencil.
        index: shape (K, 5), the stencil's waypoints.
        c: from :func:`step_stencil`.
        k: the stencil's row.
        qddot_max: shape (6,), rad/s^2.
    """
    worst = -1.0
    limiting = 0
    for j in range(steps.shape[1]):
        ratio = abs(row_second(steps[:, j], start + 1, index, c, k)) / qddot_max[j]
        if ratio > worst:
            worst = ratio
            limiting = j
    return worst, limiting
