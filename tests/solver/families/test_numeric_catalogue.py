"""The numeric-IK arms of the catalogue: frames, dof and limits against the makers' datasheets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.families import get_robot
from tests.cases import NUMERIC_MODELS

DEG = math.pi / 180
# name: dof, base frame, flange, joint speed limits (rad/s), position limits (rad, [lower, upper])
DATASHEETS = {
    # Franka Emika Panda datasheet ("Robot and interface specifications").
    "panda": (
        7,
        "panda_link0",
        "panda_link8",
        [2.175] * 4 + [2.61] * 3,
        [
            [-2.8973, 2.8973],
            [-1.7628, 1.7628],
            [-2.8973, 2.8973],
            [-3.0718, -0.0698],
            [-2.8973, 2.8973],
            [-0.0175, 3.7525],
            [-2.8973, 2.8973],
        ],
    ),
    # UFactory xArm7: 180 deg/s per joint; joints 1, 3, 5, 7 +-360 deg.
    "xarm7": (
        7,
        "link_base",
        "link_eef",
        [3.14] * 7,
        [
            [-2 * math.pi, 2 * math.pi],
            [-2.059, 2.0944],
            [-2 * math.pi, 2 * math.pi],
            [-0.19198, 3.927],
            [-2 * math.pi, 2 * math.pi],
            [-1.69297, math.pi],
            [-2 * math.pi, 2 * math.pi],
        ],
    ),
    # Kinova Jaco2 (j2s6s200): 36 deg/s on the large actuators, 48 deg/s on the small ones;
    # joints 2, 3, 5 limited (47..313, 19..341, 30..330 deg), the others continuous (+-2 pi).
    "kinova_jaco2": (
        6,
        "j2s6s200_link_base",
        "j2s6s200_end_effector",
        [36 * DEG] * 3 + [48 * DEG] * 3,
        [
            [-2 * math.pi, 2 * math.pi],
            [47 * DEG, 313 * DEG],
            [19 * DEG, 341 * DEG],
            [-2 * math.pi, 2 * math.pi],
            [30 * DEG, 330 * DEG],
            [-2 * math.pi, 2 * math.pi],
        ],
    ),
}


@pytest.mark.parametrize("name", NUMERIC_MODELS)
def test_numeric_arm_matches_its_datasheet(name: str) -> None:
    robot = get_robot(name)
    dof, base, tool, speeds, positions = DATASHEETS[name]
    assert robot.family is not None and robot.family.name == "numeric"
    assert robot.dof == robot.family.dof == dof
    assert (robot.base_frame, robot.tool_frame) == (base, tool)
    np.testing.assert_allclose(robot.qdot_max, speeds, rtol=0, atol=1e-3)
    np.testing.assert_allclose(
        np.column_stack([robot.q_lower, robot.q_upper]), positions, atol=2e-3
    )
    assert len(robot.family.branches) == (32 if dof == 6 else 64)
