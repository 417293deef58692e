"""The kernels' acceleration hook against the numpy limit, on the same joint paths.

Both map kernels form D from a branch's joint steps (:func:`solver.kernels.limits.step_stencil`,
:func:`solver.kernels.limits.acceleration_at`). The kernel comparisons (test_map_kernel.py,
test_free_spin_kernel.py) see it through joint angles that differ from the pipeline's in the
last bits, so here, on paths the hook and :class:`solver.path.limits.JointAccelerationLimit`
share: the same numbers, exact ties, the same bits for joint paths whose steps are equal or
opposite (what lets the kernels leave a branch tied with an earlier one), the steps along the
spin schedule against the spun path's; and the kernels' joint path
(:func:`solver.kernels.positions.relative_path`) against track()'s.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.codes import FEASIBLE
from solver.kernels.accelerations import pair_steps, spun_steps
from solver.kernels.limits import acceleration_at, step_stencil
from solver.kernels.positions import relative_path
from solver.kernels.spin_schedule import spun_failure
from solver.path.blend_stencil import BlendStencil
from solver.path.limits import JointAccelerationLimit, JointMotion


def numpy_bound(path: np.ndarray, limit: JointAccelerationLimit) -> tuple[np.ndarray, int, int]:
    """V_acc per waypoint by the numpy limit, and where the least binds (the pipeline's rule)."""
    q = path.T
    speed, joint = limit.speed_bound(JointMotion(q=q, qd_unit=np.zeros_like(q)))
    low = int(np.argmin(speed))
    return speed, low, int(joint[low])


@pytest.mark.parametrize("largest_step", [0.02, 0.3, 3.0])
def test_relative_path_is_the_unwrapped_path(largest_step: float) -> None:
    """The fixed-spin kernel's joint path from its (cos, sin) pairs (steps by the asin series
    where small, atan2 otherwise) against track()'s: the first angle plus the wrapped steps."""
    rng = np.random.default_rng(7)
    angles = np.cumsum(rng.uniform(-largest_step, largest_step, (2, 6, 100)), axis=-1)
    angles = np.angle(np.exp(1j * angles))  # in [-pi, pi], as IK gives them
    cq, sq = np.cos(angles), np.sin(angles)
    step = np.diff(angles, axis=-1)
    step -= np.where(step > np.pi, 2 * np.pi, np.where(step < -np.pi, -2 * np.pi, 0.0))
    expected = np.concatenate([angles[..., :1], angles[..., :1] + np.cumsum(step, axis=-1)], -1)
    for b in range(2):
        np.testing.assert_allclose(relative_path(cq, sq, b, True), expected[b].T, atol=1e-13)
        np.testing.assert_allclose(
            relative_path(cq, sq, b, False), (expected[b] - expected[b, :, :1]).T, atol=1e-13
        )


def step_form(path: np.ndarray, limit: JointAccelerationLimit) -> tuple[np.ndarray, np.ndarray]:
    """max_j |D_j| / a_j and its joint at every stencil row, from the path's steps."""
    stencil = limit.stencil
    steps = np.zeros_like(path)
    steps[1:] = np.diff(path, axis=0)
    c = step_stencil(stencil.index, stencil.weight)
    rows = [
        acceleration_at(steps, stencil.index[k, 0], stencil.index, c, k, limit.qddot_max)
        for k in range(len(stencil.waypoints))
    ]
    return np.array([r[0] for r in rows]), np.array([r[1] for r in rows])


@pytest.mark.parametrize("seed", range(5))
def test_the_step_form_equals_the_numpy_limit(seed: int) -> None:
    """Random tool points (uneven spacing, several points within b, two passes) and joint
    paths: V_acc and its joint from the steps equal the numpy limit's from the angles."""
    rng = np.random.default_rng(seed)
    n = 90
    tool = np.cumsum(rng.uniform(0.0001, 0.003, (n, 3)), axis=0)
    in_pass = np.ones(n - 1, dtype=bool)
    in_pass[45] = False
    limit = JointAccelerationLimit(
        rng.uniform(2.0, 30.0, 6), BlendStencil.of_path(tool, in_pass, 0.002)
    )
    path = np.cumsum(rng.normal(0.0, 0.01, (n, 6)), axis=0) + rng.uniform(-3.0, 3.0, 6)
    ratio, joint = step_form(path, limit)
    speed, _, _ = numpy_bound(path, limit)
    _, joints = limit.speed_bound(JointMotion(q=path.T, qd_unit=np.zeros_like(path.T)))
    waypoints = limit.stencil.waypoints
    np.testing.assert_allclose(1.0 / np.sqrt(ratio), speed[waypoints], rtol=1e-12, atol=0.0)
    np.testing.assert_array_equal(joint, joints[waypoints])


def test_the_step_form_is_exact_on_a_parabola() -> None:
    """q = s^2 on points 0.25 m apart with b = 0.5 m: D = 2 exactly at every row."""
    s = np.arange(12) * 0.25
    tool = np.column_stack([s, np.zeros(12), np.zeros(12)])
    limit = JointAccelerationLimit(
        np.full(6, 4.0), BlendStencil.of_path(tool, np.ones(11, dtype=bool), 0.5)
    )
    path = np.zeros((12, 6))
    path[:, 3] = s**2
    path[:, 4] = -(s**2)
    ratio, joint = step_form(path, limit)
    assert np.all(ratio == 0.5) and np.all(joint == 3)


def test_a_joint_moved_by_pi_or_mirrored_gives_the_same_bits() -> None:
    """A joint path, the same moved by pi (a UR's wrist_3 on the other wrist) and its mirror
    image, as (cos, sin) pairs: the kernel's steps (:func:`pair_steps`) and then the ratios
    at every row are the same to the bit, as the angles' size does not enter D."""
    rng = np.random.default_rng(3)
    n = 60
    tool = np.cumsum(rng.uniform(0.001, 0.003, (n, 3)), axis=0)
    limit = JointAccelerationLimit(
        np.full(6, 10.0), BlendStencil.of_path(tool, np.ones(n - 1, dtype=bool), 0.002)
    )
    angles = np.cumsum(rng.normal(0.0, 0.05, (6, n)), axis=1) + rng.uniform(-3.0, 3.0, (6, 1))
    cq = np.stack([np.cos(angles), -np.cos(angles), np.cos(angles)])
    sq = np.stack([np.sin(angles), -np.sin(angles), -np.sin(angles)])
    index = limit.stencil.index
    c = step_stencil(index, limit.stencil.weight)
    rows = []
    for b in range(3):
        steps = np.zeros((n, 6))
        pair_steps(cq, sq, b, 0, n - 1, steps)
        rows.append(
            [
                acceleration_at(steps, index[k, 0], index, c, k, limit.qddot_max)
                for k in range(len(index))
            ]
        )
    assert rows[0] == rows[1] == rows[2]
    speed, _, _ = numpy_bound(angles.T.copy(), limit)
    ratio = np.array([r[0] for r in rows[0]])
    np.testing.assert_allclose(1.0 / np.sqrt(ratio), speed[limit.stencil.waypoints], rtol=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_the_spun_steps_are_the_spin_schedules_path(seed: int) -> None:
    """The free-spin kernel's steps along the spin schedule (:func:`spun_steps`) against the
    steps of the joint path the schedule's tracking forms (:func:`spun_failure`)."""
    rng = np.random.default_rng(seed)
    n = 50
    angles = np.cumsum(rng.uniform(-0.05, 0.05, (8, 6, n)), axis=-1)
    cq, sq = np.cos(angles), np.sin(angles)
    qd = rng.normal(0.0, 10.0, (8, 6, n))  # the feed alone would break the speed limits
    qs = rng.uniform(0.5, 1.0, (8, 6, n)) * rng.choice([-1.0, 1.0], (8, 6, n))
    length = rng.uniform(0.001, 0.003, n - 1)
    qdot_max = np.full(6, 3.0)
    b, rate = 2, 0.2
    spun = np.empty((n, 6))
    code, _ = spun_failure(
        relative_path(cq, sq, b, True), qd, qs, b, rate, length, np.ones(n - 1, dtype=bool),
        np.full(6, -100.0), np.full(6, 100.0), qdot_max, np.pi, spun,
    )  # fmt: skip
    assert code == FEASIBLE
    steps = np.zeros((n, 6))
    spun_steps(cq, sq, qd, qs, b, 0, n - 1, rate, length, qdot_max, steps)
    moved = np.diff(spun, axis=0) - np.diff(angles[b].T, axis=0)
    assert np.abs(moved).max() > 1e-3  # the spin moves the joints
    np.testing.assert_allclose(steps[1:], np.diff(spun, axis=0), rtol=0.0, atol=1e-13)
