"""OPW arms as robots: the catalogue's six arms, and an arm defined in a request."""

from __future__ import annotations

import math

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.joint_limits import check_speed_limits
from solver.core.robots import Robot, robot_from_model
from solver.families.opw.arms import ARMS
from solver.families.opw.family import OpwFamily
from solver.families.opw.model import opw_model
from solver.families.opw.parameters import OpwParameters

JOINT_NAMES = tuple(f"joint_{i}" for i in range(1, 7))


def check_position_limits(
    limits: np.ndarray | list[list[float]], joint_names: tuple[str, ...] = JOINT_NAMES
) -> np.ndarray:
    """Joint position limits as a (6, 2) array [lower, upper] (rad), after checking them.

    Args:
        limits: shape (6, 2), rad, [lower, upper] per joint.
        joint_names: the six joint names, for the message.

    Raises:
        InvalidInputError: on ``robot.joint_position_limits``: a wrong count, a value that is
            not finite, or lower >= upper (naming the joint).
    """
    field = "robot.joint_position_limits"
    try:
        arr = np.asarray(limits, dtype=float)
    except (TypeError, ValueError) as error:
        raise InvalidInputError(
            field, f"needs 6 [lower, upper] pairs of numbers: {error}"
        ) from None
    if arr.shape != (6, 2):
        raise InvalidInputError(field, f"needs 6 [lower, upper] pairs (rad), got shape {arr.shape}")
    for j, (low, high) in enumerate(arr):
        if not (math.isfinite(low) and math.isfinite(high)) or low >= high:
            raise InvalidInputError(
                field,
                f"joint {j + 1} ({joint_names[j]}): [{low:g}, {high:g}] rad needs finite "
                "lower < upper",
            )
    return arr


def robot_from_opw(
    name: str,
    parameters: OpwParameters,
    *,
    joint_position_limits: np.ndarray | list[list[float]],
    qdot_max: np.ndarray | list[float],
    joint_names: tuple[str, ...] = JOINT_NAMES,
) -> Robot:
    """An OPW arm as a robot: {B} = base_link, the tool frame the flange tool0.

    Args:
        name: the robot's name.
        parameters: the geometry (checked when it was made).
        joint_position_limits: shape (6, 2), rad, [lower, upper] per joint, maker's convention.
        qdot_max: shape (6,), rad/s.
        joint_names: the six joint names.

    Raises:
        InvalidInputError: on ``robot.joint_names``, not six distinct names; on
            ``robot.joint_position_limits``, limits of the wrong count, not finite or not
            ordered; on ``robot.joint_velocity_limits``, speed limits out of range.
    """
    if len(joint_names) != 6 or len(set(joint_names)) != 6:
        raise InvalidInputError(
            "robot.joint_names", f"needs 6 distinct names, got {list(joint_names)}"
        )
    limits = check_position_limits(joint_position_limits, joint_names)
    speeds = check_speed_limits(qdot_max, joint_names)
    model = opw_model(
        parameters,
        joint_names=joint_names,
        q_lower=limits[:, 0],
        q_upper=limits[:, 1],
        qdot_max=speeds,
    )
    return robot_from_model(
        name,
        model,
        base_frame="base_link",
        tool_frame="tool0",
        qdot_max=speeds,
        family=OpwFamily(parameters),
    )


def robots() -> dict[str, Robot]:
    """The catalogue's OPW arms by name."""
    return {
        arm.name: robot_from_opw(
            arm.name,
            arm.parameters,
            joint_position_limits=np.array(arm.position_limits),
            qdot_max=np.array(arm.velocity_limits),
            joint_names=arm.joint_names,
        )
        for arm in ARMS
    }
