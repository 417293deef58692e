"""Following IK branches along a path, batched over branches and placements (spec section 4).

A branch is feasible along a path when every waypoint has a regular solution on it, no joint
moves more than ``max_joint_step`` between neighbouring waypoints nor does the sign of det J
change between them (``OK`` to ``OK_MIRRORED``: a singularity crossed between the samples,
which only a numeric family's statuses show), and each joint's whole path,
unwrapped, fits inside its position limits with some 2 pi copy. The first failure names the
waypoint; at one waypoint ``unreachable`` comes before ``singular`` before ``discontinuous``,
and ``joint_limits`` is the first waypoint whose joint range no copy can hold.

Layout: joint axis first, waypoints last: q (n, *batch, W), for any number of joints n.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.core.codes import (
    EDGE,
    FEASIBLE,
    OK,
    OK_MIRRORED,
    REASON_DISCONTINUOUS,
    REASON_JOINT_LIMITS,
    REASON_SINGULAR,
    REASON_UNREACHABLE,
    SINGULAR,
    TIE_RTOL,
    UNREACHABLE,
)

_TWO_PI = 2 * math.pi


@dataclass(frozen=True)
class Tracked:
    """Branches followed along a path.

    Attributes:
        reason: shape batch, index into ``REASONS``, or ``FEASIBLE``.
        failed_waypoint: shape batch, the first failing waypoint, or -1.
        q: shape (n, *batch, W), rad, the continuous joint paths with the 2 pi copy that fits the
            limits (the first waypoint nearest zero among those that fit); meaningful only where
            feasible.
    """

    reason: np.ndarray
    failed_waypoint: np.ndarray
    q: np.ndarray


def _first_true(mask: np.ndarray) -> np.ndarray:
    """Index of the first True along the last axis, or the axis length where there is none."""
    first: np.ndarray = np.where(mask.any(axis=-1), mask.argmax(axis=-1), mask.shape[-1])
    return first


def crossed(status: np.ndarray) -> np.ndarray:
    """Where det J changes sign between neighbouring waypoints: status (..., W) -> (..., W - 1).

    True where one end is ``OK`` and the other ``OK_MIRRORED`` (both regular, det J of opposite
    signs): the branch passed a singular configuration between the samples.
    """
    before, after = status[..., :-1], status[..., 1:]
    result: np.ndarray = ((before == OK) & (after == OK_MIRRORED)) | (
        (before == OK_MIRRORED) & (after == OK)
    )
    return result


def track(
    q: np.ndarray,
    status: np.ndarray,
    *,
    lower: np.ndarray,
    upper: np.ndarray,
    max_joint_step: float,
    segment_checked: np.ndarray | None = None,
) -> Tracked:
    """Follow IK branches along a path.

    Args:
        q: shape (n, *batch, W), rad in [-pi, pi], each branch's solution at every waypoint.
        status: shape (*batch, W), the IK status of those solutions (``OK_MIRRORED`` next to
            ``OK`` is a discontinuity, see :func:`crossed`).
        lower: shape (n,), rad, lower position limits.
        upper: shape (n,), rad, upper position limits.
        max_joint_step: rad, the largest move of any joint between neighbouring waypoints.
        segment_checked: shape (W - 1,), where the step bound applies (None: everywhere); a
            rapid between two passes is not bounded (the branch and the joint copy carry on).

    Returns:
        The first failure of each branch, and the joint paths.
    """
    n_waypoints = q.shape[-1]
    step = np.diff(q, axis=-1)  # in [-2 pi, 2 pi]: one turn at most brings it to [-pi, pi]
    step -= np.where(step > math.pi, _TWO_PI, np.where(step < -math.pi, -_TWO_PI, 0.0))
    with np.errstate(invalid="ignore"):
        jump = np.any(np.abs(step) > max_joint_step, axis=0)
    jump |= crossed(status)
    if segment_checked is not None:
        jump &= segment_checked
    first = np.stack(
        [
            _first_true(status == UNREACHABLE),
            np.full(status.shape[:-1], n_waypoints),  # joint limits: filled below
            _first_true(status == SINGULAR),
            _first_true(jump) + 1,
        ]
    )
    first[REASON_DISCONTINUOUS] = np.where(
        jump.any(axis=-1), first[REASON_DISCONTINUOUS], n_waypoints
    )
    path = np.concatenate([q[..., :1], q[..., :1] + np.cumsum(step, axis=-1)], axis=-1)
    lower_b = lower.reshape((-1,) + (1,) * (q.ndim - 2))
    upper_b = upper.reshape((-1,) + (1,) * (q.ndim - 2))
    # The copies 2 pi k that fit the whole path: k_low <= k <= k_high, per joint.
    k_low = np.ceil((lower_b - path.min(axis=-1)) / _TWO_PI - EDGE)
    k_high = np.floor((upper_b - path.max(axis=-1)) / _TWO_PI + EDGE)
    other = first[[REASON_UNREACHABLE, REASON_SINGULAR, REASON_DISCONTINUOUS]].min(axis=0)
    # Joint limits count only on a path that got through every waypoint otherwise; where no
    # copy fits the whole path, the running range finds the first waypoint that breaks it.
    no_fit = np.flatnonzero(np.any(k_low > k_high, axis=0) & (other == n_waypoints))
    if no_fit.size:
        flat = path.reshape(len(q), -1, n_waypoints)[:, no_fit]
        running_low = np.ceil(
            (lower[:, None, None] - np.minimum.accumulate(flat, axis=-1)) / _TWO_PI - EDGE
        )
        running_high = np.floor(
            (upper[:, None, None] - np.maximum.accumulate(flat, axis=-1)) / _TWO_PI + EDGE
        )
        first[REASON_JOINT_LIMITS].reshape(-1)[no_fit] = _first_true(
            np.any(running_low > running_high, axis=0)
        )
    failed = first.min(axis=0)
    # argmin takes the lowest code at a tie: unreachable, then singular, then discontinuous.
    reason = np.where(failed < n_waypoints, first.argmin(axis=0), FEASIBLE)
    shift = np.clip(np.round(-path[..., 0] / _TWO_PI), k_low, k_high)
    shifted = path + _TWO_PI * np.nan_to_num(shift)[..., None]
    return Tracked(
        reason=reason,
        failed_waypoint=np.where(reason == FEASIBLE, -1, failed),
        q=shifted,
    )


# TIE_RTOL (solver.core.codes): branches whose mu_path agree to it (relative) are tied: the four
# branches of one shoulder share |qd1|, |qd5| and |qd6| exactly, so when one of those joints
# limits the path they differ only by rounding.


def choose_branch(
    mu_path: np.ndarray,
    feasible: np.ndarray,
    failed_waypoint: np.ndarray,
    tie_rtol: float = TIE_RTOL,
) -> np.ndarray:
    """The ``auto`` branch: the highest mu_path, or the furthest failure when none is feasible.

    Ties (within ``tie_rtol``) go to the first branch in the family's order, so the choice
    does not depend on rounding.

    Args:
        mu_path: shape (B, *batch), m/s (any value where infeasible); or mu_acc.
        feasible: shape (B, *batch), bool.
        failed_waypoint: shape (B, *batch), the first failing waypoint where infeasible.
        tie_rtol: ``TIE_RTOL`` for mu_path, ``ACC_TIE_RTOL`` for mu_acc.

    Returns:
        shape batch, the index of the chosen branch on axis 0.
    """
    values = np.where(feasible, mu_path, -np.inf)
    top = values.max(axis=0)
    tied = feasible & (values >= top - tie_rtol * np.abs(top))
    furthest = np.where(feasible, -1, failed_waypoint).max(axis=0)
    fallback = ~feasible & (failed_waypoint == furthest)
    chosen: np.ndarray = np.where(
        feasible.any(axis=0), tied.argmax(axis=0), fallback.argmax(axis=0)
    )
    return chosen
