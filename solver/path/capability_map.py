"""Capability map: mu_path over a grid of placements (spec section 6).

Every cell is what :func:`solver.path.evaluate.evaluate_path` gives at that placement, computed for
all cells at once by :mod:`solver.path.placements`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from solver.core.codes import REASONS
from solver.core.exceptions import InvalidInputError
from solver.core.parallel import SERIAL, TaskRunner
from solver.core.spatial import Placement
from solver.core.written import stepped_as_written
from solver.path.cell.verdict import Unchecked
from solver.path.path_checks import checks_model
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem
from solver.path.pruning import can_prune

__all__ = [
    "REASONS",
    "CapabilityMap",
    "axis_length",
    "capability_map",
    "grid_axis",
    "map_cost",
]


@dataclass(frozen=True)
class CapabilityMap:
    """mu_path at every placement (x, y, yaw) and tool spin of a grid at height z.

    Arrays are indexed [spin, yaw, y, x].

    Attributes:
        xs: shape (nx,), m. ys: shape (ny,), m. yaws: shape (nyaw,), rad. z: m.
        spins: shape (nspin,), rad, the constant tool spins (cam.md section 3).
        mu_path: m/s, NaN where infeasible.
        reason: index into ``REASONS``, -1 where feasible.
        failed_waypoint: the first waypoint that fails, -1 where feasible.
        branch: index into the robot family's ``branches`` of the branch used.
        bottleneck_waypoint: where V_max is smallest, -1 where infeasible.
        bottleneck_joint: the joint on its limit there, -1 where infeasible.
        mu_acc: m/s, the acceleration-limited index (motion.md section 2), NaN where
            infeasible; None without acceleration limits. The map's colour when given.
        limited_by: what binds mu_acc: 0 speed, 1 acceleration, -1 where infeasible (None
            likewise); acc_waypoint, acc_joint: where, and which joint (-1 where infeasible).
        cell_approximated: with a cell, the robot's links given capsules; else None.
        cell_unchecked: with a cell, the robot parts not checked against a ``fixed`` object
            (no joint moves them relative to it), with their distance; else None.
    """

    xs: np.ndarray
    ys: np.ndarray
    yaws: np.ndarray
    z: float
    spins: np.ndarray
    mu_path: np.ndarray
    reason: np.ndarray
    failed_waypoint: np.ndarray
    branch: np.ndarray
    bottleneck_waypoint: np.ndarray
    bottleneck_joint: np.ndarray
    mu_acc: np.ndarray | None = None
    limited_by: np.ndarray | None = None
    acc_waypoint: np.ndarray | None = None
    acc_joint: np.ndarray | None = None
    cell_approximated: tuple[str, ...] | None = None
    cell_unchecked: tuple[Unchecked, ...] | None = None

    @property
    def feed_index(self) -> np.ndarray:
        """mu_acc where acceleration limits are given, else mu_path (the map's colour)."""
        return self.mu_path if self.mu_acc is None else self.mu_acc

    def placement(self, index: tuple[int, ...]) -> Placement:
        """The placement of cell [spin, yaw, y, x]."""
        s, k, j, i = index
        return Placement(
            float(self.xs[i]),
            float(self.ys[j]),
            self.z,
            float(self.yaws[k]),
            spin=float(self.spins[s]),
        )

    def extreme(self, *, best: bool) -> tuple[int, ...] | None:
        """Index [spin, yaw, y, x] of the feasible cell with the highest (or lowest) index.

        The index is :attr:`feed_index`: mu_acc with acceleration limits, else mu_path.

        Ties go to the first cell in [spin, yaw, y, x] order; ``None`` when none is feasible.
        """
        feasible = ~np.isnan(self.mu_path)
        if not feasible.any():
            return None
        values = np.where(feasible, self.feed_index, -np.inf if best else np.inf)
        flat = int(np.argmax(values) if best else np.argmin(values))
        return tuple(int(v) for v in np.unravel_index(flat, self.mu_path.shape))


def axis_length(lower: float, upper: float, step: float, *, field: str) -> int:
    """How many values :func:`grid_axis` gives, without making them (to check a size first).

    Raises:
        InvalidInputError: values not finite, step <= 0 or upper < lower.
    """
    if not all(math.isfinite(v) for v in (lower, upper, step)):
        raise InvalidInputError(field, "min, max and step must be finite")
    if step <= 0 or upper < lower:
        raise InvalidInputError(
            field, f"needs step > 0 and max >= min; got min {lower}, max {upper}, step {step}"
        )
    count = (upper - lower) / step + 1e-9
    if count >= 2**53:
        raise InvalidInputError(field, f"{count:.3g} grid values: the step is too small")
    return math.floor(count) + 1


def grid_axis(lower: float, upper: float, step: float, *, field: str) -> np.ndarray:
    """Grid values lower, lower + step, ... up to upper.

    upper is included when it falls on the grid to within 1e-9 of a step. Each value is the
    float nearest lower + i step taken in the decimals the two are written in
    (:func:`solver.core.written.stepped_as_written`): -0.25 + 15 x 0.02 is 0.05, where the
    floats' own sum is 0.04999999999999999.

    Raises:
        InvalidInputError: values not finite, step <= 0 or upper < lower.
    """
    return stepped_as_written(lower, step, axis_length(lower, upper, step, field=field))


def capability_map(
    problem: PathProblem,
    *,
    xs: np.ndarray,
    ys: np.ndarray,
    z: float,
    yaws: np.ndarray,
    spins: np.ndarray | None = None,
    chunk: int | None = None,
    progress: Callable[[float], None] | None = None,
    runner: TaskRunner = SERIAL,
    compiled: bool = True,
) -> CapabilityMap:
    """mu_path over the grid spins x yaws x ys x xs at height z (spec section 6).

    The placements are evaluated in :func:`serpentine` order (each row of x after its
    neighbour), each answer put back on its own cell: the same answers as any order, less work.

    Args:
        problem: the robot (with a kinematics family), the path with its passes and the
            options (the branch followed everywhere, the step bound, the spin mode).
        xs: shape (nx,), m, placement x values.
        ys: shape (ny,), m, placement y values.
        z: m, the height of every placement.
        yaws: shape (nyaw,), rad, placement yaw values.
        spins: shape (nspin,), rad, constant tool spins (cam.md section 3); default [0].
        chunk: placements computed together; None: as
            :func:`solver.path.placements.chunk_of` decides.
        progress: called with the fraction done (0..1] as the work goes; it may raise
            :class:`solver.core.progress.Cancelled` to stop it.
        runner: where the placements' tasks run (:mod:`solver.core.parallel`); same answer on any.
        compiled: the compiled kernel where there is one; False: the numpy pipeline (the
            reference, :func:`solver.path.placements.evaluate_placements`).

    Raises:
        NoAnalyticIkError, InvalidInputError, RepeatedWaypointError: as ``evaluate_path``.
    """
    _ = problem.prepared  # the path is checked before the options
    spins = np.zeros(1) if spins is None else spins
    xs, ys, yaws, spins = (np.asarray(v, dtype=float) for v in (xs, ys, yaws, spins))
    shape = (len(spins), len(yaws), len(ys), len(xs))
    grid_spin, grid_yaw, grid_y, grid_x = np.meshgrid(spins, yaws, ys, xs, indexing="ij")
    placements = np.stack(
        [
            grid_x.ravel(),
            grid_y.ravel(),
            np.full(grid_x.size, float(z)),
            grid_yaw.ravel(),
            grid_spin.ravel(),
        ],
        axis=1,
    )
    order = serpentine(len(placements) // len(xs), len(xs))
    result = evaluate_placements(
        problem,
        placements[order],
        chunk=chunk,
        progress=progress,
        runner=runner,
        compiled=compiled,
    ).taken(order)
    optional: dict[str, Any] = {  # acceleration limits' columns; the path checks' models
        **{
            name: None if value is None else value.reshape(shape)
            for name, value in (
                ("mu_acc", result.mu_acc),
                ("limited_by", result.limited_by),
                ("acc_waypoint", result.acc_waypoint),
                ("acc_joint", result.acc_joint),
            )
        },
        **checks_model(problem),
    }
    return CapabilityMap(
        xs=xs,
        ys=ys,
        yaws=yaws,
        z=float(z),
        spins=spins,
        mu_path=result.mu_path.reshape(shape),
        reason=result.reason.reshape(shape),
        failed_waypoint=result.failed_waypoint.reshape(shape),
        branch=result.branch.reshape(shape),
        bottleneck_waypoint=result.bottleneck_waypoint.reshape(shape),
        bottleneck_joint=result.bottleneck_joint.reshape(shape),
        **optional,
    )


def serpentine(n_rows: int, n_columns: int) -> np.ndarray:
    """The cells of an (n_rows, n_columns) grid row by row, every other row backwards.

    Consecutive placements are then neighbours: the kernels follow the branch the previous
    placement chose first, which a row's first cell in C order (after the previous row's last,
    across the grid) does not share as often. Its own inverse.
    """
    index = np.arange(n_rows * n_columns).reshape(n_rows, n_columns)
    index[1::2] = index[1::2, ::-1]
    return index.ravel()


def map_cost(problem: PathProblem) -> float:
    """The work of one placement of ``problem``'s map, in closed-form poses (the size limits').

    The family's map figure (:meth:`solver.core.family.KinematicsFamily.map_cost`), told
    whether the map may drop branches (:func:`solver.path.pruning.can_prune`), times
    :attr:`PathProblem.exact_spin_weight` in free spin with an angled or offset spindle or seven
    joints (:attr:`PathProblem.exact_spin`), plus the limits' (joint accelerations:
    :meth:`PathProblem.limits_cost`) and the path checks' (a cell's collision check:
    :meth:`PathProblem.checks_cost`). A map with a path check is given the figure of following
    every branch: it drops branches too, but follows a refused placement's next branches again
    (:mod:`solver.path.path_checks`).
    """
    n_waypoints = problem.prepared.n_waypoints
    free_spin = problem.options.spin_mode == "free"
    pruned = not problem.path_checks and can_prune(problem)
    cost = problem.family.map_cost(n_waypoints, free_spin=free_spin, pruned=pruned)
    cost *= problem.exact_spin_weight  # the spun poses solved again, on the numpy pipeline
    return cost + problem.limits_cost(n_waypoints) + problem.checks_cost(n_waypoints)
