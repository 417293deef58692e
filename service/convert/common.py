"""Conversions shared by every resource: robots, paths, placements, branches, h."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import BaseModel

from service import schemas
from service.config import Settings, get_settings
from service.schemas.path_input import PathInput
from solver.cam.frames import frames_of_placement
from solver.core.exceptions import InvalidInputError
from solver.core.family import Branch
from solver.core.robots import Robot
from solver.core.spatial import (
    Placement,
    spun_waypoints,
)
from solver.core.urdf_structure import collision_count, joint_count
from solver.path.cell.shapes import Cell
from solver.path.cell.verdict import Unchecked
from solver.path.problem import PathOptions, PathProblem, SpinMode


def robot_from_schema(spec: schemas.Robot, *, max_urdf_joints: int | None = None) -> Robot:
    """The solver robot a request names, with its speed limits and tool point.

    Args:
        spec: the request's robot.
        max_urdf_joints: most joints a URDF may have; ``None`` reads DTF_MAX_URDF_JOINTS.

    Raises:
        InvalidInputError: an OPW geometry, its limits or the speed limits are out of range;
            on ``robot.urdf``, a URDF of more joints than the limit (counted before parsing).
        RobotModelError: the URDF or its frames do not fit.
    """
    if isinstance(spec, schemas.UrdfRobot):
        limit = get_settings().max_urdf_joints if max_urdf_joints is None else max_urdf_joints
        count = joint_count(spec.urdf)
        if count > limit:
            raise InvalidInputError(
                "robot.urdf",
                f"the URDF has {count} joints, more than DTF_MAX_URDF_JOINTS = {limit}",
            )
    return spec.to_solver()


def path_of(path: schemas.Path) -> PathInput:
    """The poses of a path in {O}, from whichever form the request used.

    Raises:
        InvalidInputError, RepeatedWaypointError: naming the field and the waypoint.
    """
    return path.to_solver()


def request_correction(path: PathInput, *parts: BaseModel | None) -> float:
    """The answer's ``axis_correction``: the path's and :func:`quaternion_correction`'s, the larger.

    ``parts``: the request's robot and cell.
    """
    return max(path.axis_correction, quaternion_correction(*parts))


def quaternion_correction(*parts: BaseModel | None) -> float:
    """The largest |norm - 1| of the quaternions of every Pose in ``parts`` (0 for none).

    A Pose's quaternion within 1e-3 of unit is normalised (api.md, Pose) and the answer says
    by how much: the path's own are in its ``axis_correction``; these are the robot's TCP and
    the cell's object poses (``parts``: the request's robot and cell), which went unsaid.
    """
    largest, stack = 0.0, [part for part in parts if part is not None]
    while stack:
        item = stack.pop()
        if isinstance(item, schemas.Pose):
            largest = max(largest, abs(math.hypot(*item.orientation) - 1.0))
        elif isinstance(item, BaseModel):
            stack.extend(getattr(item, name) for name in type(item).model_fields)
        elif isinstance(item, list | tuple):
            stack.extend(item)
    return largest


def spun_poses(path: PathInput, spins: list[float] | None) -> np.ndarray:
    """The path's poses, each turned by its spin about its tool z axis when spins are given.

    Raises:
        InvalidInputError: on ``spins``, a count that is not the number of waypoints.
    """
    if spins is None:
        return path.poses
    if len(spins) != len(path.poses):
        raise InvalidInputError(
            "spins", f"{len(spins)} spins for {len(path.poses)} waypoints: one per waypoint"
        )
    return spun_waypoints(path.poses, np.array(spins, dtype=float))


def joint_path_of(rows: list[list[float]], robot: Robot) -> np.ndarray:
    """A joint path (N, n), rad, from the request's rows.

    Raises:
        InvalidInputError: on ``joint_path`` and the waypoint, a row without one value a joint.
    """
    for i, row in enumerate(rows):
        if len(row) != robot.dof:
            raise InvalidInputError(
                "joint_path",
                f"{len(row)} values but {robot.shown_name!r} has {robot.dof} joints",
                waypoint=i,
            )
    return np.array(rows, dtype=float)


def check_path_size(path: schemas.Path, *, limit: int, setting: str) -> None:
    """Refuse a path with more waypoints than a setting allows, before any work.

    Raises:
        InvalidInputError: on ``path``, saying the size asked for and the limit.
    """
    if path.n_waypoints() > limit:
        raise InvalidInputError(
            "path", f"{path.n_waypoints()} waypoints; the limit is {limit} ({setting})"
        )


def spin_mode_of(requested: SpinMode | None, path: PathInput) -> SpinMode:
    """The spin mode asked for, or the path form's default."""
    return path.default_spin_mode if requested is None else requested


def problem_of(
    robot: Robot,
    poses: np.ndarray,
    path: PathInput,
    *,
    ik: schemas.IkPolicy | schemas.AutoIkPolicy,
    spin_mode: SpinMode,
    cell: Cell | None = None,
) -> PathProblem:
    """The solver's problem: the robot along ``poses``, with the request's IK and spin mode.

    Args:
        robot: the request's robot.
        poses: shape (N, 4, 4), the path's poses in {O} (or those spun by a request's spins).
        path: the path as read (its passes).
        ik: the request's IK policy (branch, max_joint_step, blend_length).
        spin_mode: the spin mode (:func:`spin_mode_of`).
        cell: the request's cell (:func:`cell_of`), or None.
    """
    options = PathOptions(
        branch=branch_of(ik.branch),
        max_joint_step=ik.max_joint_step,
        spin_mode=spin_mode,
        blend_length=ik.blend_length,
        cell=cell,
    )
    return PathProblem.of(robot, poses, options, passes=path.passes, source=path.source)


def cell_of(cell: schemas.CellSpec | None, settings: Settings, robot: Robot) -> Cell | None:
    """The solver's cell of a request, bounded by the settings; None without one.

    The robot checked against it may have at most DTF_MAX_CELL_OBJECTS collision elements as
    well: each pair of them not on neighbouring links is checked, and a 186 KB URDF of 1,800
    small boxes took minutes and 8 GB (the hostile-input audit).

    Raises:
        InvalidInputError: too many objects (DTF_MAX_CELL_OBJECTS), a mesh over
            DTF_MAX_MESH_TRIANGLES or not an STL, naming the field; on ``robot.urdf``, more
            collision elements than DTF_MAX_CELL_OBJECTS.
    """
    if cell is None:
        return None
    solver_cell = cell.to_solver(
        max_objects=settings.max_cell_objects, max_triangles=settings.max_mesh_triangles
    )
    parts = collision_count(robot.urdf) if robot.urdf is not None else 0
    if parts > settings.max_cell_objects:
        raise InvalidInputError(
            "robot.urdf",
            f"{parts} collision elements; a robot checked against a cell may have at most "
            f"{settings.max_cell_objects} (DTF_MAX_CELL_OBJECTS): every two of them are "
            "checked against each other",
        )
    return solver_cell


def placement_of(placement: schemas.Placement) -> Placement:
    """The solver's placement (m, rad)."""
    return Placement(
        x=placement.x, y=placement.y, z=placement.z, yaw=placement.yaw, spin=placement.spin
    )


def branch_of(choice: schemas.Branch | schemas.NumericBranch | str) -> Branch | None:
    """The solver's branch label; ``None`` for ``"auto"``."""
    if isinstance(choice, str):
        return None
    if isinstance(choice, schemas.NumericBranch):
        return Branch.named(solution=str(choice.solution))
    return Branch.named(shoulder=choice.shoulder, elbow=choice.elbow, wrist=choice.wrist)


def branch_to_api(branch: Branch | None) -> schemas.Branch | schemas.NumericBranch | None:
    """The API's branch: named levels, or the numeric family's solution index."""
    if branch is None:
        return None
    choices = branch.as_dict()
    if set(choices) == {"solution"}:
        return schemas.NumericBranch(solution=int(choices["solution"]))
    return schemas.Branch.model_validate(choices)


def h_of(h: float | None) -> float:
    """The solver's h (m): ``math.inf`` for the API's ``null`` (pure translation)."""
    return math.inf if h is None else h


def h_to_api(h: float) -> float | None:
    """The API's h (m): ``None`` for ``math.inf`` (pure translation)."""
    return None if math.isinf(h) else float(h)


def api_placement(placement: Placement) -> schemas.PlacementResult:
    """The API's placement (m, rad) of a solver placement, with its controller frames."""
    frames = frames_of_placement(placement)
    return schemas.PlacementResult(
        x=placement.x,
        y=placement.y,
        z=placement.z,
        yaw=placement.yaw,
        spin=placement.spin,
        frames=schemas.ControllerFrames(
            matrix=frames.matrix, ur=frames.ur, kuka=frames.kuka, abb=frames.abb, fanuc=frames.fanuc
        ),
    )


def _accept_weights(accept: str) -> dict[str, float]:
    """Media range -> q-value of an Accept header (RFC 9110 section 12.5.1; q defaults to 1)."""
    weights: dict[str, float] = {}
    for part in accept.split(","):
        media, *parameters = (piece.strip().lower() for piece in part.split(";"))
        q = 1.0
        for parameter in parameters:
            name, _, value = parameter.partition("=")
            if name.strip() == "q":
                try:
                    q = min(max(float(value), 0.0), 1.0)
                except ValueError:
                    q = 0.0
        if media:
            weights[media] = max(q, weights.get(media, 0.0))
    return weights


def wants_png(accept: str) -> bool:
    """Whether an Accept header prefers the picture to JSON.

    The most specific range that names each counts (``image/png``, else ``image/*``, else
    ``*/*``; ``application/json``, else ``application/*``, else ``*/*``); the picture wins on a
    higher q, or on an equal q when it is named more specifically than JSON. No Accept, or
    ``*/*`` alone, is JSON.
    """
    weights = _accept_weights(accept)

    def weight(*ranges: str) -> tuple[float, int]:
        for specificity, media in enumerate(ranges):
            if media in weights:
                return weights[media], -specificity
        return 0.0, -len(ranges)

    png = weight("image/png", "image/*", "*/*")
    json_ = weight("application/json", "application/*", "*/*")
    return png[0] > 0.0 and png > json_


def cell_model_to_api(
    approximated: tuple[str, ...] | None, unchecked: tuple[Unchecked, ...] | None
) -> dict[str, Any]:
    """An answer's ``cell_approximated`` and ``cell_unchecked`` (None without a cell)."""
    return {
        "cell_approximated": None if approximated is None else list(approximated),
        "cell_unchecked": None
        if unchecked is None
        else [schemas.UncheckedPair.from_solver(pair) for pair in unchecked],
    }
