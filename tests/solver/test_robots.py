"""Robot models: frames, limits, FK against independent references, Jacobians against FD."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
import ur_analytic_ik

from solver.core.exceptions import InvalidInputError, RobotModelError, UnknownRobotError
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import example_robot_data_dir
from solver.families import catalogue, get_robot, robot_from_urdf
from solver.families.ur.ik import forward_kinematics_dh
from tests.cases import (
    CB_URDF_VS_DH_ATOL,
    E_SERIES,
    FK_IK_ATOL,
    NUMERIC_MODELS,
    OPW_MODELS,
    UR_MODELS,
)


def test_catalogue_has_every_ur_and_opw_model() -> None:
    assert sorted(catalogue()) == sorted(UR_MODELS + OPW_MODELS + NUMERIC_MODELS)
    for name in UR_MODELS + OPW_MODELS:
        robot = catalogue()[name]
        assert robot.dof == 6
        assert robot.tool_frame == "tool0"
        assert robot.base_frame == ("base" if name in UR_MODELS else "base_link")
        assert robot.family is not None
        assert robot.family.name == ("ur" if name in UR_MODELS else "opw")


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("ur5e", [math.pi] * 6),
        ("ur3e", [math.pi] * 3 + [2 * math.pi] * 3),
        ("ur10e", [2 * math.pi / 3] * 2 + [math.pi] * 4),
        ("ur16e", [2 * math.pi / 3] * 2 + [math.pi] * 4),
        ("ur5", [3.15, 3.15, 3.15, 3.2, 3.2, 3.2]),  # the URDF's values
    ],
)
def test_velocity_limits(name: str, expected: list[float]) -> None:
    np.testing.assert_allclose(get_robot(name).qdot_max, expected, rtol=0, atol=1e-12)


def test_unknown_robot_names_known_ones() -> None:
    with pytest.raises(UnknownRobotError, match="ur5e"):
        get_robot("ur99")


@pytest.mark.parametrize("name", UR_MODELS)
def test_fk_equals_ur_analytic_ik(name: str) -> None:
    """Issue 2: e-series FK equals ur-analytic-ik's to 1e-9 (checked for CB-series too)."""
    robot = get_robot(name)
    rng = np.random.default_rng(7)
    reference = getattr(ur_analytic_ik, name)
    atol = FK_IK_ATOL if name in E_SERIES else CB_URDF_VS_DH_ATOL
    for q in rng.uniform(-2 * math.pi, 2 * math.pi, (200, 6)):
        np.testing.assert_allclose(
            tool_pose_in_base(robot, q), reference.forward_kinematics(*q), rtol=0, atol=atol
        )


@pytest.mark.parametrize("name", UR_MODELS)
def test_pinocchio_chain_equals_dh_chain(name: str) -> None:
    robot = get_robot(name)
    q = np.random.default_rng(3).uniform(-math.pi, math.pi, (100, 6))
    dh_poses = forward_kinematics_dh(robot.family.parameters, q)
    for qi, pose in zip(q, dh_poses, strict=True):
        np.testing.assert_allclose(tool_pose_in_base(robot, qi), pose, atol=CB_URDF_VS_DH_ATOL)


def test_base_is_base_link_turned_by_pi() -> None:
    """The UR controller's base frame is the URDF base_link turned by pi about z."""
    robot = get_robot("ur5")
    np.testing.assert_allclose(
        robot.transform_world_to_base[:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-10
    )


def _finite_difference_jacobian(robot, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """Central differences of FK: linear rows from positions, angular from log3 of R+ R-^T."""
    jac = np.zeros((6, robot.dof))
    for j in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[j] = step
        plus, minus = tool_pose_in_base(robot, q + dq), tool_pose_in_base(robot, q - dq)
        jac[:3, j] = (plus[:3, 3] - minus[:3, 3]) / (2 * step)
        jac[3:, j] = pin.log3(plus[:3, :3] @ minus[:3, :3].T) / (2 * step)
    return jac


def _panda():
    path = example_robot_data_dir() / "panda_description" / "urdf" / "panda.urdf"
    return robot_from_urdf(path.read_text(), base_frame="panda_link0", tool_frame="panda_link8")


@pytest.mark.parametrize("name", [*UR_MODELS, "panda"])
@pytest.mark.parametrize("with_tcp", [False, True])
def test_jacobian_equals_finite_differences(name: str, with_tcp: bool) -> None:
    robot = _panda() if name == "panda" else get_robot(name)
    if with_tcp:
        tcp = np.eye(4)
        tcp[:3, :3] = pin.utils.rotate("x", 0.4) @ pin.utils.rotate("z", -0.3)
        tcp[:3, 3] = [0.01, -0.02, 0.15]
        robot = robot.with_options(transform_tool_to_tcp=tcp)
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = rng.uniform(robot.q_lower, robot.q_upper) if name == "panda" else rng.uniform(-3, 3, 6)
        np.testing.assert_allclose(
            jacobian_in_base(robot, q), _finite_difference_jacobian(robot, q), atol=1e-8
        )


def test_tcp_offset_moves_the_tool_point() -> None:
    robot = get_robot("ur5e")
    tcp = np.eye(4)
    tcp[:3, 3] = [0.0, 0.0, 0.2]
    q = np.array([0.1, -1.2, 1.4, -0.3, 1.2, 0.5])
    flange = tool_pose_in_base(robot, q)
    tool_point = tool_pose_in_base(robot.with_options(transform_tool_to_tcp=tcp), q)
    np.testing.assert_allclose(tool_point[:3, 3], flange[:3, 3] + 0.2 * flange[:3, 2], atol=1e-12)


def test_panda_is_reduced_to_its_arm() -> None:
    robot = _panda()
    assert robot.dof == 7
    assert robot.joint_names[0] == "panda_joint1"
    np.testing.assert_allclose(robot.qdot_max, [2.175] * 4 + [2.61] * 3)


@pytest.mark.parametrize(
    ("urdf", "base", "tool", "field"),
    [
        ("<robot name='x'><link name='a'/>", "a", "a", "robot.urdf"),
        ("not xml at all", "a", "a", "robot.urdf"),
        (None, "panda_link0", "no_such_frame", "robot.tool_frame"),
        (None, "no_such_frame", "panda_link8", "robot.base_frame"),
        (None, "panda_link3", "panda_link8", "robot.base_frame"),
    ],
)
def test_bad_urdf_names_the_field(urdf: str | None, base: str, tool: str, field: str) -> None:
    if urdf is None:
        urdf = (example_robot_data_dir() / "panda_description/urdf/panda.urdf").read_text()
    with pytest.raises(RobotModelError) as info:
        robot_from_urdf(urdf, base_frame=base, tool_frame=tool)
    assert info.value.field == field


@pytest.mark.parametrize("limits", [[1.0] * 5, [1.0] * 5 + [0.0], [1.0] * 5 + [-2.0], [np.nan] * 6])
def test_bad_velocity_limits(limits: list[float]) -> None:
    with pytest.raises(InvalidInputError) as info:
        get_robot("ur5").with_options(qdot_max=limits)
    assert info.value.field == "robot.joint_velocity_limits"


def test_urdf_without_usable_limits_takes_the_given_ones() -> None:
    """A URDF with a zero velocity limit is refused, unless the request brings limits."""
    path = example_robot_data_dir() / "panda_description" / "urdf" / "panda.urdf"
    urdf = path.read_text().replace('velocity="2.175"', 'velocity="0"', 1)
    frames = {"base_frame": "panda_link0", "tool_frame": "panda_link8"}
    with pytest.raises(RobotModelError, match="joint_velocity_limits"):
        robot_from_urdf(urdf, **frames)
    robot = robot_from_urdf(urdf, **frames, qdot_max=[1.0] * 7)
    np.testing.assert_array_equal(robot.qdot_max, 1.0)


@pytest.mark.parametrize("limit", [1e-7, 1e5, math.inf])
def test_speed_limits_out_of_range(limit: float) -> None:
    with pytest.raises(InvalidInputError, match="rad/s"):
        get_robot("ur5e").with_options(qdot_max=[limit] * 6)
