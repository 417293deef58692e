"""``POST /v1/evaluate``: mu_path of a path at one placement (spec sections 2-4)."""

from __future__ import annotations

from fastapi import APIRouter

from service import convert
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.schemas import EvaluateRequest, EvaluateResponse
from solver.evaluate import evaluate_path
from solver.feed import check_feed

router = APIRouter(prefix="/evaluate", tags=["evaluate"], responses=ERROR_RESPONSES)


@router.post(
    "", operation_id="evaluate", summary="Feasibility and mu_path of a path at a placement"
)
def post_evaluate(body: EvaluateRequest, settings: SettingsDep) -> EvaluateResponse:
    """An unreachable placement is not an error: it answers ``feasible: false`` with a reason."""
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    evaluation = evaluate_path(
        robot,
        convert.spun_poses(path, body.spins),
        convert.placement_of(body.placement),
        branch=convert.branch_of(body.ik.branch),
        max_joint_step=body.ik.max_joint_step,
        spin_mode=convert.spin_mode_of(body.spin_mode, path),
        passes=path.passes,
    )
    detail = body.detail or (
        "waypoints" if body.path.n_waypoints() <= settings.max_detail_waypoints else "summary"
    )
    feed = body.feed if body.feed is not None else path.feed
    return convert.evaluate_response(
        evaluation,
        robot,
        axis_correction=path.axis_correction,
        with_waypoints=detail == "waypoints",
        feed=None if feed is None else check_feed(evaluation, feed, robot.qdot_max),
    )
