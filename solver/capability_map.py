"""Capability map: mu_path over a grid of placements, computed as arrays (spec sections 6, 9).

Every cell is what :func:`solver.evaluate.evaluate_path` gives at that placement: the same task
requirements, analytic IK and branch tracking, with J^-1 t from the closed form of
:mod:`solver.ur_jacobian` instead of pinocchio and a 6x6 solve. What makes it fast:

- t_hat depends on the yaw only (u_T and u_R turn with it, h does not): computed once per path
  and turned per yaw;
- all placements of a chunk, all waypoints and all eight IK branches are one set of arrays,
  component-first with waypoints last;
- chunks of about 32 placements keep the arrays in cache (measured: 16-64 are alike here).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from solver.evaluate import DEFAULT_MAX_JOINT_STEP, check_max_joint_step, require_analytic_ik
from solver.exceptions import InvalidInputError
from solver.ik.ur_analytic import Branch, branch_index, solve_components
from solver.robots import Robot
from solver.spatial import Placement
from solver.task import task_requirements
from solver.tracking import FEASIBLE, REASONS, choose_branch, track
from solver.ur_jacobian import joint_speeds_per_unit_twist

__all__ = ["REASONS", "CapabilityMap", "axis_length", "capability_map", "grid_axis"]

DEFAULT_CHUNK = 32


@dataclass(frozen=True)
class CapabilityMap:
    """mu_path at every placement (x, y, yaw) of a grid at height z.

    Arrays are indexed [yaw, y, x].

    Attributes:
        xs: shape (nx,), m. ys: shape (ny,), m. yaws: shape (nyaw,), rad. z: m.
        mu_path: m/s, NaN where infeasible.
        reason: index into ``REASONS``, -1 where feasible.
        failed_waypoint: the first waypoint that fails, -1 where feasible.
        branch: index into ``solver.ik.ur_analytic.BRANCHES`` of the branch used.
        bottleneck_waypoint: where V_max is smallest, -1 where infeasible.
        bottleneck_joint: the joint on its limit there, -1 where infeasible.
    """

    xs: np.ndarray
    ys: np.ndarray
    yaws: np.ndarray
    z: float
    mu_path: np.ndarray
    reason: np.ndarray
    failed_waypoint: np.ndarray
    branch: np.ndarray
    bottleneck_waypoint: np.ndarray
    bottleneck_joint: np.ndarray

    def placement(self, index: tuple[int, int, int]) -> Placement:
        """The placement of cell [yaw, y, x]."""
        k, j, i = index
        return Placement(float(self.xs[i]), float(self.ys[j]), self.z, float(self.yaws[k]))

    def extreme(self, *, best: bool) -> tuple[int, int, int] | None:
        """Index [yaw, y, x] of the feasible cell with the highest (or lowest) mu_path.

        Ties go to the first cell in [yaw, y, x] order; ``None`` when no cell is feasible.
        """
        feasible = ~np.isnan(self.mu_path)
        if not feasible.any():
            return None
        values = np.where(feasible, self.mu_path, -np.inf if best else np.inf)
        flat = int(np.argmax(values) if best else np.argmin(values))
        k, j, i = np.unravel_index(flat, self.mu_path.shape)
        return int(k), int(j), int(i)


def axis_length(lower: float, upper: float, step: float, *, field: str) -> int:
    """How many values :func:`grid_axis` gives, without making them (to check a size first).

    Raises:
        InvalidInputError: values not finite, step <= 0 or upper < lower.
    """
    if not all(math.isfinite(v) for v in (lower, upper, step)):
        raise InvalidInputError(field, "min, max and step must be finite")
    if step <= 0 or upper < lower:
        raise InvalidInputError(
            field, f"needs step > 0 and max >= min, got {lower=}, {upper=}, {step=}"
        )
    count = (upper - lower) / step + 1e-9
    if count >= 2**53:
        raise InvalidInputError(field, f"{count:.3g} grid values: the step is too small")
    return math.floor(count) + 1


def grid_axis(lower: float, upper: float, step: float, *, field: str) -> np.ndarray:
    """Grid values lower, lower + step, ... up to upper.

    upper is included when it falls on the grid to within 1e-9 of a step.

    Raises:
        InvalidInputError: values not finite, step <= 0 or upper < lower.
    """
    count = axis_length(lower, upper, step, field=field)
    return lower + step * np.arange(count)


def _yaw_rotation(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def capability_map(
    robot: Robot,
    waypoints_in_workpiece: np.ndarray,
    *,
    xs: np.ndarray,
    ys: np.ndarray,
    z: float,
    yaws: np.ndarray,
    branch: Branch | None = None,
    max_joint_step: float = DEFAULT_MAX_JOINT_STEP,
    chunk: int = DEFAULT_CHUNK,
    progress: Callable[[float], None] | None = None,
) -> CapabilityMap:
    """mu_path over the grid xs x ys x yaws at height z (spec section 6).

    Args:
        robot: a UR arm of the catalogue, with its speed limits and TCP.
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i (metres).
        xs: shape (nx,), m, placement x values.
        ys: shape (ny,), m, placement y values.
        z: m, the height of every placement.
        yaws: shape (nyaw,), rad, placement yaw values.
        branch: the IK branch to follow everywhere; ``None`` is ``auto``.
        max_joint_step: rad, > 0.
        chunk: placements computed together.
        progress: called with the fraction done (0..1] after each chunk.

    Raises:
        NoAnalyticIkError, InvalidInputError, RepeatedWaypointError: as ``evaluate_path``.
    """
    dh = require_analytic_ik(robot)
    check_max_joint_step(max_joint_step)
    path = np.asarray(waypoints_in_workpiece, dtype=float)
    requirements = task_requirements(path)  # in {O}; turned per yaw below
    twist_o = requirements.twists()  # (W, 6)
    pure_rotation = requirements.h == 0.0
    tcp_inverse = np.linalg.inv(robot.transform_tool_to_tcp)
    flange_o = path @ tcp_inverse  # flange poses in {O}
    xs, ys, yaws = (np.asarray(v, dtype=float) for v in (xs, ys, yaws))
    grid_x, grid_y = np.meshgrid(xs, ys)  # [y, x]
    offsets = np.stack([grid_x.ravel(), grid_y.ravel(), np.full(grid_x.size, z)])  # (3, P)
    n_cells = offsets.shape[1]
    shape = (len(yaws), len(ys), len(xs))
    mu = np.full(shape, np.nan)
    reason = np.full(shape, FEASIBLE)
    failed = np.full(shape, -1)
    chosen = np.zeros(shape, dtype=int)
    bottleneck_waypoint = np.full(shape, -1)
    bottleneck_joint = np.full(shape, -1)
    branches = np.arange(8) if branch is None else np.array([branch_index(branch)])
    limits = robot.qdot_max.reshape(6, 1, 1, 1)
    done, total = 0, len(yaws) * n_cells
    for k, yaw in enumerate(yaws):
        turn = _yaw_rotation(float(yaw))
        rotation = np.einsum("ij,wjk->ikw", turn, flange_o[:, :3, :3])  # (3, 3, W)
        flange_position = turn @ flange_o[:, :3, 3].T  # (3, W)
        tool_position = turn @ path[:, :3, 3].T  # (3, W)
        twist = np.concatenate([turn @ twist_o[:, :3].T, turn @ twist_o[:, 3:].T])  # (6, W)
        for start in range(0, n_cells, chunk):
            cells = slice(start, min(start + chunk, n_cells))
            offset = offsets[:, cells, None]  # (3, C, 1)
            q, status = solve_components(
                dh, rotation[:, :, None, :], flange_position[:, None, :] + offset
            )  # (6, 8, C, W), (8, C, W)
            q, status = q[:, branches], status[branches]
            tracked = track(
                q, status, lower=robot.q_lower, upper=robot.q_upper, max_joint_step=max_joint_step
            )
            speeds = joint_speeds_per_unit_twist(
                dh, tracked.q, twist[:, None, None, :], tool_position[:, None, :] + offset
            )
            ratio = np.abs(speeds) / limits
            limiting = ratio.argmax(axis=0)  # (B, C, W)
            with np.errstate(divide="ignore", invalid="ignore"):  # infeasible branches
                v_max = np.where(pure_rotation, 0.0, 1.0 / ratio.max(axis=0))
            feasible = tracked.reason == FEASIBLE  # (B, C)
            mu_branch = np.where(feasible, v_max.min(axis=-1), -np.inf)
            pick = choose_branch(mu_branch, feasible, tracked.failed_waypoint)
            any_feasible = feasible.any(axis=0)
            columns = np.arange(pick.size)
            flat = np.unravel_index(np.arange(start, cells.stop), shape[1:])
            mu[k][flat] = np.where(any_feasible, mu_branch[pick, columns], np.nan)
            reason[k][flat] = tracked.reason[pick, columns]
            failed[k][flat] = tracked.failed_waypoint[pick, columns]
            chosen[k][flat] = branches[pick]
            worst_waypoint = v_max[pick, columns].argmin(axis=-1)
            bottleneck_waypoint[k][flat] = np.where(any_feasible, worst_waypoint, -1)
            bottleneck_joint[k][flat] = np.where(
                any_feasible, limiting[pick, columns, worst_waypoint], -1
            )
            done += cells.stop - cells.start
            if progress is not None:
                progress(done / total)
    return CapabilityMap(
        xs=xs,
        ys=ys,
        yaws=yaws,
        z=float(z),
        mu_path=mu,
        reason=reason,
        failed_waypoint=failed,
        branch=chosen,
        bottleneck_waypoint=bottleneck_waypoint,
        bottleneck_joint=bottleneck_joint,
    )
