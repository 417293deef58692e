"""Free tool spin (cam.md section 2): the two-variable LP, the spin schedule, map = evaluate."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.optimize

from solver.core.exceptions import InvalidInputError, RepeatedWaypointError
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.spatial import Placement
from solver.core.two_variable_lp import spin_rate_nearest_zero, two_variable_speed
from solver.families import get_robot, robot_from_urdf
from solver.optimise.search_space import PlacementBounds
from tests.cases import (
    FREE_SPIN_LP_RTOL,
    MAP_EVALUATE_RTOL,
    OPTIMUM_EVALUATE_RTOL,
    OPTIMUM_METHODS_RTOL,
    SPIN_SCHEDULE_RTOL,
)
from tests.problems import capability_map, evaluate_path, optimize_placement
from tests.solver.test_evaluate import load_path
from tests.solver.test_optimize import best_coarse_cell

README_PLACEMENT = Placement(0.0, 0.45, 0.1, 0.0)


def _free_spin_lp(jacobian: np.ndarray, twist: np.ndarray, axis: np.ndarray, limits: np.ndarray):
    """HiGHS on max s s.t. J qdot = s t_hat + sigma [0; z], |qdot| <= limits (sigma free)."""
    n = jacobian.shape[1]
    cost = np.zeros(n + 2)
    cost[n] = -1.0
    spin = np.concatenate([np.zeros(3), axis])
    a_eq = np.hstack([jacobian, -twist[:, None], -spin[:, None]])
    bounds = [(-m, m) for m in limits] + [(0.0, None), (None, None)]
    result = scipy.optimize.linprog(
        cost,
        A_eq=a_eq,
        b_eq=np.zeros(6),
        bounds=bounds,
        method="highs",
        options={"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10},
    )
    assert result.status == 0, result.message
    return float(result.x[n])


@pytest.mark.parametrize(("name", "tcp_turn"), [("ur5", 0.0), ("ur5e", 0.0), ("ur5e", 0.7)])
def test_free_spin_speed_equals_highs(name: str, tcp_turn: float) -> None:
    """1000 random configurations and directions; an angled, offset tool for tcp_turn != 0."""
    robot = get_robot(name)
    if tcp_turn:
        tcp = np.eye(4)
        c, s = np.cos(tcp_turn), np.sin(tcp_turn)
        tcp[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
        tcp[:3, 3] = [0.02, 0.05, 0.15]
        robot = robot.with_options(transform_tool_to_tcp=tcp)
    rng = np.random.default_rng(11)
    a, b, lp = [], [], []
    while len(lp) < 1000:
        q = rng.uniform(-np.pi, np.pi, 6)
        jacobian = jacobian_in_base(robot, q)
        if np.linalg.cond(jacobian) > 1e4:
            continue
        twist = np.concatenate([rng.normal(size=3), rng.normal(size=3) / rng.uniform(0.01, 2.0)])
        axis = tool_pose_in_base(robot, q)[:3, 2]
        a.append(np.linalg.solve(jacobian, twist))
        b.append(np.linalg.solve(jacobian, np.concatenate([np.zeros(3), axis])))
        lp.append(_free_spin_lp(jacobian, twist, axis, robot.qdot_max))
    speed, limiting = two_variable_speed(np.array(a).T, np.array(b).T, robot.qdot_max)
    np.testing.assert_allclose(speed, lp, rtol=FREE_SPIN_LP_RTOL)
    # At the optimum some spin rate keeps every joint within its limit, the limiting one on it.
    sigma = spin_rate_nearest_zero(np.array(a).T, np.array(b).T, robot.qdot_max, speed)
    load = np.abs(speed * np.array(a).T + sigma * np.array(b).T) / robot.qdot_max[:, None]
    assert np.all(load <= 1 + 1e-9)
    np.testing.assert_allclose(load[limiting, np.arange(1000)], 1.0, rtol=1e-9)


def test_straight_spindle_drops_the_last_joint() -> None:
    """Tool z on the flange axis: V_max = 1 / max over joints 1-5 of |a_j| / limit_j."""
    robot = get_robot("ur5")
    rng = np.random.default_rng(3)
    q = rng.uniform(-np.pi, np.pi, (200, 6))
    a = rng.normal(size=(6, 200))
    b = np.array(
        [
            np.linalg.solve(
                jacobian_in_base(robot, qi),
                np.concatenate([np.zeros(3), tool_pose_in_base(robot, qi)[:3, 2]]),
            )
            for qi in q
        ]
    ).T
    speed, limiting = two_variable_speed(a, b, robot.qdot_max)
    expected = 1.0 / np.max(np.abs(a[:5]) / robot.qdot_max[:5, None], axis=0)
    np.testing.assert_allclose(speed, expected, rtol=1e-9)
    assert np.all(limiting < 5)


def test_readme_example_free_spin_schedule_realises_mu_path() -> None:
    """The issue's figure, and fixed mode with the free mode's spins within 1 %."""
    robot = get_robot("ur5")
    path = load_path("curved_line")
    fixed = evaluate_path(robot, path, README_PLACEMENT)
    free = evaluate_path(robot, path, README_PLACEMENT, spin_mode="free")
    assert fixed.mu_path == pytest.approx(0.293729, abs=1e-6)
    assert free.mu_path == pytest.approx(1.248073, abs=1e-6)  # independent LP: 1.2481
    assert free.spins is not None and free.q is not None and free.qdot is not None
    turn = np.zeros((len(path), 4, 4))
    turn[:, 0, 0] = turn[:, 1, 1] = np.cos(free.spins)
    turn[:, 1, 0] = np.sin(free.spins)
    turn[:, 0, 1] = -np.sin(free.spins)
    turn[:, 2, 2] = turn[:, 3, 3] = 1.0
    spun = evaluate_path(robot, path @ turn, README_PLACEMENT)
    assert spun.mu_path is not None
    assert abs(spun.mu_path / free.mu_path - 1) < SPIN_SCHEDULE_RTOL
    # The schedule's joint path: within limits, and its joint speeds at V_max within theirs.
    assert np.all((free.q >= robot.q_lower) & (free.q <= robot.q_upper))
    assert np.all(np.abs(free.qdot) <= robot.qdot_max * (1 + 1e-9))
    # The schedule's last joint is the given one turned by the spin (a straight spindle).
    np.testing.assert_allclose(free.q[:, 5] - fixed.q[:, 5], free.spins, atol=1e-9)


def test_last_joint_limits_are_checked_along_the_schedule() -> None:
    """Limits that hold the spun path but not the given one, then ones 0.05 rad tighter."""
    robot = get_robot("ur5")
    path = load_path("curved_line")
    free = evaluate_path(robot, path, README_PLACEMENT, spin_mode="free")
    assert free.q is not None
    lower, upper = robot.q_lower.copy(), robot.q_upper.copy()
    lower[5], upper[5] = free.q[:, 5].min() - 1e-6, free.q[:, 5].max() + 1e-6
    fits = dataclasses.replace(robot, q_lower=lower, q_upper=upper)
    assert evaluate_path(fits, path, README_PLACEMENT).reason == "joint_limits"
    assert evaluate_path(fits, path, README_PLACEMENT, spin_mode="free").feasible
    lower[5] += 0.05
    tight = dataclasses.replace(robot, q_lower=lower, q_upper=upper)
    result = evaluate_path(tight, path, README_PLACEMENT, spin_mode="free")
    assert (result.feasible, result.reason) == (False, "joint_limits")


def test_free_spin_map_equals_evaluate() -> None:
    robot = get_robot("ur5")
    path = load_path("curved_line")
    xs, ys, yaws = np.array([-0.1, 0.0, 0.15]), np.array([0.35, 0.5]), np.array([0.0, 2.0])
    cmap = capability_map(robot, path, xs=xs, ys=ys, z=0.1, yaws=yaws, spin_mode="free")
    for index in np.ndindex(cmap.mu_path.shape):
        expected = evaluate_path(robot, path, cmap.placement(index), spin_mode="free")
        if expected.mu_path is None:
            assert np.isnan(cmap.mu_path[index])
        else:
            assert cmap.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)


@pytest.fixture(scope="module")
def free_optima() -> dict:
    robot, path = get_robot("ur5"), load_path("curved_line")
    bounds = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
    return {
        "robot": robot,
        "path": path,
        "bounds": bounds,
        "best_cell": best_coarse_cell(robot, path, bounds, spin_mode="free"),
        "fixed": optimize_placement(robot, path, bounds=bounds),
        **{
            method: optimize_placement(robot, path, bounds=bounds, method=method, spin_mode="free")
            for method in ("casadi", "scipy")
        },
    }


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_free_spin_optimum(free_optima: dict, method: str) -> None:
    """At or above the free-spin map's best cell and the fixed-spin optimum; = the evaluator."""
    optimum = free_optima[method]
    assert optimum is not None and free_optima["fixed"] is not None
    assert optimum.mu_path >= free_optima["best_cell"]
    assert optimum.mu_path >= free_optima["fixed"].mu_path
    evaluation = evaluate_path(
        free_optima["robot"], free_optima["path"], optimum.placement, spin_mode="free"
    )
    assert optimum.mu_path == pytest.approx(evaluation.mu_path, rel=OPTIMUM_EVALUATE_RTOL)
    assert optimum.evaluation.spins is not None
    other = free_optima["scipy" if method == "casadi" else "casadi"]
    assert optimum.mu_path == pytest.approx(other.mu_path, rel=OPTIMUM_METHODS_RTOL)


PRISMATIC_TIP = """<robot name="slide">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="tool"/>
  <joint name="turn" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="2" effort="1"/></joint>
  <joint name="reach" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" velocity="2" effort="1"/>
  </joint>
  <joint name="plunge" type="prismatic"><parent link="l2"/><child link="tool"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.1" velocity="0.5" effort="1"/>
  </joint>
</robot>"""


def test_free_spin_needs_a_revolute_last_joint() -> None:
    robot = robot_from_urdf(PRISMATIC_TIP, base_frame="base", tool_frame="tool")
    with pytest.raises(InvalidInputError) as error:
        evaluate_path(robot, load_path("curved_line"), README_PLACEMENT, spin_mode="free")
    assert error.value.field == "spin_mode" and "plunge" in error.value.message
    with pytest.raises(InvalidInputError) as error:
        evaluate_path(get_robot("ur5"), load_path("curved_line"), README_PLACEMENT, spin_mode="x")
    assert error.value.field == "spin_mode"


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("compiled", [True, False])
def test_a_path_singular_on_every_pose_is_singular_without_a_warning(compiled: bool) -> None:
    """The UR5e's elbow stretched (q3 = 0) along a turn of its base, in free spin: the answer
    was right (singular at the first waypoint), with a numpy RuntimeWarning in the service's log
    from the spun joint paths (0 times inf; audit 23). The path from forward kinematics."""
    robot = get_robot("ur5e")
    base = np.array([0.3, -1.0, 0.0, -1.0, 1.0, 0.5])
    poses = np.array(
        [tool_pose_in_base(robot, base + [t, 0, 0, 0, 0, 0]) for t in np.linspace(0, 0.3, 11)]
    )
    origin = Placement(0.0, 0.0, 0.0, 0.0)
    answer = evaluate_path(robot, poses, origin, spin_mode="free")
    assert (answer.reason, answer.failed_waypoint) == ("singular", 0)
    cells = capability_map(
        robot, poses, xs=np.zeros(1), ys=np.zeros(1), z=0.0, yaws=np.zeros(1), spin_mode="free",
        compiled=compiled,
    )  # fmt: skip
    assert np.isnan(cells.mu_path).all()


def _spun_about_tool_z(pose: np.ndarray, angle: float, tilt: float = 0.0) -> np.ndarray:
    """``pose`` turned in place by ``angle`` about its own z axis (then ``tilt`` about its x)."""
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    c, s = math.cos(tilt), math.sin(tilt)
    turn = turn @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    turned = pose.copy()
    turned[:3, :3] = pose[:3, :3] @ turn
    return turned


def test_a_turn_about_the_tool_axis_alone_repeats_its_waypoint_in_free_spin() -> None:
    """The spin takes the whole turn and the joints none: the free-spin LP had no bound and
    omega_max came out 6.6e15 rad/s (audit 24). Refused as a repeated waypoint, naming it; in
    fixed spin the same path is answered, pure reorientation there (V_max 0); a turn that also
    tilts the tool axis by 1e-6 rad is a segment in free spin too."""
    robot = get_robot("ur5")
    path = load_path("curved_line")[:6].copy()
    path[3] = _spun_about_tool_z(path[2], 0.2)
    with pytest.raises(RepeatedWaypointError) as refused:
        evaluate_path(robot, path, README_PLACEMENT, spin_mode="free")
    assert refused.value.waypoint == 3 and "free spin" in refused.value.message
    fixed = evaluate_path(robot, path, README_PLACEMENT, spin_mode="fixed")
    assert fixed.mu_path == 0.0 and fixed.omega_max is not None and fixed.omega_max[2] < 100.0
    path[3] = _spun_about_tool_z(path[2], 0.2, tilt=1e-6)
    tilted = evaluate_path(robot, path, README_PLACEMENT, spin_mode="free")
    assert tilted.mu_path == 0.0  # pure reorientation: V_max 0 (dtf.md section 2)
