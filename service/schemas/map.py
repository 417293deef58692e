"""``POST /v1/map``: mu_path over a grid of placements (spec section 6)."""

from __future__ import annotations

from typing import Annotated

from pydantic import ConfigDict, Field
from pydantic.config import JsonDict

from service.schemas.cell import CELL_APPROXIMATED, CELL_UNCHECKED, CellSpec, UncheckedPair
from service.schemas.common import Angle, Coordinate, RequestModel, ResponseModel, SpinMode
from service.schemas.evaluate_request import _REQUEST_EXAMPLE
from service.schemas.evaluate_response import FailureReason
from service.schemas.ik import Branch, IkPolicy, NumericBranch
from service.schemas.motion import LimitedBy
from service.schemas.path import Path
from service.schemas.path_read import PATH_READ, PathRead
from service.schemas.placement import PlacementResult, placement_example
from service.schemas.robot import Robot
from service.schemas.robot_read import ROBOT_READ, RobotRead
from solver.core.spatial import MAX_COORDINATE
from solver.path.capability_map import axis_length

MAX_GRID_VALUES = 360
MIN_GRID_STEP = 1e-6  # m: a finer grid than a micrometre is no placement a cell can hold
ValueList = Annotated[list[Angle], Field(min_length=1, max_length=MAX_GRID_VALUES)]


class GridAxis(RequestModel):
    """Values min, min + step, ... up to max (included when it falls on the grid), metres."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"min": -0.25, "max": 0.25, "step": 0.02}]}
    )

    min: Coordinate = Field(description="First value (m), within 1 km.")
    max: Coordinate = Field(description="Last value at most (m), >= min, within 1 km.")
    step: float = Field(
        ge=MIN_GRID_STEP, le=2 * MAX_COORDINATE, description="Spacing (m), at least 1 micrometre."
    )


class Grid(RequestModel):
    """Placements to map: x and y on a grid at height z, for one yaw or a list of yaws."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "x": {"min": -0.25, "max": 0.25, "step": 0.02},
                    "y": {"min": 0.25, "max": 0.65, "step": 0.02},
                    "z": 0.1,
                    "yaw": 0.0,
                }
            ]
        }
    )

    x: GridAxis = Field(description="Placement x values (m).")
    y: GridAxis = Field(description="Placement y values (m).")
    z: Coordinate = Field(description="Height of every placement (m), within 1 km.")
    yaw: Angle | ValueList = Field(
        description="Yaw of the workpiece about the base z axis (rad): one value or a list of 1 "
        "to 360 values, each mapped."
    )

    spin: Angle | ValueList = Field(
        default=0.0,
        description="Constant tool spin about each waypoint's tool axis (rad, cam.md section 3): "
        "one value or a list of 1 to 360 values, each mapped. Default 0.",
    )

    def n_placements(self) -> int:
        """How many placements the grid holds (x values x y values x yaws x spins)."""
        nx = axis_length(self.x.min, self.x.max, self.x.step, field="grid.x")
        ny = axis_length(self.y.min, self.y.max, self.y.step, field="grid.y")
        return nx * ny * len(self.yaws()) * len(self.spins())

    def yaws(self) -> list[float]:
        """The yaw values as a list (rad)."""
        return self.yaw if isinstance(self.yaw, list) else [self.yaw]

    def spins(self) -> list[float]:
        """The spin values as a list (rad)."""
        return self.spin if isinstance(self.spin, list) else [self.spin]


_MAP_REQUEST_EXAMPLE: JsonDict = {
    "robot": _REQUEST_EXAMPLE["robot"],
    "path": _REQUEST_EXAMPLE["path"],
    "grid": {
        "x": {"min": -0.1, "max": 0.1, "step": 0.1},
        "y": {"min": 0.35, "max": 0.45, "step": 0.1},
        "z": 0.1,
        "yaw": [0.0, 1.5708],
    },
    "ik": {"branch": "auto", "max_joint_step": 0.35},
}


class MapRequest(RequestModel):
    """A robot, a path in the workpiece frame and a grid of workpiece placements."""

    model_config = ConfigDict(json_schema_extra={"examples": [_MAP_REQUEST_EXAMPLE]})

    robot: Robot = Field(
        description="The arm: a catalogue model, an opw geometry, or a URDF chain of 6 joints or "
        "more (numeric IK, which costs more per placement: smaller grids are allowed)."
    )
    path: Path = Field(description="The tool path in the workpiece frame {O}.")
    grid: Grid = Field(description="The placements to evaluate.")
    ik: IkPolicy = Field(default_factory=IkPolicy, description="IK branch policy.")
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


_CELL: JsonDict = {
    "x": 0.0,
    "y": 0.35,
    "yaw": 0.0,
    "mu_path": 0.2913,
    "reason": None,
    "failed_waypoint": None,
    "bottleneck_waypoint": 0,
    "bottleneck_joint": 5,
    "branch": {"shoulder": "left", "elbow": "up", "wrist": "noflip"},
}


class MapCell(ResponseModel):
    """One placement of the grid and how fast the path runs there."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                _CELL,
                {
                    "x": 0.9,
                    "y": 0.9,
                    "yaw": 0.0,
                    "mu_path": None,
                    "reason": "unreachable",
                    "failed_waypoint": 0,
                },
            ]
        }
    )

    x: float = Field(description="Placement x (m).")
    y: float = Field(description="Placement y (m).")
    yaw: float = Field(description="Placement yaw (rad).")
    spin: float = Field(default=0.0, description="Tool spin (rad).")
    mu_path: float | None = Field(
        description="Highest constant feed rate (m/s); null when infeasible."
    )
    reason: FailureReason | None = Field(
        description="Why the placement is infeasible; null when feasible."
    )
    failed_waypoint: int | None = Field(
        description="First waypoint that fails; null when feasible."
    )
    bottleneck_waypoint: int | None = Field(
        default=None,
        description="Where V_max is smallest along the path (of waypoints that tie within "
        "1e-12, the first, as /v1/evaluate names it); null when infeasible.",
    )
    bottleneck_joint: int | None = Field(
        default=None, description="The joint on its speed limit there; null when infeasible."
    )
    branch: Branch | NumericBranch | None = Field(
        default=None, description="The IK branch the path runs on; null when infeasible."
    )
    mu_acc: float | None = Field(
        default=None,
        description="With robot.joint_acceleration_limits: the constant feed the joint speed "
        "and acceleration limits allow (m/s, as /v1/evaluate's acceleration.mu_acc); the "
        "map's colour and what best and worst rank. null without them or when infeasible.",
    )
    limited_by: LimitedBy | None = Field(
        default=None,
        description="With joint acceleration limits: what binds mu_acc there; null without them "
        "or when infeasible.",
    )


class MapExtreme(ResponseModel):
    """The best or worst feasible placement of the grid."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"placement": placement_example(0.0, 0.35, 0.1, 0.0), "mu_path": 0.29}]
        }
    )

    placement: PlacementResult = Field(description="Where the workpiece sits (m, rad).")
    mu_path: float = Field(description="Its mu_path (m/s).")
    mu_acc: float | None = Field(
        default=None,
        description="With joint acceleration limits its mu_acc (m/s), which ranks the cells; "
        "null without them.",
    )


class MapResponse(ResponseModel):
    """mu_path at every placement of the grid, in the order yaw, y, x; the best and the worst."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "cells": [_CELL],
                    "best": {
                        "placement": placement_example(0.0, 0.35, 0.1, 0.0),
                        "mu_path": 0.2913,
                    },
                    "worst": {
                        "placement": placement_example(0.0, 0.35, 0.1, 0.0),
                        "mu_path": 0.2913,
                    },
                    "feasible_cells": 1,
                }
            ]
        }
    )

    cells: list[MapCell] = Field(description="Every placement, yaw-major, then y, then x.")
    best: MapExtreme | None = Field(
        description="The feasible cell with the highest mu_path; null if none."
    )
    worst: MapExtreme | None = Field(
        description="The feasible cell with the lowest mu_path; null if none."
    )
    feasible_cells: int = Field(description="How many cells are feasible.")
    spin_mode: SpinMode = Field(default="fixed", description="The spin mode used (fixed or free).")
    recognised: str | None = Field(
        default=None,
        description="Set when the robot is a URDF whose chain was recognised as an OPW or UR arm "
        "and solved in closed form (as /v1/evaluate's ik.recognised); null otherwise.",
    )
    path_read: PathRead | None = Field(default=None, description=PATH_READ)
    robot_read: RobotRead | None = Field(default=None, description=ROBOT_READ)
    axis_correction: float = Field(
        default=0.0,
        description="The largest correction made in normalising the request's unit vectors and "
        "quaternions, as /v1/evaluate's axis_correction: the path's tool axes (their length) or "
        "pose quaternions (their norm), the robot's tcp and the cell's object poses "
        "(dimensionless; 0 when none was needed).",
    )
    cell_approximated: list[str] | None = Field(
        default=None, description=f"{CELL_APPROXIMATED} Null without a cell."
    )
    cell_unchecked: list[UncheckedPair] | None = Field(
        default=None, description=f"{CELL_UNCHECKED} Null without a cell."
    )
