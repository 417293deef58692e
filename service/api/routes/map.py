"""``POST /v1/map``: the capability map, as JSON or as a PNG picture (spec section 6)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Header
from fastapi.responses import Response

from service import convert
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.render import render_png
from service.schemas import MapRequest, MapResponse
from solver.capability_map import capability_map

router = APIRouter(prefix="/map", tags=["map"], responses=ERROR_RESPONSES)


@router.post(
    "",
    operation_id="map",
    summary="mu_path over a grid of placements (JSON, or PNG with Accept: image/png)",
    response_model=MapResponse,
    responses={
        200: {
            "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}},
            "description": "The map, or its picture.",
        }
    },
)
def post_map(
    body: MapRequest, settings: SettingsDep, accept: Annotated[str, Header()] = "application/json"
) -> MapResponse | Response:
    """Every placement of the grid with its mu_path (or why it is infeasible), best and worst.

    With ``Accept: image/png`` the answer is the colour map: one panel per yaw, colour bar in
    m/s, infeasible cells blank, the best and worst placements marked.
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    grid = convert.map_grid(body.grid, settings=settings, n_waypoints=body.path.n_waypoints())
    png = convert.wants_png(accept)
    if png:
        convert.check_png_size(grid, settings=settings)
    robot = convert.robot_from_schema(body.robot)
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
    )
    if png:
        return Response(render_png(result, title=f"{robot.name}: mu_path"), media_type="image/png")
    return convert.map_response(result, spin_mode=spin_mode)
