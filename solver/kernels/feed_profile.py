"""The feed profiles of the cycle time, compiled: the ramps and TOPP-RA's time-optimal profile.

:mod:`solver.path.cycle_time` runs both on one pass's blended joint path, given on a grid s_i
by q_s and q_ss there (:mod:`solver.path.blended_path`); x = sdot^2, u = sddot, a joint's
acceleration q_s u + q_ss x.

- :func:`time_optimal`: the time-optimal rest-to-rest profile of TOPP-RA (Pham & Pham, "A new
  approach to time-optimal path parameterization based on reachability analysis", T-RO 2018)
  for joint speed and acceleration limits, discretised as toppra discretises them
  (toppra.algorithm.TOPPRA with JointVelocityConstraint and JointAccelerationConstraint, its
  default interpolation scheme): at stage i, x_i <= min_j (qdot_j / q_s,ij)^2, and
  |q_s,i u + q_ss,i x| <= a, |(q_s,i+1 + 2 d_i q_ss,i+1) u + q_ss,i+1 x| <= a (the stage's end,
  x_i+1 = x_i + 2 d_i u); the controllable sets K_i backwards from K_N = {0}, then the largest
  u forwards from x_0 = 0. toppra solves each stage's two-variable LP with Seidel's algorithm
  through Python, about 25 us a grid point (7 s of an evaluation of a 17,073-move program with
  acceleration limits, 80 % of it). With only these constraints a stage's LP is a projection:
  for each x the feasible u form an interval [L(x), U(x)] (the largest lower and the least
  upper bound of the constraints), so the x of K_i are those where every lower bound is at
  most every upper bound, one linear inequality in x per pair, solved here in closed form.
  The same profile as toppra's on the same grid (tests/solver/test_cycle_time.py, to 1e-9).
- :func:`capped_profile`: the same with the feed held below a cap (mu_acc): the ramps at a
  pass's ends and the constant feed between, on the time-optimal profile's own discretisation
  (ramps integrated point by point, each step's acceleration bounded at its start only, let the
  'ramp' time beat the time-optimal one by up to 0.8 %, which motion.md calls a lower bound).
"""

from __future__ import annotations

import numpy as np
from numba import njit

SHRINK = 1e-8
"""m^2/s^2: each forward step's x lowered by this or by SHRINK_SHARE of it, the less (toppra's own
margin against rounding, TOPPRA.compute_parameterization: x_i+1 = max(x - 1e-8, 0.9999 x)),
so that the profile is toppra's: 4e-6 of x at 0.05 m/s, 1e-4 below 1 cm/s."""
SHRINK_SHARE = 1e-4


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _stage(i, s, q_s, q_ss, qddot_max, low, high, alpha, beta, gamma):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Stage i's constraints alpha u + beta x <= gamma (returns their count).

    The acceleration limits at grid point i, at i + 1 by the interpolation scheme (x_i+1 =
    x + 2 d_i u), and x + 2 d_i u within [low, high], the next point's controllable set.
    """
    n = q_s.shape[1]
    twice = 2.0 * (s[i + 1] - s[i])
    m = 0
    for j in range(n):
        a = qddot_max[j]
        for side in (1.0, -1.0):
            alpha[m], beta[m], gamma[m] = side * q_s[i, j], side * q_ss[i, j], a
            m += 1
            ahead = q_s[i + 1, j] + twice * q_ss[i + 1, j]
            alpha[m], beta[m], gamma[m] = side * ahead, side * q_ss[i + 1, j], a
            m += 1
    alpha[m], beta[m], gamma[m] = twice, 1.0, high
    alpha[m + 1], beta[m + 1], gamma[m + 1] = -twice, -1.0, -low
    return m + 2


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _projection(m, alpha, beta, gamma, top):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The x in [0, top] for which some u meets the m constraints: (lowest, highest).

    A constraint with alpha = 0 bounds x alone; every pair of a lower bound on u (alpha < 0)
    and an upper one (alpha > 0) meets where (gamma_k - beta_k x) / alpha_k <=
    (gamma_l - beta_l x) / alpha_l, that is c x <= d with c = beta_k alpha_l - beta_l alpha_k and
    d = gamma_k alpha_l - gamma_l alpha_k. x = 0 meets every one (d >= 0: the gammas are limits
    and controllable speeds, >= 0, but -low, which is 0), so the set is never empty.
    """
    lowest, highest = 0.0, top
    for k in range(m):
        if alpha[k] == 0.0:
            if beta[k] > 0.0:
                highest = min(highest, gamma[k] / beta[k])
            elif beta[k] < 0.0:
                lowest = max(lowest, gamma[k] / beta[k])
            continue
        if alpha[k] > 0.0:
            continue
        for l in range(m):  # noqa: E741 - the paper's k and l
            if alpha[l] <= 0.0:
                continue
            c = beta[k] * alpha[l] - beta[l] * alpha[k]
            d = gamma[k] * alpha[l] - gamma[l] * alpha[k]
            if c > 0.0:
                highest = min(highest, d / c)
            elif c < 0.0:
                lowest = max(lowest, d / c)
    return lowest, highest


@njit(cache=True, nogil=True, error_model="numpy")
def time_optimal(s, q_s, q_ss, qdot_max, qddot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The time-optimal sdot^2 (G,) rest to rest on the grid ``s`` (see the module).

    Args:
        s: shape (G,), m, ascending, G >= 2.
        q_s: shape (G, n), rad/m, at each grid point.
        q_ss: shape (G, n), rad/m^2, at each grid point.
        qdot_max: shape (n,), rad/s.
        qddot_max: shape (n,), rad/s^2.
    """
    return _profile(s, q_s, q_ss, qdot_max, qddot_max, np.inf)


@njit(cache=True, nogil=True, error_model="numpy")
def capped_profile(s, q_s, q_ss, qdot_max, qddot_max, cap):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The fastest sdot^2 (G,) rest to rest that never exceeds ``cap`` (m^2/s^2), on the grid.

    :func:`time_optimal` with the feed held to sqrt(cap) as well, on the same discretisation
    and with the same margin: the pass at mu_acc with its ramps (cap = mu_acc^2), a profile
    the time-optimal one is never slower than (without the margin here, the capped profile
    beat the time-optimal one by 1e-6 of its time where the two coincide). Arguments as there.
    """
    return _profile(s, q_s, q_ss, qdot_max, qddot_max, cap)


@njit(cache=True, nogil=True, error_model="numpy")
def _profile(s, q_s, q_ss, qdot_max, qddot_max, cap):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """TOPP-RA's profile, toppra's margin each step, with x <= cap at every point."""
    count, n = q_s.shape
    top = np.empty(count)  # the speed limits' largest x at each point, and the cap
    for i in range(count):
        largest = cap
        for j in range(n):
            if q_s[i, j] != 0.0:
                largest = min(largest, (qdot_max[j] / abs(q_s[i, j])) ** 2)
        top[i] = largest
    low, high = np.zeros(count), np.zeros(count)  # K_i; K_N = {0}
    alpha, beta, gamma = np.empty(4 * n + 2), np.empty(4 * n + 2), np.empty(4 * n + 2)
    for i in range(count - 2, -1, -1):
        m = _stage(i, s, q_s, q_ss, qddot_max, low[i + 1], high[i + 1], alpha, beta, gamma)
        low[i], high[i] = _projection(m, alpha, beta, gamma, top[i])
    x = np.zeros(count)
    for i in range(count - 1):
        m = _stage(i, s, q_s, q_ss, qddot_max, low[i + 1], high[i + 1], alpha, beta, gamma)
        u = np.inf
        for k in range(m):
            if alpha[k] > 0.0:
                u = min(u, (gamma[k] - beta[k] * x[i]) / alpha[k])
        step = x[i] + 2.0 * (s[i + 1] - s[i]) * u
        step = max(step - SHRINK, (1.0 - SHRINK_SHARE) * step)  # toppra's margin, as toppra
        x[i + 1] = min(max(step, low[i + 1]), high[i + 1])
    return x


def warm_up() -> None:
    """Compile the kernels, or load them from the disk cache, so that no request pays for it."""
    s = np.array([0.0, 0.001, 0.002])
    q_s, q_ss = np.full((3, 6), 0.5), np.zeros((3, 6))
    limits = np.full(6, 3.0)
    time_optimal(s, q_s, q_ss, limits, limits)
    capped_profile(s, q_s, q_ss, limits, limits, 1.0)
