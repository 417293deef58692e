"""Exact DTF of redundant arms: the batched two-variable LP against HiGHS, and in the pipeline."""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.dtf import lp_speed
from solver.core.dtf_redundant import redundant_speed
from solver.core.kinematics import jacobian_in_base
from solver.core.spatial import Placement
from solver.families import get_robot
from tests.cases import DTF_LP_RTOL
from tests.problems import evaluate_path
from tests.solver.test_evaluate import load_path


def random_problems(count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Panda Jacobians (pinocchio) at random q within limits, and random t_hat (any h)."""
    robot = get_robot("panda")
    rng = np.random.default_rng(seed)
    q = rng.uniform(robot.q_lower, robot.q_upper, (count, robot.dof))
    jacobian = np.array([jacobian_in_base(robot, qi) for qi in q])
    u_t = rng.normal(size=(count, 3))
    u_r = rng.normal(size=(count, 3))
    u_t /= np.linalg.norm(u_t, axis=1, keepdims=True)
    u_r /= np.linalg.norm(u_r, axis=1, keepdims=True)
    h = np.exp(rng.uniform(np.log(0.01), np.log(10.0), count))
    twist = np.concatenate([u_t, u_r / h[:, None]], axis=1)
    twist[:50, 3:] = 0.0  # pure translation
    twist[50:100, :3] = 0.0  # pure reorientation (per rad/s)
    return jacobian, twist, robot.qdot_max


def test_seven_joints_equals_highs_on_1000_panda_problems() -> None:
    jacobian, twist, limits = random_problems(1000, seed=7)
    speed, qdot = redundant_speed(jacobian, twist, limits)
    highs = np.array(
        [lp_speed(j, t, qdot_max=limits)[0] for j, t in zip(jacobian, twist, strict=True)]
    )
    np.testing.assert_allclose(speed, highs, rtol=DTF_LP_RTOL, atol=0)
    # The optimum's joint speeds realise s t_hat, within the limits, one on its limit.
    np.testing.assert_allclose(
        np.einsum("mij,mj->mi", jacobian, qdot), speed[:, None] * twist, rtol=0, atol=1e-9
    )
    ratio = np.abs(qdot) / limits
    assert ratio.max() <= 1.0 + 1e-9
    np.testing.assert_allclose(ratio.max(axis=1), 1.0, atol=1e-9)
    # At least the pseudo-inverse DTF (min-norm speeds scaled to the limits).
    pseudo = np.einsum("mij,mj->mi", np.linalg.pinv(jacobian), twist)
    pseudo_speed = 1.0 / (np.abs(pseudo) / limits).max(axis=1)
    assert np.all(speed >= pseudo_speed * (1 - 1e-12))
    assert np.mean(speed > pseudo_speed * (1 + 1e-6)) > 0.9  # and usually more


def test_more_than_seven_joints_uses_highs() -> None:
    rng = np.random.default_rng(8)
    jacobian = rng.normal(size=(5, 6, 9))
    twist = rng.normal(size=(5, 6))
    limits = rng.uniform(1.0, 3.0, 9)
    speed, qdot = redundant_speed(jacobian, twist, limits)
    for m in range(5):
        assert speed[m] == pytest.approx(lp_speed(jacobian[m], twist[m], qdot_max=limits)[0])
        np.testing.assert_allclose(jacobian[m] @ qdot[m], speed[m] * twist[m], atol=1e-9)


def test_panda_path_speeds_are_the_lp_at_the_tracked_joints() -> None:
    robot = get_robot("panda")
    path = load_path("curved_line")
    placement = Placement(0.4, 0.0, 0.1, 0.0)
    result = evaluate_path(robot, path, placement)
    assert result.feasible and result.q is not None and result.v_max is not None
    assert result.qdot is not None
    poses = placement.transform_workpiece_to_base() @ path
    for i in (0, 40, 90, 131):  # segment i -> i + 1, in {B}
        jacobian = jacobian_in_base(robot, result.q[i])
        dp = poses[i + 1, :3, 3] - poses[i, :3, 3]
        relative = poses[i + 1, :3, :3] @ poses[i, :3, :3].T
        angle = np.arccos(np.clip((np.trace(relative) - 1) / 2, -1, 1))
        axis = np.array(
            [
                relative[2, 1] - relative[1, 2],
                relative[0, 2] - relative[2, 0],
                relative[1, 0] - relative[0, 1],
            ]
        ) / (2 * np.sin(angle))
        twist = np.concatenate([dp / np.linalg.norm(dp), axis * angle / np.linalg.norm(dp)])
        expected, _ = lp_speed(jacobian, twist, qdot_max=robot.qdot_max)
        assert result.v_max[i] == pytest.approx(expected, rel=1e-9)
        np.testing.assert_allclose(jacobian @ result.qdot[i], result.v_max[i] * twist, atol=1e-9)
    assert result.mu_path == pytest.approx(result.v_max.min(), rel=1e-15)
