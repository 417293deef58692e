"""The arm of a request: one object per robot source, told apart by its key (api.md, robots.md).

``robot`` is a ``oneOf``: a catalogue ``model``, a ``urdf`` with its frames, or an ``opw``
geometry. Each variant states its own rules as JSON Schema (the model names as an enum, speed
limits within [1e-6, 1e4], list lengths), so a generated client knows what is accepted, and each
converts itself to the solver's robot (``to_solver``). A new robot source is a new variant here.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import ConfigDict, Discriminator, Field, Tag, field_validator
from pydantic.config import JsonValue
from pydantic_core import PydanticCustomError

from service.schemas.common import Angle, Pose, RequestModel, pose_matrix_of, shown
from solver.core.robots import (
    MAX_ACCELERATION_LIMIT,
    MAX_SPEED_LIMIT,
    MIN_ACCELERATION_LIMIT,
    MIN_SPEED_LIMIT,
)
from solver.core.robots import Robot as SolverRobot
from solver.families import catalogue, robot_from_urdf
from solver.families.opw.catalogue import robot_from_opw
from solver.families.opw.parameters import MAX_LENGTH, OpwParameters

SpeedLimit = Annotated[float, Field(ge=MIN_SPEED_LIMIT, le=MAX_SPEED_LIMIT)]
AccelerationLimit = Annotated[float, Field(ge=MIN_ACCELERATION_LIMIT, le=MAX_ACCELERATION_LIMIT)]
Length = Annotated[float, Field(ge=-MAX_LENGTH, le=MAX_LENGTH)]
PositiveLength = Annotated[float, Field(gt=0.0, le=MAX_LENGTH)]
JointRange = Annotated[list[Angle], Field(min_length=2, max_length=2)]
MAX_JOINTS = 64  # a URDF chain longer than this is not an arm


def catalogue_dofs() -> set[int]:
    """The numbers of joints of the catalogue's arms."""
    return {robot.dof for robot in catalogue().values()}


def _speed_limits(dofs: list[int] | None, *, required: bool, extra: str = "") -> Any:
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


class _RobotOptions(RequestModel):
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


_DOFS = sorted(catalogue_dofs())


class CatalogueRobot(_RobotOptions):
    """A robot of the catalogue (GET /v1/robots), optionally with other speed limits."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"model": "ur5e"},
                {"model": "ur5", "joint_velocity_limits": [3.0, 3.0, 3.0, 3.0, 3.0, 3.0]},
            ]
        }
    )

    model: str = Field(
        description="A robot name from GET /v1/robots.",
        json_schema_extra={"enum": list[JsonValue](sorted(catalogue()))},
    )
    joint_velocity_limits: list[SpeedLimit] | None = _speed_limits(
        _DOFS, required=False, extra=" Default: the model's."
    )

    @field_validator("model")
    @classmethod
    def _known(cls, value: str) -> str:
        names = catalogue()
        if value not in names:
            raise PydanticCustomError(
                "unknown_robot",
                "unknown robot {name}; the catalogue has {names}",
                {"name": shown(value), "names": ", ".join(sorted(names))},
            )
        return value

    def to_solver(self) -> SolverRobot:
        """The catalogue robot with this request's speed limits and tool point."""
        robot = catalogue()[self.model].with_options(qdot_max=self.joint_velocity_limits)
        return self._with_tcp(robot)


class UrdfRobot(_RobotOptions):
    """A serial arm described by a URDF document and the two frames that bound its chain."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "urdf": "<robot name='arm'>...</robot>",
                    "base_frame": "base",
                    "tool_frame": "tool0",
                }
            ]
        }
    )

    urdf: str = Field(
        min_length=1,
        description="URDF document of a serial arm (lengths in m, angles in rad); joints that do "
        "not move tool_frame are locked.",
    )
    base_frame: str = Field(
        min_length=1,
        description="The frame fixed to the root that poses and twists are expressed in; a link "
        "or frame of the URDF.",
    )
    tool_frame: str = Field(
        min_length=1, description="The tool flange frame; a link or frame of the URDF."
    )
    joint_velocity_limits: list[SpeedLimit] | None = _speed_limits(
        None,
        required=False,
        extra=" Default: the URDF's velocity limits. With <mimic> joints, one per coordinate (a "
        "mimic joint has none): a leader's limit above its mimic joint's own over |multiplier| "
        "is refused (422).",
    )

    def to_solver(self) -> SolverRobot:
        """The arm of the URDF, with its speed limits and tool point."""
        robot = robot_from_urdf(
            self.urdf,
            base_frame=self.base_frame,
            tool_frame=self.tool_frame,
            qdot_max=self.joint_velocity_limits,
        )
        return self._with_tcp(robot)


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


class OpwRobot(_RobotOptions):
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
    joint_velocity_limits: list[SpeedLimit] = _speed_limits([6], required=True)
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


_SOURCES = ("model", "urdf", "opw")


def _robot_source(value: object) -> str | None:
    """Tag of a robot: which one of model, urdf or opw it gives (``None``: not exactly one)."""
    if isinstance(value, dict):
        given = [key for key in _SOURCES if value.get(key) is not None]
        return f"robot:{given[0]}" if len(given) == 1 else None
    for kind, source in ((CatalogueRobot, "model"), (UrdfRobot, "urdf"), (OpwRobot, "opw")):
        if isinstance(value, kind):
            return f"robot:{source}"
    return None


Robot = Annotated[
    Annotated[CatalogueRobot, Tag("robot:model")]
    | Annotated[UrdfRobot, Tag("robot:urdf")]
    | Annotated[OpwRobot, Tag("robot:opw")],
    Discriminator(
        _robot_source,
        custom_error_type="robot_source",
        custom_error_message="give exactly one of model (a name from GET /v1/robots), urdf or opw",
    ),
]
"""The arm: a catalogue model, a URDF with its frames, or an OPW geometry with its limits."""
