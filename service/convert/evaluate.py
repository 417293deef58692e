"""``POST /v1/evaluate``: the answer from the solver's path evaluation."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import TypeAdapter

from service import schemas
from service.convert.common import api_placement, branch_to_api, cell_model_to_api
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.path.cycle_time import CycleTime
from solver.path.evaluate import AccelerationIndex, PathEvaluation
from solver.path.feed import FeedCheck
from solver.path.problem import require_family

_WAYPOINTS = TypeAdapter(list[schemas.WaypointResult])


def _rows(values: np.ndarray | None, n: int) -> list[Any]:
    """The rows of values as Python lists (None each without values)."""
    return [None] * n if values is None else values.tolist()


def _rows_or_none(values: np.ndarray | None, n: int) -> list[Any]:
    """The rows of values as JSON numbers, None where NaN (None each without values)."""
    if values is None:
        return [None] * n
    return [[None if math.isnan(v) else v for v in row] for row in values.tolist()]


def _whole_rows(values: np.ndarray | None, n: int) -> list[Any]:
    """The rows of values as lists, None for a row of NaN (None each without values)."""
    if values is None:
        return [None] * n
    return [None if math.isnan(row[0]) else row for row in values.tolist()]


def acceleration_to_api(
    acceleration: AccelerationIndex | None, robot: Robot
) -> schemas.AccelerationResult | None:
    """The answer's ``acceleration`` object (None without acceleration limits)."""
    if acceleration is None:
        return None
    return schemas.AccelerationResult(
        mu_acc=acceleration.mu_acc,
        limited_by="acceleration" if acceleration.limited_by == "acceleration" else "speed",
        waypoint=acceleration.waypoint,
        joint=acceleration.joint,
        joint_name=robot.joint_names[acceleration.joint],
        blend_length=acceleration.blend_length,
    )


def cycle_time_to_api(times: CycleTime | None) -> schemas.CycleTimeResult | None:
    """The answer's ``cycle_time`` object (None without it)."""
    if times is None:
        return None
    passes = [
        schemas.PassCycleTime(
            start=p.start,
            stop=p.stop,
            length=p.length,
            constant_feed_time=p.constant_feed_time,
            ramp_up_length=p.ramp_up_length,
            ramp_up_time=p.ramp_up_time,
            ramp_down_length=p.ramp_down_length,
            ramp_down_time=p.ramp_down_time,
            ramp=p.ramp_time,
            time_optimal=p.time_optimal,
        )
        for p in times.passes
    ]
    return schemas.CycleTimeResult(
        constant_feed_time=times.constant_feed_time,
        ramp=times.ramp_time,
        time_optimal=times.time_optimal,
        passes=passes,
    )


def _waypoints(
    ev: PathEvaluation, robot: Robot, feed: FeedCheck | None
) -> list[schemas.WaypointResult]:
    """Every waypoint's detail, as the fields of schemas.WaypointResult.

    Built a column at a time and validated in one call: a WaypointResult made one at a time
    from rows of the arrays cost 1.5 ms of a /v1/evaluate of 133 waypoints, this 1.0 ms.
    """
    n = ev.h.shape[0]
    limiting = [None] * n if ev.limiting_joint is None else ev.limiting_joint.tolist()
    columns = {
        "index": range(n),
        "q": _rows(ev.q, n),
        "u_T": ev.u_T.tolist(),
        "u_R": ev.u_R.tolist(),
        "h": [None if math.isinf(h) else h for h in ev.h.tolist()],
        "v_max": _rows(ev.v_max, n),
        "omega_max": _rows(ev.omega_max, n),
        "qdot": _rows(ev.qdot, n),
        "limiting_joint": limiting,
        "limiting_joint_name": [None if j is None else robot.joint_names[j] for j in limiting],
        "qdot_at_feed": _rows_or_none(None if feed is None else feed.qdot_at_feed, n),
        "use": _rows_or_none(None if feed is None else feed.use, n),
        "qdd_at_mu_acc": _whole_rows(None if ev.acceleration is None else ev.acceleration.qdd, n),
    }
    rows = [dict(zip(columns, row, strict=True)) for row in zip(*columns.values(), strict=True)]
    return _WAYPOINTS.validate_python(rows)


def evaluate_response(
    evaluation: PathEvaluation,
    robot: Robot,
    *,
    axis_correction: float = 0.0,
    with_waypoints: bool = True,
    feed: FeedCheck | None = None,
    cycle_time: CycleTime | None = None,
    path_read: schemas.PathRead | None = None,
    robot_read: schemas.RobotRead | None = None,
    failed_in: tuple[int | None, str | None] = (None, None),
    placement: Placement | None = None,
    lines: np.ndarray | None = None,
) -> schemas.EvaluateResponse:
    """The response of ``POST /v1/evaluate`` (per-waypoint detail when ``with_waypoints``).

    ``path_read``: how the CAM program was read, None for poses and tool axes (and in
    ``/v1/optimize``'s evaluation, whose answer has it); ``robot_read``: what was changed in
    the robot's URDF (:func:`service.convert.robots.robot_read_of`; None in that evaluation
    too); ``failed_in``: the pass and operation of the failed waypoint, of CAM input
    (:func:`service.convert.path_read.pass_at`); ``placement``: the placement evaluated,
    answered with its controller frames; ``lines``: the program's line of each waypoint, of
    CAM input (:attr:`~service.schemas.path_input.PathInput.lines`).
    """
    ev = evaluation
    bottleneck = None
    if ev.bottleneck_waypoint is not None and ev.bottleneck_joint is not None:
        bottleneck = schemas.Bottleneck(
            waypoint=ev.bottleneck_waypoint,
            joint=ev.bottleneck_joint,
            joint_name=robot.joint_names[ev.bottleneck_joint],
            line=None if lines is None else int(lines[ev.bottleneck_waypoint]),
        )
    return schemas.EvaluateResponse(
        feasible=ev.feasible,
        mu_path=ev.mu_path,
        bottleneck=bottleneck,
        reason=None if ev.reason is None else schemas.FailureReason(ev.reason),
        failed_waypoint=ev.failed_waypoint,
        failed_pass=failed_in[0],
        failed_line=None
        if lines is None or ev.failed_waypoint is None
        else int(lines[ev.failed_waypoint]),
        failed_operation=failed_in[1],
        branch=branch_to_api(ev.branch),
        ik=schemas.IkInfo.model_validate(
            {
                "family": require_family(robot).name,
                "seeds": ev.ik_seeds,
                "branches_found": ev.ik_branches_found,
                "recognised": require_family(robot).recognised,
            }
        ),
        waypoints=_waypoints(ev, robot, feed) if with_waypoints else [],
        detail="waypoints" if with_waypoints else "summary",
        spin_mode=ev.spin_mode,
        spins=None if ev.spins is None else ev.spins.tolist(),
        placement=None if placement is None else api_placement(placement),
        axis_correction=axis_correction,
        acceleration=acceleration_to_api(ev.acceleration, robot),
        cycle_time=cycle_time_to_api(cycle_time),
        collision=schemas.Contact.from_solver(ev.collision),
        min_clearance=schemas.Contact.from_solver(ev.min_clearance),
        **cell_model_to_api(ev.cell_approximated, ev.cell_unchecked),
        feed_check=None
        if feed is None
        else schemas.FeedCheckResult(feed=feed.feed, feasible=feed.feasible, margin=feed.margin),
        path_read=path_read,
        robot_read=robot_read,
    )
