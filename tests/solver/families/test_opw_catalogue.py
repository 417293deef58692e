"""OPW arms as robots: the catalogue against robots.md's table, and bad geometry or limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.core.codes import UNREACHABLE
from solver.core.exceptions import InvalidInputError
from solver.core.family import Branch
from solver.core.kinematics import tool_pose_in_base
from solver.families.opw.arms import ARMS, OpwArm
from solver.families.opw.catalogue import robot_from_opw, robots
from solver.families.opw.parameters import OpwParameters
from tests.cases import FK_IK_ATOL
from tests.solver.families.test_opw import ROWS

KR6 = {"a1": 0.025, "a2": -0.035, "b": 0.0, "c1": 0.4, "c2": 0.315, "c3": 0.365, "c4": 0.08}


@pytest.mark.parametrize("name", list(ROWS))
def test_catalogue_geometry_is_the_table(name: str) -> None:
    """Each of robots.md's six arms is in the catalogue with the table's geometry."""
    arm = next((a for a in ARMS if a.name == name), None)
    assert arm is not None, f"{name} is not in ARMS"
    ours, row = arm.parameters, ROWS[name]
    lengths = ("a1", "a2", "b", "c1", "c2", "c3", "c4")
    assert [getattr(ours, k) for k in lengths] == [getattr(row, k) for k in lengths]
    np.testing.assert_allclose(ours.offsets, row.offsets, atol=1e-12)
    assert tuple(ours.sign_corrections) == tuple(row.sign_corrections)


@pytest.fixture(scope="module")
def catalogue() -> dict:
    """The catalogue's robots, built once."""
    return robots()


@pytest.mark.parametrize("arm", ARMS, ids=[a.name for a in ARMS])
def test_catalogue_robot_carries_its_arm(catalogue: dict, arm: OpwArm) -> None:
    """Names, limits (rad), speeds and geometry reach the robot, whose family solves poses of
    its own model (FK(IK(T)) = T through ``family.solve``)."""
    robot = catalogue[arm.name]
    assert robot.joint_names == arm.joint_names
    np.testing.assert_array_equal(np.c_[robot.q_lower, robot.q_upper], arm.position_limits)
    np.testing.assert_array_equal(robot.qdot_max, arm.velocity_limits)
    assert robot.family.name == "opw" and robot.family.parameters == arm.parameters
    assert (robot.base_frame, robot.tool_frame) == ("base_link", "tool0")
    rng = np.random.default_rng(3)
    q = rng.uniform(
        np.maximum(robot.q_lower, -math.pi), np.minimum(robot.q_upper, math.pi), (50, 6)
    )
    poses = np.array([tool_pose_in_base(robot, qi) for qi in q])
    solutions, status = robot.family.solve(np.moveaxis(poses[:, :3, :3], 0, -1), poses[:, :3, 3].T)
    assert solutions.shape == (6, 8, 50)
    for b, i in zip(*np.nonzero(status != UNREACHABLE), strict=True):
        np.testing.assert_allclose(
            tool_pose_in_base(robot, solutions[:, b, i]), poses[i], atol=FK_IK_ATOL
        )


def test_branch_names() -> None:
    """Branch index 4 shoulder + 2 elbow + wrist; a UR name is refused on ``ik.branch``."""
    family = robots()[ARMS[0].name].family
    assert family.branch_index(Branch.named(shoulder="front", elbow="up", wrist="noflip")) == 0
    assert family.branch_index(Branch.named(shoulder="back", elbow="down", wrist="flip")) == 7
    assert family.branch_index(Branch.named(shoulder="back", elbow="up", wrist="flip")) == 5
    with pytest.raises(InvalidInputError) as error:
        family.branch_index(Branch.named(shoulder="left", elbow="up", wrist="noflip"))
    assert error.value.field == "ik.branch"


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"c2": 0.0}, "robot.opw.c2"),
        ({"c2": -0.3}, "robot.opw.c2"),
        ({"c3": 0.0}, "robot.opw.c3"),
        ({"c3": -0.1}, "robot.opw.c3"),
        ({"a1": 150.0}, "robot.opw.a1"),
        ({"c4": -100.5}, "robot.opw.c4"),
        ({"c1": math.nan}, "robot.opw.c1"),
        ({"offsets": (0.0,) * 5}, "robot.opw.offsets"),
        ({"offsets": (0.0,) * 7}, "robot.opw.offsets"),
        ({"sign_corrections": (1, 1, 1, 1, 1)}, "robot.opw.sign_corrections"),
        ({"sign_corrections": (1, 1, 1, 1, 1, 0.5)}, "robot.opw.sign_corrections"),
        ({"sign_corrections": (1, 1, 1, 1, 1, 0)}, "robot.opw.sign_corrections"),
    ],
)
def test_bad_parameters_name_the_field(change: dict, field: str) -> None:
    with pytest.raises(InvalidInputError) as error:
        OpwParameters(**{**KR6, **change})
    assert error.value.field == field


@pytest.mark.parametrize(
    ("limits", "joint"),
    [
        ([[-3.0, 3.0]] * 5, None),
        ([[-3.0, 3.0]] * 7, None),
        ([[-3.0, 3.0]] * 5 + [[1.0, 1.0]], "joint 6 (joint_6)"),
        ([[-3.0, 3.0]] * 2 + [[2.0, -2.0]] + [[-3.0, 3.0]] * 3, "joint 3 (joint_3)"),
        ([[-3.0, math.inf]] + [[-3.0, 3.0]] * 5, "joint 1 (joint_1)"),
        ([[-3.0, 3.0]] * 4 + [[math.nan, 3.0]] + [[-3.0, 3.0]], "joint 5 (joint_5)"),
        ([[-3.0, 3.0]] * 5 + [[1.0]], None),
    ],
    ids=["five pairs", "seven pairs", "empty range", "reversed", "infinite", "nan", "ragged"],
)
def test_bad_position_limits(limits: list, joint: str | None) -> None:
    with pytest.raises(InvalidInputError) as error:
        robot_from_opw("arm", OpwParameters(**KR6), joint_position_limits=limits, qdot_max=[3] * 6)
    assert error.value.field == "robot.joint_position_limits"
    assert joint is None or joint in str(error.value)


def test_bad_joint_names_and_speeds() -> None:
    limits = [[-3.0, 3.0]] * 6
    with pytest.raises(InvalidInputError) as error:
        robot_from_opw(
            "arm",
            OpwParameters(**KR6),
            joint_position_limits=limits,
            qdot_max=[3] * 6,
            joint_names=("a",) * 6,
        )
    assert error.value.field == "robot.joint_names"
    with pytest.raises(InvalidInputError) as error:
        robot_from_opw("arm", OpwParameters(**KR6), joint_position_limits=limits, qdot_max=[3] * 5)
    assert error.value.field == "robot.joint_velocity_limits"
