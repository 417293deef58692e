"""mu_path at many placements at once, as arrays (the engine of the map and the optimisers).

Every placement gets what :func:`solver.evaluate.evaluate_path` gives there: the same task
requirements, analytic IK, branch tracking and branch choice, with J^-1 t from the closed form of
:mod:`solver.ur_jacobian` instead of pinocchio and a 6x6 solve. What makes it fast (spec
section 9): t_hat is computed once in {O} and only turned by each placement's yaw; all
placements of a chunk, all waypoints and all eight IK branches are one set of component-first
arrays with waypoints last; chunks of about 32 placements keep the arrays in cache.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from solver._malloc import raise_malloc_thresholds
from solver.evaluate import DEFAULT_MAX_JOINT_STEP, check_max_joint_step, require_analytic_ik
from solver.exceptions import InvalidInputError
from solver.ik.ur_analytic import Branch, branch_index, solve_components
from solver.robots import Robot
from solver.spatial import MAX_COORDINATE
from solver.task import task_requirements
from solver.tracking import FEASIBLE, choose_branch, track
from solver.ur_dh import UrDh
from solver.ur_jacobian import joint_speeds_per_unit_twist

DEFAULT_CHUNK = 32


@dataclass(frozen=True)
class PreparedPath:
    """A path checked and reduced to what every placement needs, all in {O}.

    Attributes:
        n_waypoints: N.
        flange_rotation: shape (N, 3, 3), R_O_F of the flange at each waypoint.
        flange_position: shape (N, 3), m.
        tool_position: shape (N, 3), m, the tool point.
        twist: shape (N, 6), t_hat in {O} axes.
        pure_rotation: shape (N,), where h = 0 (V_max is 0 there).
    """

    n_waypoints: int
    flange_rotation: np.ndarray
    flange_position: np.ndarray
    tool_position: np.ndarray
    twist: np.ndarray
    pure_rotation: np.ndarray


def prepare_path(robot: Robot, waypoints_in_workpiece: np.ndarray) -> PreparedPath:
    """Check a path and precompute its placement-independent data.

    Args:
        robot: the arm (its TCP offset turns tool poses into flange poses).
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i (metres).

    Raises:
        InvalidInputError, RepeatedWaypointError: as :func:`solver.task.task_requirements`.
    """
    path = np.asarray(waypoints_in_workpiece, dtype=float)
    requirements = task_requirements(path)  # u_T, u_R turn with the yaw, h does not
    flange = path @ np.linalg.inv(robot.transform_tool_to_tcp)
    return PreparedPath(
        n_waypoints=len(path),
        flange_rotation=flange[:, :3, :3],
        flange_position=flange[:, :3, 3],
        tool_position=path[:, :3, 3],
        twist=requirements.twists(),
        pure_rotation=requirements.h == 0.0,
    )


@dataclass(frozen=True)
class PlacementResults:
    """mu_path at P placements.

    Attributes:
        mu_path: shape (P,), m/s, NaN where infeasible.
        reason: shape (P,), index into ``solver.tracking.REASONS``, -1 where feasible.
        failed_waypoint: shape (P,), -1 where feasible.
        branch: shape (P,), index into ``BRANCHES`` of the branch used.
        bottleneck_waypoint: shape (P,), -1 where infeasible.
        bottleneck_joint: shape (P,), -1 where infeasible.
        v_max: shape (P, N), m/s, V_max at every waypoint on the branch used (NaN where
            infeasible); only when asked for.
    """

    mu_path: np.ndarray
    reason: np.ndarray
    failed_waypoint: np.ndarray
    branch: np.ndarray
    bottleneck_waypoint: np.ndarray
    bottleneck_joint: np.ndarray
    v_max: np.ndarray | None = None


def check_placements(placements: np.ndarray) -> np.ndarray:
    """Placements as a float array (P, 4) of finite [x, y, z, yaw] within MAX_COORDINATE.

    Raises:
        InvalidInputError: wrong shape, not finite, or too far.
    """
    arr = np.asarray(placements, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise InvalidInputError("placements", f"{arr.shape=}, needs (P, 4): x, y, z, yaw")
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr[:, :3]) > MAX_COORDINATE):
        raise InvalidInputError(
            "placements", f"need finite values, positions within {MAX_COORDINATE} m"
        )
    return arr


def _chunk(
    dh: UrDh,
    robot: Robot,
    path: PreparedPath,
    placements: np.ndarray,
    branches: np.ndarray,
    max_joint_step: float,
) -> tuple[np.ndarray, ...]:
    """Evaluate C placements: per placement mu, reason, failed, branch, bottleneck, V_max."""
    yaws = placements[:, 3]
    if np.all(yaws == yaws[0]):  # one turn for the chunk: broadcast it (less memory to read)
        yaws = yaws[:1]
    cos = np.cos(yaws)[:, None]  # (C or 1, 1): the turn Rz(yaw)
    sin = np.sin(yaws)[:, None]

    def turned(vectors: np.ndarray) -> np.ndarray:
        """Rz(yaw) v for v of shape (3, ..., W) in {O}: shape (3, ..., C, W), C-contiguous."""
        x, y = vectors[0][..., None, :], vectors[1][..., None, :]
        z = np.broadcast_to(vectors[2][..., None, :], np.broadcast_shapes(x.shape, cos.shape))
        return np.stack([cos * x - sin * y, sin * x + cos * y, z])

    offset = placements[:, :3].T[:, :, None]  # (3, C, 1)
    rotation = turned(path.flange_rotation.transpose(1, 2, 0))  # (3, 3, C, W)
    flange_position = turned(path.flange_position.T) + offset
    tool_position = turned(path.tool_position.T) + offset
    twist = np.concatenate([turned(path.twist[:, :3].T), turned(path.twist[:, 3:].T)])
    q, status = solve_components(dh, rotation, flange_position)  # (6, 8, C, W), (8, C, W)
    q, status = q[:, branches], status[branches]
    tracked = track(
        q, status, lower=robot.q_lower, upper=robot.q_upper, max_joint_step=max_joint_step
    )
    speeds = joint_speeds_per_unit_twist(dh, tracked.q, twist[:, None], tool_position[:, None])
    ratio = np.abs(speeds) / robot.qdot_max.reshape(6, 1, 1, 1)
    limiting = ratio.argmax(axis=0)  # (B, C, W)
    with np.errstate(divide="ignore", invalid="ignore"):  # infeasible branches
        v_max = np.where(path.pure_rotation, 0.0, 1.0 / ratio.max(axis=0))
    feasible = tracked.reason == FEASIBLE  # (B, C)
    mu_branch = np.where(feasible, v_max.min(axis=-1), -np.inf)
    pick = choose_branch(mu_branch, feasible, tracked.failed_waypoint)
    any_feasible = feasible.any(axis=0)
    columns = np.arange(pick.size)
    chosen_v = np.where(any_feasible[:, None], v_max[pick, columns], np.nan)  # (C, W)
    worst = np.nan_to_num(chosen_v, nan=np.inf).argmin(axis=-1)
    return (
        np.where(any_feasible, mu_branch[pick, columns], np.nan),
        tracked.reason[pick, columns],
        tracked.failed_waypoint[pick, columns],
        branches[pick],
        np.where(any_feasible, worst, -1),
        np.where(any_feasible, limiting[pick, columns, worst], -1),
        chosen_v,
    )


def evaluate_placements(
    robot: Robot,
    path: PreparedPath,
    placements: np.ndarray,
    *,
    branch: Branch | None = None,
    max_joint_step: float = DEFAULT_MAX_JOINT_STEP,
    with_speeds: bool = False,
    chunk: int = DEFAULT_CHUNK,
    progress: Callable[[float], None] | None = None,
) -> PlacementResults:
    """mu_path of a path at each of P placements.

    Args:
        robot: a UR arm of the catalogue, with its speed limits and TCP.
        path: from :func:`prepare_path` for the same robot.
        placements: shape (P, 4), [x (m), y (m), z (m), yaw (rad)] of {O} in {B}.
        branch: the IK branch to follow everywhere; ``None`` is ``auto``.
        max_joint_step: rad, > 0.
        with_speeds: also return V_max at every waypoint.
        chunk: placements computed together.
        progress: called with the fraction done (0..1] after each chunk.

    Raises:
        NoAnalyticIkError, InvalidInputError: as :func:`solver.evaluate.evaluate_path`.
    """
    dh = require_analytic_ik(robot)
    check_max_joint_step(max_joint_step)
    cells = check_placements(placements)
    raise_malloc_thresholds()
    branches = np.arange(8) if branch is None else np.array([branch_index(branch)])
    # Chunks of consecutive placements, cut where the yaw changes (a grid's yaw-major order
    # gives chunks of one yaw each, which are cheaper).
    cuts = np.flatnonzero(np.diff(cells[:, 3])) + 1
    parts = []
    for run in np.split(np.arange(len(cells)), cuts):
        for start in range(0, len(run), chunk):
            rows = run[start : start + chunk]
            parts.append(_chunk(dh, robot, path, cells[rows], branches, max_joint_step))
            if progress is not None:
                progress((rows[-1] + 1) / len(cells))
    empty = (np.zeros(0), *(np.zeros(0, dtype=int),) * 5, np.zeros((0, path.n_waypoints)))
    columns = [np.concatenate(c) for c in zip(*parts, strict=True)] if parts else list(empty)
    mu, reason, failed, chosen, bottleneck_waypoint, bottleneck_joint, v_max = columns
    return PlacementResults(
        mu_path=mu,
        reason=reason,
        failed_waypoint=failed,
        branch=chosen,
        bottleneck_waypoint=bottleneck_waypoint,
        bottleneck_joint=bottleneck_joint,
        v_max=v_max if with_speeds else None,
    )
