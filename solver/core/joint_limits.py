"""Joint speed and acceleration limits, checked: one per joint, finite, within a range.

A robot's limits (:class:`solver.core.robots.Robot`) come from its model or its request; both
pass through here, and the service's schemas take the same ranges as their bounds.
"""

from __future__ import annotations

import numpy as np

from solver.core.exceptions import InvalidInputError, quoted, quoted_names

# Joint speed limits outside this range (rad/s) are input errors: no arm is that slow or fast,
# and the LP solver treats bounds past 1e20 as infinite.
MIN_SPEED_LIMIT = 1e-6
MAX_SPEED_LIMIT = 1e4
# Joint acceleration limits outside this range (rad/s^2) are input errors likewise (motion.md).
MIN_ACCELERATION_LIMIT = 1e-6
MAX_ACCELERATION_LIMIT = 1e8


def _checked_limits(
    values: np.ndarray | list[float],
    joint_names: tuple[str, ...],
    *,
    field: str,
    unit: str,
    lower: float,
    upper: float,
) -> np.ndarray:
    """Per-joint limits as a float array: one per joint, finite, within [lower, upper].

    Raises:
        InvalidInputError: on ``field``, naming the count or the joint at fault.
    """
    limits = np.array(values, dtype=float)
    if limits.shape != (len(joint_names),):
        count = limits.size if limits.ndim == 1 else f"an array of shape {limits.shape} of"
        raise InvalidInputError(
            field,
            f"{count} values for the {len(joint_names)} joints ({quoted_names(joint_names)}): "
            "give one per joint, in this order",
        )
    bad = np.flatnonzero(~np.isfinite(limits) | (limits < lower) | (limits > upper))
    if bad.size:
        j = int(bad[0])
        raise InvalidInputError(
            field,
            f"joint {j} ({quoted(joint_names[j])}) limit {float(limits[j]):.6g} {unit} must be "
            f"> 0, within [{lower}, {upper}] {unit}",
        )
    return limits


def check_speed_limits(
    qdot_max: np.ndarray | list[float], joint_names: tuple[str, ...]
) -> np.ndarray:
    """Joint speed limits as a float array, after checking them.

    Args:
        qdot_max: shape (n,), rad/s, each in [MIN_SPEED_LIMIT, MAX_SPEED_LIMIT].
        joint_names: the n joint names, for the message.

    Raises:
        InvalidInputError: on ``robot.joint_velocity_limits``: wrong length, not finite, or
            out of range.
    """
    return _checked_limits(
        qdot_max,
        joint_names,
        field="robot.joint_velocity_limits",
        unit="rad/s",
        lower=MIN_SPEED_LIMIT,
        upper=MAX_SPEED_LIMIT,
    )


def check_acceleration_limits(
    qddot_max: np.ndarray | list[float], joint_names: tuple[str, ...]
) -> np.ndarray:
    """Joint acceleration limits as a float array, after checking them (motion.md section 1).

    Args:
        qddot_max: shape (n,), rad/s^2, each in [MIN_ACCELERATION_LIMIT, MAX_ACCELERATION_LIMIT].
        joint_names: the n joint names, for the message.

    Raises:
        InvalidInputError: on ``robot.joint_acceleration_limits``, naming the joint: wrong
            length, not finite, or out of range.
    """
    return _checked_limits(
        qddot_max,
        joint_names,
        field="robot.joint_acceleration_limits",
        unit="rad/s^2",
        lower=MIN_ACCELERATION_LIMIT,
        upper=MAX_ACCELERATION_LIMIT,
    )
