"""A job's result in the store: a map's cells in pages of their own, the rest as one text.

A 500,000-placement map's result is about 108 MiB of JSON. Kept as one text, every read of the
job parsed all of it: a job listing read and dropped every result, and ``GET /v1/jobs/{id}``
answered all of it at once. Here the cells are kept in rows of PAGE_CELLS, so that the job
without its cells, its number of cells and any page of them are read without the rest.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from pydantic_core import from_json

from service.convert.path_read import NO_END_RECORD

PAGE_CELLS = 1000
"""Cells in one stored row (about 220 KB of JSON)."""

SCHEMA = """
CREATE TABLE IF NOT EXISTS jobs (
    id TEXT PRIMARY KEY,
    kind TEXT NOT NULL,
    status TEXT NOT NULL,
    request TEXT NOT NULL,
    result TEXT,
    error TEXT,
    done REAL NOT NULL DEFAULT 0,
    created REAL NOT NULL,
    started REAL,
    finished REAL,
    attempts INTEGER NOT NULL DEFAULT 0,
    cancel INTEGER NOT NULL DEFAULT 0,
    total INTEGER,
    cells INTEGER,
    first_at REAL,
    first_done REAL,
    owner TEXT
);
CREATE INDEX IF NOT EXISTS jobs_created ON jobs (created);
CREATE INDEX IF NOT EXISTS jobs_finished ON jobs (finished);
CREATE TABLE IF NOT EXISTS job_cells (
    job_id TEXT NOT NULL,
    page INTEGER NOT NULL,
    cells TEXT NOT NULL,
    PRIMARY KEY (job_id, page)
);
CREATE TABLE IF NOT EXISTS job_places (
    id TEXT PRIMARY KEY,
    created REAL NOT NULL,
    forgotten REAL NOT NULL
);
CREATE INDEX IF NOT EXISTS job_places_forgotten ON job_places (forgotten);
CREATE TABLE IF NOT EXISTS job_totals (
    one INTEGER PRIMARY KEY CHECK (one = 1),
    finished INTEGER NOT NULL,
    seconds REAL NOT NULL
);
INSERT OR IGNORE INTO job_totals
    SELECT 1, COUNT(*), COALESCE(SUM(finished - started), 0.0) FROM jobs
    WHERE finished IS NOT NULL AND started IS NOT NULL;
CREATE TRIGGER IF NOT EXISTS job_ran_to_its_end AFTER UPDATE OF finished ON jobs
    WHEN OLD.finished IS NULL AND NEW.finished IS NOT NULL AND NEW.started IS NOT NULL
BEGIN
    UPDATE job_totals SET finished = finished + 1, seconds = seconds + NEW.finished - NEW.started;
END;
CREATE TABLE IF NOT EXISTS job_ended (
    status TEXT PRIMARY KEY,
    count INTEGER NOT NULL
);
INSERT OR IGNORE INTO job_ended
    SELECT ended.status, (SELECT COUNT(*) FROM jobs WHERE jobs.status = ended.status
                          AND finished IS NOT NULL)
    FROM (SELECT 'done' AS status UNION ALL SELECT 'failed' UNION ALL SELECT 'cancelled') AS ended;
CREATE TRIGGER IF NOT EXISTS job_ended_as AFTER UPDATE OF finished ON jobs
    WHEN OLD.finished IS NULL AND NEW.finished IS NOT NULL
BEGIN
    UPDATE job_ended SET count = count + 1 WHERE status = NEW.status;
END;
"""
"""The jobs, their result pages, the places of forgotten jobs in the listing, and the totals of
the jobs that ran to an end (``/metrics``).

A job deleted or expired leaves its id and submission time (``job_places``) for another TTL, so
that a listing read in pages goes on after it (``GET /v1/jobs?after=<id>``) when another client
deleted the last job of the page before.

The totals only grow: a trigger adds each job as it finishes after running (done, failed,
cancelled), whichever update finishes it; a deleted or expired job stays counted. A store
made by an older release gets them from its finished jobs, once. ``job_ended`` counts the jobs
that ended by how they ended (a job cancelled before it ran too), the same way: its three rows
are made once, from the jobs the store holds then.
"""

_ADDED_COLUMNS = {
    "total": "INTEGER",
    "cells": "INTEGER",
    "first_at": "REAL",
    "first_done": "REAL",
    "owner": "TEXT",  # the service running the job (service.jobs.owner)
}
"""Columns a store made by an older release lacks (added on open; NULL in its rows)."""


UNCHECKED_END = "read by an earlier release, which did not check how a program ends"
"""``end_note`` of a CL program's reading stored before the end was checked (``ended`` null)."""


def make_tables(db: sqlite3.Connection) -> None:
    """The tables, and the columns an older store lacks."""
    db.executescript(SCHEMA)
    present = {row[1] for row in db.execute("PRAGMA table_info(jobs)")}
    for name, kind in _ADDED_COLUMNS.items():
        if name not in present:
            db.execute(f"ALTER TABLE jobs ADD COLUMN {name} {kind}")


def answered_now(result: Any) -> Any:
    """A stored answer with the fields the answers' schemas require now, where it lacks them.

    A finished job's answer is kept as its route gave it. One computed from a CAM program by a
    release before stop 62 (in a store kept across an upgrade, or written by an older release
    during a rollback or a rolling upgrade) has a ``path_read`` without ``ended`` and
    ``end_note``, which a client generated from the current spec refuses: they are added as
    read, ``ended`` null (not checked) with a note saying so. The stored text is not changed.
    """
    read = result.get("path_read") if isinstance(result, dict) else None
    if isinstance(read, dict) and "ended" not in read:
        note = NO_END_RECORD["csv"] if read.get("form") == "csv" else UNCHECKED_END
        result["path_read"] = {**read, "ended": None, "end_note": note}
    return result


@dataclass(frozen=True)
class CellPages:
    """A map's answer for the store, its cells already JSON text a page at a time.

    A map job wrote a validated model a cell, dumped it to dicts and those to JSON: for 400,000
    cells 3.2, 1.6 and 1.9 s after its last progress report (the jobs audit of stop 56), and
    4.8 GB at 2 million cells. Its cells now come as the map route writes them, from the
    map's columns (:func:`service.convert.map_json.cell_pages`), a page at a time as the store
    takes them.

    Attributes:
        rest: the answer but its cells, as JSON values.
        pages: PAGE_CELLS cells a page (the last fewer), each page its cells' JSON objects
            joined by commas, in the answer's order; read once.
        count: how many cells.
    """

    rest: dict[str, Any]
    pages: Iterable[str]
    count: int


Result = dict[str, Any] | CellPages
"""A job's answer as its work gives it to the store."""


def write_result(db: sqlite3.Connection, job_id: str, result: Result) -> tuple[str, int | None]:
    """Keep a result's ``cells`` in pages (replacing any of an earlier run).

    Returns:
        The rest of the result as JSON text, and the number of cells (None without cells).
    """
    db.execute("DELETE FROM job_cells WHERE job_id = ?", (job_id,))
    if isinstance(result, CellPages):
        db.executemany(
            "INSERT INTO job_cells (job_id, page, cells) VALUES (?, ?, ?)",
            ((job_id, k, "[" + text + "]") for k, text in enumerate(result.pages)),
        )
        return json.dumps(result.rest), result.count
    cells = result.get("cells")
    if not isinstance(cells, list):
        return json.dumps(result), None
    db.executemany(
        "INSERT INTO job_cells (job_id, page, cells) VALUES (?, ?, ?)",
        (
            (job_id, start // PAGE_CELLS, json.dumps(cells[start : start + PAGE_CELLS]))
            for start in range(0, len(cells), PAGE_CELLS)
        ),
    )
    return json.dumps({k: v for k, v in result.items() if k != "cells"}), len(cells)


def parsed_cells(text: str) -> list[dict[str, Any]]:
    """A stored row's cells, parsed.

    By pydantic-core's parser: twice as fast as ``json.loads`` on them (1.2 ms a page of 1,000
    map cells against 2.4), the same floats.
    """
    cells: list[dict[str, Any]] = from_json(text)
    return cells


def read_cells(
    db: sqlite3.Connection, job_id: str, *, offset: int, limit: int
) -> list[dict[str, Any]]:
    """Cells ``offset`` to ``offset + limit`` (end exclusive) of a job's result, in order."""
    if limit <= 0:
        return []
    first, last = offset // PAGE_CELLS, (offset + limit - 1) // PAGE_CELLS
    texts = page_texts(db, job_id, first=first, last=last)
    cells = [cell for text in texts for cell in parsed_cells(text)]
    start = offset - first * PAGE_CELLS
    return cells[start : start + limit]


def page_texts(db: sqlite3.Connection, job_id: str, *, first: int, last: int) -> list[str]:
    """Stored pages ``first`` to ``last`` (inclusive) of a job's cells, each its JSON text."""
    rows = db.execute(
        "SELECT cells FROM job_cells WHERE job_id = ? AND page BETWEEN ? AND ? ORDER BY page",
        (job_id, first, last),
    ).fetchall()
    return [row[0] for row in rows]


def cells_text(
    db: sqlite3.Connection, job_id: str, *, offset: int, limit: int, total: int
) -> tuple[str, int]:
    """Cells ``offset`` to ``offset + limit`` of a result of ``total`` cells, as a JSON array.

    Stored rows the page takes whole are copied as text, unparsed; only a row the page cuts
    is parsed (at most two). A page of 10,000 cells is then about 2 MB copied, not parsed
    and written again.

    Returns:
        The JSON array's text and how many cells it holds.
    """
    end = min(offset + limit, total)
    if end <= offset:
        return "[]", 0
    rows = db.execute(
        "SELECT page, cells FROM job_cells WHERE job_id = ? AND page BETWEEN ? AND ? ORDER BY page",
        (job_id, offset // PAGE_CELLS, (end - 1) // PAGE_CELLS),
    ).fetchall()
    parts = []
    for page, text in rows:
        first = page * PAGE_CELLS
        low, high = max(offset - first, 0), min(end - first, PAGE_CELLS)
        if low == 0 and high == min(PAGE_CELLS, total - first):
            parts.append(text[1:-1])  # the whole row: its items, without the brackets
        else:
            parts.append(json.dumps(parsed_cells(text)[low:high])[1:-1])
    return "[" + ", ".join(parts) + "]", end - offset


def with_cells(result: dict[str, Any], cells: list[dict[str, Any]]) -> dict[str, Any]:
    """The result with its cells put back first, where the map route answers them."""
    return {"cells": cells, **result}
