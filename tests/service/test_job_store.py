"""The job store on its own: opened lazily, a bad file refused with its reason, an atomic limit."""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import sqlite3
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.jobs.job import JobState, JobStoreUnavailable, QueueFull
from service.jobs.store import JobStore
from service.jobs.views import eta_seconds
from service.schemas import EvaluateResponse
from tests.cases import ROOT

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
EVALUATE = {k: EXAMPLE[k] for k in ("robot", "path", "placement")}


def test_importing_the_app_creates_no_store_and_starts_no_thread(tmp_path: Path) -> None:
    script = (
        "import threading, os, service.main\n"
        "print(sorted(t.name for t in threading.enumerate()))\n"
        "print(os.path.exists('var'))\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith("DTF_")}
    env["PYTHONPATH"] = str(ROOT)
    done = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    threads, var = done.stdout.splitlines()
    assert threads == "['MainThread']"
    assert var == "False" and list(tmp_path.iterdir()) == []


def test_a_store_opens_its_file_on_first_use(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "data" / "jobs.sqlite3")
    assert not (tmp_path / "data").exists()
    assert store.get("no-such-job") is None
    assert (tmp_path / "data" / "jobs.sqlite3").is_file()


@pytest.mark.parametrize(
    "content", [b"this is not a database" * 100, b"SQLite format 3\x00" + b"\xff" * 4000]
)
def test_a_corrupt_file_makes_the_store_unavailable_with_its_reason(
    tmp_path: Path, content: bytes
) -> None:
    path = tmp_path / "jobs.sqlite3"
    path.write_bytes(content)
    store = JobStore(path)
    for call in (
        lambda: store.get("x"),
        lambda: store.jobs(status=None, limit=10),
        lambda: store.create("evaluate", EVALUATE, limit=10),
        store.figures,
    ):
        with pytest.raises(JobStoreUnavailable) as raised:
            call()
        assert str(path) in raised.value.reason and "cannot be used" in raised.value.reason


def test_a_file_corrupted_while_in_use_makes_the_store_unavailable(tmp_path: Path) -> None:
    path = tmp_path / "jobs.sqlite3"
    store = JobStore(path)
    job = store.create("evaluate", EVALUATE)
    with path.open("r+b") as file:  # the same file (inode), its content overwritten
        file.write(b"garbage!" * 512)
    with pytest.raises(JobStoreUnavailable, match="cannot be used"):
        store.get(job.id)


def test_a_deleted_file_is_found_out_not_silently_made_again(tmp_path: Path) -> None:
    path = tmp_path / "jobs.sqlite3"
    store = JobStore(path)
    job = store.create("evaluate", EVALUATE)
    for file in tmp_path.iterdir():  # the database and its WAL files
        file.unlink()
    with pytest.raises(JobStoreUnavailable, match="was deleted while the service ran"):
        store.get(job.id)
    worker_store = JobStore(path, create=False)  # a worker process's
    with pytest.raises(JobStoreUnavailable, match="cannot be used"):
        worker_store.get(job.id)
    assert list(tmp_path.iterdir()) == []  # no new, empty store that loses the jobs quietly


def test_a_replaced_file_is_found_out(tmp_path: Path) -> None:
    path = tmp_path / "jobs.sqlite3"
    store = JobStore(path)
    store.create("evaluate", EVALUATE)
    other = JobStore(tmp_path / "other.sqlite3")
    other.create("map", EVALUATE)
    os.replace(tmp_path / "other.sqlite3", path)
    with pytest.raises(JobStoreUnavailable, match="was replaced by another file"):
        store.jobs(status=None, limit=10)


def test_the_queue_limit_holds_against_64_concurrent_submissions(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    store.get("open-it")  # the table made before the race
    outcomes: list[str] = []
    start = threading.Barrier(64)

    def submit() -> None:
        start.wait()
        try:
            store.create("evaluate", EVALUATE, limit=10)
        except QueueFull:
            outcomes.append("full")
        else:
            outcomes.append("queued")

    threads = [threading.Thread(target=submit) for _ in range(64)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert outcomes.count("queued") == 10 and outcomes.count("full") == 54
    assert len(store.jobs(status="queued", limit=100)) == 10


def test_a_deleted_job_is_gone_and_its_worker_is_told_to_stop(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id)
    assert store.delete(job.id) and store.get(job.id) is None
    assert not store.delete(job.id)
    assert store.progress(job.id, 0.5)  # a worker stops at its next report
    assert store.cancel_asked([job.id]) == {job.id}  # the supervisor stops one that does not


def stored_cells(path: Path) -> int:
    """Rows of result pages in the store's file, of any job."""
    with sqlite3.connect(path) as db:
        return int(db.execute("SELECT COUNT(*) FROM job_cells").fetchone()[0])


def test_a_job_deleted_while_it_runs_leaves_no_result_when_its_worker_finishes(
    tmp_path: Path,
) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("map", {"robot": EXAMPLE["robot"]})
    assert store.start(job.id)
    assert store.delete(job.id)
    cells = [{"x": 0.1 * i, "y": 0.4, "yaw": 0.0, "mu_path": 1.0, "reason": None} for i in range(5)]
    store.finish(job.id, "done", result={"cells": cells, "best": None, "worst": None})
    assert store.get(job.id) is None
    assert store.jobs(status=None, limit=10) == []
    assert stored_cells(store.path) == 0


def test_an_expired_job_goes_with_its_result_pages(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    kept, expired = (store.create("map", {"robot": EXAMPLE["robot"]}) for _ in range(2))
    cells = [{"x": 0.1, "y": 0.4, "yaw": 0.0, "mu_path": 1.0, "reason": None}]
    for job in (kept, expired):
        assert store.start(job.id)
        store.finish(job.id, "done", result={"cells": cells, "best": None, "worst": None})
    with sqlite3.connect(store.path) as db:
        db.execute("UPDATE jobs SET finished = finished - 100 WHERE id = ?", (expired.id,))
    assert store.expire(ttl=50.0) == 1
    assert store.get(expired.id) is None and store.cells(expired.id, offset=0, limit=9) == []
    assert store.cells(kept.id, offset=0, limit=9) == cells
    assert stored_cells(store.path) == 1


def test_an_expired_jobs_place_in_the_listing_is_kept_for_another_ttl(tmp_path: Path) -> None:
    """``after`` an expired job goes on after its place (audit 26, F4), until a TTL after."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    older, expired, newer = (store.create("evaluate", {"n": k}) for k in range(3))
    for job in (older, expired, newer):
        assert store.start(job.id)
        store.finish(job.id, "done", result={})
    with sqlite3.connect(store.path) as db:
        db.execute("UPDATE jobs SET finished = finished - 100 WHERE id = ?", (expired.id,))
        for k, job in enumerate((older, expired, newer)):  # submitted 1 s apart
            db.execute("UPDATE jobs SET created = created + ? WHERE id = ?", (k, job.id))
    assert store.expire(ttl=50.0) == 1 and store.state(expired.id) is None
    assert store.placed(expired.id)
    assert [j.id for j in store.jobs(status=None, limit=9, after=expired.id)] == [older.id]
    with sqlite3.connect(store.path) as db:  # forgotten over a TTL ago
        db.execute("UPDATE job_places SET forgotten = forgotten - 100")
    assert store.expire(ttl=50.0) == 0
    assert not store.placed(expired.id)
    assert store.jobs(status=None, limit=9, after=expired.id) == []


def test_a_store_that_takes_no_place_still_deletes_and_expires_its_jobs(tmp_path: Path) -> None:
    """On a full disk deleting a job frees room: it must not fail for want of room for the
    job's place in the listing (kept after the delete, if the store takes it)."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    deleted, expired = (store.create("evaluate", {"n": k}) for k in range(2))
    assert store.start(expired.id)
    store.finish(expired.id, "done", result={})
    with sqlite3.connect(store.path) as db:  # every place refused, as a full disk would
        db.execute(
            "CREATE TRIGGER full BEFORE INSERT ON job_places "
            "BEGIN SELECT RAISE(FAIL, 'database or disk is full'); END"
        )
        db.execute("UPDATE jobs SET finished = finished - 100 WHERE id = ?", (expired.id,))
    assert store.delete(deleted.id) and store.state(deleted.id) is None
    assert store.expire(ttl=50.0) == 1 and store.state(expired.id) is None
    assert not store.placed(deleted.id) and not store.placed(expired.id)


def test_a_restart_says_which_jobs_it_queued_again_and_which_failed(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """After a restart only a job's second 'running' line told it had been interrupted (stop
    61's soak audit): each interrupted job is said, queued again or failed on its runs."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    again, spent, waiting = (store.create("evaluate", EVALUATE) for _ in range(3))
    assert store.start(spent.id)
    for _ in range(2):  # spent's third run is interrupted too
        store.recover(attempts=9)
        assert store.start(spent.id)
    assert store.start(again.id)  # its first run
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        queued = store.recover(attempts=3)
    assert queued == [again.id, waiting.id]
    assert caplog.messages == [
        f"job {again.id} interrupted (its service stopped): queued again (run 2 of at most 3)",
        f"job {spent.id} interrupted (its service stopped) after 3 runs: failed",
    ]


def test_a_run_a_restart_failed_is_counted_without_the_downtime(tmp_path: Path) -> None:
    """The totals counted a failed job's finished - started, the restart's time: an outage of
    a weekend added two days to dtf_job_seconds (the upgrade audit of stop 62). The run is
    counted, with no seconds; a job that ran to its end keeps its own."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    done, cut = (store.create("evaluate", EVALUATE) for _ in range(2))
    assert store.start(done.id) and store.start(cut.id)
    store.finish(done.id, "done", result={"mu_path": 0.3})
    with sqlite3.connect(store.path) as db:  # the service was down for 1,000 s after cut started
        db.execute("UPDATE jobs SET started = started - 1000 WHERE id = ?", (cut.id,))
        started, finished = db.execute(
            "SELECT started, finished FROM jobs WHERE id = ?", (done.id,)
        ).fetchone()
    assert store.recover(attempts=1) == []
    state = store.state(cut.id)
    assert state is not None and state.status == "failed"
    assert store.figures()[1] == (2, pytest.approx(finished - started, abs=1e-6))


def test_a_cancel_asked_before_a_restart_ends_the_job_cancelled(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Audit 26's F5: a running job cancelled, the service stopped before its worker ended it:
    queued again after the restart it never ran (no cancelled job is handed out) and never
    ended, holding a place in the queue. Cancelled now, its downtime not counted."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    asked, other = (store.create("evaluate", EVALUATE) for _ in range(2))
    assert store.start(asked.id) and store.start(other.id)
    store.cancel(asked.id)
    with sqlite3.connect(store.path) as db:  # the service was down for 1,000 s
        db.execute("UPDATE jobs SET started = started - 1000")
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        assert store.recover(attempts=3) == [other.id]
    state = store.state(asked.id)
    assert state is not None and state.status == "cancelled" and state.finished is not None
    assert store.queued(exclude=set(), limit=9) == [other.id]
    assert f"job {asked.id}, cancelled before its service stopped: cancelled" in caplog.messages
    assert store.figures()[1] == (1, 0.0)


def test_a_cancelled_job_whose_worker_dies_is_cancelled_not_failed(tmp_path: Path) -> None:
    """Audit 26's F11: a cancel asked, then the worker killed before it ended the job: the job
    was failed, "in each of the job's 3 runs", after one run. Its user asked it to stop."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    asked, dead = (store.create("evaluate", EVALUATE) for _ in range(2))
    error = [{"loc": [], "msg": "the worker process ended", "type": "interrupted"}]
    for job in (asked, dead):
        assert store.start(job.id)
    store.cancel(asked.id)
    assert store.retry(asked.id, attempts=3, error=error) == "cancelled"
    state = store.state(asked.id)
    assert state is not None and state.status == "cancelled" and state.error is None
    assert store.retry(dead.id, attempts=3, error=error) == "queued"  # its first run of three
    assert store.start(dead.id)
    assert store.retry(dead.id, attempts=2, error=error) == "failed"
    failed = store.state(dead.id)
    assert failed is not None and failed.status == "failed" and failed.error == error


def test_a_job_queued_again_after_a_restart_starts_its_progress_again(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id)
    assert not store.progress(job.id, 0.4)
    assert store.recover(attempts=3) == [job.id]  # the service was killed while it ran
    queued = store.state(job.id)
    assert queued is not None and queued.status == "queued"
    assert queued.fraction == 0.0 and queued.started is None
    assert store.start(job.id)
    running = store.state(job.id)
    assert running is not None and running.fraction == 0.0 and running.started is not None


def test_a_job_whose_cancel_came_before_its_end_is_cancelled_not_done(tmp_path: Path) -> None:
    """A map's answer stored from its columns may end before the next progress report would
    have seen the cancel: the job is then cancelled, its answer not kept (api.md: cancel stops
    the job, kept as cancelled); one that ended before the cancel stays done."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    asked, late = (store.create("evaluate", {"n": k}) for k in range(2))
    for job in (asked, late):
        assert store.start(job.id)
    store.cancel(asked.id)
    store.finish(asked.id, "done", result={"mu_path": 0.3})
    store.finish(late.id, "done", result={"mu_path": 0.3})
    store.cancel(late.id)
    cancelled, done = store.get(asked.id), store.get(late.id)
    assert cancelled is not None and cancelled.status == "cancelled" and cancelled.result is None
    assert done is not None and done.status == "done" and done.result == {"mu_path": 0.3}


def _running(fraction: float, first_report: tuple[float, float] | None) -> JobState:
    return JobState(
        id="j", kind="map", status="running", error=None, fraction=fraction, total=100,
        cells=None, created=0.0, started=0.0, finished=None, attempts=1, cancel=False,
        first_report=first_report,
    )  # fmt: skip


def test_the_eta_is_taken_at_the_rate_after_the_set_up() -> None:
    # A run that sets up for 8 s, then does 5 % a second: 10 % at 10 s (its first report), 60 %
    # at 20 s; it ends at 28 s. From the start, 20 s for 60 % said 13.3 s left.
    assert eta_seconds(_running(0.6, (10.0, 0.1)), now=20.0) == pytest.approx(8.0, abs=1e-12)
    # one report only: no rate yet, no ETA (from the start: 90 s, 14x too high in the audit's
    # job); a row of an older release, without a first report, from the start
    assert eta_seconds(_running(0.1, (10.0, 0.1)), now=10.5) is None
    assert eta_seconds(_running(0.5, None), now=20.0) == pytest.approx(20.0, abs=1e-12)
    assert eta_seconds(_running(0.0, None), now=20.0) is None
    queued = dataclasses.replace(_running(0.0, None), status="queued", started=None)
    assert eta_seconds(queued, now=20.0) is None


def test_a_runs_first_report_is_kept_and_a_new_run_forgets_it(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id)
    store.progress(job.id, 0.0)
    assert (state := store.state(job.id)) is not None and state.first_report is None
    before = time.time()
    store.progress(job.id, 0.25)
    store.progress(job.id, 0.5)
    state = store.state(job.id)
    assert state is not None and state.first_report is not None and state.fraction == 0.5
    at, done = state.first_report
    assert done == 0.25 and before <= at <= time.time()
    assert store.recover(attempts=3) == [job.id] and store.start(job.id)
    assert (state := store.state(job.id)) is not None and state.first_report is None


def test_a_store_of_an_older_release_gets_the_new_columns(tmp_path: Path) -> None:
    path = tmp_path / "jobs.sqlite3"
    with sqlite3.connect(path) as db:  # the jobs table before total, cells and first reports
        db.execute(
            "CREATE TABLE jobs (id TEXT PRIMARY KEY, kind TEXT NOT NULL, status TEXT NOT NULL, "
            "request TEXT NOT NULL, result TEXT, error TEXT, done REAL NOT NULL DEFAULT 0, "
            "created REAL NOT NULL, started REAL, finished REAL, "
            "attempts INTEGER NOT NULL DEFAULT 0, cancel INTEGER NOT NULL DEFAULT 0)"
        )
        db.execute(
            "INSERT INTO jobs (id, kind, status, request, done, created, started, attempts) "
            "VALUES ('old', 'evaluate', 'running', '{}', 0.5, 1.0, 2.0, 1)"
        )
    state = JobStore(path).state("old")
    assert state is not None and (state.total, state.cells, state.first_report) == (None,) * 3
    assert eta_seconds(state, now=12.0) == pytest.approx(10.0, abs=1e-12)


def test_the_jobs_that_ran_are_counted_once_each_and_never_less(tmp_path: Path) -> None:
    """/metrics' dtf_job_seconds was read from the jobs held: its count fell from 748 to 0 when
    they were deleted or expired (a counter reset to Prometheus), and each scrape read every
    finished job's times (the soak audit of stop 61). Done, failed by restarts, cancelled while
    running: each counted once with its seconds (a run a restart failed with none: how long it
    ran is not known), whatever the update that ended it; deleting and expiring them changes
    nothing; a job cancelled before it ran is not counted."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    done, spent, stopped, waiting = (store.create("evaluate", EVALUATE) for _ in range(4))
    for job in (done, spent, stopped):
        assert store.start(job.id)
    store.finish(done.id, "done", result={"mu_path": 0.3})
    store.recover(attempts=1)  # spent and stopped were running: failed on their one run
    assert store.start(waiting.id)
    store.cancel(waiting.id)  # asked while running: the worker ends it cancelled
    store.finish(waiting.id, "done", result={"mu_path": 0.3}, if_running=True)
    store.cancel(store.create("evaluate", EVALUATE).id)  # never ran: not counted
    with sqlite3.connect(store.path) as db:
        expected = db.execute(
            "SELECT COUNT(*), SUM(CASE status WHEN 'failed' THEN 0 ELSE finished - started END) "
            "FROM jobs WHERE started IS NOT NULL AND status IN ('done', 'failed', 'cancelled')"
        ).fetchone()
    counts, totals, _ = store.figures()
    assert counts == {"done": 1, "failed": 2, "cancelled": 2}
    assert totals == (4, pytest.approx(expected[1], rel=1e-12, abs=1e-12)) and expected[0] == 4
    for job in (done, spent):
        assert store.delete(job.id)
    assert store.expire(ttl=-1.0) == 3  # every finished job left
    assert store.figures()[:2] == ({}, totals)


def test_the_jobs_that_ended_are_counted_by_status_and_never_less(tmp_path: Path) -> None:
    """The jobs held by status fall as jobs are deleted or expire: an alert on failed jobs could
    not tell a failure from an expiry (operator audit, L3). Each end counted once by its status,
    whichever update ended the job, a job cancelled before it ran too; read against the jobs
    table itself before they go, and unchanged after."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    done, spent, stopped, waiting, never = (store.create("evaluate", EVALUATE) for _ in range(5))
    for job in (done, spent, stopped):
        assert store.start(job.id)
    store.finish(done.id, "done", result={"mu_path": 0.3})
    store.cancel(stopped.id)  # asked while running, then a restart: cancelled by recover
    store.recover(attempts=1)  # spent was running: failed on its one run
    assert store.start(waiting.id)
    store.finish(waiting.id, "failed", error=[{"loc": [], "msg": "m", "type": "t"}])
    store.cancel(never.id)  # never ran: ended all the same
    store.create("evaluate", EVALUATE)  # still queued: not ended
    with sqlite3.connect(store.path) as db:
        held = dict(
            db.execute(
                "SELECT status, COUNT(*) FROM jobs WHERE finished IS NOT NULL GROUP BY status"
            ).fetchall()
        )
    assert held == {"done": 1, "failed": 2, "cancelled": 2}
    assert store.figures()[2] == held
    for job in (done, spent):
        assert store.delete(job.id)
    assert store.expire(ttl=-1.0) == 3
    assert store.figures()[2] == held
    assert JobStore(store.path).figures()[2] == held  # opened again: not counted twice


def test_a_store_of_an_older_release_counts_its_ended_jobs_once(tmp_path: Path) -> None:
    path = tmp_path / "jobs.sqlite3"
    store = JobStore(path)
    for status in ("done", "cancelled"):
        job = store.create("evaluate", EVALUATE)
        assert store.start(job.id)
        store.finish(job.id, status, result={"mu_path": 0.3})
    with sqlite3.connect(path) as db:
        db.execute("DROP TRIGGER job_ended_as")
        db.execute("DROP TABLE job_ended")
    assert JobStore(path).figures()[2] == {"done": 1, "failed": 0, "cancelled": 1}
    assert JobStore(path).figures()[2] == {"done": 1, "failed": 0, "cancelled": 1}


def test_a_store_of_an_older_release_counts_the_jobs_it_holds(tmp_path: Path) -> None:
    """A store made before the totals gets them from its finished jobs when it is opened."""
    path = tmp_path / "jobs.sqlite3"
    store = JobStore(path)
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id)
    store.finish(job.id, "done", result={"mu_path": 0.3})
    with sqlite3.connect(path) as db:
        db.execute("DROP TRIGGER job_ran_to_its_end")
        db.execute("DROP TABLE job_totals")
        started, finished = db.execute("SELECT started, finished FROM jobs").fetchone()
    assert JobStore(path).figures()[:2] == ({"done": 1}, (1, pytest.approx(finished - started)))


def test_deleted_and_expired_jobs_give_their_space_back_to_the_disk(tmp_path: Path) -> None:
    """748 jobs deleted left the store's file at 564 MB (the soak audit of stop 61): the pages a
    map's result took go back to the disk when it is deleted, and when it expires."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    cells = [
        {"x": 0.001 * i, "y": 0.4, "yaw": 0.0, "mu_path": 1.0, "reason": None}
        for i in range(20_000)
    ]

    def size() -> int:
        with sqlite3.connect(store.path) as db:
            db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        return store.path.stat().st_size

    assert store.jobs(status=None, limit=1) == []  # the store made, empty
    empty = size()
    for ends in ("deleted", "expired"):
        job = store.create("map", {"robot": EXAMPLE["robot"]})
        assert store.start(job.id)
        store.finish(job.id, "done", result={"cells": cells, "best": None, "worst": None})
        assert size() > empty + 1_000_000  # about 1.4 MB of pages
        if ends == "deleted":
            assert store.delete(job.id)
        else:
            assert store.expire(ttl=-1.0) == 1
        assert size() < empty + 100_000, ends


def test_the_file_keeps_wal_and_incremental_vacuum_set_once_by_its_maker(tmp_path: Path) -> None:
    """Both are set when the web process's store makes the file, and kept in it (read back by
    SQLite here): a worker's store, which never makes the file, and every later connection find
    them set, so no connection sets them again (auto_vacuum took 0.9 ms a connection)."""
    path = tmp_path / "jobs.sqlite3"
    JobStore(path).jobs(status=None, limit=1)  # the file made
    worker = JobStore(path, create=False)
    job = worker.create("evaluate", {"robot": EXAMPLE["robot"]})
    assert worker.start(job.id) and not worker.progress(job.id, 0.5)  # a worker's connections
    with sqlite3.connect(path) as db:
        assert db.execute("PRAGMA journal_mode").fetchone() == ("wal",)
        assert db.execute("PRAGMA auto_vacuum").fetchone() == (2,)  # INCREMENTAL


@pytest.mark.parametrize(
    ("path", "note"),
    [
        ({"cl_data": (ROOT / "examples" / "cam" / "sweep_mm.cl").read_text()}, "earlier release"),
        ({"csv": "0,0,0,0,0,1\n10,0,0,0,0,1\n20,0,1,0,0,1\n", "units": "mm"}, "a CSV has no end"),
    ],
    ids=["cl_data", "csv"],
)
def test_results_stored_by_an_older_release_get_the_fields_answers_now_have(
    tmp_path: Path, client: TestClient, path: dict[str, Any], note: str
) -> None:
    """An evaluation of a CAM program stored by a release before its reading said how the
    program ends (``path_read`` without ``ended`` and ``end_note``, which the current schema
    requires: a store kept across an upgrade, or written by the old release in a rollback) is
    answered with both: the end not checked (null), every other value as it was stored."""
    body = {**EVALUATE, "path": path, "placement": {"x": 0.3, "y": 0.3, "z": 0.0, "yaw": 0.0}}
    answer = client.post("/v1/evaluate", json=body)
    assert answer.status_code == 200, answer.text
    old = answer.json()
    for field in ("ended", "end_note"):  # as a release before stop 62 wrote it
        del old["path_read"][field]
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", body)
    assert store.start(job.id)
    store.finish(job.id, "done", result=old)
    stored = JobStore(tmp_path / "jobs.sqlite3").get(job.id)
    assert stored is not None and stored.result is not None
    EvaluateResponse.model_validate(stored.result)  # what the current schema requires is there
    read = stored.result["path_read"]
    assert read["ended"] is None and note in read["end_note"]
    del read["ended"], read["end_note"]
    assert stored.result == old


def test_a_store_made_without_incremental_vacuum_is_said_once_with_the_command(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A store of a release before 2026-12-06 keeps its size after deletes: the start says so
    and names the command; a store of this release says nothing."""
    old = tmp_path / "old.sqlite3"
    with sqlite3.connect(old) as db:  # as an older release made it: WAL, no auto_vacuum
        db.execute("PRAGMA journal_mode=WAL")
        db.execute("CREATE TABLE kept (x)")
    with caplog.at_level(logging.WARNING, logger="dtf.jobs"):
        JobStore(old).jobs(status=None, limit=1)
        JobStore(tmp_path / "new.sqlite3").jobs(status=None, limit=1)
    said = [r.getMessage() for r in caplog.records if r.name == "dtf.jobs"]
    assert said == [
        f"the job store {old} was made by a release before 2026-12-06: deleted and expired "
        "jobs' pages are reused but not given back to the disk; to give them back once, stop "
        f"the service and run: sqlite3 {old} 'PRAGMA auto_vacuum=INCREMENTAL; VACUUM' (README, "
        "Upgrading)"
    ]
    with sqlite3.connect(old) as db:
        assert db.execute("PRAGMA auto_vacuum").fetchone() == (0,)
