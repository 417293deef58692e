"""Numeric IK family: its chain against pinocchio, FK(IK(T)) = T, limits, determinism."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from solver.core.codes import OK, UNREACHABLE
from solver.core.exceptions import InvalidInputError
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import Robot, chain_from_urdf, example_robot_data_dir
from solver.core.spatial import Placement, wrap_angle
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric.family import NumericFamily, seed_count
from solver.families.numeric.ik import rotation_log
from solver.families.ur.catalogue import _exact_right_angles
from tests.cases import FK_IK_ATOL, NUMERIC_MODELS
from tests.problems import evaluate_path
from tests.solver.test_evaluate import load_path


def ur5_as_urdf() -> Robot:
    """The UR5 of example-robot-data as a plain URDF with the numeric family.

    Given no family, the registry would recognise it as a UR arm (solver.families.recognise);
    these tests are about numeric IK, so it is given the numeric family.
    """
    path = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    urdf = _exact_right_angles(path.read_text())
    frames = {"base_frame": "base", "tool_frame": "tool0"}
    family = NumericFamily(chain_from_urdf(urdf, tool_frame="tool0"), **frames)
    return robot_from_urdf(urdf, **frames, name="ur5_urdf", family=family)


def numeric(robot: Robot) -> NumericFamily:
    assert isinstance(robot.family, NumericFamily)
    return robot.family


def random_configurations(robot: Robot, count: int, seed: int) -> np.ndarray:
    """(count, n) joint positions within the limits (a full turn at most for +-2 pi joints)."""
    lower = np.maximum(robot.q_lower, -np.pi)
    upper = np.minimum(robot.q_upper, np.pi)
    lower = np.where(upper - lower < 0.1, robot.q_lower, lower)  # limits beyond [-pi, pi]
    upper = np.where(upper - lower < 0.1, robot.q_upper, upper)
    return np.random.default_rng(seed).uniform(lower, upper, (count, robot.dof))


ROBOTS = (*NUMERIC_MODELS, "ur5_urdf")


def get(name: str) -> Robot:
    return ur5_as_urdf() if name == "ur5_urdf" else get_robot(name)


@pytest.mark.parametrize("name", ROBOTS)
def test_chain_equals_pinocchio(name: str) -> None:
    robot = get(name)
    chain = numeric(robot).chain
    q = random_configurations(robot, 20, seed=1)
    rotation, position = chain.forward(q)
    jacobian, _, _ = chain.jacobian(q, position)
    for i in range(len(q)):
        pose = tool_pose_in_base(robot, q[i])  # the tool point is the flange here
        np.testing.assert_allclose(rotation[i], pose[:3, :3], rtol=0, atol=1e-13)
        np.testing.assert_allclose(position[i], pose[:3, 3], rtol=0, atol=1e-13)
        np.testing.assert_allclose(jacobian[i], jacobian_in_base(robot, q[i]), rtol=0, atol=1e-13)


def test_rotation_log_equals_pinocchio_up_to_pi() -> None:
    rng = np.random.default_rng(2)
    axes = rng.normal(size=(300, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.concatenate([rng.uniform(0, np.pi, 200), np.pi - np.logspace(-12, -1, 99), [0.0]])
    vectors = axes * angles[:, None]
    rotations = np.array([pin.exp3(v) for v in vectors])
    ours = rotation_log(rotations)
    theirs = np.array([pin.log3(r) for r in rotations])
    # At pi exactly, v and -v are the same rotation: compare the rotations there.
    np.testing.assert_allclose(np.array([pin.exp3(v) for v in ours]), rotations, atol=1e-12)
    near_pi = angles > np.pi - 1e-6
    np.testing.assert_allclose(ours[~near_pi], theirs[~near_pi], rtol=0, atol=1e-9)


def solve_random_poses(robot: Robot, count: int, seed: int) -> tuple[np.ndarray, ...]:
    """Poses of random configurations and the family's solutions: q (K, P, n), status (K, P)."""
    family = numeric(robot)
    q_true = random_configurations(robot, count, seed)
    rotation, position = family.chain.forward(q_true)
    q, status = family.solve(np.moveaxis(rotation, 0, -1), position.T)
    return q_true, rotation, position, np.moveaxis(q, 0, -1), status


@pytest.mark.parametrize("name", ROBOTS)
def test_every_solution_reaches_the_pose_within_limits(name: str) -> None:
    robot = get(name)
    q_true, rotation, position, q, status = solve_random_poses(robot, 40, seed=3)
    assert q.shape[:2] == (seed_count(robot.dof), 40)
    found = status == OK
    assert found.any(axis=0).mean() >= 0.95  # each pose is reachable: nearly always found
    for k, p in zip(*np.nonzero(found), strict=True):
        pose = tool_pose_in_base(robot, q[k, p])  # pinocchio, not the family's chain
        np.testing.assert_allclose(pose[:3, :3], rotation[p], rtol=0, atol=FK_IK_ATOL)
        np.testing.assert_allclose(pose[:3, 3], position[p], rtol=0, atol=FK_IK_ATOL)
        # Within the limits with some 2 pi copy (q is given in [-pi, pi)).
        turns = np.arange(-2, 3)[:, None] * 2 * np.pi
        copies = q[k, p] + turns
        inside = (copies >= robot.q_lower - 1e-12) & (copies <= robot.q_upper + 1e-12)
        assert inside.any(axis=0).all()
    # The slots after the solutions found are empty; the found ones are distinct.
    empty = np.isnan(q).any(axis=-1)
    assert np.all(status[empty] == UNREACHABLE) and np.all(np.isfinite(q[~empty]))
    assert np.all(np.diff(empty.astype(int), axis=0) >= 0)  # packed to the front
    for p in range(q.shape[1]):
        solutions = q[~empty[:, p], p]
        gaps = wrap_angle(solutions[:, None] - solutions[None])
        distance = np.linalg.norm(gaps, axis=-1) + np.eye(len(solutions))
        assert distance.min() > 1e-3


@pytest.mark.parametrize("name", ["panda", "ur5_urdf"])
def test_same_input_same_branches(name: str) -> None:
    first = solve_random_poses(get(name), 10, seed=4)
    second = solve_random_poses(get(name), 10, seed=4)
    for a, b in zip(first, second, strict=True):
        np.testing.assert_array_equal(a, b)
    path = load_path("curved_line")[:20]
    placement = Placement(0.4, 0.0, 0.1, 0.0) if name == "panda" else Placement(0, 0.45, 0.1, 0)
    one, two = (evaluate_path(get(name), path, placement) for _ in range(2))
    assert one.branch == two.branch and one.mu_path == two.mu_path
    np.testing.assert_array_equal(one.q, two.q)


def test_ur5_solutions_are_analytic_ones() -> None:
    """Each numeric solution of the UR5 is one of the 8 analytic ones (ur-analytic-ik, wrapped)."""
    import ur_analytic_ik

    robot = ur5_as_urdf()
    q_true, rotation, position, q, status = solve_random_poses(robot, 30, seed=5)
    for p in range(q.shape[1]):
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = rotation[p], position[p]
        analytic = np.array(ur_analytic_ik.ur5.inverse_kinematics(pose))
        for k in np.flatnonzero(status[:, p] == OK):
            gap = np.abs(wrap_angle(analytic - q[k, p])).max(axis=1)
            assert gap.min() < 1e-6


@pytest.mark.parametrize(("name", "placement"), [("panda", Placement(0.4, 0.0, 0.1, 0.0))])
def test_tracked_path_reaches_every_waypoint(name: str, placement: Placement) -> None:
    robot = get_robot(name)
    path = load_path("curved_line")
    result = evaluate_path(robot, path, placement)
    assert result.feasible and result.q is not None
    assert result.ik_seeds == 64 and result.ik_branches_found is not None
    assert 1 <= result.ik_branches_found <= 64
    poses = placement.transform_workpiece_to_base() @ path
    for i in range(len(path)):
        np.testing.assert_allclose(tool_pose_in_base(robot, result.q[i]), poses[i], atol=1e-9)
    assert np.all(result.q >= robot.q_lower - 1e-12) and np.all(result.q <= robot.q_upper + 1e-12)
    assert np.abs(np.diff(result.q, axis=0)).max() <= 0.35


def test_free_spin_is_refused_beyond_seven_joints() -> None:
    """Seven joints have the three-variable spin LP (test_free_spin_redundant.py); eight not."""
    panda = (example_robot_data_dir() / "panda_description" / "urdf" / "panda.urdf").read_text()
    extra = (
        '<link name="extra"/><joint name="extra_joint" type="revolute">'
        '<parent link="panda_link8"/><child link="extra"/><origin xyz="0 0 0.05"/>'
        '<axis xyz="1 0 0"/><limit lower="-2" upper="2" velocity="2" effort="1"/></joint>'
    )
    robot = robot_from_urdf(
        panda.replace("</robot>", extra + "</robot>"),
        base_frame="panda_link0",
        tool_frame="extra",
    )
    assert robot.dof == 8
    with pytest.raises(InvalidInputError) as info:
        evaluate_path(robot, load_path("curved_line"), Placement(0.4, 0, 0.1, 0), spin_mode="free")
    assert info.value.field == "spin_mode" and "8 joints" in info.value.message


@pytest.mark.parametrize("tilt", [1e-8, 1e-6])
def test_an_axis_a_hair_off_a_coordinate_axis_is_read_as_it_is(tilt: float) -> None:
    """FK(IK(T)) = T where a joint's axis is tilted under 1.5e-8 rad from y (the UR5's shoulder).

    Such an axis rounded to |y . axis| == 1 and was paired with an x square to y, not to the
    axis: the joint frame skewed by the tilt, answers 7e-9 m off (the robots audit of stop 55).
    """
    path = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    urdf = _exact_right_angles(path.read_text())
    shoulder = urdf.index('name="shoulder_lift_joint"')
    axis = urdf.index('<axis xyz="0 1 0"/>', shoulder)
    urdf = urdf[:axis] + f'<axis xyz="0 1 {tilt}"/>' + urdf[axis + len('<axis xyz="0 1 0"/>') :]
    robot = robot_from_urdf(urdf, base_frame="base", tool_frame="tool0")
    assert isinstance(robot.family, NumericFamily)  # not recognised as a UR arm: tilted
    waypoints = load_path("curved_line")[:20]
    placement = Placement(0.0, 0.45, 0.1, 0.0)
    answer = evaluate_path(robot, waypoints, placement)
    assert answer.feasible and answer.q is not None
    poses = placement.transform_workpiece_to_base() @ waypoints
    reached = np.array([tool_pose_in_base(robot, q) for q in answer.q])
    assert np.abs(reached - poses).max() < 1e-10
