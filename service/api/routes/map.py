"""``POST /v1/map``: the capability map, as JSON or as a PNG picture (spec section 6)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Header, Request
from fastapi.responses import Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.metrics import PLACEMENTS
from service.operations import computed_map, map_png
from service.schemas import MapRequest, MapResponse
from service.work import run_stoppable
from solver.core.progress import Progress
from solver.core.robots import Robot
from solver.path.capability_map import CapabilityMap

router = APIRouter(prefix="/map", tags=["maps"], responses=ERROR_RESPONSES)


def _picture(result: CapabilityMap, robot: Robot) -> Response:
    """The PNG answer."""
    return Response(map_png(result, robot), media_type="image/png")


@router.post(
    "",
    operation_id="map",
    summary="mu_path over a grid of placements (JSON; PNG with Accept: image/png)",
    response_model=MapResponse,
    openapi_extra=body_openapi(MapRequest),
)
async def post_map(
    request: Request,
    body: Annotated[MapRequest, body_in_thread(MapRequest)],
    settings: SettingsDep,
    accept: Annotated[str, Header(include_in_schema=False)] = "application/json",
) -> MapResponse | Response:
    """Every placement of the grid with its mu_path (or why it is infeasible), best and worst.

    The colour map is ``POST /v1/map/png`` (a browser may also ask this operation for it with
    ``Accept: image/png``; one content type an operation keeps generated clients able to read
    every answer).
    """
    png = convert.wants_png(accept)

    def work(progress: Progress) -> MapResponse | Response:
        computed = computed_map(body, settings, png=png, progress=progress)
        result, robot = computed.result, computed.robot
        PLACEMENTS.inc(result.mu_path.size)
        if png:
            return _picture(result, robot)
        # The model's JSON written from the columns (no model a cell; tests/service/test_map_json)
        return Response(computed.answer_json(), media_type="application/json")

    return await run_stoppable(request, work)


@router.post(
    "/png",
    operation_id="map_png",
    summary="The colour map of a grid of placements, as a PNG",
    response_class=Response,
    responses={
        200: {
            "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}},
            "description": "The colour map: one panel per yaw and spin, colour bar in m/s, "
            "each infeasible cell in its reason's colour, as on the page (unreachable, joint "
            "limits, singular, discontinuous, collision with the cell), the best and worst "
            "placements marked.",
        }
    },
    openapi_extra=body_openapi(MapRequest),
)
async def post_map_png(
    request: Request,
    body: Annotated[MapRequest, body_in_thread(MapRequest)],
    settings: SettingsDep,
) -> Response:
    """The map of ``POST /v1/map`` as a picture (generated clients get bytes)."""

    def work(progress: Progress) -> Response:
        computed = computed_map(body, settings, png=True, progress=progress)
        result, robot = computed.result, computed.robot
        PLACEMENTS.inc(result.mu_path.size)
        return _picture(result, robot)

    return await run_stoppable(request, work)
