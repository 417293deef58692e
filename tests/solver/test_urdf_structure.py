"""A URDF's structure said in the answer: links joined to nothing, two root links, mimic joints.

The fixtures are the UR5 URDF of example-robot-data, edited as the published files that showed
each case (a ROS 2 generated UR5e with a stray ``world`` link; a mimic joint between base and
tool, as ABB IRB 5400's joint5b, here following a joint that is not there).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from solver.core.exceptions import RobotModelError
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import example_robot_data_dir
from solver.core.urdf_structure import (
    StrayLink,
    fixed_to_root,
    mimic_joints,
    root_links,
    stray_links,
)
from solver.families import catalogue, robot_from_urdf

UR5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
FRAMES = {"base_frame": "base", "tool_frame": "tool0"}


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
    assert robot.left_out_links == ("world",)
    assert robot.urdf is not None and root_links(robot.urdf) == ["base_link"]
    # The same arm as the document with the link deleted by hand (and as the catalogue's UR5,
    # whose world is base_link's parent at the identity): forward kinematics at random q.
    by_hand = robot_from_urdf(STRAY.replace('<link name="world"/>', ""), **FRAMES)
    assert by_hand.left_out_links == ()
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
