"""The numeric family's compiled solves: J x = t by LU, the sign of det J, the normal equations.

LU with partial pivoting in scalar loops, what LAPACK's gesv (``np.linalg.solve``) and getrf
(``np.linalg.det``) do, for the compiled chain (:mod:`solver.families.numeric.chain_kernel`)
and the kernels that take it in (:mod:`~solver.families.numeric.ik_kernel`,
:mod:`~solver.families.numeric.scout_kernel`). Every function releases the GIL (``nogil``); the
entry points are inlined into their callers (``inline="always"``), the bodies they call are
not: each is compiled once per size, a literal 6 (its loops' trip counts constants, unrolled)
and any other, where inlining both copies at every call site made a cold compile of the
six-joint kernels 109 s of CPU instead of 60 (and the map 1-2 % faster). The callers' disk
caches take this module's source into their stale marker
(:func:`solver.families.numeric.chain_kernel.drop_stale_cache`).
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def lu_solve(a, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Solve a x = b in place (x in ``b``) by LU with partial pivoting; False if a is singular.

    What LAPACK's gesv (``np.linalg.solve``) does; ``a`` (k, k) is overwritten: the body of
    :func:`lu_solve_signed`, the sign of det a dropped (following it changes no operation on
    ``a`` or ``b``).
    """
    solved, _ = lu_solve_signed(a, b)
    return solved


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def lu_solve_signed(a, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`lu_solve` (the same operations, the same x), and whether det a < 0.

    The sign of det a from the factors: a row swap and a negative pivot each flip it, as in
    :func:`det_negative`. Returns (solved, negative); ``negative`` is meaningless unless solved.
    Six unknowns (every J J^T and 6 x 6 J here) take a copy whose size is a constant, which the
    compiler unrolls: the same operations in the same order.
    """
    if len(b) == 6:
        return _lu_solve_signed(a, b, 6)
    return _lu_solve_signed(a, b, len(b))


@njit(cache=True, nogil=True, error_model="numpy")
def _lu_solve_signed(a, b, size):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`lu_solve_signed` of ``size`` unknowns."""
    negative = False
    for col in range(size):
        pivot = col
        for row in range(col + 1, size):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        if a[pivot, col] == 0.0:
            return False, negative
        if pivot != col:
            negative = not negative
            for k in range(size):
                a[col, k], a[pivot, k] = a[pivot, k], a[col, k]
            b[col], b[pivot] = b[pivot], b[col]
        if a[col, col] < 0.0:
            negative = not negative
        for row in range(col + 1, size):
            f = a[row, col] / a[col, col]
            for k in range(col + 1, size):
                a[row, k] -= f * a[col, k]
            b[row] -= f * b[col]
    for row in range(size - 1, -1, -1):
        total = b[row]
        for k in range(row + 1, size):
            total -= a[row, k] * b[k]
        b[row] = total / a[row, row]
    return True, negative


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def det_negative(jac, a):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether det J < 0, J (6, 6) in ``jac`` (left alone), by LU with partial pivoting in ``a``.

    LAPACK's getrf (``np.linalg.det``) takes the same pivots; where J is regular (as the
    singularity test asks first) the sign does not depend on the rounding.
    """
    for i in range(6):
        for k in range(6):
            a[i, k] = jac[i, k]
    negative = False
    for col in range(6):
        pivot = col
        for row in range(col + 1, 6):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        if pivot != col:
            negative = not negative
            for k in range(6):
                a[col, k], a[pivot, k] = a[pivot, k], a[col, k]
        if a[col, col] < 0.0:
            negative = not negative
        for row in range(col + 1, 6):
            f = a[row, col] / a[col, col]
            for k in range(col + 1, 6):
                a[row, k] -= f * a[col, k]
    return negative


@njit(cache=True, nogil=True, error_model="numpy")
def normal_solve(a, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Solve a x = b in place (x in ``b``), ``a`` (6, 6) symmetric positive definite: LDL^T.

    The damped normal equations (J J^T + lambda I) y = e of every least-squares step
    (:func:`solver.families.numeric.ik_kernel._levenberg_marquardt`,
    :func:`~solver.families.numeric.scout_kernel.rough_steps`): a = L D L^T (L unit lower, D
    diagonal; Cholesky without its square roots, backward stable on such matrices without
    pivoting), from the lower triangle of ``a``, which is left as it is. Written out on
    scalars, so the factors stay in registers: 45 to 60 ns a solve against 170 to 250 for
    :func:`lu_solve` on the same matrices (2026-12-06, one thread); the solution agrees with
    LU's (and numpy's) to rounding, 8e-16 relative on a random J J^T. False, ``b`` left as it
    is, where a pivot d_j is not positive (a not positive definite as rounded):
    :func:`damped_solve` then takes :func:`lu_solve`.

    Compiled on its own, not inlined by numba (``inline="always"``): numba's inlining copies a
    callee's whole scope into each block it copies, and the 660 variables of these scalars,
    inlined at five steps and again into every kernel that inlines those, made the numeric
    kernels' cold compile 110.7 s of CPU against 91.7 s (2026-12-07, numeric6 and numeric7,
    one process). LLVM inlines or calls it: the UR5-as-URDF map took the same CPU time (219 to
    236 ms against 222 to 231, best of 8, alternated), the Panda's within 1.5 %, both maps the
    same to the bit.
    """
    a00, a10, a11, a20, a21, a22 = a[0, 0], a[1, 0], a[1, 1], a[2, 0], a[2, 1], a[2, 2]
    a30, a31, a32, a33 = a[3, 0], a[3, 1], a[3, 2], a[3, 3]
    a40, a41, a42, a43, a44 = a[4, 0], a[4, 1], a[4, 2], a[4, 3], a[4, 4]
    a50, a51, a52, a53, a54, a55 = a[5, 0], a[5, 1], a[5, 2], a[5, 3], a[5, 4], a[5, 5]
    # column 0: d0, then l_i0 = c_i0 / d0 (c_ik = l_ik d_k)
    d0 = a00
    if not d0 > 0.0:
        return False
    r0 = 1.0 / d0
    c10 = a10
    l10 = c10 * r0
    c20 = a20
    l20 = c20 * r0
    c30 = a30
    l30 = c30 * r0
    c40 = a40
    l40 = c40 * r0
    c50 = a50
    l50 = c50 * r0
    # column 1: d1, then l_i1 = c_i1 / d1 (c_ik = l_ik d_k)
    d1 = a11 - c10 * l10
    if not d1 > 0.0:
        return False
    r1 = 1.0 / d1
    c21 = a21 - c20 * l10
    l21 = c21 * r1
    c31 = a31 - c30 * l10
    l31 = c31 * r1
    c41 = a41 - c40 * l10
    l41 = c41 * r1
    c51 = a51 - c50 * l10
    l51 = c51 * r1
    # column 2: d2, then l_i2 = c_i2 / d2 (c_ik = l_ik d_k)
    d2 = a22 - c20 * l20 - c21 * l21
    if not d2 > 0.0:
        return False
    r2 = 1.0 / d2
    c32 = a32 - c30 * l20 - c31 * l21
    l32 = c32 * r2
    c42 = a42 - c40 * l20 - c41 * l21
    l42 = c42 * r2
    c52 = a52 - c50 * l20 - c51 * l21
    l52 = c52 * r2
    # column 3: d3, then l_i3 = c_i3 / d3 (c_ik = l_ik d_k)
    d3 = a33 - c30 * l30 - c31 * l31 - c32 * l32
    if not d3 > 0.0:
        return False
    r3 = 1.0 / d3
    c43 = a43 - c40 * l30 - c41 * l31 - c42 * l32
    l43 = c43 * r3
    c53 = a53 - c50 * l30 - c51 * l31 - c52 * l32
    l53 = c53 * r3
    # column 4: d4, then l_i4 = c_i4 / d4 (c_ik = l_ik d_k)
    d4 = a44 - c40 * l40 - c41 * l41 - c42 * l42 - c43 * l43
    if not d4 > 0.0:
        return False
    r4 = 1.0 / d4
    c54 = a54 - c50 * l40 - c51 * l41 - c52 * l42 - c53 * l43
    l54 = c54 * r4
    # column 5: d5, then l_i5 = c_i5 / d5 (c_ik = l_ik d_k)
    d5 = a55 - c50 * l50 - c51 * l51 - c52 * l52 - c53 * l53 - c54 * l54
    if not d5 > 0.0:
        return False
    r5 = 1.0 / d5
    # L y = b, then D L^T x = y
    y0 = b[0]
    y1 = b[1] - l10 * y0
    y2 = b[2] - l20 * y0 - l21 * y1
    y3 = b[3] - l30 * y0 - l31 * y1 - l32 * y2
    y4 = b[4] - l40 * y0 - l41 * y1 - l42 * y2 - l43 * y3
    y5 = b[5] - l50 * y0 - l51 * y1 - l52 * y2 - l53 * y3 - l54 * y4
    x5 = y5 * r5
    x4 = y4 * r4 - l54 * x5
    x3 = y3 * r3 - l43 * x4 - l53 * x5
    x2 = y2 * r2 - l32 * x3 - l42 * x4 - l52 * x5
    x1 = y1 * r1 - l21 * x2 - l31 * x3 - l41 * x4 - l51 * x5
    x0 = y0 * r0 - l10 * x1 - l20 * x2 - l30 * x3 - l40 * x4 - l50 * x5
    b[0], b[1], b[2], b[3], b[4], b[5] = x0, x1, x2, x3, x4, x5
    return True


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def damped_solve(a, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The damped normal equations (J J^T + lambda I) y = e of a least-squares step, in place.

    :func:`normal_solve`; where it meets a pivot not positive (``a`` and ``b`` then as they
    were), :func:`lu_solve`. False only where the LU finds ``a`` singular too.
    """
    return normal_solve(a, b) or lu_solve(a, b)
