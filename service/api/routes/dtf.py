"""``POST /v1/dtf``: the DTF index at one configuration (spec section 3)."""

from __future__ import annotations

import math
from typing import Annotated

from fastapi import APIRouter

from service import convert
from service.body import body_in_thread, body_openapi
from service.errors import ERROR_RESPONSES
from service.schemas import DtfRequest, DtfResponse
from solver.core.dtf import chiu, dtf, twist_per_unit_speed, yoshikawa
from solver.core.kinematics import check_configuration, jacobian_in_base

router = APIRouter(prefix="/dtf", tags=["dtf"], responses=ERROR_RESPONSES)


@router.post(
    "",
    operation_id="dtf",
    summary="Largest tool speed along a direction at one configuration",
    openapi_extra=body_openapi(DtfRequest),
)
def post_dtf(body: Annotated[DtfRequest, body_in_thread(DtfRequest)]) -> DtfResponse:
    """V_max, Omega_max and the joint speeds there, plus Yoshikawa and Chiu for comparison."""
    robot = convert.robot_from_schema(body.robot)
    q = check_configuration(robot, body.q)
    jacobian = jacobian_in_base(robot, q)
    h = convert.h_of(body.h)
    result = dtf(
        jacobian, u_T=body.u_T, u_R=body.u_R, h=h, qdot_max=robot.qdot_max, method=body.method
    )
    twist = twist_per_unit_speed(body.u_T, body.u_R, h)
    given = [u for u in (body.u_T, body.u_R) if u is not None]
    correction = float(max((abs(math.hypot(*u) - 1.0) for u in given), default=0.0))
    answer = convert.dtf_response(
        result, robot, yoshikawa=yoshikawa(jacobian), chiu=chiu(jacobian, twist)
    )
    return answer.model_copy(update={"correction": correction})
