"""Worker threads run below the event loop (Linux), so /healthz keeps its time slices."""

from __future__ import annotations

import os
import sys
import threading

import pytest

from service.work import WORK_NICENESS, lower_this_thread

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux thread nice")


def _nice() -> int:
    return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


def test_a_worker_thread_is_lowered_once_and_its_threads_inherit_it() -> None:
    seen: dict[str, int] = {}

    def child() -> None:
        seen["child"] = _nice()

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
    assert seen["child"] == seen["after"]
    assert _nice() == seen["before"]  # the calling thread (the event loop's stand-in) is not
