"""``POST /v1/evaluate``: the answer from the solver's path evaluation."""

from __future__ import annotations

import math

import numpy as np

from service import schemas
from service.convert.common import branch_to_api, h_to_api
from solver.evaluate import PathEvaluation
from solver.feed import FeedCheck
from solver.pipeline import require_family
from solver.robots import Robot


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
