"""The compiled joint paths of chosen branches equal the numpy pipeline's tracked paths.

:func:`solver.path.kernel_cells.kernel_joint_paths` (the map's joint paths for the cell, compiled)
against :func:`solver.path.pipeline.run_chunk` with every branch followed: the family's numpy IK
(checked against ur-analytic-ik and py-opw-kinematics elsewhere) and
:func:`solver.path.tracking.track`. On every branch feasible at a placement, every joint and
waypoint agrees to 1e-12 rad, the 2 pi copy included. In free spin the paths along each branch's
spin schedule at its own mu_path (the pipeline's ``tracked`` in free mode).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from solver.core.codes import FEASIBLE
from solver.core.robots import Robot
from solver.families import get_robot
from solver.path.kernel_cells import kernel_inputs, kernel_joint_paths, kernel_of
from solver.path.pipeline import run_chunk
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_evaluate import load_path
from tests.solver.test_parallel import grid_placements


def _narrow(name: str) -> Robot:
    """A UR5e whose position limits span less than a turn (the narrow tests and copies)."""
    return dataclasses.replace(
        get_robot(name), q_lower=np.full(6, -math.pi / 2), q_upper=np.full(6, math.pi)
    )


@pytest.mark.parametrize(
    ("robot", "path", "shift"),
    [
        (get_robot("ur5"), "curved_line", (0.0, 0.0)),
        (get_robot("ur5"), "s_curve", (0.0, 0.0)),
        (_narrow("ur5e"), "curved_line", (0.0, 0.0)),
        (get_robot("kuka_kr16_2"), "curved_line", (0.6, 0.0)),
        (get_robot("abb_irb2400"), "s_curve", (0.5, -0.2)),
    ],
    ids=["ur5", "ur5-s", "ur5e-narrow", "kr16", "irb2400-s"],
)
@pytest.mark.parametrize("spin", ["fixed", "free"])
def test_kernel_joint_paths_equal_the_tracked_paths(
    robot: Robot, path: str, shift: tuple[float, float], spin: str
) -> None:
    problem = PathProblem.of(robot, load_path(path), PathOptions(spin_mode=spin))  # type: ignore[arg-type]
    placements = grid_placements()
    placements[:, 0] += shift[0]
    placements[:, 1] += shift[1]
    placements = np.column_stack([placements, np.zeros(len(placements))])
    kernel = kernel_of(problem)
    assert kernel is not None
    inputs = kernel_inputs(problem, 0.0, kernel)
    reference = run_chunk(problem, placements)  # every branch followed to the end
    feasible = reference.tracked.reason == FEASIBLE  # (B, C)
    compared, moved = 0, 0.0
    for b, branch in enumerate(problem.branches):
        cells = np.flatnonzero(feasible[b])
        if not len(cells):
            continue
        feeds = reference.mu_path[b, cells]  # the free spin schedule's feed
        paths = kernel_joint_paths(inputs, placements[cells], np.full(len(cells), branch), feeds)
        expected = reference.tracked.q[:, b, cells].transpose(1, 2, 0)  # (C, W, 6)
        np.testing.assert_allclose(paths, expected, rtol=0.0, atol=1e-12)
        compared += len(cells)
        if spin == "free":  # the schedule moves the joints (not the fixed path at zero spin)
            still = kernel_joint_paths(
                inputs, placements[cells], np.full(len(cells), branch), 0 * feeds
            )
            moved = max(moved, float(np.abs(paths - still).max()))
    assert compared >= 20, compared  # enough feasible (branch, placement) pairs to mean much
    assert spin == "fixed" or moved > 0.05, moved


def test_each_placement_takes_its_own_branch() -> None:
    """Rows pick the branch per placement: two placements, two branches, in one call."""
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line"))
    placements = np.array([[0.0, 0.45, 0.1, 0.0, 0.0], [0.05, 0.45, 0.1, 0.3, 0.0]])
    kernel = kernel_of(problem)
    assert kernel is not None
    inputs = kernel_inputs(problem, 0.0, kernel)
    reference = run_chunk(problem, placements)
    pairs = [
        (b, c)
        for c in range(2)
        for b in range(len(problem.branches))
        if reference.tracked.reason[b, c] == FEASIBLE
    ]
    first = pairs[0]
    second = next(p for p in pairs if p[1] == 1 and p[0] != first[0])
    rows = np.array([problem.branches[first[0]], problem.branches[second[0]]])
    paths = kernel_joint_paths(inputs, placements, rows)
    for k, (b, c) in enumerate((first, second)):
        np.testing.assert_allclose(paths[k], reference.tracked.q[:, b, c].T, rtol=0.0, atol=1e-12)


def test_a_free_spin_path_needs_its_feed() -> None:
    """In free spin the schedule runs at the branch's mu_path: without it, a ValueError."""
    problem = PathProblem.of(
        get_robot("ur5"), load_path("curved_line"), PathOptions(spin_mode="free")
    )
    kernel = kernel_of(problem)
    assert kernel is not None
    inputs = kernel_inputs(problem, 0.0, kernel)
    with pytest.raises(ValueError, match="feed"):
        kernel_joint_paths(inputs, np.array([[0.0, 0.45, 0.1, 0.0, 0.0]]), np.array([0]))
