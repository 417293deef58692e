"""``POST /v1/optimize``: the best workpiece placement inside a box (spec section 6)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Request, Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.config import Settings
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.schemas import OptimizeRequest, OptimizeResponse
from service.work import json_response, run_stoppable
from solver.optimize import optimize_placement
from solver.parallel import TaskRunner, ThreadRunner
from solver.progress import Progress

router = APIRouter(prefix="/optimize", tags=["optimize"], responses=ERROR_RESPONSES)


@router.post(
    "",
    operation_id="optimize",
    summary="The placement where the whole path runs fastest",
    response_model=OptimizeResponse,
    openapi_extra=body_openapi(OptimizeRequest),
)
async def post_optimize(
    request: Request,
    body: Annotated[OptimizeRequest, body_in_thread(OptimizeRequest)],
    settings: SettingsDep,
) -> Response:
    """Maximise mu_path over (x, y, yaw) inside the bounds; every answer checked by the evaluator.

    No feasible placement inside the bounds is not an error: ``found`` is false. A box whose
    coarse map (20 mm, 15 degrees) would exceed DTF_MAX_MAP_CELLS cells, or DTF_MAX_MAP_POSES
    placement-waypoint pairs weighed by the IK family's cost, or whose scipy search would
    exceed DTF_MAX_SEARCH_POSES, is a 422 on ``bounds``.
    """
    return await run_stoppable(
        request, lambda progress: json_response(optimum_of(body, settings, progress))
    )


def optimum_of(
    body: OptimizeRequest,
    settings: Settings,
    progress: Progress,
    runner: TaskRunner | None = None,
) -> OptimizeResponse:
    """The answer of ``POST /v1/optimize``, its size checked first."""
    convert.check_path_size(
        body.path, limit=settings.max_optimize_waypoints, setting="DTF_MAX_OPTIMIZE_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    bounds = convert.bounds_of(body.bounds, z=body.z)
    start = None if body.start is None else convert.placement_of(body.start)
    optimum = optimize_placement(
        robot,
        path.poses,
        bounds=bounds,
        start=start,
        method=body.method,
        max_joint_step=body.ik.max_joint_step,
        spin_mode=convert.spin_mode_of(body.spin_mode, path),
        max_spin_step=None if body.spin_path is None else body.spin_path.max_spin_step,
        max_coarse_cells=settings.max_map_cells,
        max_coarse_poses=settings.max_map_poses,
        max_search_poses=settings.max_search_poses,
        max_solver_seconds=settings.max_solver_seconds,
        progress=progress,
        runner=ThreadRunner(settings.threads) if runner is None else runner,
        passes=path.passes,
    )
    return convert.optimize_response(optimum, robot, axis_correction=path.axis_correction)
