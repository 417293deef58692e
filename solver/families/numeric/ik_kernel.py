"""The numeric family's compiled IK step: damped least squares and the singularity test.

The compiled twin of :mod:`solver.families.numeric.ik` (``solve``, ``is_singular``,
``regular_status``), one problem at a time on the compiled chain
(:mod:`solver.families.numeric.chain_kernel`): the same algorithm, constants and decisions; the
numpy code is the reference the tests hold it to (the solutions and the maps, cell by cell).
The seeding (:mod:`solver.families.numeric.seed_kernel`) and the following
(:mod:`solver.families.numeric.follow_kernel`) of the family's paths take these in. Every
function releases the GIL (``nogil``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core.codes import OK, OK_MIRRORED, SINGULAR
from solver.families.numeric.chain_kernel import drop_stale_cache, frames, jacobian_at, workspace
from solver.families.numeric.lu_kernel import damped_solve, det_negative

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
    """J J^T of jac (6, n) into normal (6, 6), the lower triangle summed and mirrored.

    Six joints take a copy whose n is a constant, which the compiler unrolls (the same sums
    in the same order).
    """
    if jac.shape[1] == 6:
        _normal_of(jac, normal, 6)
    else:
        _normal_of(jac, normal, jac.shape[1])


@njit(cache=True, nogil=True, error_model="numpy")
def _normal_of(jac, normal, n):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`_normal` over the first n columns."""
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
    return ``work`` holds the frames of the last iterate (:func:`chain_kernel.frames`). The
    damped normal equations are solved by LDL^T (:func:`lu_kernel.damped_solve`; LU where that
    meets a pivot not positive), numpy's reference by LU: the same step to rounding.
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
        if not damped_solve(normal, error):
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


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _joint_step(newer, older, revolute):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The step from ``older`` to ``newer``, a revolute joint's within [-pi, pi] (both wrapped)."""
    step = newer - older
    if revolute:
        if step > math.pi:
            step -= 2.0 * math.pi
        elif step < -math.pi:
            step += 2.0 * math.pi
    return step


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _extrapolated_step(qs, j, w, revolute):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint j's last step s_1 and its extrapolation 4 s_1 - 6 s_2 + 4 s_3 - s_4 (``ik``'s)."""
    s1 = _joint_step(qs[j, w - 1], qs[j, w - 2], revolute)
    s2 = _joint_step(qs[j, w - 2], qs[j, w - 3], revolute)
    s3 = _joint_step(qs[j, w - 3], qs[j, w - 4], revolute)
    s4 = _joint_step(qs[j, w - 4], qs[j, w - 5], revolute)
    return s1, 4.0 * s1 - 6.0 * s2 + 4.0 * s3 - s4


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def extrapolated(slot, qs, w, revolute, smooth):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.extrapolated`` for one slot before waypoint w: True where ``slot`` was moved.

    ``slot``: shape (n,), its solution at waypoint w - 1 (unwrapped), moved to the extrapolation
    where the rule of ``ik.PREDICT_SMOOTH`` (``smooth``) takes it, six joints only. ``qs``:
    shape (n, W), the slot's solutions as written (wrapped; NaN where none): the steps are taken
    from them, so a path followed in any pieces extrapolates alike.
    """
    if len(slot) != 6 or w < 5:
        return False
    largest, deviation, finite = 0.0, 0.0, True
    for j in range(6):
        s1, step = _extrapolated_step(qs, j, w, revolute[j])
        finite = finite and not math.isnan(step)
        largest = max(largest, abs(s1))
        deviation = max(deviation, abs(step - s1))
    if not (finite and largest > 0.0 and deviation <= smooth * largest):
        return False
    for j in range(6):
        slot[j] += _extrapolated_step(qs, j, w, revolute[j])[1]
    return True


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
