"""The synchronous routes' thread runner: one per DTF_THREADS value, its helper threads kept.

A :class:`solver.core.parallel.ThreadRunner` makes its helper threads at its first run and keeps
them, so the routes share one rather than making one a request. Its helpers run below the event
loop, as the routes' worker threads do (:func:`service.work.lower_this_thread`).
"""

from __future__ import annotations

import functools

from service.work import lower_this_thread
from solver.core.parallel import ThreadRunner


@functools.cache
def thread_runner(threads: int) -> ThreadRunner:
    """The runner of ``threads`` threads (DTF_THREADS), made once."""
    return ThreadRunner(threads, initializer=lower_this_thread)
