"""A stored job, and the two ways the job store refuses (``service.jobs.store``)."""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, TypeVar

from pydantic import TypeAdapter, ValidationError

from service.jobs.results import answered_now
from service.schemas import ErrorDetail

T = TypeVar("T")

Status = Literal["queued", "running", "done", "failed", "cancelled"]
Kind = Literal["map", "optimize", "evaluate"]
FINISHED = ("done", "failed", "cancelled")

STATE_COLUMNS = (
    "id, kind, status, error, done, total, cells, created, started, finished, attempts, cancel, "
    "first_at, first_done"
)
"""The columns of a job's state: everything but its request and its result (the large ones)."""


class JobStoreUnavailable(Exception):
    """The job store's file cannot be used: corrupt, replaced or deleted, or unreadable.

    Attributes:
        reason: what is wrong, naming the file (the 503's message).
    """

    def __init__(self, reason: str) -> None:
        """Keep the reason."""
        super().__init__(reason)
        self.reason = reason


class DamagedJob(JobStoreUnavailable):
    """One job's row holds what the service never writes (a file edited by hand, or damaged).

    A 503 for that job, as for a corrupt file; a job listing leaves the job out.

    Attributes:
        job_id: the job's id, as stored.
    """

    def __init__(self, store: Path, job_id: object, what: str) -> None:
        """Say which store, which job and what is wrong, and how to be rid of it."""
        super().__init__(
            f"the job store {str(store)!r} holds job {str(job_id)!r} damaged ({what}); "
            f"DELETE /v1/jobs/{job_id} removes it"
        )
        self.job_id = job_id


class QueueFull(Exception):
    """As many jobs as the limit are queued or running; no job was added."""

    def __init__(self, limit: int) -> None:
        """Keep the limit."""
        super().__init__(f"{limit} jobs are queued or running")
        self.limit = limit


@dataclass(frozen=True)
class JobState:
    """One job as stored, without its request and its result (what a job listing shows).

    Attributes:
        error: a 422-style detail list when failed.
        fraction: the fraction of its work done, 0..1.
        total: its units of work (a map's placements, else 100); None for a job stored by a
            release that did not keep it.
        cells: how many cells its result holds in pages (``JobStore.cells``); None when the
            result has no cells (not a map, not done, or stored whole by an older release).
        created, started, finished: Unix times (s); None until they happen.
        first_report: the time (Unix, s) and fraction of the run's first progress report over
            0 (the rate of progress after it excludes the run's set-up); None before it, and for
            a run by a release that did not keep it.
    """

    id: str
    kind: Kind
    status: Status
    error: list[dict[str, Any]] | None
    fraction: float
    total: int | None
    cells: int | None
    created: float
    started: float | None
    finished: float | None
    attempts: int
    cancel: bool
    first_report: tuple[float, float] | None


@dataclass(frozen=True)
class Job(JobState):
    """One job as stored, with its request and its result.

    Attributes:
        request: the route's body, as JSON.
        result: the route's JSON answer when done; a map's ``cells`` are in it only when the
            store was asked for them (``JobStore.get``'s ``inline_cells``).
    """

    request: dict[str, Any]
    result: dict[str, Any] | None


_STATE = TypeAdapter(JobState)
_JOB = TypeAdapter(Job)
_ERRORS = TypeAdapter(list[ErrorDetail])


def _state_fields(row: sqlite3.Row) -> dict[str, Any]:
    """A row's state, its error read (and checked to be a list of error details)."""
    error = None if row["error"] is None else json.loads(row["error"])
    if error is not None:
        _ERRORS.validate_python(error)
    return {
        "id": row["id"],
        "kind": row["kind"],
        "status": row["status"],
        "error": error,
        "fraction": row["done"],
        "total": row["total"],
        "cells": row["cells"],
        "created": row["created"],
        "started": row["started"],
        "finished": row["finished"],
        "attempts": row["attempts"],
        "cancel": row["cancel"],
        "first_report": None
        if row["first_at"] is None or row["first_done"] is None
        else (row["first_at"], row["first_done"]),
    }


def _checked(row: sqlite3.Row, store: Path, read: Callable[[], T]) -> T:
    """What ``read`` makes of a row, or DamagedJob when the row holds what is never written.

    A status or kind unknown, an error not a list of error details, a time or fraction not a
    number, a request or result not a JSON object.
    """
    try:
        return read()
    except (ValueError, TypeError) as error:  # ValidationError and JSONDecodeError included
        if isinstance(error, ValidationError):
            first = error.errors()[0]
            what = f"{'.'.join(map(str, first['loc']))}: {first['msg']}"
        else:
            what = f"{type(error).__name__}: {error}"
        raise DamagedJob(store, row["id"], what) from error


def state_of_row(row: sqlite3.Row, *, store: Path) -> JobState:
    """The state a row of the ``jobs`` table holds (its STATE_COLUMNS).

    Raises:
        DamagedJob: the row holds what the service never writes.
    """
    return _checked(row, store, lambda: _STATE.validate_python(_state_fields(row)))


def job_of_row(row: sqlite3.Row, *, store: Path) -> Job:
    """The job a whole row of the ``jobs`` table holds (a map's result without its cells).

    Raises:
        DamagedJob: the row holds what the service never writes.
    """

    def read() -> Job:
        request = json.loads(row["request"])
        result = None if row["result"] is None else answered_now(json.loads(row["result"]))
        return _JOB.validate_python({**_state_fields(row), "request": request, "result": result})

    return _checked(row, store, read)
