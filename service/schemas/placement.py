"""Where the workpiece sits: a request's placement, and an answer's with its controller frames.

A placement is Trans(x, y, z) Rot_z(yaw) of the workpiece frame {O} in the base frame {B}, plus a
tool spin; an answer adds the same transform as robot controllers write it (cam.md section 8).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from pydantic import ConfigDict, Field

from service.schemas.common import Angle, Coordinate, RequestModel, ResponseModel
from solver.cam.frames import frames_of_placement
from solver.core.spatial import Placement as SolverPlacement


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
