"""The free-spin map kernel equals the numpy pipeline's free mode, cell by cell.

As tests/solver/test_map_kernel.py, with the tool spin rate free (cam.md section 2): the same
reasons, failed waypoints, branches and bottlenecks, mu_path and V_max to 1e-12 relative. In
free spin the position limits are checked on the joint path moved by the spin schedule only,
so every joint-limit cell here comes from the kernel's second pass. That the kernel is what
runs in free spin is checked in test_map_kernel.py. With joint acceleration limits
(``accelerations``) mu_acc is taken along the spun joint path, as test_map_kernel.py compares.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from solver.core.family import Branch
from solver.families import get_robot
from tests.solver.families.test_opw import build
from tests.solver.test_evaluate import load_path, wrist_singular_path
from tests.solver.test_map_kernel import (
    ACCELERATIONS,
    OPW_CASES,
    Accelerations,
    grid,
    opw_grid,
    same_cells,
)
from tests.solver.test_parallel import grid_placements

FREE = {"spin_mode": "free"}
EVERY_REASON = {"feasible", "unreachable", "joint_limits", "singular", "discontinuous"}


@pytest.mark.parametrize("accelerations", ACCELERATIONS)
def test_erk_grid_and_eight_yaws(accelerations: Accelerations) -> None:
    erk = grid(
        np.arange(-0.25, 0.25 + 1e-9, 0.02), np.arange(0.25, 0.65 + 1e-9, 0.02), 0.1, np.zeros(1)
    )
    acc = {"accelerations": accelerations, **FREE}
    result, _ = same_cells(get_robot("ur5"), load_path("curved_line"), erk, **acc)
    assert np.isfinite(result.mu_path).all()
    if accelerations is not None:  # the limits bind on every cell, or (1e6) on none
        assert result.limited_by is not None
        assert set(result.limited_by) == {0 if np.min(accelerations) > 100.0 else 1}
    placements = grid_placements()
    shuffled = placements[np.random.default_rng(3).permutation(len(placements))]
    _, reasons = same_cells(get_robot("ur5"), load_path("s_curve"), shuffled, **acc)
    assert {"feasible", "unreachable"} <= reasons


@pytest.mark.parametrize("accelerations", [None, 10.0])
def test_wide_grids_with_every_reason(accelerations: float | None) -> None:
    seen: set[str] = set()
    acc = {"accelerations": accelerations, **FREE}
    wide = grid(
        np.linspace(-1.0, 1.0, 11), np.linspace(-1.0, 1.0, 11), 0.1, np.array([0.0, 2.0, -2.5])
    )
    ur5e = get_robot("ur5e")
    for lower, upper in ((-math.pi / 2, math.pi), (-math.pi, math.pi)):  # an arc; one turn
        robot = dataclasses.replace(ur5e, q_lower=np.full(6, lower), q_upper=np.full(6, upper))
        _, reasons = same_cells(robot, load_path("curved_line"), wide, **acc)
        assert "joint_limits" in reasons
        seen |= reasons
    singular = grid(np.array([-0.05, 0.0, 0.05]), np.array([0.0, 0.05]), 0.0, np.array([0.0, 0.2]))
    branch = Branch.named(shoulder="left", elbow="up", wrist="flip")
    for choice in (None, branch):
        _, reasons = same_cells(ur5e, wrist_singular_path(ur5e), singular, branch=choice, **acc)
        seen |= reasons
    assert EVERY_REASON <= seen


@pytest.mark.parametrize("accelerations", ACCELERATIONS)
def test_steps_passes_and_one_branch(accelerations: Accelerations) -> None:
    """A tight step, no step bound, passes (each restarts the spin), a fixed branch."""
    free = {"spin_mode": "free", "accelerations": accelerations}
    robot = get_robot("ur10")
    waypoints = load_path("s_curve")
    placements = grid(np.linspace(-0.6, 0.6, 7), np.linspace(0.2, 1.0, 5), 0.2, np.array([0.5]))
    _, tight = same_cells(robot, waypoints, placements, max_joint_step=0.02, **free)
    assert "discontinuous" in tight
    same_cells(robot, waypoints, placements, max_joint_step=4.0, **free)
    half = len(waypoints) // 2
    passes = [(0, half), (half, len(waypoints))]
    same_cells(robot, waypoints, placements, passes=passes, **free)
    narrow = dataclasses.replace(
        get_robot("ur5e"), q_lower=np.full(6, -math.pi / 2), q_upper=np.full(6, math.pi)
    )
    wide = grid(np.linspace(-1.0, 1.0, 9), np.linspace(-1.0, 1.0, 9), 0.1, np.array([0.0, 2.0]))
    _, reasons = same_cells(
        narrow, load_path("curved_line"), wide, passes=[(0, 60), (60, 133)], **free
    )
    assert "joint_limits" in reasons
    fixed = Branch.named(shoulder="right", elbow="down", wrist="noflip")
    result, _ = same_cells(robot, waypoints, placements, branch=fixed, **free)
    assert set(result.branch) == {robot.family.branch_index(fixed)}  # type: ignore[union-attr]


@pytest.mark.parametrize("accelerations", [None, 10.0])
@pytest.mark.parametrize(("name", "expected"), OPW_CASES)
def test_opw_arms(name: str, expected: set[str], accelerations: float | None) -> None:
    robot = build(name)
    acc = {"accelerations": accelerations, **FREE}
    _, reasons = same_cells(robot, load_path("curved_line"), opw_grid(robot), **acc)
    assert expected <= reasons
