"""The map kernels' final-path step: mu_acc per branch, and its answer columns (motion.md s. 2).

With joint acceleration limits the numpy pipeline (:func:`solver.path.pipeline.run_chunk`)
bounds a constant feed along each feasible branch's final tracked joint path (in free spin,
the path along the spin schedule): mu_acc = min(mu_path, min_i V_acc,i), and the ``auto``
branch is the one with the highest mu_acc (:func:`solver.path.tracking.choose_branch`, ties
within ``ACC_TIE_RTOL``). The
kernels do the same here, with the limit's hook
(:func:`solver.kernels.limits.acceleration_bound`). Since mu_acc <= mu_path, a branch whose
mu_path is below the highest mu_acc found (and not tied with it) can be neither chosen nor
tied: the kernels take branches fastest first and stop there (:func:`next_fastest`), so a cell
forms the angles of only the branches that can matter.

Without acceleration limits the kernels get ``qddot_max`` of shape (0,) and skip all of this.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.core.codes import ACC_TIE_RTOL, FEASIBLE
from solver.kernels.limits import acceleration_bound


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def acc_work(n_branches, n_waypoints, keep_speeds):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Per branch: its index for the choice, where mu_acc binds, and V_acc per waypoint.

    The index is mu_acc, or mu_path where it was not computed; ``taken`` marks the branches
    whose mu_acc was.

    Returns:
        feed, acc_at, acc_joint, taken: shape (B,); acc_speeds: shape (B, W), or (B, 0) when
        not ``keep_speeds``.
    """
    feed = np.empty(n_branches)
    acc_at = np.empty(n_branches, dtype=np.int64)
    acc_joint = np.empty(n_branches, dtype=np.int64)
    taken = np.empty(n_branches, dtype=np.bool_)
    acc_speeds = np.empty((n_branches, n_waypoints if keep_speeds else 0))
    return feed, acc_at, acc_joint, taken, acc_speeds


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
def branch_mu_acc(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    i, path, slowest, index, weight, waypoints, qddot_max, feed, acc_at, acc_joint, acc_speeds,
    top,
):  # fmt: skip
    """mu_acc of branch row i along its final joint path (W, 6), kept in ``feed[i]``.

    :func:`solver.path.pipeline._final_path_bounds`: min(mu_path, the least V_acc); where
    V_acc binds (below mu_path), its waypoint and joint go to ``acc_at`` and ``acc_joint``.
    Where V_acc falls below ``top`` (the highest mu_acc so far) and is not tied with it, the
    branch cannot be chosen and the rest of its path is not looked at (its ``feed`` is then
    such a V_acc, low enough for the choice). Returns mu_acc.
    """
    row = acc_speeds[i] if acc_speeds.shape[1] else acc_speeds[0, :0]
    floor = top - ACC_TIE_RTOL * abs(top) if top > 0.0 and np.isfinite(top) else 0.0
    least, at, joint = acceleration_bound(path, index, weight, waypoints, qddot_max, row, floor)
    feed[i] = min(slowest[i], least)
    acc_at[i] = at
    acc_joint[i] = joint
    return feed[i]


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
