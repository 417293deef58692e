"""``POST /v1/evaluate``: mu_path of a path at one placement (spec sections 2-4, cam.md 7)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Header, Request, Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.config import Settings
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.operations import evaluation_of, joint_use_png
from service.schemas import EvaluateRequest, EvaluateResponse
from service.work import json_response, run_stoppable

router = APIRouter(prefix="/evaluate", tags=["evaluate"], responses=ERROR_RESPONSES)


@router.post(
    "",
    operation_id="evaluate",
    summary="Feasibility and mu_path of a path at a placement",
    response_model=EvaluateResponse,
    openapi_extra=body_openapi(EvaluateRequest),
)
async def post_evaluate(
    request: Request,
    body: Annotated[EvaluateRequest, body_in_thread(EvaluateRequest)],
    settings: SettingsDep,
    accept: Annotated[str, Header(include_in_schema=False)] = "application/json",
) -> Response:
    """An unreachable placement is not an error: it answers ``feasible: false`` with a reason.

    The picture of the joints' use is ``POST /v1/evaluate/png`` (a browser may also ask this
    operation for it with ``Accept: image/png``; one content type an operation keeps generated
    clients able to read every answer). A client that leaves stops the work within about a
    second, with numeric IK too (a long path with numeric IK takes tens of seconds: 20,000
    waypoints on a seven-joint arm).
    """
    if convert.wants_png(accept):
        return await _picture(request, body, settings)
    return await run_stoppable(
        request, lambda progress: json_response(evaluation_of(body, settings, progress))
    )


async def _picture(request: Request, body: EvaluateRequest, settings: Settings) -> Response:
    """The PNG answer: each joint's use of its speed limit along the path."""
    picture = await run_stoppable(request, lambda progress: joint_use_png(body, settings, progress))
    return Response(picture, media_type="image/png")


@router.post(
    "/png",
    operation_id="evaluate_png",
    summary="Each joint's use of its speed limit along the path, as a PNG",
    response_class=Response,
    responses={
        200: {
            "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}},
            "description": "Each joint's use of its speed limit along the path at the feed "
            "(default: mu_path), the limit at 1, the bottleneck marked (the ERK 2021 figs. 3-4 "
            "picture).",
        }
    },
    openapi_extra=body_openapi(EvaluateRequest),
)
async def post_evaluate_png(
    request: Request,
    body: Annotated[EvaluateRequest, body_in_thread(EvaluateRequest)],
    settings: SettingsDep,
) -> Response:
    """The picture of ``POST /v1/evaluate`` (generated clients get bytes)."""
    return await _picture(request, body, settings)
