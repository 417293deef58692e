"""The web page at ``/``: the colour map, the best placement and the joint speeds (issue 14).

Plain HTML, CSS and JavaScript under ``static/``, no library and no build step; the page calls
only this service's API (jobs for maps, /v1/evaluate, /v1/optimize), so nothing is fetched from
the internet. The example paths under ``static/examples/`` are copies of ``examples/``.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles
from starlette.responses import Response
from starlette.types import Scope

STATIC = Path(__file__).parent / "static"
REVALIDATE = {"Cache-Control": "no-cache"}
"""The page's files are asked for again each load (an unchanged one answers 304 by its ETag):
with no header a browser kept a heuristically fresh old script beside a new release's
index.html (the upgrade audit of stop 62: 6 of the page's 9 files changed in a week)."""


class _Revalidated(StaticFiles):
    """StaticFiles whose answers say :data:`REVALIDATE`."""

    async def get_response(self, path: str, scope: Scope) -> Response:
        response = await super().get_response(path, scope)
        response.headers.update(REVALIDATE)
        return response


def mount_page(app: FastAPI) -> None:
    """Serve the page at ``/`` and its files under ``/ui/`` (both outside the API's spec)."""
    app.mount("/ui", _Revalidated(directory=STATIC), name="ui")

    @app.get("/", include_in_schema=False)
    async def page() -> FileResponse:
        return FileResponse(STATIC / "index.html", media_type="text/html", headers=REVALIDATE)

    @app.get("/favicon.ico", include_in_schema=False)
    async def favicon() -> FileResponse:
        """The page's icon, for the browsers and bookmarks that ask for it at the root."""
        return FileResponse(STATIC / "favicon.svg", media_type="image/svg+xml")
