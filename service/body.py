"""Request bodies parsed and validated in a worker thread, never on the event loop.

FastAPI validates a declared body on the event loop: a 2 MB path (20,000 waypoints) is about
0.2 s of JSON parsing and validation during which no other request, ``/healthz`` included, is
answered. A route that takes a large body declares it with :func:`body_in_thread` instead: the
body is validated by pydantic (``model_validate_json``) in a worker thread, errors come back as
the same ``422`` as FastAPI's, and :func:`body_openapi` keeps the operation's request body in
the OpenAPI description. A body under INLINE_BODY_BYTES (the README example is 19 KB, 0.3 ms)
is validated on the event loop: the hop to a thread and back would cost more than it.

A thread alone does not free the event loop: pydantic-core validates a body in one call that
holds the GIL (about 10 us a waypoint, 0.2-0.3 s for 20,000). So a larger body is validated in
pieces (:func:`validated_in_pieces`): the JSON parsed, then its path's waypoints PIECE_WAYPOINTS
at a time, between which the event loop gets its turn, then the rest of the model around them.
"""

from __future__ import annotations

import json
from typing import Any, TypeVar

import anyio
from fastapi import Depends, Request
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel, TypeAdapter, ValidationError

from service.schemas import Pose, ToolAxisWaypoint

M = TypeVar("M", bound=BaseModel)
INLINE_BODY_BYTES = 32 * 1024
"""Bodies up to this size are validated on the event loop (about 1 ms at most)."""
BODY_MODELS: list[type[BaseModel]] = []
"""Every model taken by :func:`body_in_thread`; their schemas go into the OpenAPI components."""
PIECE_WAYPOINTS = 1000
"""Waypoints validated in one call (about 10 ms: the longest the event loop then waits)."""
PIECES: dict[str, TypeAdapter[Any]] = {
    "waypoints": TypeAdapter(list[Pose]),
    "tool_axis_waypoints": TypeAdapter(list[ToolAxisWaypoint]),
}
"""The path's lists validated in pieces, by their field names, with their items' validators."""


def validated_in_pieces(model: type[M], raw: bytes) -> M:
    """``model.model_validate_json(raw)``, its path's waypoints validated in pieces.

    The same model, or the same ValidationError: on any error (bad JSON, a bad waypoint, a
    field that validates differently from Python than from JSON) the body is validated whole,
    as pydantic does, so errors keep their exact form. The whole validation holds the GIL for
    one call (0.2-0.3 s at 20,000 waypoints); here the longest call is one piece (or the JSON
    parser's, about 20 ms for 2 MB).
    """
    try:
        data = json.loads(raw)
        path = data.get("path") if isinstance(data, dict) else None
        if isinstance(path, dict):
            for name, adapter in PIECES.items():
                items = path.get(name)
                if isinstance(items, list) and len(items) > PIECE_WAYPOINTS:
                    path[name] = [
                        item
                        for start in range(0, len(items), PIECE_WAYPOINTS)
                        for item in adapter.validate_python(items[start : start + PIECE_WAYPOINTS])
                    ]
        return model.model_validate(data)
    except (ValueError, ValidationError):  # JSONDecodeError and ValidationError are ValueErrors
        return model.model_validate_json(raw)


def body_in_thread(model: type[M]) -> Any:
    """A dependency giving the request body as ``model``, validated in a worker thread."""

    async def parse(request: Request) -> M:
        raw = await request.body()
        try:
            if len(raw) <= INLINE_BODY_BYTES:
                return model.model_validate_json(raw)
            return await anyio.to_thread.run_sync(validated_in_pieces, model, raw)
        except ValidationError as error:
            errors = [{**e, "loc": ("body", *e["loc"])} for e in error.errors()]
            raise RequestValidationError(errors) from None

    BODY_MODELS.append(model)
    return Depends(parse)


def body_openapi(model: type[BaseModel]) -> dict[str, Any]:
    """The ``openapi_extra`` of a route whose body is ``model`` (taken by body_in_thread)."""
    schema = {"$ref": f"#/components/schemas/{model.__name__}"}
    return {"requestBody": {"required": True, "content": {"application/json": {"schema": schema}}}}
