"""The damped normal equations' LDL^T (:func:`solver.families.numeric.lu_kernel.normal_solve`).

Held against numpy's LU solve (LAPACK's gesv) on J J^T + lambda I of random Jacobians, their
columns scaled apart and down to the singularity test's sigma_min / sigma_max (1e-7), with the
IK's damping floor; and on matrices that are not positive definite, which it must refuse with
``a`` and ``b`` as they were (the caller then takes the LU).
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from solver.families.numeric import ik, lu_kernel


@njit(cache=False)
def _solve(a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover - compiled
    return lu_kernel.normal_solve(a, b)  # type: ignore[no-any-return]


@pytest.mark.parametrize("smallest", [1.0, 1e-3, 1e-7])
def test_the_normal_equations_are_solved_as_numpys_lu_solves_them(smallest: float) -> None:
    """Backward stable as LU is (the residual of the solution rounding-small against a and x)
    and apart from numpy's solution by at most what the condition number allows."""
    rng = np.random.default_rng(7)
    for _ in range(500):
        u, _, vt = np.linalg.svd(rng.normal(size=(6, 6)))
        sigma = np.geomspace(1.0, smallest, 6) * rng.uniform(0.05, 3.0)
        jacobian = (u * sigma) @ vt
        damping = ik.DAMPING_FLOOR * rng.uniform(1.0, 1e4)
        normal = jacobian @ jacobian.T + damping * np.eye(6)
        error = rng.normal(size=6)
        expected = np.linalg.solve(normal, error)
        a, b = normal.copy(), error.copy()
        assert _solve(a, b)
        np.testing.assert_array_equal(a, normal)  # left as it is
        for x in (b, expected):
            scale = np.abs(normal).max() * np.abs(x).max() + np.abs(error).max()
            assert np.abs(normal @ x - error).max() <= 1e-14 * scale
        apart = np.abs(b - expected).max() / np.abs(expected).max()
        assert apart <= 1e-14 * np.linalg.cond(normal)


def test_a_matrix_not_positive_definite_is_refused_as_it_was() -> None:
    """a = L D L^T with one pivot d_k not positive, k = 0 to 5: refused, a and b untouched."""
    rng = np.random.default_rng(8)
    for k in range(6):
        for pivot in (-0.5, -1e-3):
            lower = np.tril(rng.normal(size=(6, 6)), -1) + np.eye(6)
            d = rng.uniform(0.5, 2.0, size=6)
            d[k] = pivot
            a = (lower * d) @ lower.T
            b = rng.normal(size=6)
            a_before, b_before = a.copy(), b.copy()
            assert not _solve(a, b), (k, pivot)
            np.testing.assert_array_equal(a, a_before)
            np.testing.assert_array_equal(b, b_before)
