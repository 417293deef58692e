"""A UR arm given as a URDF is recognised and mapped as the catalogue's UR arm (issue 27).

The UR5 as a plain URDF (example-robot-data's, as a user would send it): the registry fits the
six UR lengths to its forward kinematics and solves it in closed form, so its ERK map is the
catalogue UR5's cell for cell (numeric IK took 413 times as long). In its DH base frame
``base`` the lengths are the catalogue's; in ROS's ``base_link``, half a turn about z from it,
the family solves in the turned frame, so a placement there is the catalogue's placement half a
turn away (geometry), and the map equals the numeric family's on the same chain. A frame tilted
from z is no turn of a UR arm's frame: numeric IK.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from solver.core.codes import REASONS
from solver.core.robots import chain_from_urdf, example_robot_data_dir
from solver.core.spatial import Placement
from solver.families import closed_form_bases, get_robot, robot_from_urdf
from solver.families.numeric.family import NumericFamily
from solver.families.ur.dh import UR_DH
from solver.path.cell.shapes import Box, Cell
from tests.cases import MAP_EVALUATE_RTOL
from tests.problems import capability_map, evaluate_path, evaluate_placements, prepare_path
from tests.solver.families.recognised import answers_alike
from tests.solver.test_evaluate import load_path

UR5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
XS, YS = np.arange(-0.25, 0.25 + 1e-9, 0.02), np.arange(0.25, 0.65 + 1e-9, 0.02)  # ERK's grid


def _with_frame(name: str, xyz: str, rpy: str) -> str:
    """The UR5 URDF with a link ``name`` fixed to base_link at the origin ``xyz``, ``rpy``."""
    joint = (
        f'<link name="{name}"/><joint name="{name}_joint" type="fixed"><parent link="base_link"/>'
        f'<child link="{name}"/><origin xyz="{xyz}" rpy="{rpy}"/></joint>'
    )
    return UR5.replace("</robot>", joint + "</robot>")


def test_the_ur5_urdf_is_recognised_with_its_lengths_from_base_and_base_link() -> None:
    for frame, turn in (("base", None), ("base_link", math.pi)):
        robot = robot_from_urdf(UR5, base_frame=frame, tool_frame="tool0")
        assert robot.family is not None and robot.family.name == "ur", frame
        assert robot.family.recognised is not None and "UR arm" in robot.family.recognised
        fitted = robot.family.parameters
        for name in ("d1", "a2", "a3", "d4", "d5", "d6"):
            assert abs(getattr(fitted, name) - getattr(UR_DH["ur5"], name)) < 1e-9, name
        if turn is None:
            assert robot.family.base_turn is None
        else:
            assert robot.family.base_turn is not None
            assert abs(abs(robot.family.base_turn.angle) - turn) < 1e-12
            assert robot.family.base_turn.shift == (0.0, 0.0, 0.0)
            assert "turned by 180 deg about z" in robot.family.recognised


def test_the_base_frames_with_a_closed_form_are_named() -> None:
    # The URDF's links and frames fixed to its root: world, base_link and base (its DH frame),
    # each a turn about z of the DH frame, and a frame tilted about x (joint 1 not upright in
    # it: the closed form in that frame tilted back, tests/solver/families/test_tilted_base).
    urdf = _with_frame("tilted", "0 0 0", "0.3 0 0")
    named = closed_form_bases(urdf, tool_frame="tool0")
    assert sorted(named) == ["base", "base_link", "tilted", "world"]
    robot = robot_from_urdf(urdf, base_frame="tilted", tool_frame="tool0")
    assert robot.family is not None and robot.family.name == "ur"
    assert (
        robot.family.recognised is not None and "tilted by 17.1887 deg" in robot.family.recognised
    )
    assert closed_form_bases(UR5, tool_frame="wrist_2_link") == []  # five joints: no closed form


def test_the_ur5_urdf_map_equals_the_catalogue_map_on_the_erk_grid() -> None:
    maps = [
        capability_map(robot, load_path("curved_line"), xs=XS, ys=YS, z=0.1, yaws=np.zeros(1))
        for robot in (get_robot("ur5"), robot_from_urdf(UR5, base_frame="base", tool_frame="tool0"))
    ]
    expected, answer = maps
    assert expected.mu_path.size == 546 and np.isfinite(expected.mu_path).all()
    np.testing.assert_allclose(answer.mu_path, expected.mu_path, rtol=MAP_EVALUATE_RTOL)
    np.testing.assert_array_equal(answer.branch, expected.branch)
    np.testing.assert_array_equal(answer.bottleneck_joint, expected.bottleneck_joint)


def test_from_base_link_the_map_is_the_catalogue_map_half_a_turn_away_and_the_numeric_map() -> None:
    # (x, y, yaw) in base_link is (-x, -y, yaw + pi) in the DH frame: the catalogue's map on the
    # grid turned by half a turn, its axes reversed, is this map cell for cell; so is the map of
    # numeric IK on the same chain (its branches are numbered as found: not compared).
    path = load_path("curved_line")
    frames = {"base_frame": "base_link", "tool_frame": "tool0"}
    turned = robot_from_urdf(UR5, **frames)
    numeric_family = NumericFamily(chain_from_urdf(UR5, tool_frame="tool0"), **frames)
    numeric = robot_from_urdf(UR5, **frames, family=numeric_family)
    answer = capability_map(turned, path, xs=XS, ys=YS, z=0.1, yaws=np.zeros(1))
    catalogue = capability_map(
        get_robot("ur5"), path, xs=-XS[::-1], ys=-YS[::-1], z=0.1, yaws=np.array([math.pi])
    )
    assert np.isfinite(answer.mu_path).all()
    reversed_axes = (slice(None), slice(None), slice(None, None, -1), slice(None, None, -1))
    expected = catalogue.mu_path[reversed_axes]
    np.testing.assert_allclose(answer.mu_path, expected, rtol=MAP_EVALUATE_RTOL)
    np.testing.assert_array_equal(answer.branch, catalogue.branch[reversed_axes])
    np.testing.assert_array_equal(
        answer.bottleneck_joint, catalogue.bottleneck_joint[reversed_axes]
    )
    by_numeric = capability_map(numeric, path, xs=XS, ys=YS, z=0.1, yaws=np.zeros(1))
    np.testing.assert_allclose(by_numeric.mu_path, answer.mu_path, rtol=MAP_EVALUATE_RTOL)


@pytest.mark.parametrize("catalogue_placement", [(0.0, 0.4, 0.1, 0.0), (-0.2, 0.55, 0.05, 0.4)])
def test_a_base_turned_and_moved_gives_the_catalogue_answer_at_the_same_place(
    catalogue_placement: tuple[float, float, float, float],
) -> None:
    # A frame "pedestal" in which base_link is at (0.4, -0.3, 0.2), turned a quarter about z
    # (so pedestal is at (0.3, 0.4, -0.2) in base_link, turned by -pi/2): the DH frame is
    # pedestal's turned by -pi/2 (base_link is half a turn from it) at (0.4, -0.3, 0.2). The
    # catalogue's placement (X, Y, Z, YAW) in the DH frame is, in pedestal,
    # (Y + 0.4, -X - 0.3, Z + 0.2, YAW - pi/2): the same joint path, the same feed.
    urdf = _with_frame("pedestal", "0.3 0.4 -0.2", f"0 0 {-math.pi / 2!r}")
    robot = robot_from_urdf(urdf, base_frame="pedestal", tool_frame="tool0")
    assert robot.family is not None and robot.family.name == "ur"
    assert robot.family.recognised is not None and "(0.4, -0.3, 0) m" in robot.family.recognised
    x, y, z, yaw = catalogue_placement
    path = load_path("curved_line")
    expected = evaluate_path(get_robot("ur5"), path, Placement(x, y, z, yaw))
    placement = Placement(y + 0.4, -x - 0.3, z + 0.2, yaw - math.pi / 2)
    answer = evaluate_path(robot, path, placement)
    assert expected.feasible and answer.feasible
    assert answer.mu_path == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
    mapped = evaluate_placements(robot, prepare_path(robot, path), placement.as_row()[None])
    assert mapped.mu_path[0] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)  # kernel
    assert expected.q is not None and answer.q is not None
    np.testing.assert_allclose(answer.q, expected.q, atol=1e-9)
    assert answer.branch == expected.branch


def test_from_base_link_the_cell_sees_the_joint_paths_numeric_ik_finds() -> None:
    # The collision check places the URDF's links at the joint paths the kernel gives: in a
    # cell of two posts in base_link, the map (the kernel solving in the turned frame) collides
    # where, and only where, the map of numeric IK on the same chain does.
    def post(x: float, y: float, z: float) -> Box:
        pose = np.eye(4)
        pose[:3, 3] = [x, y, z]
        return Box((0.15, 0.15, 0.15), pose, name=f"post {x}")

    cell = Cell(fixed=(post(0.15, 0.0, 0.55), post(-0.3, 0.1, 0.45)))
    frames = {"base_frame": "base_link", "tool_frame": "tool0"}
    numeric_family = NumericFamily(chain_from_urdf(UR5, tool_frame="tool0"), **frames)
    maps = [
        capability_map(
            robot,
            load_path("curved_line"),
            xs=XS[::5],
            ys=YS[::5],
            z=0.1,
            yaws=np.zeros(1),
            cell=cell,
        )
        for robot in (
            robot_from_urdf(UR5, **frames),
            robot_from_urdf(UR5, **frames, family=numeric_family),
        )
    ]
    answer, by_numeric = maps
    collides = answer.reason == REASONS.index("collision")
    assert 0 < collides.sum() < collides.size - 1  # both kinds of cell
    np.testing.assert_array_equal(answer.reason, by_numeric.reason)
    np.testing.assert_allclose(answer.mu_path, by_numeric.mu_path, rtol=MAP_EVALUATE_RTOL)


@pytest.mark.parametrize(("base", "tool"), [("base_link", "ee_link"), ("base", "wrist_3_link")])
def test_a_tool_frame_on_the_last_link_gives_the_tool0_answer_with_that_tool_point(
    base: str, tool: str
) -> None:
    # ROS's UR descriptions end in ee_link (MoveIt's classic tip: x along the tool axis) and
    # wrist_3_link (the joint's own frame) beside tool0: the DH flange turned or moved on the
    # last link. Recognised with that offset: at the same placements it must answer what the
    # chain to tool0 answers with the frame as its tool point (the pose of the frame in tool0,
    # from pinocchio), through evaluate and the map kernel; and its map must be the numeric
    # family's on the same chain.
    robot = robot_from_urdf(UR5, base_frame=base, tool_frame=tool)
    assert robot.family is not None and robot.family.name == "ur"
    assert robot.family.flange_offset is not None
    assert robot.family.recognised is not None and "whose tool frame is the DH flange" in (
        robot.family.recognised
    )
    for name in ("d1", "a2", "a3", "d4", "d5"):
        assert abs(getattr(robot.family.parameters, name) - getattr(UR_DH["ur5"], name)) < 1e-9
    model = pin.buildModelFromXML(UR5)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    frame = {name: data.oMf[model.getFrameId(name)] for name in ("tool0", tool)}
    at_tool0 = robot_from_urdf(UR5, base_frame=base, tool_frame="tool0").with_options(
        transform_tool_to_tcp=(frame["tool0"].inverse() * frame[tool]).homogeneous
    )
    path = load_path("curved_line")
    checked = 0
    for x, y, yaw in ((0.0, 0.4, 0.0), (-0.2, 0.55, 0.4), (0.15, 0.3, 2.0)):
        placement = Placement(x, y, 0.1, yaw)
        expected = evaluate_path(at_tool0, path, placement)
        checked += answers_alike(robot, path, placement, expected)
        free = evaluate_path(at_tool0, path, placement, spin_mode="free")
        answers_alike(robot, path, placement, free, spin_mode="free")
    assert checked >= 2
    frames = {"base_frame": base, "tool_frame": tool}
    numeric_family = NumericFamily(chain_from_urdf(UR5, tool_frame=tool), **frames)
    numeric = robot_from_urdf(UR5, **frames, family=numeric_family)
    grid = {"xs": XS[::4], "ys": YS[::4], "z": 0.1, "yaws": np.array([0.0, 2.0])}
    answer, by_numeric = (capability_map(arm, path, **grid) for arm in (robot, numeric))
    assert np.isfinite(answer.mu_path).sum() >= 20
    np.testing.assert_allclose(by_numeric.mu_path, answer.mu_path, rtol=MAP_EVALUATE_RTOL)
