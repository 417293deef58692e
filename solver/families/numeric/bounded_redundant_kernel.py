"""A seven-joint chain's branches followed best bound first, dropped once they cannot be the pick.

The compiled half of :mod:`solver.path.bounded` for redundant arms (robots.md sections 4 and 5).
A redundant branch's solution at a waypoint depends on every waypoint followed before it (the
self-motion drifts), so the six-joint scouting (rough strides,
:mod:`solver.families.numeric.scout_kernel`) would bound another path than the branch's: here
every slot is followed exactly, waypoint by waypoint, and V_max, the exact DTF LP of
:func:`solver.families.numeric.redundant_kernel.redundant_speeds` (J at the tool point, its QR,
the two-variable LP), is taken at every waypoint followed. Its least value so far bounds the
slot's mu_path.

At each path the slots are followed best bound first, one waypoint at a time: the slot whose
bound is highest (slots that may still pass tracking before those that cannot; the one followed
last, then the lowest index, at a tie) goes one waypoint further, again and again. A slot that
reaches the end clean (no singular waypoint, no step near the jump, a 2 pi copy within the joint
limits: tracking decides, this only guesses, with margins) may become the candidate, the first of
the highest among the clean ones, as :func:`solver.path.tracking.choose_branch` picks; a slot is
no longer followed once its bound shows that it can neither tie with the candidate nor beat it
(:func:`hopeless`), and the pass ends when no slot is left to follow. Following best first, no
slot is followed past the waypoint where its bound falls below the pick's mu_path, but for ties.
Every slot followed to the end has ``follow_paths``' solutions and status, bit for bit: the same
steps from the same starts. The pipeline decides whether the drops were right
(:func:`solver.path.bounded.pick_stands`). Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.families.numeric import ik_kernel, redundant_kernel, scout_kernel
from solver.families.numeric.chain_kernel import drop_stale_cache, frames, jacobian_at, workspace
from solver.families.numeric.ik_kernel import _levenberg_marquardt, _singular
from solver.families.numeric.redundant_kernel import _null_and_pseudo_inverse
from solver.families.numeric.scout_kernel import hopeless, within_limits

_TWO_PI = 2.0 * math.pi

drop_stale_cache(
    Path(__file__),
    Path(ik_kernel.__file__),
    Path(redundant_kernel.__file__),
    Path(scout_kernel.__file__),
)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def redundant_v_max(chain, twist, tool, qdot_max, work, spare):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """V_max at the frames in ``work`` as the pipeline takes it; inf where it cannot tell.

    The joint speeds per unit speed of :func:`redundant_kernel.redundant_speeds` (the same
    operations), then 1 / max_j |qd_j| / qdot_max_j as
    :class:`solver.path.limits.JointSpeedLimit` does. ``spare``: J at the tool point (6, 7),
    the QR's (7, 7), a and b (7,); ``work``'s own J and J J^T (the next step reuses them) are
    left alone. Where J nears rank loss (numpy decides there) or a number is not finite: inf,
    no bound.
    """
    jac, house, a, b = spare
    n = len(qdot_max)
    jacobian_at(chain[3], work[0], work[1], tool, jac)
    if not _null_and_pseudo_inverse(jac, twist, house, a, b):
        return math.inf
    best = np.inf
    for j in range(n):
        for k in range(j + 1, n):
            bound = (qdot_max[j] * abs(b[k]) + qdot_max[k] * abs(b[j])) / abs(
                a[j] * b[k] - a[k] * b[j]
            )
            if bound < best:
                best = bound
    inside = best * (1.0 - 1e-12)
    low, high = -np.inf, np.inf
    for j in range(n):
        if b[j] != 0.0:
            one = (-qdot_max[j] - inside * a[j]) / b[j]
            other = (qdot_max[j] - inside * a[j]) / b[j]
            low, high = max(low, min(one, other)), min(high, max(one, other))
    lam = (low + high) / 2 if low > high else min(max(0.0, low), high)
    lam = lam if math.isfinite(lam) else 0.0
    ratio = 0.0
    for j in range(n):
        share = abs((best * a[j] + lam * b[j]) / best) / qdot_max[j]
        if not share <= math.inf:  # NaN
            return math.inf
        ratio = max(ratio, share)
    return 1.0 / ratio if ratio > 0.0 else math.inf


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _next_slot(state, active, candidate, best, tie, margin):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The slot to follow next: the highest bound among those left; -1 when none is left.

    ``state``: next waypoint (K,), done (K,), failed (K,), least V_max (K,). Slots that may
    still pass tracking come first; at a tie the ``active`` slot, then the lowest index.
    """
    _, done, failed, least = state
    chosen, chosen_failed, chosen_least = -1, True, -math.inf
    for b in range(len(done)):
        if done[b] or hopeless(b, least[b], candidate, best, tie, margin):
            continue
        better = chosen < 0 or (chosen_failed and not failed[b])
        if not better and failed[b] == chosen_failed:
            better = least[b] > chosen_least or (least[b] == chosen_least and b == active)
        if better:
            chosen, chosen_failed, chosen_least = b, failed[b], least[b]
    return chosen


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _one_waypoint(chain, b, w, cached, path, limits, settings, constants, slots, work, spare, out):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Slot ``b`` followed to waypoint ``w`` (``follow_paths``' step); its V_max, or NaN: lost.

    ``slots``: the slots' solutions (K, n), unwrapped, and their tracking so far: the last
    solution, least and greatest value (K, n) each, and failed (K,) (a singular waypoint, a
    step not below the jump). ``cached``: ``work`` holds the frames, J and J J^T of slot b's
    solution at ``w - 1``. ``out``: q (n, K, W) and status (K, W) of this path.
    """
    rotations, positions, twists, tools = path
    qdot_max, pure_rotation, max_step = limits[0], limits[1], limits[4]
    current, before, low, high, failed = slots
    q, status = out
    track_iterations, rcond = int(settings[1]), settings[3]
    revolute = chain[3]
    slot = current[b]
    if w == 0:
        frames(chain, slot, work)
    elif not _levenberg_marquardt(
        chain,
        slot,
        rotations[w],
        positions[w],
        track_iterations,
        None,
        constants,
        work,
        cached,
        (0, 0.0),
    ):
        return math.nan  # lost: NaN and UNREACHABLE from here, as the arrays start
    if _singular(chain, rcond, work):
        status[b, w] = SINGULAR
        failed[b] = True
    else:
        status[b, w] = OK
    for j in range(len(slot)):
        value = slot[j]
        q[j, b, w] = (value + math.pi) % _TWO_PI - math.pi if revolute[j] else value
        if w == 0:
            low[b, j], high[b, j] = value, value
        elif not abs(value - before[b, j]) < max_step:
            failed[b] = True
        low[b, j], high[b, j] = min(low[b, j], value), max(high[b, j], value)
        before[b, j] = value
    if pure_rotation[w]:
        return 0.0
    return redundant_v_max(chain, twists[w], tools[w], qdot_max, work, spare)


@njit(cache=True, nogil=True, error_model="numpy")
def follow_bounded(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    chain,
    current,
    rotations,
    positions,
    twists,
    tools,
    qdot_max,
    pure_rotation,
    joint_limits,
    settings,
    constants,
    rules,
):
    """Each path's slots followed from their first-waypoint solutions, best bound first.

    Args:
        chain: :meth:`SerialChain.packed`, seven joints.
        current: shape (P, K, 7), the slots' solutions at each path's first waypoint
            (:func:`~solver.families.numeric.seed_kernel.seed_paths`), NaN without one; read only.
        rotations: shape (P, W, 3, 3), R_B_F* of every waypoint.
        positions: shape (P, W, 3), m in {B}.
        twists: shape (P, W, 6), t_hat in {B} at the tool point.
        tools: shape (P, W, 3), the tool point in {B}, m.
        qdot_max: shape (7,), rad/s.
        pure_rotation: shape (W,), bool: V_max is 0 there (the pipeline's rule).
        joint_limits: lower and upper (7,) and (max_joint_step,): a slot outside them (as
            tracking judges, with a margin) is not taken as the candidate.
        settings: as for :func:`~solver.families.numeric.seed_kernel.seed_paths`.
        constants: as for :func:`~solver.families.numeric.follow_kernel.follow_paths`.
        rules: (tie, margin) for :func:`hopeless` (the rest, the six-joint scouting's, unused).

    Returns:
        q: shape (7, K, P, W), wrapped, NaN where not followed or lost (dropped slots: left
        as followed); status: shape (K, P, W); bound: shape (K, P), the least V_max followed
        times (1 + margin), an upper bound of the pipeline's mu_path of the slot (inf before
        any); dropped: shape (K, P), bool, the slots not followed to the end.
    """
    n_paths, n_seeds, n = current.shape
    n_waypoints = positions.shape[1]
    tie, margin = rules[0], rules[1]
    q = np.full((n, n_seeds, n_paths, n_waypoints), np.nan)
    status = np.full((n_seeds, n_paths, n_waypoints), UNREACHABLE)
    bound = np.full((n_seeds, n_paths), np.inf)
    dropped = np.zeros((n_seeds, n_paths), dtype=np.bool_)
    work = workspace(n)
    spare = (np.empty((6, n)), np.empty((7, 7)), np.empty(n), np.empty(n))
    limits = (qdot_max, pure_rotation, joint_limits[0], joint_limits[1], joint_limits[2][0])
    solution, before = np.empty((n_seeds, n)), np.empty((n_seeds, n))
    low, high = np.empty((n_seeds, n)), np.empty((n_seeds, n))
    following = np.zeros(n_seeds, dtype=np.int64)
    done, failed = np.zeros(n_seeds, dtype=np.bool_), np.zeros(n_seeds, dtype=np.bool_)
    least, clean = np.empty(n_seeds), np.empty(n_seeds)
    slots = (solution, before, low, high, failed)
    state = (following, done, failed, least)
    for p in range(n_paths):
        path = (rotations[p], positions[p], twists[p], tools[p])
        out = (q[:, :, p], status[:, p])
        for b in range(n_seeds):
            solution[b] = current[p, b]
            following[b], failed[b], least[b], clean[b] = 0, False, math.inf, -math.inf
            done[b] = math.isnan(current[p, b, 0])
        candidate, best, active = -1, -math.inf, -1
        while True:
            b = _next_slot(state, active, candidate, best, tie, margin)
            if b < 0:
                break
            w = following[b]
            cached = b == active
            active = b
            speed = _one_waypoint(
                chain, b, w, cached, path, limits, settings, constants, slots, work, spare, out
            )
            if math.isnan(speed):  # lost: followed as far as it goes
                done[b], failed[b] = True, True
                continue
            least[b] = min(least[b], speed)
            following[b] = w + 1
            if w + 1 < n_waypoints:
                continue
            done[b] = True
            failed[b] = failed[b] or not within_limits(limits[2], limits[3], low[b], high[b])
            if failed[b]:
                continue
            clean[b] = least[b]
            top = -math.inf  # the candidate as the pick is taken: the first of the top's tie
            for other in range(n_seeds):
                top = max(top, clean[other])
            for other in range(n_seeds):
                if clean[other] >= top - tie * abs(top):
                    candidate, best = other, clean[other]
                    break
        for b in range(n_seeds):
            bound[b, p] = least[b] * (1.0 + margin)
            dropped[b, p] = not done[b]
    return q, status, bound, dropped
