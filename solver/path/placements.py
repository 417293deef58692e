"""mu_path at many placements at once, as arrays (the engine of the map and the optimisers).

Every placement gets what :func:`solver.path.evaluate.evaluate_path` gives there: both run the one
pipeline of :mod:`solver.path.pipeline`. Here placements go through it in chunks of about 32, which
keeps the arrays in cache, and each placement is reduced to its chosen branch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from solver.core.codes import FEASIBLE
from solver.core.malloc import raise_malloc_thresholds
from solver.core.parallel import SERIAL, TaskRunner
from solver.kernels.fixed_spin import map_cells
from solver.kernels.free_spin import free_cells
from solver.kernels.positions import limit_modes
from solver.path.pipeline import check_placements, flange_at_spin, run_chunk
from solver.path.problem import PathProblem

__all__ = ["PlacementEvaluator", "PlacementResults", "evaluate_placements"]

DEFAULT_CHUNK = 32


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
    """

    mu_path: np.ndarray
    reason: np.ndarray
    failed_waypoint: np.ndarray
    branch: np.ndarray
    bottleneck_waypoint: np.ndarray
    bottleneck_joint: np.ndarray
    v_max: np.ndarray | None = None


def _chunk(
    problem: PathProblem, placements: np.ndarray, with_speeds: bool
) -> tuple[np.ndarray, ...]:
    """Evaluate C placements: per placement mu, reason, failed, branch, bottleneck, V_max.

    V_max along the path is (C, W) when ``with_speeds``, else (C, 0): a map of millions of
    placements keeps nothing per waypoint.
    """
    run = run_chunk(problem, placements)
    branches = problem.branches
    pick, columns = run.pick, np.arange(len(placements))
    any_feasible = (run.tracked.reason == FEASIBLE).any(axis=0)
    chosen_v = np.where(any_feasible[:, None], run.v_max[pick, columns], np.nan)  # (C, W)
    worst = np.nan_to_num(chosen_v, nan=np.inf).argmin(axis=-1)
    return (
        np.where(any_feasible, run.mu_path[pick, columns], np.nan),
        run.tracked.reason[pick, columns],
        run.tracked.failed_waypoint[pick, columns],
        branches[pick],
        np.where(any_feasible, worst, -1),
        np.where(any_feasible, run.limiting[pick, columns, worst], -1),
        chosen_v if with_speeds else chosen_v[:, :0],
    )


@dataclass(frozen=True)
class _KernelInputs:
    """What the compiled kernel takes of a problem at one spin, made once per spin."""

    code: int
    parameters: np.ndarray
    rotation: np.ndarray  # (W, 3, 3), R_O_F at the spin
    position: np.ndarray  # (W, 3), m, p_O_F at the spin
    tool_position: np.ndarray
    twist: np.ndarray
    tool_axis: np.ndarray  # (W, 3), z of the tool in {O}: the spin's axis
    length: np.ndarray  # (W - 1,), m, the segments' lengths
    pure_rotation: np.ndarray
    segment_checked: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    modes: np.ndarray
    arc: np.ndarray
    qdot_max: np.ndarray
    branches: np.ndarray  # the branches followed
    max_joint_step: float
    free_spin: bool


def _kernel_inputs(
    problem: PathProblem, spin: float, kernel: tuple[int, np.ndarray]
) -> _KernelInputs:
    """The kernel's inputs of the problem's robot and path at ``spin``, as contiguous arrays."""
    robot, path = problem.robot, problem.prepared
    rotation, position = flange_at_spin(path, spin)
    modes, arc = limit_modes(robot.q_lower, robot.q_upper)
    contiguous = np.ascontiguousarray
    return _KernelInputs(
        code=kernel[0],
        parameters=kernel[1],
        rotation=contiguous(rotation),
        position=contiguous(position),
        tool_position=contiguous(path.tool_position),
        twist=contiguous(path.twist),
        tool_axis=contiguous(path.tool_rotation[:, :, 2]),
        length=np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1),
        pure_rotation=contiguous(path.pure_rotation),
        segment_checked=contiguous(path.segment_in_pass),
        lower=contiguous(robot.q_lower, dtype=float),
        upper=contiguous(robot.q_upper, dtype=float),
        modes=modes,
        arc=arc,
        qdot_max=contiguous(robot.qdot_max, dtype=float),
        branches=contiguous(problem.branches, dtype=np.int64),
        max_joint_step=float(problem.options.max_joint_step),
        free_spin=problem.options.spin_mode == "free",
    )


def _run_kernel(
    inputs: _KernelInputs, placements: np.ndarray, with_speeds: bool
) -> tuple[np.ndarray, ...]:
    """The columns of :func:`_chunk` by the compiled kernel, at placements of one spin."""
    n_cells, n_waypoints = len(placements), inputs.rotation.shape[0]
    mu = np.empty(n_cells)
    codes = [np.empty(n_cells, dtype=np.int64) for _ in range(5)]
    v_max = np.empty((n_cells, n_waypoints if with_speeds else 0))
    placed = (
        inputs.code,
        inputs.parameters,
        np.cos(placements[:, 3]),
        np.sin(placements[:, 3]),
        np.ascontiguousarray(placements[:, :3]),
        inputs.rotation,
        inputs.position,
        inputs.tool_position,
        inputs.twist,
    )
    followed = inputs.branches
    if inputs.free_spin:
        free_cells(
            *placed,
            inputs.tool_axis,
            inputs.length,
            inputs.pure_rotation,
            inputs.segment_checked,
            followed,
            inputs.lower,
            inputs.upper,
            inputs.qdot_max,
            inputs.max_joint_step,
            mu,
            *codes,
            v_max,
        )
    else:
        map_cells(
            *placed,
            inputs.pure_rotation,
            inputs.segment_checked,
            followed,
            inputs.lower,
            inputs.upper,
            inputs.modes,
            inputs.arc,
            inputs.qdot_max,
            inputs.max_joint_step,
            mu,
            *codes,
            v_max,
        )
    return (mu, *codes, v_max)


def _kernel_of(problem: PathProblem) -> tuple[int, np.ndarray] | None:
    """The compiled pose kernel of the robot's family, where it has one (either spin mode)."""
    return problem.family.map_kernel()


def _task(
    problem: PathProblem,
    with_speeds: bool,
    chunk: int,
    compiled: bool,
    placements: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """Evaluate a task's placements in chunks: the columns of :func:`_chunk`, concatenated.

    The compiled kernel (:mod:`solver.kernels.fixed_spin`, in free spin
    :mod:`solver.kernels.free_spin`), where the family has one, or else the numpy pipeline,
    both taking placements of any yaws together. A task may run in another process
    (a Dask worker), so it sets the malloc thresholds itself.
    """
    raise_malloc_thresholds()
    kernel = _kernel_of(problem) if compiled else None
    if kernel is not None:
        inputs: dict[float, _KernelInputs] = {}  # made once per spin, not once per chunk
        parts = []
        for rows in _pieces(placements, chunk):
            spin = float(rows[0, 4])
            if spin not in inputs:
                inputs[spin] = _kernel_inputs(problem, spin, kernel)
            parts.append(_run_kernel(inputs[spin], rows, with_speeds))
    else:
        parts = [_chunk(problem, rows, with_speeds) for rows in _pieces(placements, chunk)]
    return tuple(np.concatenate(c) for c in zip(*parts, strict=True))


def _pieces(placements: np.ndarray, size: int) -> list[np.ndarray]:
    """Consecutive rows, at most ``size``, cut where the spin changes (a chunk has one spin).

    Placements of several yaws share a chunk: a differential evolution's population has a yaw
    per member, and a numeric family seeds its IK for a whole chunk at once (its Python work
    is per chunk): the Panda's scipy search on 10 waypoints took 55 s cut by yaw, one placement
    a chunk.
    """
    cuts = np.flatnonzero(np.diff(placements[:, 4]) != 0.0) + 1
    return [
        run[start : start + size]
        for run in np.split(placements, cuts)
        for start in range(0, len(run), size)
    ]


def evaluate_placements(
    problem: PathProblem,
    placements: np.ndarray,
    *,
    with_speeds: bool = False,
    chunk: int = DEFAULT_CHUNK,
    progress: Callable[[float], None] | None = None,
    runner: TaskRunner = SERIAL,
    compiled: bool = True,
) -> PlacementResults:
    """mu_path of a path at each of P placements.

    Args:
        problem: the robot (with a kinematics family), the path and the options (the branch
            followed everywhere, the step bound, the spin mode).
        placements: shape (P, 5), [x (m), y (m), z (m), yaw (rad), spin (rad)] of {O} in {B}
            (:meth:`solver.core.spatial.Placement.as_row`); (P, 4) is taken with spin 0.
        with_speeds: also return V_max at every waypoint.
        chunk: placements computed together.
        progress: called with the fraction done (0..1] as tasks complete; it may raise
            (:class:`solver.core.progress.Cancelled`) to stop the work.
        runner: runs the tasks (:mod:`solver.core.parallel`); every runner gives the same answer.
        compiled: use the compiled kernel where the family has one
            (:mod:`solver.kernels.fixed_spin`); False runs the numpy pipeline, the reference.

    Raises:
        NoAnalyticIkError, InvalidInputError: as :func:`solver.path.evaluate.evaluate_path`.
    """
    _ = problem.branches  # the options checked before any work
    cells = check_placements(placements)
    raise_malloc_thresholds()
    tasks = _pieces(cells, runner.task_size(len(cells), chunk))
    completed = [0]

    def done(i: int) -> None:
        completed[0] += len(tasks[i])
        if progress is not None:
            progress(completed[0] / len(cells))

    work = partial(_task, problem, with_speeds, chunk, compiled)
    parts = runner.run(work, tasks, done)
    n_waypoints = problem.prepared.n_waypoints
    empty = (np.zeros(0), *(np.zeros(0, dtype=int),) * 5, np.zeros((0, n_waypoints)))
    columns = [np.concatenate(c) for c in zip(*parts, strict=True)] if parts else list(empty)
    mu, reason, failed, chosen, bottleneck_waypoint, bottleneck_joint, v_max = columns
    return PlacementResults(
        mu_path=mu,
        reason=reason,
        failed_waypoint=failed,
        branch=chosen,
        bottleneck_waypoint=bottleneck_waypoint,
        bottleneck_joint=bottleneck_joint,
        v_max=v_max if with_speeds else None,
    )


class PlacementEvaluator:
    """mu_path of one path at placements asked for one or a few at a time (the local searches).

    The same answers as :func:`evaluate_placements` with the same settings: the same compiled
    kernel, or that function itself where the family has no kernel. The
    kernel's inputs are made once per spin, not once per call, and no tasks are planned: the
    optimisers' Nelder-Mead climbs ask for one placement at a time, 1,200 times an
    optimisation, and that preparation cost twice the kernel's own time.
    """

    def __init__(self, problem: PathProblem) -> None:
        """An evaluator of the problem's path on its robot, on the ``auto`` branch.

        Raises:
            NoAnalyticIkError, InvalidInputError: as :func:`evaluate_placements`.
        """
        self._problem = problem.with_options(branch=None)
        _ = self._problem.branches  # the options checked first
        self._kernel = _kernel_of(self._problem)
        self._last: tuple[float, _KernelInputs] | None = None  # the spin asked for last

    def __call__(self, placements: np.ndarray) -> PlacementResults:
        """mu_path at P placements, shape (P, 5) as :func:`evaluate_placements` takes them."""
        cells = check_placements(placements)
        if self._kernel is None or np.any(cells[:, 4] != cells[0, 4]):
            return evaluate_placements(self._problem, cells)
        spin = float(cells[0, 4])
        if self._last is None or self._last[0] != spin:
            self._last = (spin, _kernel_inputs(self._problem, spin, self._kernel))
        mu, reason, failed, chosen, waypoint, joint, _ = _run_kernel(self._last[1], cells, False)
        return PlacementResults(mu, reason, failed, chosen, waypoint, joint)
