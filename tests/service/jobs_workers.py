"""Worker lives for the job runner's tests (imported by spawned worker processes)."""

from __future__ import annotations

import time
from multiprocessing.connection import Connection
from pathlib import Path

from service.jobs.store import JobStore


def stuck(connection: Connection, store_path: str, settings_json: str) -> None:
    """A worker whose jobs never end and never look for a cancel (a solver step that hangs)."""
    store = JobStore(Path(store_path))
    job_id = connection.recv()
    store.start(job_id)
    while True:
        time.sleep(1)
