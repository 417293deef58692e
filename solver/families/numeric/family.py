"""Any serial arm as a kinematics family: numeric IK from fixed seeds, J^-1 t by a batched solve.

robots.md section 4. At the first waypoint of a path the IK starts from a fixed scrambled Sobol
set of seeds over the joint box (K = 32 for six joints, 64 for seven or more), keeps every
distinct solution within the joint limits as a branch, labelled by its index in seed order, and
follows each branch to the next waypoint from its solution at the previous one. The same input
gives the same branches. A numeric family cannot promise that it found every branch: it reports
how many it found.

J^-1 t: a batched 6 x 6 solve for six joints; for more, the joint speeds of the exact DTF LP
(:mod:`solver.core.dtf_redundant`), which the pipeline's ratio turns into V_max unchanged.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pinocchio as pin

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.core.dtf_redundant import redundant_speed
from solver.core.family import Branch, KinematicsFamily, PathSolutions
from solver.core.progress import Progress, span
from solver.core.spatial import wrap_angle
from solver.families.numeric import ik
from solver.families.numeric.chain import SerialChain

# The Sobol sequence's seed: fixed, so that the same input gives the same branches.
SOBOL_SEED = 20240611
# Work of one placement in poses of a closed-form family (KinematicsFamily.path_cost), measured
# on the 2-core development machine against the analytic UR5 map (3.8 us a pose on the ERK
# path): seeding the first waypoint (K seeds, up to ik.SEED_ITERATIONS each) and following the
# branches found to each next waypoint, for the worst catalogue arm of each size.
# Seeding: the Panda took up to 24 ms a placement (64 seeds; placements of a differential
# evolution, many seeds unconverged), UR5 as a URDF and the Jaco2 6-12 ms (32 seeds).
SEED_COST = {6: 3_200.0, 7: 6_400.0}
# Following: UR5 as a URDF 0.24 ms a waypoint, the Jaco2 0.08 ms; the Panda 0.59 ms, the xArm7
# (whose +-2 pi joints give many distinct solutions) 1.44 ms.
TRACK_COST = {6: 65.0, 7: 400.0}
CHUNK_ROWS = 2048
"""Configurations checked (singularity, joint speeds) between two progress reports: about
0.2 s for seven joints under load, so that a cancelled evaluation stops within a second."""
SEED_SHARE, FOLLOW_SHARE = 0.05, 0.9
"""Where seeding the first waypoint ends, and following the branches, in a path's solve's
progress (the rest: the singularity checks)."""


def seed_count(dof: int) -> int:
    """K, the number of seeds: 32 for up to six joints, 64 beyond (robots.md section 4)."""
    return 32 if dof <= 6 else 64


class NumericFamily(KinematicsFamily):
    """A serial chain of a pinocchio model, from {B} to the flange {F}.

    Branch ``solution=k`` is the k-th distinct solution found at a path's first waypoint (at
    each pose, for :meth:`solve`); it names nothing geometric, and another placement may number
    its solutions differently.
    """

    name = "numeric"

    def __init__(
        self, model: pin.Model, *, base_frame: str, tool_frame: str, seed: int = SOBOL_SEED
    ) -> None:
        """Read the chain and fix the seeds.

        Args:
            model: pinocchio model whose joints (1-DOF, one serial chain) all move the tool.
            base_frame: {B}, fixed to the root.
            tool_frame: the flange {F}.
            seed: the Sobol sequence's seed.

        Raises:
            RobotModelError: the model is not such a chain.
        """
        self.chain = SerialChain.from_model(model, base_frame=base_frame, tool_frame=tool_frame)
        self.lower = model.lowerPositionLimit.copy()
        self.upper = model.upperPositionLimit.copy()
        count = seed_count(self.chain.dof)
        self.seeds = ik.seeds(
            count, lower=self.lower, upper=self.upper, revolute=self.chain.revolute, seed=seed
        )
        self._branches = tuple(Branch.named(solution=str(k)) for k in range(count))

    @property
    def dof(self) -> int:
        """Number of joints."""
        return self.chain.dof

    def path_cost(self, n_waypoints: int) -> float:
        """Seeding plus following, in closed-form poses (SEED_COST, TRACK_COST).

        Arms of more than seven joints scale the seven-joint figures by (dof / 7)^2 (the
        Jacobian products and solves grow about so).
        """
        size = min(max(self.dof, 6), 7)
        scale = max(self.dof / 7, 1.0) ** 2
        return scale * (SEED_COST[size] + max(n_waypoints - 1, 0) * TRACK_COST[size])

    @property
    def branches(self) -> tuple[Branch, ...]:
        """``solution=0`` ... ``solution=K-1``: slots for the distinct solutions, in seed order."""
        return self._branches

    def _seeded(
        self, rotation: np.ndarray, position: np.ndarray, progress: Progress | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Distinct solutions within the limits from every seed: (P, 3, 3), (P, 3) -> slots.

        ``progress`` is called after each iteration of the seeds' solve.

        Returns:
            slots (P, K, n), rad, NaN after the solutions found; count (P,).
        """
        n_poses, n_seeds = len(position), len(self.seeds)
        start = np.broadcast_to(self.seeds, (n_poses, n_seeds, self.dof)).reshape(-1, self.dof)
        q, converged = ik.solve(
            self.chain,
            start,
            np.repeat(rotation, n_seeds, axis=0),
            np.repeat(position, n_seeds, axis=0),
            iterations=ik.SEED_ITERATIONS,
            lower=self.lower,
            upper=self.upper,
            progress=progress,
        )
        q = q.reshape(n_poses, n_seeds, self.dof)
        return ik.distinct(q, converged.reshape(n_poses, n_seeds), self.chain.revolute)

    def _wrapped_with_status(
        self, q: np.ndarray, progress: Progress | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Revolute joints wrapped to [-pi, pi) and the status of each solution, q (..., n)."""
        flat = q.reshape(-1, self.dof)
        status = np.full(len(flat), UNREACHABLE)
        solved = np.flatnonzero(np.isfinite(flat).all(axis=-1))
        for rows in _in_chunks(solved, progress):
            status[rows] = np.where(ik.is_singular(self.chain, flat[rows]), SINGULAR, OK)
        wrapped = np.where(self.chain.revolute, wrap_angle(q), q)
        return wrapped, status.reshape(q.shape[:-1])

    def solve(self, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The distinct solutions found from the seeds at each pose (see KinematicsFamily.solve).

        Returns:
            q: shape (dof, K, *batch), NaN in the slots after the solutions found;
            status: shape (K, *batch).
        """
        batch = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
        rotation_flat = np.moveaxis(np.broadcast_to(rotation, (3, 3, *batch)), (0, 1), (-2, -1))
        position_flat = np.moveaxis(np.broadcast_to(position, (3, *batch)), 0, -1)
        slots, _ = self._seeded(rotation_flat.reshape(-1, 3, 3), position_flat.reshape(-1, 3))
        q, status = self._wrapped_with_status(slots)  # (P, K, n), (P, K)
        q = np.moveaxis(q.reshape(*batch, len(self.seeds), self.dof), (-1, -2), (0, 1))
        return q, np.moveaxis(status.reshape(*batch, len(self.seeds)), -1, 0)

    def solve_path(
        self, rotation: np.ndarray, position: np.ndarray, *, progress: Progress | None = None
    ) -> PathSolutions:
        """Seeded solutions at the first waypoint, each followed along its path.

        Each step starts from the branch's solution at the previous waypoint (so for dof > 6 it
        takes about the least joint motion), without joint limits (tracking checks them on the
        whole path). A branch that does not converge at a waypoint is ``UNREACHABLE`` there and
        after.

        Args:
            rotation: shape (3, 3, *batch, W), R_B_F, broadcasting with ``position``.
            position: shape (3, *batch, W), m in {B}.
            progress: called after each waypoint followed, and after each chunk of
                CHUNK_ROWS solutions checked for singularity; it may raise
                :class:`solver.core.progress.Cancelled` to stop the work.
        """
        shape = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
        *batch, n_waypoints = shape
        rotations = np.moveaxis(np.broadcast_to(rotation, (3, 3, *shape)), (0, 1), (-2, -1))
        rotations = rotations.reshape(-1, n_waypoints, 3, 3)  # (P, W, 3, 3)
        positions = np.moveaxis(np.broadcast_to(position, (3, *shape)), 0, -1)
        positions = positions.reshape(-1, n_waypoints, 3)
        n_paths, n_seeds = len(positions), len(self.seeds)
        slots, count = self._seeded(
            rotations[:, 0], positions[:, 0], span(progress, 0.0, SEED_SHARE)
        )
        q = np.full((n_paths, n_seeds, n_waypoints, self.dof), np.nan)
        q[:, :, 0] = slots
        paths, branches = np.nonzero(np.isfinite(slots[..., 0]))
        q[paths, branches] = self._followed(
            slots[paths, branches],
            rotations[paths],
            positions[paths],
            progress=span(progress, SEED_SHARE, FOLLOW_SHARE),
        )
        wrapped, status = self._wrapped_with_status(q, span(progress, FOLLOW_SHARE, 1.0))
        return PathSolutions(
            q=wrapped.transpose(3, 1, 0, 2).reshape(self.dof, n_seeds, *batch, n_waypoints),
            status=np.moveaxis(status, 1, 0).reshape(n_seeds, *batch, n_waypoints),
            seeds=n_seeds,
            branches_found=count.reshape(batch),
        )

    def _followed(
        self,
        start: np.ndarray,
        rotations: np.ndarray,
        positions: np.ndarray,
        *,
        progress: Progress | None = None,
    ) -> np.ndarray:
        """Each branch followed from its first solution, NaN from the waypoint where it is lost.

        Args:
            start: shape (M, n), the branches' solutions at the first waypoint.
            rotations: shape (M, W, 3, 3), R_B_F* of each branch's path.
            positions: shape (M, W, 3), m in {B}.
            progress: called after each waypoint with the fraction of waypoints followed.

        Returns:
            shape (M, W, n). A lost branch stays in the batch, frozen, until at least half of
            it is lost and it holds ``ik.COMPACT_MIN_ROWS`` rows, for the reason given there.
        """
        n_waypoints = positions.shape[1]
        track = np.full((len(start), n_waypoints, self.dof), np.nan)
        rows = np.arange(len(start))  # the branch of each batch row
        local = track.copy()  # the batch's rows of track
        local[:, 0] = current = start
        lost = np.zeros(len(start), dtype=bool)
        for waypoint in range(1, n_waypoints):
            if lost.all():
                break
            if progress is not None:
                progress(waypoint / n_waypoints)
            solved, converged = ik.solve(
                self.chain,
                current,
                rotations[:, waypoint],
                positions[:, waypoint],
                iterations=ik.TRACK_ITERATIONS,
                frozen=lost,
            )
            lost |= ~converged
            current = np.where(lost[:, None], current, solved)  # a lost row keeps a finite q
            local[:, waypoint] = np.where(lost[:, None], np.nan, solved)
            if len(rows) >= ik.COMPACT_MIN_ROWS and 2 * np.count_nonzero(lost) >= len(rows):
                track[rows] = local
                keep = ~lost
                rows, local, current, lost = rows[keep], local[keep], current[keep], lost[keep]
                rotations, positions = rotations[keep], positions[keep]
        track[rows] = local
        return track

    def joint_speeds_per_unit_twist(
        self,
        q: np.ndarray,
        twist: np.ndarray,
        tool_point: np.ndarray,
        *,
        qdot_max: np.ndarray | None = None,
        progress: Progress | None = None,
    ) -> np.ndarray:
        """J^-1 t (six joints) or the exact DTF LP's joint speeds per unit speed (more).

        See :meth:`KinematicsFamily.joint_speeds_per_unit_twist`. Only configurations with
        finite joints are computed, CHUNK_ROWS at a time with ``progress`` called after each;
        the others come back NaN.

        Raises:
            ValueError: dof > 6 and no ``qdot_max``.
        """
        if self.dof > 6 and qdot_max is None:
            raise ValueError(f"the DTF LP of a {self.dof}-joint arm needs qdot_max")
        shape = np.broadcast_shapes(q.shape[1:], twist.shape[1:], tool_point.shape[1:])
        q_flat = np.moveaxis(np.broadcast_to(q, (self.dof, *shape)), 0, -1).reshape(-1, self.dof)
        twist_flat = np.moveaxis(np.broadcast_to(twist, (6, *shape)), 0, -1).reshape(-1, 6)
        point_flat = np.moveaxis(np.broadcast_to(tool_point, (3, *shape)), 0, -1).reshape(-1, 3)
        speeds = np.full(q_flat.shape, np.nan)
        finite = np.flatnonzero(np.isfinite(q_flat).all(axis=-1))
        for rows in _in_chunks(finite, progress):
            speeds[rows] = self._speeds(q_flat[rows], twist_flat[rows], point_flat[rows], qdot_max)
        return np.moveaxis(speeds.reshape(*shape, self.dof), -1, 0)

    def _speeds(
        self,
        q: np.ndarray,
        twist: np.ndarray,
        tool_point: np.ndarray,
        qdot_max: np.ndarray | None,
    ) -> np.ndarray:
        """Joint speeds per unit twist at M finite configurations: (M, n), (M, 6), (M, 3)."""
        jacobian, _, _ = self.chain.jacobian(q, tool_point)
        if self.dof == 6:
            return _solve_or_nan(jacobian, twist)
        if self.dof > 6 and qdot_max is not None:
            speed, qdot = redundant_speed(jacobian, twist, qdot_max)
            with np.errstate(divide="ignore", invalid="ignore"):
                out: np.ndarray = qdot / speed[:, None]
            return out
        # fewer than six joints: the least-squares speeds (the twist may be out of reach)
        least: np.ndarray = (np.linalg.pinv(jacobian) @ twist[..., None])[..., 0]
        return least


def _in_chunks(rows: np.ndarray, progress: Progress | None) -> Iterator[np.ndarray]:
    """``rows`` in pieces of CHUNK_ROWS, ``progress`` called after each piece is done."""
    for start in range(0, len(rows), CHUNK_ROWS):
        yield rows[start : start + CHUNK_ROWS]
        if progress is not None:
            progress(min(start + CHUNK_ROWS, len(rows)) / len(rows))


def _solve_or_nan(jacobian: np.ndarray, twist: np.ndarray) -> np.ndarray:
    """J^-1 t for (M, 6, 6) and (M, 6); NaN rows where J is exactly singular."""
    try:
        speeds: np.ndarray = np.linalg.solve(jacobian, twist[..., None])[..., 0]
    except np.linalg.LinAlgError:  # one exactly singular J stops the batch: go one by one
        speeds = np.full(twist.shape, np.nan)
        for m in range(len(twist)):
            try:
                speeds[m] = np.linalg.solve(jacobian[m], twist[m])
            except np.linalg.LinAlgError:
                continue
    return speeds
