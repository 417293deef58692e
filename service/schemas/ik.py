"""The IK policy of a request: which branch to follow along the path, and how (api.md).

A branch is named for a closed-form arm (UR, OPW), an index among the solutions found for the
numeric family, or ``auto``; the policy adds the continuity bound and the blend length.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, ConfigDict, Discriminator, Field, Tag

from service.schemas.common import RequestModel
from solver.path.problem import BLEND_LENGTHS, DEFAULT_BLEND_LENGTH, DEFAULT_MAX_JOINT_STEP


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
        ge=BLEND_LENGTHS[0],
        le=BLEND_LENGTHS[1],
        description="The length (m) over which the controller rounds a corner of the path (a "
        "zone of radius blend_length / 2: ABB z1, KUKA $APO.CDIS = 1, UR blend radius 1 mm), "
        "1e-6 to 1; the joint accelerations at a constant feed are taken over it (motion.md "
        "section 2). Used only with robot.joint_acceleration_limits.",
    )


class AutoIkPolicy(RequestModel):
    """How inverse kinematics is followed along the path when the route chooses the branch."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"branch": "auto", "max_joint_step": 0.35}]}
    )

    branch: Literal["auto"] = Field(
        default="auto",
        description='"auto": each candidate follows its own feasible branch, continuous along '
        "the path, and the answer uses the best. The optimisers search no fixed branch: a "
        "configuration the cell requires is mapped (/v1/map with that branch) or evaluated.",
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
