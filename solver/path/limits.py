"""The limits on the path index: each gives, along tracked joint paths, a speed bound per waypoint.

pink's ``Limit`` seam: a limit is an object with one method the pipeline calls,
:meth:`Limit.speed_bound`, and the pipeline (:func:`solver.path.pipeline.run_chunk`) takes the
least bound over the problem's limits (:func:`bound_by_limits`) without naming any. Joint speed
limits, the DTF of Sensors 2022, are the first limit; joint accelerations (motion.md) and the
cell (cell.md) are the next, each a class of its own here. The compiled kernels compute the same
bound in their own hook (:mod:`solver.kernels`), tested cell by cell against this one.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from solver.core.dtf import two_variable_speed


@dataclass(frozen=True)
class JointMotion:
    """What a limit sees of joint paths: B branches at C placements along W waypoints.

    The batch axes ``...`` are (B, C, W) in the pipeline and (W,) for one joint path.

    Attributes:
        q: shape (n, ...), rad, the tracked joint paths.
        qd_unit: shape (n, ...), J^-1 t_hat (rad/s per m/s of feed; per rad/s where h = 0).
        qd_spin: shape (n, ...), J^-1 [0; z_tool] (rad/s per rad/s of tool spin) when the spin
            rate is free (cam.md section 2); None in fixed spin.
    """

    q: np.ndarray
    qd_unit: np.ndarray
    qd_spin: np.ndarray | None = None


class Limit(abc.ABC):
    """A limit on how fast a path can run, as a speed bound at every waypoint."""

    #: Short name, reported where the limit binds (``"speed"``).
    name: str

    @abc.abstractmethod
    def speed_bound(self, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        """The largest feed each waypoint allows, and the joint that binds it.

        Args:
            motion: the joint paths and their speeds per unit feed.

        Returns:
            speed: shape ``...``, m/s (rad/s where h = 0), inf where nothing bounds it and NaN
            or inf at a singular configuration;
            joint: shape ``...``, the binding joint's index.
        """


class JointSpeedLimit(Limit):
    """Joint speed limits: the DTF, 1 / max_j |qd_j| / qdot_max_j (Sensors 2022 eq. (30)).

    With the spin rate free, the exact two-variable LP (:func:`solver.core.dtf.two_variable_speed`).
    """

    name = "speed"

    def __init__(self, qdot_max: np.ndarray) -> None:
        """Hold the limits.

        Args:
            qdot_max: shape (n,), rad/s, each joint's speed limit (> 0).
        """
        self.qdot_max = np.asarray(qdot_max, dtype=float)

    def speed_bound(self, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        """The DTF at every waypoint, and the joint on its limit (see :meth:`Limit.speed_bound`)."""
        qd_unit = motion.qd_unit
        if motion.qd_spin is not None:
            return two_variable_speed(qd_unit, motion.qd_spin, self.qdot_max)
        ratio = np.abs(qd_unit) / self.qdot_max.reshape((-1,) + (1,) * (qd_unit.ndim - 1))
        limiting = ratio.argmax(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):  # infeasible branches
            speed = 1.0 / ratio.max(axis=0)
        return speed, limiting


def bound_by_limits(
    limits: tuple[Limit, ...], motion: JointMotion
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The least speed bound over ``limits`` at every waypoint, its joint and which limit it is.

    Returns:
        speed and joint as :meth:`Limit.speed_bound`; binding: shape ``...``, the index in
        ``limits`` of the limit that binds (the first where two bind alike).
    """
    speed, joint = limits[0].speed_bound(motion)
    binding = np.zeros(np.shape(speed), dtype=np.int64)
    for k, limit in enumerate(limits[1:], start=1):
        other, other_joint = limit.speed_bound(motion)
        tighter = other < speed
        speed = np.where(tighter, other, speed)
        joint = np.where(tighter, other_joint, joint)
        binding = np.where(tighter, k, binding)
    return speed, joint, binding
