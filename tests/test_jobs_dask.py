"""Map jobs on a real Dask cluster (``DTF_DASK_SCHEDULER``): same cells, monotone progress, cancel.

A ``LocalCluster`` of two worker processes stands for machines running ``dask worker``; the
service is a live uvicorn pointed at its scheduler. The cells are compared with the synchronous
route's, which computes them in the web process.
"""

from __future__ import annotations

import math
import os
import socket
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import dask
import httpx
import numpy as np
import pytest
from distributed import LocalCluster

from service.config import Settings
from service.jobs import dask_runner
from service.jobs.dask_runner import ClusterUnavailable, DaskRunner
from service.jobs.store import JobStore
from service.jobs.worker import run_job, task_runner
from tests.test_jobs import BIG_GRID, EXAMPLE, GRID_8K, SMALL_GRID, map_request, server, wait_for


@pytest.fixture(scope="module")
def cluster() -> Iterator[LocalCluster]:
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        yield cluster


def transitions(cluster: LocalCluster) -> int:
    """Task state transitions on the scheduler since it started (a task makes several)."""
    return int(cluster.scheduler.transition_counter)


def cells(answer: dict[str, Any]) -> np.ndarray:
    return np.array([c["mu_path"] if c["mu_path"] is not None else np.nan for c in answer["cells"]])


def test_a_map_job_on_dask_gives_the_local_cells(tmp_path: Path, cluster: LocalCluster) -> None:
    body = map_request(GRID_8K)
    before = transitions(cluster)
    process, url = server(
        tmp_path, DTF_DASK_SCHEDULER=cluster.scheduler_address, DTF_MAX_MAP_POSES="10000000"
    )
    try:
        job_id = httpx.post(f"{url}/v1/jobs", json={"kind": "map", "request": body}).json()["id"]
        fractions = []
        while True:
            job = httpx.get(f"{url}/v1/jobs/{job_id}").json()
            fractions.append(job["progress"]["fraction"])
            if job["status"] not in ("queued", "running"):
                break
            time.sleep(0.05)
        assert job["status"] == "done", job
        assert fractions == sorted(fractions) and fractions[-1] == 1.0
        assert len(set(fractions)) >= 3  # progress came as the tasks completed
        assert transitions(cluster) - before >= 8 * 3  # tasks ran on the cluster
        local = httpx.post(f"{url}/v1/map", json=body, timeout=60).json()
        np.testing.assert_allclose(cells(job["result"]), cells(local), rtol=1e-12)
        for key in ("x", "y", "yaw", "reason", "failed_waypoint"):
            assert [c[key] for c in job["result"]["cells"]] == [c[key] for c in local["cells"]], key
    finally:
        process.terminate()
        process.wait()


@pytest.mark.latency  # a cancel within a second: run alone (scripts/run_tests.py)
def test_a_cancelled_job_stops_its_dask_tasks(tmp_path: Path, cluster: LocalCluster) -> None:
    process, url = server(tmp_path, DTF_DASK_SCHEDULER=cluster.scheduler_address)
    try:
        body = {"kind": "map", "request": map_request(BIG_GRID)}
        job_id = httpx.post(f"{url}/v1/jobs", json=body).json()["id"]
        wait_for(url, job_id, lambda j: j["progress"]["fraction"] > 0)
        assert httpx.post(f"{url}/v1/jobs/{job_id}/cancel").status_code == 200
        asked = time.monotonic()
        job = wait_for(url, job_id, lambda j: j["status"] != "running", timeout=10)
        assert job["status"] == "cancelled" and time.monotonic() - asked < 1.0
        deadline = time.monotonic() + 10
        while cluster.scheduler.tasks and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not cluster.scheduler.tasks  # nothing left queued or running on the cluster
    finally:
        process.terminate()
        process.wait()


def test_an_optimize_job_on_dask_finds_the_routes_optimum(
    tmp_path: Path, cluster: LocalCluster
) -> None:
    """The casadi method's coarse map runs on the cluster (the scipy method's differential
    evolution takes the same runner, but its 60 small batches take a minute on this machine)."""
    request = {
        "robot": EXAMPLE["robot"],
        "path": EXAMPLE["path"],
        "bounds": {"x": [-0.1, 0.1], "y": [0.35, 0.55], "yaw": [-0.5, 0.5]},
        "z": 0.1,
        "method": "casadi",
    }
    before = transitions(cluster)
    process, url = server(tmp_path, DTF_DASK_SCHEDULER=cluster.scheduler_address)
    try:
        job_id = httpx.post(f"{url}/v1/jobs", json={"kind": "optimize", "request": request})
        job = wait_for(url, job_id.json()["id"], lambda j: j["status"] in ("done", "failed"))
        assert job["status"] == "done", job
        assert transitions(cluster) - before >= 3  # its placements ran on the cluster
        direct = httpx.post(f"{url}/v1/optimize", json=request, timeout=120).json()
        assert job["result"]["mu_path"] == pytest.approx(direct["mu_path"], rel=1e-9)
        assert job["result"]["placement"] == direct["placement"]
    finally:
        process.terminate()
        process.wait()


def _noted(done: list[int]) -> Callable[[int], None]:
    return done.append


def test_a_runner_whose_client_closed_connects_again(cluster: LocalCluster) -> None:
    """A scheduler's outage past the client's reconnect window closes it for good: every later
    job failed ('NoneType' object has no attribute 'ncores') until the service restarted."""
    runner = DaskRunner(cluster.scheduler_address)
    done: list[int] = []
    assert runner.run(abs, [-1, -2, 3], _noted(done)) == [1, 2, 3]
    runner.client().close()  # as an outage longer than the reconnect window leaves it
    assert runner.task_size(1000, 32) >= 32
    assert runner.run(abs, [-4, 5], _noted(done)) == [4, 5]
    assert sorted(done) == [0, 0, 1, 1, 2]


def test_a_tasks_own_error_is_raised_as_it_is(cluster: LocalCluster) -> None:
    runner = DaskRunner(cluster.scheduler_address)
    with pytest.raises(ValueError, match="math domain error"):
        runner.run(math.sqrt, [4.0, -1.0], _noted([]))


def test_a_cluster_that_cannot_run_a_job_says_so() -> None:
    """No scheduler at the address; a scheduler without a worker (the tasks would wait, the job
    running, its ETA growing): ClusterUnavailable, naming the address and what is missing."""
    with pytest.raises(ClusterUnavailable, match=r"tcp://127.0.0.1:9 .* cannot be reached"):
        DaskRunner("tcp://127.0.0.1:9", connect_seconds=1.0).run(abs, [1], _noted([]))
    with LocalCluster(n_workers=0, dashboard_address=":0") as empty:
        runner = DaskRunner(empty.scheduler_address, connect_seconds=0.5)
        with pytest.raises(ClusterUnavailable, match=r"has no worker after 0\.5 s"):
            runner.task_size(1000, 32)


def test_a_job_the_cluster_cannot_run_fails_as_unavailable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Its error's type is 'unavailable' (it was 'internal', which reads as a bug of ours)."""
    monkeypatch.setattr(dask_runner, "CONNECT_SECONDS", 1.0)
    task_runner.cache_clear()
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("map", map_request(SMALL_GRID), total=1)
    try:
        run_job(store, job.id, Settings(dask_scheduler="tcp://127.0.0.1:9"))
    finally:
        task_runner.cache_clear()
    state = store.get(job.id)
    assert state is not None and state.status == "failed"
    assert state.error is not None
    (error,) = state.error
    assert error["type"] == "unavailable", error
    assert "tcp://127.0.0.1:9" in error["msg"]


def _nap(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


def test_a_cluster_that_loses_its_workers_during_a_job_says_so() -> None:
    """Every worker gone while the tasks run: they waited for one, the job running for ever
    (the runner blocked in as_completed); now ClusterUnavailable once none has come back for
    ``connect_seconds``."""
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
    ) as lonely:
        runner = DaskRunner(lonely.scheduler_address, connect_seconds=1.0)
        done: list[int] = []

        def retire_after_first(i: int) -> None:
            done.append(i)
            if len(done) == 1:
                threading.Thread(target=lonely.scale, args=(0,)).start()

        with ThreadPoolExecutor(1) as pool:
            running = pool.submit(runner.run, _nap, [0.2] * 40, retire_after_first)
            try:
                with pytest.raises(ClusterUnavailable, match=r"has had no worker for 1 s"):
                    running.result(timeout=60)
            finally:
                runner.client().close()  # unblocks a runner that waits for ever
        assert 1 <= len(done) < 40


def _die() -> None:
    os._exit(3)


def test_a_task_that_kills_its_workers_is_the_clusters_failure_named() -> None:
    """A worker process dying under a task (out of memory, say) until the scheduler gives the
    task up (KilledWorker): the job failed as 'internal', a bug of ours; now unavailable,
    saying a worker died."""
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
        ) as fragile:
            runner = DaskRunner(fragile.scheduler_address, connect_seconds=5.0)
            with pytest.raises(ClusterUnavailable, match=r"worker process die .* KilledWorker"):
                runner.run(lambda _: _die(), [0], _noted([]))


def test_workers_whose_code_is_not_the_services_are_refused(
    cluster: LocalCluster, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A worker on another release (or another numpy) gave its own numbers without a word.
    Here the service's side is made to differ: every worker is named, with what differs."""
    assert DaskRunner(cluster.scheduler_address).run(abs, [-1], _noted([])) == [1]
    elsewhere = {**dask_runner.code_fingerprint(), "numpy": "0.0.1"}
    monkeypatch.setattr(dask_runner, "code_fingerprint", lambda: elsewhere)
    runner = DaskRunner(cluster.scheduler_address)
    with pytest.raises(ClusterUnavailable, match=r"2 worker\(s\) whose code") as refused:
        runner.run(abs, [-1], _noted([]))
    said = str(refused.value)
    for address in cluster.scheduler_info["workers"]:
        assert f"{address}: numpy {np.__version__} (here 0.0.1)" in said


def test_workers_that_cannot_be_asked_their_code_are_the_clusters_failure(
    cluster: LocalCluster, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A worker gone between the scheduler's list and the question (a KeyError out of the
    client) failed the job as 'internal'."""
    runner = DaskRunner(cluster.scheduler_address)

    def gone(*args: object, **kwargs: object) -> None:
        raise KeyError("tcp://127.0.0.1:1")

    monkeypatch.setattr(runner.client(), "run", gone)
    with pytest.raises(ClusterUnavailable, match="could not be asked which code .* KeyError"):
        runner.run(abs, [-1], _noted([]))


def test_workers_of_a_release_before_the_check_are_told_to_be_upgraded(
    cluster: LocalCluster, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A worker on a release older than the check cannot unpickle it: the job failed as if the
    cluster were down ("submitted again once the cluster runs", which never helps; the upgrade
    audit of stop 62, F10). The worker's error as Dask relays it, raised here."""
    runner = DaskRunner(cluster.scheduler_address)
    old = "Can't get attribute 'worker_fingerprint' on <module 'service.jobs.dask_runner'>"

    def older(*args: object, **kwargs: object) -> None:
        raise Exception(repr(AttributeError(old)))  # noqa: TRY002 - as distributed relays it

    monkeypatch.setattr(runner.client(), "run", older)
    with pytest.raises(ClusterUnavailable) as refused:
        runner.run(abs, [-1], _noted([]))
    said = str(refused.value)
    assert "worker(s) whose code is not the service's" in said
    assert "install the service's release on them" in said and "could not be asked" not in said


def test_a_worker_restarted_at_its_address_is_checked_again(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Checked once an address, a worker restarted at the same address (a fixed port) with
    other code was taken for the one checked. Here one worker on a fixed port is restarted by
    its nanny; the service's side is then made to differ (as the test above): refused."""
    port = _free_port()
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        worker_port=port,
    ) as fixed:
        runner = DaskRunner(fixed.scheduler_address)
        assert runner.run(abs, [-1], _noted([])) == [1]
        (address,) = fixed.scheduler_info["workers"]
        client = runner.client()
        before = client.scheduler_info(n_workers=-1)["workers"][address]["local_directory"]
        client.restart_workers([address])
        after = client.scheduler_info(n_workers=-1)["workers"]
        assert list(after) == [address]  # the same address, another process:
        assert after[address]["local_directory"] != before
        elsewhere = {**dask_runner.code_fingerprint(), "numpy": "0.0.1"}
        monkeypatch.setattr(dask_runner, "code_fingerprint", lambda: elsewhere)
        with pytest.raises(ClusterUnavailable, match=r"1 worker\(s\) whose code"):
            runner.run(abs, [-1], _noted([]))


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
    return port
