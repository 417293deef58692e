"""Worker lives for the job runner's tests (imported by spawned worker processes)."""

from __future__ import annotations

import time
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from service.jobs.job import JobStoreUnavailable, Status
from service.jobs.store import JobStore
from service.jobs.worker import serve


def stuck(connection: Connection, store_path: str, settings_json: str, owner: str) -> None:
    """A worker whose jobs never end and never look for a cancel (a solver step that hangs)."""
    store = JobStore(Path(store_path))
    job_id = connection.recv()
    store.start(job_id, owner)
    while True:
        time.sleep(1)


FULL = "the job store '{}' cannot be used: database or disk is full"


def full_for_results(
    connection: Connection, store_path: str, settings_json: str, owner: str
) -> None:
    """``serve`` on a store that cannot take a job's result (a full disk), but its failure."""
    finish = JobStore.finish

    def no_result(self: JobStore, job_id: str, status: Status, **ends: Any) -> bool:
        if status == "done":
            raise JobStoreUnavailable(FULL.format(store_path))
        return finish(self, job_id, status, **ends)

    JobStore.finish = no_result  # type: ignore[method-assign]
    serve(connection, store_path, settings_json, owner)


def full_for_ends(connection: Connection, store_path: str, settings_json: str, owner: str) -> None:
    """``serve`` on a store that takes no job's end at all (a full disk, a failure too)."""

    def no_end(self: JobStore, job_id: str, status: Status, **ends: Any) -> bool:
        raise JobStoreUnavailable(FULL.format(store_path))

    JobStore.finish = no_end  # type: ignore[method-assign]
    serve(connection, store_path, settings_json, owner)
