"""The path pipeline, written once for every robot family and any dof (robots.md section 1).

requirements -> IK -> tracking -> speeds -> limits -> branch choice -> bottleneck, for a chunk
of placements at once. :func:`solver.path.evaluate.evaluate_path` (one placement, with
per-waypoint detail) and :func:`solver.path.placements.evaluate_placements` (the map and the
optimisers) both run :func:`run_chunk`; only the robot's kinematics family
(:mod:`solver.core.family`) knows how IK and J^-1 t are solved, and only the problem's limits
(:mod:`solver.path.limits`, the DTF first) how fast each waypoint may run.

What makes it fast (dtf.md section 9): t_hat is computed once in {O} and only turned by each
placement's yaw; all placements of a chunk, all waypoints and all IK branches are one set of
component-first arrays with waypoints last.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.codes import ACC_TIE_RTOL, FEASIBLE, UNREACHABLE
from solver.core.dtf import spin_rate_nearest_zero
from solver.core.exceptions import InvalidInputError
from solver.core.family import FollowsInSteps
from solver.core.progress import Progress, span
from solver.core.spatial import MAX_COORDINATE, rotation_about_z
from solver.path.bounded import bounded_solutions, pick_stands
from solver.path.in_pieces import bound_in_pieces, spin_rates_in_pieces, track_in_pieces
from solver.path.limits import JointMotion, bound_by_limits
from solver.path.prepare import PreparedPath
from solver.path.problem import PathProblem
from solver.path.pruning import can_prune, pruned_solutions
from solver.path.tracking import Tracked, choose_branch, track


def check_placements(placements: np.ndarray) -> np.ndarray:
    """Placements as a float array (P, 5) of finite [x, y, z, yaw, spin] within MAX_COORDINATE.

    The one batched layout of placements (:meth:`solver.core.spatial.Placement.as_row`); (P, 4)
    arrays without the spin are taken with spin 0.

    Raises:
        InvalidInputError: wrong shape, not finite, or too far.
    """
    arr = np.asarray(placements, dtype=float)
    if arr.ndim == 2 and arr.shape[1] == 4:
        arr = np.column_stack([arr, np.zeros(len(arr))])
    if arr.ndim != 2 or arr.shape[1] != 5:
        raise InvalidInputError("placements", f"{arr.shape=}, needs (P, 5): x, y, z, yaw, spin")
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr[:, :3]) > MAX_COORDINATE):
        raise InvalidInputError(
            "placements", f"need finite values, positions within {MAX_COORDINATE} m"
        )
    return arr


@dataclass(frozen=True)
class ChunkResult:
    """Every branch at every placement of a chunk, and the branch each placement takes.

    B branches, C placements, W waypoints, n joints.

    Attributes:
        tracked: the branches followed along the path (reason, failed waypoint: (B, C);
            q: (n, B, C, W), rad).
        qd_unit: shape (n, B, C, W), J^-1 t_hat (rad/s per m/s; per rad/s where h = 0).
        qd_spin: shape (n, B, C, W), J^-1 [0; z_tool] (rad/s per rad/s of tool spin); only in
            ``free`` spin mode, else None.
        qd_null: shape (n, B, C, W), a unit null-space vector of J of a seven-joint arm in
            ``free`` spin mode (the spin LP's third variable), else None.
        speed: shape (B, C, W), the DTF: V_max (Omega_max where h = 0), 1 / max_j |qd_unit_j| /
            qdot_max_j in ``fixed`` mode, the two-variable LP with the spin rate free in ``free``
            mode (cam.md section 2); meaningful only on feasible branches.
        limiting: shape (B, C, W), the joint on its limit.
        v_max: shape (B, C, W), m/s, 0 where h = 0.
        mu_path: shape (B, C), m/s, -inf on infeasible branches.
        spins: shape (B, C, W), rad, the spin schedule that realises mu_path in ``free`` mode
            (cam.md section 2: at the feed mu_path, the spin rate nearest zero at each waypoint,
            integrated along the path); None in ``fixed`` mode. ``tracked`` then holds the joint
            paths along that schedule, so its position limits and steps are checked.
        pick: shape (C,), the index on axis B of the branch each placement takes (``auto``: the
            highest mu_path; the furthest failure where none is feasible).
        ik_seeds: the seeds a numeric family started from (None for an analytic one).
        branches_found: shape (C,), the distinct IK solutions a numeric family found at the
            first waypoint (None for an analytic one).
        v_final: shape (B, C, W), m/s, the least bound of the problem's final-path limits
            (:attr:`PathProblem.final_path_limits`: V_acc,i of motion.md section 2) along the
            final tracked joint paths, inf where none bounds; None without such limits.
        final_limiting: shape (B, C, W), the joint that binds it (None likewise).
        final_binding: shape (B, C, W), which of the final-path limits binds (None likewise).
        mu_acc: shape (B, C), m/s, min(mu_path, min_i v_final), -inf on infeasible branches;
            None without final-path limits. With it, ``pick`` takes the highest mu_acc.
        branch_of: shape (B, C), the index on :attr:`PathProblem.branches` of each row at each
            placement, where the rows are a pruned map's (``PathSolutions.slots``); None:
            row b is branch b.
    """

    tracked: Tracked
    qd_unit: np.ndarray
    qd_spin: np.ndarray | None
    speed: np.ndarray
    limiting: np.ndarray
    v_max: np.ndarray
    mu_path: np.ndarray
    pick: np.ndarray
    spins: np.ndarray | None = None
    ik_seeds: int | None = None
    branches_found: np.ndarray | None = None
    qd_null: np.ndarray | None = None
    v_final: np.ndarray | None = None
    final_limiting: np.ndarray | None = None
    final_binding: np.ndarray | None = None
    mu_acc: np.ndarray | None = None
    branch_of: np.ndarray | None = None


def turn_by_yaw(vectors: np.ndarray, yaws: np.ndarray) -> np.ndarray:
    """Rz(yaw) v for every yaw: vectors (3, ..., W) in {O} -> (3, ..., C, W), C-contiguous.

    Args:
        vectors: shape (3, ..., W), in {O}.
        yaws: shape (C,), rad (C = 1 broadcasts one turn over a chunk).
    """
    cos, sin = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    x, y = vectors[0][..., None, :], vectors[1][..., None, :]
    z = np.broadcast_to(vectors[2][..., None, :], np.broadcast_shapes(x.shape, cos.shape))
    return np.stack([cos * x - sin * y, sin * x + cos * y, z])


def flange_at_spin(path: PreparedPath, spin: float) -> tuple[np.ndarray, np.ndarray]:
    """R_O_F (N, 3, 3) and p_O_F (N, 3) with every tool pose turned by ``spin`` about its z."""
    if spin == 0.0:
        return path.flange_rotation, path.flange_position
    turned = path.tool_rotation @ rotation_about_z(spin)
    rotation = turned @ path.tool_to_flange[:3, :3]
    position = path.tool_position + turned @ path.tool_to_flange[:3, 3]
    return rotation, position


def placed_flange(
    problem: PathProblem, placements: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The yaws and the flange poses in {B} of a chunk's placements (one spin).

    Returns:
        yaws: shape (C,), rad, or (1,) where they are all one (broadcast: less to read);
        R_B_F: shape (3, 3, C, W); p_B_F: shape (3, C, W), m.
    """
    yaws = placements[:, 3]
    if np.all(yaws == yaws[0]):
        yaws = yaws[:1]
    if np.any(placements[:, 4] != placements[0, 4]):
        raise InvalidInputError("placements", "a chunk must have one spin")
    offset = placements[:, :3].T[:, :, None]  # (3, C, 1)
    flange_rotation, flange_position_o = flange_at_spin(problem.prepared, float(placements[0, 4]))
    rotation = turn_by_yaw(flange_rotation.transpose(1, 2, 0), yaws)  # (3, 3, C, W)
    flange_position = turn_by_yaw(flange_position_o.T, yaws) + offset
    return yaws, rotation, flange_position


def tracked_joint_paths(
    problem: PathProblem, placements: np.ndarray, rows: np.ndarray
) -> np.ndarray | None:
    """The joint paths a run on one branch gives, each placement on its own branch.

    What :func:`run_chunk` tracks at placement c with the problem's branch set to the family's
    branch ``rows[c]``, without the joint speeds (a path check needs the angles alone); one IK
    solve for every placement.

    Args:
        problem: the problem (fixed spin: free spin tracks its spin schedule's path).
        placements: shape (C, 5), one spin, checked.
        rows: shape (C,), an index into the family's branches per placement.

    Returns:
        shape (C, W, n), rad; None where the family answers in slots (numeric IK) or the
        spin is free: there :func:`run_chunk` on each branch is the way.
    """
    if problem.options.spin_mode == "free":
        return None
    _, rotation, flange_position = placed_flange(problem, placements)
    solutions = problem.family.solve_path(rotation, flange_position)
    if solutions.slots is not None:
        return None
    cells = np.arange(len(placements))
    robot = problem.robot
    tracked = track(
        solutions.q[:, rows, cells][:, None],  # (n, 1, C, W): one branch, as run_chunk's
        solutions.status[rows, cells][None],
        lower=robot.q_lower,
        upper=robot.q_upper,
        max_joint_step=problem.options.max_joint_step,
        segment_checked=problem.prepared.segment_in_pass,
    )
    joint_paths: np.ndarray = tracked.q[:, 0].transpose(1, 2, 0)
    return joint_paths


def run_chunk(
    problem: PathProblem,
    placements: np.ndarray,
    *,
    progress: Progress | None = None,
    prune: bool = False,
) -> ChunkResult:
    """The pipeline at C placements on the problem's branches.

    Args:
        problem: the robot (with a kinematics family), the path and the options, checked
            (:attr:`PathProblem.branches` made).
        placements: shape (C, 5), [x (m), y (m), z (m), yaw (rad), spin (rad)], checked; one
            spin for the whole chunk.
        progress: handed to the family's IK and joint speeds (a numeric family reports as
            it goes; it may raise :class:`solver.core.progress.Cancelled`).
        prune: a map's run: where :func:`solver.path.pruning.can_prune` admits it, branches
            that cannot be the chosen one are not followed to the end, and come back
            unreachable; the chosen branch's answer is the same (``progress`` then unused by
            the IK). False: every branch followed (an evaluation reports them).
    """
    robot, path, branches = problem.robot, problem.prepared, problem.branches
    family = problem.family
    yaws, rotation, flange_position = placed_flange(problem, placements)
    offset = placements[:, :3].T[:, :, None]  # (3, C, 1)
    tool_position = turn_by_yaw(path.tool_position.T, yaws) + offset
    twist = np.concatenate(
        [turn_by_yaw(path.twist[:, :3].T, yaws), turn_by_yaw(path.twist[:, 3:].T, yaws)]
    )
    free = problem.options.spin_mode == "free"
    shares = REDUNDANT_FREE_SHARES if free and robot.dof > 6 else SHARES
    if prune and can_prune(problem):
        bounded = isinstance(family, FollowsInSteps) and family.follows_bounded
        prune_with = bounded_solutions if bounded else pruned_solutions
        solutions = prune_with(problem, rotation, flange_position, twist, tool_position)
    else:
        solutions = family.solve_path(
            rotation, flange_position, progress=_part(progress, shares, 0)
        )
    q, status = solutions.q, solutions.status  # (n, B_all, C, W), (B_all, C, W)
    branches = without_empty_slots(branches, status)
    # In free mode the position limits hold along the spin schedule, checked there, not here.
    tracked = track_in_pieces(
        q[:, branches],
        status[branches],
        _part(progress, shares, 1),
        lower=np.full(robot.dof, -np.inf) if free else robot.q_lower,
        upper=np.full(robot.dof, np.inf) if free else robot.q_upper,
        max_joint_step=problem.options.max_joint_step,
        segment_checked=path.segment_in_pass,
    )
    # For dof > 6 these are the exact DTF LP's joint speeds per unit speed (robots.md section 5),
    # so the ratio below gives the LP's V_max for every dof.
    qd_unit = family.joint_speeds_per_unit_twist(
        tracked.q,
        twist[:, None],
        tool_position[:, None],
        qdot_max=robot.qdot_max,
        progress=_part(progress, shares, 2),
    )
    qd_spin = qd_null = None
    if free:
        tool_z = turn_by_yaw(path.tool_rotation[:, :, 2].T, yaws)
        spin = np.concatenate([np.zeros_like(tool_z), np.broadcast_to(tool_z, twist[3:].shape)])
        qd_spin = family.joint_speeds_per_unit_twist(
            tracked.q, spin[:, None], tool_position[:, None], progress=_part(progress, shares, 3)
        )  # the least-norm solution for more than six joints
        if robot.dof > 6:
            qd_null = family.null_space(
                tracked.q, tool_position[:, None], progress=_part(progress, shares, 4)
            )
    motion = JointMotion(q=tracked.q, qd_unit=qd_unit, qd_spin=qd_spin, qd_null=qd_null)
    speed, limiting = bound_in_pieces(problem.waypoint_limits, motion, _part(progress, shares, 5))
    v_max = np.where(path.pure_rotation, 0.0, speed)
    feasible = tracked.reason == FEASIBLE  # (B, C)
    mu_path = np.where(feasible, v_max.min(axis=-1), -np.inf)
    if solutions.bound is not None and not pick_stands(solutions, branches, mu_path):
        return run_chunk(problem, placements, progress=progress)  # every branch followed
    spins = None
    if qd_spin is not None:
        spins, tracked = _spin_schedule(
            problem, tracked, motion, qd_spin, mu_path, _part(progress, shares, 6)
        )
        feasible = tracked.reason == FEASIBLE
        mu_path = np.where(feasible, mu_path, -np.inf)
    if progress is not None:
        progress(1.0)
    final = _final_path_bounds(problem, tracked, qd_unit, qd_spin, mu_path, feasible)
    mu_acc = final[3]
    if mu_acc is None:
        pick = choose_branch(mu_path, feasible, tracked.failed_waypoint)
    else:
        pick = choose_branch(mu_acc, feasible, tracked.failed_waypoint, ACC_TIE_RTOL)
    return ChunkResult(
        tracked=tracked,
        qd_unit=qd_unit,
        qd_spin=qd_spin,
        qd_null=qd_null,
        speed=speed,
        limiting=limiting,
        v_max=v_max,
        mu_path=mu_path,
        pick=pick,
        spins=spins,
        ik_seeds=solutions.seeds,
        branches_found=solutions.branches_found,
        v_final=final[0],
        final_limiting=final[1],
        final_binding=final[2],
        mu_acc=mu_acc,
        branch_of=None if solutions.slots is None else solutions.slots[branches],
    )


SHARES = (0.8, 0.85, 0.95, 1.0, 1.0, 1.0, 1.0)
"""Where each part of a chunk's work ends in its progress: the IK, the tracking, the joint
speeds per unit feed, those per unit spin (free spin), the null space, the limits, the spin
schedule."""
REDUNDANT_FREE_SHARES = (0.55, 0.6, 0.7, 0.75, 0.8, 0.9, 1.0)
"""The same for an arm of more than six joints in free spin, where the spin LP is work too."""


def _part(progress: Progress | None, shares: tuple[float, ...], k: int) -> Progress | None:
    """The progress callback of part ``k`` of a chunk's work (:data:`SHARES`)."""
    return span(progress, shares[k - 1] if k else 0.0, shares[k])


def without_empty_slots(branches: np.ndarray, status: np.ndarray) -> np.ndarray:
    """The branches to follow, less the trailing ones no placement of the chunk has solved.

    A numeric family answers K slots and fills the first few (the distinct solutions it found);
    the slots after the last one solved anywhere in the chunk would be tracked, bounded and
    compared for nothing. Dropped, they change no answer: they are unreachable at the first
    waypoint, so ``auto`` never takes them (a failure at waypoint 0 loses every tie to an
    earlier branch). Only ``auto``'s branches 0..B-1 are trimmed, so the kept ones are a prefix
    and the result's branch axis still indexes :attr:`PathProblem.branches`; one is always kept.

    Args:
        branches: the problem's branch indices (:attr:`PathProblem.branches`).
        status: shape (B_all, C, W), the family's IK status of every slot.
    """
    if not np.array_equal(branches, np.arange(len(branches))):
        return branches
    given = status[: len(branches)]  # a pruned map's IK answers only the slots it solved
    solved = np.flatnonzero((given != UNREACHABLE).reshape(len(given), -1).any(axis=1))
    return branches[: solved[-1] + 1 if solved.size else 1]


_NoBounds = tuple[None, None, None, None]


def _final_path_bounds(
    problem: PathProblem,
    tracked: Tracked,
    qd_unit: np.ndarray,
    qd_spin: np.ndarray | None,
    mu_path: np.ndarray,
    feasible: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | _NoBounds:
    """The final-path limits along the final joint paths: bound, joint, limit, and mu_acc.

    mu_acc = min(mu_path, min_i bound_i) (motion.md section 2), -inf where infeasible; all
    None when the problem has no final-path limits.
    """
    limits = problem.final_path_limits
    if not limits:
        return None, None, None, None
    motion = JointMotion(q=tracked.q, qd_unit=qd_unit, qd_spin=qd_spin)
    bound, joint, binding = bound_by_limits(limits, motion)  # (B, C, W)
    lowest = bound.min(axis=-1) if bound.shape[-1] else np.full(mu_path.shape, np.inf)
    mu_acc = np.where(feasible, np.minimum(mu_path, lowest), -np.inf)
    return bound, joint, binding, mu_acc


def _spin_schedule(
    problem: PathProblem,
    tracked: Tracked,
    motion: JointMotion,
    qd_spin: np.ndarray,
    mu_path: np.ndarray,
    progress: Progress | None = None,
) -> tuple[np.ndarray, Tracked]:
    """The spins that realise mu_path in free mode, and the joint paths along them.

    At the feed F = mu_path each waypoint admits an interval of spin rates; the one nearest zero
    is held over the segment (its duration |dp_i| / F), which gives the spins phi_i. The joints
    follow q_i + sum_k<i sigma_k dt_k J^-1 [0; z_tool]_k: exact for a straight spindle (only the
    last joint moves), first order otherwise (cam.md section 2). Those joint paths are tracked
    again, so the last joint's limits and steps are checked along the schedule.

    Args:
        problem: the robot, the prepared path and the options.
        tracked: the branches followed at the given spin; q (n, B, C, W).
        motion: their joint speeds per unit feed (qd_unit) and, for seven joints, the null
            space of J (qd_null), each (n, B, C, W). A seven-joint arm's spin rate is that of
            the three-variable LP (:func:`solver.core.dtf_redundant.spin_rate_at_feed`), and
            its joints follow the spin by the least-norm qd_spin.
        qd_spin: shape (n, B, C, W), J^-1 [0; z_tool] (the least-norm one for seven joints).
        mu_path: shape (B, C), m/s, -inf where infeasible.
        progress: called after each piece of waypoints whose spin rates are found (seven
            joints: the LP, :func:`solver.path.in_pieces.spin_rates_in_pieces`), then after each
            piece of branches tracked along the spins.

    Returns:
        spins (B, C, W), rad (0 where infeasible or mu_path = 0), and the tracking of the spun
        joint paths (where the branch was feasible).
    """
    robot, path = problem.robot, problem.prepared
    feed = np.where(np.isfinite(mu_path) & (mu_path > 0.0), mu_path, 0.0)[..., None]
    qd_unit = motion.qd_unit
    if motion.qd_null is None:
        rate = spin_rate_nearest_zero(qd_unit, qd_spin, robot.qdot_max, feed)
    else:
        rate = spin_rates_in_pieces(
            qd_unit, qd_spin, motion.qd_null, robot.qdot_max, feed, span(progress, 0.0, 0.5)
        )
    length = np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1)  # (W - 1,)
    with np.errstate(divide="ignore", invalid="ignore"):
        step = np.where(feed > 0.0, rate[..., :-1] * length / feed, 0.0)  # (B, C, W - 1)
    step = np.where(path.segment_in_pass, step, 0.0)  # each pass starts at the placement's spin
    spins = cumsum_within_passes(step, path.segment_in_pass)

    def spun_joints(rows: slice) -> np.ndarray:
        """The joint paths of some branches moved by the spins, (n, b, C, W)."""
        moved = cumsum_within_passes(step[rows] * qd_spin[:, rows, ..., :-1], path.segment_in_pass)
        joints: np.ndarray = tracked.q[:, rows] + np.nan_to_num(moved)
        return joints

    spun = track_in_pieces(
        tracked.q,
        np.zeros(tracked.q.shape[1:], dtype=int),  # every pose was solved: only limits, steps
        span(progress, 0.5, 1.0),
        joints_of=spun_joints,
        lower=robot.q_lower,
        upper=robot.q_upper,
        max_joint_step=problem.options.max_joint_step,
        segment_checked=path.segment_in_pass,
    )
    keep = np.isfinite(mu_path)
    return spins, Tracked(
        reason=np.where(keep, spun.reason, tracked.reason),
        failed_waypoint=np.where(keep, spun.failed_waypoint, tracked.failed_waypoint),
        q=np.where(keep[None, ..., None], spun.q, tracked.q),
    )


def cumsum_within_passes(steps: np.ndarray, segment_in_pass: np.ndarray) -> np.ndarray:
    """Running sums of per-segment steps along the last axis, restarting at 0 at each pass.

    Args:
        steps: shape (..., W - 1), one value per segment.
        segment_in_pass: shape (W - 1,), False where a segment joins two passes.

    Returns:
        shape (..., W): 0 at the first waypoint of every pass.
    """
    total = np.concatenate([np.zeros(steps.shape[:-1] + (1,)), np.cumsum(steps, axis=-1)], axis=-1)
    starts = np.concatenate([[True], ~segment_in_pass])  # (W,), the first waypoint of each pass
    first = np.maximum.accumulate(np.where(starts, np.arange(len(starts)), 0))
    result: np.ndarray = total - total[..., first]
    return result
