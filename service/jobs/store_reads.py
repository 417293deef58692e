"""What the job store reads: a job, its state, a listing, its request and its result's cells.

Reads never change the file. A map's cells are read a page at a time
(:mod:`service.jobs.results`), so that a job listing reads no result and a page of cells reads
only that page. The changes (submit, run, finish, cancel, expire) are
:class:`service.jobs.store.JobStore`'s.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Generator
from typing import Any

from service.jobs.job import (
    STATE_COLUMNS,
    DamagedJob,
    Job,
    JobState,
    job_of_row,
    state_of_row,
)
from service.jobs.results import (
    PAGE_CELLS,
    cells_text,
    page_texts,
    parsed_cells,
    read_cells,
    with_cells,
)
from service.jobs.store_file import StoreFile
from service.logs import log

READ_PAGES = 50
"""Stored pages of cells read in one query by :meth:`JobReads.cell_pages` (about 11 MB)."""
_PLACE = (
    "SELECT created, id FROM jobs WHERE id = ? "
    "UNION ALL SELECT created, id FROM job_places WHERE id = ? LIMIT 1"
)
"""A job's place in the listing (created, id), held or forgotten within a TTL (the id twice)."""


class JobReads(StoreFile):
    """The queries of the job store's SQLite file (:class:`StoreFile`): what the routes read."""

    def get(self, job_id: str, *, inline_cells: int | None = None) -> Job | None:
        """The job with its request and result, or None for an unknown id.

        Args:
            job_id: the job's id.
            inline_cells: a result's cells are put in it when there are at most this many
                (``Job.cells`` says how many there are); None: always.
        """
        with self._connection() as db:
            row = db.execute("SELECT * FROM jobs WHERE id = ?", (job_id,)).fetchone()
            if row is None:
                return None
            job = job_of_row(row, store=self.path)
            count = job.cells
            if job.result is not None and count is not None:
                if inline_cells is None or count <= inline_cells:
                    cells = read_cells(db, job_id, offset=0, limit=count)
                    job = dataclasses.replace(job, result=with_cells(job.result, cells))
        return job

    def placed(self, job_id: str) -> bool:
        """Whether the listing has a place for this id: a job held, or forgotten within a TTL."""
        with self._connection() as db:
            return db.execute(_PLACE, (job_id, job_id)).fetchone() is not None

    def state(self, job_id: str) -> JobState | None:
        """The job without its request and result, or None for an unknown id."""
        with self._connection() as db:
            row = db.execute(f"SELECT {STATE_COLUMNS} FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else state_of_row(row, store=self.path)

    def jobs(
        self, *, status: str | None, limit: int, after: str | None = None, kind: str | None = None
    ) -> list[JobState]:
        """The newest jobs first, optionally of one status and kind, without requests and results.

        Jobs submitted in the same instant are in the order of their ids, so the order is total.

        Args:
            status: only the jobs of this status (None: all).
            kind: only the jobs of this kind (None: all).
            limit: at most this many.
            after: the listing goes on after this job's place in it (the last id of a page),
                a deleted or expired job's too while its place is kept (:meth:`placed`); an id
                of neither gives no jobs.
        """
        conditions, args = [], []
        if status is not None:
            conditions, args = ["status = ?"], [status]
        if kind is not None:
            conditions.append("kind = ?")
            args.append(kind)
        if after is not None:
            conditions.append(f"(created, id) < ({_PLACE})")
            args += [after, after]
        where = f" WHERE {' AND '.join(conditions)}" if conditions else ""
        query = f"SELECT {STATE_COLUMNS} FROM jobs{where} ORDER BY created DESC, id DESC LIMIT ?"
        with self._connection() as db:
            rows = db.execute(query, [*args, limit]).fetchall()
        states = []
        for row in rows:
            try:
                states.append(state_of_row(row, store=self.path))
            except DamagedJob as error:  # the others are still listed
                log.warning("job listing: %s; left out", error.reason)
        return states

    def request(self, job_id: str) -> dict[str, Any] | None:
        """The job's request (the route's body), or None for an unknown id."""
        with self._connection() as db:
            row = db.execute("SELECT request FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else dict(json.loads(row[0]))

    def cells(self, job_id: str, *, offset: int, limit: int) -> list[dict[str, Any]]:
        """Cells ``offset`` to ``offset + limit`` of a done job's result (fewer at its end).

        A result stored whole by an older release (``Job.cells`` None) is read whole.
        """
        with self._connection() as db:
            row = db.execute("SELECT result, cells FROM jobs WHERE id = ?", (job_id,)).fetchone()
            if row is None or row["result"] is None:
                return []
            if row["cells"] is not None:
                return read_cells(db, job_id, offset=offset, limit=limit)
        cells = json.loads(row["result"]).get("cells", [])
        return list(cells[offset : offset + limit])

    def cell_pages(self, job_id: str) -> Generator[list[dict[str, Any]], None, None]:
        """Every cell of a done job's result, a stored page (PAGE_CELLS) at a time, in order.

        Read on one connection in one transaction (a 2-million-cell map has 2,000 pages): one
        snapshot of the file, so a job deleted (or expired) meanwhile is read whole, or not at
        all (no page: the job is gone), never in part. Each page is parsed as it is taken:
        parsed ahead, fifty pages' cells alive at once made Python's garbage collector twice
        the parsing's time. A result stored whole by an older release is one page.
        """
        with self._connection() as db:
            db.execute("BEGIN")  # deferred: the snapshot is taken at the first read below
            row = db.execute("SELECT result, cells FROM jobs WHERE id = ?", (job_id,)).fetchone()
            if row is None or row["result"] is None:
                return
            if row["cells"] is None:  # stored whole by an older release
                yield list(json.loads(row["result"]).get("cells", []))
                return
            pages = -(-row["cells"] // PAGE_CELLS)
            for first in range(0, pages, READ_PAGES):
                texts = page_texts(db, job_id, first=first, last=first + READ_PAGES - 1)
                yield from (parsed_cells(text) for text in texts)

    def cells_json(self, job_id: str, *, offset: int, limit: int) -> tuple[str, int]:
        """:meth:`cells` as a JSON array's text, and how many cells it holds.

        Whole stored pages are copied unparsed (:func:`service.jobs.results.cells_text`).
        """
        state = self.state(job_id)
        if state is None or state.cells is None:
            cells = self.cells(job_id, offset=offset, limit=limit)
            return json.dumps(cells), len(cells)
        with self._connection() as db:
            return cells_text(db, job_id, offset=offset, limit=limit, total=state.cells)

    def cell_count(self, job_id: str) -> int:
        """How many cells a done job's result has (0 without cells or result)."""
        state = self.state(job_id)
        if state is not None and state.cells is not None:
            return state.cells
        return len(self.cells(job_id, offset=0, limit=2**62))  # stored whole by an older release
