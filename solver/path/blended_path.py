"""One pass's blended joint path on a grid (motion.md section 4).

The joint path mu_acc is defined on, and the cycle time (:mod:`solver.path.cycle_time`) runs
on: the pass's tracked joint path q(s), piecewise linear in the tool point's arc length
(continued along its first and last segment beyond the pass ends), with every corner rounded
by a parabolic blend of length b around its waypoint and straight in between: the running mean
of q over a window of length b, so q_s(s) = (q(s + b/2) - q(s - b/2)) / b and q_ss(s) =
(q'(s + b/2) - q'(s - b/2)) / b. Where waypoints are at least b apart, q_ss is the corner's
slope change over b in its blend, the D_i of mu_acc, and 0 between blends, where the feed may
rise again; where they are closer, the blends overlap into a smooth path. Along the path, a
joint's speed is q_s sdot and its acceleration q_s sddot + q_ss sdot^2. The path is given on a
grid of the blends' ends (on which q_ss is constant and q_s linear between grid points), each
blend cut in :data:`BLEND_STEPS`, q_ss of each grid point that of the stretch after it.
"""

from __future__ import annotations

import numpy as np

# Grid steps a blend length, everywhere (the feed rises and falls again between blends).
# toppra's time on the grid converges to the path's from above, in proportion to the step (on
# the README example at 10 rad/s^2: 1.305 s at 4 steps, 1.269 at 8, 1.251 at 16, 1.240 at 32;
# toppra on a uniform 20 um grid 1.233).
BLEND_STEPS = 16
# The grid's steps a waypoint at most, so that the work is bounded by the waypoints whatever
# the length: where waypoints are more than b apart the grid is coarser than b / BLEND_STEPS
# (on the README example, 2.4 mm apart, b / 13: 1.255 s).
MAX_STEPS_A_WAYPOINT = 16
MIN_GRID = 64  # grid points a pass at least: rest to rest needs room to speed up


def blended_path(
    q: np.ndarray, s: np.ndarray, blend_length: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One pass's blended joint path on its grid (see the module).

    Args:
        q: shape (M, n), rad, the joint path of the pass.
        s: shape (M,), m, the arc lengths from the pass start (ascending, s_0 = 0).
        blend_length: b, m.

    Returns:
        grid: shape (G,), m, from 0 to s_end: every waypoint and every blend's ends within
        the pass, in steps of b / :data:`BLEND_STEPS` (at most :data:`MAX_STEPS_A_WAYPOINT`
        a waypoint) and at least :data:`MIN_GRID` points; q_s (G, n), rad/m; q_ss (G, n),
        rad/m^2, on the stretch after each grid point (the last: before it).
    """
    b, end = blend_length, float(s[-1])
    span = np.maximum(np.diff(s), 1e-300)
    slope = np.diff(q, axis=0) / span[:, None]  # (M - 1, n), q' on each segment

    def path_at(target: np.ndarray) -> np.ndarray:
        """q(s) continued along the end segments beyond the pass."""
        values = np.column_stack([np.interp(target, s, q[:, j]) for j in range(q.shape[1])])
        values += np.minimum(target, 0.0)[:, None] * slope[0]
        values += np.maximum(target - end, 0.0)[:, None] * slope[-1]
        return values

    def slope_at(target: np.ndarray) -> np.ndarray:
        """q'(s), right-continuous: the slope of the segment holding s (the end ones beyond)."""
        k = np.clip(np.searchsorted(s, target, side="right") - 1, 0, len(s) - 2)
        result: np.ndarray = slope[k]
        return result

    ends = np.concatenate([s, s - b / 2, s + b / 2])
    ends = np.unique(np.clip(ends, 0.0, end))
    step = max(b / BLEND_STEPS, end / (MAX_STEPS_A_WAYPOINT * len(s)))
    step = min(step, end / (MIN_GRID - 1)) if end > 0.0 else 1.0
    grid = np.append(interval_points(ends, step), end) if len(ends) > 1 else np.array([0.0, end])
    middle = (grid[:-1] + grid[1:]) / 2
    middle = np.append(middle, middle[-1:])
    q_s = (path_at(grid + b / 2) - path_at(grid - b / 2)) / b
    q_ss = (slope_at(middle + b / 2) - slope_at(middle - b / 2)) / b
    return grid, q_s, q_ss


def interval_points(ends: np.ndarray, step: float) -> np.ndarray:
    """Each interval between consecutive ``ends`` cut in equal steps of at most ``step``.

    The points of ``np.linspace(left, right, k + 1)[:-1]`` for each interval, k its steps, the
    same floats (left + i (right - left) / k), made at once: one linspace an interval took
    0.5 s of a 17,073-move program's cycle time (50,000 intervals).
    """
    left, width = ends[:-1], np.diff(ends)
    counts = np.maximum(np.ceil(width / step - 1e-9).astype(np.int64), 1)
    owner = np.repeat(np.arange(len(left)), counts)
    index = np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts, counts)
    points: np.ndarray = index * (width / counts)[owner] + left[owner]
    return points
