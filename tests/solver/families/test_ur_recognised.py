"""A UR arm given as a URDF is recognised and mapped as the catalogue's UR arm (issue 27).

The UR5 as a plain URDF (example-robot-data's, as a user would send it) in its DH base frame
``base``: the registry fits the six UR lengths to its forward kinematics and solves it in closed
form, so its ERK map is the catalogue UR5's cell for cell (numeric IK took 413 times as long).
In ``base_link`` (turned by pi about z) it is not a UR arm in {B} and keeps numeric IK.
"""

from __future__ import annotations

import numpy as np

from solver.core.robots import example_robot_data_dir
from solver.families import closed_form_bases, get_robot, robot_from_urdf
from solver.families.ur.dh import UR_DH
from tests.cases import MAP_EVALUATE_RTOL
from tests.problems import capability_map
from tests.solver.test_evaluate import load_path

UR5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()


def test_the_ur5_urdf_is_recognised_with_its_lengths() -> None:
    robot = robot_from_urdf(UR5, base_frame="base", tool_frame="tool0")
    assert robot.family is not None and robot.family.name == "ur"
    assert robot.family.recognised is not None and "UR arm" in robot.family.recognised
    fitted = robot.family.parameters
    for name in ("d1", "a2", "a3", "d4", "d5", "d6"):
        assert abs(getattr(fitted, name) - getattr(UR_DH["ur5"], name)) < 1e-9, name
    other = robot_from_urdf(UR5, base_frame="base_link", tool_frame="tool0")
    assert other.family is not None and other.family.name == "numeric"


def test_the_base_frames_with_a_closed_form_are_named() -> None:
    # The URDF's links and frames fixed to its root: world, base_link and base (its DH frame);
    # only from base is the chain the UR arm's, as each frame's own robot says.
    named = closed_form_bases(UR5, tool_frame="tool0")
    assert named == ["base"]
    for frame in ("world", "base_link"):
        robot = robot_from_urdf(UR5, base_frame=frame, tool_frame="tool0")
        assert robot.family is not None and robot.family.name == "numeric", frame
    assert closed_form_bases(UR5, tool_frame="wrist_2_link") == []  # five joints: no closed form


def test_the_ur5_urdf_map_equals_the_catalogue_map_on_the_erk_grid() -> None:
    maps = [
        capability_map(
            robot,
            load_path("curved_line"),
            xs=np.arange(-0.25, 0.25 + 1e-9, 0.02),
            ys=np.arange(0.25, 0.65 + 1e-9, 0.02),
            z=0.1,
            yaws=np.zeros(1),
        )
        for robot in (get_robot("ur5"), robot_from_urdf(UR5, base_frame="base", tool_frame="tool0"))
    ]
    expected, answer = maps
    assert expected.mu_path.size == 546 and np.isfinite(expected.mu_path).all()
    np.testing.assert_allclose(answer.mu_path, expected.mu_path, rtol=MAP_EVALUATE_RTOL)
    np.testing.assert_array_equal(answer.branch, expected.branch)
    np.testing.assert_array_equal(answer.bottleneck_joint, expected.bottleneck_joint)
