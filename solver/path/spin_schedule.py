"""Free spin's schedule: the spins that realise mu_path, and the joint paths along them.

cam.md section 2: at the feed mu_path each waypoint admits an interval of spin rates; the one
nearest zero is held over each segment, integrated along the path, and the joint paths moved by
it are tracked again. :func:`solver.path.pipeline.run_chunk` calls it in ``free`` spin mode;
:mod:`solver.kernels.spin_schedule` is its compiled twin.
"""

from __future__ import annotations

import numpy as np

from solver.core.progress import Progress, span
from solver.core.two_variable_lp import spin_rate_nearest_zero
from solver.path.in_pieces import spin_rates_in_pieces, track_in_pieces
from solver.path.limits import JointMotion
from solver.path.problem import PathProblem
from solver.path.tracking import Tracked


def spin_schedule(
    problem: PathProblem,
    tracked: Tracked,
    motion: JointMotion,
    qd_spin: np.ndarray,
    mu_path: np.ndarray,
    progress: Progress | None = None,
) -> tuple[np.ndarray, Tracked]:
    """The spins that realise mu_path in free mode, and the joint paths along them.

    Six joints turning a straight spindle only (:attr:`PathProblem.exact_spin` false): at the
    feed F = mu_path each waypoint admits an interval of spin rates; the one nearest zero is held
    over the segment (its duration |dp_i| / F), which gives the spins phi_i (:func:`schedule`).
    The joints follow q_i + sum_k<i sigma_k dt_k J^-1 [0; z_tool]_k, exact here since only the
    last joint moves (cam.md section 2; where the spin moves more, the spun poses are solved
    instead, :mod:`solver.path.exact_spin`). Those joint paths are tracked again, so the last
    joint's limits and steps are checked along the schedule.

    Args:
        problem: the robot, the prepared path and the options.
        tracked: the branches followed at the given spin; q (n, B, C, W).
        motion: their joint speeds per unit feed (qd_unit), each (n, B, C, W).
        qd_spin: shape (n, B, C, W), J^-1 [0; z_tool].
        mu_path: shape (B, C), m/s, -inf where infeasible.
        progress: called after each piece of waypoints whose spin rates are found, then after
            each piece of branches tracked along the spins.

    Returns:
        spins (B, C, W), rad (0 where infeasible or mu_path = 0), and the tracking of the spun
        joint paths (where the branch was feasible).
    """
    robot, path = problem.robot, problem.prepared
    spins, step = schedule(problem, motion, qd_spin, mu_path, span(progress, 0.0, 0.5))

    def spun_joints(rows: slice) -> np.ndarray:
        """The joint paths of some branches moved by the spins, (n, b, C, W).

        A singular branch's J^-1 [0; z_tool] is inf where its spin step is 0 (it has no
        spins): the NaN of 0 inf is its move, 0, without a numpy warning (audit 23).
        """
        with np.errstate(invalid="ignore"):
            moves = step[rows] * qd_spin[:, rows, ..., :-1]
        moved = cumsum_within_passes(moves, path.segment_in_pass)
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


def schedule(
    problem: PathProblem,
    motion: JointMotion,
    qd_spin: np.ndarray,
    mu_path: np.ndarray,
    progress: Progress | None = None,
    *,
    inside: float = 1.0 - 1e-12,
) -> tuple[np.ndarray, np.ndarray]:
    """The spins (B, C, W) of :func:`spin_schedule`, and each segment's spin (B, C, W - 1), rad.

    At the feed F = mu_path (none where infeasible or 0), the spin rate nearest zero at each
    segment's first waypoint held over the segment (|dp_i| / F), summed within each pass.
    A seven-joint arm's rate is that of the three-variable LP
    (:func:`solver.core.dtf_redundant.spin_rate_at_feed`, ``motion.qd_null`` its null space),
    reported to ``progress`` piece by piece. ``inside``: the share of the feed the rates are
    taken at (:func:`solver.core.two_variable_lp.spin_rate_nearest_zero`).
    """
    robot, path = problem.robot, problem.prepared
    feed = np.where(np.isfinite(mu_path) & (mu_path > 0.0), mu_path, 0.0)[..., None]
    qd_unit = motion.qd_unit
    if motion.qd_null is None:
        rate = spin_rate_nearest_zero(qd_unit, qd_spin, robot.qdot_max, feed, inside=inside)
    else:
        rate = spin_rates_in_pieces(
            qd_unit, qd_spin, motion.qd_null, robot.qdot_max, feed, progress, inside=inside
        )
    length = np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1)  # (W - 1,)
    with np.errstate(divide="ignore", invalid="ignore"):
        step = np.where(feed > 0.0, rate[..., :-1] * length / feed, 0.0)  # (B, C, W - 1)
    step = np.where(path.segment_in_pass, step, 0.0)  # each pass starts at the placement's spin
    return cumsum_within_passes(step, path.segment_in_pass), step


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
