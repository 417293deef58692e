"""The UR arms of the catalogue.

The CB-series arms (ur3, ur5, ur10) are the example-robot-data URDFs, loaded by path; {B} is
the controller's ``base`` frame (the URDF's ``base_link`` turned by pi about z, and the frame of
the DH parameters), {F} the flange ``tool0``. No URDF ships for the e-series, so ur3e, ur5e,
ur10e and ur16e are built from their published nominal DH parameters (dtf.md section 8).
"""

from __future__ import annotations

import math
import re

import numpy as np

from solver.core.robots import Robot, example_robot_data_dir, robot_from_model
from solver.families import robot_from_urdf
from solver.families.ur.dh import E_SERIES_SPEEDS, UR_DH, ur_model_from_dh
from solver.families.ur.family import UrFamily


def _exact_right_angles(urdf: str) -> str:
    """Restore pi/2 and pi in the joint orientations (rpy) where the UR URDFs round them.

    ``rpy="0.0 1.57079632679 0.0"`` is pi/2 - 5e-12: the chain then misses the DH chain (and the
    controller) by ~1e-11 m, which near a singularity grows to ~1e-9 relative in J^-1. Joint
    limits are left as written.
    """
    exact = {"1.57079632679": math.pi / 2, "3.14159265359": math.pi}

    def fix(match: re.Match[str]) -> str:
        values = []
        for token in match.group(1).split():
            sign, digits = ("-", token[1:]) if token.startswith("-") else ("", token)
            values.append(f"{sign}{exact[digits]!r}" if digits in exact else token)
        return f'rpy="{" ".join(values)}"'

    return re.sub(r'rpy="([^"]*)"', fix, urdf)


def robots() -> dict[str, Robot]:
    """The UR arms by name."""
    arms: dict[str, Robot] = {}
    for name in ("ur3", "ur5", "ur10"):
        path = example_robot_data_dir() / "ur_description" / "urdf" / f"{name}_robot.urdf"
        urdf = _exact_right_angles(path.read_text())
        arms[name] = robot_from_urdf(
            urdf, base_frame="base", tool_frame="tool0", name=name, family=UrFamily(UR_DH[name])
        )
    for name, speeds in E_SERIES_SPEEDS.items():
        arms[name] = robot_from_model(
            name,
            ur_model_from_dh(UR_DH[name]),
            base_frame="base",
            tool_frame="tool0",
            qdot_max=np.array(speeds),
            family=UrFamily(UR_DH[name]),
        )
    return arms
