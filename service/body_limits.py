"""The request body's limits, checked before a route reads it: media type, size, arrival time.

A body not declared as JSON, or sent compressed, is a ``415``, one over
``Settings.max_body_bytes`` a ``413``, one that stops short of its length a ``408``; each in
the validation-error shape of every error answer (:mod:`service.errors`).
"""

from __future__ import annotations

import anyio
from fastapi import status
from fastapi.responses import JSONResponse
from starlette.datastructures import Headers
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from service.config import get_settings
from service.errors import CLIENT_CLOSED_REQUEST, client_left, error_response
from service.schemas import ErrorDetail


def _too_large(size: int, limit: int) -> JSONResponse:
    """The ``413`` answer, for a body of at least ``size`` bytes."""
    detail = ErrorDetail(
        loc=["body"],
        msg=f"request body is over the limit of {limit} bytes (at least {size} bytes)",
        type="body_too_large",
    )
    return error_response(status.HTTP_413_CONTENT_TOO_LARGE, [detail])


def _not_json(content_type: str) -> JSONResponse:
    """The ``415`` answer to a body declared as something other than JSON."""
    shown = content_type if len(content_type) <= 100 else content_type[:100] + "..."
    detail = ErrorDetail(
        loc=["header", "content-type"],
        msg=f"the body must be JSON (content-type application/json), not {shown!r}",
        type="unsupported_media_type",
    )
    return error_response(status.HTTP_415_UNSUPPORTED_MEDIA_TYPE, [detail])


def _encoded(encoding: str) -> JSONResponse:
    """The ``415`` answer to a body sent compressed (a Content-Encoding other than identity)."""
    shown = encoding if len(encoding) <= 100 else encoding[:100] + "..."
    detail = ErrorDetail(
        loc=["header", "content-encoding"],
        msg=f"the body must be sent as it is, not encoded ({shown!r}): no content coding is "
        "read (the JSON parser saw the compressed bytes: 'Invalid JSON')",
        type="unsupported_media_type",
    )
    return error_response(status.HTTP_415_UNSUPPORTED_MEDIA_TYPE, [detail])


def _no_content_type() -> JSONResponse:
    """The ``415`` answer to a body sent without a Content-Type."""
    detail = ErrorDetail(
        loc=["header", "content-type"],
        msg="the body must be declared as JSON (content-type application/json); no content-type "
        "was sent",
        type="unsupported_media_type",
    )
    return error_response(status.HTTP_415_UNSUPPORTED_MEDIA_TYPE, [detail])


def _too_slow(seconds: float, size: int) -> JSONResponse:
    """The ``408`` answer to a body that did not arrive within ``seconds``."""
    detail = ErrorDetail(
        loc=["body"],
        msg=f"the body did not arrive within {seconds:g} s ({size} bytes came; "
        "DTF_BODY_READ_SECONDS)",
        type="body_timeout",
    )
    response = error_response(status.HTTP_408_REQUEST_TIMEOUT, [detail])
    response.headers["Connection"] = "close"
    return response


def _has_body(headers: Headers) -> bool:
    """Whether a request announces a body (a Content-Length above 0, or chunks)."""
    length = headers.get("content-length", "")
    return (length.isdigit() and int(length) > 0) or "transfer-encoding" in headers


def is_json(content_type: str) -> bool:
    """Whether a Content-Type names JSON (application/json or a +json type)."""
    media = content_type.split(";")[0].strip().lower()
    return media == "application/json" or (
        media.startswith("application/") and media.endswith("+json")
    )


def _client_left(scope: Scope, size: int) -> JSONResponse:
    """The answer (nobody hears it) to a body its client stopped sending and left.

    Sent so that the request metrics count it, as 4xx (:data:`CLIENT_CLOSED_REQUEST`): the
    middleware returned without an answer, which the metrics counted as a server error.
    """
    client_left(scope["method"], scope["path"], f"its body stopped after {size} bytes")
    detail = ErrorDetail(loc=["body"], msg="the client left before its body ended", type="left")
    return error_response(CLIENT_CLOSED_REQUEST, [detail])


class BodySizeLimitMiddleware:
    """Answer ``413`` to a body over ``Settings.max_body_bytes``, ``415`` to one not JSON.

    Pure ASGI. A body declared as something other than JSON, sent without a Content-Type or
    with a Content-Encoding (gzip: nothing decodes it), is refused unread. A declared
    ``Content-Length`` over the limit is refused before reading; otherwise the body is read
    (counting the bytes as they stream in, so a chunked body cannot slip through) and handed
    on in one piece. A body that stops short of its length is
    answered ``408`` after ``Settings.body_read_seconds`` instead of holding the connection.
    """

    def __init__(self, app: ASGIApp) -> None:
        """Wrap ``app``."""
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Check the body size of an HTTP request, then pass it on."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        settings = get_settings()
        limit = settings.max_body_bytes
        headers = Headers(scope=scope)
        content_type = headers.get("content-type")
        if scope["method"] in ("POST", "PUT", "PATCH"):
            if content_type and not is_json(content_type):
                await _not_json(content_type)(scope, receive, send)
                return
            encoding = headers.get("content-encoding", "").strip()
            if encoding and encoding.lower() != "identity":
                await _encoded(encoding)(scope, receive, send)
                return
            if not content_type and _has_body(headers):
                await _no_content_type()(scope, receive, send)
                return
        declared = headers.get("content-length", "")
        if declared.isdigit() and int(declared) > limit:
            await _too_large(int(declared), limit)(scope, receive, send)
            return
        chunks: list[bytes] = []
        size = 0
        more_body = True
        with anyio.move_on_after(settings.body_read_seconds) as deadline:
            while more_body:
                message = await receive()
                if message["type"] != "http.request":  # the client went away
                    await _client_left(scope, size)(scope, receive, send)
                    return
                chunk: bytes = message.get("body", b"")
                size += len(chunk)
                if size > limit:
                    await _too_large(size, limit)(scope, receive, send)
                    return
                chunks.append(chunk)
                more_body = message.get("more_body", False)
        if deadline.cancelled_caught:
            await _too_slow(settings.body_read_seconds, size)(scope, receive, send)
            return
        body: Message | None = {
            "type": "http.request",
            "body": b"".join(chunks),
            "more_body": False,
        }

        async def replay() -> Message:
            nonlocal body
            if body is None:
                return await receive()
            message, body = body, None
            return message

        await self.app(scope, replay, send)
