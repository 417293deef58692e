"""``POST /v1/map``: the capability map, as JSON or as a PNG picture (spec section 6)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Header, Request
from fastapi.responses import Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.config import Settings
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.metrics import PLACEMENTS
from service.render import render_png
from service.schemas import MapRequest, MapResponse
from service.work import json_response, run_stoppable
from solver.capability_map import CapabilityMap, capability_map
from solver.parallel import TaskRunner, ThreadRunner
from solver.pipeline import SpinMode
from solver.progress import Progress
from solver.robots import Robot

router = APIRouter(prefix="/map", tags=["maps"], responses=ERROR_RESPONSES)


def checked_grid(body: MapRequest, settings: Settings) -> tuple[Robot, convert.MapGrid]:
    """The robot and the grid of a map request, its size checked against ``settings``.

    Raises:
        InvalidInputError: the path or the grid over a limit (the message names the setting).
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    grid = convert.map_grid(
        body.grid, settings=settings, n_waypoints=body.path.n_waypoints(), robot=robot
    )
    return robot, grid


def _computed_map(
    body: MapRequest,
    settings: Settings,
    *,
    png: bool,
    progress: Progress,
    runner: TaskRunner | None = None,
) -> tuple[CapabilityMap, Robot, SpinMode]:
    """The map a request asks for, its size checked first; the robot; the spin mode.

    The placements run on ``runner``, by default on DTF_THREADS threads.
    """
    robot, grid = checked_grid(body, settings)
    if png:
        convert.check_png_size(grid, settings=settings)
    path = convert.path_of(body.path)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    result = capability_map(
        robot,
        path.poses,
        xs=grid.xs,
        ys=grid.ys,
        z=body.grid.z,
        yaws=grid.yaws,
        spins=grid.spins,
        branch=convert.branch_of(body.ik.branch),
        max_joint_step=body.ik.max_joint_step,
        spin_mode=spin_mode,
        progress=progress,
        passes=path.passes,
        runner=ThreadRunner(settings.threads) if runner is None else runner,
    )
    PLACEMENTS.inc(result.mu_path.size)
    return result, robot, spin_mode


def map_of(
    body: MapRequest, settings: Settings, progress: Progress, runner: TaskRunner | None = None
) -> MapResponse:
    """The JSON answer of ``POST /v1/map`` (a map job's result too, its tasks on ``runner``)."""
    result, robot, spin_mode = _computed_map(
        body, settings, png=False, progress=progress, runner=runner
    )
    return convert.map_response(result, robot, spin_mode=spin_mode)


def map_with_picture(
    body: MapRequest, settings: Settings, progress: Progress
) -> tuple[MapResponse, bytes]:
    """The JSON answer of ``POST /v1/map`` and the picture of ``POST /v1/map/png``, one map."""
    result, robot, spin_mode = _computed_map(body, settings, png=True, progress=progress)
    picture = render_png(result, title=f"{robot.name}: mu_path")
    return convert.map_response(result, robot, spin_mode=spin_mode), picture


def _picture(result: CapabilityMap, name: str) -> Response:
    """The PNG answer."""
    return Response(render_png(result, title=f"{name}: mu_path"), media_type="image/png")


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
    accept: Annotated[str, Header()] = "application/json",
) -> MapResponse | Response:
    """Every placement of the grid with its mu_path (or why it is infeasible), best and worst.

    With ``Accept: image/png`` the answer is the colour map (as ``POST /v1/map/png`` gives it,
    the operation generated clients should use for the picture).
    """
    png = convert.wants_png(accept)

    def work(progress: Progress) -> MapResponse | Response:
        result, robot, spin_mode = _computed_map(body, settings, png=png, progress=progress)
        if png:
            return _picture(result, robot.name)
        return json_response(convert.map_response(result, robot, spin_mode=spin_mode))

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
            "infeasible cells blank, the best and worst placements marked.",
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
        result, robot, _ = _computed_map(body, settings, png=True, progress=progress)
        return _picture(result, robot.name)

    return await run_stoppable(request, work)
