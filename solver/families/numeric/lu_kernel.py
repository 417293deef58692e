"""The numeric family's compiled LU: J x = t solved in place, and the sign of det J.

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
