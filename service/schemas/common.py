"""Objects shared by several routes: Pose, Robot, Path, Placement, IK branch (api.md).

Every request model is strict (a number is a JSON number, not a string), refuses unknown fields,
and refuses NaN and infinities, so bad input of any kind is a ``422`` that names the field.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    PositiveFloat,
    Tag,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic_core import PydanticCustomError

from solver.evaluate import DEFAULT_MAX_JOINT_STEP
from solver.spatial import QUATERNION_NORM_TOLERANCE

Vector3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Quaternion = Annotated[list[float], Field(min_length=4, max_length=4)]


class RequestModel(BaseModel):
    """Base of request bodies: strict types, no unknown fields, finite numbers only."""

    model_config = ConfigDict(allow_inf_nan=False, strict=True, extra="forbid")


class ResponseModel(BaseModel):
    """Base of response bodies: finite numbers only (``null`` where a value does not exist)."""

    model_config = ConfigDict(allow_inf_nan=False)


class Pose(RequestModel):
    """A tool point pose: position and unit quaternion in ROS order (x, y, z, w)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"position": [0.4, 0.1, 0.2], "orientation": [1, 0, 0, 0]}]}
    )

    position: Vector3 = Field(description="Position [x, y, z] (m).")
    orientation: Quaternion = Field(
        description="Unit quaternion [qx, qy, qz, qw] (dimensionless, ROS order). A norm off "
        "by more than 1e-6 is refused, never normalised."
    )

    @field_validator("orientation")
    @classmethod
    def _unit_norm(cls, value: list[float]) -> list[float]:
        norm = math.hypot(*value)
        if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
            raise PydanticCustomError(
                "unit_quaternion",
                "quaternion norm is {norm}; a unit quaternion is needed (tolerance 1e-6)",
                {"norm": norm},
            )
        return value


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

    a1: float = Field(description="Shoulder offset along x (m), |a1| <= 100.")
    a2: float = Field(description="Elbow offset (m), |a2| <= 100.")
    b: float = Field(description="Lateral offset (m), |b| <= 100.")
    c1: float = Field(description="Height of the shoulder above the base (m), |c1| <= 100.")
    c2: float = Field(description="Upper arm length (m), 0 < c2 <= 100.")
    c3: float = Field(description="Forearm length (m), 0 < c3 <= 100.")
    c4: float = Field(description="Wrist centre to flange (m), |c4| <= 100.")
    offsets: list[float] = Field(
        default=[0.0] * 6, description="Joint zero offsets (rad), 6 values. Default: zeros."
    )
    sign_corrections: list[int] = Field(
        default=[1] * 6, description="Joint directions, 6 values, each +1 or -1. Default: ones."
    )


class Robot(RequestModel):
    """The arm: a catalogue ``model``, a ``urdf`` with its frames, or an ``opw`` geometry."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"model": "ur5e"},
                {"model": "ur5", "joint_velocity_limits": [3.0, 3.0, 3.0, 3.0, 3.0, 3.0]},
                {
                    "urdf": "<robot name='arm'>...</robot>",
                    "base_frame": "base",
                    "tool_frame": "tool0",
                },
            ]
        }
    )

    model: str | None = Field(
        default=None,
        description="A robot name from GET /v1/robots. Give exactly one of model, urdf, opw.",
    )
    urdf: str | None = Field(
        default=None,
        description="URDF document of a serial arm (lengths in m, angles in rad). Give model or "
        "urdf; joints that do not move tool_frame are locked.",
    )
    base_frame: str | None = Field(
        default=None,
        validate_default=True,
        description="With urdf only, required: the frame fixed to the root that poses and twists "
        "are expressed in.",
    )
    tool_frame: str | None = Field(
        default=None,
        validate_default=True,
        description="With urdf only, required: the tool flange frame.",
    )
    opw: OpwGeometry | None = Field(
        default=None,
        description="An OPW industrial arm of your own (joint angles in the maker's convention, "
        "{B} the base_link, the tool frame the flange tool0); needs joint_position_limits and "
        "joint_velocity_limits.",
    )
    joint_position_limits: list[list[float]] | None = Field(
        default=None,
        description="With opw only, required: [lower, upper] (rad) for each of the 6 joints, "
        "lower < upper.",
    )
    joint_velocity_limits: list[PositiveFloat] | None = Field(
        default=None,
        min_length=1,
        description="Joint speed limits (rad/s; m/s for prismatic joints), one per joint, "
        "each > 0. Default: the model's.",
    )
    tcp: Pose | None = Field(
        default=None,
        description="Tool point relative to the tool frame (m, unit quaternion). Default: "
        "identity, the tool point is the tool frame.",
    )

    @field_validator("urdf")
    @classmethod
    def _not_both(cls, value: str | None, info: ValidationInfo) -> str | None:
        if value is not None and info.data.get("model") is not None:
            raise PydanticCustomError("robot_source", "give model or urdf, not both")
        return value

    @field_validator("base_frame", "tool_frame")
    @classmethod
    def _frames_go_with_urdf(cls, value: str | None, info: ValidationInfo) -> str | None:
        if value is None and info.data.get("urdf") is not None:
            raise PydanticCustomError("missing", "required with urdf")
        if value is not None and info.data.get("model") is not None:
            raise PydanticCustomError("robot_source", "only with urdf, not with model")
        return value

    @model_validator(mode="after")
    def _model_or_urdf(self) -> Robot:
        given = [name for name in ("model", "urdf", "opw") if getattr(self, name) is not None]
        if len(given) != 1:
            raise PydanticCustomError(
                "robot_source",
                "give exactly one of model (a name from GET /v1/robots), urdf or opw; got {given}",
                {"given": ", ".join(given) or "none"},
            )
        if self.opw is not None and self.joint_position_limits is None:
            raise PydanticCustomError("missing", "opw needs joint_position_limits (rad)")
        if self.opw is not None and self.joint_velocity_limits is None:
            raise PydanticCustomError("missing", "opw needs joint_velocity_limits (rad/s)")
        if self.opw is None and self.joint_position_limits is not None:
            raise PydanticCustomError("robot_source", "joint_position_limits go with opw only")
        return self


class ToolAxisWaypoint(RequestModel):
    """A tool point and the tool axis, as 5-axis CAM writes them (cam.md section 1)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"position": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0]}]}
    )

    position: Vector3 = Field(description="Tool tip [x, y, z] in {O} (m).")
    axis: Vector3 = Field(
        description="Tool axis [i, j, k] from the tip towards the holder (tool z = -axis); unit "
        "to within 1e-3, where it is normalised and the correction reported."
    )


SpinMode = Literal["fixed", "free"]


class Path(RequestModel):
    """The tool path in the workpiece frame {O}, in machining order: poses or tool axes.

    Give exactly one of ``waypoints`` (full poses) or ``tool_axis_waypoints`` (tool point and
    axis; the rotation about the axis is the minimal-rotation frame, cam.md section 1).
    """

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "waypoints": [
                        {"position": [0.0, 0.0, 0.0], "orientation": [1, 0, 0, 0]},
                        {"position": [0.01, 0.0, 0.0], "orientation": [1, 0, 0, 0]},
                    ]
                }
            ]
        }
    )

    waypoints: list[Pose] | None = Field(
        default=None,
        min_length=2,
        description="N >= 2 poses in {O} (m, unit quaternions); consecutive ones distinct.",
    )
    tool_axis_waypoints: list[ToolAxisWaypoint] | None = Field(
        default=None,
        min_length=2,
        description="N >= 2 tool points and axes in {O} (m); consecutive ones distinct. The "
        "default spin_mode of such a path is free.",
    )

    @model_validator(mode="after")
    def _one_form(self) -> Path:
        given = [f for f in ("waypoints", "tool_axis_waypoints") if getattr(self, f) is not None]
        if len(given) != 1:
            raise PydanticCustomError(
                "path_form",
                "give exactly one of waypoints or tool_axis_waypoints; got {given}",
                {"given": ", ".join(given) or "none"},
            )
        return self

    def n_waypoints(self) -> int:
        """The number of waypoints N."""
        return len(self.waypoints or self.tool_axis_waypoints or [])


class Placement(RequestModel):
    """Where the workpiece frame {O} sits in the base frame {B}: Trans(x, y, z) Rot_z(yaw)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}]}
    )

    x: float = Field(description="x of {O} in {B} (m).")
    y: float = Field(description="y of {O} in {B} (m).")
    z: float = Field(description="z of {O} in {B} (m), the table height.")
    yaw: float = Field(description="Rotation of {O} about the z axis of {B} (rad).")
    spin: float = Field(
        default=0.0,
        description="Tool spin (rad): every waypoint turned about its own tool z axis (cam.md "
        "section 3); it changes the IK, never the task requirements. Default 0.",
    )


class Branch(RequestModel):
    """A named inverse-kinematics branch: UR arms shoulder left/right, OPW arms front/back."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"shoulder": "left", "elbow": "up", "wrist": "noflip"}]}
    )

    shoulder: Literal["left", "right", "front", "back"] = Field(
        description="Shoulder choice (joint 1): left or right for UR arms, front or back for "
        "OPW arms (GET /v1/robots lists each robot's branches)."
    )
    elbow: Literal["up", "down"] = Field(description="Elbow choice (joint 3).")
    wrist: Literal["flip", "noflip"] = Field(description="Wrist choice (joint 5).")


def _branch_kind(value: object) -> str:
    """Tag of an ``ik.branch`` value: ``auto`` for a string, ``named`` otherwise."""
    return "auto" if isinstance(value, str) else "named"


BranchChoice = Annotated[
    Annotated[Literal["auto"], Tag("auto")] | Annotated[Branch, Tag("named")],
    Discriminator(_branch_kind),
]


class IkPolicy(RequestModel):
    """How inverse kinematics is followed along the path."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"branch": "auto", "max_joint_step": 0.35},
                {"branch": {"shoulder": "left", "elbow": "up", "wrist": "noflip"}},
            ]
        }
    )

    branch: BranchChoice = Field(
        default="auto",
        description='"auto": the feasible branch, continuous along the path, with the highest '
        "mu_path; or a named branch to follow.",
    )
    max_joint_step: float = Field(
        default=DEFAULT_MAX_JOINT_STEP,
        gt=0.0,
        description="Largest move of any joint between neighbouring waypoints (rad), > 0.",
    )
