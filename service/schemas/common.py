"""What every request and answer stands on: the base models, bounded numbers, poses (api.md).

Every request model is strict (a number is a JSON number, not a string), refuses unknown fields,
and refuses NaN and infinities, so bad input of any kind is a ``422`` that names the field. The
placement is in :mod:`service.schemas.placement`, the IK policy in :mod:`service.schemas.ik`.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator
from pydantic_core import PydanticCustomError
from typing_extensions import TypeAliasType

from solver.core.spatial import MAX_COORDINATE, QUATERNION_NORM_TOLERANCE, pose_matrix

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
            "given; free, chosen per waypoint (a spindle, disc or grinder; cam.md section 2).",
            examples=["fixed"],
        ),
    ],
)
"""One component for every spin_mode field, requests and answers alike."""
