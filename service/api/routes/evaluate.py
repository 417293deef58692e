"""``POST /v1/evaluate``: mu_path of a path at one placement (spec sections 2-4, cam.md 7)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Header, Request, Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.config import Settings
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.render import render_joint_use
from service.schemas import EvaluateRequest, EvaluateResponse, PathInput
from service.work import json_response, run_stoppable
from solver.evaluate import PathEvaluation, evaluate_path
from solver.exceptions import InvalidInputError
from solver.feed import check_feed
from solver.joint_path import evaluate_joint_path
from solver.progress import Progress
from solver.robots import Robot as SolverRobot

router = APIRouter(prefix="/evaluate", tags=["evaluate"], responses=ERROR_RESPONSES)


@router.post(
    "",
    operation_id="evaluate",
    summary="Feasibility and mu_path of a path at a placement (PNG of joint use on request)",
    response_model=EvaluateResponse,
    openapi_extra=body_openapi(EvaluateRequest),
    responses={
        200: {
            "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}},
            "description": "JSON; or with Accept: image/png each joint's use of its speed limit "
            "along the path at the feed (default: mu_path), the limit at 1, the bottleneck "
            "marked (the ERK 2021 figs. 3-4 picture).",
        }
    },
)
async def post_evaluate(
    request: Request,
    body: Annotated[EvaluateRequest, body_in_thread(EvaluateRequest)],
    settings: SettingsDep,
    accept: Annotated[str, Header()] = "application/json",
) -> Response:
    """An unreachable placement is not an error: it answers ``feasible: false`` with a reason."""
    png = convert.wants_png(accept)
    return await run_stoppable(request, lambda _: _answer(body, settings, png=png))


def _evaluated(
    body: EvaluateRequest, settings: Settings
) -> tuple[SolverRobot, PathInput, PathEvaluation, float | None]:
    """The robot, the path, its evaluation and the feed to check; the path's size checked first."""
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    poses, placement = convert.spun_poses(path, body.spins), convert.placement_of(body.placement)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    if body.joint_path is not None:
        if spin_mode != "fixed":
            raise InvalidInputError("joint_path", "a joint path is evaluated in spin_mode fixed")
        evaluation = evaluate_joint_path(
            robot,
            poses,
            placement,
            convert.joint_path_of(body.joint_path, robot),
            max_joint_step=body.ik.max_joint_step,
            passes=path.passes,
        )
    else:
        evaluation = evaluate_path(
            robot,
            poses,
            placement,
            branch=convert.branch_of(body.ik.branch),
            max_joint_step=body.ik.max_joint_step,
            spin_mode=spin_mode,
            passes=path.passes,
        )
    feed = body.feed if body.feed is not None else path.feed
    return robot, path, evaluation, feed


def _answer(body: EvaluateRequest, settings: Settings, *, png: bool) -> Response:
    """The JSON answer, or the PNG of joint use."""
    if not png:
        return json_response(evaluation_of(body, settings, lambda _: None))
    robot, _, evaluation, feed = _evaluated(body, settings)
    if evaluation.mu_path is None or evaluation.mu_path <= 0.0:
        raise InvalidInputError(
            "placement",
            f"the path does not run here ({evaluation.reason or 'mu_path is 0'}): no joint "
            "speeds to draw; ask for JSON to see why",
        )
    check = check_feed(evaluation, evaluation.mu_path if feed is None else feed, robot.qdot_max)
    picture = render_joint_use(check, evaluation, robot.joint_names, title=robot.name)
    return Response(picture, media_type="image/png")


def evaluation_of(
    body: EvaluateRequest, settings: Settings, progress: Progress
) -> EvaluateResponse:
    """The JSON answer of ``POST /v1/evaluate`` (an evaluate job's result too)."""
    robot, path, evaluation, feed = _evaluated(body, settings)
    detail = body.detail or (
        "waypoints" if body.path.n_waypoints() <= settings.max_detail_waypoints else "summary"
    )
    return convert.evaluate_response(
        evaluation,
        robot,
        axis_correction=path.axis_correction,
        with_waypoints=detail == "waypoints",
        feed=None if feed is None else check_feed(evaluation, feed, robot.qdot_max),
    )
