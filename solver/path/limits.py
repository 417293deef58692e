"""The limits on the path index: each gives, along tracked joint paths, a speed bound per waypoint.

pink's ``Limit`` seam: a limit is an object with one method the pipeline calls,
:meth:`Limit.speed_bound`, and the pipeline (:func:`solver.path.pipeline.run_chunk`) takes the
least bound over the problem's limits (:func:`bound_by_limits`) without naming any. Joint speed
limits, the DTF of Sensors 2022, are the first limit; joint accelerations (motion.md) and the
cell (cell.md) are the next, each a class of its own here. The compiled kernels compute the same
bound in their own hook (:mod:`solver.kernels`), tested cell by cell against this one.

A limit is of one of two kinds (:attr:`Limit.on_final_path`): a *waypoint* limit bounds V_max,
the feed at each waypoint by its joint speeds per unit feed, whose minimum is mu_path; a
*final-path* limit bounds a constant feed along the final tracked joint path (in free spin, the
path along the spin schedule that realises mu_path), and min(mu_path, its bounds) is the index
the arm can run at: joint accelerations (:class:`JointAccelerationLimit`, motion.md section 2)
give mu_acc.

A limit that bounds no speed but admits or refuses a whole joint path (the cell, cell.md) is a
:class:`PathCheck`: it runs after the speed limits, on the branches they leave feasible, best
first (:mod:`solver.path.path_checks`).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import Any

import numpy as np

from solver.core.two_variable_lp import two_variable_speed
from solver.kernels.spin_lp import spin_speed
from solver.path.blend_stencil import BlendStencil

ACC_ROW_COST = 0.5
"""A waypoint's work under joint acceleration limits (its stencil row's scan, the probes) besides
its span's, in closed-form poses: the UR5's ERK-size map was 1.46x its time without them
(bench/run.py, 2026-12-06), 1.7x on a 20,000-waypoint path at b = 10 um (two steps a row)."""
ACC_STEP_COST = 0.04
"""The work of one step of a stencil row's span at one placement, in closed-form poses: 5.0 to
6.8 ns on one thread (0.029 to 0.040 of the UR5 map's pose without the limits, 171 ns), a
20,000-waypoint dome path, 49 placements, b = 2 mm to 30 mm (249 to 3,119 steps a row),
2026-12-06. Unweighed, a 196-placement map of that path at b = 5 cm was accepted at 78 % of
DTF_MAX_MAP_POSES and ran 190 s (47 s since a row reads its own span, not the longest); at
b = 2 mm it ran 3.3 s on two threads against 0.43 s without the limits (weighed 11 x)."""


@dataclass(frozen=True)
class JointMotion:
    """What a limit sees of joint paths: B branches at C placements along W waypoints.

    The batch axes ``...`` are (B, C, W) in the pipeline and (W,) for one joint path.

    Attributes:
        q: shape (n, ...), rad, the tracked joint paths.
        qd_unit: shape (n, ...), J^-1 t_hat (rad/s per m/s of feed; per rad/s where h = 0).
        qd_spin: shape (n, ...), J^-1 [0; z_tool] (rad/s per rad/s of tool spin) when the spin
            rate is free (cam.md section 2); None in fixed spin.
        qd_null: shape (n, ...), a unit vector spanning the null space of J, for a seven-joint
            arm whose spin rate is free (the LP's third variable); None otherwise.
    """

    q: np.ndarray
    qd_unit: np.ndarray
    qd_spin: np.ndarray | None = None
    qd_null: np.ndarray | None = None


class Limit(abc.ABC):
    """A limit on how fast a path can run, as a speed bound at every waypoint."""

    #: Short name, reported where the limit binds (``"speed"``).
    name: str
    #: False: it bounds V_max at each waypoint (mu_path); True: it bounds a constant feed along
    #: the final tracked joint path (mu_acc), and V_max keeps its meaning.
    on_final_path: bool = False
    #: True where its bound is the same at a placement turned about the base z axis (the joint
    #: paths then differ by joint 1's shift alone): the optimisers may search over (r, psi)
    #: (:func:`solver.optimise.symmetry.symmetric_search`). False unless a limit says so.
    keeps_base_turn: bool = False

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

    @abc.abstractmethod
    def pose_cost(self) -> float:
        """What this limit adds to one pose's work, in poses of a closed-form family's map.

        The size limits add it to the family's figure at every waypoint
        (:meth:`solver.path.problem.PathProblem.path_cost`,
        :func:`solver.path.capability_map.map_cost`), as a :class:`PathCheck`'s, so a new
        limit's work is weighed before any of it runs (0 where the family's figure holds it).
        """


class JointSpeedLimit(Limit):
    """Joint speed limits: the DTF, 1 / max_j |qd_j| / qdot_max_j (Sensors 2022 eq. (30)).

    With the spin rate free, the exact two-variable LP
    (:func:`solver.core.two_variable_lp.two_variable_speed`), and for seven joints the
    three-variable one (:func:`solver.core.dtf_redundant.spin_speed`, compiled:
    :func:`solver.kernels.spin_lp.spin_speed`).
    """

    name = "speed"
    keeps_base_turn = True  # joint speeds per unit feed do not depend on q1

    def __init__(self, qdot_max: np.ndarray) -> None:
        """Hold the limits.

        Args:
            qdot_max: shape (n,), rad/s, each joint's speed limit (> 0).
        """
        self.qdot_max = np.asarray(qdot_max, dtype=float)

    def speed_bound(self, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        """The DTF at every waypoint, and the joint on its limit (see :meth:`Limit.speed_bound`)."""
        qd_unit = motion.qd_unit
        if motion.qd_spin is not None and motion.qd_null is not None:
            return spin_speed(qd_unit, motion.qd_spin, motion.qd_null, self.qdot_max)
        if motion.qd_spin is not None:
            return two_variable_speed(qd_unit, motion.qd_spin, self.qdot_max)
        ratio = np.abs(qd_unit) / self.qdot_max.reshape((-1,) + (1,) * (qd_unit.ndim - 1))
        limiting = ratio.argmax(axis=0)
        # The largest ratio is the one at its argmax (NaN where argmax stopped at a NaN, as max
        # gives): taken there, not reduced again; a reduction over the joint axis, innermost in
        # memory as the families return qd_unit, cost a numeric six-joint map about a tenth of
        # its time.
        worst = np.take_along_axis(ratio, limiting[None], axis=0)[0]
        with np.errstate(divide="ignore", invalid="ignore"):  # infeasible branches
            speed = 1.0 / worst
        return speed, limiting

    def pose_cost(self) -> float:
        """None added: every family's figure is the work of its DTF (the index itself)."""
        return 0.0


@dataclass(frozen=True)
class PathVerdict:
    """What a path check says of one joint path.

    Attributes:
        failed_waypoint: where the path is refused; None: admitted.
        detail: the check's report (the cell: :class:`solver.path.cell.verdict.CellVerdict`).
        reason: the refusing check's reason code (:data:`solver.core.codes.REASONS`); None
            where admitted. A problem may hold several checks: answers take the reason from
            the verdict that refused, not from the first check.
    """

    failed_waypoint: int | None
    detail: object
    reason: int | None = None


def refused_reason(verdict: PathVerdict) -> int:
    """The reason code of a refusing verdict: its check's (not the problem's first check's).

    Raises:
        ValueError: the verdict refuses no path, or its check gave no reason.
    """
    if verdict.failed_waypoint is None or verdict.reason is None:
        raise ValueError("a path check refused a path without giving its reason")
    return verdict.reason


class PathCheck(abc.ABC):
    """A limit that admits or refuses a tracked joint path at a placement (cell.md section 3)."""

    #: Short name (``"collision"``).
    name: str
    #: The reason code (:data:`solver.core.codes.REASONS`) of a refused path.
    reason: int

    @abc.abstractmethod
    def check(self, q: np.ndarray, placement: np.ndarray, *, thorough: bool) -> PathVerdict:
        """Admit or refuse a joint path.

        Args:
            q: shape (W, n), rad, the tracked joint path.
            placement: shape (5,), [x, y, z, yaw, spin] of {O} in {B}.
            thorough: report everything (an evaluation); False: only whether it is refused,
                as fast as can be (a map, an optimiser).
        """

    @abc.abstractmethod
    def pose_cost(self) -> float:
        """What checking one pose of a path weighs, in poses of a closed-form family's map.

        The size limits add it to the family's figure at every waypoint
        (:meth:`solver.path.problem.PathProblem.path_cost`,
        :func:`solver.path.capability_map.map_cost`), so a check's work is weighed before any
        of it runs; the cell's: :func:`solver.path.cell.cost.cell_pose_cost`.
        """

    def check_many(self, joint_paths: np.ndarray, placements: np.ndarray) -> list[PathVerdict]:
        """:meth:`check` of N joint paths, not thorough (a map's chunk): the same verdicts.

        Args:
            joint_paths: shape (N, W, n), rad, tracked joint paths.
            placements: shape (N, 5), each path's placement.
        """
        return [
            self.check(q, placement, thorough=False)
            for q, placement in zip(joint_paths, placements, strict=True)
        ]

    def model(self) -> dict[str, Any]:
        """What a map's answer reports of this check's model, as its fields (none here).

        The cell: the links given capsules and the parts not checked
        (:meth:`solver.path.cell.limit.CellLimit.model`), whatever the placement.
        """
        return {}

    def refuses_at(self, q: np.ndarray, placement: np.ndarray, refusal: PathVerdict) -> bool:
        """A quick test: True only where :meth:`check` refuses ``q`` too (none here).

        A map tries a refused pick's next branches (``q`` (W, n) at ``placement`` (5,)) where
        ``refusal`` refused the pick, before checking them whole; False says nothing.
        """
        return False


class JointAccelerationLimit(Limit):
    """Joint acceleration limits at a constant feed (motion.md section 2).

    At feed v the joint accelerations are D_i v^2, so V_acc,i = min_j sqrt(a_j / |D_ij|)
    (infinite where D_ij = 0, and at the waypoints within b of a pass end).
    """

    name = "acceleration"
    on_final_path = True
    keeps_base_turn = True  # D_i: second differences of the joint paths, joint 1's shift cancels

    def __init__(self, qddot_max: np.ndarray, stencil: BlendStencil) -> None:
        """Hold the limits and the path's stencil.

        Args:
            qddot_max: shape (n,), rad/s^2, each joint's acceleration limit (> 0).
            stencil: the path's second difference over the blend length.
        """
        self.qddot_max = np.asarray(qddot_max, dtype=float)
        self.stencil = stencil

    def speed_bound(self, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        """V_acc at every waypoint, and the joint that binds (see :meth:`Limit.speed_bound`)."""
        q = motion.q
        speed = np.full(q.shape[1:], np.inf)
        joint = np.zeros(q.shape[1:], dtype=np.int64)
        if not self.stencil.waypoints.size:
            return speed, joint
        second = self.stencil.second_difference(q)  # (n, ..., K)
        ratio = np.abs(second) / self.qddot_max.reshape((-1,) + (1,) * (second.ndim - 1))
        worst = ratio.max(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            speed[..., self.stencil.waypoints] = 1.0 / np.sqrt(worst)
        joint[..., self.stencil.waypoints] = ratio.argmax(axis=0)
        return speed, joint

    def pose_cost(self) -> float:
        """ACC_ROW_COST, plus ACC_STEP_COST for each step of a stencil row's span, on average.

        The compiled kernels form a row's D from the steps its blend spans
        (:func:`solver.kernels.limits.row_second`): a map's work at each placement grows with
        the spans, 2 b over the waypoints' spacing, a hundred steps and more on a dense path
        (the numpy pipeline's D reads five waypoints a row: weighed as the kernels' here).
        """
        spans = self.stencil.index[:, -1] - self.stencil.index[:, 0]
        if not spans.size:
            return 0.0
        return ACC_ROW_COST + ACC_STEP_COST * float(spans.mean())


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
