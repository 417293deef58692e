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

from solver.core.codes import FEASIBLE
from solver.core.family import Branch
from solver.families import get_robot
from solver.path.pipeline import run_chunk
from solver.path.placements import evaluate_placements
from tests.problems import prepare_path
from tests.solver.families.test_opw import build
from tests.solver.test_evaluate import load_path, wrist_singular_path
from tests.solver.test_map_kernel import (
    ACCELERATIONS,
    COLUMNS,
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


def half_turn_passes(
    n_passes: int = 8, per_pass: int = 5
) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Passes of a horizontal tool (z along -y of {O}, x along x) in two alternating lanes.

    A tool axis with no vertical part gives the UR wrist's q6 as atan2 of an exact (signed)
    zero: 0 or pi. Each rapid from one lane to the other turns the wrist over (z1 x z5 changes
    its direction), and q6 jumps by exactly half a turn, one way and back. The feature of the
    corpus program aamorim_boss.apt (a UR5e free-spin cell of 126, issue 23), in a few poses.
    """
    rotation = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    poses: list[np.ndarray] = []
    passes: list[tuple[int, int]] = []
    for k in range(n_passes):
        start = len(poses)
        lane = k % 2
        for i in range(per_pass):
            pose = np.eye(4)
            pose[:3, :3] = rotation
            pose[:3, 3] = [-0.123 - 0.0005 * i - 0.0001 * k, 0.0267 - 0.05 * lane,
                           0.074 - 0.0005 * i + 0.006 * lane]  # fmt: skip
            poses.append(pose)
        passes.append((start, len(poses)))
    return np.array(poses), passes


@pytest.mark.parametrize("elbow", ["up", "down"])
def test_half_turns_at_rapids_keep_their_sign(elbow: str) -> None:
    """A joint that turns by exactly pi at a rapid turns the way track() says, every time.

    track() takes the step of the two angles' difference: 0 -> -pi is -pi and -pi -> 0 is +pi,
    so q6 goes to and fro. The kernel's step of the (cos, sin) pairs took atan2 of a cross
    product rounded to +0.0, +pi both ways: q6 climbed by a turn every two rapids and failed
    its +-2 pi limits (joint_limits) where the pipeline's path holds (before the fix: 12 cells
    of 27 on each of these branches). The lanes lie on both sides of the wrist singularity, so
    J^-1 divides by sin q5 (down to 0.003 here): mu_path agrees to 1e-13 / min |sin q5| of
    each cell (1.5e-11 at the nearest), the discrete columns exactly.
    """
    robot = get_robot("ur5e")
    poses, passes = half_turn_passes()
    branch = Branch.named(shoulder="right", elbow=elbow, wrist="noflip")
    problem = prepare_path(robot, poses, passes=passes)
    on_branch = problem.with_options(branch=branch, spin_mode="free")
    cells = grid(np.array([0.28, 0.3, 0.32]), np.array([0.58, 0.6, 0.62]), 0.0,
                 np.array([1.45, 1.5, 1.55]))  # fmt: skip
    cells = np.column_stack([cells, np.zeros(len(cells))])  # spin 0
    q = run_chunk(on_branch, cells).tracked.q  # (6, 1, C, W), the pipeline's joint paths
    centre = q[5, 0, len(cells) // 2]
    half_turns = np.flatnonzero(np.abs(np.diff(centre)) == math.pi)
    assert len(half_turns) >= 4  # the fixture shows the feature: exact half turns, both ways
    assert not np.any(np.asarray(on_branch.prepared.segment_in_pass)[half_turns])  # at rapids
    compiled = evaluate_placements(on_branch, cells)
    numpy = evaluate_placements(on_branch, cells, compiled=False)
    for name in COLUMNS:
        np.testing.assert_array_equal(getattr(compiled, name), getattr(numpy, name), err_msg=name)
    assert np.all(numpy.reason == FEASIBLE)
    conditioning = np.abs(np.sin(q[4, 0])).min(axis=-1)
    error = np.abs(compiled.mu_path - numpy.mu_path) / numpy.mu_path
    assert np.all(error <= 1e-13 / conditioning)
