"""Any serial arm as a kinematics family: numeric IK from fixed seeds, J^-1 t by a batched solve.

robots.md section 4. At the first waypoint of a path the IK starts from a fixed set of seeds
covering the joint box (a fractional factorial design at each joint's quartiles,
:func:`solver.families.numeric.ik.seeds`; K = 32 for six joints, 64 for seven or more; a seed
whose error stops shrinking is given up, ``ik.STALL_STEPS``), keeps every distinct solution
within the joint limits as a branch, labelled by its index in seed order, and
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
from solver.core.follows_in_steps import FollowsInSteps
from solver.core.progress import Progress, span
from solver.core.spatial import wrap_angle
from solver.families.numeric import (
    bounded_kernel,
    chain_kernel,
    ik,
    ik_kernel,
    redundant_kernel,
)
from solver.families.numeric.chain import SerialChain

# Work of one placement in poses of a closed-form family (KinematicsFamily.path_cost), measured
# with the compiled chain (ik_kernel) on the 2-core development machine against the analytic
# UR5 map of the same run (ERK grid, 546 placements, 133 waypoints; CPU time, the machine
# loaded, 2026-12-02, after seeds were given up on a stall, ik.STALL_STEPS): seeding the first
# waypoint (K seeds) and following each branch found to each next waypoint, the whole map's
# time per placement and per waypoint, from maps of 2 and 133 waypoints. Each size has the
# lines (seeding, following per waypoint) of its measured arms, about 25 % above the
# measurement, and a path costs the highest. Six joints: UR5 as a URDF 618 and 38.7, the Jaco2
# 742 and 13.0; placements out of reach (z 5 m) seed for less now (596 and 504: their seeds
# stall early). Seven: the Panda 2,021 and 125, the xArm7 1,388 and 177 (the following line
# kept at the 200 measured before, which the free spin's weight was measured against).
# Maps share these lines with evaluations, which follow every branch: a six-joint map pruned
# in one pass (solver/path/bounded.py) costs about a quarter of its line (UR5 as a URDF, ERK
# map, 2026-12-02), so its estimate is an upper bound; the lines are not lowered for it.
COST_LINES: dict[int, tuple[tuple[float, float], ...]] = {
    6: ((800.0, 48.0), (1_000.0, 17.0)),
    7: ((2_600.0, 200.0),),
}
FREE_SPIN_REDUNDANT_COST = 3.0
"""A seven-joint path's work in free spin against the fixed spin's cost line (the vertex LPs of
:mod:`solver.kernels.spin_lp`, the QR's null space). Evaluations, CPU time, best of 2, loaded
machine, 2026-12-02, same run: the Panda along 2,000 waypoints free 0.246 s against fixed
0.120 s (2.05 times), 20,000: 2.75 s against 1.28 s (2.15); the xArm7 2.29 and 1.87 times.
Maps (ERK path, 99 placements; a free-spin map is not pruned): the Panda's free map 3.0 times
its pruned fixed map, the xArm7's 2.5 times, about 2 times the unpruned line this weighs.
(Before the LPs were compiled: 50, measured 35-57 times.)"""
NUMPY_CHAIN_COST = 35.0
"""The numpy chain's work against the compiled one's (a chain with mimic joints runs on numpy):
the UR5 as a URDF, ERK path (133 waypoints), CPU time, loaded machine, 2026-12-02, same run:
an evaluation 0.164 s against 0.005 s (33 times), a 30-placement map 0.93 s against 0.10 s."""
NUMPY_MAP_COST = 12.0
"""The numpy chain's map against the compiled chain's line: measured 9.3 times (the UR5 as a
URDF, 30 placements of the ERK path, the run of NUMPY_CHAIN_COST)."""
FIRST_PIECE = 32
"""Waypoints every branch of a pruned map is followed before any is dropped (the pruning's
``solver.path.pruning.PIECE``, held equal by a test)."""
MAP_TAIL_SHARE = 0.5
"""A pruned map's work after the first piece against following every branch (the seven-joint
line). Measured: the CPU time of the following and the bounds past the first piece, pruned
against unpruned, 99 placements, ERK path (133 waypoints) and 600 (the ERK path there and back),
loaded machine, 2026-12-02, same run: Panda 0.19 and 0.11, xArm7 0.38 and 0.29 (the whole map
0.46 / 0.18 and 0.60 / 0.34 of the unpruned one). In counts (tests/solver/families/
test_numeric_map_work.py), the branch-waypoints followed past the first piece: 0.09 to 0.16."""
CHUNK_ROWS = 2048
"""Configurations checked (singularity, joint speeds) between two progress reports: about
0.2 s for seven joints under load, so that a cancelled evaluation stops within a second."""
FOLLOW_WAYPOINTS = 256
"""Waypoints of each path followed by the compiled chain between two progress reports (a
seven-joint arm's slots: about 0.2 s)."""
SEED_SHARE, FOLLOW_SHARE = 0.05, 0.9
"""Where seeding the first waypoint ends, and following the branches, in a path's solve's
progress (the rest: the singularity checks)."""


def seed_count(dof: int) -> int:
    """K, the number of seeds: 32 for up to six joints, 64 beyond (robots.md section 4)."""
    return 32 if dof <= 6 else 64


class NumericFamily(KinematicsFamily, FollowsInSteps):
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
            compiled: solve with the compiled chain (:mod:`solver.families.numeric.ik_kernel`);
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

    def path_cost(self, n_waypoints: int, *, free_spin: bool = False) -> float:
        """Seeding plus following, in closed-form poses: the highest line of COST_LINES.

        In free spin an arm of more than six joints also solves the three-variable LP at every
        configuration (:func:`solver.kernels.spin_lp.spin_speeds`): times
        :data:`FREE_SPIN_REDUNDANT_COST`.

        Arms of more than seven joints scale the seven-joint figures by (dof / 7)^2 (the
        Jacobian products and solves grow about so); the numpy chain (mimic joints) costs
        :data:`NUMPY_CHAIN_COST` times the compiled one.
        """
        size = min(max(self.dof, 6), 7)
        scale = max(self.dof / 7, 1.0) ** 2
        following = max(n_waypoints - 1, 0)
        cost = scale * max(seed + following * track for seed, track in COST_LINES[size])
        cost = cost if self.compiled else cost * NUMPY_CHAIN_COST
        return cost * FREE_SPIN_REDUNDANT_COST if free_spin and self.dof > 6 else cost

    def map_cost(self, n_waypoints: int, *, free_spin: bool = False, pruned: bool = False) -> float:
        """A map's placement (see the base), in the unit of :meth:`path_cost`.

        A pruned map (compiled, seven joints, fixed spin) follows every branch for FIRST_PIECE
        waypoints, then about MAP_TAIL_SHARE of them; the numpy chain weighs NUMPY_MAP_COST.
        """
        if not self.compiled:
            return self.path_cost(n_waypoints, free_spin=free_spin) * (
                NUMPY_MAP_COST / NUMPY_CHAIN_COST
            )
        if free_spin or not (pruned and self.follows_in_steps):
            return self.path_cost(n_waypoints, free_spin=free_spin)
        following = max(n_waypoints - 1, 0)
        tail = max(following - FIRST_PIECE, 0)
        followed = following - tail + MAP_TAIL_SHARE * tail
        scale = max(self.dof / 7, 1.0) ** 2
        return scale * max(seed + followed * track for seed, track in COST_LINES[7])

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
            stall=(ik.STALL_STEPS, ik.STALL_RATIO),
            progress=progress,
        )
        q = q.reshape(n_poses, n_seeds, self.dof)
        return ik.distinct(q, converged.reshape(n_poses, n_seeds), self.chain.q_revolute)

    def _settings(self) -> tuple[np.ndarray, np.ndarray]:
        """The compiled IK's settings and constants (:func:`ik_kernel.seed_paths`)."""
        settings = np.array(
            [
                ik.SEED_ITERATIONS,
                ik.TRACK_ITERATIONS,
                ik.DISTINCT,
                ik.SINGULAR_RCOND,
                ik.STALL_STEPS,
                ik.STALL_RATIO,
            ],
            dtype=float,
        )
        return settings, np.array([ik.TOLERANCE, ik.DAMPING_SCALE, ik.DAMPING_FLOOR])

    @property
    def follows_in_steps(self) -> bool:
        """The compiled chain of more than six joints; the numpy reference only whole paths.

        Six joints are pruned in one compiled pass instead (:attr:`follows_bounded`); in
        steps, a pruned map of the UR5 URDF took 1.05 times the
        unpruned one, of an IRB 2400 URDF 1.8 times (143 placements of the ERK path, same run,
        loaded machine, 2026-12-02): their few branches are cheap to follow (a UR's four
        shoulder branches tie and are all followed anyway), and the bounds cost more than the
        following they save. Seven joints, pruned against unpruned (CPU time, best of 3, same
        run): the Panda's ERK map 1.76 times faster, the xArm7 1.69, the LBR iiwa 14 1.25.
        """
        return self.compiled and self.dof > 6

    def seed_first(
        self, rotations: np.ndarray, positions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`ik_kernel.seed_paths` (see :meth:`FollowsInSteps.seed_first`)."""
        settings, constants = self._settings()
        current, count = ik_kernel.seed_paths(
            self._packed,
            self.seeds,
            (self.lower, self.upper),
            np.ascontiguousarray(rotations, dtype=float),
            np.ascontiguousarray(positions, dtype=float),
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
        """:func:`ik_kernel.follow_paths` (see :meth:`FollowsInSteps.follow_piece`)."""
        settings, constants = self._settings()
        q, status = ik_kernel.follow_paths(
            self._packed,
            current,
            np.ascontiguousarray(rotations, dtype=float),
            np.ascontiguousarray(positions, dtype=float),
            solve_first,
            settings,
            constants,
        )
        return q, status

    @property
    def follows_bounded(self) -> bool:
        """The compiled chain of six joints (:mod:`solver.path.bounded`)."""
        return self.compiled and self.dof == 6

    def follow_bounded(
        self,
        current: np.ndarray,
        poses: tuple[np.ndarray, np.ndarray],
        speeds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float],
        rules: tuple[float, ...],
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:func:`bounded_kernel.follow_bounded` (see :meth:`FollowsInSteps.follow_bounded`)."""
        settings, constants = self._settings()
        result: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] = (
            bounded_kernel.follow_bounded(
                self._packed,
                current,
                *(np.ascontiguousarray(a, dtype=float) for a in (*poses, *speeds[:3])),
                np.asarray(speeds[3], dtype=np.bool_),
                (self.lower, self.upper, np.array([speeds[4]], dtype=float)),
                settings,
                constants,
                np.array(rules, dtype=float),
            )
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
        """:func:`ik_kernel.follow_ranges` (see :meth:`FollowsInSteps.follow_ranges`)."""
        settings, constants = self._settings()
        ik_kernel.follow_ranges(
            self._packed,
            current,
            rotations,
            positions,
            np.ascontiguousarray(start, dtype=np.int64),
            np.ascontiguousarray(stop, dtype=np.int64),
            out,
            settings,
            constants,
        )

    def _compiled(
        self, rotations: np.ndarray, positions: np.ndarray, progress: Progress | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The compiled seeding and following at rotations (P, W, 3, 3) and positions (P, W, 3).

        :meth:`seed_first` at the first waypoints, then :meth:`follow_piece` in pieces of
        :data:`FOLLOW_WAYPOINTS` waypoints, ``progress`` called after each (the pieces give the
        same bits as one).

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
        q = np.empty((self.dof, n_seeds, n_paths, n_waypoints))
        status = np.empty((n_seeds, n_paths, n_waypoints), dtype=np.int64)
        for first in range(0, n_waypoints, FOLLOW_WAYPOINTS):
            piece = slice(first, min(first + FOLLOW_WAYPOINTS, n_waypoints))
            q[..., piece], status[..., piece] = self.follow_piece(
                current, rotations[:, piece], positions[:, piece], first > 0
            )
            if progress is not None:
                progress(SEED_SHARE + (1.0 - SEED_SHARE) * piece.stop / n_waypoints)
        return q, status, count

    def _wrapped_with_status(
        self, q: np.ndarray, progress: Progress | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Revolute joints wrapped to [-pi, pi) and the status of each solution, q (..., n)."""
        flat = q.reshape(-1, self.dof)
        status = np.full(len(flat), UNREACHABLE)
        solved = np.flatnonzero(np.isfinite(flat).all(axis=-1))
        for rows in _in_chunks(solved, progress):
            status[rows] = np.where(ik.is_singular(self.chain, flat[rows]), SINGULAR, OK)
        wrapped = np.where(self.chain.q_revolute, wrap_angle(q), q)
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
        rotation_flat, position_flat = rotation_flat.reshape(-1, 3, 3), position_flat.reshape(-1, 3)
        if self.compiled:  # a path of one waypoint: the seeding alone
            q_k, status_k, _ = self._compiled(rotation_flat[:, None], position_flat[:, None])
            q_shape = (self.dof, len(self.seeds), *batch)
            return q_k.reshape(q_shape), status_k.reshape(q_shape[1:])
        slots, _ = self._seeded(rotation_flat, position_flat)
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
        finite joints are computed; the others come back NaN. With ``progress``, CHUNK_ROWS
        configurations at a time, ``progress`` called after each (the same numbers).

        For dof > 6 without ``qdot_max``, the least-norm J^+ t (the free spin's direction).
        """
        shape = np.broadcast_shapes(q.shape[1:], twist.shape[1:], tool_point.shape[1:])
        q_flat = np.moveaxis(np.broadcast_to(q, (self.dof, *shape)), 0, -1).reshape(-1, self.dof)
        twist_flat = np.moveaxis(np.broadcast_to(twist, (6, *shape)), 0, -1).reshape(-1, 6)
        point_flat = np.moveaxis(np.broadcast_to(tool_point, (3, *shape)), 0, -1).reshape(-1, 3)
        if progress is None:
            speeds = self._speeds(q_flat, twist_flat, point_flat, qdot_max)
        else:  # the finite rows in chunks: each row's speeds as alone
            speeds = np.full(q_flat.shape, np.nan)
            finite = np.flatnonzero(np.isfinite(q_flat).all(axis=-1))
            for rows in _in_chunks(finite, progress):
                speeds[rows] = self._speeds(
                    q_flat[rows], twist_flat[rows], point_flat[rows], qdot_max
                )
        return np.moveaxis(speeds.reshape(*shape, self.dof), -1, 0)

    def _speeds(
        self,
        q_flat: np.ndarray,
        twist_flat: np.ndarray,
        point_flat: np.ndarray,
        qdot_max: np.ndarray | None,
    ) -> np.ndarray:
        """Joint speeds per unit twist at M configurations: (M, n), (M, 6), (M, 3) -> (M, n)."""
        speeds = np.full(q_flat.shape, np.nan)
        rows = np.flatnonzero(np.isfinite(q_flat).all(axis=-1))
        if self.compiled and self.dof == 6:
            six: np.ndarray = chain_kernel.speeds_per_twist(
                self._packed, *(np.ascontiguousarray(a) for a in (q_flat, twist_flat, point_flat))
            )
            return six
        if self.compiled and self.dof == 7 and qdot_max is not None:
            speeds, irregular = redundant_kernel.redundant_speeds(
                self._packed,
                *(np.ascontiguousarray(a) for a in (q_flat, twist_flat, point_flat)),
                np.asarray(qdot_max, dtype=float),
            )
            rows = np.flatnonzero(irregular)  # J near rank loss: numpy's SVD or the LP decides
        elif self.compiled and self.dof == 7:  # the free spin's least-norm direction
            speeds, _, irregular = redundant_kernel.least_norm_and_null(
                self._packed,
                *(np.ascontiguousarray(a) for a in (q_flat, twist_flat, point_flat)),
            )
            rows = np.flatnonzero(irregular)
        if self.compiled:
            jacobian = chain_kernel.jacobians(
                self._packed,
                np.ascontiguousarray(q_flat[rows]),
                np.ascontiguousarray(point_flat[rows]),
            )
        else:
            jacobian, _, _ = self.chain.jacobian(q_flat[rows], point_flat[rows])
        if self.dof == 6:
            speeds[rows] = _solve_or_nan(jacobian, twist_flat[rows])
        elif self.dof > 6 and qdot_max is not None:
            speed, qdot = redundant_speed(jacobian, twist_flat[rows], qdot_max)
            with np.errstate(divide="ignore", invalid="ignore"):
                speeds[rows] = qdot / speed[:, None]
        else:  # fewer than six joints: least squares; more, without limits: the least norm
            speeds[rows] = (np.linalg.pinv(jacobian) @ twist_flat[rows, :, None])[..., 0]
        return speeds

    def null_space(
        self, q: np.ndarray, tool_point: np.ndarray, *, progress: Progress | None = None
    ) -> np.ndarray:
        """The last right singular vector of J at the tool point (see the base), batched.

        Seven joints on the compiled chain: the QR's (:mod:`redundant_kernel`; its sign may
        differ from the SVD's, which no LP answer depends on), the SVD's where J nears rank
        loss. CHUNK_ROWS configurations at a time, ``progress`` called after each.
        """
        shape = np.broadcast_shapes(q.shape[1:], tool_point.shape[1:])
        q_flat = np.moveaxis(np.broadcast_to(q, (self.dof, *shape)), 0, -1).reshape(-1, self.dof)
        point_flat = np.moveaxis(np.broadcast_to(tool_point, (3, *shape)), 0, -1).reshape(-1, 3)
        null = np.full(q_flat.shape, np.nan)
        for rows in _in_chunks(np.flatnonzero(np.isfinite(q_flat).all(axis=-1)), progress):
            if self.compiled and self.dof == 7:
                _, null[rows], irregular = redundant_kernel.least_norm_and_null(
                    self._packed,
                    np.ascontiguousarray(q_flat[rows]),
                    np.zeros((len(rows), 6)),
                    np.ascontiguousarray(point_flat[rows]),
                )
                rows = rows[irregular]
            jacobian, _, _ = self.chain.jacobian(q_flat[rows], point_flat[rows])
            null[rows] = np.linalg.svd(jacobian)[2][:, -1]
        return np.moveaxis(null.reshape(*shape, self.dof), -1, 0)


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
