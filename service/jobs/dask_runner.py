"""Placement tasks on a Dask cluster (``DTF_DASK_SCHEDULER``), behind :mod:`solver.core.parallel`.

Dask's ``distributed`` is the standard engine for numpy work across machines; it is imported
only when a scheduler is set. The workers must have this package installed (README, "Jobs on a
Dask cluster"). Progress comes from completed tasks; a cancel cancels the futures.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from solver.core.parallel import tasks_of

T = TypeVar("T")
R = TypeVar("R")

CONNECT_SECONDS = 10.0
"""How long to wait for the scheduler before a job fails (s)."""


class DaskRunner:
    """Tasks as futures on the cluster of one scheduler; the client is made on first use."""

    threads = 1  # the cluster's threads run the tasks; the caller's own work stays in its thread

    def __init__(self, address: str) -> None:
        """A runner on the scheduler at ``address`` (``tcp://host:8786``)."""
        self.address = address
        self._client: Any = None

    def client(self) -> Any:
        """The connected client (``distributed.Client``), made on first use."""
        if self._client is None:
            from distributed import Client

            try:
                self._client = Client(  # type: ignore[no-untyped-call]
                    self.address, timeout=CONNECT_SECONDS, set_as_default=False
                )
            except (OSError, TimeoutError) as error:
                raise RuntimeError(
                    f"cannot reach the Dask scheduler {self.address} (DTF_DASK_SCHEDULER): {error}"
                ) from None
        return self._client

    def task_size(self, n_placements: int, chunk: int) -> int:
        """About eight tasks per cluster thread, each a fraction of a second at most.

        Progress and a cancel are seen as tasks complete, so no task may be long.
        """
        threads = sum(self.client().nthreads().values()) or 1
        return tasks_of(n_placements, chunk, per_worker=8, workers=threads, cap=8 * chunk)

    def run(
        self, work: Callable[[T], R], tasks: Sequence[T], done: Callable[[int], None]
    ) -> list[R]:
        """The tasks as futures; completions reported as they arrive; cancelled on a raise."""
        from distributed import as_completed

        client = self.client()
        futures = client.map(work, list(tasks), pure=False)
        index = {future.key: i for i, future in enumerate(futures)}
        try:
            for future in as_completed(futures, loop=client.loop):  # type: ignore[no-untyped-call]
                if future.status == "error":
                    future.result()  # the task's exception, raised here
                done(index[future.key])
        except BaseException:
            client.cancel(futures)
            raise
        results: list[R] = client.gather(futures)
        return results
