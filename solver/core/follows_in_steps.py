"""The seam a numeric family's branch following is steered through (:mod:`solver.path.pruning`).

A family that follows its branches from waypoint to waypoint (a numeric one) implements this
besides :class:`solver.core.family.KinematicsFamily`; the map's pipeline then follows the most
promising branch first and stops following the others once they cannot be the best.
"""

from __future__ import annotations

import abc

import numpy as np


class FollowsInSteps(abc.ABC):
    """A family that follows its branches waypoint by waypoint, and lets the caller steer it.

    A numeric family's work is following branches from waypoint to waypoint; a map needs only
    the best branch's answer, so its pipeline (:mod:`solver.path.pruning`) follows the most
    promising branch first and stops following a branch once a bound of its index is below
    the best complete one's. This is the seam it steers the following through: seed the first
    waypoints, then follow any chosen slots along any piece of the path.

    Layout: paths first, as the compiled chain takes them: current (P, K, n), rotations
    (P, W, 3, 3), positions (P, W, 3).
    """

    @property
    @abc.abstractmethod
    def follows_in_steps(self) -> bool:
        """Whether :meth:`seed_first` and :meth:`follow_piece` can be used (else solve_path)."""

    @abc.abstractmethod
    def seed_first(
        self, rotations: np.ndarray, positions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The slots' solutions at each path's first pose: (P, 3, 3), (P, 3) -> (P, K, n), (P,).

        Returns:
            current: shape (P, K, n), rad, unwrapped, NaN in the slots without a solution;
            count: shape (P,), the distinct solutions found (``PathSolutions.branches_found``).
        """

    @abc.abstractmethod
    def follow_piece(
        self,
        current: np.ndarray,
        rotations: np.ndarray,
        positions: np.ndarray,
        solve_first: bool,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Follow every slot of ``current`` that is not NaN along a piece of its path.

        The same numbers, slot by slot, as :meth:`KinematicsFamily.solve_path` gives there,
        whatever the other slots, for a path in one piece. A family may start a waypoint's solve
        from the solutions before it (the numeric family's six joints: ``ik.PREDICT_SMOOTH``),
        which a later piece does not see: a path cut in pieces goes through
        :meth:`follow_ranges`, whose ``out`` holds them.

        Args:
            current: shape (P, K, n), in and out: each slot's solution at the waypoint before
                the piece (``solve_first``), or at the piece's first waypoint (the first piece);
                NaN: not followed. On return, the solution at the piece's last waypoint, NaN
                where the slot was lost.
            rotations: shape (P, W, 3, 3), R_B_F* of the piece's waypoints.
            positions: shape (P, W, 3), m in {B}.
            solve_first: whether the piece's first waypoint is solved (all pieces but the
                path's first).

        Returns:
            q (n, K, P, W), rad, wrapped, NaN where not followed or lost; status (K, P, W).
        """

    @property
    def follows_bounded(self) -> bool:
        """Whether :meth:`follow_bounded` can be used (:mod:`solver.path.bounded`)."""
        return False

    def follow_bounded(
        self,
        current: np.ndarray,
        poses: tuple[np.ndarray, np.ndarray],
        speeds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float],
        rules: tuple[float, ...],
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every slot followed from the first waypoints, those that cannot be a map's pick dropped.

        Args:
            current: shape (P, K, n), the slots' solutions at the first waypoints (read only).
            poses: rotations (P, W, 3, 3) and positions (P, W, 3) of the flange.
            speeds: twists (P, W, 6), tool points (P, W, 3), qdot_max (n,), the waypoints of
                pure rotation (W,), for V_max along each slot, and the joint step tracking
                calls a jump.
            rules: (tie, margin, rough steps, slack): the pick's tie tolerance, a margin for
                rounding, and how slots are scouted (:mod:`solver.path.bounded`).

        Returns:
            q (n, K, P, W), wrapped; status (K, P, W); bound (K, P), the least V_max
            followed; dropped (K, P), the slots whose following was stopped.
        """
        raise NotImplementedError

    @abc.abstractmethod
    def follow_ranges(
        self,
        current: np.ndarray,
        rotations: np.ndarray,
        positions: np.ndarray,
        start: np.ndarray,
        stop: np.ndarray,
        out: tuple[np.ndarray, np.ndarray],
    ) -> None:
        """:meth:`follow_piece` with a piece of its own for each slot, written into ``out``.

        Args:
            current: shape (P, K, n), in and out, as for :meth:`follow_piece`, each slot's at
                waypoint ``start - 1`` (at 0 where ``start`` is 0).
            rotations: shape (P, W, 3, 3), every waypoint of the paths.
            positions: shape (P, W, 3).
            start: shape (K, P), each slot's first waypoint.
            stop: shape (K, P), the waypoint after its last (``stop <= start``: not followed).
            out: q (n, K, P, W) and status (K, P, W), written at the slots' pieces only; q
                holds each slot's solutions before its ``start`` where it was followed there
                (NaN where not): a path cut in pieces gives the bits of one piece.
        """
