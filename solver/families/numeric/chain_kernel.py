"""The numeric family's compiled chain: forward kinematics, the Jacobian, J^-1 t.

The compiled twin of :class:`solver.families.numeric.chain.SerialChain` (``frames``,
``jacobian``), one configuration at a time in scalar loops (the numpy chain spends its time in
small products over the batch and numpy's per-call overhead), and of the family's batched
J^-1 t. The numpy chain is the reference the tests hold it to, with pinocchio and finite
differences. Every function releases the GIL (``nogil``): a map on a worker thread does not
starve the service's event loop (issue stop 19), and nothing here indexes numpy arrays by index
arrays in a loop.

The chain is the tuple :meth:`SerialChain.packed` gives: joint rotations (n, 3, 3), joint
translations (n, 3), axes (n, 3), revolute (n,) bool, base rotation (3, 3) and translation (3,),
tool rotation (3, 3) and translation (3,). J^-1 t solves by the LU of
:mod:`solver.families.numeric.lu_kernel`. The helpers :mod:`solver.families.numeric.ik_kernel`
takes into itself are inlined (``inline="always"``), which lets numba drop the reference counting
of the work arrays between them.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core import codes
from solver.core.compiled_cache import drop_stale_caches
from solver.families.numeric import lu_kernel
from solver.families.numeric.lu_kernel import lu_solve


def drop_stale_cache(module_file: Path, *also: Path) -> None:
    """Drop the cached machine code of a module whose compiled code takes this module's in.

    numba keys a function's disk cache by its own source file, but the IK and redundant-speed
    kernels take this chain's code and its LU's (:mod:`~solver.families.numeric.lu_kernel`)
    into themselves, and the status codes of :mod:`solver.core.codes` they return: after an
    edit of any they would load the old code. A marker named by
    the hash of these sources and the module's says which code the cache holds (as
    :mod:`solver.kernels.cache` does for the map kernels), wherever numba keeps it.

    Args:
        module_file: the source file of the module whose cache to check.
        also: the source files of other modules whose compiled code it takes in.
    """
    shared = (Path(__file__), Path(str(lu_kernel.__file__)), Path(str(codes.__file__)))
    drop_stale_caches(module_file.stem, (*shared, module_file, *also), (module_file,))


drop_stale_cache(Path(__file__))  # speeds_per_twist takes the LU in


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def frames(chain, q, work):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint axes and origins, the flange's rotation and position, all in {B}, into ``work``.

    ``SerialChain.frames`` for one q (n,), on the frames :meth:`SerialChain.packed` turns so
    that every joint turns about its z: R_j = R_{j-1} M_j Rz(q_j), so the axis is the third
    column of R_{j-1} M_j and the joint's rotation mixes two columns. ``work`` is workspace's:
    axes (n, 3), origins (n, 3), rot (3, 3), pos (3,) are written.
    """
    joint_rotation, joint_translation, _, revolute, base_r, base_t, tool_r, tool_t = chain
    axes, origins, rot, pos, r = work[0], work[1], work[2], work[3], work[4]
    p0, p1, p2 = base_t[0], base_t[1], base_t[2]
    for i in range(3):
        for k in range(3):
            r[i, k] = base_r[i, k]
    for j in range(len(revolute)):
        t0, t1, t2 = joint_translation[j, 0], joint_translation[j, 1], joint_translation[j, 2]
        p0 += r[0, 0] * t0 + r[0, 1] * t1 + r[0, 2] * t2
        p1 += r[1, 0] * t0 + r[1, 1] * t1 + r[1, 2] * t2
        p2 += r[2, 0] * t0 + r[2, 1] * t1 + r[2, 2] * t2
        origins[j, 0], origins[j, 1], origins[j, 2] = p0, p1, p2
        turns = revolute[j]
        c, s = (math.cos(q[j]), math.sin(q[j])) if turns else (1.0, 0.0)
        for i in range(3):
            r0, r1, r2 = r[i, 0], r[i, 1], r[i, 2]
            m0 = (
                r0 * joint_rotation[j, 0, 0]
                + r1 * joint_rotation[j, 1, 0]
                + r2 * joint_rotation[j, 2, 0]
            )
            m1 = (
                r0 * joint_rotation[j, 0, 1]
                + r1 * joint_rotation[j, 1, 1]
                + r2 * joint_rotation[j, 2, 1]
            )
            m2 = (
                r0 * joint_rotation[j, 0, 2]
                + r1 * joint_rotation[j, 1, 2]
                + r2 * joint_rotation[j, 2, 2]
            )
            axes[j, i] = m2
            r[i, 0] = c * m0 + s * m1
            r[i, 1] = c * m1 - s * m0
            r[i, 2] = m2
        if not turns:
            p0 += axes[j, 0] * q[j]
            p1 += axes[j, 1] * q[j]
            p2 += axes[j, 2] * q[j]
    t0, t1, t2 = tool_t[0], tool_t[1], tool_t[2]
    pos[0] = p0 + r[0, 0] * t0 + r[0, 1] * t1 + r[0, 2] * t2
    pos[1] = p1 + r[1, 0] * t0 + r[1, 1] * t1 + r[1, 2] * t2
    pos[2] = p2 + r[2, 0] * t0 + r[2, 1] * t1 + r[2, 2] * t2
    for i in range(3):
        for k in range(3):
            rot[i, k] = r[i, 0] * tool_r[0, k] + r[i, 1] * tool_r[1, k] + r[i, 2] * tool_r[2, k]


@njit(cache=True, nogil=True, error_model="numpy")
def workspace(n):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Work arrays for a chain of n joints, in this order.

    axes, origins (n, 3); the flange's rot (3, 3) and pos (3,); r, tmp (3, 3); jac (6, n);
    normal (6, 6); error (6,); the relative rotation (3, 3); a factor (6, 6).
    """
    return (
        np.empty((n, 3)),
        np.empty((n, 3)),
        np.empty((3, 3)),
        np.empty(3),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((6, n)),
        np.empty((6, 6)),
        np.empty(6),
        np.empty((3, 3)),
        np.empty((6, 6)),
    )


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def jacobian_at(revolute, axes, origins, at, jac):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The geometric Jacobian (6, n) at the point ``at`` (3,), {B} axes, linear rows first."""
    for j in range(len(revolute)):
        a0, a1, a2 = axes[j, 0], axes[j, 1], axes[j, 2]
        if revolute[j]:
            d0, d1, d2 = at[0] - origins[j, 0], at[1] - origins[j, 1], at[2] - origins[j, 2]
            jac[0, j] = a1 * d2 - a2 * d1
            jac[1, j] = a2 * d0 - a0 * d2
            jac[2, j] = a0 * d1 - a1 * d0
            jac[3, j], jac[4, j], jac[5, j] = a0, a1, a2
        else:
            jac[0, j], jac[1, j], jac[2, j] = a0, a1, a2
            jac[3, j], jac[4, j], jac[5, j] = 0.0, 0.0, 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def jacobians(chain, q, point):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``SerialChain.jacobian`` at M configurations: (M, 6, n) at the points (M, 3), {B} axes.

    Rows of q that are not finite give NaN.
    """
    n_rows, n = q.shape
    result = np.full((n_rows, 6, n), np.nan)
    work = workspace(n)
    for m in range(n_rows):
        if np.isfinite(q[m]).all():
            frames(chain, q[m], work)
            jacobian_at(chain[3], work[0], work[1], point[m], result[m])
    return result


@njit(cache=True, nogil=True, error_model="numpy")
def forward(chain, q):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``SerialChain.forward`` at M configurations: the flange's rotations and positions."""
    n_rows, n = q.shape
    rotations, positions = np.empty((n_rows, 3, 3)), np.empty((n_rows, 3))
    work = workspace(n)
    for m in range(n_rows):
        frames(chain, q[m], work)
        rotations[m] = work[2]
        positions[m] = work[3]
    return rotations, positions


@njit(cache=True, nogil=True, error_model="numpy")
def speeds_per_twist(chain, q, twist, point):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """J^-1 t of a six-joint chain at M configurations (M, 6), twists (M, 6) at points (M, 3).

    NaN rows where q is not finite or J is exactly singular (as the family's numpy solve).
    """
    result = np.full(q.shape, np.nan)
    _speeds_into(chain, q, twist, point, workspace(q.shape[1]), result)
    return result


@njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _speeds_into(chain, q, twist, point, work, result):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`speeds_per_twist`' loop into its preallocated ``result`` (M, 6).

    Compiled without numba's reference counting (``_nrt=False``: it allocates nothing), which
    the inlined :func:`frames` otherwise costs at every row; the same arithmetic, the same bits.
    """
    n_rows, n = q.shape
    jac, rhs = work[6], work[8]
    for m in range(n_rows):
        finite = True
        for j in range(n):
            finite = finite and math.isfinite(q[m, j])
        if not finite:
            continue
        frames(chain, q[m], work)
        jacobian_at(chain[3], work[0], work[1], point[m], jac)
        for i in range(6):
            rhs[i] = twist[m, i]
        if lu_solve(jac, rhs):
            for j in range(n):
                result[m, j] = rhs[j]
