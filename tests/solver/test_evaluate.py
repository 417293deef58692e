"""mu_path at a placement: an independent pipeline, branch choice, and every infeasibility."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
import scipy.optimize
import ur_analytic_ik
from scipy.spatial.transform import Rotation

from solver.core.exceptions import InvalidInputError, NoAnalyticIkError, RepeatedWaypointError
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import example_robot_data_dir
from solver.core.spatial import Placement, pose_matrix, wrap_angle
from solver.families import get_robot, robot_from_urdf
from solver.families.ur.ik import BRANCHES
from solver.path.evaluate import Branch
from tests.cases import EXAMPLES, TWO_PI
from tests.problems import evaluate_path

PLACEMENT = Placement(0.0, 0.45, 0.1, 0.0)


def load_path(name: str) -> np.ndarray:
    waypoints = json.loads((EXAMPLES / "paths" / f"{name}.json").read_text())["waypoints"]
    return np.array([pose_matrix(w["position"], w["orientation"], field="w") for w in waypoints])


def segment_twists(poses: np.ndarray) -> list[np.ndarray]:
    """t_hat of each waypoint's segment (the last its segment's), from scipy's rotations."""
    out = []
    for i in range(len(poses)):
        a, b = (i, i + 1) if i + 1 < len(poses) else (i - 1, i)
        dp = poses[b, :3, 3] - poses[a, :3, 3]
        dphi = Rotation.from_matrix(poses[b, :3, :3] @ poses[a, :3, :3].T).as_rotvec()
        out.append(np.concatenate([dp, dphi]) / np.linalg.norm(dp))
    return out


def independent_mu_path(name: str, path: np.ndarray, placement: Placement, step: float) -> float:
    """mu_path from other code: ur-analytic-ik, nearest-solution tracking, scipy rotations, LP."""
    robot = get_robot(name)
    poses = placement.transform_workpiece_to_base() @ path
    solutions = [getattr(ur_analytic_ik, name).inverse_kinematics(p) for p in poses]
    twists = segment_twists(poses)
    best = -1.0
    for start in solutions[0]:
        track = [np.array(start)]
        for options in solutions[1:]:
            moves = [np.max(np.abs(wrap_angle(np.array(s) - track[-1]))) for s in options]
            if not moves or min(moves) > step:
                break
            track.append(
                track[-1] + wrap_angle(np.array(options[int(np.argmin(moves))]) - track[-1])
            )
        if len(track) < len(poses):
            continue
        joints = np.array(track)
        span = joints.max(axis=0) - joints.min(axis=0)
        if np.any(span > robot.q_upper - robot.q_lower):
            continue
        speeds = []
        for q, twist in zip(joints, twists, strict=True):
            jac = jacobian_in_base(robot, q)
            n = jac.shape[1]
            res = scipy.optimize.linprog(
                np.r_[np.zeros(n), -1.0],
                A_eq=np.hstack([jac, -twist[:, None]]),
                b_eq=np.zeros(6),
                bounds=[(-v, v) for v in robot.qdot_max] + [(0, None)],
                method="highs",
            )
            speeds.append(res.x[-1])
        best = max(best, min(speeds))
    return best


@pytest.mark.parametrize(
    ("robot_name", "path_name"),
    [("ur5", "curved_line"), ("ur5e", "curved_line"), ("ur5e", "s_curve")],
)
def test_mu_path_equals_an_independent_pipeline(robot_name: str, path_name: str) -> None:
    path = load_path(path_name)
    result = evaluate_path(get_robot(robot_name), path, PLACEMENT)
    assert result.feasible
    expected = independent_mu_path(robot_name, path, PLACEMENT, 0.35)
    assert result.mu_path == pytest.approx(expected, rel=1e-8)


def test_mu_path_is_the_minimum_and_the_detail_is_consistent() -> None:
    robot = get_robot("ur5")
    path = load_path("curved_line")
    result = evaluate_path(robot, path, PLACEMENT)
    assert result.mu_path == np.min(result.v_max)
    assert result.bottleneck_waypoint == int(np.argmin(result.v_max))
    assert result.bottleneck_joint == result.limiting_joint[result.bottleneck_waypoint]
    poses = PLACEMENT.transform_workpiece_to_base() @ path
    for i, q in enumerate(result.q):
        np.testing.assert_allclose(tool_pose_in_base(robot, q), poses[i], atol=1e-9)
        j = result.limiting_joint[i]
        assert abs(result.qdot[i, j]) == pytest.approx(robot.qdot_max[j], rel=1e-12)
        twist = np.concatenate(
            [result.v_max[i] * result.u_T[i], result.omega_max[i] * result.u_R[i]]
        )
        np.testing.assert_allclose(jacobian_in_base(robot, q) @ result.qdot[i], twist, atol=1e-10)
    np.testing.assert_allclose(result.v_max / result.omega_max, result.h, rtol=1e-12)
    assert np.all(np.abs(np.diff(result.q, axis=0)) <= 0.35)
    assert np.all((result.q >= robot.q_lower) & (result.q <= robot.q_upper))


@pytest.mark.parametrize("robot_name", ["ur5", "ur5e"])
def test_auto_is_the_best_named_branch(robot_name: str) -> None:
    robot = get_robot(robot_name)
    path = load_path("curved_line")
    auto = evaluate_path(robot, path, PLACEMENT)
    named = [evaluate_path(robot, path, PLACEMENT, branch=b) for b in BRANCHES]
    feasible = [r.mu_path for r in named if r.feasible]
    assert len(feasible) >= 2
    # The best, where branches within 1e-12 count as tied and the first in BRANCHES order is
    # taken (the branches of one shoulder move joints 1, 5 and 6 at the same speeds).
    assert auto.mu_path >= max(feasible) * (1 - 1e-12)
    first_tied = next(
        b
        for b, r in zip(BRANCHES, named, strict=True)
        if r.feasible and r.mu_path >= max(feasible) * (1 - 1e-12)
    )
    assert auto.branch == first_tied
    assert auto.mu_path == named[BRANCHES.index(first_tied)].mu_path


def test_unreachable_placement() -> None:
    result = evaluate_path(get_robot("ur5"), load_path("curved_line"), Placement(5.0, 0, 0.1, 0))
    assert (result.feasible, result.reason, result.failed_waypoint) == (False, "unreachable", 0)
    assert result.mu_path is None and result.q is None


def test_discontinuous_when_the_step_is_too_small() -> None:
    result = evaluate_path(
        get_robot("ur5"), load_path("curved_line"), PLACEMENT, max_joint_step=1e-3
    )
    assert (result.feasible, result.reason, result.failed_waypoint) == (False, "discontinuous", 1)


def test_joint_limits_name_the_first_waypoint_out_of_range() -> None:
    robot = get_robot("ur5e")
    path = load_path("curved_line")
    free = evaluate_path(
        robot, path, PLACEMENT, branch=Branch.named(shoulder="left", elbow="up", wrist="noflip")
    )
    q1 = free.q[:, 0]
    # Limits on q1 that the first 40 waypoints fit but waypoint 40 leaves, whichever 2 pi copy.
    lower, upper = robot.q_lower.copy(), robot.q_upper.copy()
    first = q1[:40]
    if q1[40] > first.max():
        lower[0], upper[0] = first.min() - 1e-9, (first.max() + q1[40]) / 2
    else:
        lower[0], upper[0] = (first.min() + q1[40]) / 2, first.max() + 1e-9
    assert abs(q1[40] - q1[39]) > 1e-6
    limited = dataclasses.replace(robot, q_lower=lower, q_upper=upper)
    result = evaluate_path(
        limited, path, PLACEMENT, branch=Branch.named(shoulder="left", elbow="up", wrist="noflip")
    )
    assert (result.feasible, result.reason, result.failed_waypoint) == (False, "joint_limits", 40)


def test_two_pi_copy_is_chosen_to_fit_the_limits() -> None:
    """Limits that only the +2 pi copy of the whole path fits: that copy is chosen."""
    robot = get_robot("ur5e")
    path = load_path("curved_line")
    base = evaluate_path(robot, path, PLACEMENT)
    lower = base.q.min(axis=0) + TWO_PI - 1e-3
    shifted = dataclasses.replace(robot, q_lower=lower, q_upper=lower + TWO_PI)
    result = evaluate_path(shifted, path, PLACEMENT, branch=base.branch)
    assert result.feasible and result.mu_path == pytest.approx(base.mu_path, rel=1e-12)
    np.testing.assert_allclose(result.q, base.q + TWO_PI, atol=1e-12)


def wrist_singular_path(robot) -> np.ndarray:
    """5 poses in {B} on branch (left, up, flip) whose wrist passes q5 = 0 at waypoint 2."""
    q_path = np.tile([0.3, -1.1, 1.2, -0.4, 0.0, 0.7], (5, 1))
    q_path[:, 4] = np.linspace(-0.2, 0.2, 5)
    q_path[:, 0] += np.linspace(0, 0.1, 5)
    return np.array([tool_pose_in_base(robot, q) for q in q_path])


def test_singular_waypoint() -> None:
    robot = get_robot("ur5e")
    path = wrist_singular_path(robot)
    result = evaluate_path(
        robot,
        path,
        Placement(0, 0, 0, 0),
        branch=Branch.named(shoulder="left", elbow="up", wrist="flip"),
    )
    assert (result.reason, result.failed_waypoint) == ("singular", 2)


def test_pure_reorientation_waypoint_has_zero_speed() -> None:
    path = load_path("curved_line")[:10].copy()
    path[5, :3, 3] = path[4, :3, 3]  # waypoint 4 -> 5 only turns
    result = evaluate_path(get_robot("ur5e"), path, PLACEMENT)
    assert result.h[4] == 0.0 and result.v_max[4] == 0.0 and result.omega_max[4] > 0
    assert result.mu_path == 0.0 and result.bottleneck_waypoint == 4


def test_tool_point_offset_is_tracked() -> None:
    tcp = np.eye(4)
    tcp[:3, 3] = [0.0, 0.0, 0.12]
    robot = get_robot("ur5e").with_options(transform_tool_to_tcp=tcp)
    path = load_path("curved_line")
    result = evaluate_path(robot, path, PLACEMENT)
    poses = PLACEMENT.transform_workpiece_to_base() @ path
    for i in (0, 50, 132):
        np.testing.assert_allclose(tool_pose_in_base(robot, result.q[i]), poses[i], atol=1e-9)


def test_input_errors() -> None:
    path = load_path("curved_line")
    with pytest.raises(RepeatedWaypointError) as info:
        evaluate_path(get_robot("ur5"), np.concatenate([path[:3], path[2:5]]), PLACEMENT)
    assert info.value.waypoint == 3
    with pytest.raises(InvalidInputError) as bad_step:
        evaluate_path(get_robot("ur5"), path, PLACEMENT, max_joint_step=0.0)
    assert bad_step.value.field == "ik.max_joint_step"
    panda_urdf = (example_robot_data_dir() / "panda_description/urdf/panda.urdf").read_text()
    # Five joints cannot solve six-dimensional poses: no family, numeric or other.
    short = robot_from_urdf(panda_urdf, base_frame="panda_link0", tool_frame="panda_link5")
    assert short.dof == 5 and short.family is None
    with pytest.raises(NoAnalyticIkError):
        evaluate_path(short, path, PLACEMENT)
