"""The path index mu_path of a workpiece placement (spec section 4, ERK 2021 eq. 19).

A placement is feasible when every waypoint has an IK solution on one branch, followed
continuously along the path (no branch switch, no joint moving more than ``max_joint_step``
between neighbours, no singular configuration) and within the joint position limits, each joint
taken with the 2 pi copy that fits. Then mu_path = min_i V_max(i) is the highest constant feed
rate at which no joint exceeds its speed limit anywhere on the path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.dtf import closed_form_batch
from solver.exceptions import InvalidInputError, NoAnalyticIkError
from solver.ik.ur_analytic import (
    BRANCHES,
    N_BRANCHES,
    SINGULAR,
    UNREACHABLE,
    Branch,
    branch_index,
    solve_batch,
    wrap_angle,
)
from solver.kinematics import jacobian_in_base
from solver.robots import Robot
from solver.spatial import Placement
from solver.task import TaskRequirements, task_requirements

__all__ = ["Branch", "PathEvaluation", "evaluate_path", "DEFAULT_MAX_JOINT_STEP"]

DEFAULT_MAX_JOINT_STEP = 0.35
_TWO_PI = 2 * math.pi
_EDGE = 1e-12  # slack (rad) when fitting a joint's 2 pi copy inside its limits


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
    reason: str | None
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


@dataclass(frozen=True)
class _Failure:
    reason: str
    waypoint: int


def _first(mask: np.ndarray) -> int | None:
    """Index of the first True of a 1-D mask, or None."""
    hits = np.flatnonzero(mask)
    return int(hits[0]) if hits.size else None


def track_branch(
    q_branch: np.ndarray,
    status: np.ndarray,
    *,
    lower: np.ndarray,
    upper: np.ndarray,
    max_joint_step: float,
) -> np.ndarray | _Failure:
    """Follow one IK branch along a path.

    Args:
        q_branch: shape (N, 6), rad in [-pi, pi), the branch's solution at every waypoint.
        status: shape (N,), the IK status codes of those solutions.
        lower: shape (6,), rad, lower position limits.
        upper: shape (6,), rad, upper position limits.
        max_joint_step: rad, the largest move of any joint between neighbouring waypoints.

    Returns:
        shape (N, 6), the continuous joint path with each joint's 2 pi copy chosen so that the
        whole path fits its limits (the first waypoint nearest zero among those that fit), or
        the first failure.
    """
    step = wrap_angle(np.diff(q_branch, axis=0))
    with np.errstate(invalid="ignore"):
        jump = np.concatenate([[False], np.any(np.abs(step) > max_joint_step, axis=1)])
    candidates = [
        (_first(status == UNREACHABLE), 0, "unreachable"),
        (_first(status == SINGULAR), 1, "singular"),
        (_first(jump), 2, "discontinuous"),
    ]
    failures = [(i, rank, reason) for i, rank, reason in candidates if i is not None]
    if failures:
        i, _, reason = min(failures)
        return _Failure(reason, i)
    path = q_branch[0] + np.concatenate([np.zeros((1, 6)), np.cumsum(step, axis=0)])
    k_low = np.ceil((lower - np.minimum.accumulate(path, axis=0)) / _TWO_PI - _EDGE)
    k_high = np.floor((upper - np.maximum.accumulate(path, axis=0)) / _TWO_PI + _EDGE)
    no_fit = _first(np.any(k_low > k_high, axis=1))
    if no_fit is not None:
        return _Failure("joint_limits", no_fit)
    shift = np.clip(np.round(-path[0] / _TWO_PI), k_low[-1], k_high[-1])
    shifted: np.ndarray = path + _TWO_PI * shift
    return shifted


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
    if robot.dh is None:
        raise NoAnalyticIkError(
            "robot", f"path evaluation needs a UR arm with analytic IK; {robot.name!r} has none"
        )
    if not (math.isfinite(max_joint_step) and max_joint_step > 0.0):
        raise InvalidInputError("ik.max_joint_step", f"{max_joint_step!r} rad must be > 0")
    workpiece_to_base = placement.transform_workpiece_to_base()
    poses = workpiece_to_base @ np.asarray(waypoints_in_workpiece, dtype=float)
    requirements = task_requirements(poses)
    flange_poses = poses @ np.linalg.inv(robot.transform_tool_to_tcp)
    q_all, status = solve_batch(robot.dh, flange_poses)
    indices = range(N_BRANCHES) if branch is None else [branch_index(branch)]
    best: tuple[float, int, np.ndarray, tuple[np.ndarray, ...]] | None = None
    furthest: tuple[int, int, _Failure] | None = None
    for b in indices:
        tracked = track_branch(
            q_all[:, b],
            status[:, b],
            lower=robot.q_lower,
            upper=robot.q_upper,
            max_joint_step=max_joint_step,
        )
        if isinstance(tracked, _Failure):
            if furthest is None or tracked.waypoint > furthest[0]:
                furthest = (tracked.waypoint, b, tracked)
            continue
        speeds = _speeds(robot, tracked, requirements)
        mu_path = float(np.min(speeds[0]))
        if best is None or mu_path > best[0]:
            best = (mu_path, b, tracked, speeds)
    common = {"u_T": requirements.u_T, "u_R": requirements.u_R, "h": requirements.h}
    if best is None:
        if furthest is None:  # Not reached: at least one branch is always tried.
            raise RuntimeError("no IK branch was evaluated")
        _, b, failure = furthest
        return PathEvaluation(
            feasible=False,
            mu_path=None,
            bottleneck_waypoint=None,
            bottleneck_joint=None,
            reason=failure.reason,
            failed_waypoint=failure.waypoint,
            branch=BRANCHES[b],
            **common,
        )
    mu_path, b, q_path, (v_max, omega_max, qdot, limiting) = best
    bottleneck = int(np.argmin(v_max))
    return PathEvaluation(
        feasible=True,
        mu_path=mu_path,
        bottleneck_waypoint=bottleneck,
        bottleneck_joint=int(limiting[bottleneck]),
        reason=None,
        failed_waypoint=None,
        branch=BRANCHES[b],
        q=q_path,
        v_max=v_max,
        omega_max=omega_max,
        qdot=qdot,
        limiting_joint=limiting,
        **common,
    )
