"""One problem object: a robot, a path and the options of its evaluation, checked once.

A request becomes a frozen :class:`PathProblem` (qpsolvers' ``Problem``): the robot, the tool
path in {O} with its passes, and :class:`PathOptions` (the branch policy, the joint step bound,
the spin mode; later options are fields here too). Every solver entry point takes the problem,
not loose settings: :func:`solver.path.evaluate.evaluate_path`,
:func:`solver.path.placements.evaluate_placements`,
:func:`solver.path.capability_map.capability_map`,
:func:`solver.optimise.optimize.optimize_placement`. The limits on the path index are the
problem's too (:mod:`solver.path.limits`), so the pipeline loops over them and never names one.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from solver.core.exceptions import InvalidInputError, NoAnalyticIkError, quoted
from solver.core.family import Branch, KinematicsFamily
from solver.core.kinematics import straight_spindle
from solver.core.robots import Robot
from solver.path.blend_stencil import BlendStencil
from solver.path.cell.cache import checker_for
from solver.path.cell.limit import CellLimit
from solver.path.cell.shapes import Cell
from solver.path.limits import JointAccelerationLimit, JointSpeedLimit, Limit, PathCheck
from solver.path.prepare import PreparedPath, prepare_path

DEFAULT_MAX_JOINT_STEP = 0.35
DEFAULT_BLEND_LENGTH = 0.002  # m, the corner zone of motion.md section 1 (ABB z1, UR 1 mm)
BLEND_LENGTHS = (1e-6, 1.0)
"""m, the blend lengths taken: a controller's corner zone (ABB's largest, z200, is 0.4 m across)
above CAM's rounding (1e-4 mm). Below 1e-100 s +- b rounded to s and mu_acc jumped back to
mu_path (78,000 times 1e-12's); at 1000 m the blended path was no longer the pass's."""
EXACT_SPIN_COST = 12.0
"""A placement's work in free spin with the spun poses solved again (:attr:`PathProblem.exact_spin`,
on the numpy pipeline, solver.path.exact_spin.ROUNDS rounds, a closed-form family's spun poses
by the compiled :mod:`solver.kernels.spun_rows`) against the closed-form unit (about 2 us a
pose: DTF_MAX_MAP_POSES' 5 million, about 10 s). Measured 23-24 us a pose (CPU time): the UR5
with a tcp tilted 0.5 rad and 3 cm off its axis, the ERK map (546 placements, 133 waypoints,
four rounds), 1.7 s, 2026-12-05, the machine loaded (the numpy arithmetic's spun poses, in the
same run: 57-59 us a pose, the weight was 30; the kernel's map without the rounds: 0.022 s)."""
NUMERIC_EXACT_SPIN_COST = 5.0
"""The same for a numeric family, whose figure already weighs its following: the rounds' spun
paths followed again from their first solutions. Maps of 55 placements on the ERK path, CPU
time, loaded machine, 2026-12-05: the Panda 4.4 s against 0.97 s, the xArm7 6.3 against 1.35,
the Jaco2 0.34 against 0.09 (before solving the spun poses)."""

SpinMode = Literal["fixed", "free"]
SPIN_MODES: tuple[SpinMode, ...] = ("fixed", "free")


@dataclass(frozen=True)
class PathOptions:
    """How a path is evaluated (dtf.md section 4, cam.md section 2).

    Attributes:
        branch: the IK branch to follow; ``None`` is ``auto``, the feasible branch with the
            highest mu_path.
        max_joint_step: rad, > 0, the largest move of any joint between neighbouring
            waypoints of one pass.
        spin_mode: ``fixed`` (the orientations as given) or ``free`` (the tool spin rate a free
            variable of the DTF).
        blend_length: m, within BLEND_LENGTHS, the length b over which a controller rounds a
            corner (motion.md section 1); used only with joint acceleration limits.
        cell: the robot's surroundings and tool (cell.md); None checks no collisions.
    """

    branch: Branch | None = None
    max_joint_step: float = DEFAULT_MAX_JOINT_STEP
    spin_mode: SpinMode = "fixed"
    blend_length: float = DEFAULT_BLEND_LENGTH
    cell: Cell | None = None

    def check(self, robot: Robot) -> np.ndarray:
        """Check the options against ``robot``; the branches to follow (all for ``auto``).

        Raises:
            InvalidInputError: a bad spin mode, step or branch name; NoAnalyticIkError: the
                robot has no kinematics family.
        """
        check_spin_mode(robot, self.spin_mode)
        family = require_family(robot)
        self.check_step()
        if self.branch is None:
            return np.arange(len(family.branches))
        return np.array([family.branch_index(self.branch)])

    def check_step(self) -> None:
        """Raise InvalidInputError on ``ik.max_joint_step`` unless it is finite and > 0 (rad).

        And on ``ik.blend_length`` unless it is within BLEND_LENGTHS (m).
        """
        if not (math.isfinite(self.max_joint_step) and self.max_joint_step > 0.0):
            raise InvalidInputError(
                "ik.max_joint_step", f"{self.max_joint_step:.6g} rad must be > 0"
            )
        low, high = BLEND_LENGTHS
        if not low <= self.blend_length <= high:  # NaN too
            raise InvalidInputError(
                "ik.blend_length",
                f"{self.blend_length:.6g} m is outside [{low:g}, {high:g}] m (a controller's "
                "corner zone: ABB z1 is 2 mm across)",
            )


@dataclass(frozen=True, eq=False)
class PathProblem:
    """A robot, a tool path and the options of its evaluation.

    The path's placement-independent data (:attr:`prepared`) and the options' check
    (:attr:`branches`) are made once, on first use, in the order the evaluation needs them (a
    request with several faults reports the same one as before).

    Attributes:
        robot: an arm with a kinematics family, with its speed limits and TCP.
        waypoints: shape (N, 4, 4), T_O_i, tool point poses in {O} (m).
        options: how the path is evaluated.
        passes: index ranges [start, stop) of the passes of a CAM program (cam.md section 5);
            None: one pass.
        source: the request's field the path came in (``path.cl_data`` for a CL program),
            which the path's errors name, with the waypoint in the whole path.
    """

    robot: Robot
    waypoints: np.ndarray
    options: PathOptions = field(default_factory=PathOptions)
    passes: tuple[tuple[int, int], ...] | None = None
    source: str = "path.waypoints"

    def __post_init__(self) -> None:
        """Hold the waypoints as a float array and the passes as a tuple."""
        object.__setattr__(self, "waypoints", np.asarray(self.waypoints, dtype=float))
        if self.passes is not None:
            passes = tuple((int(start), int(stop)) for start, stop in self.passes)
            object.__setattr__(self, "passes", passes)

    @classmethod
    def of(
        cls,
        robot: Robot,
        waypoints: np.ndarray,
        options: PathOptions | None = None,
        *,
        passes: Sequence[tuple[int, int]] | None = None,
        source: str = "path.waypoints",
    ) -> PathProblem:
        """The problem of ``robot`` along ``waypoints`` (default options)."""
        passes_tuple = None if passes is None else tuple(passes)
        return cls(robot, waypoints, options or PathOptions(), passes_tuple, source)

    @property
    def family(self) -> KinematicsFamily:
        """The robot's kinematics family; NoAnalyticIkError when it has none."""
        return require_family(self.robot)

    @functools.cached_property
    def branches(self) -> np.ndarray:
        """The options checked: indices of the family's branches to follow (all for auto)."""
        return self.options.check(self.robot)

    @functools.cached_property
    def prepared(self) -> PreparedPath:
        """The path checked and reduced to what every placement needs (in {O}).

        In free spin a segment that only turns about the tool axis is a repeated waypoint
        (:func:`solver.core.task.task_requirements`).
        """
        free_spin = self.options.spin_mode == "free"
        return prepare_path(
            self.robot, self.waypoints, passes=self.passes, field=self.source, free_spin=free_spin
        )

    @functools.cached_property
    def limits(self) -> tuple[Limit, ...]:
        """The limits on the path index: the joint speed limits (the DTF) first.

        Then, where the robot has acceleration limits, :class:`JointAccelerationLimit` on the
        path's blend stencil (made here, once per problem and blend length).
        """
        limits: list[Limit] = [JointSpeedLimit(self.robot.qdot_max)]
        if self.robot.qddot_max is not None:
            path = self.prepared
            stencil = BlendStencil.of_path(
                path.tool_position, path.segment_in_pass, self.options.blend_length
            )
            limits.append(JointAccelerationLimit(self.robot.qddot_max, stencil))
        return tuple(limits)

    @functools.cached_property
    def path_checks(self) -> tuple[PathCheck, ...]:
        """The limits that admit or refuse whole joint paths: the cell's, where one is given.

        Raises:
            InvalidInputError: a bad cell field (checked here, once per problem).
        """
        cell = self.options.cell
        if cell is None:
            return ()
        checker = checker_for(self.robot, cell)
        return (CellLimit(checker, self.prepared.segment_in_pass),)

    @property
    def keeps_base_turn(self) -> bool:
        """Whether every limit and path check is the same at a placement turned about base z.

        Each limit says so (:attr:`solver.path.limits.Limit.keeps_base_turn`); the path checks
        are the cell's (:attr:`path_checks`), which keeps it where its fixed objects turn into
        themselves (:meth:`solver.path.cell.shapes.Cell.turns_into_itself`), told from the cell
        without building its checker. A check added to :attr:`path_checks` says here whether
        it keeps the turn.
        """
        cell = self.options.cell
        limits_keep = all(limit.keeps_base_turn for limit in self.limits)
        return limits_keep and (cell is None or cell.turns_into_itself())

    @functools.cached_property
    def exact_spin(self) -> bool:
        """Whether free spin's joint paths are solved again at the spun poses.

        Free spin, unless six joints turn a straight spindle
        (:func:`solver.core.kinematics.straight_spindle`), where only the last joint moves and
        the schedule's joint paths are exact: an angled or offset spindle, or seven joints
        (whose spin moves every joint): :mod:`solver.path.exact_spin`, on the numpy pipeline,
        whose work :attr:`exact_spin_weight` weighs.
        """
        if self.options.spin_mode != "free":  # the spindle read only where it matters
            return False
        return not (self.robot.dof == 6 and straight_spindle(self.robot))

    def path_cost(self, n_waypoints: int) -> float:
        """The work of one placement of ``n_waypoints``, in poses of a closed-form family's map.

        The family's cost (:meth:`KinematicsFamily.path_cost`; times :attr:`exact_spin_weight`
        where the spun poses are solved again, :attr:`exact_spin`), plus each limit's
        (:meth:`limits_cost`) and each path check's (:meth:`checks_cost`): what the size limits
        of the maps and searches weigh.
        """
        cost = self.family.path_cost(n_waypoints, free_spin=self.options.spin_mode == "free")
        cost *= self.exact_spin_weight
        return cost + self.limits_cost(n_waypoints) + self.checks_cost(n_waypoints)

    def limits_cost(self, n_waypoints: int) -> float:
        """The limits' work along ``n_waypoints`` beyond the family's figure, in closed-form poses.

        Each limit's weight a pose (:meth:`solver.path.limits.Limit.pose_cost`: none for the
        joint speeds, whose DTF the figure is; the joint accelerations' grows with the blend's
        span in waypoints).
        """
        return n_waypoints * sum(limit.pose_cost() for limit in self.limits)

    def checks_cost(self, n_waypoints: int) -> float:
        """The path checks' work along ``n_waypoints``, in closed-form poses.

        Each check's weight a pose (:meth:`solver.path.limits.PathCheck.pose_cost`; the cell's
        grows with its collision step and its pairs), added to the family's figure whatever the
        family: a check looks at the joint paths the family found, not at how it found them.
        """
        return n_waypoints * sum(check.pose_cost() for check in self.path_checks)

    @property
    def exact_spin_weight(self) -> float:
        """The work of :attr:`exact_spin` against the family's figure (1 without it)."""
        if not self.exact_spin:
            return 1.0
        return EXACT_SPIN_COST if self.family.map_kernel() is not None else NUMERIC_EXACT_SPIN_COST

    @property
    def waypoint_limits(self) -> tuple[Limit, ...]:
        """The limits that bound V_max at each waypoint (their least bound's minimum: mu_path)."""
        return tuple(limit for limit in self.limits if not limit.on_final_path)

    @property
    def final_path_limits(self) -> tuple[Limit, ...]:
        """The limits on a constant feed along the final joint path (mu_acc); () for none."""
        return tuple(limit for limit in self.limits if limit.on_final_path)

    def without_path_checks(self) -> PathProblem:
        """The same problem with no path checks: the kinematics and the limits alone.

        What a search scores a refused placement by (how fast the arm would be there). Every
        path check is left out, not only the cell's: ``with_options(cell=None)``, as the
        searches wrote it, kept any other check (and, on a problem without a cell, shared its
        checks as they were).
        """
        clear = self.with_options(cell=None)
        clear.__dict__["path_checks"] = ()  # the cached property, as with_options shares it
        return clear

    def with_options(self, **changes: object) -> PathProblem:
        """The same robot and path with some options changed (e.g. ``branch=...``).

        The prepared path is shared, and so are the limits unless the blend length changed.
        """
        options = dataclasses.replace(self.options, **changes)  # type: ignore[arg-type]
        other = dataclasses.replace(self, options=options)
        shared = ["prepared"]
        if options.blend_length == self.options.blend_length:
            shared.append("limits")
        if options.cell is self.options.cell:
            shared.append("path_checks")
        for name in shared:
            if name in self.__dict__:
                other.__dict__[name] = self.__dict__[name]
        return other

    def with_waypoints(self, waypoints: np.ndarray) -> PathProblem:
        """The same robot, passes and options along other waypoints (e.g. spun ones)."""
        return dataclasses.replace(self, waypoints=waypoints)


def check_spin_mode(robot: Robot, spin_mode: str) -> None:
    """Raise InvalidInputError on ``spin_mode``: unknown, or free with no last joint to spin.

    A free tool spin needs the last joint to turn the tool, so ``free`` on an arm whose last
    joint is prismatic is refused.
    """
    if spin_mode not in SPIN_MODES:
        raise InvalidInputError(
            "spin_mode", f"unknown spin mode {quoted(str(spin_mode))}; use fixed or free"
        )
    last = robot.model.joints[robot.model.njoints - 1].shortname()
    prismatic = "Prismatic" in last or last.startswith("JointModelP")
    if spin_mode == "free" and prismatic:
        raise InvalidInputError(
            "spin_mode",
            f"free spin needs a revolute last joint; {robot.joint_names[-1]!r} is prismatic",
        )
    if spin_mode == "free" and robot.dof not in (6, 7):
        raise InvalidInputError(
            "spin_mode",
            f"free spin is solved for six- and seven-joint arms; {robot.shown_name!r} has "
            f"{robot.dof} joints",
        )


def require_family(robot: Robot) -> KinematicsFamily:
    """The robot's kinematics family; NoAnalyticIkError when it has none."""
    if robot.family is None:
        raise NoAnalyticIkError(
            "robot",
            f"path evaluation needs an arm with an IK family (UR, OPW, or numeric for a serial "
            f"chain of six joints or more); {robot.shown_name!r} has none",
        )
    return robot.family
