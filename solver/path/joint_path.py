"""mu_path along a given joint path, instead of the tracked one (issue 11, robots.md section 4).

A redundant arm (dof > 6) reaches every pose of a path by many joint paths; the evaluator tracks
the one of least joint motion, while the placement NLP
(:mod:`solver.optimise.methods.placement_nlp`) chooses its own for speed. This module judges a
joint path as it is given: it must reach every waypoint's
pose (forward kinematics within ``tolerance``), stay within the position limits and move no joint
more than ``max_joint_step`` between neighbours of one pass; then V_max at each waypoint is the
exact DTF LP at that configuration (the family's joint speeds per unit twist, dtf.md section 3,
:mod:`solver.core.dtf_redundant`), the same computation the pipeline makes at the tracked joints.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from solver.core.codes import REASONS
from solver.core.exceptions import InvalidInputError
from solver.core.kinematics import tool_pose_in_base
from solver.core.progress import Progress
from solver.core.spatial import Placement, rotation_about_z
from solver.path.bottleneck import bottleneck_waypoints
from solver.path.evaluate import (
    PathEvaluation,
    acceleration_index,
    cell_report,
    closest_of,
)
from solver.path.limits import JointMotion, bound_by_limits, refused_reason
from solver.path.path_checks import check_path, checks_model
from solver.path.placed import turn_by_yaw
from solver.path.problem import PathProblem

# m and rad: how far forward kinematics of a joint path sent to /v1/evaluate may be from the
# waypoints (a path printed with 7 digits still passes).
POSE_TOLERANCE = 1e-6
# The optimiser's check of the NLP's own joint path: IPOPT's constraint tolerance is 1e-10.
EXACT_POSE_TOLERANCE = 1e-9
_EDGE = 1e-12  # rad, slack on the position limits (as tracking allows)


def check_joint_path(
    problem: PathProblem,
    waypoints_in_base: np.ndarray,
    joint_path: np.ndarray,
    *,
    tolerance: float = POSE_TOLERANCE,
    field: str = "joint_path",
) -> np.ndarray:
    """The joint path as a float array, checked against the tool poses it must reach.

    Args:
        problem: the arm, the passes (the step bound applies within a pass) and the options
            (the largest move of a joint between neighbours of one pass).
        waypoints_in_base: shape (N, 4, 4), T_B_TCP at every waypoint (m).
        joint_path: shape (N, n), rad (m for prismatic joints).
        tolerance: m and rad, the largest position and rotation error of FK(q_i).
        field: the input's name, for the errors.

    Raises:
        InvalidInputError: on ``field`` (with the waypoint where one is at fault): a wrong shape,
            a value that is not finite, a joint outside its limits, a step over the bound, or
            FK(q_i) away from waypoint i.
    """
    robot, max_joint_step = problem.robot, problem.options.max_joint_step
    segment_in_pass = problem.prepared.segment_in_pass
    q = np.asarray(joint_path, dtype=float)
    n_waypoints = len(waypoints_in_base)
    if q.shape != (n_waypoints, robot.dof):
        raise InvalidInputError(
            field,
            f"{q.shape=} but the path has {n_waypoints} waypoints and the robot "
            f"{robot.dof} joints: needs ({n_waypoints}, {robot.dof})",
        )
    for i, row in enumerate(q):
        if not np.isfinite(row).all():
            raise InvalidInputError(field, "a joint value is not finite", waypoint=i)
        outside = np.flatnonzero((row < robot.q_lower - _EDGE) | (row > robot.q_upper + _EDGE))
        if outside.size:
            j = int(outside[0])
            raise InvalidInputError(
                field,
                f"joint {j} ({robot.joint_names[j]}) is {row[j]:.9g} rad, outside its limits "
                f"[{robot.q_lower[j]:.6g}, {robot.q_upper[j]:.6g}] rad",
                waypoint=i,
            )
    steps = np.abs(np.diff(q, axis=0)).max(axis=1) if n_waypoints > 1 else np.zeros(0)
    over = np.flatnonzero(segment_in_pass & (steps > max_joint_step))
    if over.size:
        i = int(over[0])
        raise InvalidInputError(
            field,
            f"a joint moves {steps[i]:.6g} rad from waypoint {i}, over max_joint_step "
            f"{max_joint_step:.6g} rad",
            waypoint=i + 1,
        )
    for i, target in enumerate(waypoints_in_base):
        reached = tool_pose_in_base(robot, q[i])
        position_error = float(np.linalg.norm(reached[:3, 3] - target[:3, 3]))
        rotation_error = _angle(target[:3, :3].T @ reached[:3, :3])
        if not (position_error <= tolerance and rotation_error <= tolerance):
            raise InvalidInputError(
                field,
                f"FK is {position_error:.3g} m and {rotation_error:.3g} rad from the waypoint's "
                f"pose (tolerance {tolerance:g})",
                waypoint=i,
            )
    return q


def evaluate_joint_path(
    problem: PathProblem,
    placement: Placement,
    joint_path: np.ndarray,
    *,
    tolerance: float = POSE_TOLERANCE,
    progress: Progress | None = None,
) -> PathEvaluation:
    """mu_path of a path at a placement along the given joint path (fixed spin mode).

    Args:
        problem: an arm with a kinematics family, the path with its passes, the step bound
            (the options' branch and spin mode are not used: no branch is followed).
        placement: where {O} sits in {B}, and the tool spin.
        joint_path: shape (N, n), rad, the configuration at every waypoint.
        tolerance: m and rad, as :func:`check_joint_path`.
        progress: handed to the family's joint speeds (a numeric family reports as it goes;
            it may raise :class:`solver.core.progress.Cancelled`).

    Returns:
        The evaluation along that joint path (``branch`` None: no IK branch was followed;
        ``singular`` where the LP has no finite optimum).

    Raises:
        InvalidInputError: a bad path or step, or a joint path that :func:`check_joint_path`
            refuses; NoAnalyticIkError: the robot has no kinematics family.
    """
    robot, family = problem.robot, problem.family
    problem.options.check_step()
    path = problem.prepared
    spun = np.array(problem.waypoints, dtype=float)
    spun[:, :3, :3] = spun[:, :3, :3] @ rotation_about_z(placement.spin)
    poses = placement.transform_workpiece_to_base() @ spun
    q = check_joint_path(problem, poses, joint_path, tolerance=tolerance)
    yaw = np.array([placement.yaw])
    twist = np.concatenate(
        [turn_by_yaw(path.twist[:, :3].T, yaw), turn_by_yaw(path.twist[:, 3:].T, yaw)]
    )
    qd_unit = family.joint_speeds_per_unit_twist(
        q.T, twist[:, 0], poses[:, :3, 3].T, qdot_max=robot.qdot_max, progress=progress
    )  # (n, N), the same computation as the pipeline's at the tracked joints
    speed, limiting, _ = bound_by_limits(
        problem.waypoint_limits, JointMotion(q=q.T, qd_unit=qd_unit)
    )
    u_T, u_R = _twist_directions(path.u_T, path.u_R, placement.yaw)
    infeasible = PathEvaluation(
        feasible=False,
        mu_path=None,
        bottleneck_waypoint=None,
        bottleneck_joint=None,
        reason=None,
        failed_waypoint=None,
        branch=None,
        u_T=u_T,
        u_R=u_R,
        h=path.h,
    )
    singular = np.flatnonzero(~np.isfinite(speed))
    if singular.size:
        return dataclasses.replace(infeasible, reason="singular", failed_waypoint=int(singular[0]))
    verdict = check_path(problem, q, placement.as_row(), thorough=True)
    if verdict is not None and verdict.failed_waypoint is not None:
        report = cell_report(verdict)
        return dataclasses.replace(
            infeasible,
            reason=REASONS[refused_reason(verdict)],
            failed_waypoint=verdict.failed_waypoint,
            collision=None if report is None else report.collision,
            **checks_model(problem),
        )
    v_max = np.where(path.pure_rotation, 0.0, speed)
    with np.errstate(divide="ignore", invalid="ignore"):
        omega_max = np.where(
            path.pure_rotation, speed, np.where(np.isinf(path.h), 0.0, speed / path.h)
        )
    bottleneck = int(bottleneck_waypoints(v_max))
    mu_path = float(np.min(v_max))  # V_max at the bottleneck, or a last bit below (a tie)
    return dataclasses.replace(
        infeasible,
        feasible=True,
        mu_path=mu_path,
        acceleration=acceleration_index(
            problem, q, mu_path, (bottleneck, int(limiting[bottleneck]))
        ),
        bottleneck_waypoint=bottleneck,
        bottleneck_joint=int(limiting[bottleneck]),
        q=q,
        v_max=v_max,
        omega_max=omega_max,
        qdot=(qd_unit * speed).T,
        limiting_joint=limiting,
        min_clearance=closest_of(verdict),
        **({} if verdict is None else checks_model(problem)),
    )


def _twist_directions(
    u_T: np.ndarray, u_R: np.ndarray, yaw: float
) -> tuple[np.ndarray, np.ndarray]:
    """u_T and u_R (N, 3) in {O} turned into {B} by the placement's yaw."""
    turn = rotation_about_z(yaw)
    return u_T @ turn.T, u_R @ turn.T


def _angle(rotation: np.ndarray) -> float:
    """The rotation angle of a 3 x 3 rotation (rad), accurate near 0 (atan2 of sin and cos)."""
    axis = 0.5 * np.array(
        [
            rotation[2, 1] - rotation[1, 2],
            rotation[0, 2] - rotation[2, 0],
            rotation[1, 0] - rotation[0, 1],
        ]
    )
    return math.atan2(float(np.linalg.norm(axis)), (float(np.trace(rotation)) - 1.0) / 2.0)
