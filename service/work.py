"""Solver work off the event loop, stopped when its client leaves or the service stops.

A route hands its work to :func:`run_stoppable`: the work runs in a worker thread with a
progress callback, while the request's task watches the connection. When the client
disconnects, or the request task is cancelled (uvicorn's graceful-shutdown timeout on SIGTERM),
the callback raises :class:`solver.core.progress.Cancelled` at the work's next report (after a chunk
of placements, a DE generation or an IPOPT iteration), so no thread keeps computing for nobody.
"""

from __future__ import annotations

import asyncio
import os
import sys
import threading
from collections.abc import Callable
from typing import TypeVar

import anyio
from fastapi import Request, Response
from pydantic import BaseModel

from solver.core.progress import Cancelled, Progress

T = TypeVar("T")
WATCH_SECONDS = 0.1
"""How often the connection is looked at while work runs (s)."""
STOPPING = threading.Event()
"""Set when the service shuts down: every running work stops at its next report."""
WORK_NICENESS = 10
"""How much lower than the event loop a worker thread runs (Linux nice steps)."""


def lower_this_thread() -> None:
    """Run the calling thread WORK_NICENESS below the process; threads it starts inherit it.

    On a machine whose cores are all busy with solver work, the event loop otherwise waits
    for a time slice like any worker, and /healthz takes tens of milliseconds. Linux only: a
    thread's nice value is its own; elsewhere nothing changes. A thread already that low (one
    started by a lowered thread) is left as it is.
    """
    if getattr(_lowered, "done", False) or not sys.platform.startswith("linux"):
        return
    thread = threading.get_native_id()
    lowered = min(_PROCESS_NICENESS + WORK_NICENESS, 19)
    if os.getpriority(os.PRIO_PROCESS, thread) < lowered:
        os.setpriority(os.PRIO_PROCESS, thread, lowered)
    _lowered.done = True


_lowered = threading.local()
_PROCESS_NICENESS = os.getpriority(os.PRIO_PROCESS, 0) if sys.platform.startswith("linux") else 0
"""The nice value of the thread that imports this module (the process's main thread)."""


def json_response(answer: BaseModel) -> Response:
    """The JSON answer, serialised here (in the worker thread), not on the event loop."""
    return Response(answer.model_dump_json(), media_type="application/json")


async def run_stoppable(request: Request, work: Callable[[Progress], T]) -> T:
    """Run ``work(progress)`` in a worker thread; stop it when the client goes away.

    Raises:
        Cancelled: the client left or the service is stopping (answered 503 if anyone listens).
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
