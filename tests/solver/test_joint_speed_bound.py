"""The fixed-spin DTF of :class:`solver.path.limits.JointSpeedLimit` against its definition.

1 / max_j |qd_j| / qdot_max_j and the binding joint (the first of a tie), computed here one
waypoint at a time in Python, on the layouts the pipeline hands over (the joint axis
innermost in memory, as the families return J^-1 t, and outermost), with the cases a map
meets: branches without a solution (NaN), singular rows (inf), ties, and zero speeds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.path.limits import JointMotion, JointSpeedLimit


def _reference(qd: np.ndarray, qdot_max: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Speed and joint of each waypoint of qd (n, M), by a loop over plain floats."""
    speeds, joints = [], []
    for column in qd.T.tolist():
        ratios = [abs(v) / float(limit) for v, limit in zip(column, qdot_max, strict=True)]
        if any(math.isnan(r) for r in ratios):
            speeds.append(math.nan)
            joints.append(next(j for j, r in enumerate(ratios) if math.isnan(r)))
            continue
        top = max(ratios)
        joints.append(ratios.index(top))
        speeds.append(math.inf if top == 0.0 else 1.0 / top)
    return np.array(speeds), np.array(joints)


@pytest.mark.parametrize("joint_innermost", [True, False])
def test_speed_bound_is_the_dtf_and_its_first_binding_joint(joint_innermost: bool) -> None:
    rng = np.random.default_rng(5)
    n, shape = 6, (3, 4, 20)
    qd = rng.normal(size=(*shape, n))
    qd[1, :, ::3] = np.nan  # a branch lost on some waypoints
    qd[2, 1, 4] = np.inf  # a singular configuration
    qd[0, 2, 5] = 0.0  # no motion: no bound
    qd[0, 3, 6, 2] = qd[0, 3, 6, 4] = 50.0  # a tie: the first joint binds
    qd[2, 0, 7, 3] = np.nan  # one NaN joint among finite ones
    qdot_max = np.array([3.15, 3.15, 3.15, 3.2, 3.2, 3.2])
    qd_unit = np.moveaxis(qd, -1, 0) if joint_innermost else np.moveaxis(qd, -1, 0).copy()
    speed, joint = JointSpeedLimit(qdot_max).speed_bound(JointMotion(q=qd_unit, qd_unit=qd_unit))
    expected_speed, expected_joint = _reference(qd_unit.reshape(n, -1), qdot_max)
    np.testing.assert_array_equal(speed.ravel(), expected_speed)
    np.testing.assert_array_equal(joint.ravel(), expected_joint)
    assert joint[0, 3, 6] == 2 and math.isinf(speed[0, 2, 5]) and speed[2, 1, 4] == 0.0
