"""The numeric family's compiled IK: damped least squares, seeding and following, batched.

The compiled twin of :mod:`solver.families.numeric.ik` (``solve``, ``distinct``,
``is_singular``) and of :class:`~solver.families.numeric.family.NumericFamily`'s seeding and
following (robots.md section 4), one problem at a time on the compiled chain
(:mod:`solver.families.numeric.chain_kernel`): the same algorithm, constants and decisions; the
numpy code is the reference the tests hold it to (the solutions and the maps, cell by cell).
Every function releases the GIL (``nogil``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core.codes import OK, OK_MIRRORED, SINGULAR, UNREACHABLE
from solver.families.numeric.chain_kernel import (
    det_negative,
    drop_stale_cache,
    frames,
    jacobian_at,
    lu_solve,
    workspace,
)

_TWO_PI = 2.0 * math.pi


drop_stale_cache(Path(__file__))


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _pose_error(target_r, target_p, work):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.pose_error`` at the flange in ``work``: e = [p* - p; log(R* R^T)] into work[8]."""
    rot, pos, error, m = work[2], work[3], work[8], work[9]
    for i in range(3):
        error[i] = target_p[i] - pos[i]
        for k in range(3):
            m[i, k] = (
                target_r[i, 0] * rot[k, 0] + target_r[i, 1] * rot[k, 1] + target_r[i, 2] * rot[k, 2]
            )
    s0 = 0.5 * (m[2, 1] - m[1, 2])
    s1 = 0.5 * (m[0, 2] - m[2, 0])
    s2 = 0.5 * (m[1, 0] - m[0, 1])
    sin = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    cos = 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0)
    angle = math.atan2(sin, cos)
    factor = angle / sin if sin > 1e-300 else 1.0
    error[3], error[4], error[5] = factor * s0, factor * s1, factor * s2
    if cos < -0.9:  # ik.rotation_log: the axis from the symmetric part near pi
        c = 0
        for k in range(1, 3):
            if m[k, k] - cos > m[c, c] - cos:
                c = k
        v0 = 0.5 * (m[0, c] + m[c, 0]) - (cos if c == 0 else 0.0)
        v1 = 0.5 * (m[1, c] + m[c, 1]) - (cos if c == 1 else 0.0)
        v2 = 0.5 * (m[2, c] + m[c, 2]) - (cos if c == 2 else 0.0)
        norm = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
        v0, v1, v2 = v0 / norm, v1 / norm, v2 / norm
        turn = (-1.0 if v0 * s0 + v1 * s1 + v2 * s2 < 0.0 else 1.0) * angle
        error[3], error[4], error[5] = turn * v0, turn * v1, turn * v2


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _normal(jac, normal):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """J J^T of jac (6, n) into normal (6, 6), the lower triangle summed and mirrored."""
    n = jac.shape[1]
    for i in range(6):
        for k in range(i + 1):
            total = 0.0
            for j in range(n):
                total += jac[i, j] * jac[k, j]
            normal[i, k] = total
            normal[k, i] = total


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _levenberg_marquardt(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    chain, q, target_r, target_p, iterations, box, constants, work, cached, stall
):
    """``ik.solve`` for one problem: iterate q (n,) in place; True when converged.

    ``box``: None, or (lower, upper) that every iterate is clipped into. ``constants``:
    ik.TOLERANCE, ik.DAMPING_SCALE, ik.DAMPING_FLOOR. ``cached``: ``work`` already holds the
    frames of q, its Jacobian at the flange and J J^T (as :func:`_singular` leaves them), so the
    first step takes them from there: the same numbers, one chain evaluation fewer. ``stall``:
    (steps, ratio), give up (False) at every ``steps``-th step where |e|_inf is above ``ratio``
    times what it was ``steps`` steps before (``ik.solve``'s ``stall``); steps 0: never. On
    return ``work`` holds the frames of the last iterate (:func:`chain_kernel.frames`).
    """
    tolerance, scale, floor = constants[0], constants[1], constants[2]
    stall_steps, stall_ratio = stall
    checkpoint = math.inf
    n = len(q)
    jac, normal, error = work[6], work[7], work[8]
    for step in range(iterations + 1):
        reuse = cached and step == 0
        if not reuse:
            frames(chain, q, work)
        _pose_error(target_r, target_p, work)
        largest, finite, energy = 0.0, True, 0.0
        for i in range(6):
            largest = max(largest, abs(error[i]))
            finite = finite and not math.isnan(error[i])
            energy += error[i] * error[i]
        if not finite or largest < tolerance:  # a NaN error stops a row in numpy too
            return True
        if step == iterations:
            return False
        if stall_steps > 0 and step % stall_steps == 0:
            if largest > stall_ratio * checkpoint:
                return False
            checkpoint = largest
        damping = scale * 0.5 * energy + floor
        if not reuse:
            jacobian_at(chain[3], work[0], work[1], work[3], jac)
            _normal(jac, normal)
        for i in range(6):
            normal[i, i] += damping
        if not lu_solve(normal, error):
            return False
        for j in range(n):
            moved = q[j]
            moved += (
                jac[0, j] * error[0]
                + jac[1, j] * error[1]
                + jac[2, j] * error[2]
                + jac[3, j] * error[3]
                + jac[4, j] * error[4]
                + jac[5, j] * error[5]
            )
            if box is not None:
                moved = min(max(moved, box[0][j]), box[1][j])
            q[j] = moved
    return False


@njit(cache=True, nogil=True, error_model="numpy")
def solve_rows(chain, start, target_r, target_p, iterations, box, constants, stall=(0, 0.0)):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.solve`` over M problems: q (M, n), the last iterates, and converged (M,), bool.

    Args:
        chain: :meth:`SerialChain.packed`.
        start: shape (M, n), rad.
        target_r: shape (M, 3, 3), R_B_F*.
        target_p: shape (M, 3), m in {B}.
        iterations: the most steps any problem takes.
        box: None, or (lower, upper), each (n,), the box every iterate is clipped into.
        constants: as for :func:`_levenberg_marquardt`.
        stall: (steps, ratio), as ``ik.solve``'s ``stall``; steps 0: never given up early.
    """
    q = start.copy()
    converged = np.zeros(len(q), dtype=np.bool_)
    work = workspace(q.shape[1])
    for m in range(len(q)):
        converged[m] = _levenberg_marquardt(
            chain, q[m], target_r[m], target_p[m], iterations, box, constants, work, False, stall
        )
    return q, converged


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _wrapped_distance(a, b, revolute):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.joint_distance`` of two configurations (n,): revolute differences wrapped."""
    total = 0.0
    for j in range(len(a)):
        d = a[j] - b[j]
        if revolute[j]:
            d = (d + math.pi) % _TWO_PI - math.pi
        total += d * d
    return math.sqrt(total)


@njit("boolean(float64[:, ::1], float64)", cache=True, nogil=True, error_model="numpy")
def _eigen_singular(normal, rcond):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """sigma_min / sigma_max below ``rcond`` from the eigenvalues of J J^T (``normal``), as numpy.

    Not inlined, and compiled at import for its one signature (so with numba's runtime,
    whatever calls it): kernels that take :func:`_singular` in may then be compiled without
    reference counting (``_nrt=False``), which only this call's allocation needs.
    """
    squares = np.linalg.eigvalsh(normal)
    return squares[0] < rcond * rcond * squares[-1]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _singular(chain, rcond, work):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.is_singular`` at the frames in ``work``: sigma_min / sigma_max of J below ``rcond``.

    A Cholesky factor of J J^T - rcond^2 trace(J J^T) I proves sigma_min^2 above rcond^2
    sigma_max^2 (trace >= sigma_max^2) without eigenvalues; only where it fails are the
    eigenvalues computed, as numpy does.
    """
    jac, normal, factor = work[6], work[7], work[10]
    jacobian_at(chain[3], work[0], work[1], work[3], jac)
    _normal(jac, normal)
    trace = 0.0
    for i in range(6):
        trace += normal[i, i]
    shift = rcond * rcond * trace
    for j in range(6):  # Cholesky of normal - shift I, lower triangle
        s = normal[j, j] - shift
        for k in range(j):
            s -= factor[j, k] * factor[j, k]
        if not s > 0.0:
            return _eigen_singular(normal, rcond)
        d = math.sqrt(s)
        factor[j, j] = d
        for i in range(j + 1, 6):
            t = normal[i, j]
            for k in range(j):
                t -= factor[i, k] * factor[j, k]
            factor[i, j] = t / d
    return False


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def regular_status(chain, rcond, work):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.regular_status`` at the frames in ``work``: SINGULAR, else OK or OK_MIRRORED.

    After :func:`_singular` (which leaves J at the flange in ``work[6]``), a six-joint chain's
    sign of det J by LU in ``work[10]`` (the Cholesky factor, free again).
    """
    if _singular(chain, rcond, work):
        return SINGULAR
    if len(chain[3]) == 6 and det_negative(work[6], work[10]):
        return OK_MIRRORED
    return OK


@njit(cache=True, nogil=True, error_model="numpy")
def seed_paths(chain, seeds, box, rotations, positions, settings, constants):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The distinct solutions at each path's first pose, from every seed, within the joint box.

    The distinct solutions (``ik.distinct``: wrapped joint distance above ``settings[2]`` from
    every earlier kept one) fill the slots in seed order.

    Args:
        chain: :meth:`SerialChain.packed`.
        seeds: shape (K, n), the starts.
        box: (lower, upper), each (n,), the joint box.
        rotations: shape (P, 3, 3), R_B_F* of each path's first waypoint.
        positions: shape (P, 3), m in {B}.
        settings: ik.SEED_ITERATIONS, ik.TRACK_ITERATIONS, ik.DISTINCT, ik.SINGULAR_RCOND,
            ik.STALL_STEPS, ik.STALL_RATIO.
        constants: as for :func:`_levenberg_marquardt`.

    Returns:
        found: shape (P, K, n), rad, unwrapped, NaN in the slots after the solutions found;
        count: shape (P,), the distinct solutions found.
    """
    n_seeds, n = seeds.shape
    n_paths = positions.shape[0]
    found = np.full((n_paths, n_seeds, n), np.nan)
    count = np.zeros(n_paths, dtype=np.int64)
    first = (
        np.empty((n_seeds, n, 3)),
        np.empty((n_seeds, n, 3)),
        np.empty((n_seeds, 3, 3)),
        np.empty((n_seeds, 3)),
        np.empty((n_seeds, 6, n)),
        np.empty((n_seeds, 6, 6)),
    )
    _seed_all(
        chain,
        seeds,
        box,
        (rotations, positions),
        settings,
        constants,
        (workspace(n), np.empty(n), first),
        (found, count),
    )
    return found, count


@njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _seed_all(chain, seeds, box, poses, settings, constants, buffers, out):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`seed_paths`' loop into its preallocated ``out`` (found, count).

    Compiled without numba's reference counting (``_nrt=False``: it allocates nothing), which
    the inlined helpers' tuples of arrays otherwise cost at every step (atomic increments and
    decrements); the same arithmetic, the same bits. ``poses``: rotations and positions;
    ``buffers``: the chain's workspace, the iterate (n,), and ``first``: each seed's frames (axes
    (K, n, 3), origins (K, n, 3), rotation (K, 3, 3), position (K, 3)), its Jacobian at the
    flange (K, 6, n) and J J^T (K, 6, 6). A seed's frames do not depend on the pose sought, so
    they are computed once for all the paths and copied into the workspace before each
    solve's first step (``cached``): the numbers the step would compute, not computed again.
    """
    rotations, positions = poses
    found, count = out
    work, current, first = buffers
    n_seeds, n = seeds.shape
    seed_iterations, apart = int(settings[0]), settings[2]
    stall = (int(settings[4]), settings[5])
    revolute = chain[3]
    for k in range(n_seeds):
        frames(chain, seeds[k], work)
        jacobian_at(revolute, work[0], work[1], work[3], work[6])
        _normal(work[6], work[7])
        _copy_frames(work, first, k, True)
    for p in range(positions.shape[0]):
        kept = 0
        for k in range(n_seeds):
            for j in range(n):
                current[j] = seeds[k, j]
            _copy_frames(work, first, k, False)
            if not _levenberg_marquardt(
                chain,
                current,
                rotations[p],
                positions[p],
                seed_iterations,
                box,
                constants,
                work,
                True,  # the seed's frames, J and J J^T, copied in
                stall,
            ):
                continue
            new = True
            for other in range(kept):
                if _wrapped_distance(found[p, other], current, revolute) <= apart:
                    new = False
                    break
            if new:
                for j in range(n):
                    found[p, kept, j] = current[j]
                kept += 1
        count[p] = kept


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _copy_frames(work, first, k, into_first):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Seed k's frames, J and J J^T between the workspace and ``first`` (:func:`_seed_all`).

    ``into_first``: from the workspace into row k of ``first``; else from there into it.
    """
    axes, origins, rot, pos, jac, normal = first
    for j in range(axes.shape[1]):
        for i in range(3):
            if into_first:
                axes[k, j, i], origins[k, j, i] = work[0][j, i], work[1][j, i]
            else:
                work[0][j, i], work[1][j, i] = axes[k, j, i], origins[k, j, i]
    for i in range(3):
        if into_first:
            pos[k, i] = work[3][i]
        else:
            work[3][i] = pos[k, i]
        for c in range(3):
            if into_first:
                rot[k, i, c] = work[2][i, c]
            else:
                work[2][i, c] = rot[k, i, c]
    for i in range(6):
        for c in range(jac.shape[2]):
            if into_first:
                jac[k, i, c] = work[6][i, c]
            else:
                work[6][i, c] = jac[k, i, c]
        for c in range(6):
            if into_first:
                normal[k, i, c] = work[7][i, c]
            else:
                work[7][i, c] = normal[k, i, c]


@njit(cache=True, nogil=True, error_model="numpy")
def _follow(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    chain,
    slot,
    rotations,
    positions,
    first,
    last,
    skip_first,
    track_iterations,
    rcond,
    revolute,
    constants,
    work,
    q,
    status,
    b,
    p,
):
    """One slot followed over waypoints ``first`` to ``last - 1`` of its path, into q and status.

    ``slot`` holds its solution at the waypoint before ``first``, or at ``first`` itself with
    ``skip_first`` (the path's first waypoint: the seed's solution, not solved again). Lost
    where a waypoint does not converge: ``slot`` NaN, and NaN / ``UNREACHABLE`` from there to
    ``last``. The serving loops of :func:`follow_paths` and :func:`follow_ranges`.
    """
    n = slot.shape[0]
    if skip_first:
        frames(chain, slot, work)
    for w in range(first, last):
        if not (skip_first and w == first) and not _levenberg_marquardt(
            chain,
            slot,
            rotations[w],
            positions[w],
            track_iterations,
            None,
            constants,
            work,
            w > first,  # the frames, J and J J^T of the waypoint before, from _singular
            (0, 0.0),
        ):
            slot[:] = np.nan
            for rest in range(w, last):
                status[b, p, rest] = UNREACHABLE
                for j in range(n):
                    q[j, b, p, rest] = np.nan
            return
        status[b, p, w] = regular_status(chain, rcond, work)
        for j in range(n):
            value = slot[j]
            q[j, b, p, w] = (value + math.pi) % _TWO_PI - math.pi if revolute[j] else value


@njit(cache=True, nogil=True, error_model="numpy")
def follow_paths(chain, current, rotations, positions, solve_first, settings, constants):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Each slot followed along one piece of its path, from its solution before the piece.

    A slot is followed to each next waypoint from its solution at the previous one, without the
    joint box, until it does not converge; it is then lost (NaN from there, and in every later
    piece). A path cut in pieces gives the same bits as the whole path in one piece.

    Args:
        chain: :meth:`SerialChain.packed`.
        current: shape (P, K, n), rad, unwrapped, in and out: each slot's solution at the
            waypoint before the piece (``solve_first``) or at the piece's first waypoint (the
            path's first piece, from :func:`seed_paths`); NaN for a slot without one. On return,
            its solution at the piece's last waypoint, NaN where it was lost.
        rotations: shape (P, W, 3, 3), R_B_F* of the piece's waypoints.
        positions: shape (P, W, 3), m in {B}.
        solve_first: whether the piece's first waypoint is solved (every piece but the first).
        settings: as for :func:`seed_paths`.
        constants: as for :func:`_levenberg_marquardt`.

    Returns:
        q: shape (n, K, P, W), revolute joints wrapped to [-pi, pi), NaN where a slot has no
        solution; status: shape (K, P, W), ``OK``, ``SINGULAR`` or ``UNREACHABLE``.
    """
    n_paths, n_seeds, n = current.shape
    n_waypoints = positions.shape[1]
    track_iterations, rcond = int(settings[1]), settings[3]
    revolute = chain[3]
    q = np.full((n, n_seeds, n_paths, n_waypoints), np.nan)
    status = np.full((n_seeds, n_paths, n_waypoints), UNREACHABLE)
    slot = np.empty(n)
    work = workspace(n)
    for p in range(n_paths):
        for b in range(n_seeds):
            if math.isnan(current[p, b, 0]):
                continue
            slot[:] = current[p, b]
            _follow(
                chain,
                slot,
                rotations[p],
                positions[p],
                np.int64(0),  # not a literal 0: follow_ranges' signature, compiled once
                n_waypoints,
                not solve_first,
                track_iterations,
                rcond,
                revolute,
                constants,
                work,
                q,
                status,
                b,
                p,
            )
            current[p, b] = slot
    return q, status


@njit(cache=True, nogil=True, error_model="numpy")
def follow_ranges(chain, current, rotations, positions, start, stop, out, settings, constants):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Each slot followed from its own waypoint ``start`` to before ``stop``, into q and status.

    :func:`follow_paths` with a piece per slot: the same decisions and numbers, a slot's
    waypoints solved as they would be in any pieces (the first piece's first waypoint is the
    seed's solution, not solved again).

    Args:
        chain: :meth:`SerialChain.packed`.
        current: shape (P, K, n), in and out: each slot's solution at waypoint ``start - 1``
            (at waypoint 0 where ``start`` is 0); on return at ``stop - 1``, NaN where lost.
        rotations: shape (P, W, 3, 3), R_B_F* of every waypoint of the paths.
        positions: shape (P, W, 3), m in {B}.
        start: shape (K, P), the first waypoint of each slot's piece.
        stop: shape (K, P), the waypoint after its last; a slot with ``stop <= start``, or a
            NaN solution, is not followed.
        out: q (n, K, P, W), written with the pieces' solutions, wrapped (left alone
            elsewhere), and status (K, P, W), their statuses (``UNREACHABLE`` once lost).
        settings: as for :func:`seed_paths`.
        constants: as for :func:`_levenberg_marquardt`.
    """
    n_paths, n_seeds, n = current.shape
    q, status = out
    track_iterations, rcond = int(settings[1]), settings[3]
    revolute = chain[3]
    slot = np.empty(n)
    work = workspace(n)
    for p in range(n_paths):
        for b in range(n_seeds):
            first, last = start[b, p], stop[b, p]
            if last <= first or math.isnan(current[p, b, 0]):
                continue
            slot[:] = current[p, b]
            _follow(
                chain,
                slot,
                rotations[p],
                positions[p],
                first,
                last,
                first == 0,
                track_iterations,
                rcond,
                revolute,
                constants,
                work,
                q,
                status,
                b,
                p,
            )
            current[p, b] = slot
