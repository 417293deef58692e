"""Conservative advancement along a path's configurations, compiled (the cell sweep's scan).

From a pair's distance d at configuration i, the pair is clear at every later configuration m
with sum_j w_j |q_mj - q_ij| < d - clearance (:mod:`solver.path.cell.bounds`): the scan finds
the first m where that sum reaches the slack. It runs for every pair the sweep
(:mod:`solver.path.cell.sweep`) computes, over the configurations up to the next check: a
third of the UR5e's sweep was this loop, one chained sum of n products per configuration.
For six joints the sum is three independent pairs added at the end (loads of the weights and
of configuration i hoisted out of the loop); the rounding differs from a left-to-right sum by
an ulp, which only moves where a pair is next checked, never what a check answers.

Before that scan, a search on the path's joint travel (:func:`travelled`): |q_mj - q_ij| is at
most the joint's travel from i to m, which only grows with m, so an exponential then binary
search finds the configurations the travel alone proves clear, and the scan goes on from there
to the same answer. A far object's pair (most pairs of a cell with many objects) is proven
clear to the path's end in a few looks, where the scan went through every configuration: the
UR5e's ERK-size map with 100 objects in its cell took 428 ms before it, 296 ms with it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.path.cell.kernel_cache import drop_stale_cell_kernels

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in


@njit(cache=True, nogil=True, error_model="numpy")
def travelled(configurations):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Each joint's travel along the configurations: shape (M, n), row m the sum to m of |dq|."""
    count, n = configurations.shape
    travel = np.empty((count, n))
    for j in range(n):
        travel[0, j] = 0.0
    for m in range(1, count):
        for j in range(n):
            travel[m, j] = travel[m - 1, j] + abs(configurations[m, j] - configurations[m - 1, j])
    return travel


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _travel_proves(travel, weights, p, index, slack):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The last configuration after ``index`` whose weighted travel from it stays under slack.

    Kept under the slack by a margin far above the sums' rounding (the travel's running sums
    err by at most count ulps of the total), so every configuration it returns the scan of
    :func:`clear_until` would pass too, and the scan's answer is unchanged.
    """
    count, n = travel.shape
    total = 0.0
    for j in range(n):
        total += weights[p, j] * travel[count - 1, j]
    bound = slack - 1e-9 - 1e-15 * (count * total + abs(slack))
    good, bad, step = index, count, 1
    while True:  # exponential first: most pairs are due again within a few configurations
        m = min(index + step, count - 1)
        if m <= good:
            break
        moved = 0.0
        for j in range(n):
            moved += weights[p, j] * (travel[m, j] - travel[index, j])
        if moved >= bound:
            bad = m
            break
        good = m
        if m == count - 1:
            return good
        step *= 2
    while bad - good > 1:
        m = (good + bad) // 2
        moved = 0.0
        for j in range(n):
            moved += weights[p, j] * (travel[m, j] - travel[index, j])
        if moved >= bound:
            bad = m
        else:
            good = m
    return good


@njit(cache=True, nogil=True, error_model="numpy")
def clear_until(configurations, travel, weights, p, index, slack):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The last configuration after ``index`` that pair p's slack proves clear (m - 1 above).

    Args:
        configurations: shape (M, n), rad, the path's configurations.
        travel: shape (M, n), rad, :func:`travelled` of them.
        weights: shape (P, n), m/rad, how fast each pair can close in.
        p: the pair.
        index: the configuration its distance was computed at.
        slack: m, that distance less the clearance.

    Returns:
        The index of the last configuration proven clear (``index`` itself at least).
    """
    count, n = configurations.shape
    m = _travel_proves(travel, weights, p, index, slack) + 1
    if n == 6:
        w0, w1, w2 = weights[p, 0], weights[p, 1], weights[p, 2]
        w3, w4, w5 = weights[p, 3], weights[p, 4], weights[p, 5]
        c0, c1, c2 = configurations[index, 0], configurations[index, 1], configurations[index, 2]
        c3, c4, c5 = configurations[index, 3], configurations[index, 4], configurations[index, 5]
        while m < count:
            row = configurations[m]
            first = w0 * abs(row[0] - c0) + w1 * abs(row[1] - c1)
            second = w2 * abs(row[2] - c2) + w3 * abs(row[3] - c3)
            third = w4 * abs(row[4] - c4) + w5 * abs(row[5] - c5)
            if first + second + third >= slack:
                break
            m += 1
        return m - 1
    while m < count:
        moved = 0.0
        for j in range(n):
            moved += weights[p, j] * abs(configurations[m, j] - configurations[index, j])
        if moved >= slack:
            break
        m += 1
    return m - 1
