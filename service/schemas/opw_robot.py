"""An OPW arm of a request's own: its geometry and joint limits (robots.md).

Brandstotter, Angerer, Hofbaur (2014): an ortho-parallel basis and a spherical wrist, solved in
closed form (the ``opw`` variant of a request's ``robot``).
"""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import ConfigDict, Field
from pydantic.config import JsonValue

from service.schemas.common import Angle, RequestModel
from service.schemas.robot_options import (
    AccelerationLimit,
    RobotOptions,
    SpeedLimit,
    speed_limits_field,
)
from solver.core.robots import Robot as SolverRobot
from solver.families.opw.catalogue import robot_from_opw
from solver.families.opw.parameters import MAX_LENGTH, OpwParameters

Length = Annotated[float, Field(ge=-MAX_LENGTH, le=MAX_LENGTH)]
PositiveLength = Annotated[float, Field(gt=0.0, le=MAX_LENGTH)]
JointRange = Annotated[list[Angle], Field(min_length=2, max_length=2)]


class OpwGeometry(RequestModel):
    """An industrial arm with an ortho-parallel basis and a spherical wrist (OPW, robots.md).

    Brandstotter, Angerer, Hofbaur (2014): seven lengths, and per-joint offsets and sign
    corrections that map the paper's joint zero and direction to the maker's (the convention of
    the ROS-Industrial ``opw_parameters_*.yaml`` files and of ``opw_kinematics``).
    """

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "a1": 0.025,
                    "a2": -0.035,
                    "b": 0.0,
                    "c1": 0.4,
                    "c2": 0.315,
                    "c3": 0.365,
                    "c4": 0.08,
                    "offsets": [0.0, -1.5707963267948966, 0.0, 0.0, 0.0, 0.0],
                    "sign_corrections": [-1, 1, 1, -1, 1, -1],
                }
            ]
        }
    )

    a1: Length = Field(description="Shoulder offset along x (m), |a1| <= 100.")
    a2: Length = Field(description="Elbow offset (m), |a2| <= 100.")
    b: Length = Field(description="Lateral offset (m), |b| <= 100.")
    c1: Length = Field(description="Height of the shoulder above the base (m), |c1| <= 100.")
    c2: PositiveLength = Field(description="Upper arm length (m), 0 < c2 <= 100.")
    c3: PositiveLength = Field(description="Forearm length (m), 0 < c3 <= 100.")
    c4: Length = Field(description="Wrist centre to flange (m), |c4| <= 100.")
    offsets: list[Angle] = Field(
        default=[0.0] * 6,
        min_length=6,
        max_length=6,
        description="Joint zero offsets (rad), 6 values. Default: zeros.",
    )
    sign_corrections: list[Annotated[int, Field(json_schema_extra={"enum": [-1, 1]})]] = Field(
        default=[1] * 6,
        min_length=6,
        max_length=6,
        description="Joint directions, 6 values, each +1 or -1. Default: ones.",
    )

    def to_solver(self) -> OpwParameters:
        """The solver's OPW parameters (checked there)."""
        return OpwParameters(
            a1=self.a1,
            a2=self.a2,
            b=self.b,
            c1=self.c1,
            c2=self.c2,
            c3=self.c3,
            c4=self.c4,
            offsets=tuple(self.offsets),
            sign_corrections=tuple(self.sign_corrections),
        )


_OPW_LIMITS_EXAMPLE: list[JsonValue] = [
    [-3.2, 3.2],
    [-3.3, 0.8],
    [-2.1, 2.9],
    [-6.1, 6.1],
    [-2.1, 2.1],
    [-6.1, 6.1],
]


class OpwRobot(RobotOptions):
    """An OPW industrial arm of your own: its geometry and both kinds of joint limits."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "opw": OpwGeometry.model_config["json_schema_extra"]["examples"][0],  # type: ignore[index]
                    "joint_position_limits": _OPW_LIMITS_EXAMPLE,
                    "joint_velocity_limits": [6.0, 5.0, 6.0, 6.0, 6.0, 9.0],
                }
            ]
        }
    )

    opw: OpwGeometry = Field(
        description="The geometry (joint angles in the maker's convention, {B} the base_link, "
        "the tool frame the flange tool0)."
    )
    joint_position_limits: list[JointRange] = Field(
        min_length=6,
        max_length=6,
        description="[lower, upper] (rad) for each of the 6 joints, lower < upper.",
    )
    joint_velocity_limits: list[SpeedLimit] = speed_limits_field([6], required=True)
    joint_acceleration_limits: list[AccelerationLimit] | None = Field(
        default=None,
        min_length=6,
        max_length=6,
        description="Joint acceleration limits (rad/s^2), 6, each within [1e-6, 1e8]. With them "
        "the answers add mu_acc, the constant feed the joint accelerations allow over the blend "
        "length (ik.blend_length; motion.md), and the cycle time. Default: none.",
    )

    def to_solver(self) -> SolverRobot:
        """The OPW arm, with its limits and tool point."""
        robot = robot_from_opw(
            "opw",
            self.opw.to_solver(),
            joint_position_limits=np.array(self.joint_position_limits, dtype=float),
            qdot_max=self.joint_velocity_limits,
        )
        return self._with_tcp(robot)
