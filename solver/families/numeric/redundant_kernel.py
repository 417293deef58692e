"""The exact DTF of a seven-joint chain, compiled: the twin of :func:`redundant_speed`.

robots.md section 5 and :mod:`solver.core.dtf_redundant`: with J (6 x 7) of full rank every
solution of J qdot = s t_hat is qdot = s a + lam b, a = J^+ t_hat and b a unit null-space
vector, and the LP max s s.t. |s a_j + lam b_j| <= qdot_max_j has the closed form of
:func:`solver.core.two_variable_lp.two_variable_speed`, lam then
:func:`solver.core.two_variable_lp.spin_rate_nearest_zero`.
numpy takes a and b from a batched SVD, which was most of a Panda map; here they come from a
Householder QR of J^T = Q R (b the last column of Q, a = Q_1 R^-T t_hat), per configuration on
the compiled chain. Where R's diagonal spans more than ``QR_RCOND`` the configuration is left
to numpy (``irregular``), whose SVD decides the rank as before. Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.families.numeric.chain_kernel import drop_stale_cache, frames, jacobian_at, workspace

drop_stale_cache(Path(__file__))

# Below this min |R_ii| / max |R_ii| the QR is not trusted to have full rank (sigma_min <=
# min |R_ii|), and numpy's SVD decides (its RANK_RCOND is 1e-12; above this ratio sigma_6 /
# sigma_1 is far above that for six columns).
QR_RCOND = 1e-6


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _null_and_pseudo_inverse(jac, twist, house, a, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The unit null-space vector b (7,) of jac (6, 7) and a = J^+ twist (7,); False: not trusted.

    Householder QR of J^T (7 x 6) in ``house`` (7, 7): column k from the diagonal down holds
    the reflector v_k (v_k^T v_k in ``house[k, 6]``), R's entries above the diagonal are above
    it, R's diagonal is kept apart.
    """
    for i in range(7):
        for k in range(6):
            house[i, k] = jac[k, i]
    diagonal = np.empty(6)
    for k in range(6):
        norm = 0.0
        for i in range(k, 7):
            norm += house[i, k] * house[i, k]
        norm = math.sqrt(norm)
        alpha = -norm if house[k, k] >= 0.0 else norm
        house[k, k] -= alpha  # v = x - alpha e_k, stored in place
        vnorm = 0.0
        for i in range(k, 7):
            vnorm += house[i, k] * house[i, k]
        if vnorm == 0.0:
            return False
        for col in range(k + 1, 6):  # A <- (I - 2 v v^T / v^T v) A
            dot = 0.0
            for i in range(k, 7):
                dot += house[i, k] * house[i, col]
            f = 2.0 * dot / vnorm
            for i in range(k, 7):
                house[i, col] -= f * house[i, k]
        house[k, 6] = vnorm  # column 6 is free: v^T v of reflector k
        diagonal[k] = alpha
    largest, smallest = 0.0, np.inf
    for k in range(6):
        largest, smallest = max(largest, abs(diagonal[k])), min(smallest, abs(diagonal[k]))
    if not smallest > QR_RCOND * largest:
        return False
    y = np.empty(6)  # R^T y = twist, R upper: forward substitution
    for k in range(6):
        total = twist[k]
        for i in range(k):
            total -= house[i, k] * y[i]
        y[k] = total / diagonal[k]
    for i in range(7):
        a[i] = y[i] if i < 6 else 0.0
        b[i] = 1.0 if i == 6 else 0.0
    for k in range(5, -1, -1):  # Q = H_0 ... H_5: apply H_5 first
        for vector in (a, b):
            dot = 0.0
            for i in range(k, 7):
                dot += house[i, k] * vector[i]
            f = 2.0 * dot / house[k, 6]
            for i in range(k, 7):
                vector[i] -= f * house[i, k]
    return True


_SKIPPED, _IRREGULAR, _SOLVED = 0, 1, 2
"""What :func:`_directions_at` did with a configuration: not finite, J near rank loss, solved."""


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _directions_at(chain, q, twist, point, work, house, a, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """J^+ twist into ``a`` and the null space into ``b`` at one configuration ``q`` (7,).

    Returns:
        _SKIPPED where ``q`` is not finite, _IRREGULAR where J nears rank loss (numpy
        decides), else _SOLVED.
    """
    for j in range(q.shape[0]):
        if not math.isfinite(q[j]):
            return _SKIPPED
    frames(chain, q, work)
    jacobian_at(chain[3], work[0], work[1], point, work[6])
    if not _null_and_pseudo_inverse(work[6], twist, house, a, b):
        return _IRREGULAR
    return _SOLVED


@njit(cache=True, nogil=True, error_model="numpy")
def redundant_speeds(chain, q, twist, point, qdot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The joint speeds qdot / s at the LP optimum, at M configurations of a seven-joint chain.

    Args:
        chain: :meth:`SerialChain.packed`, seven joints.
        q: shape (M, 7), rad; rows not finite give NaN.
        twist: shape (M, 6), t_hat at the points.
        point: shape (M, 3), m in {B}, where the twist is.
        qdot_max: shape (7,), rad/s.

    Returns:
        speeds: shape (M, 7), the joint speeds per unit speed (what the family's
        ``joint_speeds_per_unit_twist`` answers); irregular: shape (M,), bool, rows left to
        numpy (J near rank loss), NaN in ``speeds``.
    """
    n_rows, n = q.shape
    speeds = np.full((n_rows, n), np.nan)
    irregular = np.zeros(n_rows, dtype=np.bool_)
    work = workspace(n)
    house, a, b = np.empty((7, 7)), np.empty(7), np.empty(7)
    for m in range(n_rows):
        solved = _directions_at(chain, q[m], twist[m], point[m], work, house, a, b)
        if solved != _SOLVED:
            irregular[m] = solved == _IRREGULAR
            continue
        best = np.inf  # two_variable_speed: the least pair bound, NaN pairs ignored
        for j in range(n):
            for k in range(j + 1, n):
                bound = (qdot_max[j] * abs(b[k]) + qdot_max[k] * abs(b[j])) / abs(
                    a[j] * b[k] - a[k] * b[j]
                )
                if bound < best:
                    best = bound
        inside = best * (1.0 - 1e-12)  # spin_rate_nearest_zero at the optimum
        low, high = -np.inf, np.inf
        for j in range(n):
            if b[j] != 0.0:
                one = (-qdot_max[j] - inside * a[j]) / b[j]
                other = (qdot_max[j] - inside * a[j]) / b[j]
                low, high = max(low, min(one, other)), min(high, max(one, other))
        lam = (low + high) / 2 if low > high else min(max(0.0, low), high)
        lam = lam if math.isfinite(lam) else 0.0
        for j in range(n):
            speeds[m, j] = (best * a[j] + lam * b[j]) / best
    return speeds, irregular


@njit(cache=True, nogil=True, error_model="numpy")
def least_norm_and_null(chain, q, twist, point):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """J^+ t and a unit null-space vector of J at M configurations of a seven-joint chain.

    The free spin's directions (robots.md section 5): the least-norm joint speeds of the twist
    (``[0; z_tool]``) and the null space, from the QR of :func:`redundant_speeds`.

    Args:
        chain: :meth:`SerialChain.packed`, seven joints.
        q: shape (M, 7), rad; rows not finite give NaN.
        twist: shape (M, 6), at the points.
        point: shape (M, 3), m in {B}, where the twist is.

    Returns:
        least: shape (M, 7), J^+ twist; null: shape (M, 7), unit, its sign arbitrary;
        irregular: shape (M,), bool, rows left to numpy (J near rank loss), NaN in both.
    """
    n_rows, n = q.shape
    least = np.full((n_rows, n), np.nan)
    null = np.full((n_rows, n), np.nan)
    irregular = np.zeros(n_rows, dtype=np.bool_)
    work = workspace(n)
    house, a, b = np.empty((7, 7)), np.empty(7), np.empty(7)
    for m in range(n_rows):
        solved = _directions_at(chain, q[m], twist[m], point[m], work, house, a, b)
        if solved != _SOLVED:
            irregular[m] = solved == _IRREGULAR
            continue
        least[m] = a
        null[m] = b
    return least, null, irregular
