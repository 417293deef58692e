"""mu_path at many placements at once, as arrays (the engine of the map and the optimisers).

Every placement gets what :func:`solver.path.evaluate.evaluate_path` gives there: both run the one
pipeline of :mod:`solver.path.pipeline`. Here placements go through it in chunks of about 32, which
keeps the arrays in cache, and each placement is reduced to its chosen branch.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from solver.core.codes import FEASIBLE
from solver.core.malloc import raise_malloc_thresholds
from solver.core.parallel import SERIAL, TaskRunner
from solver.path.bottleneck import bottleneck_waypoints
from solver.path.bounded import one_pass_chunk
from solver.path.kernel_branches import KernelBranches
from solver.path.kernel_cells import (
    KernelInputs,
    kernel_inputs,
    kernel_of,
    no_acc_columns,
    run_kernel,
)
from solver.path.path_checks import refuse_colliding
from solver.path.pipeline import ChunkResult, run_chunk
from solver.path.placed import check_placements
from solver.path.problem import PathProblem

__all__ = ["PlacementResults", "columns_of_run", "evaluate_placements", "results_of_columns"]

DEFAULT_CHUNK = 32
SMALL_RUN_POSES = 500_000.0
"""Without a chunk asked for, a compiled-kernel run of at most this much work (closed-form
poses, :meth:`solver.path.problem.PathProblem.path_cost` a placement: about 45 ms of the UR5's
map on one thread) is cut into one task per thread rather than chunks of
:data:`DEFAULT_CHUNK`: each kernel call starts its pruning afresh (its first placement follows
every branch to the end) and costs about 15 us to enter. The ERK-size map (546 placements, 133
waypoints, 72,618 poses) took 3.6-3.7 ms on two threads in two tasks against 3.7-4.1 ms in
six, and 6.3-6.5 ms serially in one against 7.2-7.4 ms in eighteen (2026-12-07, medians of 100,
in process); its progress is then said twice, once a thread, within a few milliseconds."""


@dataclass(frozen=True)
class PlacementResults:
    """mu_path at P placements.

    Attributes:
        mu_path: shape (P,), m/s, NaN where infeasible.
        reason: shape (P,), index into ``solver.path.tracking.REASONS``, -1 where feasible.
        failed_waypoint: shape (P,), -1 where feasible.
        branch: shape (P,), index into the family's ``branches`` of the branch used.
        bottleneck_waypoint: shape (P,), -1 where infeasible.
        bottleneck_joint: shape (P,), -1 where infeasible.
        v_max: shape (P, N), m/s, V_max at every waypoint on the branch used (NaN where
            infeasible); only when asked for.
        mu_acc: shape (P,), m/s, min(mu_path, min_i V_acc,i) on the final joint path (motion.md
            section 2), NaN where infeasible; None without acceleration limits.
        limited_by: shape (P,), what binds mu_acc: 0 the speed limits (mu_acc = mu_path),
            k + 1 the problem's k-th final-path limit (1: acceleration), -1 where infeasible;
            None without acceleration limits.
        acc_waypoint: shape (P,), where mu_acc binds (-1 where infeasible); None likewise.
        acc_joint: shape (P,), the joint that binds there (-1 where infeasible); None likewise.
        v_acc: shape (P, N), m/s, the final-path bound at every waypoint (inf where
            unconstrained, NaN where infeasible); only when asked for, with such limits.
    """

    mu_path: np.ndarray
    reason: np.ndarray
    failed_waypoint: np.ndarray
    branch: np.ndarray
    bottleneck_waypoint: np.ndarray
    bottleneck_joint: np.ndarray
    v_max: np.ndarray | None = None
    mu_acc: np.ndarray | None = None
    limited_by: np.ndarray | None = None
    acc_waypoint: np.ndarray | None = None
    acc_joint: np.ndarray | None = None
    v_acc: np.ndarray | None = None

    def taken(self, index: np.ndarray) -> PlacementResults:
        """The results at the placements ``index`` (an integer array), in its order."""
        columns = {field.name: getattr(self, field.name) for field in dataclasses.fields(self)}
        return dataclasses.replace(
            self, **{name: value[index] for name, value in columns.items() if value is not None}
        )

    @property
    def feed_index(self) -> np.ndarray:
        """mu_acc where acceleration limits are given, else mu_path: what the optimisers climb."""
        return self.mu_path if self.mu_acc is None else self.mu_acc

    @property
    def feed_bounds(self) -> np.ndarray | None:
        """Per waypoint, the least of V_max and the final-path bound (whose minimum is the index).

        Only when asked for (``with_speeds``); V_max alone without final-path limits.
        """
        if self.v_max is None or self.v_acc is None:
            return self.v_max
        least: np.ndarray = np.fmin(self.v_max, self.v_acc)
        return least


def columns_of_run(
    problem: PathProblem, run: ChunkResult, with_speeds: bool
) -> tuple[np.ndarray, ...]:
    """A pipeline run's columns, each placement at its ``pick``.

    Per placement mu, reason, failed waypoint, branch, bottleneck waypoint and joint, V_max
    ((C, W) when ``with_speeds``, else (C, 0): a map of millions of placements keeps nothing per
    waypoint), then the acceleration columns.
    """
    branches = problem.branches
    pick, columns = run.pick, np.arange(len(run.pick))
    any_feasible = (run.tracked.reason == FEASIBLE).any(axis=0)
    chosen_v = np.where(any_feasible[:, None], run.v_max[pick, columns], np.nan)  # (C, W)
    worst = bottleneck_waypoints(np.nan_to_num(chosen_v, nan=np.inf))
    speed_columns = (
        np.where(any_feasible, run.mu_path[pick, columns], np.nan),
        run.tracked.reason[pick, columns],
        run.tracked.failed_waypoint[pick, columns],
        branches[pick if run.branch_of is None else run.branch_of[pick, columns]],
        np.where(any_feasible, worst, -1),
        np.where(any_feasible, run.limiting[pick, columns, worst], -1),
        chosen_v if with_speeds else chosen_v[:, :0],
    )
    bound, joint, binding = run.v_final, run.final_limiting, run.final_binding
    if run.mu_acc is None or bound is None or joint is None or binding is None:
        return speed_columns + no_acc_columns(len(pick), with_speeds * chosen_v.shape[1])
    final_v = np.where(any_feasible[:, None], bound[pick, columns], np.nan)  # (C, W)
    low = np.nan_to_num(final_v, nan=np.inf).argmin(axis=-1)
    accelerated = any_feasible & (final_v[columns, low] < speed_columns[0])
    acc_columns = (
        np.where(any_feasible, run.mu_acc[pick, columns], np.nan),
        np.where(any_feasible, np.where(accelerated, binding[pick, columns, low] + 1, 0), -1),
        np.where(accelerated, low, speed_columns[4]),
        np.where(accelerated, joint[pick, columns, low], speed_columns[5]),
        final_v if with_speeds else final_v[:, :0],
    )
    return speed_columns + acc_columns


def _task(
    problem: PathProblem,
    with_speeds: bool,
    chunk: int,
    inputs: dict[float, KernelInputs] | None,
    prune: bool,
    compiled: bool,
    placements: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """Evaluate a task's placements in chunks: the columns of :func:`columns_of_run`, concatenated.

    The compiled kernel (:mod:`solver.kernels.fixed_spin`, in free spin
    :mod:`solver.kernels.free_spin`) where ``inputs`` holds its inputs (one per spin of the
    placements, made once for all the tasks), or else the numpy pipeline, both taking
    placements of any yaws together (``compiled``: the numpy pipeline's free spin solves its
    spun paths by the compiled kernel, :mod:`solver.kernels.spun_rows`, where it can). A task
    may run in another process (a Dask worker), so it sets the malloc thresholds itself.
    """
    raise_malloc_thresholds()
    columns_of = partial(columns_of_run, problem, with_speeds=with_speeds)
    if inputs is not None:
        # The kernel keeps no array per placement: one call per spin of the task (a call costs
        # about 15 us, and each starts its pruning afresh), in chunks only where the path checks
        # run on the chunk's placements after it.
        size = chunk if problem.path_checks else max(1, len(placements))
        parts = [
            run_kernel(inputs[float(rows[0, 4])], rows, with_speeds)
            for rows in _pieces(placements, size)
        ]
        if problem.path_checks:  # the kernel's joint paths and next branches (path_checks.py)
            pieces = _pieces(placements, chunk)
            parts = [
                refuse_colliding(
                    problem,
                    rows,
                    part,
                    columns_of,
                    compiled=KernelBranches(inputs[float(rows[0, 4])], with_speeds),
                )
                for rows, part in zip(pieces, parts, strict=True)
            ]
    else:
        parts = []
        for rows in _pieces(placements, chunk):
            run = run_chunk(problem, rows, prune=prune, compiled=compiled)
            part = columns_of(run)
            if problem.path_checks:  # on the run's own joint paths: no IK solved again
                part = refuse_colliding(problem, rows, part, columns_of, run=run)
            parts.append(part)
    if len(parts) == 1:  # evaluate_placements concatenates the tasks' columns (a copy) anyway
        return tuple(parts[0])
    return tuple(np.concatenate(c) for c in zip(*parts, strict=True))


def _pieces(placements: np.ndarray, size: int) -> list[np.ndarray]:
    """Consecutive rows, at most ``size``, cut where the spin changes (a chunk has one spin).

    Placements of several yaws share a chunk: a differential evolution's population has a yaw
    per member, and a numeric family seeds its IK for a whole chunk at once (its Python work
    is per chunk): the Panda's scipy search on 10 waypoints took 55 s cut by yaw, one placement
    a chunk.
    """
    spins = placements[:, 4]
    if not len(spins) or (spins == spins[0]).all():  # one spin: slices, not numpy's split
        runs = [placements]
    else:
        runs = np.split(placements, np.flatnonzero(np.diff(spins) != 0.0) + 1)
    return [run[start : start + size] for run in runs for start in range(0, len(run), size)]


def chunk_of(
    problem: PathProblem, n_placements: int, threads: int, kernel: bool, chunk: int | None
) -> int:
    """The placements a run computes together: ``chunk`` where the caller asked for one.

    Else :data:`DEFAULT_CHUNK`, or, where the compiled kernel takes each task in one call
    (``kernel``, no path checks) and the whole run is at most :data:`SMALL_RUN_POSES` of work,
    enough that each of the runner's ``threads`` takes one task.
    """
    if chunk is not None:
        return chunk
    if kernel and not problem.path_checks:
        work = n_placements * problem.path_cost(problem.prepared.n_waypoints)
        if work <= SMALL_RUN_POSES:
            return max(DEFAULT_CHUNK, -(-n_placements // max(1, threads)))
    return DEFAULT_CHUNK


def evaluate_placements(
    problem: PathProblem,
    placements: np.ndarray,
    *,
    with_speeds: bool = False,
    chunk: int | None = None,
    progress: Callable[[float], None] | None = None,
    runner: TaskRunner = SERIAL,
    compiled: bool = True,
    prune: bool = True,
) -> PlacementResults:
    """mu_path of a path at each of P placements.

    Args:
        problem: the robot (with a kinematics family), the path and the options (the branch
            followed everywhere, the step bound, the spin mode).
        placements: shape (P, 5), [x (m), y (m), z (m), yaw (rad), spin (rad)] of {O} in {B}
            (:meth:`solver.core.spatial.Placement.as_row`); (P, 4) is taken with spin 0.
        with_speeds: also return V_max at every waypoint.
        chunk: placements computed together (and progress said at least once a chunk); None:
            :data:`DEFAULT_CHUNK`, or one task a thread for a small run (:func:`chunk_of`).
        progress: called with the fraction done (0..1] as tasks complete; it may raise
            (:class:`solver.core.progress.Cancelled`) to stop the work.
        runner: runs the tasks (:mod:`solver.core.parallel`); every runner gives the same answer.
        compiled: use the compiled kernel where the family has one
            (:mod:`solver.kernels.fixed_spin`); False runs the numpy pipeline, the reference.
        prune: in the numpy pipeline, stop following branches that cannot be a placement's
            chosen one (:mod:`solver.path.pruning`: the same results, less work); False:
            follow every branch, the reference.

    Raises:
        NoAnalyticIkError, InvalidInputError: as :func:`solver.path.evaluate.evaluate_path`.
    """
    _ = problem.branches  # the options checked before any work
    _ = problem.path_checks  # and the cell
    cells = check_placements(placements)
    raise_malloc_thresholds()
    kernel = kernel_of(problem) if compiled else None
    chunk = chunk_of(problem, len(cells), runner.threads, kernel is not None, chunk)
    chunk = one_pass_chunk(problem, chunk) if prune else chunk
    tasks = _pieces(cells, runner.task_size(len(cells), chunk))
    completed = [0]

    def done(i: int) -> None:
        completed[0] += len(tasks[i])
        if progress is not None:
            progress(completed[0] / len(cells))

    inputs = None  # the kernel's, made once per spin, not once per task (a map's 5 tasks: 6 ms)
    if kernel is not None:
        inputs = {spin: kernel_inputs(problem, spin, kernel) for spin in set(cells[:, 4].tolist())}
    work = partial(_task, problem, with_speeds, chunk, inputs, prune, compiled)
    parts = runner.run(work, tasks, done)
    n_waypoints = problem.prepared.n_waypoints
    empty = (np.zeros(0), *(np.zeros(0, dtype=int),) * 5, np.zeros((0, n_waypoints)))
    empty += no_acc_columns(0, n_waypoints)
    columns = [np.concatenate(c) for c in zip(*parts, strict=True)] if parts else list(empty)
    return results_of_columns(problem, columns, with_speeds)


def results_of_columns(
    problem: PathProblem, columns: list[np.ndarray], with_speeds: bool
) -> PlacementResults:
    """The results of :func:`columns_of_run`'s columns (the acceleration ones where limits are)."""
    mu, reason, failed, chosen, bottleneck_waypoint, bottleneck_joint, v_max = columns[:7]
    mu_acc, limited_by, acc_waypoint, acc_joint, v_acc = columns[7:]
    accelerations = bool(problem.final_path_limits)
    return PlacementResults(
        mu_path=mu,
        reason=reason,
        failed_waypoint=failed,
        branch=chosen,
        bottleneck_waypoint=bottleneck_waypoint,
        bottleneck_joint=bottleneck_joint,
        v_max=v_max if with_speeds else None,
        mu_acc=mu_acc if accelerations else None,
        limited_by=limited_by if accelerations else None,
        acc_waypoint=acc_waypoint if accelerations else None,
        acc_joint=acc_joint if accelerations else None,
        v_acc=v_acc if accelerations and with_speeds else None,
    )
