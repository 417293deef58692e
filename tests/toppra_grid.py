"""toppra's TOPP-RA on a blended path's own grid: the oracle of ``solver/kernels/feed_profile.py``.

The cycle time computes toppra's discrete problem itself (compiled); its test
(tests/solver/test_cycle_time.py) and its benchmark (bench/cycle_time.py) run toppra on the
same grid through this one module.
"""

from __future__ import annotations

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint


class GridPath(toppra.interpolator.AbstractGeometricPath):  # type: ignore[misc]
    """q_s and q_ss given at grid points, linear in between, as toppra reads a path.

    Order 0 is zero: joint speed and acceleration limits read only orders 1 and 2.
    """

    def __init__(self, s: np.ndarray, q_s: np.ndarray, q_ss: np.ndarray) -> None:
        self.s, self.values = s, (np.zeros_like(q_s), q_s, q_ss)

    def __call__(self, at: float | np.ndarray, order: int = 0) -> np.ndarray:
        values, where = self.values[order], np.atleast_1d(np.asarray(at, dtype=float))
        out = np.column_stack([np.interp(where, self.s, column) for column in values.T])
        return out if np.ndim(at) else out[0]

    @property
    def dof(self) -> int:
        return int(self.values[1].shape[1])

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([self.s[0], self.s[-1]])


def toppra_speeds(
    grid: np.ndarray,
    q_s: np.ndarray,
    q_ss: np.ndarray,
    qdot_max: np.ndarray,
    qddot_max: np.ndarray,
) -> np.ndarray:
    """toppra's time-optimal sdot (G,) rest to rest on ``grid`` under the joints' limits."""
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-qdot_max, qdot_max])),
        toppra.constraint.JointAccelerationConstraint(np.column_stack([-qddot_max, qddot_max])),
    ]
    instance = toppra.algorithm.TOPPRA(constraints, GridPath(grid, q_s, q_ss), gridpoints=grid)
    _, speeds, _ = instance.compute_parameterization(0.0, 0.0)
    return np.asarray(speeds, dtype=float)


def duration(grid: np.ndarray, speeds: np.ndarray) -> float:
    """The time (s) of the speeds ``speeds`` on ``grid``, sddot constant a segment."""
    return float(np.sum(2.0 * np.diff(grid) / (speeds[1:] + speeds[:-1])))
