"""Work along a path done in pieces, with a progress report after each piece.

Tracking follows each branch alone, so pieces of branches give the bits of the whole. The
limits on each waypoint (:class:`solver.path.limits.Limit`, the waypoint kind) and a
seven-joint arm's spin rates at a feed look at one waypoint's motion at a time, so pieces of
waypoints give the bits of the whole. In free spin their LPs are seconds of work along a long
path (:mod:`solver.kernels.spin_lp`): the pieces let a caller see the work go on and stop it
(:class:`solver.core.progress.Cancelled`) within a second, as the IK's pieces do.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from solver.core.progress import Progress
from solver.kernels.spin_lp import spin_rate_at_feed
from solver.path.limits import JointMotion, Limit, bound_by_limits
from solver.path.tracking import Tracked, track

LIMIT_ROWS = 16_384
"""Configurations (branches x placements x waypoints) in one piece: the seven-joint spin LP
takes about 0.1 s for them under load."""


def waypoint_pieces(shape: tuple[int, ...], progress: Progress | None) -> list[slice]:
    """The last axis of ``shape`` in pieces of about LIMIT_ROWS entries; whole without progress."""
    n_waypoints = shape[-1]
    if progress is None:
        return [slice(0, n_waypoints)]
    size = max(LIMIT_ROWS // max(int(np.prod(shape[:-1])), 1), 1)
    return [slice(w, min(w + size, n_waypoints)) for w in range(0, n_waypoints, size)]


def bound_in_pieces(
    limits: tuple[Limit, ...], motion: JointMotion, progress: Progress | None
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solver.path.limits.bound_by_limits` of waypoint limits, in pieces of waypoints.

    Args:
        limits: waypoint limits (each waypoint's bound from its own motion).
        motion: the joint paths, arrays (n, ..., W).
        progress: called after each piece with the fraction of waypoints done.

    Returns:
        speed and joint, shape (..., W), as :func:`bound_by_limits`.
    """
    shape = motion.q.shape[1:]
    speed, joint = np.empty(shape), np.empty(shape, dtype=np.int64)
    for piece in waypoint_pieces(shape, progress):
        part = JointMotion(
            q=motion.q[..., piece],
            qd_unit=motion.qd_unit[..., piece],
            qd_spin=None if motion.qd_spin is None else motion.qd_spin[..., piece],
            qd_null=None if motion.qd_null is None else motion.qd_null[..., piece],
        )
        speed[..., piece], joint[..., piece], _ = bound_by_limits(limits, part)
        if progress is not None:
            progress(piece.stop / shape[-1])
    return speed, joint


def spin_rates_in_pieces(
    qd_unit: np.ndarray,
    qd_spin: np.ndarray,
    qd_null: np.ndarray,
    qdot_max: np.ndarray,
    feed: np.ndarray,
    progress: Progress | None,
    *,
    inside: float = 1.0 - 1e-12,
) -> np.ndarray:
    """A seven-joint arm's spin rate at the feed (:func:`spin_rate_at_feed`), in pieces.

    Args:
        qd_unit: shape (n, ..., W), rad/s per unit feed.
        qd_spin: shape (n, ..., W), rad/s per unit spin rate.
        qd_null: shape (n, ..., W), a unit null-space vector of J.
        qdot_max: shape (n,), rad/s.
        feed: shape broadcasting to (..., 1), m/s, constant along each path.
        progress: called after each piece with the fraction of waypoints done.
        inside: the share of the feed the rate is taken at (:func:`spin_rate_at_feed`).

    Returns:
        shape (..., W), rad/s, the spin rate nearest zero at the feed.
    """
    shape = qd_unit.shape[1:]
    rate = np.empty(shape)
    for piece in waypoint_pieces(shape, progress):
        rate[..., piece], _ = spin_rate_at_feed(
            qd_unit[..., piece],
            qd_spin[..., piece],
            qd_null[..., piece],
            qdot_max,
            feed,
            inside=inside,
        )
        if progress is not None:
            progress(piece.stop / shape[-1])
    return rate


def track_in_pieces(
    q: np.ndarray,
    status: np.ndarray,
    progress: Progress | None,
    *,
    joints_of: Callable[[slice], np.ndarray] | None = None,
    **options: Any,
) -> Tracked:
    """:func:`solver.path.tracking.track` of branches in pieces of the branch axis.

    Each branch (and placement) is tracked alone, so pieces of branches give the bits of the
    whole; a piece holds about LIMIT_ROWS configurations (one branch at least).

    Args:
        q: shape (n, B, ..., W), rad, as :func:`track` takes it.
        status: shape (B, ..., W).
        progress: called after each piece with the fraction of branches done.
        joints_of: the joint paths to track of a slice of branches (n, b, ..., W), made piece
            by piece (the free spin's moved paths); None: ``q[:, rows]``.
        options: :func:`track`'s keywords (the limits, the step, the checked segments).
    """
    joints = joints_of if joints_of is not None else (lambda rows: q[:, rows])
    if progress is None or q.shape[1] <= 1:
        return track(joints(slice(None)), status, **options)
    per_branch = max(int(np.prod(q.shape[2:])), 1)
    size = max(LIMIT_ROWS // per_branch, 1)
    n_branches = q.shape[1]
    reason = np.empty(q.shape[1:-1], dtype=np.int64)
    failed = np.empty(q.shape[1:-1], dtype=np.int64)
    tracked_q = np.empty(q.shape)
    for start in range(0, n_branches, size):
        rows = slice(start, min(start + size, n_branches))
        piece = track(joints(rows), status[rows], **options)
        reason[rows], failed[rows], tracked_q[:, rows] = (
            piece.reason,
            piece.failed_waypoint,
            piece.q,
        )
        progress(rows.stop / n_branches)
    return Tracked(reason=reason, failed_waypoint=failed, q=tracked_q)
