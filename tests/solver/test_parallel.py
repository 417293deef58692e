"""Every task runner gives the serial engine's answer; progress is monotone; a cancel stops it."""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest

from solver.core.parallel import SERIAL, SerialRunner, ThreadRunner, tasks_of
from solver.core.progress import Cancelled
from solver.families import get_robot
from solver.path import placements as placements_module
from tests.problems import evaluate_placements, prepare_path
from tests.solver.test_evaluate import load_path


def grid_placements() -> np.ndarray:
    """An 8-yaw grid in yaw-major order, feasible and infeasible cells both."""
    yaw, y, x = np.meshgrid(
        np.linspace(-math.pi, math.pi, 8, endpoint=False),
        np.linspace(0.0, 1.2, 6),
        np.linspace(-0.9, 0.9, 9),
        indexing="ij",
    )
    return np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.1), yaw.ravel()])


@pytest.mark.parametrize("threads", [2, 3])
def test_threads_give_the_serial_answer_and_monotone_progress(threads: int) -> None:
    robot = get_robot("ur5")
    path = prepare_path(robot, load_path("s_curve"))
    placements = grid_placements()
    serial = evaluate_placements(robot, path, placements, with_speeds=True)
    fractions: list[float] = []
    pooled = evaluate_placements(
        robot,
        path,
        placements,
        with_speeds=True,
        chunk=8,
        progress=fractions.append,
        runner=ThreadRunner(threads),
    )
    feasible = ~np.isnan(serial.mu_path)
    assert 0.2 < feasible.mean() < 0.9
    np.testing.assert_allclose(pooled.mu_path, serial.mu_path, rtol=1e-12)
    np.testing.assert_allclose(pooled.v_max, serial.v_max, rtol=1e-12)
    for name in ("reason", "failed_waypoint", "branch", "bottleneck_waypoint", "bottleneck_joint"):
        np.testing.assert_array_equal(getattr(pooled, name), getattr(serial, name), err_msg=name)
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    assert len(fractions) >= 8  # a task at most per yaw


@pytest.mark.parametrize("runner", [SERIAL, ThreadRunner(2)])
def test_a_progress_that_raises_stops_the_work(runner: object) -> None:
    robot = get_robot("ur5")
    path = prepare_path(robot, load_path("s_curve"))
    calls: list[float] = []

    def cancel(fraction: float) -> None:
        calls.append(fraction)
        raise Cancelled

    with pytest.raises(Cancelled):
        evaluate_placements(robot, path, grid_placements(), chunk=8, progress=cancel, runner=runner)
    assert len(calls) == 1 and calls[0] < 0.5


def test_a_threaded_run_uses_several_threads() -> None:
    seen: set[int] = set()
    barrier = threading.Barrier(2, timeout=5)

    def work(task: int) -> int:
        seen.add(threading.get_ident())
        if task < 2:
            barrier.wait()  # both first tasks must be running at once
        return task * task

    assert ThreadRunner(2).run(work, list(range(6)), lambda i: None) == [0, 1, 4, 9, 16, 25]
    assert len(seen) == 2


def test_the_calling_thread_computes_and_reports_every_task() -> None:
    caller = threading.get_ident()
    ran_on: dict[int, int] = {}
    reported_on: set[int] = set()
    barrier = threading.Barrier(2, timeout=5)

    def work(task: int) -> int:
        ran_on[task] = threading.get_ident()
        if task < 2:
            barrier.wait()  # the caller and the helper each hold one of the first two
        return -task

    def done(i: int) -> None:
        reported_on.add(threading.get_ident())

    assert ThreadRunner(2).run(work, list(range(8)), done) == [-t for t in range(8)]
    assert caller in ran_on.values() and len(set(ran_on.values())) == 2
    assert reported_on == {caller}


def test_a_task_that_raises_in_a_helper_is_raised_and_stops_the_work() -> None:
    caller = threading.get_ident()
    started: list[int] = []
    release = threading.Event()

    def work(task: int) -> int:
        started.append(task)
        if threading.get_ident() != caller:
            raise ValueError(f"task {task}")
        release.wait(5)  # the caller's first task ends once the helper has failed
        return task

    def done(i: int) -> None:
        pass

    threading.Timer(0.2, release.set).start()
    with pytest.raises(ValueError, match="task [01]"):
        ThreadRunner(2).run(work, list(range(50)), done)
    assert sorted(started) == [0, 1]  # one task each; none started after the failure


def _helper_of_a_run(runner: ThreadRunner) -> threading.Thread:
    """The thread that helped a run of ``runner`` (both first tasks held until both run)."""
    caller = threading.current_thread()
    helpers: set[threading.Thread] = set()
    barrier = threading.Barrier(2, timeout=5)

    def work(task: int) -> int:
        if threading.current_thread() is not caller:
            helpers.add(threading.current_thread())
        if task < 2:
            barrier.wait()
        return task

    assert runner.run(work, list(range(4)), lambda i: None) == [0, 1, 2, 3]
    (helper,) = helpers
    return helper


def test_the_helper_threads_are_kept_for_the_next_run() -> None:
    runner = ThreadRunner(2)
    first = _helper_of_a_run(runner)
    assert _helper_of_a_run(runner) is first
    assert _helper_of_a_run(ThreadRunner(2)) is not first  # another runner, its own helper


def test_a_stopped_run_returns_only_once_its_helper_s_task_has_ended() -> None:
    caller = threading.get_ident()
    helper_started, helper_ended = threading.Event(), threading.Event()

    def work(task: int) -> int:
        if threading.get_ident() != caller:
            helper_started.set()
            time.sleep(0.3)
            helper_ended.set()
        else:
            helper_started.wait(5)  # the caller's first report comes once the helper computes
        return task

    def done(i: int) -> None:
        raise Cancelled

    with pytest.raises(Cancelled):
        ThreadRunner(2).run(work, list(range(10)), done)
    assert helper_ended.is_set()  # no thread computes for the run after it has returned


def test_runs_at_the_same_time_share_the_helpers_and_each_gets_its_answer() -> None:
    runner = ThreadRunner(2)
    answers: dict[int, list[int]] = {}

    def run(k: int) -> None:
        def work(task: int) -> int:
            time.sleep(0.001)
            return k * 1000 + task

        answers[k] = runner.run(work, list(range(40)), lambda i: None)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert answers == {k: [k * 1000 + t for t in range(40)] for k in range(4)}


def test_task_sizes_are_whole_chunks_within_the_cap() -> None:
    assert tasks_of(1000, 32, per_worker=4, workers=2, cap=512) == 128
    assert tasks_of(10, 32, per_worker=4, workers=2, cap=512) == 32
    assert tasks_of(10**6, 32, per_worker=4, workers=2, cap=512) == 512
    with pytest.raises(ValueError, match="threads=0"):
        ThreadRunner(0)


@pytest.mark.parametrize("runner", [SERIAL, ThreadRunner(2)])
def test_a_small_kernel_run_without_a_chunk_asked_takes_one_task_a_thread(
    runner: SerialRunner | ThreadRunner,
) -> None:
    """solver.path.placements.chunk_of: the same answers as chunks of 32, progress once a thread.

    432 placements of the 49-waypoint s-curve are 21,168 closed-form poses of work, far under
    SMALL_RUN_POSES: each of the runner's threads takes one task, so progress is said once a
    thread, where chunks of 32 say it 14 times (in 7 tasks of 64 on two threads).
    """
    robot = get_robot("ur5")
    path = prepare_path(robot, load_path("s_curve"))
    placements = grid_placements()
    assert len(placements) * len(load_path("s_curve")) < placements_module.SMALL_RUN_POSES
    chunked: list[float] = []
    ours: list[float] = []
    every = evaluate_placements(
        robot, path, placements, with_speeds=True, chunk=32, progress=chunked.append, runner=runner
    )
    run = evaluate_placements(
        robot, path, placements, with_speeds=True, progress=ours.append, runner=runner
    )
    for name in ("mu_path", "reason", "failed_waypoint", "branch", "bottleneck_waypoint", "v_max"):
        np.testing.assert_array_equal(getattr(run, name), getattr(every, name), err_msg=name)
    assert len(chunked) >= 7  # tasks of 32 placements (two threads: 64, four a thread at most)
    assert len(ours) == runner.threads and ours[-1] == 1.0


def test_a_large_run_or_a_numpy_run_keeps_the_default_chunk() -> None:
    """Over SMALL_RUN_POSES of work, or without the kernel, chunks of DEFAULT_CHUNK."""
    robot = get_robot("ur5")
    problem = prepare_path(robot, load_path("s_curve"))
    n_waypoints = problem.prepared.n_waypoints
    small = int(placements_module.SMALL_RUN_POSES // n_waypoints)
    chunk_of = placements_module.chunk_of
    assert chunk_of(problem, small, 2, True, None) == math.ceil(small / 2)
    assert chunk_of(problem, small + 1, 2, True, None) == placements_module.DEFAULT_CHUNK
    assert chunk_of(problem, small, 2, False, None) == placements_module.DEFAULT_CHUNK
    assert chunk_of(problem, small, 2, True, 8) == 8  # a chunk asked for is taken
