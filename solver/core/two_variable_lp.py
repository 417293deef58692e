"""The exact two-variable LP of the DTF, batched: a speed s and one free rate sigma.

Both the free tool spin of a six-joint arm (cam.md section 2, sigma the spin rate) and the null
space of a seven-joint arm (robots.md section 5, sigma the null-space rate) reduce the DTF LP of
:mod:`solver.core.dtf` to max s s.t. |s a_j + sigma b_j| <= qdot_max_j, solved here exactly and
vectorised, with the sigma to run at a given speed.

Shapes: joints on the first axis, (n, ...), and the batch axes after it; joint speeds in rad/s.
"""

from __future__ import annotations

import numpy as np


def two_variable_speed(
    a: np.ndarray, b: np.ndarray, qdot_max: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The exact two-variable LP, batched: max s s.t. |s a_j + sigma b_j| <= qdot_max_j.

    robots.md section 5 (a = J^+ t_hat, b a null-space vector of a 7-joint arm) and cam.md
    section 2 (a = J^-1 t_hat, b = J^-1 [0; z_tool], sigma the free tool spin rate). For fixed s,
    joint j allows sigma in an interval of centre -s a_j / b_j and half-width m_j / |b_j|; all
    intervals meet exactly when every two do (one dimension), and two meet while
    s <= (m_j |b_k| + m_k |b_j|) / |a_j b_k - a_k b_j|. So the optimum is the least of these over
    the pairs j < k: exact, with no vertex search (a joint with b_j = 0 gives m_j / |a_j| in
    every pair, as the one-variable closed form does).

    Args:
        a: shape (n, ...), joint speeds per unit s (rad/s per m/s).
        b: shape (n, ...), joint speeds per unit sigma.
        qdot_max: shape (n,), rad/s, > 0.

    Returns:
        speed: shape (...), the optimum s (inf where nothing bounds it, NaN where a or b is);
        limiting: shape (...), the joint on its limit that bounds s: of the binding pair, the
        one sigma helps less (smaller |b_j| / qdot_max_j; for a straight spindle, never the
        spindle joint).
    """
    limits = np.asarray(qdot_max, dtype=float).reshape((-1,) + (1,) * (a.ndim - 1))
    rows, cols = np.triu_indices(len(a), k=1)
    abs_b = np.abs(b)
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = (limits[rows] * abs_b[cols] + limits[cols] * abs_b[rows]) / np.abs(
            a[rows] * b[cols] - a[cols] * b[rows]
        )
        help_ = abs_b / limits
    nan = np.isnan(bound)
    pair = np.where(nan, np.inf, bound).argmin(axis=0)
    speed = np.take_along_axis(np.where(nan, np.inf, bound), pair[None], axis=0)[0]
    speed = np.where(np.isnan(a).any(axis=0) | np.isnan(b).any(axis=0), np.nan, speed)
    first, second = rows[pair], cols[pair]
    first_help = np.take_along_axis(help_, first[None], axis=0)[0]
    second_help = np.take_along_axis(help_, second[None], axis=0)[0]
    limiting = np.where(first_help <= second_help, first, second)
    return speed, limiting


def spin_rate_nearest_zero(
    a: np.ndarray,
    b: np.ndarray,
    qdot_max: np.ndarray,
    speed: np.ndarray,
    *,
    inside: float = 1.0 - 1e-12,
) -> np.ndarray:
    """The sigma nearest 0 with |speed a_j + sigma b_j| <= qdot_max_j for every joint j.

    At the optimum of :func:`two_variable_speed` the interval of sigma is a point, which rounding
    can make empty, and a joint with b_j near 0 bounds it by (noise) / b_j: so the interval is
    taken at speed (1 - 1e-12) (``inside``), where it is a short interval, and the joints are
    then within their limits to about 1e-12 (times |speed a_j| / qdot_max_j, up to a few
    hundred where the spin offsets a large joint speed).

    Args:
        a: shape (n, ...), joint speeds per unit s, as for :func:`two_variable_speed`.
        b: shape (n, ...), joint speeds per unit sigma.
        qdot_max: shape (n,), rad/s.
        speed: shape (...), at most the optimum of :func:`two_variable_speed`.
        inside: the share of the speed the interval is taken at.

    Returns:
        shape (...), sigma (0 where no joint constrains it or the inputs are not finite).
    """
    limits = np.asarray(qdot_max, dtype=float).reshape((-1,) + (1,) * (a.ndim - 1))
    at = np.asarray(speed) * inside
    with np.errstate(divide="ignore", invalid="ignore"):
        one = (-limits - at * a) / b
        other = (limits - at * a) / b
    low = np.where(b == 0.0, -np.inf, np.minimum(one, other)).max(axis=0)
    high = np.where(b == 0.0, np.inf, np.maximum(one, other)).min(axis=0)
    sigma = np.where(low > high, (low + high) / 2, np.clip(0.0, low, high))
    return np.where(np.isfinite(sigma), sigma, 0.0)
