"""An OPW arm given as a URDF is recognised and mapped as the catalogue's OPW arm (issue 27).

Each catalogue arm's URDF is written in the test from its parameters, ROS-Industrial style
(:mod:`tests.solver.families.opw_urdf`): link frames parallel to the base, joint origins slid
along their axes. The registry must read the OPW parameters off its chain and map it with the
closed form; the map must equal the catalogue arm's cell for cell. A chain that is almost an
OPW arm (a wrist whose axes miss each other by 1 mm) keeps numeric IK.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from solver.core.codes import UNREACHABLE
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import get_robot, robot_from_urdf
from solver.families.opw.arms import ARMS, OpwArm
from solver.families.opw.ik import forward_kinematics
from solver.families.opw.parameters import OpwParameters
from solver.path.capability_map import grid_axis
from tests.cases import FK_IK_ATOL, MAP_EVALUATE_RTOL
from tests.problems import capability_map, evaluate_path
from tests.solver.families.opw_urdf import opw_urdf
from tests.solver.families.recognised import answers_alike, with_fixed_frame
from tests.solver.test_evaluate import load_path


def urdf_text(arm: OpwArm, parameters: OpwParameters | None = None) -> str:
    """The URDF written from the arm's (or the given) parameters, limits and speeds."""
    return opw_urdf(
        parameters or arm.parameters,
        limits=np.array(arm.position_limits),
        speeds=np.array(arm.velocity_limits),
        joint_names=arm.joint_names,
        slide_seed=len(arm.name),
    )


def urdf_robot(arm: OpwArm, parameters: OpwParameters | None = None) -> Robot:
    """The arm from :func:`urdf_text`, from base_link to tool0."""
    text = urdf_text(arm, parameters)
    return robot_from_urdf(text, base_frame="base_link", tool_frame="tool0", name=arm.name)


@pytest.mark.parametrize("arm", ARMS, ids=[a.name for a in ARMS])
def test_the_urdf_is_recognised_and_solved_in_closed_form(arm: OpwArm) -> None:
    """The fitted family's IK reproduces poses of the URDF's own model (pinocchio FK)."""
    robot = urdf_robot(arm)
    assert robot.family is not None and robot.family.name == "opw"
    assert robot.family.recognised is not None and "OPW arm" in robot.family.recognised
    rng = np.random.default_rng(7)
    q = rng.uniform(
        np.maximum(robot.q_lower, -math.pi), np.minimum(robot.q_upper, math.pi), (40, 6)
    )
    poses = np.array([tool_pose_in_base(robot, qi) for qi in q])
    # The URDF written in the test is the arm: its FK is the paper's formula with the table's row.
    np.testing.assert_allclose(poses, forward_kinematics(arm.parameters, q), atol=FK_IK_ATOL)
    solutions, status = robot.family.solve(np.moveaxis(poses[:, :3, :3], 0, -1), poses[:, :3, 3].T)
    assert np.count_nonzero(status != UNREACHABLE) >= 40 * 4
    for b, i in zip(*np.nonzero(status != UNREACHABLE), strict=True):
        pose = tool_pose_in_base(robot, solutions[:, b, i])
        np.testing.assert_allclose(pose, poses[i], atol=FK_IK_ATOL)


@pytest.mark.parametrize("arm", ARMS, ids=[a.name for a in ARMS])
def test_the_urdf_map_equals_the_opw_map_cell_for_cell(arm: OpwArm) -> None:
    """An ERK-size map (546 cells, the ERK path's 133 waypoints), scaled to the arm's reach."""
    reach = arm.parameters.c2 + arm.parameters.c3
    maps = [
        capability_map(
            robot,
            load_path("curved_line"),
            xs=grid_axis(0.2 * reach, 0.7 * reach, 0.02 * reach, field="x"),
            ys=grid_axis(-0.2 * reach, 0.2 * reach, 0.02 * reach, field="y"),
            z=0.1 * reach,
            yaws=np.zeros(1),
        )
        for robot in (get_robot(arm.name), urdf_robot(arm))
    ]
    expected, answer = maps
    assert expected.mu_path.size == 546
    assert np.isfinite(expected.mu_path).sum() >= 50
    np.testing.assert_allclose(answer.mu_path, expected.mu_path, rtol=MAP_EVALUATE_RTOL)
    np.testing.assert_array_equal(answer.reason, expected.reason)
    np.testing.assert_array_equal(answer.failed_waypoint, expected.failed_waypoint)
    np.testing.assert_array_equal(answer.bottleneck_joint, expected.bottleneck_joint)
    catalogue_branches = get_robot(arm.name).family.branches
    ours = urdf_robot(arm).family.branches
    feasible = np.isfinite(expected.mu_path)
    assert [ours[b] for b in answer.branch[feasible]] == [
        catalogue_branches[b] for b in expected.branch[feasible]
    ]


def test_a_wrist_that_is_not_spherical_keeps_numeric_ik() -> None:
    """A 1 mm offset between the wrist's axes (not an OPW arm) is not taken for one."""
    arm = ARMS[0]
    robot = urdf_robot(arm)
    text = opw_urdf(
        arm.parameters,
        limits=np.array(arm.position_limits),
        speeds=np.array(arm.velocity_limits),
        joint_names=arm.joint_names,
    )
    # Move joint 5's origin 1 mm off joint 4's axis (across it): the wrist centre is gone.
    head, _, tail = text.partition(f"<joint name='{arm.joint_names[4]}'")
    origin_start = tail.index("xyz='") + len("xyz='")
    origin_end = tail.index("'", origin_start)
    values = [float(v) for v in tail[origin_start:origin_end].split()]
    values[2] += 1e-3  # joint 4's axis is along x at q = 0, joint 5's along y
    tail = tail[:origin_start] + " ".join(map(repr, values)) + tail[origin_end:]
    moved = robot_from_urdf(
        head + f"<joint name='{arm.joint_names[4]}'" + tail,
        base_frame="base_link",
        tool_frame="tool0",
    )
    assert robot.family is not None and robot.family.name == "opw"
    assert moved.family is not None and moved.family.name == "numeric"
    assert moved.family.recognised is None


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_any_offsets_signs_and_lateral_offset_are_recognised(seed: int) -> None:
    """Random geometry (b != 0, a1 and a2 of either sign), offsets and sign corrections."""
    rng = np.random.default_rng(seed)
    a1, a2, b = rng.uniform(-0.3, 0.3, 3)
    c1, c2, c3, c4 = rng.uniform(0.1, 1.0, 4)
    parameters = OpwParameters(
        a1, a2, b, c1, c2, c3, c4,
        offsets=tuple(rng.uniform(-math.pi, math.pi, 6)),
        sign_corrections=tuple(int(s) for s in rng.choice([-1, 1], 6)),
    )  # fmt: skip
    arm = ARMS[seed % len(ARMS)]
    robot = urdf_robot(arm, parameters)
    assert robot.family is not None and robot.family.name == "opw"
    q = rng.uniform(-math.pi, math.pi, (30, 6))
    poses = np.array([tool_pose_in_base(robot, qi) for qi in q])
    np.testing.assert_allclose(poses, forward_kinematics(parameters, q), atol=FK_IK_ATOL)
    solutions, status = robot.family.solve(np.moveaxis(poses[:, :3, :3], 0, -1), poses[:, :3, 3].T)
    for b_, i in zip(*np.nonzero(status != UNREACHABLE), strict=True):
        pose = tool_pose_in_base(robot, solutions[:, b_, i])
        np.testing.assert_allclose(pose, poses[i], atol=FK_IK_ATOL)
    # Each pose's own q is one of its branches (to a turn): the closed form missed none.
    turned = np.angle(np.exp(1j * (solutions - q.T[:, None, :])))  # (6, 8, 30), wrapped
    assert np.all(np.nanmin(np.abs(turned).max(axis=0), axis=0) < 1e-6)


@pytest.mark.parametrize("arm", ARMS[:2], ids=[a.name for a in ARMS[:2]])
def test_a_base_moved_and_turned_on_its_cell_gives_the_same_answer_at_the_same_place(
    arm: OpwArm,
) -> None:
    # A frame "cell" in which base_link stands at (0.9, -0.4, 0.05) turned by 30 deg (the arm
    # mounted in a workcell): the chain from cell is the OPW arm in a shift of cell (joint 1's
    # offset takes the turn, c1 the height). The placement (X, Y, Z, YAW) in base_link is
    # t + Rz(30 deg) (X, Y, Z), YAW + 30 deg in cell: the same joint path and feed there,
    # through evaluate and the map kernel.
    t, turn = np.array([0.9, -0.4, 0.05]), math.radians(30.0)
    c, s = math.cos(turn), math.sin(turn)
    back = [-(c * t[0] + s * t[1]), s * t[0] - c * t[1], -t[2]]  # Rz(-turn) (-t)
    at_base = urdf_robot(arm)
    text = with_fixed_frame(urdf_text(arm), "cell", "base_link", back, (0.0, 0.0, -turn))
    in_cell = robot_from_urdf(text, base_frame="cell", tool_frame="tool0", name=arm.name)
    assert in_cell.family is not None and in_cell.family.name == "opw"
    assert in_cell.family.recognised is not None
    assert "moved to (0.9, -0.4, 0) m" in in_cell.family.recognised
    reach = arm.parameters.c2 + arm.parameters.c3
    path = load_path("curved_line")
    checked = 0
    for x, y in ((0.4, 0.0), (0.5, 0.1), (0.35, -0.15)):
        x_base, y_base, z_base, yaw_base = x * reach, y * reach, 0.1 * reach, 0.2
        expected = evaluate_path(at_base, path, Placement(x_base, y_base, z_base, yaw_base))
        placement = Placement(
            t[0] + c * x_base - s * y_base,
            t[1] + s * x_base + c * y_base,
            t[2] + z_base,
            yaw_base + turn,
        )
        checked += answers_alike(in_cell, path, placement, expected)
    assert checked >= 2


@pytest.mark.parametrize("arm", ARMS[:2], ids=[a.name for a in ARMS[:2]])
def test_a_tool_frame_off_the_opw_flange_gives_the_tool0_answer_with_that_tool_point(
    arm: OpwArm,
) -> None:
    # A tool frame turned and moved on the last link, as CAD exports write tool0 (the corpus's
    # KR210 R2700: turned by 90 deg, 0.24 mm off joint 6's axis). The chain to it is the OPW
    # arm up to a fixed E: recognised, and at the same placements it must answer what the
    # chain to tool0 answers with E as its tool point (the catalogue-tested path: feasibility,
    # mu_path, the joint path), through evaluate and the map kernel; FK of the joint path
    # (pinocchio) must put the tool frame on every placed waypoint.
    xyz, rpy = np.array([0.03, -0.02, 0.05]), np.array([0.3, -1.2, 0.7])
    text = with_fixed_frame(urdf_text(arm), "tool_cad", "tool0", xyz, rpy)
    cad = robot_from_urdf(text, base_frame="base_link", tool_frame="tool_cad", name=arm.name)
    assert cad.family is not None and cad.family.name == "opw"
    assert cad.family.flange_offset is not None
    assert cad.family.recognised is not None and "tool frame is the OPW flange" in (
        cad.family.recognised
    )
    offset = np.eye(4)
    offset[:3, :3], offset[:3, 3] = pin.rpy.rpyToMatrix(*rpy), xyz
    at_tool0 = robot_from_urdf(text, base_frame="base_link", tool_frame="tool0", name=arm.name)
    at_tool0 = at_tool0.with_options(transform_tool_to_tcp=offset)
    reach = arm.parameters.c2 + arm.parameters.c3
    path = load_path("curved_line")
    placements = [Placement(x * reach, y * reach, 0.1 * reach, yaw) for x, y, yaw in (
        (0.4, 0.0, 0.2), (0.5, 0.1, -0.4), (0.35, -0.15, 1.0), (0.45, 0.05, 2.5)
    )]  # fmt: skip
    checked = 0
    for placement in placements:
        free = evaluate_path(at_tool0, path, placement, spin_mode="free")
        answers_alike(cad, path, placement, free, spin_mode="free")  # free spin: [0; z_tool]
        expected = evaluate_path(at_tool0, path, placement)
        if not answers_alike(cad, path, placement, expected):
            continue
        checked += 1
        poses = placement.transform_workpiece_to_base() @ path
        assert expected.q is not None
        for w in range(0, len(path), 11):
            np.testing.assert_allclose(
                tool_pose_in_base(cad, expected.q[w]), poses[w], atol=FK_IK_ATOL
            )
    assert checked >= 2


def test_the_jaco2s_urdf_is_an_opw_arm_and_maps_as_the_catalogues_numeric_jaco2() -> None:
    # The Kinova Jaco2 j2s6s200 (spherical wrist) from example-robot-data: its chain is an OPW
    # arm's whose flange is turned half a turn on the OPW flange. Sent as a URDF it is solved
    # in closed form; the catalogue's kinova_jaco2 (the same URDF, numeric IK) maps the same.
    numeric = get_robot("kinova_jaco2")
    assert numeric.family is not None and numeric.family.name == "numeric"
    assert numeric.urdf is not None
    frames = {"base_frame": "j2s6s200_link_base", "tool_frame": "j2s6s200_end_effector"}
    robot = robot_from_urdf(numeric.urdf, **frames)
    assert robot.family is not None and robot.family.name == "opw"
    sentence = robot.family.recognised or ""
    assert "whose tool frame is the OPW flange turned by 180 deg" in sentence
    assert "a1=0, a2=0, b=-0.0098" in sentence  # a fit's 1e-14 m said as 0
    path = load_path("curved_line")
    grid = {
        "xs": grid_axis(-0.3, 0.3, 0.1, field="x"),
        "ys": grid_axis(-0.5, -0.2, 0.1, field="y"),
        "z": 0.0,
        "yaws": np.array([0.0, 1.0]),
    }
    answer, expected = (capability_map(arm, path, **grid) for arm in (robot, numeric))
    assert np.isfinite(expected.mu_path).sum() >= 10
    same = np.isclose(answer.mu_path, expected.mu_path, rtol=MAP_EVALUATE_RTOL, atol=0)
    assert np.all(same | (np.isnan(answer.mu_path) & np.isnan(expected.mu_path)))
