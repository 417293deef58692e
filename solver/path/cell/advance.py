"""Conservative advancement along a path's configurations, compiled (the cell sweep's scan).

From a pair's distance d at configuration i, the pair is clear at every later configuration m
with sum_j w_j |q_mj - q_ij| < d - clearance (:mod:`solver.path.cell.bounds`): the scan finds
the first m where that sum reaches the slack. It runs for every pair the sweep
(:mod:`solver.path.cell.sweep`) computes, over the configurations up to the next check: a
third of the UR5e's sweep was this loop, one chained sum of n products per configuration.
For six joints the sum is three independent pairs added at the end (loads of the weights and
of configuration i hoisted out of the loop); the rounding differs from a left-to-right sum by
an ulp, which only moves where a pair is next checked, never what a check answers.
"""

from __future__ import annotations

from numba import njit

from solver.path.cell.kernel_cache import drop_stale_cell_kernels

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in


@njit(cache=True, nogil=True, error_model="numpy")
def clear_until(configurations, weights, p, index, slack):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The last configuration after ``index`` that pair p's slack proves clear (m - 1 above).

    Args:
        configurations: shape (M, n), rad, the path's configurations.
        weights: shape (P, n), m/rad, how fast each pair can close in.
        p: the pair.
        index: the configuration its distance was computed at.
        slack: m, that distance less the clearance.

    Returns:
        The index of the last configuration proven clear (``index`` itself at least).
    """
    count, n = configurations.shape
    m = index + 1
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
