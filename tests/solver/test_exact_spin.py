"""Free spin with an angled or offset spindle, and on seven joints: the joint path the spins give.

cam.md section 2: the answer's spins realise its mu_path. Where the spin moves more than the
last joint (a tool axis off the last joint's axis, or seven joints), the joint path is solved
at the spun poses (solver/path/exact_spin.py); before, it was the schedule's first-order sum,
off the path by millimetres, and mu_path the LP's bound at the unspun configurations, above
what that joint path can run (the robots audit of stop 55: 12 % on the published KR210 L150).
Checked here against forward kinematics and a DTF written in the test (pinocchio's Jacobian at
the answer's joints, the twist of the spun poses from scipy's rotations).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize
from scipy.spatial.transform import Rotation

from solver.core.kinematics import jacobian_in_base, straight_spindle, tool_pose_in_base
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.path.kernel_cells import kernel_of
from tests.problems import capability_map, evaluate_path, evaluate_placements, prepare_path, problem
from tests.solver.families.test_opw import build
from tests.solver.test_evaluate import load_path, segment_twists
from tests.solver.test_map_kernel import opw_grid

PLACEMENT = Placement(0.0, 0.45, 0.1, 0.0)


def _tcp(tilt: float, offset: tuple[float, float, float]) -> np.ndarray:
    """A tool point ``offset`` from the flange, its z turned ``tilt`` about the flange's y."""
    tcp = np.eye(4)
    tcp[:3, :3] = Rotation.from_rotvec([0.0, tilt, 0.0]).as_matrix()
    tcp[:3, 3] = offset
    return tcp


def _angled_ur5() -> Robot:
    return get_robot("ur5").with_options(transform_tool_to_tcp=_tcp(0.5, (0.03, 0.0, 0.12)))


def _spun_poses(path: np.ndarray, placement: Placement, spins: np.ndarray) -> np.ndarray:
    """The path in {B} with each tool pose turned by its spin about its own z."""
    turn = np.tile(np.eye(4), (len(spins), 1, 1))
    turn[:, :3, :3] = Rotation.from_rotvec(np.outer(spins, [0.0, 0.0, 1.0])).as_matrix()
    out: np.ndarray = placement.transform_workpiece_to_base() @ path @ turn
    return out


def _spin_free_lp(
    jacobian: np.ndarray, twist: np.ndarray, axis: np.ndarray, limits: np.ndarray
) -> float:
    """HiGHS on max s s.t. J qdot = s t_hat + sigma [0; z], |qdot| <= limits, sigma free."""
    n = jacobian.shape[1]
    cost = np.zeros(n + 2)
    cost[n] = -1.0
    spin = np.concatenate([np.zeros(3), axis])
    result = scipy.optimize.linprog(
        cost,
        A_eq=np.hstack([jacobian, -twist[:, None], -spin[:, None]]),
        b_eq=np.zeros(6),
        bounds=[(-m, m) for m in limits] + [(0.0, None), (None, None)],
        method="highs",
    )
    assert result.status == 0, result.message
    return float(result.x[n])


def _independent_mu(robot: Robot, q: np.ndarray, poses: np.ndarray) -> float:
    """min over waypoints of V_max = 1 / max_j |J^-1 t_hat|_j / qdot_max_j, at the given q.

    t_hat of segment i from the poses (u_T, and u_R / h from scipy's rotation vector of
    R_{i+1} R_i^T), the last waypoint its segment's; J pinocchio's at the tool point.
    """
    speeds = []
    for i, twist in enumerate(segment_twists(poses)):
        qd = np.linalg.solve(jacobian_in_base(robot, q[i]), twist)
        speeds.append(1.0 / np.max(np.abs(qd) / robot.qdot_max))
    return float(min(speeds))


def test_a_straight_spindle_is_straight_and_an_angled_or_offset_one_is_not() -> None:
    ur5 = get_robot("ur5")
    assert straight_spindle(ur5)
    assert straight_spindle(ur5.with_options(transform_tool_to_tcp=_tcp(0.0, (0.0, 0.0, 0.2))))
    assert straight_spindle(ur5.with_options(transform_tool_to_tcp=_tcp(np.pi, (0.0, 0.0, 0.2))))
    assert not straight_spindle(ur5.with_options(transform_tool_to_tcp=_tcp(0.3, (0, 0, 0.1))))
    assert not straight_spindle(ur5.with_options(transform_tool_to_tcp=_tcp(0.0, (0.01, 0, 0.1))))


def test_an_angled_spindles_free_spin_joint_path_follows_the_spun_path() -> None:
    """FK of every waypoint's q is the path turned by the answer's spin there (was mm off)."""
    robot, path = _angled_ur5(), load_path("curved_line")
    answer = evaluate_path(robot, path, PLACEMENT, spin_mode="free")
    assert answer.feasible and answer.q is not None and answer.spins is not None
    assert np.ptp(answer.spins) > 0.05  # the schedule turns the tool: the case at stake
    poses = _spun_poses(path, PLACEMENT, answer.spins)
    reached = np.array([tool_pose_in_base(robot, q) for q in answer.q])
    assert np.abs(reached - poses).max() < 1e-9


def test_an_angled_spindles_free_spin_mu_path_is_what_its_joint_path_runs() -> None:
    """mu_path = the DTF of the answer's own joint path along its spins (was the LP's bound)."""
    robot, path = _angled_ur5(), load_path("curved_line")
    answer = evaluate_path(robot, path, PLACEMENT, spin_mode="free")
    assert answer.mu_path is not None and answer.q is not None and answer.spins is not None
    poses = _spun_poses(path, PLACEMENT, answer.spins)
    assert answer.mu_path == pytest.approx(_independent_mu(robot, answer.q, poses), rel=1e-9)
    fixed = evaluate_path(robot, path, PLACEMENT, spin_mode="fixed")
    assert fixed.mu_path is not None and answer.mu_path > fixed.mu_path  # the spin still pays


def test_a_seven_joint_arms_free_spin_joint_path_follows_the_spun_path() -> None:
    """The xArm7's spin moves every joint: its q were the schedule's first-order sum (5.9 mm)."""
    robot, path = get_robot("xarm7"), load_path("curved_line")
    placement = Placement(0.16355274202439468, 0.13315994603655779, 0.1, -0.717454380680806)
    answer = evaluate_path(robot, path, placement, spin_mode="free")
    assert answer.feasible and answer.q is not None and answer.spins is not None
    assert np.ptp(answer.spins) > 0.05
    poses = _spun_poses(path, placement, answer.spins)
    reached = np.array([tool_pose_in_base(robot, q) for q in answer.q])
    assert np.abs(reached - poses).max() < 1e-9


def test_an_angled_spindles_free_spin_map_runs_the_pipeline_and_equals_evaluate() -> None:
    """No compiled kernel there (it moves the joints to first order); every cell = evaluate."""
    robot, path = _angled_ur5(), load_path("curved_line")
    assert kernel_of(problem(robot, path, spin_mode="free")) is None
    assert kernel_of(problem(robot, path, spin_mode="fixed")) is not None
    assert kernel_of(problem(get_robot("ur5"), path, spin_mode="free")) is not None
    xs, ys = np.array([-0.1, 0.05, 0.2]), np.array([0.35, 0.5])
    cmap = capability_map(robot, path, xs=xs, ys=ys, z=0.1, yaws=np.zeros(1), spin_mode="free")
    for j, y in enumerate(ys):
        for i, x in enumerate(xs):
            answer = evaluate_path(robot, path, Placement(x, y, 0.1, 0.0), spin_mode="free")
            cell = cmap.mu_path[0, 0, j, i]
            assert (np.isfinite(cell) and answer.mu_path == cell) or (
                not np.isfinite(cell) and not answer.feasible
            )


def test_the_spins_are_where_the_spun_joints_need_them() -> None:
    """The answer is near its own fixed point: the spin-free LP at its own joints (the path's
    t_hat, the tool's z there; HiGHS in the test) is within 0.5 % of its mu_path.

    One schedule of the LP at the unspun joints left the UR5's spun path at 0.729 m/s where
    the LP at those spun joints allowed 1.094 (33 % apart); the rounds (solver/path/
    pipeline.py, exact_spin.ROUNDS) take the LP where the last round's joints were: 1.1037.
    """
    robot, path = _angled_ur5(), load_path("curved_line")
    answer = evaluate_path(robot, path, PLACEMENT, spin_mode="free")
    assert answer.mu_path is not None and answer.q is not None
    poses = PLACEMENT.transform_workpiece_to_base() @ path  # unspun: the spin is the LP's
    bound = min(
        _spin_free_lp(
            jacobian_in_base(robot, q), t, tool_pose_in_base(robot, q)[:3, 2], robot.qdot_max
        )
        for q, t in zip(answer.q, segment_twists(poses), strict=True)
    )
    assert answer.mu_path <= bound * (1 + 1e-9)
    assert answer.mu_path >= 0.995 * bound


def test_a_placements_answer_is_its_own_in_a_map_or_alone() -> None:
    """Each branch runs every round and keeps its fastest, whatever else runs with it.

    The rounds need not rise (an IRB 2400 with its tool tilted 0.4 rad: 0.7292, 0.6993,
    1.0384, ...); when they stopped for a whole chunk once none of its branches gained, a cell
    of this map and the same placement evaluated alone differed on 7 of 81 cells, by up to
    42 %: a map's best cell was not what /v1/evaluate answered there.
    """
    robot = build("abb_irb2400").with_options(transform_tool_to_tcp=_tcp(0.4, (0.0, 0.04, 0.1)))
    path = prepare_path(robot, load_path("curved_line"))
    placements = opw_grid(robot)[::3]
    together = evaluate_placements(robot, path, placements, spin_mode="free")
    assert np.isfinite(together.mu_path).sum() >= 20
    for c, placement in enumerate(placements):
        alone = evaluate_placements(robot, path, placement[None], spin_mode="free")
        assert alone.reason[0] == together.reason[c], c
        assert alone.branch[0] == together.branch[c], c
        np.testing.assert_allclose(alone.mu_path[0], together.mu_path[c], rtol=1e-12, err_msg=c)
