"""The map kernels' final-path step: mu_acc per branch, and its answer columns (motion.md s. 2).

With joint acceleration limits the numpy pipeline (:func:`solver.path.pipeline.run_chunk`)
bounds a constant feed along each feasible branch's final tracked joint path (in free spin,
the path along the spin schedule): mu_acc = min(mu_path, min_i V_acc,i), and the ``auto``
branch is the one with the highest mu_acc (:func:`solver.path.tracking.choose_branch`, ties
within ``ACC_TIE_RTOL`` to the first). The kernels do the same here, with the limit's hooks
(:mod:`solver.kernels.limits`), and prune the branches as without the limits
(:mod:`solver.kernels.acc_cells`): a branch is known either whole (its mu_acc, where it binds,
V_acc per waypoint: :func:`solver.kernels.acc_scan.scan_row`) or by a bound of its mu_acc, its
running minimum of V_max (mu_acc <= mu_path) or one stencil row's V_acc (:func:`probe_acc_rows`,
:func:`probe_free_acc_rows`), and is left once the bound is below its limit
(:func:`solver.kernels.cell.set_limits`). Branches of one shoulder share joints (a UR's
wrist_3 differs between them by pi, which no second difference sees): their V_acc there is
equal to the bit, as D is formed from the steps (:func:`solver.kernels.limits.step_stencil`).

Without acceleration limits the kernels get ``qddot_max`` of shape (0,) and skip all of this.

The functions called per branch (:func:`left_at_probes`, :func:`probe_acc_rows`,
:func:`probe_free_acc_rows`) are compiled without numba's reference counting (``_nrt=False``, as
the numeric families' kernels; they allocate nothing): it incremented and decremented each array
argument atomically at every call, and their loops keep numba from pruning the pairs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import FEASIBLE, OK
from solver.families.kernels import N_JOINTS, pose_block
from solver.kernels.cell import prune
from solver.kernels.limits import acceleration_at
from solver.kernels.positions import pair_step, wrapped_step
from solver.kernels.spin_schedule import no_spin_below, spin_rate


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def acc_work(n_branches, n_waypoints, keep_speeds):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Per branch: its mu_acc, where it binds, V_acc per waypoint, and where to probe it.

    Returns:
        feed, acc_at, acc_joint: shape (B,), mu_acc and its waypoint and joint (-1: none);
        acc_speeds: shape (B, W), or (B, 0) when not ``keep_speeds``; acc_hint: shape (B,),
        the stencil row where each branch's V_acc was least or left it (-1: none; kept from
        placement to placement); steps: shape (W, 6), one branch's joint steps; moves:
        shape (W,), its spin's moves (:func:`solver.kernels.spin_schedule.spin_moves`; zeros,
        none, in fixed spin).
    """
    feed = np.empty(n_branches)
    acc_at = np.empty(n_branches, dtype=np.int64)
    acc_joint = np.empty(n_branches, dtype=np.int64)
    acc_speeds = np.empty((n_branches, n_waypoints if keep_speeds else 0))
    acc_hint = np.full(n_branches, -1)
    steps = np.empty((n_waypoints, N_JOINTS))
    moves = np.zeros(n_waypoints)
    return feed, acc_at, acc_joint, acc_speeds, acc_hint, steps, moves


@njit(cache=True, error_model="numpy", nogil=True)
def write_acc(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    c, pick, reason, slowest, slowest_at, slowest_joint, feed, acc_at, acc_joint, acc_speeds,
    mu_acc, limited_by, acc_waypoint, acc_joint_out, v_acc,
):  # fmt: skip
    """Placement c's acceleration columns from its chosen branch row ``pick``.

    As :func:`solver.path.placements.columns_of_run`: mu_acc; what binds it (0 the speed
    limits, 1 the acceleration limits, -1 infeasible); its waypoint and joint (those of mu_path
    where the speed limits bind); V_acc along the path (NaN where infeasible).
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


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def spin_rate_of(slowest, free):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The feed a branch's spin schedule is taken at: its mu_path in free spin, else 0 (none)."""
    return slowest if free and slowest > 0.0 and math.isfinite(slowest) else 0.0


@njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
def left_at_probes(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    i, limit, probes, b, rate, cq, sq, qd, qs, length, qdot_max, index, c, qddot_max, steps,
    alive, why, where, slowest, acc_hint,
):  # fmt: skip
    """Whether row i, followed to the end, is left at one of the stencil rows ``probes``.

    Its V_acc there (:func:`spun_steps` at ``rate``, 0 in fixed spin) below ``limit`` leaves
    it (:func:`solver.kernels.cell.prune`, its bound the least of that V_acc and its mu_path).
    ``probes``: stencil rows, -1 for none (the best row's and the row's own ``acc_hint``).
    """
    for p in probes:
        if p < 0:
            continue
        start, span = index[p, 0], index[p, -1] - index[p, 0]
        spun_steps(cq, sq, qd, qs, b, start, start + span, rate, length, qdot_max, steps)
        worst, _ = acceleration_at(steps, start, index, c, p, qddot_max)
        speed = 1.0 / math.sqrt(worst)
        if speed < limit:
            prune(i, p, min(slowest[i], speed), alive, why, where, slowest, acc_hint)
            return True
    return False


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def probed_speed(i, k, b, cq, sq, status, index, c, qddot_max, steps):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Row i's V_acc at stencil row k from its pairs (no spin), -inf where it fails there.

    A branch not OK at a waypoint of the stencil fails there or before: no mu_acc.
    """
    start, span = index[k, 0], index[k, -1] - index[k, 0]
    for w in range(start, start + span + 1):
        if status[b, w] != OK:
            return -np.inf
    pair_steps(cq, sq, b, start, start + span, steps)
    worst, _ = acceleration_at(steps, start, index, c, k, qddot_max)
    return 1.0 / math.sqrt(worst)


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def probed_before(i, hints, probed, k):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether row i's hint ``hints[i]`` needs no probe of the rows left to follow.

    ``hints``: shape (B,), where each row was least or left (a stencil row, ``acc_hint``, or
    a waypoint, ``hint``). None (-1), the best row's ``k`` (probed already), or a row before i
    marked in ``probed`` (shape (B,), bool) was probed there: a second probe at the same place
    finds what the first did. (A row's hint changes only where it is left, to the place that
    left it, itself probed.)
    """
    here = hints[i]
    if here < 0 or here == k:
        return True
    for m in range(i):
        if probed[m] and hints[m] == here:
            return True
    return False


@njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
def probe_acc_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, limit, k, family, par, poses, branches, scratch, cq, sq, qd, status, need, alive,
    why, where, slowest, acc_hint, bound, index, c, qddot_max, steps,
):  # fmt: skip
    """Fixed spin: leave the rows in ``todo`` whose V_acc at stencil row k is below ``limit``.

    The stencil's waypoints solved for those rows (the family's pose kernel); V_acc from the
    steps of their pairs, the bits :func:`solver.kernels.acc_scan.scan_row` forms there. The
    others keep in ``bound`` the least bound seen (:func:`solver.kernels.cell.next_row`).
    """
    need[:] = False
    for i in range(branches.shape[0]):
        need[branches[i]] = need[branches[i]] or (todo[i] and alive[i])
    start, span = index[k, 0], index[k, -1] - index[k, 0]
    pose_block(family, par, poses, start, start + span + 1, need, scratch, cq, sq, status, qd)
    for i in range(branches.shape[0]):
        if not (todo[i] and alive[i]):
            continue
        speed = probed_speed(i, k, branches[i], cq, sq, status, index, c, qddot_max, steps)
        if speed < limit[i]:
            prune(i, k, speed, alive, why, where, slowest, acc_hint)
        else:
            bound[i] = min(bound[i], speed)


@njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
def probe_free_acc_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    todo, limit, k, family, par, poses, branches, qdot_max, scratch, cq, sq, qd, status, need,
    alive, why, where, slowest, acc_hint, bound, reach, index, c, qddot_max, steps,
):  # fmt: skip
    """Free spin: as :func:`probe_acc_rows`, for the rows whose spin is none at stencil row k.

    A row's spin schedule is taken at its mu_path, unknown until it is followed; ``reach``
    (the least V_max its probes saw) is at least that. Where even at ``reach`` the spin rate
    nearest zero is zero on every segment of the stencil
    (:func:`solver.kernels.spin_schedule.no_spin_below`), it is zero at the row's mu_path too,
    and V_acc there is that of its pairs, the bits :func:`solver.kernels.acc_scan.scan_row`
    forms; other rows are not
    probed here.
    """
    need[:] = False
    for i in range(branches.shape[0]):
        need[branches[i]] = need[branches[i]] or (todo[i] and alive[i] and reach[i] < np.inf)
    start, span = index[k, 0], index[k, -1] - index[k, 0]
    pose_block(family, par, poses, start, start + span + 1, need, scratch, cq, sq, status, qd)
    for i in range(branches.shape[0]):
        if not (todo[i] and alive[i] and need[branches[i]]):
            continue
        b = branches[i]
        speed = probed_speed(i, k, b, cq, sq, status, index, c, qddot_max, steps)
        if speed > -np.inf and not no_spin_below(qd, b, start, start + span, reach[i], qdot_max):
            continue
        if speed < limit[i]:
            prune(i, k, speed, alive, why, where, slowest, acc_hint)
        else:
            bound[i] = min(bound[i], speed)
