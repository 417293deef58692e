"""``POST /v1/evaluate``, the request: a path, a placement and an IK policy (spec sections 2-4).

The answer is in :mod:`service.schemas.evaluate_response`.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import ConfigDict, Field, model_validator
from pydantic.config import JsonDict
from pydantic_core import PydanticCustomError
from typing_extensions import TypeAliasType

from service.config import MAX_PATH_WAYPOINTS
from service.schemas.cell import CellSpec
from service.schemas.common import Angle, RequestModel, SpinMode
from service.schemas.ik import IkPolicy
from service.schemas.path import Path
from service.schemas.placement import Placement
from service.schemas.robot import Robot
from service.schemas.robot_options import MAX_JOINTS
from solver.cam.cam_path import FEED_RANGE

DetailLevel = TypeAliasType(
    "DetailLevel",
    Annotated[
        Literal["summary", "waypoints"],
        Field(
            description="summary: mu_path, bottleneck and branch only; waypoints: also every "
            "waypoint's detail.",
            examples=["summary"],
        ),
    ],
)
"""One component for the detail asked and the detail answered."""

JointValues = Annotated[list[Angle], Field(min_length=1, max_length=MAX_JOINTS)]
"""One configuration: a value per joint (rad, m for prismatic joints), each within 1000."""

_REQUEST_EXAMPLE: JsonDict = {
    "robot": {"model": "ur5"},
    "path": {
        "waypoints": [
            {
                "position": [-0.15, 0.06, 0.018197678601],
                "orientation": [0.96832240956, -0.186557136879, 0.165133112436, -0.016709308821],
            },
            {
                "position": [-0.147727272727, 0.059048361684, 0.019009432799],
                "orientation": [0.968479713301, -0.186511311708, 0.164318393215, -0.016125792377],
            },
        ]
    },
    "placement": {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0},
    "ik": {"branch": "auto", "max_joint_step": 0.35},
}


class EvaluateRequest(RequestModel):
    """A path, a workpiece placement and an IK policy."""

    model_config = ConfigDict(json_schema_extra={"examples": [_REQUEST_EXAMPLE]})

    robot: Robot = Field(
        description="The arm: a catalogue model, an opw geometry, or a URDF chain of 6 joints or "
        "more (numeric IK)."
    )
    path: Path = Field(description="The waypoints, in the workpiece frame {O}.")
    placement: Placement = Field(description="Where {O} sits in the base frame {B}.")
    ik: IkPolicy = Field(
        default_factory=IkPolicy, description="IK branch and continuity bound; default auto."
    )
    cell: CellSpec | None = Field(
        default=None,
        description="The robot's surroundings and tool (cell.md): fixed objects in {B}, "
        "workpiece objects in {O}; the path is checked against them and the robot itself at "
        "every waypoint and sub-step. Default: no collision check.",
    )
    spin_mode: SpinMode | None = Field(
        default=None,
        description="fixed: the orientations as given; free: the tool spin rate about the tool "
        "axis is free (a spindle, disc or grinder; cam.md section 2). Default: free for "
        "tool_axis_waypoints, fixed for waypoints.",
    )
    detail: DetailLevel | None = Field(
        default=None,
        description="summary: mu_path, bottleneck and branch only; waypoints: also every "
        "waypoint's q, task direction and speeds. Default: waypoints up to "
        "DTF_MAX_DETAIL_WAYPOINTS waypoints (2,000), summary beyond.",
    )
    feed: float | None = Field(
        default=None,
        ge=FEED_RANGE[0],
        le=FEED_RANGE[1],
        description="A feed to check (m/s, 1e-6 to 100): the answer then says whether the path "
        "runs at it, the margin, and every waypoint's joint speeds and use of their limits at it. "
        "Default: the program's feed (its highest FEDRAT) for CL data, else none.",
    )
    spins: list[Angle] | None = Field(
        default=None,
        min_length=2,
        max_length=MAX_PATH_WAYPOINTS,
        description="A tool spin per waypoint, one per waypoint (rad, within 1000), added to the "
        "placement's: each waypoint "
        "turned about its own tool z axis (as /v1/optimize's spin_path answers). Default none.",
    )
    joint_path: list[JointValues] | None = Field(
        default=None,
        min_length=2,
        max_length=MAX_PATH_WAYPOINTS,
        description="The configuration at every waypoint to evaluate, instead of the tracked IK "
        "branch: N rows of n joint values (rad, m for prismatic joints), e.g. /v1/optimize's "
        "joint_path for a redundant arm. Each row's forward kinematics must reach its waypoint "
        "within 1e-6 m and 1e-6 rad, within the joint limits and max_joint_step; V_max is then the "
        "exact DTF LP at those configurations. Needs ik.branch auto and spin_mode fixed; the "
        "answer's branch is then null. Default none: the IK branches are tracked.",
    )

    @model_validator(mode="after")
    def _joint_path_or_branch(self) -> EvaluateRequest:
        if self.joint_path is not None and self.ik.branch != "auto":
            raise PydanticCustomError(
                "joint_path", "give a joint_path or a named ik.branch, not both"
            )
        return self
