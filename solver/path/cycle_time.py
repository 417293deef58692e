"""The cycle time of a path under joint speed and acceleration limits (motion.md section 4).

Each pass starts and ends at rest. Three figures a pass, and their totals:

- ``constant_feed_time``: L / mu_acc, L the pass's tool-point length;
- the ramps: the arc length and time the feed needs to reach mu_acc from rest at the pass's
  start (and, mirrored, to stop at its end), the feed raised at each grid point as fast as every
  joint's speed and acceleration limit lets it (a forward integration on the path's grid),
  and the pass's time at mu_acc with those ramps (mu_acc in between: the index holds it at
  every waypoint);
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


def _largest_squared_speeds(
    q_s: np.ndarray, q_ss: np.ndarray, qdot_max: np.ndarray, qddot_max: np.ndarray
) -> np.ndarray:
    """The largest sdot^2 (M,) at each waypoint the speed and acceleration limits allow.

    The acceleration limits at sddot = 0: |q_ss sdot^2| <= a.
    """
    with np.errstate(divide="ignore"):
        speed = np.min((qdot_max / np.abs(q_s)) ** 2, axis=1)
        acceleration = np.min(qddot_max / np.abs(q_ss), axis=1)
    result: np.ndarray = np.minimum(speed, acceleration)
    return result


def _ramp_from_rest(
    s: np.ndarray,
    q_s: np.ndarray,
    q_ss: np.ndarray,
    cap: np.ndarray,
    qddot_max: np.ndarray,
    until: float = math.inf,
) -> tuple[np.ndarray, int]:
    """sdot^2 (M,) from rest at s_0, each step the largest acceleration every joint allows.

    x_{i+1} = min(cap_{i+1}, x_i + 2 (s_{i+1} - s_i) u_i), u_i the largest sddot with
    |q_s,ij u + q_ss,ij x_i| <= a_j for every joint (x_i <= cap_i makes u = 0 feasible).
    It stops at the first point where x reaches ``until`` (the rest of x left 0); compiled
    (:func:`solver.kernels.feed_profile.ramp_from_rest`: a Python step a grid point took
    seconds on a real-size program).

    Returns:
        x, and that point (-1 where x never reaches ``until``).
    """
    x, reached = feed_profile.ramp_from_rest(
        *(np.ascontiguousarray(a, dtype=float) for a in (s, q_s, q_ss, cap, qddot_max)),
        float(until),
    )
    return x, int(reached)


def _time(s: np.ndarray, x: np.ndarray) -> float:
    """The time (s) of the squared speeds ``x`` on the grid ``s``, sddot constant a segment."""
    speed = np.sqrt(np.maximum(x, 0.0))
    sums = speed[1:] + speed[:-1]
    with np.errstate(divide="ignore"):
        return float(np.sum(np.where(sums > 0.0, 2.0 * np.diff(s) / sums, np.inf)))


def _time_optimal(
    s: np.ndarray, q_s: np.ndarray, q_ss: np.ndarray, limits: tuple[np.ndarray, ...]
) -> float:
    """The time-optimal rest-to-rest time (s) on the grid ``s`` of the blended path.

    TOPP-RA as toppra computes it on that grid (:func:`solver.kernels.feed_profile.time_optimal`:
    the same profile, compiled; toppra took about 25 us a grid point, 7 s of a 17,073-move
    program's evaluation).
    """
    qdot_max, qddot_max = limits
    x = feed_profile.time_optimal(
        *(np.ascontiguousarray(a, dtype=float) for a in (s, q_s, q_ss, qdot_max, qddot_max))
    )
    return _time(s, x)


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
    before = np.vstack([q_ss[:1], q_ss[:-1]])  # a grid point ends the stretch before it too
    cap = np.minimum(
        np.minimum(*(_largest_squared_speeds(q_s, c, *limits) for c in (q_ss, before))),
        mu_acc**2,
    )
    top = mu_acc**2 * (1.0 - 1e-12)
    backward = (s[-1] - s[::-1], -q_s[::-1], q_ss[::-1], cap[::-1], limits[1])
    up, first = _ramp_from_rest(s, q_s, q_ss, cap, limits[1], until=top)
    down, from_end = _ramp_from_rest(*backward, until=top)
    last = len(s) - 1 - from_end
    if first >= 0 and from_end >= 0 and first < last:  # the feed reaches mu_acc between ramps
        cruise = np.full(last - first - 1, top)
        profile = np.concatenate([up[: first + 1], cruise, down[::-1][last:]])
    else:  # the ramps meet: the feed turns back wherever the two profiles cross
        profile = np.minimum(_ramp_from_rest(s, q_s, q_ss, cap, limits[1])[0],
                             _ramp_from_rest(*backward)[0][::-1])  # fmt: skip
        reached = np.flatnonzero(profile >= top)
        first = int(reached[0]) if reached.size else int(np.argmax(profile))
        last = int(reached[-1]) if reached.size else first
    length = float(s[-1])
    up_time = _time(s[: first + 1], profile[: first + 1])
    down_time = _time(s[last:], profile[last:])
    return (
        length,
        length / mu_acc,
        float(s[first]),
        up_time,
        float(s[-1] - s[last]),
        down_time,
        up_time + float(s[last] - s[first]) / mu_acc + down_time,
        _time_optimal(s, q_s, q_ss, limits),
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
