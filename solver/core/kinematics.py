"""Forward kinematics and Jacobians at the tool point, in the base frame {B} (pinocchio)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from solver.core.exceptions import InvalidInputError, quoted_names
from solver.core.robots import Robot


def check_configuration(
    robot: Robot, q: np.ndarray | list[float], *, field: str = "q"
) -> np.ndarray:
    """Return ``q`` as a float array after checking its shape and values.

    Args:
        robot: the arm.
        q: shape (n,), rad (m for prismatic joints), joint positions.
        field: name of the input, for the error message.

    Raises:
        InvalidInputError: wrong shape, a value that is not finite, or a joint outside its
            position limits.
    """
    q_arr = np.asarray(q, dtype=float)
    if q_arr.shape != (robot.dof,):
        given = f"{q_arr.size} joint positions" if q_arr.ndim == 1 else f"shape {q_arr.shape}"
        raise InvalidInputError(
            field,
            f"{given}; the robot has {robot.dof} joints ({quoted_names(robot.joint_names)})",
        )
    bad = np.flatnonzero(~np.isfinite(q_arr))
    if bad.size:
        raise InvalidInputError(
            field, f"joint {int(bad[0])} is {float(q_arr[bad[0]]):.6g}, not finite"
        )
    outside = np.flatnonzero((q_arr < robot.q_lower - 1e-12) | (q_arr > robot.q_upper + 1e-12))
    if outside.size:
        j = int(outside[0])
        raise InvalidInputError(
            field,
            f"joint {j} ({robot.joint_names[j]}) is {float(q_arr[j]):.6g} rad, outside its "
            f"limits [{float(robot.q_lower[j]):.6g}, {float(robot.q_upper[j]):.6g}] rad",
        )
    return q_arr


def tool_pose_in_base(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Pose of the tool point in {B}, T_B_TCP.

    Args:
        robot: the arm.
        q: shape (n,), joint positions (rad).

    Returns:
        shape (4, 4), homogeneous transform, metres.
    """
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.asarray(q, dtype=float))
    world_to_tcp = data.oMf[robot.tool_point_frame].homogeneous
    base_to_tcp: np.ndarray = np.linalg.solve(robot.transform_world_to_base, world_to_tcp)
    return base_to_tcp


def jacobian_in_base(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian at the tool point, with {B} axes (pinocchio LOCAL_WORLD_ALIGNED).

    Args:
        robot: the arm.
        q: shape (n,), joint positions (rad).

    Returns:
        shape (6, n): rows 0-2 the linear velocity of the tool point (m/s per rad/s), rows 3-5
        the angular velocity (rad/s per rad/s), both in {B} axes.
    """
    data = robot.model.createData()
    jacobian_world = pin.computeFrameJacobian(
        robot.model,
        data,
        np.asarray(q, dtype=float),
        robot.tool_point_frame,
        pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
    ).reshape(6, -1)  # a chain of one joint: eigenpy gives its 6 x 1 matrix as a vector
    rotation_base_world = robot.transform_world_to_base[:3, :3].T
    jacobian: np.ndarray = np.empty_like(jacobian_world)
    jacobian[:3] = rotation_base_world @ jacobian_world[:3]
    jacobian[3:] = rotation_base_world @ jacobian_world[3:]
    return jacobian


def revolute_axis(model: pin.Model, joint: int) -> np.ndarray | None:
    """A revolute joint's unit axis in its own frame (RX, RY, RZ or unaligned); else None."""
    name = model.joints[joint].shortname().removeprefix("JointModel")
    if name in ("RX", "RY", "RZ"):
        unit: np.ndarray = np.eye(3)["XYZ".index(name[1])]
        return unit
    if name == "RevoluteUnaligned":
        axis = np.asarray(model.joints[joint].extract().axis, dtype=float)
        return axis / float(np.linalg.norm(axis))
    return None


STRAIGHT_ATOL = 1e-9
"""m, and rad as a unit vector's components: a tool z this close to the last joint's axis, and
a tool point this close to that axis, make a straight spindle (the spin moves that joint only)."""


def straight_spindle(robot: Robot) -> bool:
    """Whether the tool turns about the last joint's own axis: tool z along it, the point on it.

    The tool point's frame as the model places it on its joint (any joint that is not revolute
    about one axis counts as not straight).
    """
    model = robot.model
    frame = model.frames[robot.tool_point_frame]
    joint = int(frame.parentJoint)
    axis = revolute_axis(model, joint) if joint > 0 else None
    if axis is None:
        return False
    tool_z = np.asarray(frame.placement.rotation)[:, 2]
    point = np.asarray(frame.placement.translation)
    along = abs(float(tool_z @ axis))
    off_axis = float(np.linalg.norm(np.cross(point, axis)))
    return along >= 1.0 - STRAIGHT_ATOL and off_axis <= STRAIGHT_ATOL
