"""The acceleration scan's floor (solver.kernels.acc_scan): where the limits cannot bind.

A branch that passed the step test has every step of a stencil row at most ``max_joint_step``,
so V_acc is at least a floor the stencil and the limits give, and a branch whose mu_path is
below it is not scanned (mu_acc = mu_path). Here: the floor is below V_acc on joint paths whose
steps keep the bound, and reached by the path that makes one row's D largest (numpy's
limit on paths written in the test); and maps that read no V_acc per waypoint (where the floor
is taken) equal the numpy pipeline where the floor is below every cell, among them and above
every cell, in both spin modes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.families import get_robot
from solver.kernels.acc_scan import scan_work
from solver.kernels.limits import step_stencil
from solver.path.limits import JointAccelerationLimit, JointMotion
from tests.cases import KERNEL_ACC_ULPS
from tests.problems import evaluate_placements, prepare_path
from tests.solver.test_evaluate import load_path
from tests.solver.test_map_kernel import COLUMNS, grid

LIMITS = np.array([12.0, 10.0, 14.0, 30.0, 8.0, 6.0])  # rad/s^2, the least on joint 5


def floor_of(limit: JointAccelerationLimit, checked: np.ndarray, max_joint_step: float) -> float:
    """The kernel's floor (m/s) for a path's stencil and limits."""
    index = np.ascontiguousarray(limit.stencil.index, dtype=np.int64)
    c = step_stencil(index, np.ascontiguousarray(limit.stencil.weight))
    rows = scan_work(index, c, int(checked.size) + 1, checked, max_joint_step, limit.qddot_max)
    return float(rows[8])


def erk_limit(qddot_max: np.ndarray) -> tuple[JointAccelerationLimit, np.ndarray, float]:
    """The ERK path's acceleration limit, where the step test applies, and the step bound."""
    robot = get_robot("ur5").with_options(qddot_max=list(qddot_max))
    problem = prepare_path(robot, load_path("curved_line"))
    (limit,) = problem.final_path_limits
    assert isinstance(limit, JointAccelerationLimit)
    checked = np.ascontiguousarray(problem.prepared.segment_in_pass)
    return limit, checked, problem.options.max_joint_step


def least_speed(limit: JointAccelerationLimit, path: np.ndarray) -> float:
    """The least V_acc (m/s) along a joint path (W, 6) by numpy's limit."""
    speed, _ = limit.speed_bound(JointMotion(q=path.T, qd_unit=np.zeros_like(path.T)))
    return float(speed.min())


def test_the_floor_bounds_v_acc_and_is_reached() -> None:
    """Random joint paths whose steps keep the bound are never slower than the floor; on each
    stencil row, the path whose steps take the bound with the sign of their weight in D (each
    step weighs the stencil weights of the waypoints at or after it) on the joint of the least
    limit reaches it, to the floor's margins."""
    limit, checked, step = erk_limit(LIMITS)
    floor = floor_of(limit, checked, step)
    n = checked.size + 1
    rng = np.random.default_rng(5)
    for _ in range(20):
        steps = rng.uniform(-step, step, (n - 1, 6))
        path = np.vstack([rng.uniform(-3.0, 3.0, (1, 6)), np.zeros((n - 1, 6))])
        path[1:] = path[0] + np.cumsum(steps, axis=0)
        assert least_speed(limit, path) >= floor
    reached = math.inf
    for index, weight in zip(limit.stencil.index, limit.stencil.weight, strict=True):
        sign = np.zeros(n - 1)
        for w in range(index[0] + 1, index[-1] + 1):  # step w moves q_w and every later q
            sign[w - 1] = np.sign(weight[index >= w].sum())
        path = np.zeros((n, 6))
        path[1:, 5] = np.cumsum(step * sign)
        reached = min(reached, least_speed(limit, path))
    assert floor <= reached <= floor * (1.0 + 1e-5)


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
@pytest.mark.parametrize("where", ["below", "among", "above"])
def test_maps_without_speeds_equal_the_pipeline(spin_mode: str, where: str) -> None:
    """The ERK map's first four columns with V_acc per waypoint not asked for (so the floor is
    taken): every column identical to the numpy pipeline's, mu_acc to the rounding of the joint
    angles, and mu_acc = mu_path exactly on the cells whose mu_path is below the floor."""
    placements = grid(-0.25 + 0.02 * np.arange(4), np.arange(0.25, 0.65 + 1e-9, 0.02), 0.1, [0.0])
    mode = {"spin_mode": spin_mode}
    robot = get_robot("ur5")
    speeds = evaluate_placements(
        robot, prepare_path(robot, load_path("curved_line")), placements, **mode
    ).mu_path
    reference = floor_of(*erk_limit(LIMITS))  # the floor scales with the square root of a
    scale = {"below": 1.0, "among": (np.median(speeds) / reference) ** 2, "above": 1e5}[where]
    limits = LIMITS * scale
    floor = floor_of(*erk_limit(limits))
    limited = robot.with_options(qddot_max=list(limits))
    path = prepare_path(limited, load_path("curved_line"))
    compiled = evaluate_placements(limited, path, placements, **mode)
    numpy = evaluate_placements(limited, path, placements, compiled=False, **mode)
    below = compiled.mu_path < floor
    expected = {"below": 0, "among": None, "above": below.size}[where]
    assert (0 < below.sum() < below.size) if expected is None else below.sum() == expected
    for name in (*COLUMNS, "limited_by", "acc_waypoint", "acc_joint"):
        np.testing.assert_array_equal(getattr(compiled, name), getattr(numpy, name), err_msg=name)
    assert compiled.mu_acc is not None and numpy.mu_acc is not None
    blend = path.options.blend_length  # the rounding of test_map_kernel.same_acceleration_cells
    rounding = KERNEL_ACC_ULPS * np.spacing(2 * math.pi) * 4 / blend**2 / limits.min()
    np.testing.assert_allclose(compiled.mu_acc**-2.0, numpy.mu_acc**-2.0, rtol=2e-12, atol=rounding)
    np.testing.assert_array_equal(compiled.mu_acc[below], compiled.mu_path[below])
