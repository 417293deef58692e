"""Worker threads run below the event loop (Linux), so /healthz keeps its time slices."""

from __future__ import annotations

import os
import sys
import threading

import pytest

from service.operations.threads import WORK_NICENESS, lower_this_thread, thread_runner

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux thread nice")


def _nice() -> int:
    return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


def test_a_worker_thread_is_lowered_once_and_its_threads_inherit_it() -> None:
    seen: dict[str, int] = {}

    def child() -> None:
        seen["child"] = _nice()
        lower_this_thread()  # a thread a lowered thread started is not lowered again
        seen["child lowered"] = _nice()

    def worker() -> None:
        seen["before"] = _nice()
        lower_this_thread()
        lower_this_thread()  # a pool thread runs many works: it is lowered only the first time
        seen["after"] = _nice()
        started = threading.Thread(target=child)
        started.start()
        started.join()

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join()
    assert seen["after"] == min(seen["before"] + WORK_NICENESS, 19)
    assert seen["child"] == seen["child lowered"] == seen["after"]
    assert _nice() == seen["before"]  # the calling thread (the event loop's stand-in) is not


def test_the_routes_runner_lowers_its_helpers_whoever_runs_it_first() -> None:
    """thread_runner's helpers run below the event loop, once, as the routes' worker threads."""
    runner = thread_runner(2)
    seen: dict[str, int] = {}
    caller = threading.current_thread()
    barrier = threading.Barrier(2, timeout=5)

    def work(task: int) -> int:
        if threading.current_thread() is not caller:
            seen["helper"] = _nice()
        if task < 2:
            barrier.wait()  # the helper holds one of the first two tasks
        return task

    base = _nice()
    assert runner.run(work, [0, 1, 2], lambda i: None) == [0, 1, 2]  # from the unlowered thread
    assert seen["helper"] == min(base + WORK_NICENESS, 19)
    assert _nice() == base
    assert thread_runner(2) is runner  # one runner a thread count, its helpers kept
