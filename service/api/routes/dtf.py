"""``POST /v1/dtf``: the DTF index at one configuration (spec section 3)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter

from service.body import body_in_thread, body_openapi
from service.errors import ERROR_RESPONSES
from service.operations import dtf_of
from service.schemas import DtfRequest, DtfResponse

router = APIRouter(prefix="/dtf", tags=["dtf"], responses=ERROR_RESPONSES)


@router.post(
    "",
    operation_id="dtf",
    summary="Largest tool speed along a direction at one configuration",
    openapi_extra=body_openapi(DtfRequest),
)
def post_dtf(body: Annotated[DtfRequest, body_in_thread(DtfRequest)]) -> DtfResponse:
    """V_max, Omega_max and the joint speeds there, plus Yoshikawa and Chiu for comparison."""
    return dtf_of(body)
