"""mu_acc, the feed joint acceleration limits allow at a constant feed (motion.md sections 2-5).

Every check is against a computation written here: the second difference D_i from the answer's
joint path and the path's own arc lengths (numpy), toppra's spline of the joint path, the map
against the evaluator, the optimisers against the map and the evaluator.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import toppra

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import Placement, pose_matrix
from solver.families import get_robot
from solver.optimise.coarse_search import Cell
from solver.optimise.local_search import climbs
from solver.optimise.methods.placement_nlp import PlacementNlp
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds, decision_vector, variables_of
from solver.path.capability_map import capability_map
from solver.path.evaluate import PathEvaluation, evaluate_path
from solver.path.feed import check_feed
from solver.path.joint_path import evaluate_joint_path
from solver.path.placements import evaluate_placements
from solver.path.problem import PathOptions, PathProblem
from tests.cases import (
    EXAMPLES,
    MAP_EVALUATE_RTOL,
    OPTIMUM_EVALUATE_RTOL,
    README_MU_ACC,
    README_MU_ACC_ATOL,
    README_MU_ACC_JOINT,
    README_MU_ACC_WAYPOINT,
    SECOND_DIFFERENCE_RTOL,
    TOPPRA_FEED_RTOL,
)
from tests.solver.test_map_kernel import same_acceleration_cells

README = json.loads((EXAMPLES / "evaluate_request.json").read_text())
WAYPOINTS = np.array(
    [pose_matrix(w["position"], w["orientation"], field="w") for w in README["path"]["waypoints"]]
)
PLACEMENT = Placement(0.0, 0.45, 0.1, 0.0)


def ur5(acceleration: float | None) -> object:
    """The UR5 with every joint limited to ``acceleration`` rad/s^2 (None: no limits)."""
    robot = get_robot("ur5")
    return robot if acceleration is None else robot.with_options(qddot_max=[acceleration] * 6)


def smooth_path(n: int = 2000) -> np.ndarray:
    """Three quarters of a 0.1 m circle with a small wave in z, one tool orientation: (n, 4, 4)."""
    t = np.linspace(0.0, 1.5 * math.pi, n)
    poses = np.tile(np.eye(4), (n, 1, 1))
    poses[:, :3, :3] = WAYPOINTS[0, :3, :3]
    poses[:, :3, 3] = np.column_stack(
        [0.1 * np.cos(t), 0.06 + 0.1 * np.sin(t), 0.02 + 0.01 * np.sin(2 * t)]
    )
    return poses


def independent_second_difference(
    q: np.ndarray, positions: np.ndarray, passes: list[tuple[int, int]], b: float
) -> np.ndarray:
    """D_i (N, n) written from motion.md section 2 with np.interp; NaN where unconstrained."""
    second = np.full(q.shape, np.nan)
    for start, stop in passes:
        p = positions[start:stop]
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        for i in range(len(s)):
            if s[i] - b < 0.0 or s[i] + b > s[-1]:
                continue
            for j in range(q.shape[1]):
                joint = q[start:stop, j]
                ahead = np.interp(s[i] + b, s, joint)
                behind = np.interp(s[i] - b, s, joint)
                second[start + i, j] = (ahead - 2 * joint[i] + behind) / b**2
    return second


def check_against_independent(
    evaluation: PathEvaluation,
    positions: np.ndarray,
    passes: list[tuple[int, int]],
    limits: np.ndarray,
    b: float,
) -> None:
    """qdd_at_mu_acc = D_i mu_acc^2 and mu_acc = min(mu_path, min sqrt(a / |D|)), from D_i here."""
    acc = evaluation.acceleration
    assert acc is not None and evaluation.q is not None and evaluation.mu_path is not None
    second = independent_second_difference(evaluation.q, positions, passes, b)
    constrained = ~np.isnan(second[:, 0])
    assert constrained.any()
    np.testing.assert_array_equal(np.isnan(acc.qdd[:, 0]), ~constrained)
    np.testing.assert_allclose(
        acc.qdd[constrained],
        second[constrained] * acc.mu_acc**2,
        rtol=SECOND_DIFFERENCE_RTOL,
        atol=SECOND_DIFFERENCE_RTOL * np.abs(second[constrained]).max() * acc.mu_acc**2,
    )
    with np.errstate(divide="ignore"):
        v_acc = np.sqrt(limits / np.abs(second[constrained])).min(axis=1)
    expected = min(evaluation.mu_path, float(v_acc.min()))
    assert acc.mu_acc == pytest.approx(expected, rel=SECOND_DIFFERENCE_RTOL)
    binds = "acceleration" if v_acc.min() < evaluation.mu_path else "speed"
    assert acc.limited_by == binds
    if binds == "acceleration":
        i = int(np.flatnonzero(constrained)[np.argmin(v_acc)])
        assert acc.waypoint == i
        assert acc.joint == int(np.argmin(np.sqrt(limits / np.abs(second[i]))))
    # The joint that binds sits exactly on its acceleration limit (the invariant).
    if binds == "acceleration":
        assert abs(acc.qdd[acc.waypoint, acc.joint]) == pytest.approx(
            limits[acc.joint], rel=SECOND_DIFFERENCE_RTOL
        )


@pytest.mark.parametrize("acceleration", sorted(README_MU_ACC))
def test_readme_example_known_answer(acceleration: float) -> None:
    evaluation = evaluate_path(PathProblem.of(ur5(acceleration), WAYPOINTS), PLACEMENT)
    acc = evaluation.acceleration
    assert acc is not None
    assert acc.mu_acc == pytest.approx(README_MU_ACC[acceleration], abs=README_MU_ACC_ATOL)
    assert acc.limited_by == "acceleration"
    assert (acc.waypoint, acc.joint) == (README_MU_ACC_WAYPOINT, README_MU_ACC_JOINT)
    assert acc.blend_length == 0.002


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
@pytest.mark.parametrize(
    ("acceleration", "blend", "passes"),
    [
        (10.0, 0.002, None),
        (3.0, 0.005, None),
        (10.0, 0.002, [(0, 60), (60, 133)]),
        (40.0, 0.001, [(0, 2), (2, 133)]),  # a pass shorter than 2 b: no constraint on it
    ],
)
def test_second_difference_is_the_independent_one(
    spin_mode: str, acceleration: float, blend: float, passes: list[tuple[int, int]] | None
) -> None:
    options = PathOptions(spin_mode=spin_mode, blend_length=blend)  # type: ignore[arg-type]
    problem = PathProblem.of(ur5(acceleration), WAYPOINTS, options, passes=passes)
    evaluation = evaluate_path(problem, PLACEMENT)
    limits = np.full(6, acceleration)
    ranges = passes or [(0, len(WAYPOINTS))]
    check_against_independent(evaluation, WAYPOINTS[:, :3, 3], ranges, limits, blend)


def test_free_spin_uses_the_joint_path_along_the_spins() -> None:
    """In free spin the answer's q is along its spins, and D_i is of that joint path."""
    problem = PathProblem.of(ur5(10.0), WAYPOINTS, PathOptions(spin_mode="free"))
    evaluation = evaluate_path(problem, PLACEMENT)
    assert evaluation.spins is not None and np.ptp(evaluation.spins) > 0.0
    check_against_independent(evaluation, WAYPOINTS[:, :3, 3], [(0, 133)], np.full(6, 10.0), 0.002)


def test_large_limits_give_mu_path_exactly() -> None:
    evaluation = evaluate_path(PathProblem.of(ur5(1e6), WAYPOINTS), PLACEMENT)
    assert evaluation.acceleration is not None
    assert evaluation.acceleration.mu_acc == evaluation.mu_path
    assert evaluation.acceleration.limited_by == "speed"
    assert evaluation.acceleration.waypoint == evaluation.bottleneck_waypoint
    assert evaluation.acceleration.joint == evaluation.bottleneck_joint


def test_no_limits_answer_as_before() -> None:
    without = evaluate_path(PathProblem.of(ur5(None), WAYPOINTS), PLACEMENT)
    limited = evaluate_path(PathProblem.of(ur5(10.0), WAYPOINTS), PLACEMENT)
    assert without.acceleration is None and without.feed_index == without.mu_path
    assert limited.mu_path == without.mu_path  # mu_path keeps its meaning
    assert limited.acceleration is not None and limited.feed_index < without.mu_path
    np.testing.assert_array_equal(limited.v_max, without.v_max)


def test_smooth_path_agrees_with_toppras_spline() -> None:
    """mu_acc against min over the path of sqrt(a / |q_ss|) with toppra's spline of q(s)."""
    path = smooth_path()
    limits = np.array([1.0, 3.0, 3.0, 10.0, 10.0, 10.0])
    robot = get_robot("ur5").with_options(qddot_max=limits)
    evaluation = evaluate_path(PathProblem.of(robot, path), PLACEMENT)
    assert evaluation.acceleration is not None and evaluation.q is not None
    positions = path[:, :3, 3]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))])
    spline = toppra.SplineInterpolator(s, evaluation.q)
    grid = np.linspace(0.002, s[-1] - 0.002, 40_001)
    toppra_feed = min(
        float(np.min(robot.qdot_max / np.abs(spline(grid, 1)))),
        float(np.min(np.sqrt(limits / np.abs(spline(grid, 2))))),
    )
    assert evaluation.acceleration.limited_by == "acceleration"
    assert evaluation.acceleration.mu_acc == pytest.approx(toppra_feed, rel=TOPPRA_FEED_RTOL)


def test_auto_branch_is_the_fastest_by_mu_acc() -> None:
    robot = ur5(3.0)
    problem = PathProblem.of(robot, WAYPOINTS)
    chosen = evaluate_path(problem, PLACEMENT)
    assert chosen.feed_index is not None
    for branch in robot.family.branches:  # type: ignore[union-attr]
        other = evaluate_path(problem.with_options(branch=branch), PLACEMENT)
        if other.feed_index is not None:
            assert other.feed_index <= chosen.feed_index * (1 + 1e-12)


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
def test_map_cells_equal_evaluate(spin_mode: str) -> None:
    problem = PathProblem.of(ur5(10.0), WAYPOINTS, PathOptions(spin_mode=spin_mode))  # type: ignore[arg-type]
    grid = capability_map(
        problem,
        xs=np.array([-0.1, 0.0, 0.1]),
        ys=np.array([0.4, 0.45]),
        z=0.1,
        yaws=np.array([0.0, 0.5]),
    )
    assert grid.mu_acc is not None and grid.limited_by is not None
    assert grid.acc_waypoint is not None and grid.acc_joint is not None
    feasible = 0
    for index in np.ndindex(grid.mu_path.shape):
        evaluation = evaluate_path(problem, grid.placement(index))
        if evaluation.acceleration is None:
            assert np.isnan(grid.mu_acc[index]) and grid.limited_by[index] == -1
            continue
        feasible += 1
        acc = evaluation.acceleration
        assert grid.mu_acc[index] == pytest.approx(acc.mu_acc, rel=MAP_EVALUATE_RTOL)
        assert grid.mu_path[index] == pytest.approx(evaluation.mu_path, rel=MAP_EVALUATE_RTOL)
        assert grid.limited_by[index] == (1 if acc.limited_by == "acceleration" else 0)
        assert (grid.acc_waypoint[index], grid.acc_joint[index]) == (acc.waypoint, acc.joint)
    assert feasible >= 4


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_optimisers_maximise_mu_acc(method: str) -> None:
    """Both optimisers: at least the best map cell, and the evaluator's mu_acc at their answer."""
    problem = PathProblem.of(ur5(10.0), WAYPOINTS)
    bounds = PlacementBounds(x=(-0.1, 0.1), y=(0.35, 0.55), yaw=(-0.3, 0.3), z=0.1)
    grid = capability_map(
        problem,
        xs=np.linspace(-0.1, 0.1, 6),
        ys=np.linspace(0.35, 0.55, 6),
        z=0.1,
        yaws=np.linspace(-0.3, 0.3, 5),
    )
    best = grid.extreme(best=True)
    assert best is not None and grid.mu_acc is not None
    optimum = optimize_placement(problem, bounds=bounds, method=method)
    assert optimum.found and optimum.placement is not None and optimum.mu_acc is not None
    assert optimum.mu_acc >= grid.mu_acc[best] * (1 - 1e-12)
    again = evaluate_path(problem, optimum.placement)
    assert again.acceleration is not None
    assert again.acceleration.mu_acc == pytest.approx(optimum.mu_acc, rel=OPTIMUM_EVALUATE_RTOL)
    assert optimum.mu_path == again.mu_path


@pytest.mark.parametrize(
    ("limits", "named"),
    [
        ([10.0] * 5, "6 joints"),
        ([10.0, 10.0, -1.0, 10.0, 10.0, 10.0], "elbow_joint"),
        ([10.0] * 5 + [math.nan], "wrist_3_joint"),
        ([0.0] * 6, "shoulder_pan_joint"),
        ([1e9] * 6, "shoulder_pan_joint"),
    ],
)
def test_bad_acceleration_limits_name_the_field_and_joint(limits: list[float], named: str) -> None:
    with pytest.raises(InvalidInputError) as error:
        get_robot("ur5").with_options(qddot_max=limits)
    assert error.value.field == "robot.joint_acceleration_limits"
    assert named in error.value.message


@pytest.mark.parametrize("blend", [0.0, -0.001, math.inf, math.nan, 1e-12, 1e-100, 2.0, 1000.0])
def test_bad_blend_length_names_the_field(blend: float) -> None:
    """Not a corner zone: at 1e-100 m s +- b rounded to s and mu_acc was mu_path (at 1e-12 it
    was 3.8e-6 m/s); at 1000 m the blended path ran far beyond the 0.32 m pass."""
    problem = PathProblem.of(ur5(10.0), WAYPOINTS, PathOptions(blend_length=blend))
    with pytest.raises(InvalidInputError) as error:
        evaluate_path(problem, PLACEMENT)
    assert error.value.field == "ik.blend_length"


def test_nlp_rows_hold_the_joint_accelerations() -> None:
    """IPOPT's optimum keeps |D_ij| s^2 <= a_j (D_i written here from its own joint path)."""
    problem = PathProblem.of(ur5(10.0), WAYPOINTS)
    bounds = PlacementBounds(x=(-0.1, 0.1), y=(0.35, 0.55), yaw=(-0.3, 0.3), z=0.1)
    start = evaluate_path(problem, PLACEMENT)
    assert start.branch is not None and start.q is not None and start.feed_index is not None
    assert start.qdot is not None and start.v_max is not None
    speed = start.feed_index
    nlp = PlacementNlp(problem, bounds)
    result = nlp.solve(
        decision_vector(x=0.0, y=0.45, yaw=0.0, spin=0.0, z=0.1),
        speed,
        start.q,
        start.qdot * (speed / start.v_max)[:, None],
    )
    assert result.success
    assert result.speed > speed  # the optimum runs faster than the start
    second = independent_second_difference(
        result.joint_path, WAYPOINTS[:, :3, 3], [(0, len(WAYPOINTS))], 0.002
    )
    use = np.nanmax(np.abs(second) * result.speed**2 / 10.0)
    assert use == pytest.approx(1.0, abs=1e-6)  # the acceleration rows bind at the optimum
    named = variables_of(result.vector)
    placed = Placement(float(named.x), float(named.y), float(named.z), float(named.yaw))
    again = evaluate_path(problem.with_options(branch=start.branch), placed)
    assert again.feed_index == pytest.approx(result.speed, rel=1e-6)


def test_feed_check_uses_both_limits() -> None:
    """At F = mu_acc the binding joint uses its whole acceleration limit, and no joint more."""
    robot = ur5(10.0)
    evaluation = evaluate_path(PathProblem.of(robot, WAYPOINTS), PLACEMENT)
    acc = evaluation.acceleration
    assert acc is not None and robot.qddot_max is not None
    at = check_feed(evaluation, acc.mu_acc, robot.qdot_max, qddot_max=robot.qddot_max)
    assert at.feasible and at.acceleration_use is not None and at.use is not None
    assert np.nanmax(at.acceleration_use) == pytest.approx(1.0, rel=1e-12)
    assert at.acceleration_use[acc.waypoint, acc.joint] == pytest.approx(1.0, rel=1e-12)
    assert np.nanmax(at.use) <= 1.0
    faster = check_feed(evaluation, acc.mu_acc * 1.01, robot.qdot_max, qddot_max=robot.qddot_max)
    assert not faster.feasible and faster.margin == pytest.approx(1 / 1.01, rel=1e-12)


def test_a_given_joint_path_gets_the_same_mu_acc() -> None:
    """evaluate_joint_path (the redundant arms' judge) along the tracked path: the same mu_acc."""
    problem = PathProblem.of(ur5(10.0), WAYPOINTS)
    tracked = evaluate_path(problem, PLACEMENT)
    assert tracked.q is not None and tracked.acceleration is not None
    given = evaluate_joint_path(problem, PLACEMENT, tracked.q)
    assert given.acceleration is not None
    assert given.acceleration.mu_acc == pytest.approx(tracked.acceleration.mu_acc, rel=1e-9)
    assert (given.acceleration.waypoint, given.acceleration.joint) == (
        tracked.acceleration.waypoint,
        tracked.acceleration.joint,
    )


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
def test_compiled_maps_equal_the_pipeline(spin_mode: str) -> None:
    """With acceleration limits the compiled kernels run (tests/solver/test_map_kernel.py) and
    give the pipeline's cells on the README path too."""
    problem = PathProblem.of(ur5(10.0), WAYPOINTS, PathOptions(spin_mode=spin_mode))  # type: ignore[arg-type]
    cells = np.array([[x, 0.45, 0.1, yaw, 0.0] for x in (-0.1, 0.0, 0.1) for yaw in (0.0, 0.3)])
    compiled = evaluate_placements(problem, cells, with_speeds=True)
    reference = evaluate_placements(problem, cells, with_speeds=True, compiled=False)
    same_acceleration_cells(compiled, reference, 10.0, problem.options.blend_length)
    np.testing.assert_array_equal(compiled.branch, reference.branch)
    np.testing.assert_allclose(compiled.mu_path, reference.mu_path, rtol=1e-12, atol=0.0)
    assert reference.limited_by is not None and set(reference.limited_by) == {1}
    without = evaluate_placements(PathProblem.of(ur5(None), WAYPOINTS), cells)
    assert without.mu_acc is None and without.limited_by is None


@pytest.mark.parametrize(("acceleration", "index"), [(10.0, "mu_acc"), (None, "mu_path")])
def test_a_climb_names_the_index_it_climbed(acceleration: float | None, index: str) -> None:
    """With acceleration limits the Nelder-Mead climb maximises mu_acc (the feed index), and its
    candidate's status says so (it said mu_path, the index it did not climb)."""
    posed = PathProblem.of(ur5(acceleration), WAYPOINTS[::8])
    bounds = PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(0.0, 0.0), z=0.1)
    start = evaluate_placements(posed, bounds.rows(bounds.centre()[None]))
    cell = Cell(bounds.centre(), float(start.feed_index[0]), int(start.branch[0]))
    (climbed,) = climbs(posed, bounds, [cell])
    assert climbed.status == f"Nelder-Mead on {index}, from a refined cell"
