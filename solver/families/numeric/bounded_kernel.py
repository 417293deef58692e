"""A six-joint chain's branches followed best first, each dropped once it cannot be a map's pick.

The compiled half of :mod:`solver.path.bounded` (robots.md section 4): at each path, the slot
the previous path ended with as its candidate is followed first to the end, then every other
slot, in order; along each, V_max = 1 / max_j |(J^-1 t)_j| / qdot_max_j is computed at every
waypoint (J at the tool point), and its least value so far bounds the branch's mu_path. A slot
is dropped (its following stopped) once that bound shows it can neither tie with the
candidate nor beat it (the rules of :func:`_hopeless`). A slot's solutions, status and loss
are those of :func:`solver.families.numeric.ik_kernel.follow_paths`, bit for bit: the same
steps from the same starts. Whether a drop was right is decided by the caller, from the
pipeline's own mu_path of the slots followed to the end. Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.families.numeric import ik_kernel
from solver.families.numeric.chain_kernel import (
    drop_stale_cache,
    frames,
    jacobian_at,
    lu_solve,
    workspace,
)
from solver.families.numeric.ik_kernel import _levenberg_marquardt, _singular

_TWO_PI = 2.0 * math.pi

drop_stale_cache(Path(__file__), Path(ik_kernel.__file__))


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _v_max(chain, twist, tool, qdot_max, work, jac, rhs):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
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
def _hopeless(slot, bound, candidate, best, tie, margin):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
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
    settings,
    constants,
    rules,
):
    """Each path's slots followed from their first-waypoint solutions, hopeless ones dropped.

    Args:
        chain: :meth:`SerialChain.packed`, six joints.
        current: shape (P, K, 6), the slots' solutions at each path's first waypoint
            (:func:`~solver.families.numeric.ik_kernel.seed_paths`), NaN without one; read only.
        rotations: shape (P, W, 3, 3), R_B_F* of every waypoint.
        positions: shape (P, W, 3), m in {B}.
        twists: shape (P, W, 6), t_hat in {B} at the tool point.
        tools: shape (P, W, 3), the tool point in {B}, m.
        qdot_max: shape (6,), rad/s.
        pure_rotation: shape (W,), bool: V_max is 0 there (the pipeline's rule).
        settings: as for :func:`~solver.families.numeric.ik_kernel.seed_paths`.
        constants: as for :func:`~solver.families.numeric.ik_kernel.follow_paths`.
        rules: (tie, margin) for :func:`_hopeless`.

    Returns:
        q: shape (6, K, P, W), wrapped, NaN where not followed or lost; status: shape
        (K, P, W); bound: shape (K, P), the least V_max followed (inf before any); dropped:
        shape (K, P), bool, the slots whose following was stopped.
    """
    n_paths, n_seeds, n = current.shape
    n_waypoints = positions.shape[1]
    track_iterations, rcond = int(settings[1]), settings[3]
    tie, margin = rules[0], rules[1]
    revolute = chain[3]
    q = np.full((n, n_seeds, n_paths, n_waypoints), np.nan)
    status = np.full((n_seeds, n_paths, n_waypoints), UNREACHABLE)
    bound = np.full((n_seeds, n_paths), np.inf)
    dropped = np.zeros((n_seeds, n_paths), dtype=np.bool_)
    slot = np.empty(n)
    work = workspace(n)
    jac, rhs = np.empty((6, n)), np.empty(6)
    order = np.empty(n_seeds, dtype=np.int64)
    lead = 0
    for p in range(n_paths):
        if math.isnan(current[p, lead, 0]):
            lead = 0
        order[0] = lead
        k = 1
        for b in range(n_seeds):
            if b != lead:
                order[k] = b
                k += 1
        candidate, best = -1, -math.inf
        for b in order:
            if math.isnan(current[p, b, 0]):
                continue
            slot[:] = current[p, b]
            frames(chain, slot, work)
            least, singular, lost = math.inf, False, False
            for w in range(n_waypoints):
                if w > 0 and not _levenberg_marquardt(
                    chain,
                    slot,
                    rotations[p, w],
                    positions[p, w],
                    track_iterations,
                    None,
                    constants,
                    work,
                    True,  # the frames, J and J J^T of the waypoint before, from _singular
                    (0, 0.0),
                ):
                    lost = True
                    for j in range(n):
                        q[j, b, p, w] = np.nan
                    break
                if _singular(chain, rcond, work):
                    status[b, p, w] = SINGULAR
                    singular = True
                else:
                    status[b, p, w] = OK
                for j in range(n):
                    value = slot[j]
                    q[j, b, p, w] = (value + math.pi) % _TWO_PI - math.pi if revolute[j] else value
                speed = (
                    0.0
                    if pure_rotation[w]
                    else _v_max(chain, twists[p, w], tools[p, w], qdot_max, work, jac, rhs)
                )
                least = min(least, speed)
                if _hopeless(b, least, candidate, best, tie, margin):
                    dropped[b, p] = True
                    break
            bound[b, p] = least
            if lost or singular or dropped[b, p]:
                continue
            if candidate < 0 or least > best or (b < candidate and least >= best):
                candidate, best = b, least
        if candidate >= 0:
            lead = candidate
    return q, status, bound, dropped
