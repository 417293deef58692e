"""The cycle time (motion.md section 4) against toppra.

The time-optimal profile against toppra on the blended joint path written here (parabolic
blends of length b around each waypoint, straight in between: the running mean of the
piecewise-linear joint path over b), sampled on a uniform grid of its own; the ramps against
toppra on its own spline of the joint path.
"""

from __future__ import annotations

import numpy as np
import pytest
import toppra
import toppra.algorithm
import toppra.constraint

from solver.core.spatial import Placement
from solver.families import get_robot
from solver.kernels.feed_profile import time_optimal
from solver.path.blended_path import blended_path, interval_points
from solver.path.cycle_time import cycle_time
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.cases import (
    README_CONSTANT_FEED_TIME_10,
    README_CONSTANT_FEED_TIME_ATOL,
    TOPPRA_RAMP_RTOL,
    TOPPRA_TIME_RTOL,
)
from tests.solver.test_acceleration import PLACEMENT, WAYPOINTS, smooth_path
from tests.toppra_grid import duration, toppra_speeds

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


class BlendedPath(toppra.interpolator.AbstractGeometricPath):  # type: ignore[misc]
    """The blended joint path of a pass (motion.md section 4), written from its definition.

    q_s(s) = (q(s + b/2) - q(s - b/2)) / b and q_ss(s) = (q'(s + b/2) - q'(s - b/2)) / b, q(s)
    the joint path linear between waypoints and continued along the end segments.
    """

    def __init__(self, q: np.ndarray, positions: np.ndarray, blend: float) -> None:
        self.s = np.concatenate(
            [[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))]
        )
        self.q, self.b = q, blend
        self.slope = np.diff(q, axis=0) / np.diff(self.s)[:, None]

    def joints(self, s: np.ndarray) -> np.ndarray:
        out = np.column_stack([np.interp(s, self.s, self.q[:, j]) for j in range(6)])
        out += np.minimum(s, 0.0)[:, None] * self.slope[0]
        return out + np.maximum(s - self.s[-1], 0.0)[:, None] * self.slope[-1]

    def slopes(self, s: np.ndarray) -> np.ndarray:
        k = np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.s) - 2)
        return self.slope[k]

    def __call__(self, at: float | np.ndarray, order: int = 0) -> np.ndarray:
        s, h = np.atleast_1d(np.asarray(at, dtype=float)), self.b / 2
        if order == 0:
            out = self.joints(s)
        elif order == 1:
            out = (self.joints(s + h) - self.joints(s - h)) / self.b
        else:
            out = (self.slopes(s + h) - self.slopes(s - h)) / self.b
        return out if np.ndim(at) else out[0]

    @property
    def dof(self) -> int:
        return 6

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([0.0, self.s[-1]])


def toppra_on_the_blended_path(
    q: np.ndarray, positions: np.ndarray, vlim: np.ndarray, alim: np.ndarray
) -> float:
    """toppra's rest-to-rest time on :class:`BlendedPath` (b = 2 mm), a uniform 20 um grid."""
    path = BlendedPath(q, positions, 0.002)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-vlim, vlim])),
        toppra.constraint.JointAccelerationConstraint(np.column_stack([-alim, alim])),
    ]
    grid = np.linspace(0.0, path.s[-1], int(path.s[-1] / 2e-5) + 1)
    return (
        toppra.algorithm.TOPPRA(constraints, path, gridpoints=grid)
        .compute_trajectory(0, 0)
        .duration
    )


@pytest.mark.parametrize("case", ["readme at 10", "smooth"])
def test_time_optimal_agrees_with_toppra_on_the_blended_path(case: str) -> None:
    """The README example (corners 2.3 to 2.6 mm apart: blends with straight stretches
    between, where the feed rises again) and a smooth path (blends overlapping)."""
    path, limits = (
        (WAYPOINTS, np.full(6, 10.0)) if case == "readme at 10" else (smooth_path(), LIMITS)
    )
    robot, evaluation, times = evaluated(path, limits)
    assert times is not None and evaluation.q is not None
    expected = toppra_on_the_blended_path(evaluation.q, path[:, :3, 3], robot.qdot_max, limits)
    assert times.time_optimal == pytest.approx(expected, rel=TOPPRA_TIME_RTOL)
    assert times.time_optimal <= times.ramp_time  # the ramped constant feed is one profile


@pytest.mark.parametrize("case", ["readme at 3", "readme at 10", "readme at 100", "smooth"])
def test_the_time_optimal_profile_is_toppras_on_the_same_grid(case: str) -> None:
    """The compiled TOPP-RA against toppra itself, on the blended path's own grid.

    The profile to 1e-7 m^2/s^2 (toppra lowers each step's x by 1e-8 and solves its LPs to
    tolerances of that order; the kernel keeps the first), the time to 1e-9.
    """
    at = {"readme at 3": 3.0, "readme at 10": 10.0, "readme at 100": 100.0}
    path, limits = (WAYPOINTS, np.full(6, at[case])) if case in at else (smooth_path(), LIMITS)
    robot, evaluation, times = evaluated(path, limits)
    assert times is not None and evaluation.q is not None and evaluation.acceleration is not None
    positions = path[:, :3, 3]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))])
    grid, q_s, q_ss = blended_path(evaluation.q, s, evaluation.acceleration.blend_length)
    speeds = toppra_speeds(grid, q_s, q_ss, robot.qdot_max, limits)
    profile = time_optimal(grid, q_s, q_ss, robot.qdot_max, limits)
    np.testing.assert_allclose(profile, speeds**2, rtol=0.0, atol=1e-7)
    assert times.time_optimal == pytest.approx(duration(grid, speeds), rel=1e-9)


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
    # Ramps: the part between them runs at mu_acc at most (a little below it where the blended
    # path's grid allows less than mu_acc's stencil: 0.05 % of the time here).
    cruise = (
        one.length - one.ramp_up_length - one.ramp_down_length
    ) / evaluation.acceleration.mu_acc
    at_mu_acc = cruise + one.ramp_up_time + one.ramp_down_time
    assert at_mu_acc * (1.0 - 1e-12) <= one.ramp_time <= at_mu_acc * (1.0 + 1e-3)
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


def test_the_grid_is_numpys_linspace_of_every_interval() -> None:
    """The blended path's grid, made at once, is one linspace an interval: the same floats."""
    rng = np.random.default_rng(48)
    for _ in range(50):
        ends = np.unique(np.append(0.0, rng.uniform(0.0, rng.uniform(0.001, 3.0), 300)))
        step = float(rng.uniform(1e-5, 0.05))
        expected = np.concatenate(
            [
                np.linspace(left, right, max(int(np.ceil((right - left) / step - 1e-9)), 1) + 1)[
                    :-1
                ]
                for left, right in zip(ends[:-1], ends[1:], strict=True)
            ]
        )
        np.testing.assert_array_equal(interval_points(ends, step), expected)


@pytest.mark.parametrize(
    ("waypoints", "blend"),
    [(20, 0.002), (20, 0.01), (20, 0.1), (20, 1.0), (3, 0.002)],
)
def test_the_time_optimal_time_is_never_above_the_ramped_one(waypoints: int, blend: float) -> None:
    """motion.md: the time-optimal time is a lower bound of every feed profile, the pass at
    mu_acc with its ramps one of them. Ramps integrated point by point (each step's
    acceleration bounded at its start) gave 0.303475 s against 0.305261 at b = 0.01 m on the
    README path's first 20 waypoints, 0.289022 against 0.291301 at 0.1 m, 0.067632 against
    0.067653 on three. Both are now profiles of one discretisation: the ramped one is the
    time-optimal one with the feed held to mu_acc, so it is never faster; and it is toppra's
    capped at mu_acc (the test above) to 1 %.
    """
    robot = get_robot("ur5").with_options(qddot_max=np.full(6, 10.0))
    problem = PathProblem.of(robot, WAYPOINTS[:waypoints], options=PathOptions(blend_length=blend))
    evaluation = evaluate_path(problem, PLACEMENT)
    times = cycle_time(problem, evaluation)
    assert evaluation.feasible and times is not None
    for one in times.passes:
        assert one.time_optimal <= one.ramp_time
        assert one.constant_feed_time <= one.ramp_time


def test_a_speed_limited_cruise_ramps_down_only_at_its_end() -> None:
    """A straight 0.1 m line at 1e6 rad/s^2: the feed reaches mu_acc (= mu_path, the speed
    limit binds) within a fraction of a mm and stops as fast, so the ramps are short and, the
    line being run at one speed limit, alike. The capped profile sits 5e-9 below mu_acc^2 on
    its cruise (TOPP-RA's margin): counted as not reaching it, the ramp down ran from the
    start's one highest point, 99.75 of the 100 mm."""
    line = np.repeat(np.diag([1.0, -1.0, -1.0, 1.0])[None], 21, axis=0)  # tool pointing down
    line[:, 0, 3] = np.linspace(-0.05, 0.05, 21)
    robot = get_robot("ur5").with_options(qddot_max=np.full(6, 1e6))
    problem = PathProblem.of(robot, line)
    evaluation = evaluate_path(problem, PLACEMENT)
    times = cycle_time(problem, evaluation)
    assert evaluation.feasible and times is not None
    (one,) = times.passes
    assert one.length == pytest.approx(0.1, rel=1e-12)
    assert 0.0 < one.ramp_up_length < 1e-3 and 0.0 < one.ramp_down_length < 1e-3
    assert one.ramp_down_length == pytest.approx(one.ramp_up_length, rel=0.1)
    assert one.ramp_time == pytest.approx(one.constant_feed_time, rel=0.02)


def test_a_slow_cruise_ramps_as_joint_1_can_at_both_ends() -> None:
    """The tool point 0.3 rad out on a 0.45 m arc about the base axis and back: joint 1 alone
    moves (q1_s = 1/r), and the reversal's blend sets mu_acc = sqrt(a r b / 2) = 0.067 m/s.
    From rest joint 1's acceleration bounds sddot by a r, so each ramp is mu_acc^2 / (2 a r)
    long and takes mu_acc / (a r) (geometry), on the grid's b / 16 steps. The capped profile
    cruises 2.2e-6 of mu_acc^2 below it there (TOPP-RA's 1e-8 margin): counted as not at
    mu_acc, the ramp down ran from the one highest point, 0.269 m of the 0.27 m pass."""
    radius, limit, blend = 0.45, 10.0, 0.002
    turns = np.concatenate([np.linspace(0.0, 0.3, 31), np.linspace(0.3, 0.0, 31)[1:]])
    arc = np.repeat(np.diag([1.0, -1.0, -1.0, 1.0])[None], len(turns), axis=0)  # tool down
    for k, turn in enumerate(turns):
        c, s = np.cos(turn), np.sin(turn)
        arc[k, :3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ arc[k, :3, :3]
        arc[k, :3, 3] = [radius * c, radius * s, 0.2]
    robot = get_robot("ur5").with_options(qddot_max=np.full(6, limit))
    problem = PathProblem.of(robot, arc, PathOptions(blend_length=blend))
    evaluation = evaluate_path(problem, Placement(0.0, 0.0, 0.0, 0.0))
    times = cycle_time(problem, evaluation)
    assert evaluation.acceleration is not None and times is not None
    mu = evaluation.acceleration.mu_acc
    chord = np.linalg.norm(np.diff(arc[:31, :3, 3], axis=0), axis=1).sum() / 0.3  # r of the chords
    assert mu == pytest.approx(np.sqrt(limit * chord * blend / 2), rel=1e-3)
    ramp_length, ramp_time = mu**2 / (2 * limit * radius), mu / (limit * radius)
    (one,) = times.passes
    step = blend / 16
    for length, seconds in (
        (one.ramp_up_length, one.ramp_up_time),
        (one.ramp_down_length, one.ramp_down_time),
    ):
        assert length == pytest.approx(ramp_length, abs=step)
        assert seconds == pytest.approx(ramp_time, rel=1e-2)
