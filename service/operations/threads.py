"""The synchronous routes' threads: run below the event loop, one runner per DTF_THREADS value.

A :class:`solver.core.parallel.ThreadRunner` makes its helper threads at its first run and keeps
them, so the routes share one rather than making one a request. Its helpers run below the event
loop, as the routes' worker threads do (:func:`lower_this_thread`, which
:func:`service.work.run_stoppable` calls in each).
"""

from __future__ import annotations

import functools
import os
import sys
import threading

from solver.core.parallel import ThreadRunner

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


@functools.cache
def thread_runner(threads: int) -> ThreadRunner:
    """The runner of ``threads`` threads (DTF_THREADS), made once."""
    return ThreadRunner(threads, initializer=lower_this_thread)
