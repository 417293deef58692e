"""``POST /v1/dtf``: the DTF index at one configuration (spec section 3)."""

from __future__ import annotations

from typing import Literal

from pydantic import ConfigDict, Field, field_validator
from pydantic_core import PydanticCustomError

from service.schemas.common import RequestModel, ResponseModel, UnitVector
from service.schemas.robot import Robot
from service.schemas.robot_read import ROBOT_READ, RobotRead

MIN_H = 1e-300  # m: below it (subnormal numbers) 1 / h overflows
MAX_H = 1e300


class DtfRequest(RequestModel):
    """A configuration and a task direction: how fast can the tool point go?"""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "robot": {"model": "ur5e"},
                    "q": [0.0, -1.2, 1.5, -1.9, -1.5708, 0.3],
                    "u_T": [1.0, 0.0, 0.0],
                    "u_R": [0.0, 0.0, 1.0],
                    "h": 0.5,
                }
            ]
        }
    )

    robot: Robot = Field(description="The arm, its speed limits and tool point.")
    q: list[float] = Field(
        min_length=1, description="Joint positions (rad; m for prismatic joints), n values."
    )
    u_T: UnitVector | None = Field(
        default=None,
        description="Unit direction of the linear tool velocity in {B} (dimensionless). "
        "Required unless h = 0.",
    )
    u_R: UnitVector | None = Field(
        default=None,
        description="Unit direction of the angular tool velocity in {B} (dimensionless). "
        "Required unless h is null.",
    )
    h: float | None = Field(
        default=None,
        ge=0.0,
        description="V / Omega (m): linear over angular speed, 0 or within [1e-300, 1e300]. "
        "null or left out for pure translation, 0 for pure reorientation.",
        json_schema_extra={
            "anyOf": [
                {
                    "type": "number",
                    "minimum": 0,
                    "maximum": MAX_H,
                    "not": {"exclusiveMinimum": 0, "exclusiveMaximum": MIN_H},
                },
                {"type": "null"},
            ]
        },
    )
    method: Literal["auto", "closed_form", "lp"] = Field(
        default="auto",
        description="closed_form (J^-1, non-singular 6-joint arms), lp (exact for every arm), "
        "or auto: closed_form where it applies, else lp.",
    )

    @field_validator("h")
    @classmethod
    def _dividable(cls, value: float | None) -> float | None:
        if value is not None and value != 0.0 and not MIN_H <= value <= MAX_H:
            raise PydanticCustomError(
                "h_range", "h = {h} m; it is 0 or within [1e-300, 1e300]", {"h": value}
            )
        return value


class DtfResponse(ResponseModel):
    """The largest feasible tool speed along the direction, and the joint speeds there."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "v_max": 0.98679,
                    "omega_max": 1.97358,
                    "qdot": [-0.00913, -2.22647, 3.14159, -0.91513, 0.05789, -1.98187],
                    "limiting_joint": 2,
                    "limiting_joint_name": "elbow_joint",
                    "method": "closed_form",
                    "yoshikawa": 0.10447,
                    "chiu": 0.49846,
                }
            ]
        }
    )

    v_max: float = Field(
        description="Largest linear tool speed (m/s) with every joint within its limit; 0 for "
        "pure reorientation (h = 0)."
    )
    omega_max: float = Field(
        description="Angular tool speed at v_max (rad/s), v_max / h; 0 for pure translation. "
        "For h = 0 the largest angular speed."
    )
    qdot: list[float] = Field(
        description="Joint speeds at that maximum (rad/s), n values; one sits on its limit."
    )
    limiting_joint: int = Field(description="Index (from 0) of the joint on its speed limit.")
    limiting_joint_name: str = Field(description="Name of the joint on its speed limit.")
    method: Literal["closed_form", "lp"] = Field(description="The method that was used.")
    yoshikawa: float = Field(
        description="Yoshikawa manipulability sqrt(det(J J^T)) (mixed units), for comparison."
    )
    correction: float = Field(
        default=0.0,
        description="The largest correction made to u_T's or u_R's length (normalised within "
        "1e-3, cam.md section 6); 0 when they were unit.",
    )
    chiu: float = Field(
        description="Chiu's directional index [t^T (J J^T)^-1 t]^(-1/2), t = [u_T; u_R / h] "
        "normalised (mixed units), for comparison; 0 when t is out of reach."
    )
    robot_read: RobotRead | None = Field(default=None, description=ROBOT_READ)
