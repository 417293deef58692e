"""Symbolic forward kinematics and Jacobian for CasADi, built from the robot's pinocchio model.

The PyPI ``pin`` wheel has no ``pinocchio.casadi``, so the serial chain is rebuilt here: each
joint's placement in its parent (``model.jointPlacements``) and its motion (a rotation about, or
a translation along, a fixed axis), then the tool point frame. Everything is expressed in the
base frame {B} at the tool point, as :mod:`solver.core.kinematics` does with pinocchio (tests check
both agree to 1e-12).
"""

from __future__ import annotations

from typing import Any

import casadi
import numpy as np
import pinocchio as pin

from solver.core.exceptions import RobotModelError
from solver.core.robots import Robot

_AXES = {
    "X": np.array([1.0, 0.0, 0.0]),
    "Y": np.array([0.0, 1.0, 0.0]),
    "Z": np.array([0.0, 0.0, 1.0]),
}

# casadi's bundled stubs reject valid SX/MX expressions (DM + SX, MX in nlpsol): untyped here.
ca: Any = casadi


def _joint_motion(joint: pin.JointModel) -> tuple[str, np.ndarray]:
    """("revolute" or "prismatic", unit axis in the joint frame) of a 1-DOF pinocchio joint."""
    name = joint.shortname()
    for kind, prefix in (("revolute", "JointModelR"), ("prismatic", "JointModelP")):
        if name in (f"{prefix}X", f"{prefix}Y", f"{prefix}Z"):
            return kind, _AXES[name[-1]]
    if name in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
        kind = "revolute" if "Revolute" in name else "prismatic"
        return kind, np.asarray(joint.extract().axis, dtype=float)
    raise RobotModelError("robot", f"joint type {name} has no symbolic model here")


def _rotation(axis: np.ndarray, angle: ca.SX) -> ca.SX:
    """Rodrigues: rotation by ``angle`` about the unit ``axis``, a 3x3 SX."""
    skew = ca.DM([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return ca.DM.eye(3) + ca.sin(angle) * skew + (1.0 - ca.cos(angle)) * (skew @ skew)


def symbolic_kinematics(robot: Robot) -> ca.Function:
    """CasADi function ``q -> (p, R, J)`` of the tool point in {B}.

    Returns:
        A function of q (n x 1) giving the tool point position p (3 x 1, m), its orientation
        R (3 x 3) and the Jacobian J (6 x n; linear rows first, {B} axes at the tool point,
        as pinocchio's LOCAL_WORLD_ALIGNED).

    Raises:
        RobotModelError: the chain is not serial in configuration order, or has a joint type
            other than 1-DOF revolute or prismatic.
    """
    model = robot.model
    n = robot.dof
    q = ca.SX.sym("q", n)
    base = pin.SE3(robot.transform_world_to_base).inverse()
    rotation = ca.DM(base.rotation)
    position = ca.DM(base.translation)
    frames: list[tuple[str, ca.SX, ca.SX]] = []  # joint kind, axis and origin in {B}
    for j in range(1, model.njoints):
        if model.parents[j] != j - 1:
            raise RobotModelError("robot", "the kinematic chain must be serial")
        placement = model.jointPlacements[j]
        position = position + rotation @ ca.DM(placement.translation)
        rotation = rotation @ ca.DM(placement.rotation)
        kind, axis = _joint_motion(model.joints[j])
        frames.append((kind, rotation @ ca.DM(axis), position))
        if kind == "revolute":
            rotation = rotation @ _rotation(axis, q[j - 1])
        else:
            position = position + rotation @ ca.DM(axis) * q[j - 1]
    tool = model.frames[robot.tool_point_frame]
    if tool.parentJoint != n:
        raise RobotModelError("robot", "the tool point must hang on the last joint")
    tool_position = position + rotation @ ca.DM(tool.placement.translation)
    tool_rotation = rotation @ ca.DM(tool.placement.rotation)
    columns = []
    for kind, axis_b, origin in frames:
        if kind == "revolute":
            columns.append(ca.vertcat(ca.cross(axis_b, tool_position - origin), axis_b))
        else:
            columns.append(ca.vertcat(axis_b, ca.DM.zeros(3)))
    jacobian = ca.horzcat(*columns)
    return ca.Function(
        "tool_kinematics", [q], [tool_position, tool_rotation, jacobian], ["q"], ["p", "R", "J"]
    )
