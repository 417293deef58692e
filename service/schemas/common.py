"""Objects shared by several routes: Pose, Robot, Path, Placement, IK branch (api.md).

Every request model is strict (a number is a JSON number, not a string), refuses unknown fields,
and refuses NaN and infinities, so bad input of any kind is a ``422`` that names the field.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    field_validator,
)
from pydantic_core import PydanticCustomError
from typing_extensions import TypeAliasType

from solver.cam.frames import frames_of_placement
from solver.core.spatial import MAX_COORDINATE, QUATERNION_NORM_TOLERANCE, pose_matrix
from solver.core.spatial import Placement as SolverPlacement
from solver.path.problem import DEFAULT_BLEND_LENGTH, DEFAULT_MAX_JOINT_STEP

UNIT_BOUND = 1.001  # a direction typed with 4 decimals may be off its unit norm by up to 1e-3

Coordinate = Annotated[float, Field(ge=-MAX_COORDINATE, le=MAX_COORDINATE)]
Position = Annotated[list[Coordinate], Field(min_length=3, max_length=3)]
"""A point (m), each coordinate within 1 km of the origin."""
MAX_ANGLE = 1e3  # rad: about 160 turns, beyond any joint or placement
Angle = Annotated[float, Field(ge=-MAX_ANGLE, le=MAX_ANGLE)]
"""An angle (rad) within 1000 rad of zero."""
UnitComponent = Annotated[float, Field(ge=-UNIT_BOUND, le=UNIT_BOUND)]
NOT_ZERO: dict[str, Any] = {"not": {"items": {"const": 0}}}
"""JSON Schema of a vector with a component other than 0 (a zero vector has no direction)."""
UnitVector = Annotated[
    list[UnitComponent], Field(min_length=3, max_length=3, json_schema_extra=NOT_ZERO)
]
"""A unit direction (dimensionless): a norm of 1, so each component within [-1, 1], not 0."""
Quaternion = Annotated[
    list[UnitComponent], Field(min_length=4, max_length=4, json_schema_extra=NOT_ZERO)
]
SHOWN_CHARACTERS = 100


def shown(value: object) -> str:
    """``value`` as echoed in an error message: at most 100 characters."""
    text = str(value)
    return text if len(text) <= SHOWN_CHARACTERS else text[:SHOWN_CHARACTERS] + "..."


def pose_matrix_of(pose: Pose, *, field: str) -> np.ndarray:
    """T of a pose, shape (4, 4), metres.

    Raises:
        InvalidInputError: on ``field``, a quaternion that is not unit.
    """
    return pose_matrix(pose.position, pose.orientation, field=field)


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

    position: Position = Field(description="Position [x, y, z] (m), each within 1 km.")
    orientation: Quaternion = Field(
        description="Unit quaternion [qx, qy, qz, qw] (dimensionless, ROS order). A norm within "
        "1e-3 of 1 is normalised and the correction reported; beyond, it is refused."
    )

    @field_validator("orientation")
    @classmethod
    def _unit_norm(cls, value: list[float]) -> list[float]:
        norm = math.hypot(*value)
        if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
            raise PydanticCustomError(
                "unit_quaternion",
                "quaternion norm is {norm}; a unit quaternion is needed (within 1e-3, then "
                "normalised)",
                {"norm": norm},
            )
        return value


class ToolAxisWaypoint(RequestModel):
    """A tool point and the tool axis, as 5-axis CAM writes them (cam.md section 1)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"position": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0]}]}
    )

    position: Position = Field(description="Tool tip [x, y, z] in {O} (m), each within 1 km.")
    axis: UnitVector = Field(
        description="Tool axis [i, j, k] from the tip towards the holder (tool z = -axis); unit "
        "to within 1e-3, where it is normalised and the correction reported."
    )


SpinMode = TypeAliasType(
    "SpinMode",
    Annotated[
        Literal["fixed", "free"],
        Field(
            description="How the tool spin about its axis is taken: fixed, the orientations as "
            "given; free, chosen per waypoint (a spindle, disc or grinder; cam.md section 2)."
        ),
    ],
)
"""One component for every spin_mode field, requests and answers alike."""


class ControllerFrames(ResponseModel):
    """A placement as robot controllers write a base, user or work-object frame (cam.md 8)."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "matrix": [[1, 0, 0, 0], [0, 1, 0, 0.45], [0, 0, 1, 0.1], [0, 0, 0, 1]],
                    "ur": [0.0, 0.45, 0.1, 0.0, 0.0, 0.0],
                    "kuka": {"X": 0.0, "Y": 450.0, "Z": 100.0, "A": 0.0, "B": 0.0, "C": 0.0},
                    "abb": [[0.0, 450.0, 100.0], [1.0, 0.0, 0.0, 0.0]],
                    "fanuc": {"X": 0.0, "Y": 450.0, "Z": 100.0, "W": 0.0, "P": 0.0, "R": 0.0},
                }
            ]
        }
    )

    matrix: list[list[float]] = Field(description="T_B_O, 4 rows of 4, row-major (m).")
    ur: list[float] = Field(
        description="Universal Robots pose [x, y, z, rx, ry, rz]: m, and a rotation vector (rad)."
    )
    kuka: dict[str, float] = Field(
        description="KUKA {X, Y, Z, A, B, C}: mm and deg, R = Rz(A) Ry(B) Rx(C)."
    )
    abb: list[list[float]] = Field(
        description="ABB wobj uframe [[x, y, z], [q1, q2, q3, q4]]: mm, q1 the scalar part."
    )
    fanuc: dict[str, float] = Field(
        description="FANUC {X, Y, Z, W, P, R}: mm and deg, R = Rz(R) Ry(P) Rx(W)."
    )


class Placement(RequestModel):
    """Where the workpiece frame {O} sits in the base frame {B}: Trans(x, y, z) Rot_z(yaw)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}]}
    )

    x: Coordinate = Field(description="x of {O} in {B} (m), within 1 km.")
    y: Coordinate = Field(description="y of {O} in {B} (m), within 1 km.")
    z: Coordinate = Field(description="z of {O} in {B} (m), the table height, within 1 km.")
    yaw: Angle = Field(description="Rotation of {O} about the z axis of {B} (rad), within 1000.")
    spin: Angle = Field(
        default=0.0,
        description="Tool spin (rad): every waypoint turned about its own tool z axis (cam.md "
        "section 3); it changes the IK, never the task requirements. Default 0.",
    )
    frames: ControllerFrames | None = Field(
        default=None,
        exclude=True,
        json_schema_extra={"readOnly": True},
        description="Read-only, ignored on input: the controller frames an answer's placement "
        "carries (PlacementResult.frames) are derived from x, y, z and yaw, so a placement taken "
        "from an answer is accepted as it is and evaluated at its x, y, z, yaw and spin; to move "
        "it, change those (editing frames changes nothing).",
    )


class Branch(RequestModel):
    """A named inverse-kinematics branch: UR arms shoulder left/right, OPW arms front/back.

    Arms of the numeric family name their branches by index instead (:class:`NumericBranch`).
    """

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"shoulder": "left", "elbow": "up", "wrist": "noflip"}]}
    )

    shoulder: Literal["left", "right", "front", "back"] = Field(
        description="Shoulder choice (joint 1): left or right for UR arms, front or back for "
        "OPW arms (GET /v1/robots lists each robot's branches)."
    )
    elbow: Literal["up", "down"] = Field(description="Elbow choice (joint 3).")
    wrist: Literal["flip", "noflip"] = Field(description="Wrist choice (joint 5).")


MAX_NUMERIC_BRANCHES = 64  # the seeds of the numeric family for seven joints or more


def _integral(value: object) -> object:
    """A whole number written as a float (``24.0``, an integer in JSON Schema) as an int."""
    if isinstance(value, float) and value.is_integer():
        return int(value)
    return value


class NumericBranch(RequestModel):
    """A branch of the numeric IK family: the k-th distinct solution found from the seeds.

    It names nothing geometric: the solutions are numbered in seed order at the path's first
    waypoint, and another placement may number them differently (robots.md section 4).
    """

    model_config = ConfigDict(json_schema_extra={"examples": [{"solution": 0}]})

    solution: Annotated[int, BeforeValidator(_integral)] = Field(
        ge=0,
        le=MAX_NUMERIC_BRANCHES - 1,
        description="Index of the solution (from 0) among the distinct ones found at the first "
        "waypoint, in seed order; below the seed count (32 for 6 joints, 64 for more).",
    )


def _branch_kind(value: object) -> str:
    """Tag of an ``ik.branch`` value: auto for a string, numeric with ``solution``, else named."""
    if isinstance(value, str):
        return "branch:auto"
    if isinstance(value, NumericBranch) or (isinstance(value, dict) and "solution" in value):
        return "branch:numeric"
    return "branch:named"


BranchChoice = Annotated[
    Annotated[Branch, Tag("branch:named")]
    | Annotated[NumericBranch, Tag("branch:numeric")]
    | Annotated[Literal["auto"], Tag("branch:auto")],
    Discriminator(_branch_kind),
]
"""The objects first: a generated client tries the variants in order, and the last untried."""


def _blend_length() -> Any:
    """The ``ik.blend_length`` field of both IK policies (motion.md section 1)."""
    return Field(
        default=DEFAULT_BLEND_LENGTH,
        gt=0.0,
        le=1000.0,
        description="The length (m) over which the controller rounds a corner of the path (a "
        "zone of radius blend_length / 2: ABB z1, KUKA $APO.CDIS = 1, UR blend radius 1 mm), "
        "> 0; the joint accelerations at a constant feed are taken over it (motion.md section "
        "2). Used only with robot.joint_acceleration_limits.",
    )


class AutoIkPolicy(RequestModel):
    """How inverse kinematics is followed along the path when the route chooses the branch."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"branch": "auto", "max_joint_step": 0.35}]}
    )

    branch: Literal["auto"] = Field(
        default="auto",
        description='"auto": each candidate follows its own feasible branch, continuous along '
        "the path, and the answer uses the best.",
    )
    max_joint_step: float = Field(
        default=DEFAULT_MAX_JOINT_STEP,
        gt=0.0,
        description="Largest move of any joint between neighbouring waypoints (rad), > 0.",
    )
    blend_length: float = _blend_length()


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
        "mu_path; or a branch to follow: named (UR, OPW arms) or by solution index (numeric "
        "family); GET /v1/robots lists each robot's branches.",
    )
    max_joint_step: float = Field(
        default=DEFAULT_MAX_JOINT_STEP,
        gt=0.0,
        description="Largest move of any joint between neighbouring waypoints (rad), > 0.",
    )
    blend_length: float = _blend_length()


class PlacementResult(ResponseModel):
    """A placement in an answer: x, y, z, yaw, spin and the same in controller terms."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "x": 0.0,
                    "y": 0.45,
                    "z": 0.1,
                    "yaw": 0.0,
                    "spin": 0.0,
                    "frames": ControllerFrames.model_config["json_schema_extra"]["examples"][0],  # type: ignore[index]
                }
            ]
        }
    )

    x: float = Field(description="x of {O} in {B} (m).")
    y: float = Field(description="y of {O} in {B} (m).")
    z: float = Field(description="z of {O} in {B} (m), the table height.")
    yaw: float = Field(description="Rotation of {O} about the z axis of {B} (rad).")
    spin: float = Field(description="Tool spin about each waypoint's tool axis (rad).")
    frames: ControllerFrames = Field(
        description="T_B_O (the workpiece frame in the base frame; the spin is the tool's, not "
        "the frame's) as controllers write it."
    )


def placement_example(x: float, y: float, z: float, yaw: float) -> dict[str, Any]:
    """A PlacementResult example (its frames computed, so that they are right)."""
    frames = frames_of_placement(SolverPlacement(x=x, y=y, z=z, yaw=yaw))
    return {"x": x, "y": y, "z": z, "yaw": yaw, "spin": 0.0, "frames": dataclasses.asdict(frames)}
