"""A stored job, and the two ways the job store refuses (``service.jobs.store``)."""

from __future__ import annotations

import json
import sqlite3
from dataclasses import dataclass
from typing import Any, Literal

Status = Literal["queued", "running", "done", "failed", "cancelled"]
Kind = Literal["map", "optimize", "evaluate"]
FINISHED = ("done", "failed", "cancelled")

STATE_COLUMNS = (
    "id, kind, status, error, done, total, cells, created, started, finished, attempts, cancel"
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


def _state_fields(row: sqlite3.Row) -> dict[str, Any]:
    return {
        "id": row["id"],
        "kind": row["kind"],
        "status": row["status"],
        "error": None if row["error"] is None else json.loads(row["error"]),
        "fraction": float(row["done"]),
        "total": row["total"],
        "cells": row["cells"],
        "created": row["created"],
        "started": row["started"],
        "finished": row["finished"],
        "attempts": row["attempts"],
        "cancel": bool(row["cancel"]),
    }


def state_of_row(row: sqlite3.Row) -> JobState:
    """The state a row of the ``jobs`` table holds (its STATE_COLUMNS)."""
    return JobState(**_state_fields(row))


def job_of_row(row: sqlite3.Row, result: dict[str, Any] | None) -> Job:
    """The job a whole row of the ``jobs`` table holds, with its result as read."""
    return Job(**_state_fields(row), request=json.loads(row["request"]), result=result)
