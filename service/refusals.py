"""A log line for each refused request, with the reason its answer gives (``dtf.requests``).

uvicorn's access line says ``"POST /v1/map HTTP/1.1" 422`` and nothing of why: an operator
could not tell a client's bad grid from a body over the limit or a full queue without the
client (the operator audit of 2026-12-07, M4). Every error answer of the service has a
``detail`` list (:mod:`service.errors`); this pure ASGI middleware reads the list of each
answer of status 400 or more as it is sent (error bodies are small; at most :data:`KEEP`
bytes are kept) and logs the request, the status and the first detail's location and message.
A 499 (a client that left) has its own line already (:func:`service.errors.client_left`).

An answer sent :data:`SLOW_SECONDS` or more after its request came has a line too, with how
long it took (``INFO dtf.requests POST /v1/optimize 200 in 4.2 s``): uvicorn's access line has
no duration, and the per-route histogram of ``/metrics`` cannot say which request was slow.
"""

from __future__ import annotations

import json
import logging
import re
import time

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from service.errors import CLIENT_CLOSED_REQUEST
from service.logs import duration, request_log

KEEP = 65536
"""Bytes of an error answer kept to read its first detail."""

MESSAGE_CHARACTERS = 200
"""A detail's message is cut to this many characters in the line."""

SLOW_SECONDS = 1.0
"""An answer whose last byte went this long after its request came is logged with its time."""


def reason_of(body: bytes, *, cut: bool = False) -> str:
    """``body.grid.x.step: Input should be greater than 0 (and 2 more)`` from an error body.

    ``cut``: the body is the answer's first :data:`KEEP` bytes only (a list of thousands of
    details): its first detail is read from them, and the others not counted.
    """
    if cut:
        found = re.search(rb'"loc":\[(.*?)\],"msg":"((?:[^"\\]|\\.)*)"', body)
        if found is None:
            return f"an answer over {KEEP} bytes"
        where = ".".join(part.strip('"') for part in found[1].decode().split(",") if part)
        said = json.loads(b'"' + found[2] + b'"')[:MESSAGE_CHARACTERS]
        return f"{where}: {said} (and more)" if where else f"{said} (and more)"
    try:
        details = json.loads(body)["detail"]
        first = details[0]
        where = ".".join(str(part) for part in first.get("loc", []))
        said = str(first["msg"])[:MESSAGE_CHARACTERS]
    except (ValueError, LookupError, TypeError, AttributeError):
        return "no detail list"
    more = f" (and {len(details) - 1} more)" if len(details) > 1 else ""
    return f"{where}: {said}{more}" if where else f"{said}{more}"


def refused(status: int) -> bool:
    """An answer this middleware logs: an error's status, but a 499's (its line is its own)."""
    return status >= 400 and status != CLIENT_CLOSED_REQUEST


class RefusalLogMiddleware:
    """Log refused answers with their first detail, slow ones with their time; pass all on."""

    def __init__(self, app: ASGIApp) -> None:
        """Wrap ``app``."""
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Pass the request on; read the answer's body where its status is an error's."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        status = 0
        kept = bytearray()
        cut = False
        came = time.perf_counter()

        async def watch(message: Message) -> None:
            nonlocal status, cut
            if message["type"] == "http.response.start":
                status = int(message["status"])
            elif message["type"] == "http.response.body" and refused(status):
                chunk = message.get("body", b"")
                cut = cut or len(kept) + len(chunk) > KEEP
                kept.extend(chunk[: max(0, KEEP - len(kept))])
                if not message.get("more_body", False):
                    reason = reason_of(bytes(kept), cut=cut)
                    level = logging.WARNING if status >= 500 else logging.INFO
                    request_log.log(
                        level, "%s %s %d: %s", scope["method"], scope["path"], status, reason
                    )
            elif message["type"] == "http.response.body" and not message.get("more_body", False):
                took = time.perf_counter() - came
                if took >= SLOW_SECONDS and status != CLIENT_CLOSED_REQUEST:
                    request_log.info(
                        "%s %s %d in %s", scope["method"], scope["path"], status, duration(took)
                    )
            await send(message)

        await self.app(scope, receive, watch)
