"""The joint path a run on one branch gives, each placement on its own branch (a reference).

A map with a cell checks each feasible placement's chosen joint path
(:mod:`solver.path.path_checks`): the compiled kernel's (:mod:`solver.path.kernel_branches`),
or the numpy pipeline run's own. :func:`tracked_joint_paths` tracks an analytic family's IK on
each placement's own branch as the pipeline tracks it, without the joint speeds: what the
kernel's joint paths are tested against (tests/solver/test_cell_batch.py).
"""

from __future__ import annotations

import numpy as np

from solver.core.family import PathSolutions
from solver.path.placed import placed_flange
from solver.path.problem import PathProblem
from solver.path.tracking import track


def tracked_joint_paths(
    problem: PathProblem,
    placements: np.ndarray,
    rows: np.ndarray,
    solutions: PathSolutions | None = None,
) -> np.ndarray | None:
    """The joint paths a run on one branch gives, each placement on its own branch.

    What :func:`solver.path.pipeline.run_chunk` tracks at placement c with the problem's
    branch set to the family's branch ``rows[c]``, without the joint speeds (a path check
    needs the angles alone); one IK solve for every placement.

    Args:
        problem: the problem (fixed spin: free spin tracks its spin schedule's path).
        placements: shape (C, 5), one spin, checked.
        rows: shape (C,), an index into the family's branches per placement.
        solutions: the family's IK at the placements, if already solved.

    Returns:
        shape (C, W, n), rad; None where the family answers in slots (numeric IK) or the
        spin is free: there :func:`solver.path.pipeline.run_chunk` on each branch is the way.
    """
    if problem.options.spin_mode == "free":
        return None
    if solutions is None:
        _, rotation, flange_position = placed_flange(problem, placements)
        solutions = problem.family.solve_path(rotation, flange_position)
    if solutions.slots is not None:
        return None
    cells = np.arange(len(placements))
    robot = problem.robot
    tracked = track(
        solutions.q[:, rows, cells][:, None],  # (n, 1, C, W): one branch, as run_chunk's
        solutions.status[rows, cells][None],
        lower=robot.q_lower,
        upper=robot.q_upper,
        max_joint_step=problem.options.max_joint_step,
        segment_checked=problem.prepared.segment_in_pass,
    )
    joint_paths: np.ndarray = tracked.q[:, 0].transpose(1, 2, 0)
    return joint_paths
