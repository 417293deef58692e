"""The path index mu_path of a workpiece placement (spec section 4, ERK 2021 eq. 19).

A placement is feasible when every waypoint has an IK solution on one branch, followed
continuously along the path (no branch switch, no joint moving more than ``max_joint_step``
between neighbours, no singular configuration) and within the joint position limits, each joint
taken with the 2 pi copy that fits (:mod:`solver.tracking`). Then mu_path = min_i V_max(i) is
the highest constant feed rate at which no joint exceeds its speed limit anywhere on the path.
This evaluator takes its Jacobians from pinocchio; the capability map shares its IK and
tracking but not its Jacobians, so the two check each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.dtf import closed_form_batch
from solver.exceptions import InvalidInputError, NoAnalyticIkError
from solver.ik.ur_analytic import BRANCHES, Branch, branch_index, solve_components
from solver.kinematics import jacobian_in_base
from solver.robots import Robot
from solver.spatial import Placement
from solver.task import TaskRequirements, task_requirements
from solver.tracking import FEASIBLE, REASONS, Reason, choose_branch, track
from solver.ur_dh import UrDh

__all__ = ["Branch", "PathEvaluation", "evaluate_path", "DEFAULT_MAX_JOINT_STEP"]

DEFAULT_MAX_JOINT_STEP = 0.35


@dataclass(frozen=True)
class PathEvaluation:
    """mu_path and per-waypoint detail of a path at one placement, all in {B}.

    Attributes:
        feasible: every waypoint reachable on one continuous branch within limits.
        mu_path: min over waypoints of V_max (m/s); ``None`` when infeasible.
        bottleneck_waypoint: where V_max is smallest (the first such waypoint).
        bottleneck_joint: the joint on its speed limit there.
        reason: ``unreachable``, ``joint_limits``, ``singular`` or ``discontinuous``.
        failed_waypoint: the first waypoint that fails.
        branch: the IK branch used (for an infeasible ``auto``, the one that got furthest).
        u_T: shape (N, 3). u_R: shape (N, 3). h: shape (N,), m, inf for pure translation.
        q: shape (N, n), rad. v_max: shape (N,), m/s. omega_max: shape (N,), rad/s.
        qdot: shape (N, n), rad/s at V_max. limiting_joint: shape (N,). These five are
            ``None`` when infeasible.
    """

    feasible: bool
    mu_path: float | None
    bottleneck_waypoint: int | None
    bottleneck_joint: int | None
    reason: Reason | None
    failed_waypoint: int | None
    branch: Branch | None
    u_T: np.ndarray
    u_R: np.ndarray
    h: np.ndarray
    q: np.ndarray | None = None
    v_max: np.ndarray | None = None
    omega_max: np.ndarray | None = None
    qdot: np.ndarray | None = None
    limiting_joint: np.ndarray | None = None


def check_max_joint_step(max_joint_step: float) -> None:
    """Raise InvalidInputError unless the step is finite and > 0 (rad)."""
    if not (math.isfinite(max_joint_step) and max_joint_step > 0.0):
        raise InvalidInputError("ik.max_joint_step", f"{max_joint_step!r} rad must be > 0")


def require_analytic_ik(robot: Robot) -> UrDh:
    """The robot's DH parameters for the analytic IK; NoAnalyticIkError when it has none."""
    if robot.dh is None:
        raise NoAnalyticIkError(
            "robot", f"path evaluation needs a UR arm with analytic IK; {robot.name!r} has none"
        )
    return robot.dh


def _speeds(
    robot: Robot, q_path: np.ndarray, requirements: TaskRequirements
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """DTF along a joint path: V_max, Omega_max, qdot and the limiting joint per waypoint."""
    jacobians = np.array([jacobian_in_base(robot, q) for q in q_path])
    speed, qdot, limiting = closed_form_batch(jacobians, requirements.twists(), robot.qdot_max)
    h = requirements.h
    pure_rotation = h == 0.0
    v_max = np.where(pure_rotation, 0.0, speed)
    with np.errstate(divide="ignore", invalid="ignore"):
        omega_max = np.where(pure_rotation, speed, np.where(np.isinf(h), 0.0, speed / h))
    return v_max, omega_max, qdot, limiting


def evaluate_path(
    robot: Robot,
    waypoints_in_workpiece: np.ndarray,
    placement: Placement,
    *,
    branch: Branch | None = None,
    max_joint_step: float = DEFAULT_MAX_JOINT_STEP,
) -> PathEvaluation:
    """mu_path of a path at a placement (spec sections 1-4).

    Args:
        robot: a UR arm of the catalogue (it needs ``robot.dh``), with its speed limits and TCP.
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i, tool point poses in {O} (metres).
        placement: where {O} sits in {B}.
        branch: the IK branch to follow; ``None`` is ``auto``, the feasible branch with the
            highest mu_path.
        max_joint_step: rad, > 0, the largest move of any joint between neighbouring waypoints.

    Raises:
        NoAnalyticIkError: the robot has no analytic IK.
        InvalidInputError: a bad path or step.
        RepeatedWaypointError: two consecutive waypoints are the same pose.
    """
    dh = require_analytic_ik(robot)
    check_max_joint_step(max_joint_step)
    workpiece_to_base = placement.transform_workpiece_to_base()
    poses = workpiece_to_base @ np.asarray(waypoints_in_workpiece, dtype=float)
    requirements = task_requirements(poses)
    flange = poses @ np.linalg.inv(robot.transform_tool_to_tcp)
    q_all, status = solve_components(dh, np.moveaxis(flange[:, :3, :3], 0, -1), flange[:, :3, 3].T)
    tracked = track(
        q_all,
        status,
        lower=robot.q_lower,
        upper=robot.q_upper,
        max_joint_step=max_joint_step,
    )
    indices = np.arange(len(BRANCHES)) if branch is None else np.array([branch_index(branch)])
    feasible = tracked.reason[indices] == FEASIBLE
    speeds = {int(b): _speeds(robot, tracked.q[:, b].T, requirements) for b in indices[feasible]}
    mu_branch = np.array([np.min(speeds[b][0]) if b in speeds else np.nan for b in indices])
    b = int(indices[choose_branch(mu_branch, feasible, tracked.failed_waypoint[indices])])
    common = {"u_T": requirements.u_T, "u_R": requirements.u_R, "h": requirements.h}
    if b not in speeds:
        return PathEvaluation(
            feasible=False,
            mu_path=None,
            bottleneck_waypoint=None,
            bottleneck_joint=None,
            reason=REASONS[int(tracked.reason[b])],
            failed_waypoint=int(tracked.failed_waypoint[b]),
            branch=BRANCHES[b],
            **common,
        )
    v_max, omega_max, qdot, limiting = speeds[b]
    bottleneck = int(np.argmin(v_max))
    return PathEvaluation(
        feasible=True,
        mu_path=float(v_max[bottleneck]),
        bottleneck_waypoint=bottleneck,
        bottleneck_joint=int(limiting[bottleneck]),
        reason=None,
        failed_waypoint=None,
        branch=BRANCHES[b],
        q=tracked.q[:, b].T,
        v_max=v_max,
        omega_max=omega_max,
        qdot=qdot,
        limiting_joint=limiting,
        **common,
    )
