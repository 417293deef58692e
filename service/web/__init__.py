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

STATIC = Path(__file__).parent / "static"


def mount_page(app: FastAPI) -> None:
    """Serve the page at ``/`` and its files under ``/ui/`` (both outside the API's spec)."""
    app.mount("/ui", StaticFiles(directory=STATIC), name="ui")

    @app.get("/", include_in_schema=False)
    async def page() -> FileResponse:
        return FileResponse(STATIC / "index.html", media_type="text/html")

    @app.get("/favicon.ico", include_in_schema=False)
    async def favicon() -> FileResponse:
        """The page's icon, for the browsers and bookmarks that ask for it at the root."""
        return FileResponse(STATIC / "favicon.svg", media_type="image/svg+xml")
