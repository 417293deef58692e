"""The free spin's LPs of a redundant arm, compiled: the twins of :mod:`solver.core.dtf_redundant`.

dtf.md section 3 with cam.md section 2's free spin, robots.md section 5: at each configuration
of a seven-joint arm the DTF is the LP max s s.t. |s a_j + sigma c_j + lam b_j| <= qdot_max_j
in (s, sigma, lam), and the spin schedule asks, at a feed, for the interval of sigma of the LP
in (sigma, lam). Both take their optimum at a vertex: d of the constraints tight, every choice
of d joints and signs tried, the feasible ones kept, the best taken, as
:func:`solver.core.dtf_redundant.vertex_lp` does in numpy. Here each configuration is one loop:
a choice of joints is inverted once (the adjugate) for its 2^d sign choices, and a vertex is
checked against every joint only when it beats the best found so far (the same first maximum
in the same order as numpy's argmax). About 40 times faster than numpy on the Panda, with the
GIL released.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core import dtf_redundant, kernel_arrays
from solver.core.compiled_cache import drop_stale_caches
from solver.core.dtf_redundant import VERTEX_DET_RTOL, VERTEX_RTOL
from solver.core.kernel_arrays import kernel_array

# The LPs build in the vertex tolerances of solver.core.dtf_redundant: an edit there changes
# their machine code, which numba's cache (keyed by this file alone) would otherwise keep.
_SOURCES = [Path(__file__), Path(str(dtf_redundant.__file__)), Path(str(kernel_arrays.__file__))]
drop_stale_caches(Path(__file__).stem, _SOURCES, [Path(__file__)])

_INSIDE = 1.0 - 1e-12  # as solver.core.dtf_redundant.spin_rate_at_feed


@njit(cache=True, nogil=True, error_model="numpy")
def spin_speeds(a, c, b, qdot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`solver.core.dtf_redundant.spin_speed` at M configurations.

    Args:
        a: shape (M, n), rad/s per unit s.
        c: shape (M, n), rad/s per unit sigma.
        b: shape (M, n), rad/s per unit lam.
        qdot_max: shape (n,), rad/s.

    Returns:
        speed: shape (M,), the optimum s (NaN where an input is not finite or no vertex is
        feasible); limiting: shape (M,), of the optimum's three tight joints the one with the
        least (|c_j| + |b_j|) / qdot_max_j.
    """
    n_rows, n = a.shape
    speed = np.full(n_rows, np.nan)
    limiting = np.zeros(n_rows, dtype=np.int64)
    g = np.empty((3, 3))
    inv = np.empty((3, 3))
    for m in range(n_rows):
        finite = True
        for j in range(n):
            finite = finite and math.isfinite(a[m, j] + c[m, j] + b[m, j])
        if not finite:
            continue
        best = -np.inf
        tight = (0, 1, 2)
        for i in range(n):
            for j in range(i + 1, n):
                for k in range(j + 1, n):
                    rows = (i, j, k)
                    scale = 1.0
                    for r in range(3):
                        g[r, 0], g[r, 1], g[r, 2] = a[m, rows[r]], c[m, rows[r]], b[m, rows[r]]
                        scale *= math.sqrt(g[r, 0] ** 2 + g[r, 1] ** 2 + g[r, 2] ** 2)
                    det = (
                        g[0, 0] * (g[1, 1] * g[2, 2] - g[1, 2] * g[2, 1])
                        - g[0, 1] * (g[1, 0] * g[2, 2] - g[1, 2] * g[2, 0])
                        + g[0, 2] * (g[1, 0] * g[2, 1] - g[1, 1] * g[2, 0])
                    )
                    if not abs(det) > VERTEX_DET_RTOL * scale:
                        continue
                    for r in range(3):  # the adjugate over det: G^-1
                        r1, r2 = (r + 1) % 3, (r + 2) % 3
                        for col in range(3):
                            c1, c2 = (col + 1) % 3, (col + 2) % 3
                            inv[col, r] = (g[r1, c1] * g[r2, c2] - g[r1, c2] * g[r2, c1]) / det
                    limit_i, limit_j, limit_k = qdot_max[i], qdot_max[j], qdot_max[k]
                    for sign in range(8):  # itertools.product((-1, 1), repeat=3) order
                        rhs_i = limit_i if sign & 4 else -limit_i
                        rhs_j = limit_j if sign & 2 else -limit_j
                        rhs_k = limit_k if sign & 1 else -limit_k
                        s = inv[0, 0] * rhs_i + inv[0, 1] * rhs_j + inv[0, 2] * rhs_k
                        if not s > best:
                            continue
                        sigma = inv[1, 0] * rhs_i + inv[1, 1] * rhs_j + inv[1, 2] * rhs_k
                        lam = inv[2, 0] * rhs_i + inv[2, 1] * rhs_j + inv[2, 2] * rhs_k
                        feasible = True
                        for joint in range(n):
                            load = a[m, joint] * s + c[m, joint] * sigma + b[m, joint] * lam
                            if not abs(load) <= qdot_max[joint] * (1.0 + VERTEX_RTOL):
                                feasible = False
                                break
                        if feasible:
                            best, tight = s, rows
        if best > -np.inf:
            speed[m] = best
        least = np.inf
        for joint in tight:
            help_ = (abs(c[m, joint]) + abs(b[m, joint])) / qdot_max[joint]
            if help_ < least:
                least, limiting[m] = help_, joint
    return speed, limiting


@njit(cache=True, nogil=True, error_model="numpy")
def _sigma_bound(offset, c, b, qdot_max, direction):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Max direction * sigma s.t. |offset_j + sigma c_j + lam b_j| <= qdot_max_j; NaN: none.

    offset, c, b: shape (n,); direction: +1 or -1 (vertex_lp's objective [direction, 0]).
    """
    n = len(offset)
    best = -np.inf
    for i in range(n):
        for j in range(i + 1, n):
            norm_i = math.sqrt(c[i] ** 2 + b[i] ** 2)
            norm_j = math.sqrt(c[j] ** 2 + b[j] ** 2)
            det = c[i] * b[j] - b[i] * c[j]
            if not abs(det) > VERTEX_DET_RTOL * norm_i * norm_j:
                continue
            for sign in range(4):  # itertools.product((-1, 1), repeat=2) order
                rhs_i = (qdot_max[i] if sign & 2 else -qdot_max[i]) - offset[i]
                rhs_j = (qdot_max[j] if sign & 1 else -qdot_max[j]) - offset[j]
                sigma = (b[j] * rhs_i - b[i] * rhs_j) / det
                score = direction * sigma
                if not score > best:
                    continue
                lam = (c[i] * rhs_j - c[j] * rhs_i) / det
                feasible = True
                for joint in range(n):
                    load = offset[joint] + c[joint] * sigma + b[joint] * lam
                    if not abs(load) <= qdot_max[joint] * (1.0 + VERTEX_RTOL):
                        feasible = False
                        break
                if feasible:
                    best = score
    return best if best > -np.inf else np.nan


@njit(cache=True, nogil=True, error_model="numpy")
def spin_rates_at_feed(a, c, b, qdot_max, feed):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`solver.core.dtf_redundant.spin_rate_at_feed` at M configurations.

    Args:
        a: shape (M, n), as for :func:`spin_speeds`.
        c: shape (M, n), as for :func:`spin_speeds`.
        b: shape (M, n), as for :func:`spin_speeds`.
        qdot_max: shape (n,), rad/s.
        feed: shape (M,), at most each configuration's :func:`spin_speeds`.

    Returns:
        sigma and lam, shape (M,) (0 where an input is not finite or no sigma is feasible).
    """
    n_rows, n = a.shape
    sigma = np.zeros(n_rows)
    lam = np.zeros(n_rows)
    offset = np.empty(n)
    for m in range(n_rows):
        inside = feed[m] * _INSIDE
        finite = True
        for j in range(n):
            offset[j] = inside * a[m, j]
            finite = finite and math.isfinite(offset[j] + c[m, j] + b[m, j])
        if not finite:
            continue
        high = _sigma_bound(offset, c[m], b[m], qdot_max, 1.0)
        low = _sigma_bound(offset, c[m], b[m], qdot_max, -1.0)
        chosen = min(max(0.0, -low), high)
        if not (math.isfinite(low) and math.isfinite(high)):
            chosen = 0.0
        sigma[m] = chosen
        low_lam, high_lam = -np.inf, np.inf  # dtf_redundant._nearest_zero
        for j in range(n):
            if b[m, j] != 0.0:
                rest = offset[j] + chosen * c[m, j]
                one = (-qdot_max[j] - rest) / b[m, j]
                other = (qdot_max[j] - rest) / b[m, j]
                low_lam = max(low_lam, min(one, other))
                high_lam = min(high_lam, max(one, other))
        value = (low_lam + high_lam) / 2 if low_lam > high_lam else min(max(0.0, low_lam), high_lam)
        lam[m] = value if math.isfinite(value) else 0.0
    return sigma, lam


def _rows(v: np.ndarray) -> np.ndarray:
    """Component-first (n, ...) -> contiguous rows (M, n), as the kernels take them."""
    return kernel_array(np.moveaxis(v, 0, -1).reshape(-1, len(v)))


def spin_speed(
    a: np.ndarray, c: np.ndarray, b: np.ndarray, qdot_max: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solver.core.dtf_redundant.spin_speed`, compiled: the same arguments and results.

    Args:
        a: shape (n, ...), rad/s per unit s.
        c: shape (n, ...), rad/s per unit sigma.
        b: shape (n, ...), rad/s per unit lam.
        qdot_max: shape (n,), rad/s.

    Returns:
        speed and limiting, shape (...).
    """
    shape = np.broadcast_shapes(a.shape, c.shape, b.shape)
    a, c, b = (np.broadcast_to(v, shape) for v in (a, c, b))
    speed, limiting = spin_speeds(_rows(a), _rows(c), _rows(b), kernel_array(qdot_max))
    return speed.reshape(shape[1:]), limiting.reshape(shape[1:])


def spin_rate_at_feed(
    a: np.ndarray,
    c: np.ndarray,
    b: np.ndarray,
    qdot_max: np.ndarray,
    feed: np.ndarray,
    *,
    inside: float = _INSIDE,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solver.core.dtf_redundant.spin_rate_at_feed`, compiled: the same results.

    Args:
        a: shape (n, ...), as for :func:`spin_speed`.
        c: shape (n, ...), as for :func:`spin_speed`.
        b: shape (n, ...), as for :func:`spin_speed`.
        qdot_max: shape (n,), rad/s.
        feed: shape broadcasting to (...).
        inside: the share of the feed the rates are taken at (the kernel's own, _INSIDE, by
            default; another is given to the kernel as the feed scaled).

    Returns:
        sigma and lam, shape (...).
    """
    shape = np.broadcast_shapes(a.shape, c.shape, b.shape)
    a, c, b = (np.broadcast_to(v, shape) for v in (a, c, b))
    feeds = np.broadcast_to(feed, shape[1:]).reshape(-1)
    feeds = kernel_array(feeds if inside == _INSIDE else feeds * (inside / _INSIDE))
    sigma, lam = spin_rates_at_feed(_rows(a), _rows(c), _rows(b), kernel_array(qdot_max), feeds)
    return sigma.reshape(shape[1:]), lam.reshape(shape[1:])
