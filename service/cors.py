"""Cross-origin requests (CORS) from the web origins ``DTF_CORS_ORIGINS`` names; none by default.

A browser page served elsewhere (a CAM tool's web front end, say) may call the API only where
the answers say its origin may (the Fetch standard's CORS protocol). Starlette's
``CORSMiddleware`` speaks it; this wrapper hands it only the requests from a named origin, and
reads the setting at each request (a test, or a settings reload, changes it without a new app).
A request from any other origin (or without one) goes on untouched: no CORS headers, so the
browser keeps the answer from the page; a preflight from one is answered as any ``OPTIONS``
request is (``405``, the service's JSON error), not with Starlette's plain-text ``400``.

Allowed for a named origin: every method and request header (the routes refuse what they do not
take, with their own errors); the answers' ``Location`` (a job's ``202``) and ``Retry-After``
(``429``, ``503``) are exposed to the page. No credentials: the service has no users.
"""

from __future__ import annotations

from starlette.datastructures import Headers
from starlette.middleware.cors import CORSMiddleware
from starlette.types import ASGIApp, Receive, Scope, Send

from service.config import get_settings

EXPOSED = ("Location", "Retry-After")
"""The answer headers a page may read: where a job is, and when to ask again."""
PREFLIGHT_SECONDS = 600
"""How long a browser may keep a preflight's answer (s)."""


class CorsMiddleware:
    """CORS for the origins of ``Settings.cors_origins``; every other request untouched."""

    def __init__(self, app: ASGIApp) -> None:
        """Wrap ``app``."""
        self.app = app
        self._cors: dict[tuple[str, ...], CORSMiddleware] = {}

    def _for(self, origins: tuple[str, ...]) -> CORSMiddleware:
        """Starlette's middleware for these origins, made once."""
        if origins not in self._cors:
            self._cors[origins] = CORSMiddleware(
                self.app,
                allow_origins=origins,
                allow_methods=["*"],
                allow_headers=["*"],
                expose_headers=EXPOSED,
                max_age=PREFLIGHT_SECONDS,
            )
        return self._cors[origins]

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Hand a request from a named origin to the CORS middleware; pass the rest on."""
        if scope["type"] == "http":
            origins = get_settings().cors_origins
            origin = Headers(scope=scope).get("origin")
            if origins and origin is not None and ("*" in origins or origin in origins):
                await self._for(origins)(scope, receive, send)
                return
        await self.app(scope, receive, send)
