"""Mimic joints honoured (issue 27): a URDF ``<mimic>`` joint in the chain follows its leader.

The fixture is a small arm of this file's own: six joints and a seventh, ``j5b``, that mimics
``j5`` (q_j5b = m q_j5 + o, as ABB's IRB 5400 couples its joint5b to joint5), with limits of its
own. pinocchio reads it coupled (``mimic=True``): six coordinates. The known answers come from
pinocchio's model of the same URDF read without the coupling (seven free joints) and from the
DTF LP written here for HiGHS with the coupling as equality rows.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import scipy.optimize

from solver.core.exceptions import InvalidInputError, RobotModelError
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import robot_from_urdf
from solver.families.numeric.family import NumericFamily
from solver.optimise.methods.casadi_kinematics import symbolic_kinematics
from tests.problems import evaluate_path

SPEED = 3.0  # rad/s, every joint but the mimic
JOINTS = [  # name, origin in the parent, axis
    ("j1", "0 0 0.4", "0 0 1"),
    ("j2", "0.1 0 0.2", "0 1 0"),
    ("j3", "0 0 0.6", "0 1 0"),
    ("j4", "0.2 0 0.1", "1 0 0"),
    ("j5", "0.4 0 0", "0 1 0"),
    ("j5b", "0.05 0 0", "0 0 1"),
    ("j6", "0.1 0 0", "1 0 0"),
]
MULTIPLIER, OFFSET = -1.5, 0.2
Q_START = np.array([0.1, 0.3, -0.6, 0.2, 0.7, 0.1])
Q_MOVE = np.array([0.2, -0.1, 0.15, 0.3, -0.4, 0.5])


def arm_urdf(mimic_speed: float, *, mimic_limit: float = 2.5) -> str:
    """The fixture arm, ``j5b`` mimicking ``j5`` with its own speed and position limits."""
    links = "".join(f'<link name="l{i}"/>' for i in range(8)) + '<link name="tool0"/>'
    joints = []
    for i, (name, xyz, axis) in enumerate(JOINTS):
        speed, limit = (mimic_speed, mimic_limit) if name == "j5b" else (SPEED, 2.5)
        mimic = (
            f'<mimic joint="j5" multiplier="{MULTIPLIER}" offset="{OFFSET}"/>'
            if name == "j5b"
            else ""
        )
        joints.append(
            f'<joint name="{name}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
            f'<limit lower="{-limit}" upper="{limit}" velocity="{speed}" effort="1"/>{mimic}'
            "</joint>"
        )
    tool = (
        '<joint name="flange" type="fixed"><parent link="l7"/><child link="tool0"/>'
        '<origin xyz="0.05 0 0"/></joint>'
    )
    return f'<robot name="mimic_arm">{links}{"".join(joints)}{tool}</robot>'


def coupled(q: np.ndarray) -> np.ndarray:
    """The seven joint angles of the six coordinates, (N, 6) -> (N, 7), j5b = m q5 + o."""
    return np.insert(q, 5, MULTIPLIER * q[:, 4] + OFFSET, axis=1)


def arm(mimic_speed: float) -> tuple[Robot, np.ndarray]:
    """The robot and a path it reaches at placement 0: its flange along a joint motion."""
    robot = robot_from_urdf(arm_urdf(mimic_speed), base_frame="l0", tool_frame="tool0")
    path = np.array([tool_pose_in_base(robot, Q_START + t * Q_MOVE) for t in np.linspace(0, 1, 40)])
    return robot, path


def coupling_lp(jacobian: np.ndarray, twist: np.ndarray, limits: np.ndarray) -> float:
    """HiGHS on max s s.t. J qdot = s t_hat, qdot_j5b = m qdot_j5, |qdot| <= limits (7 joints)."""
    coupling = np.zeros(7)
    coupling[5], coupling[4] = 1.0, -MULTIPLIER
    a_eq = np.vstack([np.column_stack([jacobian, -twist]), np.r_[coupling, 0.0]])
    result = scipy.optimize.linprog(
        np.r_[np.zeros(7), -1.0],
        A_eq=a_eq,
        b_eq=np.zeros(7),
        bounds=[(-v, v) for v in limits] + [(0.0, None)],
        method="highs",
    )
    assert result.status == 0, result.message
    return float(result.x[7])


def test_the_chain_reads_six_coordinates_and_the_mimics_limits_narrow_its_leader() -> None:
    robot, _ = arm(0.5)
    assert robot.dof == 6 and robot.joint_names == ("j1", "j2", "j3", "j4", "j5", "j6")
    assert isinstance(robot.family, NumericFamily) and not robot.family.compiled
    assert robot.qdot_max[4] == pytest.approx(0.5 / 1.5)  # |m| qdot_j5 <= 0.5
    assert robot.qdot_max[[0, 1, 2, 3, 5]] == pytest.approx(SPEED)
    narrow = robot_from_urdf(arm_urdf(0.5, mimic_limit=1.0), base_frame="l0", tool_frame="tool0")
    # -1 <= -1.5 q5 + 0.2 <= 1  <=>  -0.5333 <= q5 <= 0.8
    assert narrow.q_lower[4] == pytest.approx(-0.8 / 1.5)
    assert narrow.q_upper[4] == pytest.approx(1.2 / 1.5)


def test_a_continuous_leader_without_limits_takes_its_mimics_limits() -> None:
    # j5 continuous with no lower or upper (no position limit of its own): the mimic joint's
    # own limits still narrow it, as for a revolute leader (not left at -inf..inf, not at the
    # 0..0 pinocchio reads for a revolute joint without them).
    text = arm_urdf(0.5, mimic_limit=1.0)
    start = text.index('<joint name="j5" type="revolute">')
    end = text.index("</joint>", start)
    j5 = text[start:end].replace('type="revolute"', 'type="continuous"')
    j5 = j5.replace('lower="-2.5" upper="2.5" ', "")
    robot = robot_from_urdf(text[:start] + j5 + text[end:], base_frame="l0", tool_frame="tool0")
    assert robot.reading.continuous_joints == ("j5",) == robot.reading.unlimited_joints
    assert robot.q_lower[4] == pytest.approx(-0.8 / 1.5)  # -1 <= -1.5 q5 + 0.2 <= 1
    assert robot.q_upper[4] == pytest.approx(1.2 / 1.5)


@pytest.mark.parametrize("mimic_speed", [0.5, 100.0])  # the tighter limit, and a loose one
def test_the_path_keeps_the_coupling_and_runs_at_the_coupled_lp(mimic_speed: float) -> None:
    robot, path = arm(mimic_speed)
    evaluation = evaluate_path(robot, path, Placement(0.0, 0.0, 0.0, 0.0))
    assert evaluation.feasible and evaluation.q is not None and evaluation.v_max is not None
    assert evaluation.qdot is not None and evaluation.mu_path is not None
    free = pin.buildModelFromXML(arm_urdf(mimic_speed))  # seven free joints, no coupling
    data, tool = free.createData(), free.getFrameId("tool0")
    limits = np.array([SPEED] * 5 + [mimic_speed, SPEED])
    twists = np.column_stack(
        [
            evaluation.u_T,
            evaluation.u_R / np.where(np.isinf(evaluation.h), np.inf, evaluation.h)[:, None],
        ]
    )
    expected = []
    for q, pose, twist in zip(coupled(evaluation.q), path, twists, strict=True):
        pin.framesForwardKinematics(free, data, q)
        np.testing.assert_allclose(data.oMf[tool].homogeneous, pose, atol=1e-9)  # FK holds
        jacobian = pin.computeFrameJacobian(free, data, q, tool, pin.LOCAL_WORLD_ALIGNED)
        expected.append(coupling_lp(jacobian, twist, limits))
    np.testing.assert_allclose(evaluation.v_max, expected, rtol=1e-7)
    speeds = coupled(evaluation.qdot) - np.r_[np.zeros(5), OFFSET, 0.0]  # qdot_j5b = m qdot_j5
    load = np.abs(speeds) / limits
    assert load.max() <= 1 + 1e-9
    bottleneck = evaluation.bottleneck_waypoint
    assert bottleneck is not None
    binding = int(np.argmax(load[bottleneck]))
    assert (binding == 5) == (mimic_speed == 0.5)  # the mimic binds where it is the tighter


@pytest.mark.parametrize("through", ["urdf", "with_options"])
def test_a_leaders_speed_limit_the_mimic_cannot_follow_is_refused(through: str) -> None:
    """A request's limits, one per coordinate, cannot drop j5b's own: |m| qdot_j5 <= 0.5."""
    bound = 0.5 / abs(MULTIPLIER)
    robot, _ = arm(0.5)

    def given(j5: float) -> Robot:
        limits = [SPEED] * 4 + [j5, SPEED]
        if through == "with_options":
            return robot.with_options(qdot_max=limits)
        return robot_from_urdf(arm_urdf(0.5), base_frame="l0", tool_frame="tool0", qdot_max=limits)

    assert given(bound).qdot_max[4] == bound  # the bound itself, exactly as given
    assert given(0.1).qdot_max[4] == 0.1
    with pytest.raises(InvalidInputError) as error:
        given(np.nextafter(bound, 1.0))
    assert error.value.field == "robot.joint_velocity_limits"
    assert "joint 4 ('j5')" in error.value.message and "'j5b'" in error.value.message
    assert f"at most {bound!r}" in error.value.message
    loose, _ = arm(100.0)  # j5b's limit looser than j5's: any limit for j5 is accepted
    assert loose.with_options(qdot_max=[SPEED] * 6).qdot_max[4] == SPEED


def test_a_mimic_whose_leader_is_off_the_chain_is_refused_naming_it() -> None:
    urdf = arm_urdf(0.5).replace('mimic joint="j5"', 'mimic joint="elsewhere"')
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(urdf, base_frame="l0", tool_frame="tool0")
    assert error.value.field == "robot.urdf"
    assert "'j5b' mimics 'elsewhere'" in error.value.message


def test_the_nlp_says_it_has_no_symbolic_mimic_joint() -> None:
    """The casadi NLP rebuilds the chain joint by joint: a mimic joint is refused, clearly."""
    robot, _ = arm(0.5)
    with pytest.raises(RobotModelError, match="JointModelMimic"):
        symbolic_kinematics(robot)
