"""Closed-form UR J^-1 t against a 6x6 solve with pinocchio's Jacobian."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.families import get_robot
from tests.cases import UR_MODELS


@pytest.mark.parametrize("name", UR_MODELS)
def test_equals_solve_with_pinocchio_jacobian(name: str) -> None:
    tcp = np.eye(4)
    tcp[:3, 3] = [0.01, -0.03, 0.18]
    robot = get_robot(name).with_options(transform_tool_to_tcp=tcp)
    rng = np.random.default_rng(21)
    q = rng.uniform(-math.pi, math.pi, (300, 6))
    twists = rng.normal(size=(300, 6))
    points = np.array([tool_pose_in_base(robot, qi)[:3, 3] for qi in q])
    ours = robot.family.joint_speeds_per_unit_twist(q.T, twists.T, points.T).T
    for qi, twist, speeds in zip(q, twists, ours, strict=True):
        jacobian = jacobian_in_base(robot, qi)
        expected = np.linalg.solve(jacobian, twist)
        # Relative to the largest joint speed, scaled by the conditioning of this J.
        tolerance = 1e-15 * np.linalg.cond(jacobian) * np.abs(expected).max() * 10
        np.testing.assert_allclose(speeds, expected, rtol=0, atol=tolerance)
        np.testing.assert_allclose(jacobian @ speeds, twist, atol=1e-9 * np.abs(twist).max())
