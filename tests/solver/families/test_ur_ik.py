"""Batched analytic UR IK: FK(IK(T)) = T, completeness against ur-analytic-ik, branch labels."""

from __future__ import annotations

import math

import numpy as np
import pytest
import ur_analytic_ik

from solver.core.codes import OK, UNREACHABLE
from solver.core.family import Branch
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.spatial import wrap_angle
from solver.families import get_robot
from solver.families.ur.dh import UR_DH
from solver.families.ur.ik import BRANCHES, joint_copies, solve_batch
from tests.cases import FK_IK_ATOL, UR_MODELS

N_POSES = 1000


def _random_reachable_poses(name: str, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Poses reached by random configurations (pinocchio FK), and those configurations."""
    robot = get_robot(name)
    q = np.random.default_rng(seed).uniform(-math.pi, math.pi, (N_POSES, 6))
    return np.array([tool_pose_in_base(robot, qi) for qi in q]), q


@pytest.mark.parametrize("name", UR_MODELS)
def test_fk_of_every_solution_is_the_pose(name: str) -> None:
    """Issue 2: FK(IK(T)) = T to 1e-9 for every solution, over 1000 random reachable poses."""
    robot = get_robot(name)
    poses, _ = _random_reachable_poses(name, seed=1)
    q, status = solve_batch(robot.family.parameters, poses)
    solved = status != UNREACHABLE
    assert solved.sum() >= 4 * N_POSES  # a random pose has 4 to 8 solutions
    worst = 0.0
    for i, b in zip(*np.nonzero(solved), strict=True):
        worst = max(worst, float(np.abs(tool_pose_in_base(robot, q[i, b]) - poses[i]).max()))
    assert worst < FK_IK_ATOL


@pytest.mark.parametrize("name", UR_MODELS)
def test_every_reference_solution_is_among_ours(name: str) -> None:
    """Issue 2: every solution of ur-analytic-ik is one of ours (or its 2 pi copy)."""
    robot = get_robot(name)
    poses, q_true = _random_reachable_poses(name, seed=2)
    q, status = solve_batch(robot.family.parameters, poses)
    reference = getattr(ur_analytic_ik, name)
    for i, pose in enumerate(poses):
        theirs = reference.inverse_kinematics(pose)
        assert len(theirs) == int(np.sum(status[i] != UNREACHABLE))
        ours = q[i][status[i] != UNREACHABLE]
        for solution in [*theirs, q_true[i]]:
            distance = np.max(np.abs(wrap_angle(ours - solution)), axis=1)
            assert np.min(distance) < 1e-7, (i, solution)


def test_unreachable_pose_has_no_solution() -> None:
    pose = np.eye(4)
    pose[:3, 3] = [2.0, 0.0, 0.3]  # 2 m away: beyond every UR5e
    q, status = solve_batch(get_robot("ur5e").family.parameters, pose[None])
    assert np.all(status == UNREACHABLE)
    assert np.all(np.isnan(q))


def test_wrist_singular_pose_is_flagged() -> None:
    robot = get_robot("ur5e")
    q_singular = np.array([0.3, -1.1, 1.2, -0.4, 0.0, 0.7])  # q5 = 0: axes 4 and 6 aligned
    assert abs(np.linalg.det(jacobian_in_base(robot, q_singular))) < 1e-12
    _, status = solve_batch(robot.family.parameters, tool_pose_in_base(robot, q_singular)[None])
    assert np.any(status[0] == 2)


def test_branch_labels_are_sign_patterns() -> None:
    """Shoulder, elbow and wrist labels follow the signs documented in the module."""
    robot = get_robot("ur5e")
    poses, _ = _random_reachable_poses("ur5e", seed=4)
    q, status = solve_batch(robot.family.parameters, poses)
    for b, label in enumerate(BRANCHES):
        ok = status[:, b] == OK
        assert robot.family.branch_index(label) == b
        names = label.as_dict()
        wrist_sign = 1.0 if names["wrist"] == "noflip" else -1.0
        assert np.all(np.sign(q[ok, b, 4]) == wrist_sign)
        shoulder_sign = 1.0 if names["shoulder"] == "left" else -1.0
        elbow_sign = shoulder_sign if names["elbow"] == "up" else -shoulder_sign
        assert np.all(np.sign(q[ok, b, 2]) == elbow_sign)
    # The two shoulder solutions of a pose differ in q1 only by the choice of +-acos.
    assert (
        robot.family.branch_index(Branch.named(shoulder="right", elbow="down", wrist="flip")) == 7
    )


def test_joint_copies_within_limits() -> None:
    lower = np.array([-2 * math.pi] * 2 + [-math.pi] + [-2 * math.pi] * 3)
    upper = -lower
    q = np.array([0.5, -0.5, 2.0, 3.0, -3.0, 0.0])
    copies = joint_copies(q, lower=lower, upper=upper)
    # joints with +-2pi range have two copies (0.0 has three: -2pi, 0 and 2pi); the elbow one.
    assert copies.shape == (2 * 2 * 1 * 2 * 2 * 3, 6)
    assert np.all((copies >= lower - 1e-12) & (copies <= upper + 1e-12))
    np.testing.assert_allclose(wrap_angle(copies - q), 0.0, atol=1e-12)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize(
    "position", [(1e-320, 0.0, 0.5), (1e200, 0.0, 1e200), (1e308, 1e308, 0.0), (0.0, 0.0, 1e300)]
)
def test_a_pose_far_beyond_reach_is_unreachable_without_a_warning(
    position: tuple[float, float, float],
) -> None:
    """Overflows to inf and NaN there were numpy RuntimeWarnings in the service's log (audit 22:
    ``overflow encountered in divide`` at the shoulder's d4 / radius): the reach tests make the
    pose unreachable, which the answer says."""
    pose = np.eye(4)
    pose[:3, 3] = position
    q, status = solve_batch(UR_DH["ur5"], pose[None])
    assert np.isnan(q).all() and (status == UNREACHABLE).all()
