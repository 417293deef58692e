"""Solver work off the event loop, stopped when its client leaves or the service stops.

A route hands its work to :func:`run_stoppable`: the work runs in a worker thread with a
progress callback, while the request's task watches the connection. When the client
disconnects, or the request task is cancelled (uvicorn's graceful-shutdown timeout on SIGTERM),
the callback raises :class:`solver.core.progress.Cancelled` at the work's next report (after a chunk
of placements, a DE generation or an IPOPT iteration), so no thread keeps computing for nobody.
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Callable
from typing import TypeVar

import anyio
from fastapi import Request, Response
from pydantic import BaseModel

from service.operations.threads import lower_this_thread
from solver.core.progress import Cancelled, Progress

T = TypeVar("T")
WATCH_SECONDS = 0.1
"""How often the connection is looked at while work runs (s)."""
STOPPING = threading.Event()
"""Set when the service shuts down: every running work stops at its next report."""


def json_response(answer: BaseModel) -> Response:
    """The JSON answer, serialised here (in the worker thread), not on the event loop."""
    return Response(answer.model_dump_json(), media_type="application/json")


async def run_stoppable(request: Request, work: Callable[[Progress], T]) -> T:
    """Run ``work(progress)`` in a worker thread; stop it when the client goes away.

    Raises:
        Cancelled: the client left (answered 499, for the metrics) or the service is stopping
            (503).
    """
    stop = threading.Event()

    def progress(fraction: float) -> None:
        if stop.is_set() or STOPPING.is_set():
            raise Cancelled

    async def watch() -> None:
        while not stop.is_set():
            if await request.is_disconnected():
                stop.set()
            await asyncio.sleep(WATCH_SECONDS)

    def lowered() -> T:
        lower_this_thread()
        return work(progress)

    watcher = asyncio.create_task(watch())
    try:
        # Abandoned on cancellation (uvicorn's shutdown timeout): the finally below stops it.
        return await anyio.to_thread.run_sync(lowered, abandon_on_cancel=True)
    finally:
        stop.set()
        watcher.cancel()
