"""Services sharing a data directory: each runs its own jobs, and takes those of one that is gone.

A start queued again every job the store held as running, another live service's too, which
then ran twice (the operator audit's M1). Each service now holds a lock of its own under the
data directory and keeps its id with the jobs it starts (:mod:`service.jobs.owner`).
"""

from __future__ import annotations

import logging
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from service.jobs import runner as runner_module
from service.jobs.owner import SERVICES, ServiceLock, alive
from service.jobs.runner import JobRunner
from service.jobs.store import JobStore
from tests.service.jobs_workers import stuck
from tests.service.test_job_runner import EVALUATE, settings, wait_for


def test_a_second_service_leaves_a_live_ones_running_job_and_takes_it_once_it_stops(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    first, second = ServiceLock(tmp_path), ServiceLock(tmp_path)
    first.hold()
    second.hold()
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id, first.id)

    def lives(owner: str | None) -> bool:  # the second service's view, as its runner's
        return owner == second.id or alive(tmp_path, owner)

    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        assert store.recover(attempts=3, alive=lives) == []  # the second service starts
    assert "1 running job(s) left to the live service(s) that run them" in caplog.messages
    running = store.get(job.id)
    assert running is not None and (running.status, running.attempts) == ("running", 1)
    assert store.running_owners() == {first.id}

    first.release()  # the first service stops: its job is free
    with caplog.at_level(logging.INFO, logger="dtf.jobs"):
        assert store.recover(attempts=3, alive=lives) == [job.id]
    said = f"job {job.id} interrupted (its service stopped): queued again (run 2 of at most 3)"
    assert said in caplog.messages
    queued = store.get(job.id)
    assert queued is not None and queued.status == "queued"
    assert store.start(job.id, second.id)
    assert store.running_owners() == {second.id}


def test_a_job_of_a_release_before_owners_is_queued_again(tmp_path: Path) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", EVALUATE)
    assert store.start(job.id)  # no owner kept
    assert store.recover(attempts=3, alive=lambda owner: owner is not None) == [job.id]


def test_a_service_that_dies_frees_its_lock_and_its_file_is_removed(tmp_path: Path) -> None:
    """Another process holds the lock; killed (SIGKILL), the kernel frees it."""
    code = (
        "import sys, time; from pathlib import Path; from service.jobs.owner import ServiceLock; "
        "lock = ServiceLock(Path(sys.argv[1])); print(lock.hold(), flush=True); time.sleep(60)"
    )
    process = subprocess.Popen(
        [sys.executable, "-c", code, str(tmp_path)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert process.stdout is not None
        owner = process.stdout.readline().strip()
        path = tmp_path / SERVICES / f"{owner}.lock"
        assert path.read_text() == f"{process.pid}\n"  # which process holds it
        assert alive(tmp_path, owner)
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    assert not alive(tmp_path, owner)
    assert not path.exists()  # removed by the look that found it free
    assert not alive(tmp_path, owner)


@pytest.mark.parametrize("owner", [None, "", "../jobs", "0" * 31, "A" * 32, "0" * 32 + "/x"])
def test_an_owner_that_is_not_an_id_of_ours_is_not_alive(tmp_path: Path, owner: str | None) -> None:
    (tmp_path / SERVICES).mkdir()
    (tmp_path / "jobs.lock").write_text("")
    assert not alive(tmp_path, owner)
    assert (tmp_path / "jobs.lock").exists()  # nothing outside the services' locks touched


def test_a_stopped_service_removes_its_lock_file(tmp_path: Path) -> None:
    lock = ServiceLock(tmp_path)
    assert lock.hold() == lock.id == lock.hold()
    assert lock.path.exists()
    lock.release()
    assert not lock.path.exists() and not alive(tmp_path, lock.id)


def test_a_running_service_takes_over_the_jobs_of_one_that_stopped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two runners on one directory: the second's start and looks leave the first's job alone
    while the first lives; once the first stops, the second's supervisor queues the job again
    at its next look and runs it to its end, on its second run."""
    monkeypatch.setattr(runner_module, "TAKE_OVER_SECONDS", 0.2)
    first = JobRunner(settings(tmp_path), worker=stuck)  # its jobs never end
    second: JobRunner | None = None
    try:
        job = first.store.create("evaluate", EVALUATE)
        first.wake()
        wait_for(first.store, job.id, lambda j: j.status == "running")
        second = JobRunner(settings(tmp_path))
        assert second.recover() == []
        time.sleep(1.0)  # several of the second's looks
        running = second.store.get(job.id)
        assert running is not None and (running.status, running.attempts) == ("running", 1)
        assert second.store.running_owners() == {first.service.id}
        first.close()
        done = wait_for(second.store, job.id, lambda j: j.status == "done")
        assert (done.status, done.attempts) == ("done", 2)
        assert second.store.running_owners() == set()
        assert not (tmp_path / SERVICES / f"{first.service.id}.lock").exists()
    finally:
        first.close()
        if second is not None:
            second.close()


def test_a_start_removes_the_lock_files_of_services_killed_idle(tmp_path: Path) -> None:
    """A killed service's file stays (the kernel frees its lock, not the file); one that ran no
    job is never looked at again, and such files piled up with every crash."""
    live, killed = ServiceLock(tmp_path), ServiceLock(tmp_path)
    live.hold()
    killed.path.parent.mkdir(parents=True, exist_ok=True)
    killed.path.write_text("12345\n")  # its lock freed, its file left
    other = tmp_path / SERVICES / "notes.txt"
    other.write_text("an operator's")
    runner = JobRunner(settings(tmp_path))
    try:
        assert runner.recover() == []
        assert not killed.path.exists()
        assert live.path.exists() and other.exists()
    finally:
        runner.close()
        live.release()
