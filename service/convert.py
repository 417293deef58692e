"""Conversions between request/response schemas and solver objects (numpy, dataclasses)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from service import schemas
from service.config import Settings
from solver.capability_map import CapabilityMap, axis_length, grid_axis
from solver.dtf import DtfResult
from solver.evaluate import Branch, PathEvaluation
from solver.exceptions import InvalidInputError
from solver.optimize import PlacementOptimum
from solver.robots import Robot, get_robot, robot_from_urdf
from solver.spatial import Placement, pose_matrix
from solver.symmetry import PlacementBounds
from solver.tracking import FEASIBLE, REASONS


def robot_from_schema(spec: schemas.Robot) -> Robot:
    """The solver robot a request names, with its speed limits and tool point.

    Raises:
        UnknownRobotError: ``model`` is not in the catalogue.
        RobotModelError: the URDF or its frames do not fit.
        InvalidInputError: ``joint_velocity_limits`` has the wrong length.
    """
    tcp = None if spec.tcp is None else pose_matrix_of(spec.tcp, field="robot.tcp")
    if spec.model is not None:
        robot = get_robot(spec.model).with_options(qdot_max=spec.joint_velocity_limits)
    else:  # schemas.Robot makes sure urdf and both frames are given
        robot = robot_from_urdf(
            spec.urdf or "",
            base_frame=spec.base_frame or "",
            tool_frame=spec.tool_frame or "",
            qdot_max=spec.joint_velocity_limits,
        )
    return robot.with_options(transform_tool_to_tcp=tcp)


def pose_matrix_of(pose: schemas.Pose, *, field: str) -> np.ndarray:
    """T of a pose, shape (4, 4), metres."""
    return pose_matrix(pose.position, pose.orientation, field=field)


def waypoints_of(path: schemas.Path) -> np.ndarray:
    """T_O_i of every waypoint, shape (N, 4, 4), metres, in the workpiece frame {O}."""
    return np.array(
        [pose_matrix_of(pose, field=f"path.waypoints.{i}") for i, pose in enumerate(path.waypoints)]
    )


def placement_of(placement: schemas.Placement) -> Placement:
    """The solver's placement (m, rad)."""
    return Placement(x=placement.x, y=placement.y, z=placement.z, yaw=placement.yaw)


def branch_of(choice: schemas.Branch | str) -> Branch | None:
    """The solver's branch label; ``None`` for ``"auto"``."""
    if isinstance(choice, str):
        return None
    return Branch.named(shoulder=choice.shoulder, elbow=choice.elbow, wrist=choice.wrist)


def h_of(h: float | None) -> float:
    """The solver's h (m): ``math.inf`` for the API's ``null`` (pure translation)."""
    return math.inf if h is None else h


def h_to_api(h: float) -> float | None:
    """The API's h (m): ``None`` for ``math.inf`` (pure translation)."""
    return None if math.isinf(h) else float(h)


def dtf_response(
    result: DtfResult, robot: Robot, *, yoshikawa: float, chiu: float
) -> schemas.DtfResponse:
    """The response of ``POST /v1/dtf``."""
    return schemas.DtfResponse(
        v_max=result.v_max,
        omega_max=result.omega_max,
        qdot=result.qdot.tolist(),
        limiting_joint=result.limiting_joint,
        limiting_joint_name=robot.joint_names[result.limiting_joint],
        method=result.method,
        yoshikawa=yoshikawa,
        chiu=chiu,
    )


def robot_info(robot: Robot) -> schemas.RobotInfo:
    """One catalogue entry of ``GET /v1/robots``."""
    return schemas.RobotInfo(
        name=robot.name,
        dof=robot.dof,
        joint_names=list(robot.joint_names),
        q_lower=robot.q_lower.tolist(),
        q_upper=robot.q_upper.tolist(),
        qdot_max=robot.qdot_max.tolist(),
        base_frame=robot.base_frame,
        tool_frame=robot.tool_frame,
    )


def _optional_list(values: np.ndarray | None, i: int) -> list[float] | None:
    return None if values is None else values[i].tolist()


def _optional_float(values: np.ndarray | None, i: int) -> float | None:
    return None if values is None else float(values[i])


def evaluate_response(evaluation: PathEvaluation, robot: Robot) -> schemas.EvaluateResponse:
    """The response of ``POST /v1/evaluate``."""
    ev = evaluation
    waypoints = []
    for i in range(ev.h.shape[0]):
        limiting = None if ev.limiting_joint is None else int(ev.limiting_joint[i])
        waypoints.append(
            schemas.WaypointResult(
                index=i,
                q=_optional_list(ev.q, i),
                u_T=ev.u_T[i].tolist(),
                u_R=ev.u_R[i].tolist(),
                h=h_to_api(float(ev.h[i])),
                v_max=_optional_float(ev.v_max, i),
                omega_max=_optional_float(ev.omega_max, i),
                qdot=_optional_list(ev.qdot, i),
                limiting_joint=limiting,
                limiting_joint_name=None if limiting is None else robot.joint_names[limiting],
            )
        )
    bottleneck = None
    if ev.bottleneck_waypoint is not None and ev.bottleneck_joint is not None:
        bottleneck = schemas.Bottleneck(
            waypoint=ev.bottleneck_waypoint,
            joint=ev.bottleneck_joint,
            joint_name=robot.joint_names[ev.bottleneck_joint],
        )
    branch = None if ev.branch is None else schemas.Branch.model_validate(ev.branch.as_dict())
    return schemas.EvaluateResponse(
        feasible=ev.feasible,
        mu_path=ev.mu_path,
        bottleneck=bottleneck,
        reason=ev.reason,
        failed_waypoint=ev.failed_waypoint,
        branch=branch,
        waypoints=waypoints,
    )


@dataclass(frozen=True)
class MapGrid:
    """The grid values of a map request (m, m, rad)."""

    xs: np.ndarray
    ys: np.ndarray
    yaws: np.ndarray


def map_grid(grid: schemas.Grid, *, settings: Settings, n_waypoints: int) -> MapGrid:
    """The grid's values, after checking its size against the settings.

    Raises:
        InvalidInputError: an axis is malformed, or the grid is over a size limit; the message
            says the size asked for and the limit.
    """
    nx = axis_length(grid.x.min, grid.x.max, grid.x.step, field="grid.x")
    ny = axis_length(grid.y.min, grid.y.max, grid.y.step, field="grid.y")
    yaws = grid.yaws()
    cells = nx * ny * len(yaws)
    size = f"{nx} x * {ny} y * {len(yaws)} yaw = {cells} placements"
    if cells > settings.max_map_cells:
        raise InvalidInputError(
            "grid", f"{size}; the limit is {settings.max_map_cells} (DTF_MAX_MAP_CELLS)"
        )
    if cells * n_waypoints > settings.max_map_poses:
        raise InvalidInputError(
            "grid",
            f"{size} * {n_waypoints} waypoints = {cells * n_waypoints} poses; the limit is "
            f"{settings.max_map_poses} (DTF_MAX_MAP_POSES)",
        )
    return MapGrid(
        xs=grid_axis(grid.x.min, grid.x.max, grid.x.step, field="grid.x"),
        ys=grid_axis(grid.y.min, grid.y.max, grid.y.step, field="grid.y"),
        yaws=np.array(yaws, dtype=float),
    )


def wants_png(accept: str) -> bool:
    """Whether an Accept header asks for the picture rather than JSON."""
    media = [part.split(";")[0].strip().lower() for part in accept.split(",")]
    return "image/png" in media and "application/json" not in media


def _api_placement(placement: Placement) -> schemas.Placement:
    """The API's placement (m, rad) of a solver placement."""
    return schemas.Placement(x=placement.x, y=placement.y, z=placement.z, yaw=placement.yaw)


def _extreme(cmap: CapabilityMap, *, best: bool) -> schemas.MapExtreme | None:
    index = cmap.extreme(best=best)
    if index is None:
        return None
    return schemas.MapExtreme(
        placement=_api_placement(cmap.placement(index)),
        mu_path=float(cmap.mu_path[index]),
    )


def map_response(cmap: CapabilityMap) -> schemas.MapResponse:
    """The JSON answer of ``POST /v1/map``: cells yaw-major, then y, then x."""
    cells = []
    for k, j, i in np.ndindex(cmap.mu_path.shape):
        feasible = cmap.reason[k, j, i] == FEASIBLE
        cells.append(
            schemas.MapCell(
                x=float(cmap.xs[i]),
                y=float(cmap.ys[j]),
                yaw=float(cmap.yaws[k]),
                mu_path=float(cmap.mu_path[k, j, i]) if feasible else None,
                reason=None if feasible else REASONS[int(cmap.reason[k, j, i])],
                failed_waypoint=None if feasible else int(cmap.failed_waypoint[k, j, i]),
            )
        )
    return schemas.MapResponse(
        cells=cells,
        best=_extreme(cmap, best=True),
        worst=_extreme(cmap, best=False),
        feasible_cells=int(np.sum(cmap.reason == FEASIBLE)),
    )


def bounds_of(bounds: schemas.Bounds, *, z: float) -> PlacementBounds:
    """The solver's placement box (m, m, rad) at height z (m)."""
    return PlacementBounds(
        x=(bounds.x[0], bounds.x[1]),
        y=(bounds.y[0], bounds.y[1]),
        yaw=(bounds.yaw[0], bounds.yaw[1]),
        z=z,
    )


def optimize_response(
    optimum: PlacementOptimum | None,
    robot: Robot,
    *,
    bounds: PlacementBounds,
    start: Placement | None,
) -> schemas.OptimizeResponse:
    """The answer of ``POST /v1/optimize`` (``found: false`` when nothing was feasible)."""
    if optimum is None:
        if start is None:  # the solver's default start: the centre of the bounds
            x, y, yaw = bounds.centre()
            start = Placement(x, y, bounds.z, yaw)
        return schemas.OptimizeResponse(
            found=False,
            placement=None,
            mu_path=None,
            evaluation=None,
            start=schemas.StartInfo(placement=_api_placement(start), mu_path=None),
            improvement_percent=None,
            solver=schemas.SolverInfo(
                name="coarse search",
                status="no feasible placement inside the bounds",
                iterations=0,
                seconds=0.0,
            ),
        )
    report = optimum.solver
    return schemas.OptimizeResponse(
        found=True,
        placement=_api_placement(optimum.placement),
        mu_path=optimum.mu_path,
        evaluation=evaluate_response(optimum.evaluation, robot),
        start=schemas.StartInfo(
            placement=_api_placement(optimum.start), mu_path=optimum.start_mu_path
        ),
        improvement_percent=optimum.improvement_percent,
        solver=schemas.SolverInfo(
            name=report.name,
            status=report.status,
            iterations=report.iterations,
            seconds=report.seconds,
        ),
    )
