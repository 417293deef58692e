"""Conversions between request/response schemas and solver objects (numpy, dataclasses)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from service import schemas
from service.config import Settings
from service.schemas.path import PathInput
from solver.cam.frames import frames_of_placement
from solver.capability_map import CapabilityMap, axis_length, grid_axis
from solver.dtf import DtfResult
from solver.evaluate import Branch, PathEvaluation
from solver.exceptions import InvalidInputError
from solver.feed import FeedCheck
from solver.optimize import PlacementOptimum
from solver.pipeline import SpinMode, require_family
from solver.robots import Robot
from solver.search_space import PlacementBounds
from solver.spatial import (
    MAX_COORDINATE,
    Placement,
    spun_waypoints,
)
from solver.tracking import FEASIBLE, REASONS


def robot_from_schema(spec: schemas.Robot) -> Robot:
    """The solver robot a request names, with its speed limits and tool point.

    Raises:
        InvalidInputError: an OPW geometry, its limits or the speed limits are out of range.
        RobotModelError: the URDF or its frames do not fit.
    """
    return spec.to_solver()


def path_of(path: schemas.Path) -> PathInput:
    """The poses of a path in {O}, from whichever form the request used.

    Raises:
        InvalidInputError, RepeatedWaypointError: naming the field and the waypoint.
    """
    return path.to_solver()


def spun_poses(path: PathInput, spins: list[float] | None) -> np.ndarray:
    """The path's poses, each turned by its spin about its tool z axis when spins are given.

    Raises:
        InvalidInputError: on ``spins``, a count that is not the number of waypoints.
    """
    if spins is None:
        return path.poses
    if len(spins) != len(path.poses):
        raise InvalidInputError(
            "spins", f"{len(spins)} spins for {len(path.poses)} waypoints: one per waypoint"
        )
    return spun_waypoints(path.poses, np.array(spins, dtype=float))


def joint_path_of(rows: list[list[float]], robot: Robot) -> np.ndarray:
    """A joint path (N, n), rad, from the request's rows.

    Raises:
        InvalidInputError: on ``joint_path`` and the waypoint, a row without one value a joint.
    """
    for i, row in enumerate(rows):
        if len(row) != robot.dof:
            raise InvalidInputError(
                "joint_path",
                f"{len(row)} values but {robot.name!r} has {robot.dof} joints",
                waypoint=i,
            )
    return np.array(rows, dtype=float)


def check_path_size(path: schemas.Path, *, limit: int, setting: str) -> None:
    """Refuse a path with more waypoints than a setting allows, before any work.

    Raises:
        InvalidInputError: on ``path``, saying the size asked for and the limit.
    """
    if path.n_waypoints() > limit:
        raise InvalidInputError(
            "path", f"{path.n_waypoints()} waypoints; the limit is {limit} ({setting})"
        )


def check_png_size(grid: MapGrid, *, settings: Settings) -> None:
    """Refuse a PNG of more panels (yaw x spin values) than the setting allows.

    Raises:
        InvalidInputError: on ``grid``, saying the size asked for and the limit.
    """
    panels = len(grid.yaws) * len(grid.spins)
    if panels > settings.max_png_panels:
        raise InvalidInputError(
            "grid",
            f"{len(grid.yaws)} yaws * {len(grid.spins)} spins = {panels} PNG panels; the limit "
            f"is {settings.max_png_panels} (DTF_MAX_PNG_PANELS); ask for JSON for more",
        )


def spin_mode_of(requested: SpinMode | None, path: PathInput) -> SpinMode:
    """The spin mode asked for, or the path form's default."""
    return path.default_spin_mode if requested is None else requested


def placement_of(placement: schemas.Placement) -> Placement:
    """The solver's placement (m, rad)."""
    return Placement(
        x=placement.x, y=placement.y, z=placement.z, yaw=placement.yaw, spin=placement.spin
    )


def branch_of(choice: schemas.Branch | schemas.NumericBranch | str) -> Branch | None:
    """The solver's branch label; ``None`` for ``"auto"``."""
    if isinstance(choice, str):
        return None
    if isinstance(choice, schemas.NumericBranch):
        return Branch.named(solution=str(choice.solution))
    return Branch.named(shoulder=choice.shoulder, elbow=choice.elbow, wrist=choice.wrist)


def branch_to_api(branch: Branch | None) -> schemas.Branch | schemas.NumericBranch | None:
    """The API's branch: named levels, or the numeric family's solution index."""
    if branch is None:
        return None
    choices = branch.as_dict()
    if set(choices) == {"solution"}:
        return schemas.NumericBranch(solution=int(choices["solution"]))
    return schemas.Branch.model_validate(choices)


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
        family=None if robot.family is None else robot.family.name,
        branches=_branch_levels(robot),
    )


def _branch_levels(robot: Robot) -> list[schemas.BranchLevel]:
    """The levels of the robot's IK branches and the choices at each, in branch order."""
    if robot.family is None:
        return []
    choices: dict[str, list[str]] = {}
    for branch in robot.family.branches:
        for level, choice in branch.choices:
            if choice not in choices.setdefault(level, []):
                choices[level].append(choice)
    return [schemas.BranchLevel(level=level, choices=names) for level, names in choices.items()]


def _optional_list(values: np.ndarray | None, i: int) -> list[float] | None:
    return None if values is None else values[i].tolist()


def _optional_float(values: np.ndarray | None, i: int) -> float | None:
    return None if values is None else float(values[i])


def _numbers_or_none(values: np.ndarray | None, i: int) -> list[float | None] | None:
    """Row i of values as JSON numbers, None where NaN; None without values."""
    if values is None:
        return None
    return [None if math.isnan(v) else v for v in values[i].tolist()]


def evaluate_response(
    evaluation: PathEvaluation,
    robot: Robot,
    *,
    axis_correction: float = 0.0,
    with_waypoints: bool = True,
    feed: FeedCheck | None = None,
) -> schemas.EvaluateResponse:
    """The response of ``POST /v1/evaluate`` (per-waypoint detail when ``with_waypoints``)."""
    ev = evaluation
    at_feed_qdot = None if feed is None else feed.qdot_at_feed
    at_feed_use = None if feed is None else feed.use
    waypoints = []
    for i in range(ev.h.shape[0] if with_waypoints else 0):
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
                qdot_at_feed=_numbers_or_none(at_feed_qdot, i),
                use=_numbers_or_none(at_feed_use, i),
            )
        )
    bottleneck = None
    if ev.bottleneck_waypoint is not None and ev.bottleneck_joint is not None:
        bottleneck = schemas.Bottleneck(
            waypoint=ev.bottleneck_waypoint,
            joint=ev.bottleneck_joint,
            joint_name=robot.joint_names[ev.bottleneck_joint],
        )
    return schemas.EvaluateResponse(
        feasible=ev.feasible,
        mu_path=ev.mu_path,
        bottleneck=bottleneck,
        reason=None if ev.reason is None else schemas.FailureReason(ev.reason),
        failed_waypoint=ev.failed_waypoint,
        branch=branch_to_api(ev.branch),
        ik=schemas.IkInfo.model_validate(
            {
                "family": require_family(robot).name,
                "seeds": ev.ik_seeds,
                "branches_found": ev.ik_branches_found,
            }
        ),
        waypoints=waypoints,
        detail="waypoints" if with_waypoints else "summary",
        spin_mode=ev.spin_mode,
        spins=None if ev.spins is None else ev.spins.tolist(),
        axis_correction=axis_correction,
        feed_check=None
        if feed is None
        else schemas.FeedCheckResult(feed=feed.feed, feasible=feed.feasible, margin=feed.margin),
    )


@dataclass(frozen=True)
class MapGrid:
    """The grid values of a map request (m, m, rad)."""

    xs: np.ndarray
    ys: np.ndarray
    yaws: np.ndarray
    spins: np.ndarray


def map_grid(grid: schemas.Grid, *, settings: Settings, n_waypoints: int, robot: Robot) -> MapGrid:
    """The grid's values, after checking its size against the settings.

    The poses are weighed by the robot family's cost (``path_cost``: 1 a pose for a closed-form
    family, far more for numeric IK), so that DTF_MAX_MAP_POSES bounds the time of every map.

    Raises:
        InvalidInputError: an axis is malformed, or the grid is over a size limit; the message
            says the size asked for and the limit.
    """
    nx = axis_length(grid.x.min, grid.x.max, grid.x.step, field="grid.x")
    ny = axis_length(grid.y.min, grid.y.max, grid.y.step, field="grid.y")
    for field, values in (
        ("grid.x", (grid.x.min, grid.x.max)),
        ("grid.y", (grid.y.min, grid.y.max)),
        ("grid.z", (grid.z,)),
    ):
        if max(abs(v) for v in values) > MAX_COORDINATE:
            raise InvalidInputError(
                field, f"{max(abs(v) for v in values):.6g} m is beyond +-{MAX_COORDINATE:g} m"
            )
    yaws, spins = grid.yaws(), grid.spins()
    cells = nx * ny * len(yaws) * len(spins)
    size = f"{nx} x * {ny} y * {len(yaws)} yaw * {len(spins)} spin = {cells} placements"
    limits = settings.map_limits()
    if cells > limits.cells:
        raise InvalidInputError(
            "grid", f"{size}; the limit is {limits.cells} ({limits.cells_setting}){limits.hint}"
        )
    poses = cells * n_waypoints
    family = require_family(robot)
    work = cells * family.path_cost(n_waypoints)
    if work > limits.poses:
        weighed = "" if work == poses else f", as work {work:.4g} closed-form poses"
        weighed += "" if work == poses else f" ({family.name} IK)"
        raise InvalidInputError(
            "grid",
            f"{size} * {n_waypoints} waypoints = {poses} poses{weighed}; the limit is "
            f"{limits.poses} ({limits.poses_setting}){limits.hint}",
        )
    return MapGrid(
        xs=grid_axis(grid.x.min, grid.x.max, grid.x.step, field="grid.x"),
        ys=grid_axis(grid.y.min, grid.y.max, grid.y.step, field="grid.y"),
        yaws=np.array(yaws, dtype=float),
        spins=np.array(spins, dtype=float),
    )


def _accept_weights(accept: str) -> dict[str, float]:
    """Media range -> q-value of an Accept header (RFC 9110 section 12.5.1; q defaults to 1)."""
    weights: dict[str, float] = {}
    for part in accept.split(","):
        media, *parameters = (piece.strip().lower() for piece in part.split(";"))
        q = 1.0
        for parameter in parameters:
            name, _, value = parameter.partition("=")
            if name.strip() == "q":
                try:
                    q = min(max(float(value), 0.0), 1.0)
                except ValueError:
                    q = 0.0
        if media:
            weights[media] = max(q, weights.get(media, 0.0))
    return weights


def wants_png(accept: str) -> bool:
    """Whether an Accept header prefers the picture to JSON.

    The most specific range that names each counts (``image/png``, else ``image/*``, else
    ``*/*``; ``application/json``, else ``application/*``, else ``*/*``); the picture wins on a
    higher q, or on an equal q when it is named more specifically than JSON. No Accept, or
    ``*/*`` alone, is JSON.
    """
    weights = _accept_weights(accept)

    def weight(*ranges: str) -> tuple[float, int]:
        for specificity, media in enumerate(ranges):
            if media in weights:
                return weights[media], -specificity
        return 0.0, -len(ranges)

    png = weight("image/png", "image/*", "*/*")
    json_ = weight("application/json", "application/*", "*/*")
    return png[0] > 0.0 and png > json_


def _api_placement(placement: Placement) -> schemas.PlacementResult:
    """The API's placement (m, rad) of a solver placement, with its controller frames."""
    frames = frames_of_placement(placement)
    return schemas.PlacementResult(
        x=placement.x,
        y=placement.y,
        z=placement.z,
        yaw=placement.yaw,
        spin=placement.spin,
        frames=schemas.ControllerFrames(
            matrix=frames.matrix, ur=frames.ur, kuka=frames.kuka, abb=frames.abb, fanuc=frames.fanuc
        ),
    )


def _extreme(cmap: CapabilityMap, *, best: bool) -> schemas.MapExtreme | None:
    index = cmap.extreme(best=best)
    if index is None:
        return None
    return schemas.MapExtreme(
        placement=_api_placement(cmap.placement(index)),
        mu_path=float(cmap.mu_path[index]),
    )


def map_response(cmap: CapabilityMap, *, spin_mode: SpinMode) -> schemas.MapResponse:
    """The JSON answer of ``POST /v1/map``: cells yaw-major, then y, then x."""
    cells = []
    for s, k, j, i in np.ndindex(cmap.mu_path.shape):
        feasible = cmap.reason[s, k, j, i] == FEASIBLE
        cells.append(
            schemas.MapCell(
                x=float(cmap.xs[i]),
                y=float(cmap.ys[j]),
                yaw=float(cmap.yaws[k]),
                spin=float(cmap.spins[s]),
                mu_path=float(cmap.mu_path[s, k, j, i]) if feasible else None,
                reason=None
                if feasible
                else schemas.FailureReason(REASONS[int(cmap.reason[s, k, j, i])]),
                failed_waypoint=None if feasible else int(cmap.failed_waypoint[s, k, j, i]),
            )
        )
    return schemas.MapResponse(
        cells=cells,
        best=_extreme(cmap, best=True),
        worst=_extreme(cmap, best=False),
        feasible_cells=int(np.sum(cmap.reason == FEASIBLE)),
        spin_mode=spin_mode,
    )


def bounds_of(bounds: schemas.Bounds, *, z: float | None) -> PlacementBounds:
    """The solver's placement box (m, m, rad) at height z (m), or with the height's range."""
    return PlacementBounds(
        x=(bounds.x[0], bounds.x[1]),
        y=(bounds.y[0], bounds.y[1]),
        yaw=(bounds.yaw[0], bounds.yaw[1]),
        z=(bounds.z[0], bounds.z[1]) if bounds.z is not None else float(z or 0.0),
        spin=(bounds.spin[0], bounds.spin[1]),
    )


def optimize_response(
    optimum: PlacementOptimum, robot: Robot, *, axis_correction: float = 0.0
) -> schemas.OptimizeResponse:
    """The answer of ``POST /v1/optimize`` (``found: false`` when nothing was feasible)."""
    report = optimum.solver
    return schemas.OptimizeResponse(
        found=optimum.found,
        placement=None if optimum.placement is None else _api_placement(optimum.placement),
        mu_path=optimum.mu_path,
        evaluation=None
        if optimum.evaluation is None
        else evaluate_response(optimum.evaluation, robot, axis_correction=axis_correction),
        start=schemas.StartInfo(
            placement=_api_placement(optimum.start), mu_path=optimum.start_mu_path
        ),
        improvement_percent=optimum.improvement_percent,
        spins=None if optimum.spins is None else optimum.spins.tolist(),
        joint_path=None if optimum.joint_path is None else optimum.joint_path.tolist(),
        solver=schemas.SolverInfo(
            name=report.name,
            status=report.status,
            iterations=report.iterations,
            seconds=report.seconds,
        ),
    )
