"""Responses of ``GET /healthz`` and ``GET /v1/robots``."""

from __future__ import annotations

from typing import Literal

from pydantic import ConfigDict, Field
from pydantic.config import JsonDict

from service.schemas.common import ResponseModel
from solver.families.ur.dh import UR_JOINT_NAMES

_UR5E_EXAMPLE: JsonDict = {
    "name": "ur5e",
    "dof": 6,
    "joint_names": [*UR_JOINT_NAMES],
    "q_lower": [-6.283185307179586] * 6,
    "q_upper": [6.283185307179586] * 6,
    "qdot_max": [3.141592653589793] * 6,
    "base_frame": "base",
    "tool_frame": "tool0",
    "family": "ur",
    "branches": [
        {"level": "shoulder", "choices": ["left", "right"]},
        {"level": "elbow", "choices": ["up", "down"]},
        {"level": "wrist", "choices": ["noflip", "flip"]},
    ],
}


class BranchLevel(ResponseModel):
    """One level of a robot's IK branches and its choices (ik.branch names one per level)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"level": "shoulder", "choices": ["left", "right"]}]}
    )

    level: str = Field(description='The level, e.g. "shoulder".')
    choices: list[str] = Field(description='Its choices, e.g. ["left", "right"].')


class HealthResponse(ResponseModel):
    """The service is up; and whether its jobs can run."""

    model_config = ConfigDict(json_schema_extra={"examples": [{"status": "ok", "jobs": "ok"}]})

    status: Literal["ok"] = Field(description='Always "ok" when the service answers.')
    jobs: str = Field(
        default="ok",
        description='"ok", or "unavailable: <why>" while the job supervisor\'s last look at '
        "the job store failed (a corrupt, deleted or unwritable file: the job routes answer "
        "503 then); the synchronous routes serve either way. It says the last look, at most a "
        "few seconds old: no store is read for it.",
        examples=["ok"],
    )


class RobotInfo(ResponseModel):
    """One robot of the catalogue."""

    model_config = ConfigDict(json_schema_extra={"examples": [_UR5E_EXAMPLE]})

    name: str = Field(description='Name to use as robot.model, e.g. "ur5e".')
    dof: int = Field(description="Number of joints n.")
    joint_names: list[str] = Field(description="The n joint names, in configuration order.")
    q_lower: list[float] = Field(description="Lower joint position limits (rad), n values.")
    q_upper: list[float] = Field(description="Upper joint position limits (rad), n values.")
    qdot_max: list[float] = Field(
        description="Joint speed limits (rad/s), n values: the default joint_velocity_limits."
    )
    base_frame: str = Field(description="Frame {B} that poses and twists are expressed in.")
    tool_frame: str = Field(description="Tool flange frame {F}; a tcp is relative to it.")
    family: str | None = Field(
        description="The kinematics family that solves its IK (ur: UR arms; opw: industrial "
        "arms with a spherical wrist; numeric: any serial chain of 6 joints or more, solved "
        "numerically from fixed seeds); null for an arm that only has /v1/dtf."
    )
    branches: list[BranchLevel] = Field(
        description="The IK branch levels and their choices, as ik.branch names them."
    )


class RobotsResponse(ResponseModel):
    """The robot catalogue."""

    model_config = ConfigDict(json_schema_extra={"examples": [{"robots": [_UR5E_EXAMPLE]}]})

    robots: list[RobotInfo] = Field(description="Every robot that robot.model can name.")
