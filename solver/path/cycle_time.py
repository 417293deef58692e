"""The cycle time of a path under joint speed and acceleration limits (motion.md section 4).

Each pass starts and ends at rest. Three figures a pass, and their totals:

- ``constant_feed_time``: L / mu_acc, L the pass's tool-point length;
- the ramps: the arc length and time the feed needs to reach mu_acc from rest at the pass's
  start and to stop at its end, and the pass's time at mu_acc with those ramps: the fastest
  profile that never passes mu_acc (TOPP-RA with the feed capped,
  :func:`solver.kernels.feed_profile.capped_profile`), on the time-optimal profile's own
  discretisation, so that the time-optimal time is never above it (motion.md: a lower bound
  of every feed profile). Ramps integrated point by point, each step's acceleration bounded
  at its start only, beat the time-optimal time by up to 0.8 % (stop 51);
- ``time_optimal``: the shortest time rest to rest with the feed free along the pass, by
  TOPP-RA (Pham & Pham, T-RO 2018) on the same grid, as toppra computes it
  (:mod:`solver.kernels.feed_profile`, compiled; tests/solver/test_cycle_time.py runs toppra).

All three run on one blended joint path, the one mu_acc is defined on
(:mod:`solver.path.blended_path`): the pass's tracked joint path with every corner rounded by a
parabolic blend, on a grid of the blends' ends. Along the path, a joint's speed is q_s sdot and
its acceleration q_s sddot + q_ss sdot^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.kernels import feed_profile
from solver.path.blended_path import blended_path
from solver.path.evaluate import PathEvaluation
from solver.path.prepare import check_passes
from solver.path.problem import PathProblem


@dataclass(frozen=True)
class PassTime:
    """The cycle time of one pass (s), and its ramps.

    Attributes:
        start: the pass's first waypoint. stop: one past its last.
        length: L, m, the tool point's arc length.
        constant_feed_time: L / mu_acc, s.
        ramp_up_length: m, from rest to mu_acc at the start (L / 2 at most where the pass is too
            short to reach it); ramp_up_time: s, the time that takes.
        ramp_down_length: m, from mu_acc to rest at the end; ramp_down_time: s.
        ramp_time: s, the pass at mu_acc with its ramps.
        time_optimal: s, the time-optimal feed profile rest to rest (TOPP-RA).
    """

    start: int
    stop: int
    length: float
    constant_feed_time: float
    ramp_up_length: float
    ramp_up_time: float
    ramp_down_length: float
    ramp_down_time: float
    ramp_time: float
    time_optimal: float


@dataclass(frozen=True)
class CycleTime:
    """The cycle time of a path: totals over its passes (s), and each pass."""

    constant_feed_time: float
    ramp_time: float
    time_optimal: float
    passes: tuple[PassTime, ...]


REACHED = 1e-4
"""How close (relative, in squared speed: 5e-5 of the feed) to mu_acc^2 the capped profile is at
mu_acc, beyond TOPP-RA's margin on the cruise: see :func:`reached_from`."""


def reached_from(top: float) -> float:
    """The squared speed at and above which the capped profile is at its cap ``top`` (mu_acc^2).

    TOPP-RA's margin keeps each step a hair below what it reaches
    (:data:`solver.kernels.feed_profile.SHRINK`: 1e-8 m^2/s^2, or 1e-4 of it below 1 cm/s), so
    a cruise at the cap sits that far below it: 5e-9 relative at 1.4 m/s, 2.2e-6 at 0.067 m/s.
    A fixed relative bound missed slow cruises (at 1e-12 every one, at 1e-6 those below
    0.1 m/s): the ramp down was then taken from the one highest point on, 0.269 of a 0.27 m
    pass. And a ramp's steps add their margins up (4e-8 m^2/s^2 after four): the point where the
    ramp meets the cap is REACHED below it, the cruise twice the margin.
    """
    margin = min(feed_profile.SHRINK, feed_profile.SHRINK_SHARE * top)
    return top - 2.0 * margin - REACHED * top


def _time(s: np.ndarray, x: np.ndarray) -> float:
    """The time (s) of the squared speeds ``x`` on the grid ``s``, sddot constant a segment."""
    speed = np.sqrt(np.maximum(x, 0.0))
    sums = speed[1:] + speed[:-1]
    with np.errstate(divide="ignore"):
        return float(np.sum(np.where(sums > 0.0, 2.0 * np.diff(s) / sums, np.inf)))


def pass_time(
    q: np.ndarray,
    positions: np.ndarray,
    mu_acc: float,
    limits: tuple[np.ndarray, np.ndarray],
    blend_length: float,
) -> tuple[float, ...]:
    """One pass's figures, in :class:`PassTime`'s order from ``length`` on.

    Args:
        q: shape (M, n), rad, the pass's joint path.
        positions: shape (M, 3), m, its tool points.
        mu_acc: m/s, > 0.
        limits: qdot_max (n,), rad/s, and qddot_max (n,), rad/s^2.
        blend_length: b, m.
    """
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))])
    s, q_s, q_ss = blended_path(q, s, blend_length)
    qdot_max, qddot_max = (np.ascontiguousarray(a, dtype=float) for a in limits)
    q_s, q_ss = np.ascontiguousarray(q_s), np.ascontiguousarray(q_ss)
    top = mu_acc**2
    # The pass at mu_acc with its ramps: the fastest profile that never passes mu_acc, on the
    # time-optimal profile's own discretisation (so the time-optimal one is never slower).
    profile = feed_profile.capped_profile(s, q_s, q_ss, qdot_max, qddot_max, top)
    reached = np.flatnonzero(profile >= reached_from(top))
    first = int(reached[0]) if reached.size else int(np.argmax(profile))
    last = int(reached[-1]) if reached.size else first
    length = float(s[-1])
    return (
        length,
        length / mu_acc,
        float(s[first]),
        _time(s[: first + 1], profile[: first + 1]),
        float(s[-1] - s[last]),
        _time(s[last:], profile[last:]),
        _time(s, profile),
        _time(s, feed_profile.time_optimal(s, q_s, q_ss, qdot_max, qddot_max)),
    )


def cycle_time(problem: PathProblem, evaluation: PathEvaluation) -> CycleTime | None:
    """The cycle time of an evaluated path (motion.md section 4).

    Args:
        problem: the robot (its speed and acceleration limits), the path with its passes and
            the options (the blend length) of the evaluation.
        evaluation: :func:`solver.path.evaluate.evaluate_path` of the problem (or of a joint
            path, :func:`solver.path.joint_path.evaluate_joint_path`).

    Returns:
        None without acceleration limits, where the path is infeasible, where mu_acc is 0
        (the tool turns on the spot: no feed, no finite time), or where a figure is not
        finite.
    """
    robot, acc = problem.robot, evaluation.acceleration
    if acc is None or evaluation.q is None or robot.qddot_max is None or acc.mu_acc <= 0.0:
        return None
    limits = (robot.qdot_max, robot.qddot_max)
    positions = problem.prepared.tool_position
    passes = []
    for start, stop in check_passes(problem.passes, len(positions)):
        figures = pass_time(
            evaluation.q[start:stop], positions[start:stop], acc.mu_acc, limits, acc.blend_length
        )
        if not all(math.isfinite(figure) for figure in figures):
            return None
        passes.append(PassTime(start, stop, *figures))
    return CycleTime(
        constant_feed_time=sum(p.constant_feed_time for p in passes),
        ramp_time=sum(p.ramp_time for p in passes),
        time_optimal=sum(p.time_optimal for p in passes),
        passes=tuple(passes),
    )
