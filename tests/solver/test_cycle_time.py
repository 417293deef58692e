"""The cycle time (motion.md section 4) against toppra on toppra's own spline of the joint path."""

from __future__ import annotations

import numpy as np
import pytest
import toppra
import toppra.algorithm
import toppra.constraint

from solver.families import get_robot
from solver.path.cycle_time import cycle_time
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathProblem
from tests.cases import (
    README_CONSTANT_FEED_TIME_10,
    README_CONSTANT_FEED_TIME_ATOL,
    TOPPRA_RAMP_RTOL,
    TOPPRA_TIME_RTOL,
)
from tests.solver.test_acceleration import PLACEMENT, WAYPOINTS, smooth_path

LIMITS = np.array([3.0, 3.0, 10.0, 10.0, 10.0, 10.0])


def toppra_duration(q: np.ndarray, positions: np.ndarray, vlim: np.ndarray, alim: np.ndarray):
    """toppra's rest-to-rest time on its cubic spline of q(s), s the tool-point arc length."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))])
    spline = toppra.SplineInterpolator(s, q)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-vlim, vlim])),
        toppra.constraint.JointAccelerationConstraint(np.column_stack([-alim, alim])),
    ]
    grid = np.linspace(0.0, s[-1], 4001)
    return (
        toppra.algorithm.TOPPRA(constraints, spline, gridpoints=grid)
        .compute_trajectory(0, 0)
        .duration
    )


def evaluated(waypoints: np.ndarray, limits: np.ndarray | None, passes=None):
    robot = get_robot("ur5")
    if limits is not None:
        robot = robot.with_options(qddot_max=limits)
    problem = PathProblem.of(robot, waypoints, passes=passes)
    evaluation = evaluate_path(problem, PLACEMENT)
    return robot, evaluation, cycle_time(problem, evaluation)


def test_time_optimal_agrees_with_toppra_on_a_smooth_path() -> None:
    path = smooth_path()
    robot, evaluation, times = evaluated(path, LIMITS)
    assert times is not None and evaluation.q is not None
    expected = toppra_duration(evaluation.q, path[:, :3, 3], robot.qdot_max, LIMITS)
    assert times.time_optimal == pytest.approx(expected, rel=TOPPRA_TIME_RTOL)
    assert times.time_optimal <= times.ramp_time  # the ramped constant feed is one profile


def test_ramped_constant_feed_agrees_with_toppra_capped_at_mu_acc() -> None:
    """The pass at mu_acc with its ramps: toppra with a virtual joint q = s limited to mu_acc."""
    path = smooth_path()
    robot, evaluation, times = evaluated(path, LIMITS)
    assert times is not None and evaluation.q is not None and evaluation.acceleration is not None
    positions = path[:, :3, 3]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))])
    augmented = np.column_stack([evaluation.q, s])
    vlim = np.append(robot.qdot_max, evaluation.acceleration.mu_acc)
    expected = toppra_duration(augmented, positions, vlim, np.append(LIMITS, 1e9))
    assert times.ramp_time == pytest.approx(expected, rel=TOPPRA_RAMP_RTOL)
    one = times.passes[0]
    # Ramps: the constant-feed part runs at mu_acc.
    cruise = (
        one.length - one.ramp_up_length - one.ramp_down_length
    ) / evaluation.acceleration.mu_acc
    assert one.ramp_time == pytest.approx(cruise + one.ramp_up_time + one.ramp_down_time, rel=1e-9)
    assert one.ramp_up_time > one.ramp_up_length / evaluation.acceleration.mu_acc


def test_readme_example_at_10() -> None:
    _, evaluation, times = evaluated(WAYPOINTS, np.full(6, 10.0))
    assert times is not None
    assert times.constant_feed_time == pytest.approx(
        README_CONSTANT_FEED_TIME_10, abs=README_CONSTANT_FEED_TIME_ATOL
    )
    assert times.time_optimal <= times.constant_feed_time
    assert times.time_optimal <= times.ramp_time


@pytest.mark.parametrize("passes", [[(0, 60), (60, 133)], [(0, 2), (2, 5), (5, 133)]])
def test_passes_add_up(passes: list[tuple[int, int]]) -> None:
    """Totals are the passes' sums; a pass of two waypoints still gets finite times."""
    _, evaluation, times = evaluated(WAYPOINTS, np.full(6, 10.0), passes)
    assert times is not None and evaluation.acceleration is not None
    assert [(p.start, p.stop) for p in times.passes] == passes
    for name in ("constant_feed_time", "ramp_time", "time_optimal"):
        assert getattr(times, name) == pytest.approx(
            sum(getattr(p, name) for p in times.passes), rel=1e-12
        )
    positions = WAYPOINTS[:, :3, 3]
    for p in times.passes:
        length = np.linalg.norm(np.diff(positions[p.start : p.stop], axis=0), axis=1).sum()
        assert p.length == pytest.approx(length, rel=1e-12)
        assert p.constant_feed_time == pytest.approx(
            length / evaluation.acceleration.mu_acc, rel=1e-12
        )
        assert 0.0 < p.constant_feed_time < p.ramp_time < 10 * p.constant_feed_time + 1.0
        assert 0.0 < p.time_optimal < 10 * p.ramp_time


def test_none_without_acceleration_limits() -> None:
    _, evaluation, times = evaluated(WAYPOINTS, None)
    assert evaluation.acceleration is None and times is None
