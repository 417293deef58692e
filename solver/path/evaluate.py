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
from solver.core.family import Branch
from solver.core.progress import Progress
from solver.core.spatial import Placement, rotation_about_z
from solver.core.two_variable_lp import spin_rate_nearest_zero
from solver.kernels.spin_lp import spin_rate_at_feed
from solver.path.bottleneck import bottleneck_waypoints
from solver.path.cell.verdict import CellVerdict, Contact, Unchecked
from solver.path.limits import (
    JointAccelerationLimit,
    JointMotion,
    PathVerdict,
    bound_by_limits,
    refused_reason,
)
from solver.path.path_checks import check_path, checks_model, clear_pick
from solver.path.pipeline import run_chunk
from solver.path.placed import check_placements
from solver.path.problem import PathProblem, SpinMode

__all__ = ["AccelerationIndex", "Branch", "PathEvaluation", "acceleration_index", "evaluate_path"]


@dataclass(frozen=True)
class AccelerationIndex:
    """mu_acc of a feasible path: the constant feed its joint accelerations allow (motion.md s. 2).

    Attributes:
        mu_acc: m/s, min(mu_path, min_i V_acc,i).
        limited_by: ``"speed"`` (mu_acc = mu_path) or ``"acceleration"``.
        waypoint: where it binds (the bottleneck of mu_path when the speed limits bind).
        joint: the joint that binds there.
        blend_length: b, m.
        v_acc: shape (N,), m/s, V_acc,i; inf where unconstrained (within b of a pass end, or
            D_i = 0).
        qdd: shape (N, n), rad/s^2, D_i mu_acc^2; NaN at the waypoints within b of a pass end.
    """

    mu_acc: float
    limited_by: str
    waypoint: int
    joint: int
    blend_length: float
    v_acc: np.ndarray
    qdd: np.ndarray


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
        acceleration: mu_acc and where it binds, with acceleration limits (else ``None``).
        collision: with a cell, where an infeasible path (reason ``collision``) first comes
            closer than the clearance (cell.md section 3); else ``None``.
        min_clearance: with a cell, the closest pair of a feasible path; else ``None``.
        cell_approximated: with a cell, the robot's links given capsules; else ``None``.
        cell_unchecked: with a cell, the robot parts not checked against a ``fixed`` object
            (no joint moves them relative to it: the base, joint 1's link on its table), with
            their distance; else ``None``.
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
    acceleration: AccelerationIndex | None = None
    collision: Contact | None = None
    min_clearance: Contact | None = None
    cell_approximated: tuple[str, ...] | None = None
    cell_unchecked: tuple[Unchecked, ...] | None = None

    @property
    def feed_index(self) -> float | None:
        """The constant feed the arm can run: mu_acc with acceleration limits, else mu_path.

        What the optimisers maximise and the map colours (motion.md section 3).
        """
        return self.mu_path if self.acceleration is None else self.acceleration.mu_acc


def acceleration_index(
    problem: PathProblem, q: np.ndarray, mu_path: float, bottleneck: tuple[int, int]
) -> AccelerationIndex | None:
    """mu_acc along a feasible joint path (motion.md section 2); None without final-path limits.

    Args:
        problem: the robot, the path and the options (the blend length).
        q: shape (N, n), rad, the final tracked joint path (in free spin along the spins).
        mu_path: m/s, its mu_path.
        bottleneck: (waypoint, joint) of mu_path.
    """
    limits = problem.final_path_limits
    if not limits:
        return None
    motion = JointMotion(q=q.T, qd_unit=np.zeros_like(q.T))
    bound, joint, binding = bound_by_limits(limits, motion)  # (N,)
    worst = int(np.argmin(bound)) if len(bound) else 0
    accelerated = len(bound) > 0 and bound[worst] < mu_path
    mu_acc = float(bound[worst]) if accelerated else mu_path
    qdd = np.full(q.shape, np.nan)
    blend = problem.options.blend_length
    for limit in limits:
        if isinstance(limit, JointAccelerationLimit):
            stencil, blend = limit.stencil, limit.stencil.blend_length
            qdd[stencil.waypoints] = stencil.second_difference(q.T).T * mu_acc**2
    return AccelerationIndex(
        mu_acc=mu_acc,
        limited_by=limits[int(binding[worst])].name if accelerated else "speed",
        waypoint=worst if accelerated else bottleneck[0],
        joint=int(joint[worst]) if accelerated else bottleneck[1],
        blend_length=blend,
        v_acc=bound,
        qdd=qdd,
    )


def _turned(vectors: np.ndarray, yaw: float) -> np.ndarray:
    """Rz(yaw) v for vectors of shape (N, 3)."""
    out: np.ndarray = vectors @ rotation_about_z(yaw).T
    return out


def evaluate_path(
    problem: PathProblem,
    placement: Placement,
    *,
    progress: Progress | None = None,
    thorough: bool = True,
) -> PathEvaluation:
    """mu_path of a path at a placement (spec sections 1-4).

    Args:
        problem: the robot (with a kinematics family, its speed limits and TCP), the tool
            path in {O} with its passes, and the options (branch, step bound, spin mode).
        placement: where {O} sits in {B}, and the tool spin (cam.md section 3).
        progress: called with the fraction done while a numeric family solves the path (a
            closed-form family's evaluation takes milliseconds); it may raise
            :class:`solver.core.progress.Cancelled` to stop the work.
        thorough: with a cell, its closest pair too (``min_clearance``); False: whether the
            path collides only, as a map checks it (the same verdict, ``min_clearance`` None:
            the optimisers' evaluations, :func:`with_min_clearance` adding it to the answer's).

    Raises:
        NoAnalyticIkError: the robot has no kinematics family.
        InvalidInputError: a bad path, step or branch name.
        RepeatedWaypointError: two consecutive waypoints are the same pose.
    """
    indices = problem.branches
    family = problem.family
    cell = check_placements(placement.as_row()[None])
    path = problem.prepared
    run = run_chunk(problem, cell, progress=progress)
    robot, spin_mode = problem.robot, problem.options.spin_mode
    pick = int(run.pick[0])
    reason = int(run.tracked.reason[pick, 0])
    verdict: PathVerdict | None = None
    collision, model, refused_at = None, {}, None
    if reason == FEASIBLE and problem.path_checks:
        chosen, verdict, refusal = clear_pick(problem, run, cell, 0, thorough=thorough)
        model = checks_model(problem)
        if chosen is None and refusal is not None:
            reason, refused_at = refused_reason(refusal), refusal.failed_waypoint
            report = cell_report(refusal)
            collision = None if report is None else report.collision
        else:
            pick = int(chosen) if chosen is not None else pick
    infeasible = PathEvaluation(
        feasible=False,
        mu_path=None,
        bottleneck_waypoint=None,
        bottleneck_joint=None,
        reason=REASONS[reason] if reason != FEASIBLE else None,
        failed_waypoint=int(run.tracked.failed_waypoint[pick, 0])
        if refused_at is None
        else refused_at,
        branch=family.branches[int(indices[pick])],
        u_T=_turned(path.u_T, placement.yaw),
        u_R=_turned(path.u_R, placement.yaw),
        h=path.h,
        spin_mode=spin_mode,
        ik_seeds=run.ik_seeds,
        ik_branches_found=None if run.branches_found is None else int(run.branches_found[0]),
        collision=collision,
        **model,
    )
    if reason != FEASIBLE:
        return infeasible
    speed, v_max = run.speed[pick, 0], run.v_max[pick, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        omega_max = np.where(
            path.pure_rotation, speed, np.where(np.isinf(path.h), 0.0, speed / path.h)
        )
    limiting = run.limiting[pick, 0]
    bottleneck = int(bottleneck_waypoints(v_max))
    qdot = run.qd_unit[:, pick, 0] * speed
    spins = None if run.spins is None else run.spins[pick, 0]
    if run.spins is not None and run.qd_spin is not None:  # else the spun path's own (exact_spin)
        a, c = run.qd_unit[:, pick, 0], run.qd_spin[:, pick, 0]
        if run.qd_null is None:
            spin_rate = spin_rate_nearest_zero(a, c, robot.qdot_max, speed)
        else:  # seven joints: the spin LP's null-space rate too
            b = run.qd_null[:, pick, 0]
            spin_rate, null_rate = spin_rate_at_feed(a, c, b, robot.qdot_max, speed)
            qdot = qdot + null_rate * b
        qdot = qdot + spin_rate * c
    q = run.tracked.q[:, pick, 0].T
    mu_path = float(np.min(v_max))  # V_max at the bottleneck, or a last bit below (a tie)
    return dataclasses.replace(
        infeasible,
        feasible=True,
        mu_path=mu_path,
        bottleneck_waypoint=bottleneck,
        bottleneck_joint=int(limiting[bottleneck]),
        failed_waypoint=None,
        acceleration=acceleration_index(
            problem, q, mu_path, (bottleneck, int(limiting[bottleneck]))
        ),
        q=q,
        v_max=v_max,
        omega_max=omega_max,
        qdot=qdot.T,
        limiting_joint=limiting,
        spins=spins,
        min_clearance=closest_of(verdict),
    )


def with_min_clearance(
    problem: PathProblem, placement: Placement, evaluation: PathEvaluation
) -> PathEvaluation:
    """``evaluation`` (:func:`evaluate_path`, not thorough) with the closest pair of its cell.

    What a thorough evaluation answers: the path's verdict is the same (the first collision
    along it, found by either check), so only ``min_clearance`` is added, from the thorough
    check of the answer's own joint path. An evaluation without a cell, infeasible, or
    already thorough is returned as it is.
    """
    if evaluation.q is None or not problem.path_checks or evaluation.min_clearance is not None:
        return evaluation
    verdict = check_path(problem, evaluation.q, placement.as_row(), thorough=True)
    if verdict is None:
        return evaluation
    return dataclasses.replace(evaluation, min_clearance=closest_of(verdict))


def cell_report(verdict: PathVerdict | None) -> CellVerdict | None:
    """The cell's report in a path check's verdict; None for another check's, or no verdict."""
    detail = None if verdict is None else verdict.detail
    return detail if isinstance(detail, CellVerdict) else None


def closest_of(verdict: PathVerdict | None) -> Contact | None:
    """The closest pair a verdict of the cell reports (``min_clearance``); None otherwise."""
    report = cell_report(verdict)
    return None if report is None else report.closest
