"""What every robot variant of a request shares: its limits' bounds, tool point and options.

The variants themselves (a catalogue model, a URDF, an OPW geometry) are in
:mod:`service.schemas.robot` and :mod:`service.schemas.opw_robot`.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import Field

from service.schemas.common import Pose, RequestModel, pose_matrix_of
from solver.core.joint_limits import (
    MAX_ACCELERATION_LIMIT,
    MAX_SPEED_LIMIT,
    MIN_ACCELERATION_LIMIT,
    MIN_SPEED_LIMIT,
)
from solver.core.robots import Robot as SolverRobot

SpeedLimit = Annotated[float, Field(ge=MIN_SPEED_LIMIT, le=MAX_SPEED_LIMIT)]
AccelerationLimit = Annotated[float, Field(ge=MIN_ACCELERATION_LIMIT, le=MAX_ACCELERATION_LIMIT)]
MAX_JOINTS = 64  # a URDF chain longer than this is not an arm


def speed_limits_field(dofs: list[int] | None, *, required: bool, extra: str = "") -> Any:
    """A ``joint_velocity_limits`` field: n limits within [1e-6, 1e4] rad/s.

    Args:
        dofs: the numbers of joints the arms of this variant may have (the list's length
            must be one of them); ``None``: any, one per joint of the chain.
        required: whether the field must be given.
        extra: a sentence added to the description.
    """
    if dofs is None:
        low, high, count = 1, MAX_JOINTS, "one per joint"
    elif len(dofs) == 1:
        low, high, count = dofs[0], dofs[0], f"{dofs[0]} values"
    else:
        low, high = min(dofs), max(dofs)
        count = f"one per joint of the model ({' or '.join(map(str, sorted(dofs)))} values)"
    return Field(
        default=... if required else None,
        min_length=low,
        max_length=high,
        description=f"Joint speed limits (rad/s; m/s for prismatic joints), {count}, each within "
        f"[1e-6, 1e4].{extra}",
    )


class RobotOptions(RequestModel):
    """What every robot variant may add: its tool point and joint acceleration limits."""

    tcp: Pose | None = Field(
        default=None,
        description="Tool point relative to the tool frame (m, unit quaternion). Default: "
        "identity, the tool point is the tool frame.",
    )
    joint_acceleration_limits: list[AccelerationLimit] | None = Field(
        default=None,
        min_length=1,
        max_length=MAX_JOINTS,
        description="Joint acceleration limits (rad/s^2; m/s^2 for prismatic joints), one per "
        "joint, each within [1e-6, 1e8]. With them the answers add mu_acc, the constant feed "
        "the joint accelerations allow over the blend length (ik.blend_length; motion.md), and "
        "the cycle time. Default: none (the catalogue gives none: no public source we know of "
        "gives its arms' acceleration limits).",
    )

    def _with_tcp(self, robot: SolverRobot) -> SolverRobot:
        """The robot with this request's tool point and acceleration limits."""
        if self.joint_acceleration_limits is not None:
            robot = robot.with_options(qddot_max=self.joint_acceleration_limits)
        if self.tcp is None:
            return robot
        return robot.with_options(transform_tool_to_tcp=pose_matrix_of(self.tcp, field="robot.tcp"))
