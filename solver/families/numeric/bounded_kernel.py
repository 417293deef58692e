"""A six-joint chain's branches followed best first, each dropped once it cannot be a map's pick.

The compiled half of :mod:`solver.path.bounded` (robots.md section 4): at each path, the slot
the previous path ended with as its candidate is followed first to the end, then every other
slot, in order; along each, V_max = 1 / max_j |(J^-1 t)_j| / qdot_max_j is computed at every
waypoint (J at the tool point), and its least value so far bounds the branch's mu_path. A slot
is dropped (its following stopped) once that bound shows it can neither tie with the
candidate nor beat it (the rules of :func:`solver.families.numeric.scout_kernel.hopeless`,
where the V_max and the scouting live too). A slot's solutions, status and loss are those of
:func:`solver.families.numeric.follow_kernel.follow_paths`, bit for bit: the same steps from the
same starts. Whether a drop was right is decided by the caller, from the pipeline's own
mu_path of the slots followed to the end. Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core.codes import OK_MIRRORED, SINGULAR, UNREACHABLE
from solver.families.numeric import ik_kernel, scout_kernel
from solver.families.numeric.chain_kernel import (
    drop_stale_cache,
    frames,
    workspace,
)
from solver.families.numeric.ik_kernel import _levenberg_marquardt, extrapolated
from solver.families.numeric.scout_kernel import (
    hopeless,
    scouted,
    status_and_speed,
    within_limits,
)

_TWO_PI = 2.0 * math.pi

drop_stale_cache(Path(__file__), Path(ik_kernel.__file__), Path(scout_kernel.__file__))


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def wrapped(value):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``(value + pi) % (2 pi) - pi``, the same bits, without the modulo where it is the identity.

    For 0 <= value + pi < 2 pi (most joint values) Python's float modulo returns its left side
    unchanged (fmod is exact and keeps the sign; a zero becomes +0, which ``- pi`` makes -pi
    either way); elsewhere it is taken. The modulo (a libm fmod, a division and a floor) was
    about 3 % of the UR5-as-URDF map.
    """
    shifted = value + math.pi
    if 0.0 <= shifted < _TWO_PI:
        return shifted - math.pi
    return shifted % _TWO_PI - math.pi


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _exact(chain, slot, path, limits, settings, constants, rules, work, spare, out):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """One slot followed exactly (``follow_paths``' steps) from its first solution ``slot``.

    ``path``: the path's rotations, positions, twists and tool points; ``limits``: qdot_max,
    the pure rotations, the joint limits and the joint step tracking calls a jump; ``rules``:
    (tie, margin, slot index, candidate, best); ``out``: q and status of this slot (6, W)
    and (W,). Returns (least V_max, its first waypoint, whether it cannot be the candidate:
    lost, singular, a step not below the jump or across a change of det J's sign, or no copy
    2 pi k within the limits (judged with a margin: tracking decides), dropped).
    """
    rotations, positions, twists, tools = path
    qdot_max, pure_rotation, lower, upper, max_step = limits
    q, status = out
    track_iterations, rcond = int(settings[1]), settings[3]
    tie, margin, b, candidate, best = rules
    revolute = chain[3]
    before, low, high = spare[2], spare[3], spare[4]
    frames(chain, slot, work)
    least, slowest, failed = math.inf, 0, False
    for j in range(len(slot)):
        low[j], high[j], before[j] = slot[j], slot[j], slot[j]
    for w in range(len(positions)):
        predicted = w > 0 and extrapolated(slot, q, w, revolute, settings[6])
        if w > 0 and not _levenberg_marquardt(
            chain,
            slot,
            rotations[w],
            positions[w],
            track_iterations,
            None,
            constants,
            work,
            not predicted,  # the frames, J and J J^T of q_(w-1), from _singular
            (0, 0.0),
        ):
            return least, slowest, True, False
        status[w], speed = status_and_speed(
            chain, rcond, (twists[w], tools[w]), qdot_max, work, spare
        )
        failed = failed or status[w] == SINGULAR
        # det J changed sign from the waypoint before: a singularity crossed (tracking's jump)
        failed = failed or (w > 0 and (status[w] == OK_MIRRORED) != (status[w - 1] == OK_MIRRORED))
        for j in range(len(slot)):
            value = slot[j]
            q[j, w] = wrapped(value) if revolute[j] else value
            failed = failed or not abs(value - before[j]) < max_step
            low[j], high[j], before[j] = min(low[j], value), max(high[j], value), value
        if pure_rotation[w]:
            speed = 0.0
        if speed < least:
            least, slowest = speed, w
        if hopeless(b, least, candidate, best, tie, margin):
            return least, slowest, failed, True
    failed = failed or not within_limits(lower, upper, low, high)
    return least, slowest, failed, False


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
    """Each path's slots followed from their first-waypoint solutions, hopeless ones dropped.

    The candidate (the previous path's, else the first slot) is followed exactly
    (``follow_paths``' steps). Once a path has a candidate, every other slot is first
    scouted (:func:`scouted`): ``rules[2]`` rough steps a stride of ``rules[4]`` waypoints,
    stopping at the candidate's slowest waypoint, its rough V_max only a sign of where to
    look; there, and wherever that is within ``rules[3]`` (relative) of what would drop it,
    the slot is solved exactly (the full steps from the rough iterate) and its exact V_max
    enters its bound. A scouted slot is dropped on
    such a bound; one that reaches the end, or whose exact solve fails, is followed again
    exactly from its first waypoint, after the others (its solutions and status are then
    follow_paths'). Without a candidate, slots are followed exactly.

    Args:
        chain: :meth:`SerialChain.packed`, six joints.
        current: shape (P, K, 6), the slots' solutions at each path's first waypoint
            (:func:`~solver.families.numeric.seed_kernel.seed_paths`), NaN without one; read only.
        rotations: shape (P, W, 3, 3), R_B_F* of every waypoint.
        positions: shape (P, W, 3), m in {B}.
        twists: shape (P, W, 6), t_hat in {B} at the tool point.
        tools: shape (P, W, 3), the tool point in {B}, m.
        qdot_max: shape (6,), rad/s.
        pure_rotation: shape (W,), bool: V_max is 0 there (the pipeline's rule).
        joint_limits: lower and upper (n,) and (max_joint_step,): a slot outside them (as
            tracking judges, with a margin) is not taken as the candidate.
        settings: as for :func:`~solver.families.numeric.seed_kernel.seed_paths`.
        constants: as for :func:`~solver.families.numeric.follow_kernel.follow_paths`.
        rules: (tie, margin) for :func:`hopeless`; rough steps a stride (0: every slot
            followed exactly); the slack of the rough V_max; the stride (waypoints); the
            residual and joint motion (rad or m) a trusted stride stays within.

    Returns:
        q: shape (6, K, P, W), wrapped, NaN where not followed or lost (dropped slots: left
        as followed); status: shape (K, P, W); bound: shape (K, P), the least exact V_max
        found (inf before any); dropped: shape (K, P), bool, the slots whose following was
        stopped.
    """
    n_paths, n_seeds, n = current.shape
    q = np.full((n, n_seeds, n_paths, positions.shape[1]), np.nan)
    status = np.full((n_seeds, n_paths, positions.shape[1]), UNREACHABLE)
    bound = np.full((n_seeds, n_paths), np.inf)
    dropped = np.zeros((n_seeds, n_paths), dtype=np.bool_)
    spare = (np.empty((6, n)), np.empty(6), np.empty(n), np.empty(n), np.empty(n))
    scratch = (np.empty(n), np.empty(2 * n_seeds, dtype=np.int64), np.empty(n_seeds))
    _follow_all(
        chain,
        current,
        (rotations, positions, twists, tools),
        (qdot_max, pure_rotation, joint_limits[0], joint_limits[1], joint_limits[2][0]),
        settings,
        constants,
        rules,
        (workspace(n), spare, scratch, np.zeros(n_seeds, dtype=np.int64)),
        (q, status, bound, dropped),
    )
    return q, status, bound, dropped


@njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _follow_all(chain, current, paths, limits, settings, constants, rules, buffers, out):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`follow_bounded`'s loop over the paths, into its preallocated ``out``.

    Compiled without numba's reference counting (``_nrt=False``: it allocates nothing), which
    the inlined helpers' tuples of arrays otherwise cost at every waypoint (atomic increments
    and decrements, about a sixth of the map's time); the same arithmetic, the same bits.
    ``paths``: rotations, positions, twists, tools; ``limits``: as :func:`_exact` takes them;
    ``buffers``: the chain's workspace, the spare arrays, (slot, order, clean) and slowest_of.
    """
    rotations, positions, twists, tools = paths
    q, status, bound, dropped = out
    work, spare, scratch, slowest_of = buffers
    slot, order, clean = scratch
    n_paths, n_seeds, n = current.shape
    tie, margin, rough, slack = rules[0], rules[1], int(rules[2]), rules[3]
    stride, residual, motion = int(rules[4]), rules[5], rules[6]
    lead = 0
    for p in range(n_paths):
        path = (rotations[p], positions[p], twists[p], tools[p])
        if math.isnan(current[p, lead, 0]):
            lead = 0
        order[0], size = lead, 1
        for b in range(n_seeds):
            if b != lead:
                order[size] = b
                size += 1
        candidate, best, slowest = -1, -math.inf, 0
        for b in range(n_seeds):  # the least V_max of each slot followed exactly and clean
            clean[b] = -math.inf
        k = 0
        while k < size:
            b = order[k]
            k += 1
            if math.isnan(current[p, b, 0]):
                continue
            for j in range(n):
                slot[j] = current[p, b, j]
            if k <= n_seeds and rough > 0 and candidate >= 0:
                scout = (
                    tie,
                    margin,
                    b,
                    candidate,
                    best,
                    rough,
                    slack,
                    stride,
                    slowest,
                    residual,
                    motion,
                )
                least, drop = scouted(
                    chain, slot, path, limits, settings, constants, scout, work, spare
                )
                bound[b, p] = least
                if drop:
                    dropped[b, p] = True
                else:  # followed exactly after the others
                    order[size] = b
                    size += 1
                continue
            least, at, failed, drop = _exact(
                chain,
                slot,
                path,
                limits,
                settings,
                constants,
                (tie, margin, b, candidate, best),
                work,
                spare,
                (q[:, b, p], status[b, p]),
            )
            bound[b, p] = least
            dropped[b, p] = drop
            if failed or drop:
                continue
            clean[b], slowest_of[b] = least, at
            top = -math.inf  # the candidate as the pick is taken: the first of the top's tie
            for other in range(n_seeds):
                top = max(top, clean[other])
            for other in range(n_seeds):
                if clean[other] >= top - tie * abs(top):
                    candidate, best, slowest = other, clean[other], slowest_of[other]
                    break
        if candidate >= 0:
            lead = candidate
