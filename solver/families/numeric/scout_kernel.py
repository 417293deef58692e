"""Bounds for :mod:`solver.families.numeric.bounded_kernel`: V_max, the drop rule, scouting.

robots.md section 4, :mod:`solver.path.bounded`: V_max = 1 / max_j |(J^-1 t)_j| / qdot_max_j at
a waypoint (J at the tool point), with a followed waypoint's status; the rule that drops a slot
against the candidate; and the
scouting of a slot other than the candidate, rough damped least-squares steps a stride of
waypoints, solved exactly where its bound is decided. Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

from numba import njit

from solver.core.codes import OK, OK_MIRRORED, SINGULAR
from solver.families.numeric import ik_kernel
from solver.families.numeric.chain_kernel import drop_stale_cache, frames, jacobian_at
from solver.families.numeric.ik_kernel import _levenberg_marquardt, _pose_error, _singular
from solver.families.numeric.lu_kernel import damped_solve, det_negative, lu_solve, lu_solve_signed

drop_stale_cache(Path(__file__), Path(ik_kernel.__file__))

_TWO_PI = 2.0 * math.pi
NEAR_TOOL = 99.0
"""m: a tool point at most this far from the flange takes det J's sign from V_max's LU
(:func:`status_and_speed`); (1 + 99)^2 rcond leaves J_tool's sigma_min / sigma_max about 450 times
above the LU's backward error."""


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def v_max(chain, twist, tool, qdot_max, work, jac, rhs):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """V_max at the frames in ``work``: 1 / max_j |(J^-1 t)_j| / qdot_max_j; inf if J singular.

    J at the tool point (6, 6) into ``jac``, J^-1 t into ``rhs``; ``work``'s own J and J J^T
    (which the next waypoint's first step reuses) are left alone.
    """
    jacobian_at(chain[3], work[0], work[1], tool, jac)
    for i in range(6):
        rhs[i] = twist[i]
    if not lu_solve(jac, rhs):
        return math.inf
    ratio = 0.0
    for j in range(6):
        ratio = max(ratio, abs(rhs[j]) / qdot_max[j])
    return 1.0 / ratio if ratio > 0.0 else math.inf


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def status_and_speed(chain, rcond, at, qdot_max, work, spare):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``regular_status`` and :func:`v_max` (the same numbers) at the frames in ``work``.

    ``at``: the twist (6,) and the tool point (3,). The sign of det J comes from the LU of J
    at the tool point that V_max solves with, not from a second LU of J at the flange
    (``det_negative``): J_tool = [[I, -[d]x], [0, I]] J_flange (d from the flange to the tool
    point), a factor of determinant 1, so both have the sign of det J_flange wherever the
    status is not ``SINGULAR``. There sigma_min / sigma_max of J_flange is above ``rcond``
    (1e-7), so J_tool's is above rcond / (1 + |d|)^2, at least 1e-11 for |d| <= NEAR_TOOL,
    while the LU's backward error (about 6 * 2^5 * 1.1e-16 relative, the worst growth of
    six columns) is below 2.2e-14: the factored matrix has J_tool's sign. Farther tool points,
    or an exactly singular J_tool, take the flange's LU as before. ``spare[0]``, ``spare[1]``:
    J at the tool point and J^-1 t (as :func:`v_max` leaves them). Returns (status, V_max).
    """
    twist, tool = at
    singular = _singular(chain, rcond, work)  # J at the flange in work[6]
    jac, rhs = spare[0], spare[1]
    jacobian_at(chain[3], work[0], work[1], tool, jac)
    for i in range(6):
        rhs[i] = twist[i]
    solved, negative = lu_solve_signed(jac, rhs)
    speed = math.inf
    if solved:
        ratio = 0.0
        for j in range(6):
            ratio = max(ratio, abs(rhs[j]) / qdot_max[j])
        speed = 1.0 / ratio if ratio > 0.0 else math.inf
    if singular:
        return SINGULAR, speed
    pos = work[3]
    d0, d1, d2 = tool[0] - pos[0], tool[1] - pos[1], tool[2] - pos[2]
    if not solved or not d0 * d0 + d1 * d1 + d2 * d2 <= NEAR_TOOL * NEAR_TOOL:
        negative = det_negative(work[6], work[10])
    return (OK_MIRRORED if negative else OK), speed


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def hopeless(slot, bound, candidate, best, tie, margin):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether a slot whose mu_path is at most ``bound`` can be dropped against the candidate.

    ``best``: the candidate's mu_path as followed here. A slot after the candidate in order
    cannot take its place once bound (1 + margin) (1 - tie) <= best (1 - margin) (it could
    at most tie, and the first of a tie is taken); one before it once
    bound (1 + margin) < best (1 - margin) (1 - tie) (it cannot tie). ``margin`` covers the
    rounding between these V_max and the pipeline's.
    """
    if candidate < 0 or not best > 0.0 or math.isinf(best):
        return False
    high = bound * (1.0 + margin)
    low = best * (1.0 - margin)
    if slot > candidate:
        return high * (1.0 - tie) <= low
    return high < low * (1.0 - tie)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def within_limits(lower, upper, low, high):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether each joint's range [low, high] (n,) has a 2 pi copy within the limits (margin).

    Tracking's 2 pi k copy test (:func:`solver.path.tracking.track`) on a followed slot's range.
    """
    for j in range(len(low)):
        k_low = math.ceil((lower[j] - low[j]) / _TWO_PI + 1e-9)
        k_high = math.floor((upper[j] - high[j]) / _TWO_PI - 1e-9)
        if k_low > k_high:
            return False
    return True


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def fresh_jacobian(chain, work):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """J at the flange and J J^T of the frames in ``work``, as the next step takes them."""
    jacobian_at(chain[3], work[0], work[1], work[3], work[6])
    jac, normal = work[6], work[7]
    for i in range(6):
        for k in range(i + 1):
            total = 0.0
            for j in range(jac.shape[1]):
                total += jac[i, j] * jac[k, j]
            normal[i, k] = total
            normal[k, i] = total


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def rough_steps(chain, q, target_r, target_p, steps, residual, constants, work):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``steps`` damped least-squares steps of q towards the pose; whether |e|_inf < residual.

    ``work`` holds the frames, J and J J^T of q on entry and of the last iterate on return.
    False too where a step meets a singular system or a NaN.
    """
    scale, floor = constants[1], constants[2]
    n = len(q)
    jac, normal, error = work[6], work[7], work[8]
    for _ in range(steps):
        _pose_error(target_r, target_p, work)
        energy = 0.0
        for i in range(6):
            energy += error[i] * error[i]
        if math.isnan(energy):
            return False
        for i in range(6):
            normal[i, i] += scale * 0.5 * energy + floor
        if not damped_solve(normal, error):
            return False
        for j in range(n):
            q[j] += (
                jac[0, j] * error[0]
                + jac[1, j] * error[1]
                + jac[2, j] * error[2]
                + jac[3, j] * error[3]
                + jac[4, j] * error[4]
                + jac[5, j] * error[5]
            )
        frames(chain, q, work)
        fresh_jacobian(chain, work)
    _pose_error(target_r, target_p, work)
    largest = 0.0
    for i in range(6):
        largest = max(largest, abs(error[i]))
    return largest < residual  # False for a NaN too


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def scouted(chain, slot, path, limits, settings, constants, rules, work, spare):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """One slot scouted with rough strides from ``slot``; its exact bound, and if it is dropped.

    ``rules``: (tie, margin, slot index, candidate, best, rough steps, slack, stride, the
    candidate's slowest waypoint). The slot goes ``stride`` waypoints at a time, stopping at
    the candidate's slowest waypoint on its way, ``rough`` steps each; it is solved exactly
    at that waypoint, and wherever its rough V_max is within ``slack`` of what would drop it.
    A stride that leaves |e|_inf above ``residual`` or moves a joint more than ``motion`` is
    not trusted to stay on the branch: the scouting stops there. Returns (the least exact
    V_max, dropped); not dropped: to be followed exactly.
    """
    rotations, positions, twists, tools = path
    qdot_max, pure_rotation = limits[0], limits[1]
    track_iterations = int(settings[1])
    tie, margin, b, candidate, best, rough, slack, stride, slowest, residual, motion = rules
    before = spare[2]
    frames(chain, slot, work)
    fresh_jacobian(chain, work)
    least, w, last = math.inf, 0, len(positions) - 1
    while True:
        if pure_rotation[w]:
            least = 0.0
        else:
            speed = v_max(chain, twists[w], tools[w], qdot_max, work, spare[0], spare[1])
            near = hopeless(b, speed * (1.0 - slack), candidate, best, tie, margin)
            if near or w == slowest:
                if w > 0 and not _levenberg_marquardt(
                    chain,
                    slot,
                    rotations[w],
                    positions[w],
                    track_iterations,
                    None,
                    constants,
                    work,
                    True,
                    (0, 0.0),
                ):
                    return least, False
                exact = v_max(chain, twists[w], tools[w], qdot_max, work, spare[0], spare[1])
                least = min(least, exact)
                fresh_jacobian(chain, work)
        if hopeless(b, least, candidate, best, tie, margin):
            return least, True
        if w == last:
            return least, False
        step = min(w + stride, last)
        w = slowest if w < slowest < step else step
        for j in range(len(slot)):
            before[j] = slot[j]
        target_r, target_p = rotations[w], positions[w]
        if not rough_steps(chain, slot, target_r, target_p, rough, residual, constants, work):
            return least, False  # a stride too far to trust: followed exactly
        for j in range(len(slot)):
            if not abs(slot[j] - before[j]) <= motion:
                return least, False
