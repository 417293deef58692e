"""Closed-form distances from a capsule (a segment swept by a ball) to the cell's primitives.

Compiled scalar code (numba, ``nogil``) for the fast cell check (:mod:`solver.path.cell.sweep`):
the distance from a segment [a, b] of radius r to a halfspace, a sphere (or another capsule:
segment to segment) and a box, each exact where the shapes are apart (coal agrees, tested in
tests/solver/test_cell_closed_form.py). Where they overlap the values are only <= 0 (not coal's
penetration depth): the check takes such pairs to coal.

Segment to box: in the box's frame the squared distance from a(t) = a + t (b - a) is
sum_i max(|a_i(t)| - h_i, 0)^2, convex and quadratic between the parameters where a coordinate
crosses +-h_i; each piece's minimum, clamped to the piece, gives the exact minimum.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.path.cell.kernel_cache import drop_stale_cell_kernels

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _clamp01(x):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The value clamped to [0, 1]."""
    return 0.0 if x < 0.0 else (1.0 if x > 1.0 else x)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def segment_halfspace(a, b, radius, normal, offset):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Distance from the capsule [a, b] (radius) to the points p with normal . p <= offset."""
    da = normal[0] * a[0] + normal[1] * a[1] + normal[2] * a[2] - offset
    db = normal[0] * b[0] + normal[1] * b[1] + normal[2] * b[2] - offset
    return min(da, db) - radius


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def params(p1x, p1y, p1z, q1x, q1y, q1z, p2x, p2y, p2z, q2x, q2y, q2z):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`segment_params` of coordinates: no array (the sweep's inner loop).

    Ericson's "Real-Time Collision Detection" 5.1.9: the unclamped line parameters, clamped,
    the other one recomputed and clamped again; either segment may be a point.
    """
    d1x, d1y, d1z = q1x - p1x, q1y - p1y, q1z - p1z
    d2x, d2y, d2z = q2x - p2x, q2y - p2y, q2z - p2z
    rx, ry, rz = p1x - p2x, p1y - p2y, p1z - p2z
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    c = d1x * rx + d1y * ry + d1z * rz
    bb = d1x * d2x + d1y * d2y + d1z * d2z
    tiny = 1e-30
    if a <= tiny and e <= tiny:
        return 0.0, 0.0
    if a <= tiny:
        return 0.0, _clamp01(f / e)
    if e <= tiny:
        return _clamp01(-c / a), 0.0
    denom = a * e - bb * bb
    s = _clamp01((bb * f - c * e) / denom) if denom > 1e-14 * a * e else 0.0
    t = (bb * s + f) / e
    if t < 0.0:
        return _clamp01(-c / a), 0.0
    if t > 1.0:
        return _clamp01((bb - c) / a), 1.0
    return s, t


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def segment_params(p1, q1, p2, q2):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The parameters (s, t) of the closest points of the segments [p1, q1] and [p2, q2]."""
    return params(p1[0], p1[1], p1[2], q1[0], q1[1], q1[2],
                  p2[0], p2[1], p2[2], q2[0], q2[1], q2[2])  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def segment_segment(p1, q1, p2, q2):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Distance between the segments [p1, q1] and [p2, q2] (either may be a point)."""
    s, t = segment_params(p1, q1, p2, q2)
    total = 0.0
    for i in range(3):
        gap = p1[i] + (q1[i] - p1[i]) * s - p2[i] - (q2[i] - p2[i]) * t
        total += gap * gap
    return math.sqrt(total)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _side(x, half):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The face a coordinate x is beyond (+-half), or 0 within [-half, half]."""
    return half if x > half else (-half if x < -half else 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _axis_quadratic(a, d, half, mid):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """One coordinate's (t^2, t) coefficients of the squared distance on a piece, and its face."""
    side = _side(a + mid * d, half)
    if side == 0.0:
        return 0.0, 0.0, side
    return d * d, 2.0 * (a - side) * d, side


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _axis_gap(a, d, side, t):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """One coordinate's squared distance at t beyond its face (0 within)."""
    if side == 0.0:
        return 0.0
    gap = a - side + t * d
    return gap * gap


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _piece(a0, a1, a2, d0, d1, d2, h0, h1, h2, lo, hi):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Smallest squared distance to the box over t in [lo, hi], where no coordinate crosses."""
    mid = 0.5 * (lo + hi)
    qa0, qb0, side0 = _axis_quadratic(a0, d0, h0, mid)
    qa1, qb1, side1 = _axis_quadratic(a1, d1, h1, mid)
    qa2, qb2, side2 = _axis_quadratic(a2, d2, h2, mid)
    qa, qb = qa0 + qa1 + qa2, qb0 + qb1 + qb2  # the piece's quadratic: qa t^2 + qb t + ...
    t = lo if qa <= 0.0 else min(max(-qb / (2.0 * qa), lo), hi)
    total = _axis_gap(a0, d0, side0, t) + _axis_gap(a1, d1, side1, t)
    return total + _axis_gap(a2, d2, side2, t), t


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _insert(cuts, count, t):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Insert t into the sorted ``cuts[:count]``; the new count."""
    k = count
    while k > 0 and cuts[k - 1] > t:
        cuts[k] = cuts[k - 1]
        k -= 1
    cuts[k] = t
    return count + 1


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _axis_cuts(cuts, count, a, d, half):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Insert the parameters in (0, 1) where a coordinate crosses -half and +half."""
    if d != 0.0:
        t = (-half - a) / d
        if 0.0 < t < 1.0:
            count = _insert(cuts, count, t)
        t = (half - a) / d
        if 0.0 < t < 1.0:
            count = _insert(cuts, count, t)
    return count


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def box_param(a0, a1, a2, b0, b1, b2, h0, h1, h2, cuts):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`segment_box_param` of coordinates: no array but the work space ``cuts``."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    cuts[0] = 0.0
    count = _axis_cuts(cuts, 1, a0, d0, h0)
    count = _axis_cuts(cuts, count, a1, d1, h1)
    count = _axis_cuts(cuts, count, a2, d2, h2)
    cuts[count] = 1.0
    best, where = _piece(a0, a1, a2, d0, d1, d2, h0, h1, h2, 0.0, 0.0)  # a point, or the start
    for k in range(count):
        if cuts[k + 1] > cuts[k]:
            value, t = _piece(a0, a1, a2, d0, d1, d2, h0, h1, h2, cuts[k], cuts[k + 1])
            if value < best:
                best, where = value, t
    return best, where


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def segment_box_param(a, b, half, cuts):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The squared distance from the segment [a, b] to the box [-half, half], and where.

    Both in the box's frame; the second value is the segment's parameter of its closest point.
    ``cuts`` (8,) is work space for the pieces' ends, sorted in place.
    """
    return box_param(a[0], a[1], a[2], b[0], b[1], b[2], half[0], half[1], half[2], cuts)


@njit(cache=True, nogil=True, error_model="numpy")
def segment_box(a, b, half):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Distance from the segment [a, b] to the box [-half, half], both in the box's frame."""
    return math.sqrt(segment_box_param(a, b, half, np.empty(8))[0])
