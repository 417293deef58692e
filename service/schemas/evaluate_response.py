"""``POST /v1/evaluate``, the answer: mu_path, its bottleneck and per-waypoint detail (spec 2-4)."""

from __future__ import annotations

from enum import StrEnum
from typing import Literal

from pydantic import ConfigDict, Field, GetJsonSchemaHandler
from pydantic.config import JsonDict
from pydantic.json_schema import JsonSchemaValue
from pydantic_core import CoreSchema

from service.schemas.cell import CELL_APPROXIMATED, CELL_UNCHECKED, Contact, UncheckedPair
from service.schemas.common import ResponseModel, SpinMode
from service.schemas.evaluate_request import DetailLevel
from service.schemas.ik import Branch, NumericBranch
from service.schemas.motion import AccelerationResult, CycleTimeResult
from service.schemas.path_read import (
    FAILED_LINE,
    FAILED_OPERATION,
    FAILED_PASS,
    PATH_READ,
    PathRead,
)
from service.schemas.placement import PlacementResult, placement_example
from service.schemas.robot_read import ROBOT_READ, RobotRead

_RESPONSE_EXAMPLE_WAYPOINT: JsonDict = {
    "index": 0,
    "q": [2.105848, 2.500149, 1.960595, -3.089811, 1.302015, 0.942819],
    "u_T": [0.876082, -0.366834, 0.312912],
    "u_R": [-0.416804, 0.908953, -0.008888],
    "h": 1.277384,
    "v_max": 1.963078,
    "omega_max": 1.536795,
    "qdot": [-2.319085, 0.598154, 3.15, -2.880975, 1.040122, -2.658396],
    "limiting_joint": 2,
    "limiting_joint_name": "elbow_joint",
}
_RESPONSE_EXAMPLE: JsonDict = {
    "feasible": True,
    "mu_path": 1.963078,
    "bottleneck": {"waypoint": 0, "joint": 2, "joint_name": "elbow_joint"},
    "reason": None,
    "failed_waypoint": None,
    "branch": {"shoulder": "right", "elbow": "down", "wrist": "noflip"},
    "ik": {"family": "ur", "seeds": None, "branches_found": None, "recognised": None},
    "spin_mode": "fixed",
    "spins": None,
    "placement": placement_example(0.0, 0.45, 0.1, 0.0),
    "axis_correction": 0.0,
    "waypoints": [
        _RESPONSE_EXAMPLE_WAYPOINT,
        {
            "index": 1,
            "q": [2.102773, 2.500954, 1.964739, -3.093618, 1.30339, 0.939297],
            "u_T": [0.876082, -0.366834, 0.312912],
            "u_R": [-0.416804, 0.908953, -0.008888],
            "h": 1.277384,
            "v_max": 1.980425,
            "omega_max": 1.550375,
            "qdot": [-2.355864, 0.625913, 3.15, -2.905565, 1.049536, -2.696284],
            "limiting_joint": 2,
            "limiting_joint_name": "elbow_joint",
        },
    ],
}


class FailureReason(StrEnum):
    """Why a placement is infeasible (one enum for every answer that says so)."""

    UNREACHABLE = "unreachable"
    JOINT_LIMITS = "joint_limits"
    SINGULAR = "singular"
    DISCONTINUOUS = "discontinuous"
    COLLISION = "collision"

    @classmethod
    def __get_pydantic_json_schema__(
        cls, core_schema: CoreSchema, handler: GetJsonSchemaHandler
    ) -> JsonSchemaValue:
        """The enum's schema with an example, as every component has (api.md)."""
        schema = handler.resolve_ref_schema(handler(core_schema))
        schema["examples"] = ["joint_limits"]
        return schema


class FeedCheckResult(ResponseModel):
    """Whether the path runs at the feed (cam.md section 7)."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"feed": 0.025, "feasible": True, "margin": 11.7}]}
    )

    feed: float = Field(description="The feed F checked (m/s).")
    feasible: bool = Field(
        description="Whether the whole path runs at F with every joint within its speed limit "
        "(mu_path >= F), and within its acceleration limit when the robot has them "
        "(mu_acc >= F)."
    )
    margin: float | None = Field(
        description="mu_path / F, or mu_acc / F with acceleration limits (> 1: room to "
        "spare); null when the path is infeasible."
    )


class WaypointResult(ResponseModel):
    """Task requirements and, when feasible, the DTF at one waypoint (all in {B})."""

    model_config = ConfigDict(json_schema_extra={"examples": [_RESPONSE_EXAMPLE_WAYPOINT]})

    index: int = Field(description="Waypoint index (from 0).")
    q: list[float] | None = Field(
        description="Joint positions (rad), n values; null when infeasible."
    )
    u_T: list[float] = Field(
        description="Unit direction of the linear velocity (dimensionless), [0, 0, 0] for pure "
        "reorientation."
    )
    u_R: list[float] = Field(
        description="Unit direction of the angular velocity (dimensionless), [0, 0, 0] for pure "
        "translation."
    )
    h: float | None = Field(
        description="V / Omega (m); null for pure translation, 0 for pure reorientation."
    )
    v_max: float | None = Field(
        description="DTF: largest linear tool speed (m/s); null when infeasible."
    )
    omega_max: float | None = Field(
        description="Angular tool speed at v_max (rad/s); null when infeasible."
    )
    qdot: list[float] | None = Field(
        description="Joint speeds at v_max (rad/s), n values; null when infeasible."
    )
    limiting_joint: int | None = Field(
        description="Index of the joint on its speed limit; null when infeasible."
    )
    limiting_joint_name: str | None = Field(
        description="Name of the joint on its speed limit; null when infeasible."
    )
    qdot_at_feed: list[float | None] | None = Field(
        default=None,
        description="With a feed: the joint speeds at that feed (rad/s), n values (null values "
        "where the tool only turns); null without a feed or when infeasible.",
    )
    use: list[float | None] | None = Field(
        default=None,
        description="With a feed: each joint's |qdot| / its limit at that feed (1: on the "
        "limit), n values; null without a feed or when infeasible.",
    )
    qdd_at_mu_acc: list[float] | None = Field(
        default=None,
        description="With joint acceleration limits: the joint accelerations at the constant "
        "feed mu_acc, D_i mu_acc^2 (rad/s^2), n values; null without them, when infeasible, or "
        "at a waypoint within the blend length of a pass end (not constrained).",
    )


class Bottleneck(ResponseModel):
    """Where the path is slowest: the waypoint of mu_path and its limiting joint."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"waypoint": 0, "joint": 2, "joint_name": "elbow_joint"}]}
    )

    waypoint: int = Field(
        description="Index of the waypoint with the smallest v_max; of waypoints whose v_max "
        "tie within 1e-12 (relative: the same corner cut on several levels), the first, as a "
        "map cell of the same placement names it."
    )
    joint: int = Field(description="Index of the joint on its speed limit there.")
    line: int | None = Field(
        default=None,
        description="When the path came as CL data or CSV: the line of the program (from 1) "
        "the waypoint was read from; null otherwise.",
    )
    joint_name: str = Field(description="Name of that joint.")


class IkInfo(ResponseModel):
    """Which kinematics family solved the IK and, for numeric IK, what its seeds found."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"family": "ur", "seeds": None, "branches_found": None, "recognised": None},
                {"family": "numeric", "seeds": 64, "branches_found": 9, "recognised": None},
            ]
        }
    )

    family: Literal["ur", "opw", "numeric"] = Field(
        description="The family (GET /v1/robots): ur or opw solve in closed form and find every "
        "branch; numeric solves by damped least squares from fixed seeds (robots.md section 4)."
    )
    seeds: int | None = Field(
        description="Numeric family: how many start configurations (seeds) the IK starts from "
        "at the first waypoint (32 for 6 joints, 64 for more; a six-joint arm whose seeds find "
        "an odd number of solutions, which says one was missed, tries 128 more there); null for "
        "a closed-form family, or when the request gave the joint_path."
    )
    branches_found: int | None = Field(
        description="Numeric family: how many distinct IK solutions within the joint limits the "
        "seeds found at the first waypoint (count, at most seeds), each one branch followed "
        "along the path; a numeric family cannot promise it found every branch. null for a "
        "closed-form family, or when the request gave the joint_path."
    )
    recognised: str | None = Field(
        default=None,
        description="Set when the family was read off a URDF's geometry rather than named: a URDF "
        "whose chain is an OPW arm's (forward kinematics equal at random configurations) is "
        "solved in closed form, every branch found; the sentence gives the fitted parameters. "
        "null for a catalogue or OPW robot, and for numeric IK.",
    )


class EvaluateResponse(ResponseModel):
    """Feasibility, mu_path and per-waypoint detail of the path at the placement."""

    model_config = ConfigDict(json_schema_extra={"examples": [_RESPONSE_EXAMPLE]})

    feasible: bool = Field(
        description="Every waypoint reachable within the joint limits on one branch, "
        "followed continuously."
    )
    mu_path: float | None = Field(
        description="Highest constant feed rate (m/s) with every joint within its speed limit "
        "along the whole path: min over waypoints of v_max. null when infeasible."
    )
    bottleneck: Bottleneck | None = Field(
        description="Where mu_path is attained; null when infeasible."
    )
    reason: FailureReason | None = Field(
        description="Why the placement is infeasible; null when feasible."
    )
    failed_waypoint: int | None = Field(
        description="Index of the first waypoint that fails; null when feasible."
    )
    failed_pass: int | None = Field(default=None, description=FAILED_PASS)
    failed_line: int | None = Field(default=None, description=FAILED_LINE)
    failed_operation: str | None = Field(default=None, description=FAILED_OPERATION)
    branch: Branch | NumericBranch | None = Field(
        description="IK branch used (when infeasible with auto: the one that got furthest): "
        "named for a UR or OPW arm, a solution index for the numeric family; null when no "
        "branch reached the first waypoint, or when the request gave the joint_path."
    )
    ik: IkInfo = Field(description="The IK family that solved the path, and its seeds.")
    spin_mode: SpinMode = Field(description="The spin mode used (fixed or free).")
    placement: PlacementResult | None = Field(
        default=None,
        description="The placement evaluated, with its controller frames (cam.md section 8): "
        "the request's; in /v1/optimize's evaluation, the optimum's.",
    )
    spins: list[float] | None = Field(
        default=None,
        description="In free spin mode, the tool spin (rad) about each waypoint's tool axis that "
        "realises mu_path: the spin rate nearest zero at the feed the LP gives (cam.md "
        "section 2), summed along each pass. The waypoints' q follow these spins exactly, and "
        "mu_path is what that joint path runs: for an angled or offset spindle, or seven "
        "joints, whose spin moves more than the last joint, the path is solved again at the "
        "spun poses and judged as in fixed mode (these spins in fixed mode, on the same "
        "branch, give the same answer), the LP taken again at the spun joints, up to four "
        "rounds, the best kept. Null in fixed mode or when infeasible.",
    )
    axis_correction: float = Field(
        default=0.0,
        description="The largest correction made in normalising the request's unit vectors "
        "and quaternions: the path's tool axes (their length) or pose quaternions (their "
        "norm), the robot's tcp and the cell's object poses (dimensionless; 0 when none was "
        "needed).",
    )
    acceleration: AccelerationResult | None = Field(
        default=None,
        description="With robot.joint_acceleration_limits: mu_acc, the constant feed the joint "
        "speed and acceleration limits allow, and what binds it (motion.md section 2); null "
        "without them or when infeasible. mu_path keeps its meaning (speed limits only).",
    )
    cycle_time: CycleTimeResult | None = Field(
        default=None,
        description="With robot.joint_acceleration_limits: the cycle time at mu_acc, with the "
        "ramps at the pass ends, and the time-optimal one (s, motion.md section 4); null "
        "without them, when infeasible, or when mu_acc is 0.",
    )
    collision: Contact | None = Field(
        default=None,
        description="With a cell, when reason is collision: the first configuration closer than "
        "the clearance, its robot part, obstacle and distance (m); else null.",
    )
    min_clearance: Contact | None = Field(
        default=None,
        description="With a cell, on a feasible path: the closest pair over every checked "
        "configuration and its distance (m); else null.",
    )
    cell_approximated: list[str] | None = Field(
        default=None,
        description=f"{CELL_APPROXIMATED} Null without a cell or when the path was not checked.",
    )
    cell_unchecked: list[UncheckedPair] | None = Field(
        default=None,
        description=f"{CELL_UNCHECKED} Null without a cell or when the path was not checked.",
    )
    feed_check: FeedCheckResult | None = Field(
        default=None,
        description="With a feed (the request's, or the CL program's FEDRAT): whether the path "
        "runs at it; null without one.",
    )
    path_read: PathRead | None = Field(
        default=None,
        description=f"{PATH_READ} In /v1/optimize's evaluation, null: that answer has it.",
    )
    robot_read: RobotRead | None = Field(
        default=None,
        description=f"{ROBOT_READ} In /v1/optimize's evaluation, null: that answer has it.",
    )
    detail: DetailLevel = Field(
        default="waypoints", description="Whether waypoints holds the per-waypoint detail."
    )
    waypoints: list[WaypointResult] = Field(
        description="One entry per waypoint, in path order; empty when detail is summary."
    )
