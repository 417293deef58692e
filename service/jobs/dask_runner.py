"""Placement tasks on a Dask cluster (``DTF_DASK_SCHEDULER``), behind :mod:`solver.core.parallel`.

Dask's ``distributed`` is the standard engine for numpy work across machines; it is imported
only when a scheduler is set. The workers must have this package installed (README, "Jobs on a
Dask cluster"). Progress comes from completed tasks; a cancel cancels the futures.

A cluster that cannot run a job's tasks (its scheduler unreachable or lost during the job, no
worker when it starts or none left for ``CONNECT_SECONDS`` during it, a worker process dead under
a task) is :class:`ClusterUnavailable`: the job fails saying so (type
``unavailable``), and the next job connects again: a client that its scheduler's outage closed
for good (longer than its reconnect window) is made anew, where every later job failed with
``AttributeError: 'NoneType' object has no attribute 'ncores'`` until the service restarted (the
jobs audit of stop 56).
"""

from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeVar

import solver
from solver.core.parallel import tasks_of

T = TypeVar("T")
R = TypeVar("R")

CONNECT_SECONDS = 10.0
"""How long to wait for the scheduler, and for a worker on it, before a job fails (s)."""
POLL_SECONDS = 0.25
"""How often a job waiting for its tasks asks whether the cluster still has a worker (s)."""
LIVE = ("newly-created", "connecting", "running")
"""A ``distributed.Client``'s states in which it is, or will be, connected."""


CODE_PACKAGES = ("numpy", "scipy", "numba", "pin", "casadi")
"""The libraries whose versions a worker must share with the service (its numbers are theirs)."""


@functools.cache
def code_fingerprint() -> dict[str, str]:
    """What a placement's numbers depend on here: the solver's sources (a hash) and libraries."""
    digest = hashlib.sha256()
    root = Path(solver.__file__).parent
    for source in sorted(root.rglob("*.py")):
        digest.update(source.relative_to(root).as_posix().encode())
        digest.update(source.read_bytes())
    versions = {name: importlib.metadata.version(name) for name in CODE_PACKAGES}
    return {"solver sources": digest.hexdigest()[:12], **versions}


def worker_fingerprint() -> dict[str, str]:
    """:func:`code_fingerprint` as a worker computes it (sent by reference, run in its process)."""
    return code_fingerprint()


class ClusterUnavailable(RuntimeError):
    """The Dask cluster cannot run a job's tasks: its scheduler unreachable or lost, no worker."""


class DaskRunner:
    """Tasks as futures on the cluster of one scheduler; the client is made on first use."""

    threads = 1  # the cluster's threads run the tasks; the caller's own work stays in its thread

    def __init__(self, address: str, *, connect_seconds: float | None = None) -> None:
        """A runner on the scheduler at ``address`` (``tcp://host:8786``).

        ``connect_seconds``: how long to wait for the scheduler and a worker (default
        :data:`CONNECT_SECONDS`).
        """
        self.address = address
        self.connect_seconds = CONNECT_SECONDS if connect_seconds is None else connect_seconds
        self._client: Any = None
        self._checked: frozenset[str] = frozenset()  # worker processes whose code is the service's

    def _unavailable(self, what: str, error: BaseException | None = None) -> ClusterUnavailable:
        said = "" if error is None else f": {type(error).__name__}: {str(error)[:300]}"
        return ClusterUnavailable(
            f"the Dask cluster of {self.address} (DTF_DASK_SCHEDULER) {what}{said}; the job "
            "can be submitted again once the cluster runs"
        )

    def client(self) -> Any:
        """The connected client (``distributed.Client``), made on first use and after it closed.

        Raises:
            ClusterUnavailable: the scheduler cannot be reached within ``connect_seconds``.
        """
        if self._client is not None and self._client.status not in LIVE:
            self._client = None  # closed for good (an outage past its reconnect window)
        if self._client is None:
            from distributed import Client

            try:
                self._client = Client(  # type: ignore[no-untyped-call]
                    self.address, timeout=self.connect_seconds, set_as_default=False
                )
            except (OSError, TimeoutError) as error:
                raise self._unavailable("cannot be reached", error) from None
        return self._client

    def task_size(self, n_placements: int, chunk: int) -> int:
        """About eight tasks per cluster thread, each a fraction of a second at most.

        Progress and a cancel are seen as tasks complete, so no task may be long.

        Raises:
            ClusterUnavailable: the scheduler is unreachable, or no worker joins it within
                ``connect_seconds`` (the job's tasks would wait for one, its status running).
        """
        client = self.client()
        try:
            threads = sum(client.nthreads().values())
            if not threads:
                client.wait_for_workers(1, timeout=self.connect_seconds)
                threads = sum(client.nthreads().values())
        except TimeoutError:
            raise self._unavailable(f"has no worker after {self.connect_seconds:g} s") from None
        except (OSError, AttributeError) as error:  # a client closed meanwhile: None inside
            raise self._unavailable("was lost", error) from None
        return tasks_of(n_placements, chunk, per_worker=8, workers=threads or 1, cap=8 * chunk)

    def run(
        self, work: Callable[[T], R], tasks: Sequence[T], done: Callable[[int], None]
    ) -> list[R]:
        """The tasks as futures; completions reported as they arrive; cancelled on a raise.

        A task's own exception is raised as it is; the cluster's (the scheduler's connection
        lost, the client closed, no worker left for ``connect_seconds``, a worker process dead
        under a task: ``KilledWorker``) as :class:`ClusterUnavailable`.
        """
        from concurrent.futures import CancelledError

        from distributed import KilledWorker, as_completed
        from distributed.client import ClosedClientError

        client = self.client()
        lost = (OSError, CancelledError, ClosedClientError, AttributeError)
        try:
            self._same_code(client)
            futures = client.map(work, list(tasks), pure=False)
        except lost as error:
            raise self._unavailable("was lost", error) from None
        index = {future.key: i for i, future in enumerate(futures)}
        completed: Any = as_completed(futures, loop=client.loop)  # type: ignore[no-untyped-call]
        failed = None  # a task that raised
        alone_since: float | None = None  # when the cluster was last seen with no worker
        try:
            while failed is None and not completed.is_empty():
                finished = completed.next_batch(block=False)
                if not finished:  # none yet: wait a while, then ask whether a worker is left
                    with completed.thread_condition:  # a completion notifies it, under its lock
                        if not completed.has_ready():
                            completed.thread_condition.wait(timeout=POLL_SECONDS)
                    if not completed.has_ready():
                        alone_since = self._still_staffed(client, alone_since)
                    continue
                alone_since = None
                for future in finished:
                    if future.status == "error":
                        failed = future
                        break
                    if future.status == "cancelled":  # not the job's cancel: that raises in done
                        raise CancelledError(future.key)
                    done(index[future.key])
            if failed is None:
                results: list[R] = client.gather(futures)
                return results
        except lost as error:
            client_cancel(client, futures)
            raise self._unavailable("was lost", error) from None
        except BaseException:
            client_cancel(client, futures)
            raise
        try:
            if isinstance(failed.exception(), KilledWorker):
                raise self._unavailable(
                    "had a worker process die under one of the job's tasks (out of memory, say)",
                    failed.exception(),
                ) from None
            failed.result()  # the task's own exception, raised here as it is
        finally:
            client_cancel(client, futures)
        raise AssertionError("a task in error gave a result")  # not reached

    def _same_code(self, client: Any) -> None:
        """Refuse workers that compute with other code than the service's (checked once each).

        A worker left on an older release, or with another numpy, gives other numbers without a
        word: a map's cells would depend on which worker ran them. Each worker process is
        checked once (:func:`worker_processes`): one restarted at the same address, upgraded
        or not, is checked again.

        Raises:
            ClusterUnavailable: naming up to three such workers and what differs.
        """
        processes = worker_processes(client)
        unchecked = sorted(
            address for address, key in processes.items() if key not in self._checked
        )
        if not unchecked:
            return
        mine = code_fingerprint()
        try:
            theirs = client.run(worker_fingerprint, workers=unchecked)
        except Exception as error:  # noqa: BLE001 - a worker gone meanwhile, the scheduler lost
            if "worker_fingerprint" in str(error) or "dask_runner" in str(error):
                # The worker cannot load the check itself: its service.jobs.dask_runner is of a
                # release before the check (c09b554), or none. Submitting again fails the same.
                raise self._unavailable(
                    "has worker(s) whose code is not the service's: they cannot load its check "
                    "of which code they run (a release before it, or no service installed); "
                    "install the service's release on them",
                    error,
                ) from None
            asked = "could not be asked which code its workers run"
            raise self._unavailable(asked, error) from None
        differ = {
            address: [
                f"{key} {value} (here {mine.get(key)})"
                for key, value in sorted(worker.items())
                if mine.get(key) != value
            ]
            for address, worker in sorted(theirs.items())
        }
        wrong = [f"{address}: {', '.join(said)}" for address, said in differ.items() if said]
        if wrong:
            raise self._unavailable(
                f"has {len(wrong)} worker(s) whose code is not the service's, which would give "
                f"other numbers ({'; '.join(wrong[:3])}); install the service's release on them"
            )
        self._checked = self._checked | frozenset(processes.values())

    def _still_staffed(self, client: Any, alone_since: float | None) -> float | None:
        """None while the cluster has a worker; else since when it has had none.

        Raises:
            ClusterUnavailable: it has had none for ``connect_seconds`` (the job's tasks would
                wait for one, the job running, for ever).
        """
        if client.nthreads():
            return None
        now = time.monotonic()
        if alone_since is None:
            return now
        if now - alone_since >= self.connect_seconds:
            raise self._unavailable(f"has had no worker for {self.connect_seconds:g} s")
        return alone_since


def worker_processes(client: Any) -> dict[str, str]:
    """Each worker's address, and a key of its process.

    The scheduler names no process id; a worker's scratch directory (``local_directory``) is
    made anew, with a random name, each time a worker process starts, so the address with it
    tells a worker restarted at the same address (a fixed port) from the one checked before.
    """
    workers = client.scheduler_info(n_workers=-1)["workers"]
    return {
        address: f"{address} {info.get('local_directory', '')}" for address, info in workers.items()
    }


def client_cancel(client: Any, futures: list[Any]) -> None:
    """Cancel the futures on the cluster, if it can still be told."""
    try:
        client.cancel(futures)
    except Exception:  # noqa: BLE001 - the scheduler gone: nothing runs there to cancel
        return
