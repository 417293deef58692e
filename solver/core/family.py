"""The kinematics-family seam: what a robot family provides to the rest of the solver.

Every route works for every robot; what differs between robots is how inverse kinematics is
solved and whether J^-1 t has a closed form (robots.md section 1). A family answers both,
batched and component-first; tracking, DTF, mu_path, maps and optimisers are written once on top
of this interface and never name a family. The families themselves (:mod:`solver.families`)
sit a layer above and implement it; a :class:`solver.core.robots.Robot` carries one. A family
that follows its branches waypoint by waypoint also implements the seam a map steers that
following through (:mod:`solver.core.follows_in_steps`).

Layout: rotations (3, 3, *batch), positions (3, *batch), joint arrays (dof, ...), solutions
(dof, n_branches, *batch); waypoints are usually the last batch axis.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.progress import Progress
from solver.core.spatial import BaseTurn, FlangeOffset


@dataclass(frozen=True)
class PathSolutions:
    """IK solutions along paths, branch by branch (what :meth:`KinematicsFamily.solve_path` gives).

    Attributes:
        q: shape (dof, n_branches, *batch, W), rad, NaN where a branch has no solution.
        status: shape (n_branches, *batch, W), ``OK``, ``UNREACHABLE`` or ``SINGULAR``; a
            six-joint numeric family's regular solutions are ``OK_MIRRORED`` where det J < 0
            (tracking: a change of that sign within a pass is a discontinuity).
        seeds: how many seeds a numeric family started from at the first waypoint; ``None``
            for an analytic family (it returns every branch).
        branches_found: shape batch, the distinct solutions found at the first waypoint of each
            path (numeric families); ``None`` for an analytic family.
        slots: shape (n_branches, *batch), the family's branch each row of ``q`` holds at each
            path, in the family's order (a pruned map's rows, :mod:`solver.path.pruning`);
            ``None``: row b is branch b everywhere.
        bound: shape (K, *batch), a six-joint pruned map's (:mod:`solver.path.bounded`): the
            least V_max followed of each of the family's branches; ``None`` otherwise.
        dropped: shape (K, *batch), bool, with ``bound``: the branches whose following was
            stopped (their rows unreachable); the caller checks that the pick stands.
        first: shape (*batch, K, dof), with ``bound``: the seeding's solutions at each path's
            first waypoint (``seed_first``, NaN in slots without one; ``branches_found`` its
            counts), so that a run of the same paths again need not seed them again.
    """

    q: np.ndarray
    status: np.ndarray
    seeds: int | None = None
    branches_found: np.ndarray | None = None
    slots: np.ndarray | None = None
    bound: np.ndarray | None = None
    dropped: np.ndarray | None = None
    first: np.ndarray | None = None


@dataclass(frozen=True)
class Branch:
    """An IK branch by name: one choice per level, e.g. shoulder=left, elbow=up, wrist=noflip.

    Attributes:
        choices: (level, choice) pairs in the family's level order.
    """

    choices: tuple[tuple[str, str], ...]

    @classmethod
    def named(cls, **choices: str) -> Branch:
        """A branch from keyword choices, e.g. ``Branch.named(shoulder="left", ...)``."""
        return cls(tuple(choices.items()))

    def as_dict(self) -> dict[str, str]:
        """The choices as ``{level: choice}``."""
        return dict(self.choices)

    def __str__(self) -> str:
        """``shoulder=left, elbow=up, wrist=noflip``."""
        return ", ".join(f"{level}={choice}" for level, choice in self.choices)


class KinematicsFamily(abc.ABC):
    """IK and J^-1 t of one kind of arm (UR, OPW, numeric), batched over poses.

    A family object belongs to one robot geometry (its parameters live in the object). The
    pinocchio model of the robot is the single source of forward kinematics and Jacobians; the
    family's closed forms are checked against it in tests.
    """

    #: Short name of the family, reported in answers (``"ur"``, ``"opw"``).
    name: str
    #: How the family was chosen, when not by the caller: a sentence for the answer (an OPW arm
    #: recognised in a URDF's chain, :mod:`solver.families.recognise`); ``None`` otherwise.
    recognised: str | None = None
    #: The frame the family solves in, where it is not {B}: a turn about {B}'s z and a shift
    #: (a URDF chain recognised from a base frame other than the arm's own), after a tilt where
    #: joint 1 is not upright in {B}. :meth:`solve` and :meth:`joint_speeds_per_unit_twist`
    #: still take {B}; a compiled map kernel, which places the path itself, takes its
    #: placements in that frame (:meth:`solver.core.spatial.BaseTurn.placements_in`), or, where
    #: it is tilted, the frame in its parameters (:meth:`map_kernel`). ``None``: {B}.
    base_turn: BaseTurn | None = None
    #: Where the chain's flange sits on the family's own, where they differ (a URDF whose tool
    #: frame is turned or moved on the last link): :meth:`solve` still takes the chain's flange;
    #: a compiled map kernel takes the family's (:meth:`FlangeOffset.family_flange_rows`).
    #: ``None``: the same frame.
    flange_offset: FlangeOffset | None = None

    @property
    @abc.abstractmethod
    def dof(self) -> int:
        """Number of joints."""

    @property
    @abc.abstractmethod
    def branches(self) -> tuple[Branch, ...]:
        """The branch labels, in the order of axis 1 of :meth:`solve` (ties go to the first)."""

    def branch_index(self, label: Branch) -> int:
        """Index of a named branch on axis 1 of :meth:`solve`.

        Raises:
            InvalidInputError: on ``ik.branch``, the label is not one of this family's; the
                message lists the valid names.
        """
        for index, known in enumerate(self.branches):
            if known.as_dict() == label.as_dict():
                return index
        valid = "; ".join(f"{{{b}}}" for b in self.branches)
        raise InvalidInputError(
            "ik.branch", f"{{{label}}} is not a branch of a {self.name} arm; valid: {valid}"
        )

    @abc.abstractmethod
    def solve(self, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All IK solutions of a batch of flange poses.

        Args:
            rotation: shape (3, 3, *batch), R_B_F of the flange (columns: its x, y, z axes);
                batch axes broadcast with those of ``position``.
            position: shape (3, *batch), flange positions in {B} (m).

        Returns:
            q: shape (dof, n_branches, *batch), rad in [-pi, pi] (copies 2 pi away are left to
            tracking), NaN where a branch has no solution;
            status: shape (n_branches, *batch), ``OK``, ``UNREACHABLE`` or ``SINGULAR`` (q is
            still filled where singular); ``OK_MIRRORED`` for a regular solution with det J < 0
            (six-joint numeric families only, see :data:`solver.core.codes.OK_MIRRORED`).
        """

    def path_cost(self, n_waypoints: int, *, free_spin: bool = False) -> float:
        """Estimated work of one placement of a path of ``n_waypoints`` (IK, tracking, DTF).

        ``free_spin``: with the tool spin free (a family whose free spin costs more says so).

        In poses of a closed-form family (all its branches and their DTF): the unit of the
        service's size limits (``DTF_MAX_MAP_POSES``), so that a request's cost is bounded
        before any work starts. A closed-form family costs one unit a waypoint, this default;
        a family that costs more overrides it with measured figures.
        """
        return float(n_waypoints)

    def map_cost(self, n_waypoints: int, *, free_spin: bool = False, pruned: bool = False) -> float:
        """The work of one placement of a map, in the unit of :meth:`path_cost`.

        ``pruned``: the map may drop branches that cannot be a cell's best
        (:func:`solver.path.pruning.can_prune`). The default is :meth:`path_cost`; a family
        whose map costs otherwise than an evaluation overrides it with measured figures.
        """
        return self.path_cost(n_waypoints, free_spin=free_spin)

    def map_kernel(self) -> tuple[int, np.ndarray] | None:
        """The compiled pose kernel's family code and parameters, or None where there is none.

        A family with a pose kernel in :mod:`solver.families.kernels` runs maps through the
        compiled pipeline (:mod:`solver.kernels.fixed_spin`, in free spin
        :mod:`solver.kernels.free_spin`); any other family through the numpy pipeline, which is
        the reference.
        """
        return None

    def solve_path(
        self, rotation: np.ndarray, position: np.ndarray, *, progress: Progress | None = None
    ) -> PathSolutions:
        """IK solutions along paths: waypoints on the last batch axis, branches followed.

        An analytic family solves every waypoint on its own (its branch labels mean the same
        thing everywhere), which is this default. A numeric family overrides it: it seeds the
        first waypoint and follows each solution it found from one waypoint to the next.

        Args:
            rotation: shape (3, 3, *batch, W), R_B_F of the flange, broadcasting with
                ``position``.
            position: shape (3, *batch, W), m in {B}.
            progress: called with the fraction done as the work goes (it may raise
                :class:`solver.core.progress.Cancelled` to stop it); a family whose solve
                takes milliseconds, as this default, need not call it.
        """
        q, status = self.solve(rotation, position)
        return PathSolutions(q=q, status=status)

    def follow_from(
        self, start: np.ndarray, rotation: np.ndarray, position: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Paths followed from given solutions at their first waypoints (a numeric family).

        A closed-form family solves any pose on its own (:meth:`solve`), its branches labelled
        alike everywhere; a family that follows says how it follows from a given start.

        Args:
            start: shape (M, n), rad, each path's solution at its first waypoint.
            rotation: shape (M, W, 3, 3), R_B_F of each path's flange.
            position: shape (M, W, 3), m in {B}.

        Returns:
            q (n, M, W), rad, wrapped, NaN from where a path is lost; status (M, W).
        """
        raise NotImplementedError(f"the {self.name} family solves each pose on its own")

    def null_space(
        self, q: np.ndarray, tool_point: np.ndarray, *, progress: Progress | None = None
    ) -> np.ndarray:
        """A unit vector spanning the null space of J(q), batched (seven-joint arms).

        The free spin of a seven-joint arm is a three-variable LP whose third variable moves
        the joints along it (:func:`solver.core.dtf_redundant.spin_speed`).

        Args:
            q: shape (dof, ...), rad.
            tool_point: shape (3, ...) broadcastable to q, m in {B}.
            progress: called with the fraction done as the work goes (it may raise
                :class:`solver.core.progress.Cancelled` to stop it).

        Returns:
            shape (dof, ...), NaN where q is not finite.

        Raises:
            NotImplementedError: the family has no null space (six joints).
        """
        raise NotImplementedError(f"a {self.name} arm of {self.dof} joints has no null space")

    @abc.abstractmethod
    def joint_speeds_per_unit_twist(
        self,
        q: np.ndarray,
        twist: np.ndarray,
        tool_point: np.ndarray,
        *,
        qdot_max: np.ndarray | None = None,
        progress: Progress | None = None,
    ) -> np.ndarray:
        """J(q)^-1 t, batched, with J the Jacobian at ``tool_point`` in {B} axes.

        For dof > 6, where J qdot = t has many solutions, the joint speeds of the exact DTF LP
        (robots.md section 5): qdot* / s* with s* the largest s such that J qdot = s t has a
        solution within ``qdot_max``; so 1 / max_j |qdot_j| / qdot_max_j is s*, as for dof 6.

        Args:
            q: shape (dof, ...), joint positions (rad), non-singular.
            twist: shape (6, ...) broadcastable to q, [v (m/s); omega (rad/s)] of the tool
                point, {B} axes.
            tool_point: shape (3, ...) broadcastable to q, the tool point in {B} (m).
            qdot_max: shape (dof,), rad/s, the joint speed limits; needed for dof > 6 only.
            progress: called with the fraction done as the work goes (it may raise
                :class:`solver.core.progress.Cancelled`); a closed form need not call it.

        Returns:
            shape (dof, ...), joint speeds (rad/s); inf or NaN at an exactly singular q.
        """
