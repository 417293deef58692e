"""The numeric family's branch following on the compiled chain, steered by the pruned map.

:class:`solver.core.follows_in_steps.FollowsInSteps` as
:class:`solver.families.numeric.family.NumericFamily` implements it: the compiled seeding
(:mod:`solver.families.numeric.seed_kernel`), the following of chosen slots along pieces of the
paths (:mod:`~solver.families.numeric.follow_kernel`), and the bounded passes of six and seven
joints (:mod:`~solver.families.numeric.bounded_kernel`,
:mod:`~solver.families.numeric.bounded_redundant_kernel`), with the IK's settings and constants
(:mod:`solver.families.numeric.ik`) as the kernels take them.
"""

from __future__ import annotations

import abc

import numpy as np

from solver.core.follows_in_steps import FollowsInSteps
from solver.core.kernel_arrays import kernel_array
from solver.families.numeric import (
    bounded_kernel,
    bounded_redundant_kernel,
    follow_kernel,
    ik,
    seed_kernel,
)

REDUNDANT_MARGIN = 1e-10
"""Relative slack on a seven-joint slot's bound (:mod:`bounded_redundant_kernel`): its V_max come
from the unwrapped solutions, the pipeline's from the tracked path (2 pi k and the steps' running
sums apart): measured at most 6e-15 apart on the Panda, 1e-13 on the xArm7 (every slot of a
40 mm ERK grid followed to the end, 2026-12-02)."""


class CompiledFollowing(FollowsInSteps):
    """The seeding and following of a numeric family's slots on its compiled chain.

    The family sets the attributes below (:class:`~solver.families.numeric.family.NumericFamily`
    in its constructor) and gives its number of joints.

    Attributes:
        seeds: shape (K, n), rad or m, the IK's seeds.
        lower: shape (n,), the joints' lower limits.
        upper: shape (n,), the joints' upper limits.
        compiled: whether the family runs on the compiled chain.
    """

    seeds: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    compiled: bool
    _packed: tuple[np.ndarray, ...]

    @property
    @abc.abstractmethod
    def dof(self) -> int:
        """Number of joints."""

    @property
    @abc.abstractmethod
    def more_seeds(self) -> np.ndarray:
        """Shape (M, n): the seeds tried where the seeds found an odd number of solutions.

        Six joints: :func:`solver.families.numeric.ik.more_seeds`; else M = 0.
        """

    def _settings(self) -> tuple[np.ndarray, np.ndarray]:
        """The compiled IK's settings and constants (:func:`seed_kernel.seed_paths`)."""
        settings = np.array(
            [
                ik.SEED_ITERATIONS,
                ik.TRACK_ITERATIONS,
                ik.DISTINCT,
                ik.SINGULAR_RCOND,
                ik.STALL_STEPS,
                ik.STALL_RATIO,
                ik.PREDICT_SMOOTH,
            ],
            dtype=float,
        )
        return settings, np.array([ik.TOLERANCE, ik.DAMPING_SCALE, ik.DAMPING_FLOOR])

    @property
    def follows_in_steps(self) -> bool:
        """The compiled chain of more than six joints; the numpy reference only whole paths.

        Six and seven joints are pruned in one compiled pass instead (:attr:`follows_bounded`),
        more joints in steps (:mod:`solver.path.pruning`). Six joints in
        steps: a pruned map of the UR5 URDF took 1.05 times the
        unpruned one, of an IRB 2400 URDF 1.8 times (143 placements of the ERK path, same run,
        loaded machine, 2026-12-02): their few branches are cheap to follow (a UR's four
        shoulder branches tie and are all followed anyway), and the bounds cost more than the
        following they save. Seven joints, pruned against unpruned (CPU time, best of 3, same
        run): the Panda's ERK map 1.76 times faster, the xArm7 1.69, the LBR iiwa 14 1.25 (in
        one pass now, :attr:`follows_bounded`).
        """
        return self.compiled and self.dof > 6

    def seed_first(
        self, rotations: np.ndarray, positions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`seed_kernel.seed_paths` (see :meth:`FollowsInSteps.seed_first`)."""
        settings, constants = self._settings()
        current, count = seed_kernel.seed_paths(
            self._packed,
            self.seeds,
            self.more_seeds,
            (self.lower, self.upper),
            kernel_array(rotations),
            kernel_array(positions),
            settings,
            constants,
        )
        return current, count

    def follow_piece(
        self,
        current: np.ndarray,
        rotations: np.ndarray,
        positions: np.ndarray,
        solve_first: bool,
    ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`follow_kernel.follow_paths` (see :meth:`FollowsInSteps.follow_piece`)."""
        settings, constants = self._settings()
        q, status = follow_kernel.follow_paths(
            self._packed,
            current,
            kernel_array(rotations),
            kernel_array(positions),
            solve_first,
            settings,
            constants,
        )
        return q, status

    @property
    def follows_bounded(self) -> bool:
        """The compiled chain of six or seven joints (:mod:`solver.path.bounded`).

        Seven joints (:mod:`bounded_redundant_kernel`): the Panda's ERK map (546 placements,
        two threads) took 0.66 to 0.70 times the CPU time of its pruning in steps (best of 3,
        alternating, machine loaded to 5-6 on 2 cores, 2026-12-02), the same answers.
        """
        return self.compiled and self.dof in (6, 7)

    def follow_bounded(
        self,
        current: np.ndarray,
        poses: tuple[np.ndarray, np.ndarray],
        speeds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float],
        rules: tuple[float, ...],
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:func:`bounded_kernel.follow_bounded` (see :meth:`FollowsInSteps.follow_bounded`).

        Seven joints: :func:`bounded_redundant_kernel.follow_bounded`, its margin
        :data:`REDUNDANT_MARGIN` at least.
        """
        settings, constants = self._settings()
        kernel = bounded_kernel if self.dof == 6 else bounded_redundant_kernel
        if self.dof > 6:
            rules = (rules[0], max(rules[1], REDUNDANT_MARGIN), *rules[2:])
        result: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] = kernel.follow_bounded(
            self._packed,
            current,
            *(kernel_array(a) for a in (*poses, *speeds[:3])),
            kernel_array(speeds[3], np.bool_),
            (self.lower, self.upper, np.array([speeds[4]], dtype=float)),
            settings,
            constants,
            np.array(rules, dtype=float),
        )
        return result

    def follow_ranges(
        self,
        current: np.ndarray,
        rotations: np.ndarray,
        positions: np.ndarray,
        start: np.ndarray,
        stop: np.ndarray,
        out: tuple[np.ndarray, np.ndarray],
    ) -> None:
        """:func:`follow_kernel.follow_ranges` (see :meth:`FollowsInSteps.follow_ranges`)."""
        settings, constants = self._settings()
        follow_kernel.follow_ranges(
            self._packed,
            current,
            kernel_array(rotations),
            kernel_array(positions),
            kernel_array(start, np.int64),
            kernel_array(stop, np.int64),
            out,
            settings,
            constants,
        )
