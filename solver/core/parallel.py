"""Who runs the placement engine's tasks: in turn, on a thread pool, or on a cluster.

:func:`solver.path.placements.evaluate_placements` cuts its placements into tasks of consecutive
rows and hands them to a :class:`TaskRunner`. A runner returns the results in task order, so
every runner gives the same answer; it only decides where and how many at once. A runner calls
``done(i)`` as task ``i`` completes; when ``done`` raises (a progress callback raising
:class:`solver.core.progress.Cancelled`), the runner drops the tasks not yet started and re-raises.

The service adds a runner on a Dask cluster (``service/jobs/dask_runner.py``) behind the same
protocol; the solver never imports Dask.
"""

from __future__ import annotations

import itertools
import math
import queue
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Protocol, TypeVar

__all__ = ["SERIAL", "SerialRunner", "TaskRunner", "ThreadRunner"]

T = TypeVar("T")
R = TypeVar("R")


class TaskRunner(Protocol):
    """Runs independent tasks and returns their results in order.

    Attributes:
        threads: how many threads of this process the caller's own work may use beside its
            tasks (1: none beside the calling thread; a cluster's runner says 1).
    """

    threads: int

    def task_size(self, n_placements: int, chunk: int) -> int:
        """Placements per task for a run of ``n_placements`` (a multiple of ``chunk``)."""
        ...

    def run(
        self, work: Callable[[T], R], tasks: Sequence[T], done: Callable[[int], None]
    ) -> list[R]:
        """``[work(t) for t in tasks]``, calling ``done(i)`` as task ``i`` completes.

        Raises:
            Whatever ``done`` raises, after the tasks not yet started are dropped.
        """
        ...


def tasks_of(n_placements: int, chunk: int, *, per_worker: int, workers: int, cap: int) -> int:
    """A task size giving each worker about ``per_worker`` tasks, in whole chunks, at most cap."""
    size = math.ceil(n_placements / max(1, per_worker * workers))
    return max(chunk, min(cap, math.ceil(size / chunk) * chunk))


class SerialRunner:
    """One task after the other in the calling thread, a chunk per task (the reference)."""

    threads = 1

    def task_size(self, n_placements: int, chunk: int) -> int:
        """One chunk per task, so progress is reported per chunk."""
        return chunk

    def run(
        self, work: Callable[[T], R], tasks: Sequence[T], done: Callable[[int], None]
    ) -> list[R]:
        """The tasks in turn."""
        results = []
        for i, task in enumerate(tasks):
            results.append(work(task))
            done(i)
        return results


SERIAL = SerialRunner()
"""The default runner."""


class ThreadRunner:
    """Tasks on the calling thread and a few more (numpy and the compiled kernels release the GIL).

    The helper threads are made at the first run and kept for the next (a pool made and shut
    down per run cost about 0.2 ms, 2 % of the ERK-size map through HTTP); runs at the same time
    share them.

    Args:
        threads: threads at most, >= 1.
        initializer: called in each helper thread as it starts (the service lowers the
            thread's priority below its event loop's:
            :func:`service.operations.threads.lower_this_thread`).
    """

    def __init__(self, threads: int, *, initializer: Callable[[], None] | None = None) -> None:
        """A runner on ``threads`` threads, the caller's included (helpers made at first use)."""
        if threads < 1:
            raise ValueError(f"{threads=} must be >= 1")
        self.threads = threads
        self._initializer = initializer
        self._pool: ThreadPoolExecutor | None = None
        self._pool_made = threading.Lock()

    def _helpers(self) -> ThreadPoolExecutor:
        """The helper threads' pool, made once."""
        with self._pool_made:
            if self._pool is None:
                self._pool = ThreadPoolExecutor(
                    self.threads - 1, thread_name_prefix="dtf-task", initializer=self._initializer
                )
            return self._pool

    def task_size(self, n_placements: int, chunk: int) -> int:
        """About four tasks per thread, so the threads finish together; each short.

        Progress (and a cancel) is seen as tasks complete, so no task may be long.
        """
        return tasks_of(n_placements, chunk, per_worker=4, workers=self.threads, cap=4 * chunk)

    def run(
        self, work: Callable[[T], R], tasks: Sequence[T], done: Callable[[int], None]
    ) -> list[R]:
        """The tasks on the calling thread and ``threads - 1`` more; completions reported here.

        Every thread takes the next task not yet taken, so the threads finish together. The
        calling thread computes too (a hand-over to a thread costs tens of microseconds) and
        calls ``done`` for every task, its own as they end and the others' between its own; once
        it raises, no task starts, and the run returns once no helper computes for it.
        """
        if self.threads == 1 or len(tasks) <= 1:
            return SERIAL.run(work, tasks, done)
        results: list[R | None] = [None] * len(tasks)
        taken = itertools.count()  # next() on a count is atomic (one C call under the GIL)
        finished: queue.SimpleQueue[tuple[int, BaseException | None]] = queue.SimpleQueue()
        stop = threading.Event()

        def take() -> int | None:
            i = next(taken)
            return i if i < len(tasks) and not stop.is_set() else None

        def helper() -> None:
            while (i := take()) is not None:
                try:
                    results[i] = work(tasks[i])
                except BaseException as error:  # raised in the calling thread
                    finished.put((i, error))
                    return
                finished.put((i, None))

        def report(i: int, error: BaseException | None) -> None:
            if error is not None:
                raise error
            done(i)

        reported = 0
        pool = self._helpers()
        helping = [pool.submit(helper) for _ in range(min(self.threads, len(tasks)) - 1)]
        try:
            while (i := take()) is not None:
                results[i] = work(tasks[i])
                report(i, None)
                reported += 1
                while not finished.empty():
                    report(*finished.get())
                    reported += 1
            while reported < len(tasks):
                report(*finished.get())
                reported += 1
        except BaseException:
            stop.set()  # the helpers end their running task and take no other
            raise
        finally:
            for future in helping:  # a helper not yet started (another run's) never will
                if not future.cancel():
                    future.result()  # the others end with their task: none runs on after
        return results  # type: ignore[return-value]  # every task ran (else raised above)
