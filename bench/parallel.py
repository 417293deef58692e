"""Benchmark of where the placement tasks run: one thread, both cores, a Dask cluster.

Called by ``bench/run.py``; prints figures, asserts nothing. The ERK-size 8-yaw map on one
thread and on a pool of two (``DTF_THREADS``), then a 50,000-placement map job run by the job
worker's own code (``service.jobs.worker.run_job``) on the local worker (DTF_WORKERS=1: both
cores as threads) and on a two-worker Dask ``LocalCluster`` (``DTF_DASK_SCHEDULER``), each
timed from start to the stored result. Last, the job workers' start: jobs queued at once on a
new job runner, its workers forked from the fork server (``service.jobs.runner``) against
started by ``spawn`` (how they started before 2026-12-07), same run.
"""

from __future__ import annotations

import json
import math
import multiprocessing
import tempfile
import time
from pathlib import Path
from unittest import mock

import numpy as np

from service.config import Settings
from service.jobs import runner as runner_module
from service.jobs.store import JobStore
from service.jobs.worker import run_job
from solver.core.parallel import SERIAL, ThreadRunner
from solver.core.robots import Robot
from solver.path.capability_map import capability_map
from solver.path.problem import PathProblem

ROOT = Path(__file__).resolve().parents[1]
RUNNER_TIMEOUT = 120.0
"""The longest :func:`worker_starts` waits for its jobs (s): a few on an idle machine."""


def threads(robot: Robot, path: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float) -> None:
    """The 8-yaw map on one thread and on two."""
    yaws = np.linspace(0.0, 2 * math.pi, 8, endpoint=False)
    times = {}
    for name, runner in (("1 thread", SERIAL), ("2 threads", ThreadRunner(2))):
        best = math.inf
        for _ in range(3):
            began = time.perf_counter()
            capability_map(PathProblem.of(robot, path), xs=xs, ys=ys, z=z, yaws=yaws, runner=runner)
            best = min(best, time.perf_counter() - began)
        times[name] = best
    print(
        f"8-yaw map ({8 * len(xs) * len(ys)} placements) on 1 thread {times['1 thread']:.3f} s, "
        f"on 2 threads {times['2 threads']:.3f} s: {times['1 thread'] / times['2 threads']:.2f}x"
    )


def _job_seconds(request: dict[str, object], settings: Settings) -> float:
    with tempfile.TemporaryDirectory() as data:
        store = JobStore(Path(data) / "jobs.sqlite3")
        job = store.create("map", request)
        began = time.perf_counter()
        run_job(store, job.id, settings)
        elapsed = time.perf_counter() - began
        done = store.get(job.id)
        if done is None or done.status != "done":
            raise RuntimeError(f"the benchmark job did not finish: {done}")
        return elapsed


def map_job(*, smoke: bool) -> None:
    """A 50,000-placement map job on the local worker and on a two-worker Dask cluster."""
    from distributed import LocalCluster

    example = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
    x_step, n_y = (0.05, 10) if smoke else (0.005, 125)  # 200 x 125 x 2 = 50,000 placements
    request = {
        "robot": example["robot"],
        "path": example["path"],
        "grid": {
            "x": {"min": -0.5, "max": 0.5 - x_step, "step": x_step},
            "y": {"min": 0.0, "max": 0.005 * (n_y - 1) + 1e-9, "step": 0.005},
            "z": 0.1,
            "yaw": [0.0, 1.0],
        },
    }
    cells = 2 * n_y * round(1.0 / x_step)
    limits = {"max_job_cells": 10**7, "max_job_poses": 10**10}
    local = _job_seconds(request, Settings(workers=1, **limits))
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        on_dask = Settings(workers=1, dask_scheduler=cluster.scheduler_address, **limits)
        _job_seconds(request, on_dask)  # warm up: the workers import the solver
        dask = _job_seconds(request, on_dask)
    print(
        f"map job of {cells:,} placements: local worker (2 threads) {local:.2f} s, "
        f"two-worker Dask LocalCluster {dask:.2f} s: {local / dask:.2f}x "
        "(both on this machine's cores: Dask adds machines, not speed on one)"
    )


def _runner_seconds(request: dict[str, object], jobs: int) -> float:
    """Seconds from queueing ``jobs`` map jobs on a new runner of as many workers to all done."""
    with tempfile.TemporaryDirectory() as data:
        runner = runner_module.JobRunner(Settings(data_dir=data, workers=jobs))
        try:
            began = time.perf_counter()
            ids = [runner.store.create("map", request).id for _ in range(jobs)]
            runner.wake()
            while True:
                ended = [runner.store.get(i) for i in ids]
                if all(job is None or job.status not in ("queued", "running") for job in ended):
                    break
                if time.perf_counter() - began > RUNNER_TIMEOUT:
                    raise RuntimeError(f"the benchmark's jobs ran over {RUNNER_TIMEOUT} s")
                time.sleep(0.01)
            elapsed = time.perf_counter() - began
        finally:
            runner.close()
        if any(job is None or job.status != "done" for job in ended):
            said = [(job.status, job.error) if job else None for job in ended]
            raise RuntimeError(f"a benchmark job did not finish: {said}")
        return elapsed


def worker_starts(*, smoke: bool) -> None:
    """Small map jobs queued at once on a new runner: workers forked against spawned."""
    example = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
    axis = {"min": -0.1, "max": 0.1, "step": 0.05}
    grid = {"x": axis, "y": {**axis, "min": 0.4, "max": 0.5}, "z": 0.1, "yaw": 0.0}
    request = {"robot": example["robot"], "path": example["path"], "grid": grid}
    jobs = 2 if smoke else 4
    forked_first = _runner_seconds(request, jobs)  # the fork server starts with them
    forked = _runner_seconds(request, jobs)  # the fork server already runs
    spawn = multiprocessing.get_context("spawn")
    with mock.patch.object(runner_module, "worker_context", lambda: spawn):
        spawned = _runner_seconds(request, jobs)
    print(
        f"{jobs} small map jobs queued at once on a new runner of {jobs} workers: spawned "
        f"{spawned:.2f} s, forked {forked_first:.2f} s with the fork server's start "
        f"({spawned / forked_first:.1f}x), {forked:.2f} s once it runs ({spawned / forked:.1f}x)"
    )
