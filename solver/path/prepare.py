"""A path checked and reduced to what every placement needs (dtf.md section 9).

The task requirements are computed once in {O}, per pass (cam.md section 5); every placement
then only turns them by its yaw (:mod:`solver.path.pipeline`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.robots import Robot
from solver.core.task import TaskRequirements, task_requirements


@dataclass(frozen=True)
class PreparedPath:
    """A path checked and reduced to what every placement needs, all in {O}.

    Attributes:
        n_waypoints: N.
        tool_rotation: shape (N, 3, 3), R_O_i of the tool point.
        tool_to_flange: shape (4, 4), T_TCP_F = T_F_TCP^-1.
        flange_rotation: shape (N, 3, 3), R_O_F of the flange at each waypoint (spin 0).
        flange_position: shape (N, 3), m (spin 0).
        tool_position: shape (N, 3), m, the tool point.
        u_T: shape (N, 3). u_R: shape (N, 3). h: shape (N,), m, inf for pure translation.
        twist: shape (N, 6), t_hat in {O} axes.
        pure_rotation: shape (N,), where h = 0 (V_max is 0 there).
        segment_in_pass: shape (N - 1,), whether segment i (waypoint i to i + 1) lies within a
            pass; False where a rapid joins two passes (cam.md section 5): no feed requirement
            and no joint step bound there, and free spins restart at the next pass.
    """

    n_waypoints: int
    tool_rotation: np.ndarray
    tool_to_flange: np.ndarray
    flange_rotation: np.ndarray
    flange_position: np.ndarray
    tool_position: np.ndarray
    u_T: np.ndarray
    u_R: np.ndarray
    h: np.ndarray
    twist: np.ndarray
    pure_rotation: np.ndarray
    segment_in_pass: np.ndarray


def check_passes(
    passes: Sequence[tuple[int, int]] | None, n_waypoints: int
) -> list[tuple[int, int]]:
    """The passes as index ranges [start, stop) covering 0..N in order, each of 2 points or more.

    Raises:
        InvalidInputError: on ``path.passes``, ranges that do not tile the waypoints.
    """
    if passes is None:
        return [(0, n_waypoints)]
    ranges = [(int(start), int(stop)) for start, stop in passes]
    starts = [start for start, _ in ranges]
    stops = [stop for _, stop in ranges]
    if not ranges or starts[0] != 0 or stops[-1] != n_waypoints or starts[1:] != stops[:-1]:
        raise InvalidInputError(
            "path.passes", f"{ranges} must cover the {n_waypoints} waypoints in order"
        )
    short = [k for k, (start, stop) in enumerate(ranges) if stop - start < 2]
    if short:
        raise InvalidInputError("path.passes", f"pass {short[0]} has fewer than 2 waypoints")
    return ranges


def path_requirements(
    waypoints: np.ndarray,
    passes: Sequence[tuple[int, int]] | None = None,
    *,
    field: str = "path.waypoints",
    free_spin: bool = False,
) -> TaskRequirements:
    """The task requirements of a path of passes, each pass's own; the path checked.

    Args:
        waypoints: shape (N, 4, 4), T_O_i (metres).
        passes: as :func:`prepare_path`'s.
        field: the request's field the path came in (``path.cl_data`` for a CL program):
            errors name it, and the waypoint in the whole path.
        free_spin: as :func:`solver.core.task.task_requirements` takes it.

    Raises:
        InvalidInputError, RepeatedWaypointError: as :func:`solver.core.task.task_requirements`,
            or passes that do not cover the path.
    """
    path = np.asarray(waypoints, dtype=float)
    parts = [
        task_requirements(path[start:stop], field=field, first=start, free_spin=free_spin)
        for start, stop in check_passes(passes, len(path))
    ]
    return TaskRequirements(  # u_T, u_R turn with the yaw, h does not
        u_T=np.concatenate([part.u_T for part in parts]),
        u_R=np.concatenate([part.u_R for part in parts]),
        h=np.concatenate([part.h for part in parts]),
    )


def prepare_path(
    robot: Robot,
    waypoints_in_workpiece: np.ndarray,
    *,
    passes: Sequence[tuple[int, int]] | None = None,
    field: str = "path.waypoints",
    free_spin: bool = False,
) -> PreparedPath:
    """Check a path and precompute its placement-independent data.

    Args:
        robot: the arm (its TCP offset turns tool poses into flange poses).
        waypoints_in_workpiece: shape (N, 4, 4), T_O_i (metres).
        passes: index ranges [start, stop) of the passes (cam.md section 5), in order and
            covering every waypoint; None: one pass. The requirements are taken per pass.
        field: the request's field the path came in, which errors name.
        free_spin: the path runs in free spin (a turn about the tool axis alone is no motion:
            :func:`solver.core.task.task_requirements`).

    Raises:
        InvalidInputError, RepeatedWaypointError: as :func:`path_requirements`.
    """
    path = np.asarray(waypoints_in_workpiece, dtype=float)
    ranges = check_passes(passes, len(path))
    requirements = path_requirements(path, ranges, field=field, free_spin=free_spin)
    segment_in_pass = np.ones(max(len(path) - 1, 0), dtype=bool)
    segment_in_pass[[start - 1 for start, _ in ranges[1:]]] = False
    tool_to_flange = np.linalg.inv(robot.transform_tool_to_tcp)
    flange = path @ tool_to_flange
    return PreparedPath(
        n_waypoints=len(path),
        tool_rotation=path[:, :3, :3],
        tool_to_flange=tool_to_flange,
        flange_rotation=flange[:, :3, :3],
        flange_position=flange[:, :3, 3],
        tool_position=path[:, :3, 3],
        u_T=requirements.u_T,
        u_R=requirements.u_R,
        h=requirements.h,
        twist=requirements.twists(),
        pure_rotation=requirements.h == 0.0,
        segment_in_pass=segment_in_pass,
    )
