"""Arms the benchmark lines share: the UR5's URDF from example-robot-data, read as a user's."""

from __future__ import annotations

import math

from solver.core.robots import Robot, chain_from_urdf, example_robot_data_dir
from solver.families import robot_from_urdf
from solver.families.numeric.family import NumericFamily

UR5_FRAMES = {"base_frame": "base", "tool_frame": "tool0"}


def ur5_urdf() -> str:
    """The UR5's URDF, its right angles written to the last bit (so its maps equal the DH arm's)."""
    file = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    urdf = file.read_text().replace("1.57079632679", repr(math.pi / 2))
    return urdf.replace("3.14159265359", repr(math.pi))


def ur5_as_numeric(urdf: str) -> Robot:
    """The UR5 from ``urdf`` given the numeric family (robots.md section 4), not recognised."""
    numeric = NumericFamily(chain_from_urdf(urdf, tool_frame="tool0"), **UR5_FRAMES)
    return robot_from_urdf(urdf, **UR5_FRAMES, family=numeric)
