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


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _clamp01(x):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The value clamped to [0, 1]."""
    return 0.0 if x < 0.0 else (1.0 if x > 1.0 else x)


@njit(cache=True, nogil=True, error_model="numpy")
def segment_halfspace(a, b, radius, normal, offset):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Distance from the capsule [a, b] (radius) to the points p with normal . p <= offset."""
    da = normal[0] * a[0] + normal[1] * a[1] + normal[2] * a[2] - offset
    db = normal[0] * b[0] + normal[1] * b[1] + normal[2] * b[2] - offset
    return min(da, db) - radius


@njit(cache=True, nogil=True, error_model="numpy")
def segment_params(p1, q1, p2, q2):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The parameters (s, t) of the closest points of the segments [p1, q1] and [p2, q2].

    Ericson's "Real-Time Collision Detection" 5.1.9: the unclamped line parameters, clamped,
    the other one recomputed and clamped again; either segment may be a point. Scalar code:
    no array is made.
    """
    a = e = f = c = bb = 0.0
    for i in range(3):
        d1, d2, r = q1[i] - p1[i], q2[i] - p2[i], p1[i] - p2[i]
        a += d1 * d1
        e += d2 * d2
        f += d2 * r
        c += d1 * r
        bb += d1 * d2
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


@njit(cache=True, nogil=True, error_model="numpy")
def _box_piece(a, b, half, lo, hi):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Smallest squared distance to the box over t in [lo, hi], where no coordinate crosses."""
    mid = 0.5 * (lo + hi)
    qa, qb = 0.0, 0.0  # the piece's quadratic: qa t^2 + qb t + ...
    for i in range(3):
        d = b[i] - a[i]
        side = _side(a[i] + mid * d, half[i])
        if side != 0.0:
            qa += d * d
            qb += 2.0 * (a[i] - side) * d
    t = lo if qa <= 0.0 else min(max(-qb / (2.0 * qa), lo), hi)
    total = 0.0
    for i in range(3):
        d = b[i] - a[i]
        side = _side(a[i] + mid * d, half[i])
        if side != 0.0:
            gap = a[i] - side + t * d
            total += gap * gap
    return total, t


@njit(cache=True, nogil=True, error_model="numpy")
def segment_box_param(a, b, half, cuts):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The squared distance from the segment [a, b] to the box [-half, half], and where.

    Both in the box's frame; the second value is the segment's parameter of its closest point.
    ``cuts`` (8,) is work space for the pieces' ends, sorted in place.
    """
    cuts[0] = 0.0
    count = 1
    for i in range(3):
        d = b[i] - a[i]
        if d != 0.0:
            for sign in (-1.0, 1.0):
                t = (sign * half[i] - a[i]) / d
                if 0.0 < t < 1.0:
                    k = count  # insertion into the sorted cuts
                    while k > 0 and cuts[k - 1] > t:
                        cuts[k] = cuts[k - 1]
                        k -= 1
                    cuts[k] = t
                    count += 1
    cuts[count] = 1.0
    best, where = _box_piece(a, b, half, 0.0, 0.0)  # a point, or the start
    for k in range(count):
        if cuts[k + 1] > cuts[k]:
            value, t = _box_piece(a, b, half, cuts[k], cuts[k + 1])
            if value < best:
                best, where = value, t
    return best, where


@njit(cache=True, nogil=True, error_model="numpy")
def segment_box(a, b, half):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Distance from the segment [a, b] to the box [-half, half], both in the box's frame."""
    return math.sqrt(segment_box_param(a, b, half, np.empty(8))[0])
