"""Free spin on a seven-joint arm (issue 27): the spin rate a variable of the redundant LP.

For seven joints the DTF with the tool spin free is max s s.t. J qdot = s t_hat + sigma [0; z],
|qdot| <= qdot_max, with sigma free (cam.md section 2, dtf.md section 3): three variables
(s, sigma, and the null-space rate). The known answers are that LP written here for HiGHS
(scipy.optimize.linprog) on pinocchio's Jacobian of the Panda; the pipeline solves it compiled
(:mod:`solver.kernels.spin_lp`), and both it and the numpy reference are held to HiGHS.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
from scipy.spatial.transform import Rotation

from solver.core import dtf_redundant
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.spatial import Placement, pose_matrix
from solver.families import get_robot
from solver.kernels import spin_lp as compiled_lp
from tests.cases import EXAMPLES, FREE_SPIN_LP_RTOL, MAP_EVALUATE_RTOL
from tests.problems import capability_map, evaluate_path
from tests.solver.test_evaluate import segment_twists

PLACEMENT = Placement(0.0, 0.45, 0.1, 0.0)


def spin_lp(jacobian: np.ndarray, twist: np.ndarray, axis: np.ndarray, limits: np.ndarray) -> float:
    """HiGHS on max s s.t. J qdot - s t_hat - sigma [0; z] = 0, |qdot| <= limits, sigma free."""
    n = jacobian.shape[1]
    cost = np.zeros(n + 2)
    cost[n] = -1.0
    a_eq = np.hstack([jacobian, -twist[:, None], -np.concatenate([np.zeros(3), axis])[:, None]])
    result = scipy.optimize.linprog(
        cost,
        A_eq=a_eq,
        b_eq=np.zeros(6),
        bounds=[(-m, m) for m in limits] + [(0.0, None), (None, None)],
        method="highs",
        options={"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10},
    )
    assert result.status == 0, result.message
    return float(result.x[n])


IMPLEMENTATIONS = {"numpy": dtf_redundant, "compiled": compiled_lp}


@pytest.mark.parametrize("implementation", IMPLEMENTATIONS)
def test_the_three_variable_lp_equals_highs_and_its_joint_speeds_are_within_limits(
    implementation: str,
) -> None:
    spin_speed = IMPLEMENTATIONS[implementation].spin_speed
    spin_rate_at_feed = IMPLEMENTATIONS[implementation].spin_rate_at_feed
    robot = get_robot("panda")
    rng = np.random.default_rng(27)
    a, c, b, lp, jacobians, twists, axes = [], [], [], [], [], [], []
    while len(lp) < 300:
        q = rng.uniform(robot.q_lower, robot.q_upper)
        jacobian = jacobian_in_base(robot, q)
        if np.linalg.cond(jacobian) > 1e4:
            continue
        twist = np.concatenate([rng.normal(size=3), rng.normal(size=3) / rng.uniform(0.01, 2.0)])
        axis = tool_pose_in_base(robot, q)[:3, 2]
        pinv = np.linalg.pinv(jacobian)
        a.append(pinv @ twist)
        c.append(pinv @ np.concatenate([np.zeros(3), axis]))
        b.append(scipy.linalg.null_space(jacobian)[:, 0])
        lp.append(spin_lp(jacobian, twist, axis, robot.qdot_max))
        jacobians.append(jacobian), twists.append(twist), axes.append(axis)
    a_, c_, b_ = (np.array(v).T for v in (a, c, b))
    speed, limiting = spin_speed(a_, c_, b_, robot.qdot_max)
    np.testing.assert_allclose(speed, lp, rtol=FREE_SPIN_LP_RTOL)
    sigma, lam = spin_rate_at_feed(a_, c_, b_, robot.qdot_max, speed)
    qdot = speed * a_ + sigma * c_ + lam * b_
    load = np.abs(qdot) / robot.qdot_max[:, None]
    assert np.all(load <= 1 + 1e-9)
    np.testing.assert_allclose(load[limiting, np.arange(300)], 1.0, rtol=1e-6)
    for m in range(0, 300, 30):  # J qdot = s t_hat + sigma [0; z]
        spin = np.concatenate([np.zeros(3), axes[m]])
        expected = speed[m] * twists[m] + sigma[m] * spin
        np.testing.assert_allclose(jacobians[m] @ qdot[:, m], expected, atol=1e-9)
    # A free spin is never slower than the fixed one (sigma = 0 is a choice).
    fixed = np.array([
        scipy.optimize.linprog(
            np.r_[np.zeros(7), -1.0],
            A_eq=np.hstack([jacobians[m], -twists[m][:, None]]),
            b_eq=np.zeros(6),
            bounds=[(-v, v) for v in robot.qdot_max] + [(0.0, None)],
            method="highs",
        ).x[7]
        for m in range(0, 300, 30)
    ])  # fmt: skip
    assert np.all(speed[::30] >= fixed * (1 - 1e-9))


def test_the_compiled_lps_equal_the_numpy_reference_on_degenerate_rows_too() -> None:
    """Random directions with rows that are not finite, zero, repeated or at feed 0."""
    rng = np.random.default_rng(2027)
    count = 2_000
    a, c, b = (rng.normal(size=(7, count)) for _ in range(3))
    limits = rng.uniform(0.5, 3.0, 7)
    a[:, 3], b[2, 8] = np.nan, np.inf  # not finite: NaN speed, spin rates 0
    a[4, 10] = c[4, 10] = b[4, 10] = 0.0  # a joint that nothing moves
    a[:, 12], c[:, 12], b[:, 12] = a[:, 11], c[:, 11], b[:, 11]
    c[:, 13] = 0.0  # rank 2: no vertex (vertex_lp needs rank 3), NaN in both
    reference = dtf_redundant.spin_speed(a, c, b, limits)
    compiled = compiled_lp.spin_speed(a, c, b, limits)
    np.testing.assert_allclose(compiled[0], reference[0], rtol=1e-12)
    np.testing.assert_array_equal(compiled[1], reference[1])
    assert np.isnan(compiled[0][[3, 8, 13]]).all() and np.isfinite(compiled[0][[10, 12]]).all()
    feed = np.where(np.isfinite(reference[0]), reference[0], 0.0)
    feed = feed * rng.choice([0.0, 0.5, 0.99, 1.0], count)
    rates = dtf_redundant.spin_rate_at_feed(a, c, b, limits, feed)
    compiled_rates = compiled_lp.spin_rate_at_feed(a, c, b, limits, feed)
    inside = feed < reference[0] * 0.999  # at the optimum the interval is ~1e-12 wide
    for ours, theirs in zip(compiled_rates, rates, strict=True):
        np.testing.assert_allclose(ours[inside], theirs[inside], rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours, theirs, atol=1e-9)
    assert compiled_rates[0][3] == compiled_rates[1][3] == 0.0


@pytest.fixture(scope="module")
def path() -> np.ndarray:
    """The first ten waypoints of the example path, (10, 4, 4)."""
    waypoints = json.loads((EXAMPLES / "evaluate_request.json").read_text())["path"]["waypoints"]
    return np.array(
        [pose_matrix(w["position"], w["orientation"], field="w") for w in waypoints[:10]]
    )


def test_the_pandas_free_spin_path_runs_at_the_lp_of_each_waypoint(path: np.ndarray) -> None:
    """V_max at every waypoint = the test's LP at the answer's own joint path; mu_path its least.

    A seven-joint arm's spin moves every joint, so the joint path is solved at the spun poses
    (solver/path/exact_spin.py) and judged as that path: at each waypoint the seven-joint DTF
    (max s: J qdot = s t_hat, |qdot| <= qdot_max) with t_hat of the path turned by the answer's
    spins (scipy's rotation vectors here). Before, V_max was the LP with the spin rate free at
    the unspun configurations, and the joint path the schedule's first-order sum.
    """
    robot = get_robot("panda")
    free = evaluate_path(robot, path, PLACEMENT, spin_mode="free")
    assert free.feasible and free.v_max is not None and free.qdot is not None
    assert free.spins is not None and free.branch is not None and free.q is not None
    assert np.ptp(free.spins) > 0.01  # the spin turns the tool here
    turns = Rotation.from_rotvec(np.outer(free.spins, [0.0, 0.0, 1.0])).as_matrix()
    poses = PLACEMENT.transform_workpiece_to_base() @ path
    poses[:, :3, :3] = poses[:, :3, :3] @ turns
    reached = np.array([tool_pose_in_base(robot, q) for q in free.q])
    assert np.abs(reached - poses).max() < 1e-9
    expected = [
        spin_lp(jacobian_in_base(robot, q), twist, np.zeros(3), robot.qdot_max)
        for q, twist in zip(free.q, segment_twists(poses), strict=True)
    ]
    np.testing.assert_allclose(free.v_max, expected, rtol=FREE_SPIN_LP_RTOL)
    assert free.mu_path == pytest.approx(min(expected), rel=FREE_SPIN_LP_RTOL)
    fixed = evaluate_path(robot, path, PLACEMENT, branch=free.branch)
    assert fixed.feasible and fixed.mu_path is not None and free.mu_path > fixed.mu_path
    assert np.all(np.abs(free.qdot) <= robot.qdot_max * (1 + 1e-9))


def test_a_free_spin_map_of_the_panda_equals_evaluate(path: np.ndarray) -> None:
    robot = get_robot("panda")
    cmap = capability_map(
        robot,
        path,
        xs=np.array([-0.05, 0.05]),
        ys=np.array([0.4, 0.5]),
        z=0.1,
        yaws=np.zeros(1),
        spin_mode="free",
    )
    for index in np.ndindex(cmap.mu_path.shape):
        expected = evaluate_path(robot, path, cmap.placement(index), spin_mode="free")
        assert expected.feasible and expected.mu_path is not None
        assert cmap.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
