"""The error body of ``413`` answers; ``422`` answers have the same shape (FastAPI's)."""

from __future__ import annotations

from pydantic import ConfigDict, Field

from service.schemas.common import ResponseModel


class ErrorDetail(ResponseModel):
    """One thing wrong with the request."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "loc": ["body", "path", "waypoints", 3, "orientation"],
                    "msg": "quaternion norm is 1.01; a unit quaternion is needed (within 1e-3, "
                    "then normalised)",
                    "type": "unit_quaternion",
                }
            ]
        }
    )

    loc: list[str | int] = Field(
        description='Where: "body", then field names and list indices (waypoint index).'
    )
    msg: str = Field(description="What is wrong, naming the offending value.")
    type: str = Field(description='Kind of error, e.g. "missing", "repeated_waypoint".')


class ErrorResponse(ResponseModel):
    """An input error."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "detail": [
                        {
                            "loc": ["body"],
                            "msg": "request body is over the limit of 2000000 bytes",
                            "type": "body_too_large",
                        }
                    ]
                }
            ]
        }
    )

    detail: list[ErrorDetail] = Field(description="Every error found.")
