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

import codecs
from typing import Any, TypeVar

import anyio
from fastapi import Depends, Request
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel, TypeAdapter, ValidationError
from pydantic_core import ErrorDetails, from_json

from service.schemas import Pose, ToolAxisWaypoint

M = TypeVar("M", bound=BaseModel)
T = TypeVar("T")
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


def _path_of(data: Any) -> Any:
    """The path of a route's body, or of a job's (``{"kind": ..., "request": {"path": ...}}``)."""
    if not isinstance(data, dict):
        return None
    request = data.get("request")
    return request.get("path") if isinstance(request, dict) else data.get("path")


def validated_in_pieces(model: type[M] | TypeAdapter[T], raw: bytes) -> Any:
    """``model.model_validate_json(raw)``, its path's waypoints validated in pieces.

    ``model`` is a model, or a TypeAdapter of one (a union of models: a job's body). The same
    answer, or the same ValidationError: on any error (bad JSON, a bad waypoint, a field that
    validates differently from Python than from JSON) the body is validated whole, as
    pydantic does, so errors keep their exact form. The whole validation holds the GIL for
    one call (0.2-0.3 s at 20,000 waypoints); here the longest call is one piece (or the JSON
    parser's, about 20 ms for 2 MB).
    """
    adapter = model if isinstance(model, TypeAdapter) else TypeAdapter(model)
    try:
        # pydantic-core's parser, as validate_json's: the same floats, a lone surrogate refused
        # and nesting bounded (json.loads took "\ud800", and raised RecursionError on 17,000
        # nested arrays: a 500)
        data = from_json(raw)
        path = _path_of(data)
        if isinstance(path, dict):
            for name, pieces in PIECES.items():
                items = path.get(name)
                if isinstance(items, list) and len(items) > PIECE_WAYPOINTS:
                    path[name] = [
                        item
                        for start in range(0, len(items), PIECE_WAYPOINTS)
                        for item in pieces.validate_python(items[start : start + PIECE_WAYPOINTS])
                    ]
        return adapter.validate_python(data)
    except (ValueError, ValidationError):  # JSONDecodeError and ValidationError are ValueErrors
        return adapter.validate_json(raw)


def body_in_thread(model: type[M]) -> Any:
    """A dependency giving the request body as ``model``, validated in a worker thread."""
    BODY_MODELS.append(model)
    return _parsed(TypeAdapter(model))


def union_body_in_thread(union: Any, models: tuple[type[BaseModel], ...]) -> Any:
    """A dependency giving the request body as ``union`` (of ``models``), as body_in_thread."""
    BODY_MODELS.extend(models)
    return _parsed(TypeAdapter(union))


def _parsed(adapter: TypeAdapter[Any]) -> Any:
    """The dependency: the body read, then validated (on the loop when small, else in pieces)."""

    async def parse(request: Request) -> Any:
        # A UTF-8 byte order mark says only the encoding JSON has anyway (RFC 8259 section 8.1:
        # a parser may ignore it); Windows tools write one, and the answer was "Invalid JSON:
        # expected value at line 1 column 1", naming nothing. CL and CSV files are read past one.
        raw = (await request.body()).removeprefix(codecs.BOM_UTF8)
        try:
            if len(raw) <= INLINE_BODY_BYTES:
                return adapter.validate_json(raw)
            return await anyio.to_thread.run_sync(validated_in_pieces, adapter, raw)
        except ValidationError as error:
            errors = [{**e, "loc": _location(e)} for e in error.errors()]
            raise RequestValidationError(errors) from None

    return Depends(parse)


def _location(error: ErrorDetails) -> tuple[str | int, ...]:
    """Where an error is in the request.

    A union told apart by a field of its object (a job's ``kind``) names the field in its
    error's context (``tag_field``): a missing or unknown tag is an error on that field.
    """
    loc = ("body", *error["loc"])
    field = error.get("ctx", {}).get("tag_field")
    return (*loc, field) if isinstance(field, str) and isinstance(error["input"], dict) else loc


def body_openapi(model: type[BaseModel]) -> dict[str, Any]:
    """The ``openapi_extra`` of a route whose body is ``model`` (taken by body_in_thread)."""
    return _request_body({"$ref": f"#/components/schemas/{model.__name__}"})


def union_body_openapi(models: tuple[type[BaseModel], ...]) -> dict[str, Any]:
    """The ``openapi_extra`` of a route whose body is one of ``models`` (union_body_in_thread)."""
    refs = [{"$ref": f"#/components/schemas/{model.__name__}"} for model in models]
    return _request_body({"oneOf": refs, "title": "Body"})


def _request_body(schema: dict[str, Any]) -> dict[str, Any]:
    return {"requestBody": {"required": True, "content": {"application/json": {"schema": schema}}}}
