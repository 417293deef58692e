"""``POST /v1/optimize``: the best workpiece placement inside a box (spec section 6)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Request, Response

from service.body import body_in_thread, body_openapi
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.operations.optimize import optimum_of
from service.schemas import OptimizeRequest, OptimizeResponse
from service.work import json_response, run_stoppable

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
    coarse map (20 mm, 15 degrees) would exceed DTF_MAX_MAP_CELLS cells, or whose whole search
    (the coarse map or the scipy method's differential evolution, the refinement, the
    Nelder-Mead climbs, the whole-path checks of the local solves), in placement-waypoint
    pairs weighed by the IK family's cost, would exceed DTF_MAX_MAP_POSES (casadi) or
    DTF_MAX_SEARCH_POSES (scipy), is a 422 on ``bounds``, before any work (an optimize job
    takes DTF_MAX_JOB_CELLS and DTF_MAX_JOB_POSES instead). The height is ``z``
    or ``bounds.z``, exactly one of them (both or neither is a 422).
    """
    return await run_stoppable(
        request, lambda progress: json_response(optimum_of(body, settings, progress))
    )
