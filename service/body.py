"""Request bodies parsed and validated in a worker thread, never on the event loop.

FastAPI validates a declared body on the event loop: a 2 MB path (20,000 waypoints) is about
0.2 s of JSON parsing and validation during which no other request, ``/healthz`` included, is
answered. A route that takes a large body declares it with :func:`body_in_thread` instead: the
body is validated by pydantic (``model_validate_json``) in a worker thread, errors come back as
the same ``422`` as FastAPI's, and :func:`body_openapi` keeps the operation's request body in
the OpenAPI description. A body under INLINE_BODY_BYTES (the README example is 19 KB, 0.3 ms)
is validated on the event loop: the hop to a thread and back would cost more than it.
"""

from __future__ import annotations

from typing import Any, TypeVar

import anyio
from fastapi import Depends, Request
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel, ValidationError

M = TypeVar("M", bound=BaseModel)
INLINE_BODY_BYTES = 32 * 1024
"""Bodies up to this size are validated on the event loop (about 1 ms at most)."""
BODY_MODELS: list[type[BaseModel]] = []
"""Every model taken by :func:`body_in_thread`; their schemas go into the OpenAPI components."""


def body_in_thread(model: type[M]) -> Any:
    """A dependency giving the request body as ``model``, validated in a worker thread."""

    async def parse(request: Request) -> M:
        raw = await request.body()
        try:
            if len(raw) <= INLINE_BODY_BYTES:
                return model.model_validate_json(raw)
            return await anyio.to_thread.run_sync(model.model_validate_json, raw)
        except ValidationError as error:
            errors = [{**e, "loc": ("body", *e["loc"])} for e in error.errors()]
            raise RequestValidationError(errors) from None

    BODY_MODELS.append(model)
    return Depends(parse)


def body_openapi(model: type[BaseModel]) -> dict[str, Any]:
    """The ``openapi_extra`` of a route whose body is ``model`` (taken by body_in_thread)."""
    schema = {"$ref": f"#/components/schemas/{model.__name__}"}
    return {"requestBody": {"required": True, "content": {"application/json": {"schema": schema}}}}
