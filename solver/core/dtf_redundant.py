"""The exact DTF of a redundant arm (dof > 6), batched over configurations.

dtf.md section 3 defines V_max for every arm as the LP  max s  s.t.  J qdot = s t_hat,
|qdot| <= qdot_max. For seven joints and J of full rank (robots.md section 5) every solution is
qdot = s a + lam b with a = J^+ t_hat and b a unit vector spanning the null space of J, so the
LP has two variables, max s s.t. |s a_j + lam b_j| <= qdot_max_j, solved exactly and vectorised
by :func:`solver.core.dtf.two_variable_speed`. Beyond seven joints, or where J loses rank, HiGHS
solves the LP one configuration at a time (:func:`solver.core.dtf.lp_speed`).
"""

from __future__ import annotations

import numpy as np

from solver.core.dtf import lp_speed, spin_rate_nearest_zero, two_variable_speed

# Below this sigma_6 / sigma_1 the null space of a 6 x 7 Jacobian is not one-dimensional to
# working precision, and the LP is solved by HiGHS instead.
RANK_RCOND = 1e-12


def redundant_speed(
    jacobian: np.ndarray, twist: np.ndarray, qdot_max: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The exact DTF LP at M configurations: the optimum s and the joint speeds there.

    Args:
        jacobian: shape (M, 6, n), n >= 7, {B} axes at the tool point, linear rows first;
            finite.
        twist: shape (M, 6), t_hat (per m/s of linear speed, or per rad/s where h = 0).
        qdot_max: shape (n,), rad/s, > 0.

    Returns:
        speed: shape (M,), the optimum s (m/s, or rad/s where h = 0);
        qdot: shape (M, n), rad/s, joint speeds with J qdot = s t_hat and |qdot| <= qdot_max
        (to ~1e-12 relative); at least one joint is on its limit.
    """
    n_configurations, _, n = jacobian.shape
    limits = np.asarray(qdot_max, dtype=float)
    speed = np.full(n_configurations, np.nan)
    qdot = np.full((n_configurations, n), np.nan)
    by_lp = np.ones(n_configurations, dtype=bool)
    if n == 7 and n_configurations:
        left, values, right = np.linalg.svd(jacobian)  # (M, 6, 6), (M, 6), (M, 7, 7)
        regular = values[:, -1] > RANK_RCOND * values[:, 0]
        coefficients = np.einsum("mji,mj->mi", left, twist) / np.where(
            regular[:, None], values, 1.0
        )
        a = np.einsum("mij,mi->mj", right[:, :6], coefficients)  # J^+ t_hat, (M, 7)
        b = right[:, 6]  # unit null-space vector, (M, 7)
        best, _ = two_variable_speed(a.T, b.T, limits)
        lam = spin_rate_nearest_zero(a.T, b.T, limits, best)
        speed = np.where(regular, best, np.nan)
        qdot = np.where(regular[:, None], best[:, None] * a + lam[:, None] * b, np.nan)
        by_lp = ~regular
    for m in np.flatnonzero(by_lp):
        speed[m], qdot[m] = lp_speed(jacobian[m], twist[m], qdot_max=limits)
    return speed, qdot
