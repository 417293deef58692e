"""OPW arms (robots.md section 3): the model and the IK against independent computations.

The references are py-opw-kinematics (a Rust implementation of the same paper with its own
forward kinematics and IK) and pinocchio's FK of the model built from the parameters; J^-1 t is
in test_opw_speeds.py. The arms are robots.md's six table rows, given here directly (the catalogue
is checked against them in test_opw_catalogue.py), and two made-up geometries that the rows do
not cover: a shoulder offset b != 0, zero a1 and a2, and an offset on every joint under either
sign, where the paper's angle s q - o differs from s (q - o).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import py_opw_kinematics
import pytest
from scipy.spatial.transform import RigidTransform

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import Robot
from solver.families.opw.arms import ARMS
from solver.families.opw.catalogue import robot_from_opw
from solver.families.opw.ik import forward_kinematics, solve_components
from solver.families.opw.parameters import OpwParameters
from tests.cases import FK_IK_ATOL

N_POSES = 1000
_KUKA = ((0.0, -math.pi / 2, 0.0, 0.0, 0.0, 0.0), (-1, 1, 1, -1, 1, -1))
_ABB = ((0.0, 0.0, -math.pi / 2, 0.0, 0.0, 0.0), (1, 1, 1, 1, 1, 1))
_FANUC = ((0.0, 0.0, -math.pi / 2, 0.0, 0.0, math.pi), (1, 1, -1, -1, -1, -1))
# robots.md section 3: a1, a2, b, c1, c2, c3, c4 (m), offsets (rad), sign corrections.
ROWS: dict[str, OpwParameters] = {
    "kuka_kr6_r700_sixx": OpwParameters(0.025, -0.035, 0.0, 0.400, 0.315, 0.365, 0.080, *_KUKA),
    "kuka_kr16_2": OpwParameters(0.260, 0.035, 0.0, 0.675, 0.680, 0.670, 0.158, *_KUKA),
    "abb_irb2400": OpwParameters(0.100, -0.135, 0.0, 0.615, 0.705, 0.755, 0.085, *_ABB),
    "abb_irb4600_60_205": OpwParameters(0.175, -0.175, 0.0, 0.495, 0.900, 0.960, 0.135, *_ABB),
    "fanuc_m20ia": OpwParameters(0.150, -0.250, 0.0, 0.525, 0.790, 0.835, 0.100, *_FANUC),
    "fanuc_r2000ic_165f": OpwParameters(0.312, -0.225, 0.0, 0.670, 1.075, 1.280, 0.215, *_FANUC),
}
MADE_UP: dict[str, OpwParameters] = {
    "offsets_everywhere": OpwParameters(
        0.15,
        -0.12,
        0.09,
        0.5,
        0.7,
        0.65,
        0.11,
        (0.4, -1.1, 0.7, -0.3, 0.9, 2.0),
        (-1, 1, -1, -1, -1, 1),
    ),
    "tx40_like": OpwParameters(0.0, 0.0, 0.035, 0.32, 0.225, 0.225, 0.065, *_ABB),
}
GEOMETRIES = {**ROWS, **MADE_UP}


def build(name: str) -> Robot:
    """The arm as a robot: the catalogue's limits where it has the arm, else +-pi and 3 rad/s."""
    arm = next((a for a in ARMS if a.name == name), None)
    limits = arm.position_limits if arm else ((-math.pi, math.pi),) * 6
    speeds = arm.velocity_limits if arm else (3.0,) * 6
    return robot_from_opw(name, GEOMETRIES[name], joint_position_limits=limits, qdot_max=speeds)


def reference(p: OpwParameters) -> py_opw_kinematics.Robot:
    """py-opw-kinematics for a geometry (radians; flip_axes = sign correction -1)."""
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


def wrapped_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest joint difference modulo 2 pi, over the last axis."""
    return np.max(np.abs((a - b + math.pi) % (2 * math.pi) - math.pi), axis=-1)


def pinocchio_poses(robot: Robot, q: np.ndarray) -> np.ndarray:
    """T_B_F by pinocchio for joint sets q of shape (N, 6): shape (N, 4, 4)."""
    return np.array([tool_pose_in_base(robot, qi) for qi in q]).reshape(-1, 4, 4)


def solve(p: OpwParameters, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The batched IK of poses (N, 4, 4): q (6, 8, N), status (8, N)."""
    return solve_components(p, np.moveaxis(poses[:, :3, :3], 0, -1), poses[:, :3, 3].T)


def maker(p: OpwParameters, theta: np.ndarray) -> np.ndarray:
    """The maker's angles of the paper's, shape (..., 6)."""
    return (np.asarray(theta) + np.array(p.offsets)) * np.array(p.sign_corrections)


@pytest.fixture(scope="module", params=list(GEOMETRIES))
def arm(request: pytest.FixtureRequest) -> dict:
    """An arm, 1000 random joint sets within its limits (one turn at most), their poses and IK."""
    robot = build(request.param)
    rng = np.random.default_rng(list(GEOMETRIES).index(request.param))
    q = rng.uniform(
        np.maximum(robot.q_lower, -math.pi), np.minimum(robot.q_upper, math.pi), (N_POSES, 6)
    )
    poses = pinocchio_poses(robot, q)
    solutions, status = solve(GEOMETRIES[request.param], poses)
    return {
        "robot": robot,
        "p": GEOMETRIES[request.param],
        "q": q,
        "poses": poses,
        "solutions": solutions,
        "status": status,
    }


def test_model_fk_is_the_opw_forward_formula(arm: dict) -> None:
    """Pinocchio FK of the built model = py-opw-kinematics' forward = the paper's, to 1e-12."""
    p, q, poses = arm["p"], arm["q"], arm["poses"]
    theirs = np.array([reference(p).forward(tuple(qi)).as_matrix() for qi in q])
    np.testing.assert_allclose(poses, theirs, atol=1e-12)
    np.testing.assert_allclose(poses, forward_kinematics(p, q), atol=1e-12)


def test_fk_of_ik_is_the_pose(arm: dict) -> None:
    """Pinocchio FK of every solution of 1000 reachable poses is the pose to 1e-9; the joint set
    the pose came from is among the solutions."""
    robot, q, poses = arm["robot"], arm["q"], arm["poses"]
    solutions, status = arm["solutions"], arm["status"]
    reached = status != UNREACHABLE
    assert np.all(reached.sum(axis=0) >= 1)
    assert np.all(np.isnan(solutions[:, ~reached])) and not np.any(np.isnan(solutions[:, reached]))
    assert np.all((solutions[:, reached] >= -math.pi) & (solutions[:, reached] <= math.pi))
    found = np.zeros(N_POSES, dtype=bool)
    for b in range(8):
        ok = reached[b]
        np.testing.assert_allclose(
            pinocchio_poses(robot, solutions[:, b, ok].T), poses[ok], atol=FK_IK_ATOL
        )
        found[ok] |= wrapped_distance(solutions[:, b, ok].T, q[ok]) < 1e-7
    assert found.all()


def test_solutions_are_py_opw_kinematics_and_back(arm: dict) -> None:
    """Each of our solutions is one of py-opw-kinematics' (modulo 2 pi) and each of its ours."""
    solver = reference(arm["p"])
    solutions, status = arm["solutions"], arm["status"]
    for i, pose in enumerate(arm["poses"]):
        theirs = np.array(solver.inverse(RigidTransform.from_matrix(pose)))
        ours = solutions[:, status[:, i] != UNREACHABLE, i].T
        assert len(theirs) == len(ours)
        assert all(wrapped_distance(ours, s).min() < 1e-8 for s in theirs)
        assert all(wrapped_distance(theirs, s).min() < 1e-8 for s in ours)


def test_branches_are_py_opw_kinematics_slots(arm: dict) -> None:
    """Branch by branch: py-opw-kinematics' ``reach`` puts the same sign choices in slot
    4 wrist + 2 shoulder + elbow, ours in 4 shoulder + 2 elbow + wrist."""
    theirs = reference(arm["p"]).reach(RigidTransform.from_matrix(arm["poses"])).joints
    slots = [4 * wrist + 2 * shoulder + elbow for shoulder, elbow, wrist in np.ndindex(2, 2, 2)]
    theirs = np.transpose(theirs[:, slots], (2, 1, 0))  # (N, 8, 6) -> (6, 8, N), our order
    solutions = arm["solutions"]
    np.testing.assert_array_equal(np.isnan(theirs), np.isnan(solutions))
    reached = ~np.isnan(solutions[0])
    assert wrapped_distance(solutions[:, reached].T, theirs[:, reached].T).max() < 1e-8


def test_branch_labels_are_the_documented_signs(arm: dict) -> None:
    """Front: joint 1's x axis points to the wrist centre; up: theta3 + atan2(a2, c3) >= 0;
    noflip: theta5 >= 0 (paper's angles), on every OK solution."""
    p, poses, solutions, status = arm["p"], arm["poses"], arm["solutions"], arm["status"]
    theta = (
        solutions * np.array(p.sign_corrections)[:, None, None] - np.array(p.offsets)[:, None, None]
    )
    centre = poses[:, :3, 3] - p.c4 * poses[:, :3, 2]  # (N, 3)
    reach = np.cos(theta[0]) * centre[:, 0] + np.sin(theta[0]) * centre[:, 1]  # (8, N)
    elbow = np.sin(theta[2] + math.atan2(p.a2, p.c3))
    wrist = np.sin(theta[4])
    for b in range(8):
        ok = status[b] == OK
        assert np.all(reach[b, ok] > 0) if b < 4 else np.all(reach[b, ok] < 0)
        assert np.all(elbow[b, ok] > 0) if b % 4 < 2 else np.all(elbow[b, ok] < 0)
        assert np.all(wrist[b, ok] > 0) if b % 2 == 0 else np.all(wrist[b, ok] < 0)


def test_branch_labels_follow_a_small_move(arm: dict) -> None:
    """A solution moved by a small random dq is found again on the same branch (away from the
    wrist singularity, which a move can cross: the labels change only there)."""
    p, solutions, status = arm["p"], arm["solutions"], arm["status"]
    rng = np.random.default_rng(11)
    moved = solutions + rng.uniform(-1e-4, 1e-4, solutions.shape)
    theta5 = moved[4] * p.sign_corrections[4] - p.offsets[4]
    for b in range(8):
        ok = (status[b] == OK) & (np.abs(np.sin(theta5[b])) > 1e-3)
        start = moved[:, b, ok].T
        again, again_status = solve(p, forward_kinematics(p, start))
        same = again_status[b] == OK
        assert same.mean() > 0.99
        assert np.all(wrapped_distance(again[:, b, same].T, start[same]) < 1e-6)


def test_batch_axes_broadcast(arm: dict) -> None:
    """Rotations (3, 3, 4, 1) with positions (3, 1, 5) solve as the 20 pairs one by one."""
    p, poses = arm["p"], arm["poses"]
    rotation, position = poses[:4, :3, :3], poses[:5, :3, 3]
    q, status = solve_components(p, np.moveaxis(rotation, 0, -1)[..., None], position.T[:, None])
    assert q.shape == (6, 8, 4, 5) and status.shape == (8, 4, 5)
    pairs = np.tile(np.eye(4), (4, 5, 1, 1))
    pairs[:, :, :3, :3] = rotation[:, None]
    pairs[:, :, :3, 3] = position[None]
    one_by_one, one_status = solve(p, pairs.reshape(20, 4, 4))
    np.testing.assert_array_equal(status.reshape(8, 20), one_status)
    np.testing.assert_array_equal(q.reshape(6, 8, 20), one_by_one)


@pytest.mark.parametrize("name", list(GEOMETRIES))
def test_wrist_singularity_is_flagged(name: str) -> None:
    """Theta5 = 0: both wrists of the seed's arm are singular and still solutions."""
    p = GEOMETRIES[name]
    q = maker(p, [0.3, 0.2, 0.1, 0.4, 0.0, 0.5])
    pose = forward_kinematics(p, q)
    solutions, status = solve(p, pose[None])
    same_arm = wrapped_distance(solutions[:3, :, 0].T, q[:3]) < 1e-7
    assert same_arm.sum() == 2 and np.all(status[same_arm, 0] == SINGULAR)
    assert_solutions_reach(p, solutions[:, :, 0], status[:, 0], pose)


@pytest.mark.parametrize("name", list(GEOMETRIES))
def test_elbow_singularity_is_flagged(name: str) -> None:
    """The arm stretched (theta3 = -atan2(a2, c3)): the seed's shoulder is singular."""
    p = GEOMETRIES[name]
    q = maker(p, [0.3, 0.4, -math.atan2(p.a2, p.c3), 0.5, 0.8, -0.2])
    pose = forward_kinematics(p, q)
    solutions, status = solve(p, pose[None])
    same_shoulder = wrapped_distance(solutions[:1, :, 0].T, q[:1]) < 1e-7
    assert same_shoulder.sum() == 4 and np.all(status[same_shoulder, 0] == SINGULAR)
    assert wrapped_distance(solutions[:, same_shoulder, 0].T, q).min() < 1e-7
    assert_solutions_reach(p, solutions[:, :, 0], status[:, 0], pose)


@pytest.mark.parametrize("name", list(GEOMETRIES))
def test_shoulder_singularity_is_flagged(name: str) -> None:
    """The wrist centre on axis 1 (at distance b from it): every branch is singular."""
    p = GEOMETRIES[name]
    rotation = pin.exp3(np.array([0.3, -1.2, 0.7]))
    centre = np.array([0.0, p.b, p.c1 + 0.8 * (p.c2 + math.hypot(p.a2, p.c3))])
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, centre + p.c4 * rotation[:, 2]
    solutions, status = solve(p, pose[None])
    assert np.all(status[:, 0] == SINGULAR)
    assert_solutions_reach(p, solutions[:, :, 0], status[:, 0], pose)


@pytest.mark.parametrize("name", list(GEOMETRIES))
def test_far_poses_are_unreachable(name: str) -> None:
    """A wrist centre beyond the arm's reach, or nearer axis 1 than b: UNREACHABLE, NaN."""
    p = GEOMETRIES[name]
    poses = np.tile(np.eye(4), (2, 1, 1))
    poses[0, :3, 3] = [50.0, 0.0, 0.0]
    poses[1, :3, 3] = [0.0, p.b / 2, p.c1 + p.c4]  # z_F up: the wrist centre at height c1
    solutions, status = solve(p, poses)
    far = np.array([True, p.b != 0.0])
    assert np.all(status[:, far] == UNREACHABLE) and np.all(np.isnan(solutions[:, :, far]))


def assert_solutions_reach(
    p: OpwParameters, solutions: np.ndarray, status: np.ndarray, pose: np.ndarray
) -> None:
    """Every solution (6, 8) that is not UNREACHABLE has the flange at ``pose``."""
    reached = solutions[:, status != UNREACHABLE].T
    assert len(reached) > 0
    fk = forward_kinematics(p, reached)
    np.testing.assert_allclose(fk, np.broadcast_to(pose, fk.shape), atol=FK_IK_ATOL)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("position", [(1e200, 0.0, 1e200), (1e308, 1e308, 0.0), (0.0, 0.0, 1e300)])
def test_a_pose_far_beyond_reach_is_unreachable_without_a_warning(
    position: tuple[float, float, float],
) -> None:
    """Overflows to inf there were numpy RuntimeWarnings in the service's log (audit 22:
    ``overflow encountered`` at the elbow's and shoulder's cosines): the reach tests make the
    pose unreachable, which the answer says."""
    rotation = np.eye(3)[:, :, None]
    q, status = solve_components(ARMS[0].parameters, rotation, np.array(position)[:, None])
    assert np.isnan(q).all() and (status == UNREACHABLE).all()
