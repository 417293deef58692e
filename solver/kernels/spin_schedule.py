"""The free-spin kernel's spin schedule: the spin rates at the feed, and the spun path's tracking.

cam.md section 2, as :func:`solver.path.spin_schedule.spin_schedule`: at the feed mu_path the spin
rate nearest zero at each waypoint (:func:`spin_rate`), the joints moved by the spin, and that
joint path tracked again with the step test and the position limits (:func:`spun_failure`).
Called by :func:`solver.kernels.free_spin.free_cells`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import FEASIBLE, REASON_DISCONTINUOUS, REASON_JOINT_LIMITS
from solver.families.kernels import N_JOINTS
from solver.kernels.positions import first_outside, wrapped_step

_INSIDE = 1.0 - 1e-12  # as solver.core.two_variable_lp.spin_rate_nearest_zero
_HUGE = np.finfo(np.float64).max  # numpy.nan_to_num's value for inf


@njit(cache=True, error_model="numpy", nogil=True)
def spin_rate(qd, qs, b, w, qdot_max, feed):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`solver.core.two_variable_lp.spin_rate_nearest_zero` at one waypoint, at the feed."""
    inside = feed * _INSIDE
    low, high = -np.inf, np.inf
    for j in range(N_JOINTS):
        if qs[b, j, w] == 0.0:
            continue
        one = (-qdot_max[j] - inside * qd[b, j, w]) / qs[b, j, w]
        other = (qdot_max[j] - inside * qd[b, j, w]) / qs[b, j, w]
        low = max(low, min(one, other))
        high = min(high, max(one, other))
    sigma = (low + high) / 2 if low > high else min(max(0.0, low), high)
    return sigma if math.isfinite(sigma) else 0.0


@njit(cache=True, error_model="numpy", nogil=True)
def spin_moves(qd, qs, b, feed, length, qdot_max, moves):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch b's spin over each segment at the feed (m/s): moves[w] = sigma dt for the step to w.

    The spin rate nearest zero at the segment's first waypoint (:func:`spin_rate`) times its
    length (``length``: shape (W - 1,), m) over the feed; none (zeros) without a feed.
    ``moves``: shape (W,), out (moves[0] = 0).
    """
    moves[:] = 0.0
    if not feed > 0.0:
        return
    for w in range(1, moves.shape[0]):
        moves[w] = spin_rate(qd, qs, b, w - 1, qdot_max, feed) * length[w - 1] / feed


@njit(cache=True, error_model="numpy", nogil=True)
def spun_failure(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    path, qd, qs, b, feed, length, segment_checked, lower, upper, qdot_max, max_joint_step, spun
):
    """The reason code and waypoint where branch b's joint path, moved by the spin, fails.

    ``path`` (W, 6) is the branch's tracked joint path; it is overwritten by the spun one,
    q_i + sum_k<i sigma_k dt_k J^-1 [0; z_tool]_k, each pass restarting the sum
    (:func:`solver.path.spin_schedule.cumsum_within_passes`; a rapid moves no spin). That path
    is then tracked as :func:`solver.path.tracking.track` does: the step test, then the
    position limits; ``spun`` (W, 6), out, gets the tracked path (before its 2 pi copy is
    chosen). The spin's moves at the feed (:func:`spin_moves`), then :func:`moved_failure`.

    Returns:
        (FEASIBLE, -1) where it holds.
    """
    moves = np.empty(path.shape[0])
    spin_moves(qd, qs, b, feed, length, qdot_max, moves)
    return moved_failure(path, moves, qs, b, segment_checked, lower, upper, max_joint_step, spun)


@njit(cache=True, error_model="numpy", nogil=True)
def moved_failure(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    path, moves, qs, b, segment_checked, lower, upper, max_joint_step, spun
):
    """:func:`spun_failure` with the spin's moves made (:func:`spin_moves`, shape (W,)).

    A caller that needs the moves too (the acceleration scan) makes them once.
    """
    n_waypoints, dof = path.shape
    for j in range(dof):
        total, start = 0.0, 0.0
        for w in range(1, n_waypoints):
            step = moves[w] if segment_checked[w - 1] else 0.0
            total += step * qs[b, j, w - 1]
            if not segment_checked[w - 1]:
                start = total  # w starts a pass
            moved = total - start
            if math.isnan(moved):  # as numpy.nan_to_num
                moved = 0.0
            elif math.isinf(moved):
                moved = _HUGE if moved > 0.0 else -_HUGE
            path[w, j] += moved
    spun[0] = path[0]  # as track() forms it: the first angle plus the wrapped steps
    totals = np.zeros(dof)
    for w in range(1, n_waypoints):
        for j in range(dof):
            step = wrapped_step(path[w, j] - path[w - 1, j])
            if segment_checked[w - 1] and abs(step) > max_joint_step:
                return REASON_DISCONTINUOUS, w
            totals[j] += step
            spun[w, j] = path[0, j] + totals[j]
    at = first_outside(spun, lower, upper)
    if at < n_waypoints:
        return REASON_JOINT_LIMITS, at
    return FEASIBLE, -1


@njit(cache=True, error_model="numpy", nogil=True)
def no_spin_below(qd, b, lo, hi, feed, qdot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether :func:`spin_rate` is zero at every feed up to ``feed`` on waypoints lo..hi-1.

    Where the fixed-spin joint speeds (``qd``, J^-1 t_hat) stay within the limits at the feed,
    zero spin is inside every joint's interval and the rate nearest zero is zero; the test
    rounds as :func:`spin_rate` does, and a lower feed rounds to speeds no larger.
    """
    inside = feed * _INSIDE
    for w in range(lo, hi):
        for j in range(N_JOINTS):
            if not abs(inside * qd[b, j, w]) <= qdot_max[j]:
                return False
    return True
