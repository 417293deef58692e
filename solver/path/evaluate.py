"""The path index mu_path of a workpiece placement (spec section 4, ERK 2021 eq. 19).

A placement is feasible when every waypoint has an IK solution on one branch, followed
continuously along the path (no branch switch, no joint moving more than ``max_joint_step``
between neighbours, no singular configuration) and within the joint position limits, each joint
taken with the 2 pi copy that fits (:mod:`solver.path.tracking`). Then mu_path = min_i V_max(i) is
the highest constant feed rate at which no joint exceeds its speed limit anywhere on the path.
This is the pipeline of :mod:`solver.path.pipeline` at one placement, with every waypoint's
detail on the chosen branch.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from solver.core.codes import FEASIBLE, REASONS, Reason
from solver.core.dtf import spin_rate_nearest_zero
from solver.core.family import Branch
from solver.core.spatial import Placement, rotation_about_z
from solver.path.pipeline import check_placements, run_chunk
from solver.path.problem import PathProblem, SpinMode

__all__ = ["Branch", "PathEvaluation", "evaluate_path"]


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
        spin_mode: ``fixed`` or ``free``, as asked.
        spins: shape (N,), rad, in ``free`` spin mode the spin schedule that realises mu_path
            (q is then the joint path along it); ``None`` otherwise.
        ik_seeds: how many seeds a numeric IK family started from at the first waypoint;
            ``None`` for an analytic family (which finds every branch).
        ik_branches_found: how many distinct IK solutions it found there (``None`` likewise).
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
    spin_mode: SpinMode = "fixed"
    spins: np.ndarray | None = None
    ik_seeds: int | None = None
    ik_branches_found: int | None = None


def _turned(vectors: np.ndarray, yaw: float) -> np.ndarray:
    """Rz(yaw) v for vectors of shape (N, 3)."""
    out: np.ndarray = vectors @ rotation_about_z(yaw).T
    return out


def evaluate_path(problem: PathProblem, placement: Placement) -> PathEvaluation:
    """mu_path of a path at a placement (spec sections 1-4).

    Args:
        problem: the robot (with a kinematics family, its speed limits and TCP), the tool
            path in {O} with its passes, and the options (branch, step bound, spin mode).
        placement: where {O} sits in {B}, and the tool spin (cam.md section 3).

    Raises:
        NoAnalyticIkError: the robot has no kinematics family.
        InvalidInputError: a bad path, step or branch name.
        RepeatedWaypointError: two consecutive waypoints are the same pose.
    """
    indices = problem.branches
    family = problem.family
    cell = check_placements(placement.as_row()[None])
    path = problem.prepared
    run = run_chunk(problem, cell)
    robot, spin_mode = problem.robot, problem.options.spin_mode
    pick = int(run.pick[0])
    reason = int(run.tracked.reason[pick, 0])
    infeasible = PathEvaluation(
        feasible=False,
        mu_path=None,
        bottleneck_waypoint=None,
        bottleneck_joint=None,
        reason=REASONS[reason] if reason != FEASIBLE else None,
        failed_waypoint=int(run.tracked.failed_waypoint[pick, 0]),
        branch=family.branches[int(indices[pick])],
        u_T=_turned(path.u_T, placement.yaw),
        u_R=_turned(path.u_R, placement.yaw),
        h=path.h,
        spin_mode=spin_mode,
        ik_seeds=run.ik_seeds,
        ik_branches_found=None if run.branches_found is None else int(run.branches_found[0]),
    )
    if reason != FEASIBLE:
        return infeasible
    speed, v_max = run.speed[pick, 0], run.v_max[pick, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        omega_max = np.where(
            path.pure_rotation, speed, np.where(np.isinf(path.h), 0.0, speed / path.h)
        )
    limiting = run.limiting[pick, 0]
    bottleneck = int(np.argmin(v_max))
    qdot = run.qd_unit[:, pick, 0] * speed
    spins = None
    if run.spins is not None and run.qd_spin is not None:
        spin_rate = spin_rate_nearest_zero(
            run.qd_unit[:, pick, 0], run.qd_spin[:, pick, 0], robot.qdot_max, speed
        )
        qdot = qdot + spin_rate * run.qd_spin[:, pick, 0]
        spins = run.spins[pick, 0]
    return dataclasses.replace(
        infeasible,
        feasible=True,
        mu_path=float(v_max[bottleneck]),
        bottleneck_waypoint=bottleneck,
        bottleneck_joint=int(limiting[bottleneck]),
        failed_waypoint=None,
        q=run.tracked.q[:, pick, 0].T,
        v_max=v_max,
        omega_max=omega_max,
        qdot=qdot.T,
        limiting_joint=limiting,
        spins=spins,
    )
