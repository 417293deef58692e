"""A URDF's structure said in the answer: stray links, continuous joints, two roots, mimics.

The fixtures are the UR5 URDF of example-robot-data, edited as the published files that showed
each case (a ROS 2 generated UR5e with a stray ``world`` link; a mimic joint between base and
tool, as ABB IRB 5400's joint5b, here following a joint that is not there).
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import pytest

from solver.cam.csv_path import read_csv_path
from solver.core.exceptions import RobotModelError
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import example_robot_data_dir
from solver.core.spatial import Placement
from solver.core.tool_axis import poses_from_tool_axes
from solver.core.urdf_structure import (
    StrayLink,
    fixed_to_root,
    mimic_joints,
    root_links,
    stray_links,
)
from solver.families import catalogue, robot_from_urdf
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.service.test_urdf_recognised import fan_csv

UR5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
FRAMES = {"base_frame": "base", "tool_frame": "tool0"}
FAN = fan_csv()  # a fan-shaped 5-axis path whose tool turns about its axis
PLACEMENT = Placement(0.45, 0.1, 0.1, 0.0)


def with_mimic(joint: str, leader: str) -> str:
    start = UR5.index(f'<joint name="{joint}"')
    end = UR5.index("</joint>", start)
    mimic = f'<mimic joint="{leader}" multiplier="-1" offset="0.5"/>\n  '
    return UR5[:end] + mimic + UR5[end:]


def test_the_ur5_has_one_root_and_no_mimic() -> None:
    assert root_links(UR5) == ["world"]  # example-robot-data's UR5 hangs off its own world
    assert mimic_joints(UR5) == {}


def test_the_links_fixed_to_the_root_are_told_from_those_a_joint_moves() -> None:
    # world (the root) -> base_link -> base by fixed joints; tool0 after six revolute joints
    assert [fixed_to_root(UR5, link) for link in ("world", "base_link", "base")] == [True] * 3
    assert not fixed_to_root(UR5, "tool0") and not fixed_to_root(UR5, "shoulder_link")
    assert not fixed_to_root(UR5, "nowhere") and not fixed_to_root("<robot", "base")
    turned = UR5.replace(
        'name="base_link-base_fixed_joint" type="fixed"', 'name="b" type="revolute"'
    )
    assert not fixed_to_root(turned, "base")


def without_world_joint(urdf: str) -> str:
    """The UR5 as a ROS 2 generator wrote the UR5e: ``<link name="world"/>`` joined to nothing."""
    start = urdf.index('<joint name="world_joint"')
    return urdf[:start] + urdf[urdf.index("</joint>", start) + len("</joint>") :]


STRAY = without_world_joint(UR5)
JOINED_TREE = (  # a second tree: two links and a joint, joined to the arm by nothing
    '<link name="cart"/><link name="cart_top"/><joint name="cart_joint" type="fixed">'
    '<parent link="cart"/><child link="cart_top"/></joint>'
)
TABLE = (  # a link with collision geometry that no joint names
    '<link name="table"><collision><geometry><box size="1 1 0.1"/></geometry></collision></link>'
)


def test_a_link_no_joint_names_is_left_out_and_the_arm_reads_as_without_it() -> None:
    assert root_links(STRAY) == ["base_link", "world"]
    assert stray_links(STRAY) == [StrayLink("world", collision=False)]
    robot = robot_from_urdf(STRAY, **FRAMES)
    assert robot.reading.left_out_links == ("world",)
    assert robot.urdf is not None and root_links(robot.urdf) == ["base_link"]
    # The same arm as the document with the link deleted by hand (and as the catalogue's UR5,
    # whose world is base_link's parent at the identity): forward kinematics at random q.
    by_hand = robot_from_urdf(STRAY.replace('<link name="world"/>', ""), **FRAMES)
    assert by_hand.reading.left_out_links == ()
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, (8, 6))
    for row in q:
        left = tool_pose_in_base(robot, row)
        np.testing.assert_array_equal(left, tool_pose_in_base(by_hand, row))
        np.testing.assert_allclose(left, tool_pose_in_base(catalogue()["ur5"], row), atol=1e-12)
    assert robot.family is not None and by_hand.family is not None
    assert robot.family.recognised == by_hand.family.recognised


@pytest.mark.parametrize(
    ("edit", "frames", "roots"),
    [
        (lambda u: u.replace("</robot>", JOINED_TREE + "</robot>"), FRAMES, "'world', 'cart'"),
        (lambda u: u.replace("</robot>", TABLE + "</robot>"), FRAMES, "'world', 'table'"),
        (
            lambda u: without_world_joint(u),
            {**FRAMES, "base_frame": "world"},
            "'base_link', 'world'",
        ),
    ],
    ids=["a second tree", "a link with collision geometry", "a link named as the base frame"],
)
def test_two_root_links_are_refused_naming_both_where_one_is_more_than_a_stray_link(
    capfd: pytest.CaptureFixture[str], edit: Any, frames: dict[str, str], roots: str
) -> None:
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(edit(UR5), **frames)
    assert error.value.field == "robot.urdf"
    assert f"2 root links ({roots})" in error.value.message
    # the parser's own lines go on to the process's stderr (a server's log), as it wrote them
    assert "Two root links found" in capfd.readouterr().err


def test_a_mimic_joint_whose_leader_is_off_the_chain_is_refused_naming_both_joints() -> None:
    """A mimic joint of the chain is honoured (tests/solver/families/test_mimic.py) when its
    leader is a joint of the chain; one following a joint elsewhere is refused."""
    urdf = with_mimic("elbow_joint", "nowhere_joint")
    assert mimic_joints(urdf)["elbow_joint"].multiplier == -1.0
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(urdf, **FRAMES)
    assert error.value.field == "robot.urdf"
    message = error.value.message
    assert "'elbow_joint' mimics 'nowhere_joint'" in message
    assert "q = -1 q_leader + 0.5" in message


def test_a_mimic_joint_off_the_chain_is_locked_as_before() -> None:
    # The Panda's second finger mimics the first: both are locked, the arm reads as before.
    panda = (example_robot_data_dir() / "panda_description" / "urdf" / "panda.urdf").read_text()
    assert any(m.leader == "panda_finger_joint1" for m in mimic_joints(panda).values())
    assert catalogue()["panda"].dof == 7


XACRO = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="kr16_2">
  <xacro:include filename="$(find kuka_kr16_support)/urdf/kr16_2_macro.xacro"/>
  <xacro:kuka_kr16_2 prefix=""/>
</robot>
"""


def test_a_xacro_file_is_refused_saying_it_must_be_expanded_first() -> None:
    # As ROS-Industrial's support packages ship an arm (kr16_2.xacro): macros, no links.
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(XACRO, **FRAMES)
    assert error.value.field == "robot.urdf"
    message = error.value.message
    assert message.startswith("cannot parse the URDF: No link elements found in urdf file; ")
    assert "the document is xacro (it has xacro: elements), not a URDF: expand it first" in message
    plain = XACRO.replace("xacro:", "").replace(' xmlns:xacro="http://www.ros.org/wiki/xacro"', "")
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(plain, **FRAMES)
    assert "xacro" not in error.value.message  # no links, and nothing says it is a macro file


def continuous(urdf: str, joint: str, limits: str | None) -> str:
    """``joint`` made continuous, its <limit>'s lower and upper replaced by ``limits`` (or none)."""
    start = urdf.index(f'<joint name="{joint}"')
    end = urdf.index("</joint>", start)
    part = urdf[start:end].replace('type="revolute"', 'type="continuous"')
    part = re.sub(r' (lower|upper)="[^"]*"', "", part)
    if limits is not None:
        part = part.replace("<limit ", f"<limit {limits} ")
    return urdf[:start] + part + urdf[end:]


def test_a_continuous_joint_without_limits_has_none_and_answers_as_a_very_wide_one() -> None:
    # As Kinova's Gen3 files write joints 1, 3, 5 and 7; here the UR5's wrist 3. The same arm
    # with wrist 3 revolute over +-1000 rad (which no path of a few turns reaches) is the
    # independent answer: the same mu_path, branch and joint path.
    robot = robot_from_urdf(continuous(UR5, "wrist_3_joint", None), **FRAMES)
    wide = robot_from_urdf(
        continuous(UR5, "wrist_3_joint", 'lower="-1000" upper="1000"').replace(
            'name="wrist_3_joint" type="continuous"', 'name="wrist_3_joint" type="revolute"'
        ),
        **FRAMES,
    )
    assert (robot.q_lower[5], robot.q_upper[5]) == (-np.inf, np.inf)
    assert (wide.q_lower[5], wide.q_upper[5]) == (-1000.0, 1000.0)
    np.testing.assert_array_equal(robot.q_lower[:5], wide.q_lower[:5])
    assert robot.reading.continuous_joints == ("wrist_3_joint",)
    assert robot.reading.unlimited_joints == ("wrist_3_joint",)
    assert wide.reading.continuous_joints == ()
    cam = read_csv_path(FAN, units="mm")
    assert cam.axes is not None
    poses, _ = poses_from_tool_axes(cam.positions, cam.axes)
    for spin_mode in ("fixed", "free"):
        options = PathOptions(spin_mode=spin_mode)
        left, right = (
            evaluate_path(PathProblem.of(arm, poses, options), PLACEMENT) for arm in (robot, wide)
        )
        assert left.feasible and right.feasible
        assert left.mu_path == right.mu_path and left.branch == right.branch
        np.testing.assert_array_equal(left.q, right.q)
        np.testing.assert_array_equal(left.v_max, right.v_max)


def test_a_continuous_joints_own_limits_are_kept_and_one_without_a_limit_needs_a_speed() -> None:
    # Kinova's files give their continuous joints +-2 pi: kept, as the revolute joint's.
    kept = robot_from_urdf(continuous(UR5, "wrist_3_joint", 'lower="-3.0" upper="3.0"'), **FRAMES)
    assert (kept.q_lower[5], kept.q_upper[5]) == (-3.0, 3.0)
    assert kept.reading.continuous_joints == ("wrist_3_joint",)
    assert kept.reading.unlimited_joints == ()
    start = UR5.index('<joint name="wrist_3_joint"')
    end = UR5.index("</joint>", start)
    bare = UR5[:start] + re.sub(r"<limit [^>]*/>", "", UR5[start:end]) + UR5[end:]
    bare = bare.replace(
        'name="wrist_3_joint" type="revolute"', 'name="wrist_3_joint" type="continuous"'
    )
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(bare, **FRAMES)
    assert error.value.field == "robot.urdf" and "joint_velocity_limits" in error.value.message
    given = robot_from_urdf(bare, **FRAMES, qdot_max=[3.0] * 6)
    assert (given.q_lower[5], given.q_upper[5]) == (-np.inf, np.inf)
    assert given.qdot_max.tolist() == [3.0] * 6


def test_a_path_of_three_turns_fits_an_unlimited_wrist_and_not_the_ur5s() -> None:
    # The tool turns three times about its own axis along 0.1 m: the UR5's wrist 3 (+-2 pi)
    # runs out of range, the same joint continuous without limits turns 6 pi (geometry: the
    # tool's turn about its axis is wrist 3's, the arm's other joints moving little).
    s = np.linspace(0.0, 1.0, 241)
    poses = np.repeat(np.eye(4)[None], len(s), axis=0)
    angle = 6 * np.pi * s
    poses[:, 0, 0], poses[:, 0, 1] = np.cos(angle), -np.sin(angle)
    poses[:, 1, 0], poses[:, 1, 1] = -np.sin(angle), -np.cos(angle)
    poses[:, 2, 2] = -1.0  # tool z down: diag(1, -1, -1) Rz(angle)
    poses[:, 0, 3] = 0.1 * s
    at = Placement(0.3, 0.3, 0.1, 0.0)
    plain = evaluate_path(PathProblem.of(robot_from_urdf(UR5, **FRAMES), poses), at)
    assert not plain.feasible and plain.reason == "joint_limits"
    unlimited = robot_from_urdf(continuous(UR5, "wrist_3_joint", None), **FRAMES)
    answer = evaluate_path(PathProblem.of(unlimited, poses), at)
    assert answer.feasible and answer.q is not None
    assert abs(np.ptp(answer.q[:, 5]) - 6 * np.pi) < 0.5


def nested(urdf: str, depth: int) -> str:
    """The document with elements ``depth`` deep in all (a gazebo tag nesting depth - 1 more)."""
    inner = "<x>" * (depth - 2) + "</x>" * (depth - 2)
    return urdf.replace("</robot>", f"<gazebo>{inner}</gazebo></robot>")


@pytest.mark.parametrize("stray", [False, True], ids=["continuous", "continuous-and-stray"])
def test_a_document_nested_too_deep_is_refused_not_a_recursion_error(stray: bool) -> None:
    """1,001 deep with a continuous joint: ElementTree wrote it back by recursion (a 500).

    With a link no joint names too (the other document written back). 100 deep reads as the
    document without the nesting: the same limits, the same forward kinematics.
    """
    urdf = continuous(UR5, "wrist_3_joint", None)
    if stray:
        urdf = urdf.replace("</robot>", '<link name="stray"/></robot>')
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(nested(urdf, 1001), **FRAMES)
    assert error.value.field == "robot.urdf"
    assert "nest 1001 deep, more than 100" in error.value.message
    robot, plain = (robot_from_urdf(u, **FRAMES) for u in (nested(urdf, 100), urdf))
    np.testing.assert_array_equal(robot.q_lower, plain.q_lower)
    q = np.random.default_rng(4).uniform(-3.0, 3.0, (5, 6))
    for row in q:
        np.testing.assert_array_equal(tool_pose_in_base(robot, row), tool_pose_in_base(plain, row))


@pytest.mark.parametrize("axis", ["0 0 0", "0 0 1e-300", "1e308 0 1"])
def test_a_joint_axis_of_no_direction_is_refused_naming_the_joint(axis: str) -> None:
    """Zero, or so short or long that normalising it gave NaN: a chain of NaN, a 500 later."""
    urdf = UR5.replace('<axis xyz="0 0 1"/>', f'<axis xyz="{axis}"/>', 1)
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(urdf, **FRAMES)
    assert error.value.field == "robot.urdf"
    assert error.value.message.startswith("joint 'shoulder_pan_joint': its axis (")
    assert "an axis is a direction" in error.value.message


def test_an_axis_of_length_two_reads_as_the_unit_one() -> None:
    """URDF's axes are normalised by the parser: 0 0 2 is the arm of 0 0 1 (forward kinematics)."""
    long, plain = (
        robot_from_urdf(UR5.replace('<axis xyz="0 0 1"/>', f'<axis xyz="{a}"/>', 1), **FRAMES)
        for a in ("0 0 2", "0 0 1")
    )
    for row in np.random.default_rng(5).uniform(-3.0, 3.0, (5, 6)):
        np.testing.assert_allclose(
            tool_pose_in_base(long, row), tool_pose_in_base(plain, row), atol=1e-15
        )


def test_a_joint_limit_whose_lower_is_above_its_upper_is_refused_naming_the_joint() -> None:
    """It was read: every path then failed on joint_limits at waypoint 0 (numeric arms:
    unreachable), where a request's OPW arm with such limits is a 422. Equal limits still read."""
    start = UR5.index('<joint name="wrist_1_joint"')
    end = UR5.index("</joint>", start)
    part = re.sub(r'lower="[^"]*"', 'lower="1.0"', UR5[start:end])
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(
            UR5[:start] + re.sub(r'upper="[^"]*"', 'upper="-1.0"', part) + UR5[end:], **FRAMES
        )
    assert error.value.field == "robot.urdf"
    assert error.value.message == "joint 'wrist_1_joint': its limit's lower 1 is above its upper -1"
    equal = UR5[:start] + re.sub(r'upper="[^"]*"', 'upper="1.0"', part) + UR5[end:]
    robot = robot_from_urdf(equal, **FRAMES)
    assert (robot.q_lower[3], robot.q_upper[3]) == (1.0, 1.0)
