"""Position limits of a joint path in (cos, sin) pairs, for both map kernels (dtf.md section 9).

The fast tests need no angle: a joint whose limits span more than 2 pi fits when the path's
total turning (bounded from the squared chords of the (cos, sin) steps) leaves a full turn of
room; a joint whose range is a turn or less fits when every waypoint is inside its arc and no
step's short arc passes through the gap opposite. A branch that neither test clears forms its
angles (atan2, :func:`unwrapped`) and runs the exact test of :func:`solver.path.tracking.track`
(:func:`first_outside`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import EDGE
from solver.families.kernels import N_JOINTS

_TWO_PI = 2 * math.pi
NO_LIMIT, WIDE, NARROW = 0, 1, 2
# Fast tests of the position limits leave this much (rad) to rounding; a branch nearer than
# that to failing them goes to the exact test.
_MARGIN = 1e-9
# 2 asin(c / 2) / c, the turn per unit chord, is at most this for chords up to 0.5 (a turn of
# 0.505 rad) and at most pi / 2 for any chord.
_CHORD_SMALL = 0.5
_TURN_PER_CHORD_SMALL = 1.0108


def limit_modes(lower: np.ndarray, upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per joint: how the kernel tests its position limits, and the arc of a narrow range.

    Returns:
        modes: shape (n,), 0 no limit, 1 a range of more than 2 pi, 2 one of 2 pi or less;
        arc: shape (n, 3), cos and sin of the range's middle and cos of its half width.
    """
    width = upper - lower
    wide = width > _TWO_PI + 1e-12
    modes = np.where(~np.isfinite(width), NO_LIMIT, np.where(wide, WIDE, NARROW))
    finite = np.isfinite(width)  # an unlimited side (-inf or inf) has no middle: no NaN made
    middle = (np.where(finite, lower, 0.0) + np.where(finite, upper, 0.0)) / 2
    half = np.where(finite, width / 2, 0.0)
    arc = np.column_stack([np.cos(middle), np.sin(middle), np.cos(half)])
    return modes.astype(np.int64), arc


@njit(cache=True, error_model="numpy", nogil=True)
def wrapped_step(step):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """A step between two angles in [-pi, pi] brought into [-pi, pi], as track() does."""
    if step > math.pi:
        return step - _TWO_PI
    if step < -math.pi:
        return step + _TWO_PI
    return step


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def unwrap_joint(cq, sq, b, j, out):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint j of :func:`unwrapped`'s path into ``out`` (W,), rad."""
    first = math.atan2(sq[b, j, 0], cq[b, j, 0])
    previous, total = first, 0.0
    out[0] = first
    for w in range(1, out.shape[0]):
        angle = math.atan2(sq[b, j, w], cq[b, j, w])
        total += wrapped_step(angle - previous)
        out[w] = first + total
        previous = angle


@njit(cache=True, error_model="numpy", nogil=True)
def unwrapped(cq, sq, b):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch b's joint path (W, 6), rad: the angles of its pairs, unwrapped by the wrapped steps.

    :func:`solver.path.tracking.track`'s path: the first waypoint's angle plus the running sum of
    the steps, each brought into [-pi, pi].
    """
    dof, n_waypoints = cq.shape[1], cq.shape[2]
    path = np.empty((n_waypoints, dof))
    for j in range(dof):
        unwrap_joint(cq, sq, b, j, path[:, j])
    return path


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def first_outside_one(values, low, high):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`first_outside` of one joint's path ``values`` (W,) and its limits."""
    low_run, high_run = values[0], values[0]
    for w in range(values.shape[0]):
        low_run = min(low_run, values[w])
        high_run = max(high_run, values[w])
        k_low = math.ceil((low - low_run) / _TWO_PI - EDGE)
        k_high = math.floor((high - high_run) / _TWO_PI + EDGE)
        if k_low > k_high:
            return w
    return values.shape[0]


@njit(cache=True, error_model="numpy", nogil=True)
def first_outside(path, lower, upper):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The first waypoint of a joint path (W, n) whose range no 2 pi copy holds (W: none).

    :func:`solver.path.tracking.track`'s test: the running range of each joint (a range that fits
    holds every shorter one, so no test of the whole path is needed first); the path leaves its
    limits where its first joint does.
    """
    first = path.shape[0]
    for j in range(path.shape[1]):
        first = min(first, first_outside_one(path[:, j], lower[j], upper[j]))
    return first


@njit(cache=True, error_model="numpy", nogil=True)
def first_outside_pairs(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    cq, sq, b, i, lower, upper, modes, chords2, largest2, inside, crossed
):
    """The first waypoint where branch b's path leaves its position limits (W: none).

    The fast tests on the sums of row i that the kernel keeps along the path (``chords2`` and
    ``largest2`` of the wide joints' steps, ``inside`` and ``crossed`` of the narrow ones, shape
    (B, n)); only for the joints they do not clear, the angles and the exact test (a path
    leaves its limits where its first joint does: an OPW arm's wrist with 10 degrees of room
    beyond a turn fails the fast test on most paths, and its five other joints need no angle).
    """
    n_waypoints = cq.shape[2]
    first = n_waypoints
    values = np.empty(0)
    for j in range(N_JOINTS):
        if modes[j] == NO_LIMIT:
            continue
        if modes[j] == WIDE:
            # A chord c turns by 2 asin(c / 2) <= factor c; the sum of the chords is at most
            # sqrt(segments x the sum of their squares) (Cauchy-Schwarz).
            small = largest2[i, j] <= _CHORD_SMALL * _CHORD_SMALL
            factor = _TURN_PER_CHORD_SMALL if small else math.pi / 2
            turning = factor * math.sqrt((n_waypoints - 1) * chords2[i, j])
            exact = turning > upper[j] - lower[j] - _TWO_PI - _MARGIN
        else:  # every waypoint inside the arc, no step through the gap
            exact = inside[i, j] <= _MARGIN or crossed[i, j]
        if exact:  # this joint's angles and its exact test (the others fit: proven above)
            if values.shape[0] == 0:
                values = np.empty(n_waypoints)
            unwrap_joint(cq, sq, b, j, values)
            first = min(first, first_outside_one(values, lower[j], upper[j]))
    return first


@njit(cache=True, error_model="numpy", nogil=True)
def shift_to_copy(path, lower, upper):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Move each joint of a feasible path (W, n) to the 2 pi copy that track() reports, in place.

    :func:`solver.path.tracking.track`'s ``shifted``: of the copies 2 pi k that fit the whole
    path, the one whose first waypoint is nearest zero (k rounded half to even, as numpy.round).
    """
    for j in range(path.shape[1]):
        low, high = path[0, j], path[0, j]
        for w in range(path.shape[0]):
            low = min(low, path[w, j])
            high = max(high, path[w, j])
        k_low = np.ceil((lower[j] - low) / _TWO_PI - EDGE)
        k_high = np.floor((upper[j] - high) / _TWO_PI + EDGE)
        shift = min(max(np.rint(-path[0, j] / _TWO_PI), k_low), k_high)
        if shift != 0.0:
            for w in range(path.shape[0]):
                path[w, j] += _TWO_PI * shift


# asin(x) = x (1 + x^2 / 6 + 3 x^4 / 40 + ...): its terms to x^15, exact to rounding for
# |x| <= _SERIES (the next term is below 1e-16 of the sum).
_SERIES = 0.125
_ASIN = (1.0, 1.0 / 6.0, 3.0 / 40.0, 5.0 / 112.0, 35.0 / 1152.0, 63.0 / 2816.0, 231.0 / 13312.0,
         143.0 / 10240.0)  # fmt: skip
# rad: a step this near pi or nearer is formed from the two angles (see :func:`pair_step`).
_HALF_TURN = 1e-9


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def series_holds(cross, dot):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether :func:`small_step` gives the step of a pair's ``cross`` and ``dot`` products.

    Without a branch (``&``), so that a loop of them vectorises; False where either is NaN.
    """
    return (dot > 0.0) & (abs(cross) <= _SERIES)


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def small_step(cross):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """asin(cross) by its series (:data:`_ASIN`), for |cross| <= _SERIES and a positive dot."""
    x2 = cross * cross
    series = _ASIN[7]
    for term in range(6, -1, -1):
        series = series * x2 + _ASIN[term]
    return cross * series


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def pair_step(c0, s0, c1, s1):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The angle from the (cos, sin) pair (c0, s0) to (c1, s1), in [-pi, pi].

    As :func:`wrapped_step` gives it: asin of their cross product by its series where the step
    is small (no atan2), atan2 of cross and dot products otherwise. A step of about half a turn
    (within _HALF_TURN of pi) is :func:`wrapped_step` of the two angles' difference, as
    :func:`solver.path.tracking.track` forms it: its sign is then the difference's, not that of
    a cross product rounded to a signed zero (the pairs (1, 0) and (-1, -0.0) are a step of
    -pi there and +pi by atan2(+0.0, -1)). Such steps happen only where the step bound does not
    apply (a rapid between passes), and the sign decides which way a joint has turned: a path
    that flips a joint by half a turn at several rapids would otherwise drift by whole turns
    and fail its position limits where the numpy pipeline's holds them.
    """
    cross = c0 * s1 - s0 * c1
    dot = c0 * c1 + s0 * s1
    if series_holds(cross, dot):
        return small_step(cross)
    step = math.atan2(cross, dot)
    if abs(step) > math.pi - _HALF_TURN:
        return wrapped_step(math.atan2(s1, c1) - math.atan2(s0, c0))
    return step


@njit(cache=True, error_model="numpy", nogil=True)
def relative_path(cq, sq, b, first):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch b's joint path (W, 6), rad: from its first angle (or 0), the sum of its steps.

    Each step is the angle between neighbouring (cos, sin) pairs (:func:`pair_step`). With
    ``first`` the path starts at the first waypoint's angle, as :func:`unwrapped`'s (to
    rounding); without, at 0: it then differs from track()'s 2 pi copy by a constant per joint,
    which a second difference does not see.
    """
    dof, n_waypoints = cq.shape[1], cq.shape[2]
    path = np.empty((n_waypoints, dof))
    for j in range(dof):
        path[0, j] = math.atan2(sq[b, j, 0], cq[b, j, 0]) if first else 0.0
    for w in range(1, n_waypoints):
        for j in range(dof):
            step = pair_step(cq[b, j, w - 1], sq[b, j, w - 1], cq[b, j, w], sq[b, j, w])
            path[w, j] = path[w - 1, j] + step
    return path
