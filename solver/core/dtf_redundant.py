"""The exact DTF of a redundant arm (dof > 6), batched over configurations.

dtf.md section 3 defines V_max for every arm as the LP  max s  s.t.  J qdot = s t_hat,
|qdot| <= qdot_max. For seven joints and J of full rank (robots.md section 5) every solution is
qdot = s a + lam b with a = J^+ t_hat and b a unit vector spanning the null space of J, so the
LP has two variables, max s s.t. |s a_j + lam b_j| <= qdot_max_j, solved exactly and vectorised
by :func:`solver.core.two_variable_lp.two_variable_speed`. Beyond seven joints, or where J loses
rank, HiGHS solves the LP one configuration at a time (:func:`solver.core.dtf.lp_speed`).
"""

from __future__ import annotations

import itertools

import numpy as np

from solver.core.dtf import lp_speed
from solver.core.two_variable_lp import spin_rate_nearest_zero, two_variable_speed

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


# Configurations solved together by the vertex enumeration (memory: ~ 35 x 8 x 7 floats each).
VERTEX_CHUNK = 4096
# A vertex is feasible when every joint is within its limit to this (relative), and a d x d
# system of tight constraints is solved where its determinant exceeds this (relative).
VERTEX_RTOL = 1e-9
VERTEX_DET_RTOL = 1e-12


def vertex_lp(
    offset: np.ndarray, directions: np.ndarray, qdot_max: np.ndarray, objective: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The LP max objective . x  s.t.  |offset_j + directions_j . x| <= qdot_max_j, by its vertices.

    A bounded LP in d variables takes its optimum at a vertex, where d of the 2 n constraints
    are tight: every choice of d joints and of their signs (C(n, d) 2^d systems, 280 for seven
    joints and three variables) is solved, the feasible ones kept, the best taken. Exact and
    vectorised over configurations.

    Args:
        offset: shape (M, n), rad/s, the joint speeds at x = 0.
        directions: shape (M, n, d), rad/s per unit of each variable; of rank d.
        qdot_max: shape (n,), rad/s, > 0.
        objective: shape (d,).

    Returns:
        value: shape (M,), the optimum (NaN where no vertex is feasible or the input is not
        finite); x: shape (M, d), a vertex there; tight: shape (M, d), its joints.
    """
    m_count, n, d = directions.shape
    limits = np.asarray(qdot_max, dtype=float)
    combos = np.array(list(itertools.combinations(range(n), d)))  # (K, d)
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=d)))  # (S, d)
    value = np.full(m_count, np.nan)
    x = np.full((m_count, d), np.nan)
    tight = np.zeros((m_count, d), dtype=np.int64)
    for start in range(0, m_count, VERTEX_CHUNK):
        rows = slice(start, start + VERTEX_CHUNK)
        g = directions[rows][:, combos]  # (M, K, d, d)
        scale = np.prod(np.linalg.norm(g, axis=-1), axis=-1)
        regular = np.abs(np.linalg.det(g)) > VERTEX_DET_RTOL * scale  # (M, K)
        g = np.where(regular[..., None, None], g, np.eye(d))
        rhs = signs * limits[combos][:, None, :] - offset[rows][:, combos][:, :, None, :]
        vertex = np.linalg.solve(g[:, :, None], rhs[..., None])[..., 0]  # (M, K, S, d)
        speeds = offset[rows][:, None, None, :] + np.einsum(
            "mnd,mksd->mksn", directions[rows], vertex
        )
        feasible = regular[..., None] & np.all(
            np.abs(speeds) <= limits * (1.0 + VERTEX_RTOL), axis=-1
        )
        score = np.where(feasible, vertex @ objective, -np.inf).reshape(len(g), -1)
        best = score.argmax(axis=1)
        found = np.isfinite(score[np.arange(len(g)), best])
        value[rows] = np.where(found, score[np.arange(len(g)), best], np.nan)
        x[rows] = np.where(
            found[:, None], vertex.reshape(len(g), -1, d)[np.arange(len(g)), best], np.nan
        )
        tight[rows] = combos[best // len(signs)]
    return value, x, tight


def spin_speed(
    a: np.ndarray, c: np.ndarray, b: np.ndarray, qdot_max: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The DTF of a seven-joint arm with the tool spin rate free: a three-variable LP.

    dtf.md section 3 with cam.md section 2's free spin: max s s.t. J qdot = s t_hat + sigma
    [0; z_tool], |qdot| <= qdot_max. Every solution is qdot = s a + sigma c + lam b (a = J^+
    t_hat or any particular solution, c = J^+ [0; z_tool], b spanning the null space of J), so
    the LP has the three variables (s, sigma, lam): :func:`vertex_lp`.

    Args:
        a: shape (n, ...), rad/s per unit s (a particular solution for t_hat).
        c: shape (n, ...), rad/s per unit sigma (a particular solution for [0; z_tool]).
        b: shape (n, ...), rad/s per unit lam (the null space of J).
        qdot_max: shape (n,), rad/s.

    Returns:
        speed: shape (...), the optimum s (NaN where an input is not finite);
        limiting: shape (...), of the optimum's three tight joints the one the spin and the
        null space help least (smallest (|c_j| + |b_j|) / qdot_max_j).
    """
    shape = a.shape[1:]
    columns = [np.moveaxis(v, 0, -1).reshape(-1, len(a)) for v in (a, c, b)]
    directions = np.stack(columns, axis=-1)  # (M, n, 3)
    finite = np.isfinite(directions).all(axis=(1, 2))
    speed = np.full(len(directions), np.nan)
    limiting = np.zeros(len(directions), dtype=np.int64)
    rows = np.flatnonzero(finite)
    value, _, tight = vertex_lp(
        np.zeros((len(rows), len(a))), directions[rows], qdot_max, np.array([1.0, 0.0, 0.0])
    )
    speed[rows] = value
    help_ = (np.abs(columns[1][rows]) + np.abs(columns[2][rows])) / qdot_max
    least = np.take_along_axis(help_, tight, axis=1).argmin(axis=1)
    limiting[rows] = tight[np.arange(len(rows)), least]
    return speed.reshape(shape), limiting.reshape(shape)


def spin_rate_at_feed(
    a: np.ndarray,
    c: np.ndarray,
    b: np.ndarray,
    qdot_max: np.ndarray,
    feed: np.ndarray,
    *,
    inside: float = 1.0 - 1e-12,
) -> tuple[np.ndarray, np.ndarray]:
    """The spin rate nearest 0 at a feed, and the null-space rate then (seven joints).

    At s = feed (1 - 1e-12) (``inside``; a short interval, as in
    :func:`solver.core.two_variable_lp.spin_rate_nearest_zero`), sigma ranges over an interval:
    its ends are two LPs in (sigma, lam) (:func:`vertex_lp`); sigma is the point of it nearest 0,
    and lam then the point of its own interval nearest 0.

    Args:
        a: shape (n, ...), as for :func:`spin_speed`.
        c: shape (n, ...), as for :func:`spin_speed`.
        b: shape (n, ...), as for :func:`spin_speed`.
        qdot_max: shape (n,), rad/s.
        feed: shape broadcasting to (...), at most the optimum of :func:`spin_speed`.
        inside: the share of the feed the interval is taken at.

    Returns:
        sigma and lam, shape (...) (0 where the inputs are not finite or the feed is 0).
    """
    shape = a.shape[1:]
    n = len(a)
    columns = [np.moveaxis(v, 0, -1).reshape(-1, n) for v in (a, c, b)]
    at = (np.broadcast_to(feed, shape) * inside).reshape(-1)
    offset = at[:, None] * columns[0]
    directions = np.stack(columns[1:], axis=-1)  # (M, n, 2)
    sigma = np.zeros(len(offset))
    lam = np.zeros(len(offset))
    rows = np.flatnonzero(np.isfinite(directions).all(axis=(1, 2)) & np.isfinite(offset).all(1))
    high, _, _ = vertex_lp(offset[rows], directions[rows], qdot_max, np.array([1.0, 0.0]))
    low, _, _ = vertex_lp(offset[rows], directions[rows], qdot_max, np.array([-1.0, 0.0]))
    chosen = np.clip(0.0, -low, high)
    chosen = np.where(np.isfinite(chosen), chosen, 0.0)
    sigma[rows] = chosen
    rest = offset[rows] + chosen[:, None] * columns[1][rows]
    lam[rows] = _nearest_zero(rest, columns[2][rows], qdot_max)
    return sigma.reshape(shape), lam.reshape(shape)


def _nearest_zero(rest: np.ndarray, b: np.ndarray, qdot_max: np.ndarray) -> np.ndarray:
    """The lam nearest 0 with |rest_j + lam b_j| <= qdot_max_j: rest, b (M, n) -> (M,)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        one = (-qdot_max - rest) / b
        other = (qdot_max - rest) / b
    low = np.where(b == 0.0, -np.inf, np.minimum(one, other)).max(axis=1)
    high = np.where(b == 0.0, np.inf, np.maximum(one, other)).min(axis=1)
    lam = np.where(low > high, (low + high) / 2, np.clip(0.0, low, high))
    return np.where(np.isfinite(lam), lam, 0.0)
