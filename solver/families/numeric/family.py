"""Any serial arm as a kinematics family: numeric IK from fixed seeds, J^-1 t by a batched solve.

robots.md section 4. At the first waypoint of a path the IK starts from a fixed set of seeds
covering the joint box (a fractional factorial design at each joint's quartiles,
:func:`solver.families.numeric.ik.seeds`; K = 32 for six joints, 64 for seven or more; a seed
whose error stops shrinking is given up, ``ik.STALL_STEPS``; six joints that found an odd
number of solutions, which says one was missed, try 128 more, :func:`ik.more_seeds`), keeps
every distinct solution within the joint limits as a branch, labelled by its index in seed
order, and follows each branch to the next waypoint from its solution at the previous one.
The same input gives the same branches. Six joints: each regular solution's status carries the
sign of det J (``OK`` / ``OK_MIRRORED``), so tracking sees a branch that crosses a singularity
between two waypoints (robots.md: a wrist never passes q5 = 0) where an analytic branch, whose
label fixes that sign, jumps; seven joints have no det J (their statuses stay ``OK``). A numeric
family cannot promise that it found every branch: it reports how many it found.

J^-1 t and the null space: :mod:`solver.families.numeric.velocity`; the work model:
:mod:`solver.families.numeric.costs`; the compiled seeding and following that the pruned map
steers: :mod:`solver.families.numeric.following`.
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

from solver.core.codes import UNREACHABLE
from solver.core.family import Branch, KinematicsFamily, PathSolutions
from solver.core.progress import Progress, span
from solver.families.numeric import costs, ik, reference, velocity
from solver.families.numeric.chain import SerialChain
from solver.families.numeric.following import CompiledFollowing

FOLLOW_WAYPOINTS = 256
"""Waypoints of each path followed by the compiled chain between two progress reports (a
seven-joint arm's slots: about 0.2 s)."""
SEED_SHARE, FOLLOW_SHARE = 0.05, 0.9
"""Where seeding the first waypoint ends, and following the branches, in a path's solve's
progress (the rest: the singularity checks)."""


def seed_count(dof: int) -> int:
    """K, the number of seeds: 32 for up to six joints, 64 beyond (robots.md section 4)."""
    return 32 if dof <= 6 else 64


class NumericFamily(KinematicsFamily, CompiledFollowing):
    """A serial chain of a pinocchio model, from {B} to the flange {F}.

    Branch ``solution=k`` is the k-th distinct solution found at a path's first waypoint (at
    each pose, for :meth:`solve`); it names nothing geometric, and another placement may number
    its solutions differently.
    """

    name = "numeric"

    def __init__(
        self,
        model: pin.Model,
        *,
        base_frame: str,
        tool_frame: str,
        compiled: bool = True,
    ) -> None:
        """Read the chain and fix the seeds.

        Args:
            model: pinocchio model whose joints (1-DOF, one serial chain) all move the tool.
            base_frame: {B}, fixed to the root.
            tool_frame: the flange {F}.
            compiled: solve with the compiled chain (:mod:`solver.families.numeric.seed_kernel`,
                :mod:`~solver.families.numeric.follow_kernel`);
                False: with the numpy chain and :mod:`solver.families.numeric.ik`, the
                reference it is tested against.

        Raises:
            RobotModelError: the model is not such a chain.
        """
        self.chain = SerialChain.from_model(model, base_frame=base_frame, tool_frame=tool_frame)
        self.lower = model.lowerPositionLimit.copy()
        self.upper = model.upperPositionLimit.copy()
        count = seed_count(self.chain.dof)
        self.seeds = ik.seeds(
            count, lower=self.lower, upper=self.upper, revolute=self.chain.q_revolute
        )
        self._branches = tuple(Branch.named(solution=str(k)) for k in range(count))
        # The compiled chain has no mimic joints: a coupled chain runs on numpy.
        self.compiled = compiled and self.chain.coupling is None
        self._packed = self.chain.packed() if self.compiled else ()

    @property
    def dof(self) -> int:
        """Number of joints."""
        return self.chain.dof

    @functools.cached_property
    def more_seeds(self) -> np.ndarray:
        """The seeds tried where the seeds found an odd number of solutions (six joints).

        :func:`ik.more_seeds`; none for other numbers of joints. Made at the first seeding, not
        with the family: the catalogue's families are made in every command of dtf-place, and
        the Sobol points' scipy.stats loads scipy.optimize (tests/service/test_cli.py).
        """
        if self.chain.dof != 6:
            return np.empty((0, self.chain.dof))
        return ik.more_seeds(lower=self.lower, upper=self.upper, revolute=self.chain.q_revolute)

    def path_cost(self, n_waypoints: int, *, free_spin: bool = False) -> float:
        """Seeding plus following, in closed-form poses (:func:`costs.path_cost`)."""
        return costs.path_cost(self.dof, self.compiled, n_waypoints, free_spin=free_spin)

    def map_cost(self, n_waypoints: int, *, free_spin: bool = False, pruned: bool = False) -> float:
        """A map's placement (see the base), in the unit of :meth:`path_cost` (:mod:`costs`)."""
        return costs.map_cost(
            self.dof,
            self.compiled,
            n_waypoints,
            free_spin=free_spin,
            pruned=pruned and self.follows_in_steps and not self.follows_bounded,
            bounded=pruned and self.follows_bounded and self.dof == 7,
        )

    @property
    def branches(self) -> tuple[Branch, ...]:
        """``solution=0`` ... ``solution=K-1``: slots for the distinct solutions, in seed order."""
        return self._branches

    def _compiled(
        self, rotations: np.ndarray, positions: np.ndarray, progress: Progress | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The compiled seeding and following at rotations (P, W, 3, 3) and positions (P, W, 3).

        :meth:`seed_first` at the first waypoints, then :meth:`follow_ranges` in pieces of
        :data:`FOLLOW_WAYPOINTS` waypoints, ``progress`` called after each (the pieces give the
        same bits as one: each piece extrapolates from the solutions of the one before,
        ``ik.PREDICT_SMOOTH``).

        Returns:
            q (n, K, P, W), rad, wrapped, NaN in slots without a solution; status (K, P, W);
            count (P,), the distinct solutions found at the first waypoints.
        """
        rotations = np.asarray(rotations, dtype=float)
        positions = np.asarray(positions, dtype=float)
        current, count = self.seed_first(rotations[:, 0], positions[:, 0])
        if progress is not None:
            progress(SEED_SHARE)
        (n_paths, n_waypoints), n_seeds = positions.shape[:2], len(self.seeds)
        q = np.full((self.dof, n_seeds, n_paths, n_waypoints), np.nan)
        status = np.full((n_seeds, n_paths, n_waypoints), UNREACHABLE)
        for first in range(0, n_waypoints, FOLLOW_WAYPOINTS):
            last = min(first + FOLLOW_WAYPOINTS, n_waypoints)
            start, stop = (np.full((n_seeds, n_paths), value) for value in (first, last))
            self.follow_ranges(current, rotations, positions, start, stop, (q, status))
            if progress is not None:
                progress(SEED_SHARE + (1.0 - SEED_SHARE) * last / n_waypoints)
        return q, status, count

    def solve(self, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The distinct solutions found from the seeds at each pose (see KinematicsFamily.solve).

        Returns:
            q: shape (dof, K, *batch), NaN in the slots after the solutions found;
            status: shape (K, *batch).
        """
        batch = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
        rotation_flat = np.moveaxis(np.broadcast_to(rotation, (3, 3, *batch)), (0, 1), (-2, -1))
        position_flat = np.moveaxis(np.broadcast_to(position, (3, *batch)), 0, -1)
        rotation_flat, position_flat = rotation_flat.reshape(-1, 3, 3), position_flat.reshape(-1, 3)
        if self.compiled:  # a path of one waypoint: the seeding alone
            q_k, status_k, _ = self._compiled(rotation_flat[:, None], position_flat[:, None])
            q_shape = (self.dof, len(self.seeds), *batch)
            return q_k.reshape(q_shape), status_k.reshape(q_shape[1:])
        slots, _ = reference.seeded(
            self.chain,
            (self.seeds, self.more_seeds),
            (self.lower, self.upper),
            rotation_flat,
            position_flat,
        )
        q, status = reference.wrapped_with_status(self.chain, slots)  # (P, K, n), (P, K)
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
            progress: called after the seeding, after each piece of waypoints followed (each
                waypoint without the compiled chain), and after each chunk of CHUNK_ROWS
                solutions checked for singularity; it may raise
                :class:`solver.core.progress.Cancelled` to stop the work.
        """
        shape = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
        *batch, n_waypoints = shape
        rotations = np.moveaxis(np.broadcast_to(rotation, (3, 3, *shape)), (0, 1), (-2, -1))
        rotations = rotations.reshape(-1, n_waypoints, 3, 3)  # (P, W, 3, 3)
        positions = np.moveaxis(np.broadcast_to(position, (3, *shape)), 0, -1)
        positions = positions.reshape(-1, n_waypoints, 3)
        n_paths, n_seeds = len(positions), len(self.seeds)
        if self.compiled:
            q_k, status_k, count_k = self._compiled(rotations, positions, progress)
            return PathSolutions(
                q=q_k.reshape(self.dof, n_seeds, *batch, n_waypoints),
                status=status_k.reshape(n_seeds, *batch, n_waypoints),
                seeds=n_seeds,
                branches_found=count_k.reshape(batch),
            )
        slots, count = reference.seeded(
            self.chain,
            (self.seeds, self.more_seeds),
            (self.lower, self.upper),
            rotations[:, 0],
            positions[:, 0],
            span(progress, 0.0, SEED_SHARE),
        )
        q = np.full((n_paths, n_seeds, n_waypoints, self.dof), np.nan)
        q[:, :, 0] = slots
        paths, branches = np.nonzero(np.isfinite(slots[..., 0]))
        q[paths, branches] = reference.followed(
            self.chain,
            slots[paths, branches],
            rotations[paths],
            positions[paths],
            progress=span(progress, SEED_SHARE, FOLLOW_SHARE),
        )
        wrapped, status = reference.wrapped_with_status(
            self.chain, q, span(progress, FOLLOW_SHARE, 1.0)
        )
        return PathSolutions(
            q=wrapped.transpose(3, 1, 0, 2).reshape(self.dof, n_seeds, *batch, n_waypoints),
            status=np.moveaxis(status, 1, 0).reshape(n_seeds, *batch, n_waypoints),
            seeds=n_seeds,
            branches_found=count.reshape(batch),
        )

    def follow_from(
        self, start: np.ndarray, rotation: np.ndarray, position: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Each path followed from its start (see KinematicsFamily.follow_from).

        As :meth:`solve_path` follows a slot from its seeded solution.
        """
        if self.compiled:
            q, status = self.follow_piece(start[:, None].copy(), rotation, position, False)
            return q[:, 0], status[0]
        followed = reference.followed(self.chain, start, rotation, position)
        q, status = reference.wrapped_with_status(self.chain, followed)  # (M, W, n), (M, W)
        return np.moveaxis(q, -1, 0), status

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

        See :meth:`KinematicsFamily.joint_speeds_per_unit_twist` and
        :func:`velocity.joint_speeds_per_unit_twist`.
        """
        return velocity.joint_speeds_per_unit_twist(
            self._velocity_chain(), q, twist, tool_point, qdot_max=qdot_max, progress=progress
        )

    def null_space(
        self, q: np.ndarray, tool_point: np.ndarray, *, progress: Progress | None = None
    ) -> np.ndarray:
        """The last right singular vector of J at the tool point (:func:`velocity.null_space`)."""
        return velocity.null_space(self._velocity_chain(), q, tool_point, progress=progress)

    def _velocity_chain(self) -> velocity.VelocityChain:
        """The chain as :mod:`velocity` reads it."""
        return velocity.VelocityChain(self.chain, self._packed, self.compiled)
