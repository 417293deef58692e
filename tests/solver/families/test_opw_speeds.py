"""OPW arms' closed-form J^-1 t (robots.md section 3) against pinocchio's Jacobian and HiGHS."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pinocchio as pin
import pytest

from solver.core.dtf import lp_speed
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import Robot
from tests.cases import DTF_LP_RTOL
from tests.solver.families.test_opw import GEOMETRIES, build, maker

N_CONFIGURATIONS = 1000


@pytest.fixture(scope="module", params=list(GEOMETRIES))
def arm(request: pytest.FixtureRequest) -> dict:
    """An arm with a random tool point, and random joint sets within its limits with the
    Jacobian, tool point and a random twist at each non-singular one (cond(J) < 1e6)."""
    rng = np.random.default_rng(100 + list(GEOMETRIES).index(request.param))
    tcp = np.eye(4)
    tcp[:3, :3] = pin.exp3(rng.normal(size=3))
    tcp[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    robot = build(request.param).with_options(transform_tool_to_tcp=tcp)
    lower, upper = np.maximum(robot.q_lower, -math.pi), np.minimum(robot.q_upper, math.pi)
    q = rng.uniform(lower, upper, (N_CONFIGURATIONS, 6))
    jacobians = np.array([jacobian_in_base(robot, qi) for qi in q])
    regular = np.linalg.cond(jacobians) < 1e6
    assert regular.mean() > 0.9
    q, jacobians = q[regular], jacobians[regular]
    points = np.array([tool_pose_in_base(robot, qi)[:3, 3] for qi in q])
    twists = rng.normal(size=(len(q), 6))
    return {"robot": robot, "q": q, "jacobians": jacobians, "points": points, "twists": twists}


def speeds(robot: Robot, q: np.ndarray, twist: np.ndarray, point: np.ndarray) -> np.ndarray:
    """The family's J^-1 t (the robot has one)."""
    assert robot.family is not None
    return robot.family.joint_speeds_per_unit_twist(q, twist, point)


def test_closed_form_speeds_equal_a_jacobian_solve(arm: dict) -> None:
    """J^-1 t in closed form, batched = pinocchio's Jacobian and a 6x6 solve, to 1e-9 of the
    largest joint speed."""
    expected = np.linalg.solve(arm["jacobians"], arm["twists"][:, :, None])[:, :, 0]
    ours = speeds(arm["robot"], arm["q"].T, arm["twists"].T, arm["points"].T).T
    scale = np.max(np.abs(expected), axis=1, keepdims=True)
    np.testing.assert_allclose(ours / scale, expected / scale, atol=1e-9)


def test_one_configuration_broadcasts_over_twists(arm: dict) -> None:
    """Q (6,) with twists (6, 6) and a point (3, 1): each column as if alone (six columns, so
    a sign applied on the wrong axis would broadcast silently)."""
    q, point = arm["q"][0], arm["points"][0]
    twists = arm["twists"][:6].T
    together = speeds(arm["robot"], q, twists, point[:, None])
    alone = np.stack([speeds(arm["robot"], q, t, point) for t in twists.T], axis=1)
    np.testing.assert_allclose(together, alone, rtol=1e-14, atol=1e-14)


def test_dtf_equals_the_lp(arm: dict) -> None:
    """V_max = 1 / ||W J^-1 t||_inf from the closed form = HiGHS on the LP, to 1e-9."""
    robot = arm["robot"]
    for qi, jacobian, twist, point in list(
        zip(arm["q"], arm["jacobians"], arm["twists"], arm["points"], strict=True)
    )[:50]:
        closed = 1.0 / np.max(np.abs(speeds(robot, qi, twist, point)) / robot.qdot_max)
        lp, _ = lp_speed(jacobian, twist, qdot_max=robot.qdot_max)
        assert closed == pytest.approx(lp, rel=DTF_LP_RTOL)


@pytest.mark.parametrize("name", list(GEOMETRIES))
def test_exact_singularity_gives_inf_or_nan_quietly(name: str) -> None:
    """Theta5 = 0 exactly: some speed is inf or NaN, with no warning."""
    robot = build(name)
    q = maker(GEOMETRIES[name], [0.3, 0.2, 0.1, 0.4, 0.0, 0.5])
    point = tool_pose_in_base(robot, q)[:3, 3]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = speeds(robot, q, np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0]), point)
    assert not np.all(np.isfinite(result))
