"""``POST /v1/evaluate``: mu_path of a path at one placement (spec sections 2-4, cam.md 7)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Header, Request, Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.operations import evaluation_of, joint_use_png
from service.schemas import EvaluateRequest, EvaluateResponse
from service.work import json_response, run_stoppable

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
    """An unreachable placement is not an error: it answers ``feasible: false`` with a reason.

    A client that leaves stops the work within about a second, with numeric IK too (a long
    path with numeric IK takes tens of seconds: 20,000 waypoints on a seven-joint arm).
    """
    if convert.wants_png(accept):
        picture = await run_stoppable(
            request, lambda progress: joint_use_png(body, settings, progress)
        )
        return Response(picture, media_type="image/png")
    return await run_stoppable(
        request, lambda progress: json_response(evaluation_of(body, settings, progress))
    )
