"""Numeric IK in batches: each problem comes out as if solved alone, compacted or not.

Below ``ik.COMPACT_MIN_ROWS`` rows, converged problems stay in ``ik.solve``'s batch (and lost
branches in the tracking's), frozen; above it they are copied out once half the batch is done.
A batch of one never compacts and has no batch-mates, so it is the reference each row of a large
batch is held to, bit for bit; pinocchio's forward kinematics checks the solutions themselves.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.families.numeric import ik
from solver.families.numeric.family import NumericFamily
from tests.cases import FK_IK_ATOL
from tests.solver.test_evaluate import load_path

ITERATIONS = 6  # the farther starts do not converge; the batch compacts twice


def family_of(robot: Robot) -> NumericFamily:
    assert isinstance(robot.family, NumericFamily)
    return robot.family


def problems(robot: Robot, count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Starts (count, n) at 0.01 to 2 rad from configurations whose flange poses are the targets.

    The spread makes rows converge at different iterations, and some not within ``ITERATIONS``,
    so a batch holds every kind of row.
    """
    rng = np.random.default_rng(seed)
    target = rng.uniform(np.maximum(robot.q_lower, -np.pi), np.minimum(robot.q_upper, np.pi))
    target = target + rng.uniform(-1.0, 1.0, (count, robot.dof))
    offset = rng.normal(size=(count, robot.dof))
    offset *= np.geomspace(0.01, 2.0, count)[:, None] / np.linalg.norm(offset, axis=1)[:, None]
    rotation, position = family_of(robot).chain.forward(target)
    return target + offset, rotation, position


@pytest.mark.parametrize("name", ["panda", "kinova_jaco2"])
def test_each_row_of_a_large_batch_is_solved_as_if_alone(name: str) -> None:
    robot = get_robot(name)
    chain = family_of(robot).chain
    start, rotation, position = problems(robot, 3 * ik.COMPACT_MIN_ROWS, seed=11)
    q, converged = ik.solve(chain, start, rotation, position, iterations=ITERATIONS)
    assert 0.5 < converged.mean() < 0.95  # both kinds: a mix-up between rows would show
    for i in range(len(start)):
        alone, reached = ik.solve(
            chain, start[i : i + 1], rotation[i : i + 1], position[i : i + 1],
            iterations=ITERATIONS,
        )  # fmt: skip
        np.testing.assert_array_equal(q[i], alone[0])
        assert converged[i] == reached[0]
    for i in np.flatnonzero(converged):
        pose = tool_pose_in_base(robot, q[i])  # pinocchio, not the chain
        np.testing.assert_allclose(pose[:3, :3], rotation[i], rtol=0, atol=FK_IK_ATOL)
        np.testing.assert_allclose(pose[:3, 3], position[i], rtol=0, atol=FK_IK_ATOL)


@pytest.mark.parametrize("rows", [8, 3 * ik.COMPACT_MIN_ROWS])
def test_frozen_rows_stay_at_their_start_and_do_not_count_as_converged(rows: int) -> None:
    robot = get_robot("panda")
    chain = family_of(robot).chain
    start, rotation, position = problems(robot, rows, seed=12)
    frozen = np.arange(rows) % 3 == 0
    q, converged = ik.solve(chain, start, rotation, position, iterations=ITERATIONS, frozen=frozen)
    np.testing.assert_array_equal(q[frozen], start[frozen])
    assert not converged[frozen].any()
    free, reached = ik.solve(
        chain, start[~frozen], rotation[~frozen], position[~frozen],
        iterations=ITERATIONS,
    )  # fmt: skip
    np.testing.assert_array_equal(q[~frozen], free)
    np.testing.assert_array_equal(converged[~frozen], reached)


def test_tracking_many_placements_at_once_is_tracking_each_alone() -> None:
    """The Panda along the ERK path at 12 placements, the farther ones beyond its reach."""
    family = family_of(get_robot("panda"))
    path = load_path("curved_line")
    placements = [Placement(x, 0.0, 0.1, 0.0) for x in np.linspace(0.3, 1.0, 12)]
    poses = np.stack([p.transform_workpiece_to_base() @ path for p in placements])
    rotation = np.moveaxis(poses[..., :3, :3], (-2, -1), (0, 1))  # (3, 3, P, W)
    position = np.moveaxis(poses[..., :3, 3], -1, 0)  # (3, P, W)
    together = family.solve_path(rotation, position)
    started = np.isfinite(together.q[0, :, :, 0])
    lost = started & np.isnan(together.q[0, :, :, -1])
    # Enough branches, and enough of them lost midway, that the tracking batch compacts.
    assert started.sum() >= ik.COMPACT_MIN_ROWS and 2 * lost.sum() >= started.sum()
    for p in range(len(placements)):
        alone = family.solve_path(rotation[:, :, p : p + 1], position[:, p : p + 1])
        np.testing.assert_array_equal(together.q[:, :, p], alone.q[:, :, 0])
        np.testing.assert_array_equal(together.status[:, p], alone.status[:, 0])
        assert together.branches_found[p] == alone.branches_found[0]
