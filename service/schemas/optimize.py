"""``POST /v1/optimize``: the placement where the path runs fastest (spec section 6)."""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import ConfigDict, Field, field_validator, model_validator
from pydantic.config import JsonDict
from pydantic_core import PydanticCustomError

from service.schemas.cell import CellSpec
from service.schemas.common import Angle, Coordinate, RequestModel, ResponseModel, SpinMode
from service.schemas.evaluate_request import _REQUEST_EXAMPLE
from service.schemas.evaluate_response import EvaluateResponse, FailureReason
from service.schemas.ik import AutoIkPolicy
from service.schemas.path import Path
from service.schemas.path_read import FAILED_OPERATION, FAILED_PASS, PATH_READ, PathRead
from service.schemas.placement import Placement, PlacementResult, placement_example
from service.schemas.robot import Robot
from service.schemas.robot_read import ROBOT_READ, RobotRead

Range = Annotated[list[Coordinate], Field(min_length=2, max_length=2)]
AngleRange = Annotated[list[Angle], Field(min_length=2, max_length=2)]


class Bounds(RequestModel):
    """The box the optimum must lie in: x and y (m), yaw and tool spin (rad), as [min, max]."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-math.pi, math.pi]}]
        }
    )

    x: Range = Field(description="[min, max] of x (m), within 1 km.")
    y: Range = Field(description="[min, max] of y (m), within 1 km.")
    yaw: AngleRange = Field(description="[min, max] of the yaw (rad), within 1000.")
    spin: AngleRange = Field(
        default=[0.0, 0.0],
        description="[min, max] of the constant tool spin about each waypoint's tool axis (rad, "
        "cam.md section 3), at most a turn wide; default [0, 0] (no spin). It matters for an "
        "angled or offset spindle. A range containing 0 also runs the search without spin "
        "(its work counted with the rest), so the answer is never below that search's.",
    )

    z: Range | None = Field(
        default=None,
        description="[min, max] of the height (m) to search it too; then the request's z is left "
        "out. Default: the height is the request's z.",
    )

    @field_validator("x", "y", "yaw", "spin", "z")
    @classmethod
    def _ordered(cls, value: Range | None) -> Range | None:
        if value is not None and value[0] > value[1]:
            raise ValueError(f"min {value[0]} is above max {value[1]}")
        return value


_REQUEST: JsonDict = {
    "robot": _REQUEST_EXAMPLE["robot"],
    "path": _REQUEST_EXAMPLE["path"],
    "bounds": {"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-3.14159, 3.14159]},
    "z": 0.1,
    "method": "casadi",
    "ik": {"branch": "auto", "max_joint_step": 0.35},
}


class SpinPath(RequestModel):
    """A tool spin per waypoint for the casadi method (cam.md section 4)."""

    model_config = ConfigDict(json_schema_extra={"examples": [{"max_spin_step": 0.05}]})

    max_spin_step: float = Field(
        gt=0.0, description="Largest change of the spin between neighbouring waypoints (rad)."
    )


class OptimizeRequest(RequestModel):
    """A robot, a path in the workpiece frame, and the box of placements to search."""

    model_config = ConfigDict(json_schema_extra={"examples": [_REQUEST]})

    robot: Robot = Field(
        description="The arm: a catalogue model, an opw geometry, or a URDF chain of 6 joints or "
        "more (numeric IK, which costs more per placement: smaller bounds are allowed)."
    )
    path: Path = Field(description="The tool path in the workpiece frame {O}.")
    bounds: Bounds = Field(description="Where the workpiece may go.")
    z: Coordinate | None = Field(
        default=None,
        description="Height of the workpiece frame (m), the table height, within 1 km. Give "
        "z or bounds.z (a range to search), exactly one: both or neither is a 422 on the "
        "body (a rule between two fields, which JSON Schema here does not state).",
    )
    start: Placement | None = Field(
        default=None,
        description="Start placement, inside the bounds (default: their centre); reported with "
        "its mu_path, and the optimum reported is the point of the optimal arc nearest it.",
    )
    method: Literal["casadi", "scipy"] = Field(
        default="casadi",
        description="casadi: IPOPT from the best cells of a coarse map; scipy: differential "
        "evolution, then SLSQP (from the coarse map's best cells too, where that map and the "
        "search fit their limits).",
    )
    ik: AutoIkPolicy = Field(
        default_factory=AutoIkPolicy,
        description="IK policy: max_joint_step as for /v1/evaluate; the branch is auto (each "
        "start of the search follows its own branch, the answer uses the best).",
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
        "axis is free (cam.md section 2). Default: free for tool_axis_waypoints, fixed for "
        "waypoints.",
    )
    spin_path: SpinPath | None = Field(
        default=None,
        description="With the casadi method and spin_mode fixed: give each waypoint its own "
        "tool spin, its steps bounded (cam.md section 4); the answer's spins then hold them. "
        "The constant-spin search runs too (its work counted): the answer is never below "
        "that search's.",
    )

    @model_validator(mode="after")
    def _one_height(self) -> OptimizeRequest:
        if self.z is None and self.bounds.z is None:
            raise PydanticCustomError(
                "height", "no height: give z (a fixed height) or bounds.z (a range to search)"
            )
        if self.z is not None and self.bounds.z is not None:
            raise PydanticCustomError(
                "height",
                "z (a fixed height) and bounds.z (a range to search) are both given: give one",
            )
        return self


class StartInfo(ResponseModel):
    """The start placement and how fast the path runs there."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"placement": placement_example(0.0, 0.45, 0.1, 0.0), "mu_path": 0.2937}]
        }
    )

    placement: PlacementResult = Field(description="The start (m, rad).")
    mu_path: float | None = Field(description="Its mu_path (m/s); null when infeasible.")
    reason: FailureReason | None = Field(
        default=None, description="Why the path does not run there; null when it does."
    )
    failed_waypoint: int | None = Field(
        default=None, description="The first waypoint that fails there; null when it runs."
    )
    mu_acc: float | None = Field(
        default=None,
        description="With robot.joint_acceleration_limits: its mu_acc (m/s), what "
        "improvement_percent compares with; null without them or when infeasible.",
    )


_REASON_COUNTS: list[JsonDict] = [
    {
        "reason": "joint_limits",
        "count": 412,
        "failed_waypoint": 39,
        "failed_pass": 1,
        "failed_operation": "ROTARY_SPIN",
    },
    {
        "reason": "unreachable",
        "count": 188,
        "failed_waypoint": 0,
        "failed_pass": 0,
        "failed_operation": "FLAT_PASS",
    },
]
_TRIED: JsonDict = {"placements": 600, "feasible": 0, "reasons": list(_REASON_COUNTS)}


class ReasonCount(ResponseModel):
    """The placements a search tried that failed for one reason."""

    model_config = ConfigDict(json_schema_extra={"examples": [_REASON_COUNTS[0]]})

    reason: FailureReason = Field(description="The reason.")
    count: int = Field(description="How many placements tried failed for it.")
    failed_waypoint: int | None = Field(
        description="The most common first failing waypoint among them (the lowest of equals)."
    )
    failed_pass: int | None = Field(description=FAILED_PASS)
    failed_operation: str | None = Field(description=FAILED_OPERATION)


class TriedPlacements(ResponseModel):
    """What the search tried on the whole path on its way, by outcome."""

    model_config = ConfigDict(json_schema_extra={"examples": [_TRIED]})

    placements: int = Field(
        description="How many distinct placements the search evaluated on the whole path on "
        "its way: the casadi method's coarse map cells, the scipy method's differential "
        "evolution members (a long program, mapped or evolved on a set of its waypoints: only "
        "its placements evaluated on the whole path, the samples and best ones checked)."
    )
    feasible: int = Field(
        description="How many of them run the path (its optimiser's candidates from them did not)."
    )
    reasons: list[ReasonCount] = Field(
        description="The others by reason, most common first: which limit closes the bounds "
        "and where along the path."
    )


class SearchFailure(ResponseModel):
    """Why no placement was found: the most common failure of the placements judged."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "reason": "joint_limits",
                    "failed_waypoint": 39,
                    "failed_pass": 1,
                    "failed_operation": "ROTARY_SPIN",
                    "count": 1,
                    "judged": 1,
                    "tried": _TRIED,
                    "message": "the search proposed no placement but the start, and the start "
                    "does not run it: joint_limits, first at waypoint 39 (pass 1, ROTARY_SPIN); "
                    "none of the 600 placements it tried on the whole path runs it: 412 "
                    "joint_limits, most often first at waypoint 39 (pass 1, ROTARY_SPIN), 188 "
                    "unreachable, most often first at waypoint 0 (pass 0, FLAT_PASS)",
                }
            ]
        }
    )

    reason: FailureReason = Field(
        description="The most common reason among the placements judged on the whole path."
    )
    failed_waypoint: int | None = Field(
        description="The most common first failing waypoint of those (the lowest of equals)."
    )
    failed_pass: int | None = Field(description=FAILED_PASS)
    failed_operation: str | None = Field(description=FAILED_OPERATION)
    count: int = Field(description="How many of the placements judged failed for reason.")
    judged: int = Field(
        description="How many placements the search judged on the whole path (its candidates "
        "and the start), none feasible; 1: the search proposed none of its own (no placement "
        "of its coarse map or evolution was worth judging), the start alone was."
    )
    tried: TriedPlacements | None = Field(
        default=None,
        description="What the search tried on the whole path on its way (its coarse map's "
        "cells or its evolution's members), by reason; null where it kept none.",
    )
    message: str = Field(description="The same in a sentence.")


class SolverInfo(ResponseModel):
    """What the optimiser did."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "name": "ipopt (casadi)",
                    "status": "Solve_Succeeded",
                    "iterations": 55,
                    "seconds": 0.97,
                }
            ]
        }
    )

    name: str = Field(description="The method and its solvers.")
    status: str = Field(description="Status of the solve that gave the answer.")
    iterations: int = Field(description="Iterations (or generations) of all solves together.")
    seconds: float = Field(description="Wall time of the whole search (s).")


class OptimizeResponse(ResponseModel):
    """The best placement found, as /v1/evaluate sees it."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "found": True,
                    "placement": placement_example(0.0, 0.2994, 0.1, 2.1407),
                    "mu_path": 0.3971,
                    "evaluation": None,
                    "start": {
                        "placement": placement_example(0.0, 0.45, 0.1, 0.0),
                        "mu_path": 0.2937,
                    },
                    "improvement_percent": 35.19,
                    "solver": {
                        "name": "ipopt (casadi)",
                        "status": "Solve_Succeeded",
                        "iterations": 55,
                        "seconds": 0.97,
                    },
                }
            ]
        }
    )

    found: bool = Field(description="Whether any placement inside the bounds is feasible.")
    placement: PlacementResult | None = Field(
        description="The optimum, inside the bounds (m, rad)."
    )
    mu_path: float | None = Field(
        description="mu_path there (m/s), as /v1/evaluate gives it (given the answer's spins or "
        "joint_path where it has them: a redundant arm's casadi optimum is its NLP's joint path, "
        "which the tracked IK of /v1/evaluate without it may run slower)."
    )
    mu_acc: float | None = Field(
        default=None,
        description="With robot.joint_acceleration_limits: mu_acc there (m/s), as /v1/evaluate "
        "gives it: what the search maximised (motion.md section 3). null without them.",
    )
    evaluation: EvaluateResponse | None = Field(description="/v1/evaluate's answer there.")
    start: StartInfo = Field(description="The start placement, its mu_path and mu_acc.")
    improvement_percent: float | None = Field(
        description="100 (mu_path / start mu_path - 1), with joint acceleration limits of "
        "mu_acc; null when the start is infeasible."
    )
    solver: SolverInfo = Field(description="The method, its status, iterations and time.")
    spins: list[float] | None = Field(
        default=None,
        description="With spin_path: each waypoint's tool spin (rad) on top of the placement's; "
        "/v1/evaluate with these spins gives this mu_path. null otherwise.",
    )
    joint_path: list[list[float]] | None = Field(
        default=None,
        description="For a redundant arm (more than 6 joints): the configuration at every "
        "waypoint (N rows of n values, rad) that mu_path is at; the casadi method chooses the "
        "redundancy too, so it may differ from the tracked IK branch. /v1/evaluate with this "
        "joint_path gives this mu_path. null for six joints.",
    )
    path_read: PathRead | None = Field(default=None, description=PATH_READ)
    robot_read: RobotRead | None = Field(default=None, description=ROBOT_READ)
    failure: SearchFailure | None = Field(
        default=None,
        description="When found is false: why, the most common failure of the placements the "
        "search judged on the whole path (the start included), with its waypoint and, for CL "
        "or CSV input, its pass and operation; null when found.",
    )
