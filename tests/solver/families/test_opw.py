"""OPW arms (robots.md section 3): the model, IK and J^-1 t against independent computations.

The reference is py-opw-kinematics (a Rust implementation of the same paper, with its own
forward kinematics), pinocchio's FK and Jacobian of the model built from the parameters, and
HiGHS on the DTF LP.
"""

from __future__ import annotations

import math

import numpy as np
import py_opw_kinematics
import pytest

from solver.dtf import lp_speed
from solver.exceptions import InvalidInputError
from solver.families.base import OK, SINGULAR, UNREACHABLE
from solver.families.opw.catalogue import robot_from_opw
from solver.families.opw.ik import forward_kinematics, solve_components
from solver.families.opw.parameters import OpwParameters
from solver.kinematics import jacobian_in_base, tool_pose_in_base
from solver.robots import Robot, get_robot
from tests.cases import DTF_LP_RTOL, FK_IK_ATOL, OPW_MODELS

N_POSES = 1000


def reference(robot: Robot) -> py_opw_kinematics.Robot:
    """py-opw-kinematics for a catalogue arm (radians; flip_axes = sign correction -1)."""
    p = robot.family.parameters
    model = py_opw_kinematics.KinematicModel(
        a1=p.a1,
        a2=p.a2,
        b=p.b,
        c1=p.c1,
        c2=p.c2,
        c3=p.c3,
        c4=p.c4,
        offsets=tuple(p.offsets),
        flip_axes=tuple(s < 0 for s in p.sign_corrections),
    )
    return py_opw_kinematics.Robot(model, degrees=False)


def random_configurations(robot: Robot, count: int, seed: int) -> np.ndarray:
    """Joint positions uniformly inside the limits (at most one turn wide), shape (count, 6)."""
    rng = np.random.default_rng(seed)
    lower = np.maximum(robot.q_lower, -math.pi)
    upper = np.minimum(robot.q_upper, math.pi)
    return rng.uniform(lower, upper, (count, 6))


def wrapped_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest joint difference modulo 2 pi, over the last axis."""
    return np.max(np.abs((a - b + math.pi) % (2 * math.pi) - math.pi), axis=-1)


@pytest.fixture(scope="module", params=OPW_MODELS)
def arm(request: pytest.FixtureRequest) -> dict:
    robot = get_robot(request.param)
    q = random_configurations(robot, N_POSES, seed=OPW_MODELS.index(request.param))
    poses = np.array([tool_pose_in_base(robot, qi) for qi in q])
    solutions, status = solve_components(
        robot.family.parameters, np.moveaxis(poses[:, :3, :3], 0, -1), poses[:, :3, 3].T
    )
    return {"robot": robot, "q": q, "poses": poses, "solutions": solutions, "status": status}


def test_model_fk_is_the_opw_forward_formula(arm: dict) -> None:
    """pinocchio FK of the built model = py-opw-kinematics' forward = the paper's, to 1e-12."""
    robot, q, poses = arm["robot"], arm["q"], arm["poses"]
    theirs = np.array([reference(robot).forward(tuple(qi)).as_matrix() for qi in q[:200]])
    np.testing.assert_allclose(poses[:200], theirs, atol=1e-12)
    np.testing.assert_allclose(poses, forward_kinematics(robot.family.parameters, q), atol=1e-12)


def test_fk_of_ik_is_the_pose(arm: dict) -> None:
    """FK(IK(T)) = T to 1e-9 on every solution of 1000 reachable poses; the seed is among them."""
    robot, q, poses = arm["robot"], arm["q"], arm["poses"]
    solutions, status = arm["solutions"], arm["status"]
    assert np.all((status != UNREACHABLE).sum(axis=0) >= 1)
    found = np.zeros(N_POSES, dtype=bool)
    for b in range(8):
        ok = status[b] != UNREACHABLE
        fk = forward_kinematics(robot.family.parameters, solutions[:, b, ok].T)
        np.testing.assert_allclose(fk, poses[ok], atol=FK_IK_ATOL)
        pin_fk = np.array([tool_pose_in_base(robot, qi) for qi in solutions[:, b, ok].T[:50]])
        np.testing.assert_allclose(pin_fk, poses[ok][:50], atol=FK_IK_ATOL)
        found[ok] |= wrapped_distance(solutions[:, b, ok].T, q[ok]) < 1e-7
    assert found.all()


def test_solutions_are_py_opw_kinematics_and_back(arm: dict) -> None:
    robot, poses = arm["robot"], arm["poses"]
    solutions, status = arm["solutions"], arm["status"]
    solver = reference(robot)
    for i in range(N_POSES):
        theirs = np.array(solver.inverse(solver.forward(tuple(arm["q"][i]))))
        ours = solutions[:, status[:, i] != UNREACHABLE, i].T
        assert len(theirs) == len(ours)
        assert all(wrapped_distance(ours, s).min() < 1e-8 for s in theirs)
        assert all(wrapped_distance(theirs, s).min() < 1e-8 for s in ours)
    assert poses.shape == (N_POSES, 4, 4)


def test_branch_labels_follow_a_small_move(arm: dict) -> None:
    """A solution moved by a small dq is found again on the same branch (away from the wrist
    singularity, which a move can cross: the labels change only there)."""
    robot = arm["robot"]
    params = robot.family.parameters
    moved = arm["solutions"] + 1e-4
    status = arm["status"]
    theta5 = moved[4] * params.sign_corrections[4] - params.offsets[4]
    for b in range(8):
        ok = (status[b] == OK) & (np.abs(np.sin(theta5[b])) > 1e-3)
        start = moved[:, b, ok].T
        poses = forward_kinematics(params, start)
        again, again_status = solve_components(
            params, np.moveaxis(poses[:, :3, :3], 0, -1), poses[:, :3, 3].T
        )
        same = again_status[b] == OK
        assert same.mean() > 0.99
        assert np.all(wrapped_distance(again[:, b, same].T, start[same]) < 1e-6)


def test_closed_form_speeds_equal_a_jacobian_solve(arm: dict) -> None:
    """J^-1 t in closed form = pinocchio's Jacobian and a 6x6 solve, to 1e-9 relative."""
    rng = np.random.default_rng(7)
    tcp = np.eye(4)
    tcp[:3, :3] = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
    tcp[:3, 3] = [0.1, 0.02, 0.05]
    robot = arm["robot"].with_options(transform_tool_to_tcp=tcp)
    q, expected, twists, points = [], [], [], []
    for qi in arm["q"]:
        jacobian = jacobian_in_base(robot, qi)
        if np.linalg.cond(jacobian) > 1e6:
            continue
        twist = rng.normal(size=6)
        q.append(qi)
        expected.append(np.linalg.solve(jacobian, twist))
        twists.append(twist)
        points.append(tool_pose_in_base(robot, qi)[:3, 3])
    assert len(q) > 900
    ours = robot.family.joint_speeds_per_unit_twist(
        np.array(q).T, np.array(twists).T, np.array(points).T
    ).T
    scale = np.max(np.abs(expected), axis=1, keepdims=True)
    np.testing.assert_allclose(ours / scale, np.array(expected) / scale, atol=1e-9)


def test_dtf_equals_the_lp(arm: dict) -> None:
    """V_max = 1 / ||W J^-1 t||_inf from the closed form = HiGHS on the LP, to 1e-9."""
    robot = arm["robot"]
    rng = np.random.default_rng(8)
    for qi in arm["q"][:100]:
        jacobian = jacobian_in_base(robot, qi)
        if np.linalg.cond(jacobian) > 1e6:
            continue
        twist = rng.normal(size=6)
        point = tool_pose_in_base(robot, qi)[:3, 3]
        speeds = robot.family.joint_speeds_per_unit_twist(qi, twist, point)
        closed = 1.0 / np.max(np.abs(speeds) / robot.qdot_max)
        lp, _ = lp_speed(jacobian, twist, qdot_max=robot.qdot_max)
        assert closed == pytest.approx(lp, rel=DTF_LP_RTOL)


@pytest.mark.parametrize("name", OPW_MODELS)
def test_wrist_singularity_is_flagged(name: str) -> None:
    """theta5 = 0 (paper angle): both wrists of the seed's arm are singular, none crashes."""
    robot = get_robot(name)
    p = robot.family.parameters
    q = np.array([0.3, 0.2, 0.1, 0.4, 0.0, 0.5])
    q[4] = p.offsets[4] * p.sign_corrections[4]  # maker's q5 where theta5 = 0
    pose = tool_pose_in_base(robot, q)
    solutions, status = solve_components(p, pose[:3, :3, None], pose[:3, 3, None])
    reached = status[:, 0] != UNREACHABLE
    same_arm = wrapped_distance(solutions[:3, :, 0].T, q[:3]) < 1e-7
    assert same_arm.sum() == 2 and np.all(status[same_arm, 0] == SINGULAR)
    fk = forward_kinematics(p, solutions[:, reached, 0].T)
    np.testing.assert_allclose(fk, np.broadcast_to(pose, fk.shape), atol=FK_IK_ATOL)


KR6 = dict(a1=0.025, a2=-0.035, b=0.0, c1=0.4, c2=0.315, c3=0.365, c4=0.08)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"c2": 0.0}, "robot.opw.c2"),
        ({"c3": -0.1}, "robot.opw.c3"),
        ({"a1": 150.0}, "robot.opw.a1"),
        ({"c1": math.nan}, "robot.opw.c1"),
        ({"offsets": (0.0,) * 5}, "robot.opw.offsets"),
        ({"sign_corrections": (1, 1, 1, 1, 1)}, "robot.opw.sign_corrections"),
        ({"sign_corrections": (1, 1, 1, 1, 1, 0.5)}, "robot.opw.sign_corrections"),
    ],
)
def test_bad_parameters_name_the_field(change: dict, field: str) -> None:
    with pytest.raises(InvalidInputError) as error:
        OpwParameters(**{**KR6, **change})
    assert error.value.field == field


@pytest.mark.parametrize(
    "limits",
    [[[-3.0, 3.0]] * 5, [[-3.0, 3.0]] * 5 + [[1.0, 1.0]], [[-3.0, 3.0]] * 5 + [[2.0, -2.0]]],
    ids=["five pairs", "empty range", "reversed"],
)
def test_bad_position_limits(limits: list) -> None:
    with pytest.raises(InvalidInputError) as error:
        robot_from_opw("arm", OpwParameters(**KR6), joint_position_limits=limits, qdot_max=[3] * 6)
    assert error.value.field == "robot.joint_position_limits"
