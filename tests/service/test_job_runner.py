"""The job runner without HTTP: failures end as ``failed``, a stuck or dead worker is replaced."""

from __future__ import annotations

import json
import logging
import os
import re
import sqlite3
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from service.config import Settings
from service.jobs import worker
from service.jobs.job import Job, JobStoreUnavailable
from service.jobs.runner import IDLE_POLL_SECONDS, KILL_AFTER, POLL_SECONDS, JobRunner
from service.jobs.store import JobStore
from service.logs import log
from tests.cases import ROOT
from tests.service.jobs_workers import full_for_ends, full_for_results, stuck

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
EVALUATE = {k: EXAMPLE[k] for k in ("robot", "path", "placement")}
BIG_MAP = {  # 40,000 placements: far longer than the test
    "robot": EXAMPLE["robot"],
    "path": EXAMPLE["path"],
    "grid": {
        "x": {"min": -0.5, "max": 0.5, "step": 0.005},
        "y": {"min": 0.0, "max": 1.0, "step": 0.005},
        "z": 0.1,
        "yaw": 0.0,
    },
}


def settings(tmp_path: Path, **values: Any) -> Settings:
    limits = {"max_job_cells": 10**6, "max_job_poses": 10**9}
    return Settings(data_dir=tmp_path, workers=1, **limits, **values)


def wait_for(store: JobStore, job_id: str, done: Callable[[Job], bool]) -> Job:
    deadline = time.monotonic() + 30
    while True:
        job = store.get(job_id)
        assert job is not None
        if done(job) or time.monotonic() > deadline:
            return job
        time.sleep(0.02)


@pytest.fixture
def runner(tmp_path: Path) -> Iterator[JobRunner]:
    runner = JobRunner(settings(tmp_path))
    yield runner
    runner.close()


def test_an_unexpected_exception_fails_the_job_with_its_message(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(*args: object) -> dict[str, Any]:
        raise ZeroDivisionError("a bug")

    monkeypatch.setitem(worker.KINDS, "evaluate", broken)
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    worker.run_job(store, job.id, settings(tmp_path))
    failed = store.get(job.id)
    assert failed is not None and failed.status == "failed"
    assert failed.error == [
        {"loc": [], "msg": "internal error: ZeroDivisionError: a bug", "type": "internal"}
    ]


def test_a_job_whose_result_the_store_cannot_take_ends_failed_saying_why(tmp_path: Path) -> None:
    """On a full disk a job's result was not written and the job stayed running forever: polled
    so, its cancel ignored, its queue place held (the operator audit, H1). Its failure, a small
    write, is stored instead, naming the store's reason; the next job runs."""
    runner = JobRunner(settings(tmp_path), worker=full_for_results)
    try:
        job = runner.store.create("evaluate", EVALUATE)
        runner.wake()
        ended = wait_for(runner.store, job.id, lambda j: j.status not in ("queued", "running"))
        assert ended.status == "failed" and ended.error is not None, ended.status
        assert ended.error[0]["type"] == worker.UNSTORED
        assert "could not be written to the job store" in ended.error[0]["msg"]
        assert "database or disk is full" in ended.error[0]["msg"]
        assert ended.result is None
        second = runner.store.create("evaluate", EVALUATE)
        runner.wake()
        assert wait_for(runner.store, second.id, lambda j: j.status == "failed").status == "failed"
    finally:
        runner.close()


def test_a_job_whose_end_the_store_cannot_take_at_all_is_run_again_then_failed(
    tmp_path: Path,
) -> None:
    """Where the worker's store takes not even the failure, the supervisor queues the job again
    (as a dead worker's) and fails it after DTF_JOB_ATTEMPTS runs, saying why."""
    runner = JobRunner(settings(tmp_path, job_attempts=2), worker=full_for_ends)
    try:
        job = runner.store.create("evaluate", EVALUATE)
        runner.wake()
        ended = wait_for(runner.store, job.id, lambda j: j.status not in ("queued", "running"))
        assert ended.status == "failed" and ended.error is not None, ended.status
        assert ended.attempts == 2
        assert ended.error[0]["type"] == worker.UNSTORED
        assert "in each of the job's 2 runs (DTF_JOB_ATTEMPTS)" in ended.error[0]["msg"]
    finally:
        runner.close()


def test_a_job_the_store_failed_before_it_ran_is_not_said_failed(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """The worker's answer to a failing store logged "failed" for a job the store had not even
    started (it stays queued and runs later): a false ERROR line."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        assert worker.fail_unstored(store, job.id, JobStoreUnavailable("the store is full"))
    state = store.state(job.id)
    assert state is not None and state.status == "queued"
    said = [(r.levelname, r.getMessage()) for r in caplog.records if r.name == "dtf.jobs"]
    assert said == [("WARNING", f"job {job.id} not run: the store is full")]


def test_a_shutdown_says_which_running_jobs_it_stops(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A shutdown killed a running job's worker without a line (the operator audit, L2)."""
    runner = JobRunner(settings(tmp_path, job_attempts=3), worker=stuck)
    job = runner.store.create("evaluate", EVALUATE)
    runner.wake()
    try:
        assert wait_for(runner.store, job.id, lambda j: j.status == "running").status == "running"
    finally:
        with caplog.at_level(logging.INFO, logger="dtf.jobs"):
            runner.close()
    said = [r.getMessage() for r in caplog.records if "stopped by the shutdown" in r.getMessage()]
    assert said == [
        f"job {job.id} stopped by the shutdown: it runs again at the next start (a run of its "
        "DTF_JOB_ATTEMPTS = 3)"
    ]


def test_expired_jobs_are_said_as_they_go(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """DTF_JOB_TTL=7 (meant as days) emptied a store at the next start without a line (the
    operator audit, M5): the jobs forgotten are counted in the log, with the TTL in words."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    old, kept = (store.create("evaluate", EVALUATE) for _ in range(2))
    for job in (old, kept):
        assert store.start(job.id)
        store.finish(job.id, "done", result={})
    with sqlite3.connect(store.path) as db:
        db.execute("UPDATE jobs SET finished = finished - 100000 WHERE id = ?", (old.id,))
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        runner = JobRunner(settings(tmp_path, job_ttl=86400.0))
        try:
            deadline = time.monotonic() + 10
            while runner.store.get(old.id) is not None and time.monotonic() < deadline:
                time.sleep(0.02)
        finally:
            runner.close()
    assert runner.store.get(old.id) is None and runner.store.get(kept.id) is not None
    said = [r.getMessage() for r in caplog.records if r.getMessage().startswith("forgot ")]
    assert said == [
        "forgot 1 job(s) that finished over DTF_JOB_TTL = 86400 s (1 day) ago, with their results"
    ]


def test_a_dead_worker_is_replaced_and_its_job_run_again_up_to_its_attempts(
    tmp_path: Path,
) -> None:
    """A worker killed (for memory, say) failed its job at once (the jobs audit): the job is
    now run again, from no progress, until DTF_JOB_ATTEMPTS runs ended so; other jobs run."""
    runner = JobRunner(settings(tmp_path, job_attempts=2))
    try:
        job = runner.store.create("map", BIG_MAP)
        runner.wake()
        for attempt in (1, 2):
            running = wait_for(runner.store, job.id, lambda j: j.status == "running")
            assert running.status == "running" and running.attempts == attempt
            runner._workers[0].process.kill()
            ended = wait_for(runner.store, job.id, lambda j: j.status != "running")
            if attempt == 1:
                assert ended.status in ("queued", "running") and ended.attempts <= 2
        assert ended.status == "failed" and ended.error is not None
        assert ended.error[0]["type"] == "interrupted"
        assert "the worker process ended" in ended.error[0]["msg"]
        assert "2 runs (DTF_JOB_ATTEMPTS)" in ended.error[0]["msg"]
        second = runner.store.create("evaluate", EVALUATE)
        runner.wake()
        assert wait_for(runner.store, second.id, lambda j: j.status == "done").status == "done"
    finally:
        runner.close()


@pytest.mark.latency  # a cancel within a second: run alone (scripts/run_tests.py)
def test_a_worker_that_ignores_a_cancel_is_killed_and_replaced(tmp_path: Path) -> None:
    runner = JobRunner(settings(tmp_path), worker=stuck)
    try:
        job = runner.store.create("evaluate", EVALUATE)
        runner.wake()
        wait_for(runner.store, job.id, lambda j: j.status == "running")
        process = runner._workers[0].process
        runner.store.cancel(job.id)
        asked = time.monotonic()
        cancelled = wait_for(runner.store, job.id, lambda j: j.status != "running")
        assert cancelled.status == "cancelled"
        assert KILL_AFTER <= time.monotonic() - asked < 1.0
        assert not process.is_alive()
        deadline = time.monotonic() + 5
        while runner._workers[0].process is process and time.monotonic() < deadline:
            time.sleep(0.01)
        assert runner._workers[0].process is not process  # replaced
    finally:
        runner.close()


def test_jobs_run_in_the_order_they_were_queued(runner: JobRunner) -> None:
    ids = [runner.store.create("evaluate", EVALUATE).id for _ in range(3)]
    runner.wake()
    jobs = [wait_for(runner.store, i, lambda j: j.status == "done") for i in ids]
    assert all(j.status == "done" for j in jobs)
    started = [j.started for j in jobs]
    assert started == sorted(started)  # type: ignore[type-var]


def test_a_corrupt_store_is_logged_once_and_the_supervisor_backs_off(tmp_path: Path) -> None:
    (tmp_path / "jobs.sqlite3").write_bytes(b"not a database" * 100)
    records: list[logging.LogRecord] = []
    handler = logging.Handler()
    handler.emit = records.append  # type: ignore[method-assign]
    log.addHandler(handler)
    runner = JobRunner(settings(tmp_path))
    try:
        time.sleep(2.0)  # 40 looks at POLL_SECONDS; with the back-off, 5 or 6
        errors = [r for r in records if r.levelno >= logging.ERROR]
        assert len(errors) == 1, [r.getMessage() for r in errors]
        assert "jobs.sqlite3" in errors[0].getMessage() and errors[0].exc_info is None
        assert runner._thread.is_alive()
        with pytest.raises(JobStoreUnavailable):
            runner.recover()
        (tmp_path / "jobs.sqlite3").unlink()  # the operator moves the bad file away
        job = runner.store.create("evaluate", EVALUATE)
        runner.wake()
        assert wait_for(runner.store, job.id, lambda j: j.status == "done").status == "done"
        assert any("answers again" in r.getMessage() for r in records)
    finally:
        log.removeHandler(handler)
        runner.close()


def test_a_job_deleted_while_it_runs_frees_its_worker(runner: JobRunner) -> None:
    job = runner.store.create("map", BIG_MAP)
    runner.wake()
    wait_for(runner.store, job.id, lambda j: j.status == "running" and j.fraction > 0)
    assert runner.store.delete(job.id)
    runner.wake()
    second = runner.store.create("evaluate", EVALUATE)
    runner.wake()
    assert wait_for(runner.store, second.id, lambda j: j.status == "done").status == "done"
    assert runner.store.get(job.id) is None  # its worker's last writes made nothing again


def test_a_job_error_keeps_its_real_type(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    body = {**EVALUATE, "path": {"csv": "x,y,z\n1,2\n", "units": "mm"}}  # not checked at submit
    job = store.create("evaluate", body)
    worker.run_job(store, job.id, settings(tmp_path))
    failed = store.get(job.id)
    assert failed is not None and failed.status == "failed" and failed.error is not None
    assert failed.error[0]["type"] == "invalid_line"
    assert failed.error[0]["loc"][:3] == ["body", "path", "csv"]


def test_a_job_whose_request_is_damaged_fails_rather_than_stays_running(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    with sqlite3.connect(store.path) as db:
        db.execute("UPDATE jobs SET request = '{' WHERE id = ?", (job.id,))
    worker.run_job(store, job.id, settings(tmp_path))
    failed = store.state(job.id)
    assert failed is not None and failed.status == "failed" and failed.error is not None
    assert failed.error[0]["type"] == "damaged" and job.id in failed.error[0]["msg"]


def test_an_idle_supervisor_looks_seldom_and_still_finds_another_process_s_job(
    tmp_path: Path,
) -> None:
    # No job: the store is looked at every IDLE_POLL_SECONDS, not every POLL_SECONDS (2 s:
    # 40 looks; a slow machine looks less often, never more). A job queued through another
    # handle on the same file (another service process), with no wake, still runs.
    runner = JobRunner(settings(tmp_path))
    looks: list[float] = []
    queued = runner.store.queued

    def counted(**keywords: Any) -> list[str]:
        looks.append(time.monotonic())
        return queued(**keywords)

    runner.store.queued = counted  # type: ignore[method-assign]
    try:
        time.sleep(0.3)  # the first look (the store opened) is behind
        looks.clear()
        time.sleep(2.0)
        assert len(looks) <= 2.0 / IDLE_POLL_SECONDS + 1, len(looks)
        assert IDLE_POLL_SECONDS >= 10 * POLL_SECONDS
        other = JobStore(tmp_path / "jobs.sqlite3")
        job = other.create("evaluate", EVALUATE)
        assert wait_for(other, job.id, lambda j: j.status == "done").status == "done"
    finally:
        runner.close()


def test_a_jobs_lines_say_what_runs_and_how_long_it_took(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Kind, a map's size and the run, then the time it took (operator audit, M4): the lines
    were "job <id> running" and "job <id> done"."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    grid = {"x": {"min": 0.0, "max": 0.1, "step": 0.1}, "y": {"min": 0.4, "max": 0.4, "step": 0.1}}
    grid = {**grid, "z": 0.1, "yaw": 0.0}
    small_map = {"robot": EXAMPLE["robot"], "path": EXAMPLE["path"], "grid": grid}
    mapped = store.create("map", small_map, total=2)
    bad = store.create("evaluate", {**EVALUATE, "placement": {"x": "far"}})
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        worker.run_job(store, mapped.id, settings(tmp_path))
        worker.run_job(store, bad.id, settings(tmp_path))
    said = [r.getMessage() for r in caplog.records if r.name == "dtf.jobs"]
    assert len(said) == 4, said
    assert said[0] == f"job {mapped.id} running: map, 2 placements, run 1"
    assert re.fullmatch(rf"job {mapped.id} done in \d+(\.\d+)?(e-\d+)? s", said[1]), said[1]
    assert said[2] == f"job {bad.id} running: evaluate, run 1"
    assert said[3].startswith(f"job {bad.id} failed: invalid request (")
    assert store.state(mapped.id).status == "done"  # type: ignore[union-attr]


def test_a_recovery_the_store_refused_at_the_start_is_done_when_it_answers(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The start's recovery failed on a store that then came back: the job the restart had
    interrupted stayed running with no worker, for good (operator audit, H1's third part)."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id)  # running when the service stopped
    runner = JobRunner(settings(tmp_path))
    try:
        recover, refusals = runner.store.recover, [JobStoreUnavailable("the store is full")]

        def refusing_once(*, attempts: int, alive: Callable[[str | None], bool]) -> list[str]:
            if refusals:
                raise refusals.pop()
            return recover(attempts=attempts, alive=alive)

        monkeypatch.setattr(runner.store, "recover", refusing_once)
        with pytest.raises(JobStoreUnavailable):
            runner.recover()
        runner.wake()
        ended = wait_for(runner.store, job.id, lambda j: j.status == "done")
        assert ended.status == "done" and ended.attempts == 2
    finally:
        runner.close()


@pytest.mark.parametrize("late", [0.0, 0.3])
def test_a_start_forgets_the_expired_jobs_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, late: float
) -> None:
    """recover() forgets the expired jobs, and the supervisor's first look did it again at once
    (its own mark started at minus infinity): the store's expiry ran twice at every start.
    Then both still did where the look came first (``late``: the start's recover() after the
    supervisor's first look, POLL_SECONDS in) or while the start's expiry ran, as a loaded
    machine's fresh-clone CI found (stop 71)."""
    calls: list[JobStore] = []  # the stores expired (other tests' runners may live on)
    expire = JobStore.expire

    def counted(store: JobStore, *, ttl: float) -> int:
        calls.append(store)
        return expire(store, ttl=ttl)

    monkeypatch.setattr(JobStore, "expire", counted)
    runner = JobRunner(settings(tmp_path))
    try:
        time.sleep(late)
        runner.recover()  # as the service's start does
        for _ in range(6):  # the supervisor's looks
            runner.wake()
            time.sleep(0.1)
    finally:
        runner.close()
    assert [store for store in calls if store is runner.store] == [runner.store]


def test_a_workers_lines_are_said_by_the_service_where_its_logging_places_them(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A worker wrote its lines to its own stderr in the service's form: an operator's logging
    configuration (uvicorn --log-config) placed the web process's lines, never the workers'
    (the operator audit of 2026-12-07). They now reach this process's loggers: here caplog's
    handler on the root, at this process's levels (a DEBUG-level filter let nothing through)."""
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        runner = JobRunner(settings(tmp_path))
        try:
            job = runner.store.create("evaluate", EVALUATE)
            runner.wake()
            assert wait_for(runner.store, job.id, lambda j: j.status != "queued").status
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline and not any(
                r.getMessage().startswith(f"job {job.id} done in ") for r in caplog.records
            ):
                time.sleep(0.02)
        finally:
            runner.close()
    said = [r for r in caplog.records if r.getMessage().startswith(f"job {job.id} ")]
    assert [r.getMessage() for r in said][:1] == [f"job {job.id} running: evaluate, run 1"]
    assert re.fullmatch(rf"job {job.id} done in \S+ s", said[1].getMessage()), said[1]
    assert {r.process for r in said} - {os.getpid()} and len(said) == 2  # the worker's lines
