"""A stored job, and the two ways the job store refuses (``service.jobs.store``)."""

from __future__ import annotations

import json
import sqlite3
from dataclasses import dataclass
from typing import Any, Literal

Status = Literal["queued", "running", "done", "failed", "cancelled"]
Kind = Literal["map", "optimize", "evaluate"]
FINISHED = ("done", "failed", "cancelled")


class JobStoreUnavailable(Exception):
    """The job store's file cannot be used: corrupt, replaced or deleted, or unreadable.

    Attributes:
        reason: what is wrong, naming the file (the 503's message).
    """

    def __init__(self, reason: str) -> None:
        """Keep the reason."""
        super().__init__(reason)
        self.reason = reason


class QueueFull(Exception):
    """As many jobs as the limit are queued or running; no job was added."""

    def __init__(self, limit: int) -> None:
        """Keep the limit."""
        super().__init__(f"{limit} jobs are queued or running")
        self.limit = limit


@dataclass(frozen=True)
class Job:
    """One job as stored.

    Attributes:
        fraction: the fraction of its work done, 0..1.
        created, started, finished: Unix times (s); None until they happen.
        result: the route's JSON answer when done; error: a 422-style detail list when failed.
    """

    id: str
    kind: Kind
    status: Status
    request: dict[str, Any]
    result: dict[str, Any] | None
    error: list[dict[str, Any]] | None
    fraction: float
    created: float
    started: float | None
    finished: float | None
    attempts: int
    cancel: bool


def job_of_row(row: sqlite3.Row) -> Job:
    """The job a row of the ``jobs`` table holds."""
    return Job(
        id=row["id"],
        kind=row["kind"],
        status=row["status"],
        request=json.loads(row["request"]),
        result=None if row["result"] is None else json.loads(row["result"]),
        error=None if row["error"] is None else json.loads(row["error"]),
        fraction=float(row["done"]),
        created=row["created"],
        started=row["started"],
        finished=row["finished"],
        attempts=row["attempts"],
        cancel=bool(row["cancel"]),
    )
