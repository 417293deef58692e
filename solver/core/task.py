"""Task requirements of a path: the direction and the ratio h of every segment (spec section 2).

Sensors 2022 eq. (26)-(28), ERK 2021 eq. (2)-(4) and (17). For waypoint i < N-1 the segment
i -> i+1 gives, in the frame the poses are expressed in:

    dp = p_{i+1} - p_i,  dphi = log(R_{i+1} R_i^T),  u_T = dp/|dp|,  u_R = dphi/|dphi|,
    h = |dp| / |dphi|

and the last waypoint reuses segment N-2. None of these depends on the feed rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError, RepeatedWaypointError
from solver.core.spatial import MAX_COORDINATE, rotation_vectors

# A displacement below this (m) or a rotation below this (rad) counts as none.
LINEAR_TOLERANCE = 1e-9
ANGULAR_TOLERANCE = 1e-9
# A segment turning within this of a half turn (rad) has no defined direction of rotation: the
# rotation vector's sign would come from rounding.
HALF_TURN_TOLERANCE = 1e-6


@dataclass(frozen=True)
class TaskRequirements:
    """Per-waypoint task requirements, in the frame of the poses given.

    Attributes:
        u_T: shape (N, 3), unit direction of the linear velocity; zero where h = 0.
        u_R: shape (N, 3), unit direction of the angular velocity; zero where h = inf.
        h: shape (N,), V / Omega in metres; ``inf`` for pure translation, 0 for pure
            reorientation.
    """

    u_T: np.ndarray
    u_R: np.ndarray
    h: np.ndarray

    def twists(self) -> np.ndarray:
        """t_hat per waypoint, shape (N, 6): [u_T; u_R / h], or [0; u_R] where h = 0."""
        return twists_of(self.u_T, self.u_R, self.h)


def twists_of(u_t: np.ndarray, u_r: np.ndarray, h: np.ndarray) -> np.ndarray:
    """t_hat, shape (..., 6), of u_T and u_R (..., 3) and h (...): [u_T; u_R / h].

    [0; u_R] where h = 0 (pure reorientation), [u_T; 0] where h = inf (pure translation).
    """
    h = h[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        angular = np.where(h == 0.0, u_r, np.where(np.isinf(h), 0.0, u_r / h))
    return np.concatenate([np.broadcast_to(u_t, angular.shape), angular], axis=-1)


def segment_requirements(
    displacement: np.ndarray, rotation_vector: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u_T, u_R and h of segments from their displacements and rotation vectors (..., 3).

    A displacement under LINEAR_TOLERANCE or a rotation under ANGULAR_TOLERANCE counts as none:
    its unit vector is 0, and h is inf without rotation, 0 with rotation alone. The arrays
    broadcast against each other (one path's displacements, many spun paths' rotations).
    """
    linear = np.linalg.norm(displacement, axis=-1)
    angular = np.linalg.norm(rotation_vector, axis=-1)
    moving = linear >= LINEAR_TOLERANCE
    turning = angular >= ANGULAR_TOLERANCE
    safe_linear = np.where(moving, linear, 1.0)
    safe_angular = np.where(turning, angular, 1.0)
    u_t = np.where(moving[..., None], displacement / safe_linear[..., None], 0.0)
    u_r = np.where(turning[..., None], rotation_vector / safe_angular[..., None], 0.0)
    h = np.where(turning, np.where(moving, linear, 0.0) / safe_angular, math.inf)
    return u_t, u_r, h


def _determinants(m: np.ndarray) -> np.ndarray:
    """The determinant of each 3x3 matrix of ``m`` (N, 3, 3), by cofactors (NaN with a NaN).

    A rotation's is 1 and a reflection's -1, so the sign, all that is read, is exact here as in
    LAPACK's LU (``np.linalg.det``), which took half of :func:`check_waypoints` (a call a pose).
    """
    determinants: np.ndarray = (
        m[:, 0, 0] * (m[:, 1, 1] * m[:, 2, 2] - m[:, 1, 2] * m[:, 2, 1])
        - m[:, 0, 1] * (m[:, 1, 0] * m[:, 2, 2] - m[:, 1, 2] * m[:, 2, 0])
        + m[:, 0, 2] * (m[:, 1, 0] * m[:, 2, 1] - m[:, 1, 1] * m[:, 2, 0])
    )
    return determinants


def check_waypoints(
    poses: np.ndarray, *, field: str = "path.waypoints", first: int = 0
) -> np.ndarray:
    """Return ``poses`` as a float array after checking shape and values.

    Args:
        poses: shape (N, 4, 4), N >= 2, homogeneous transforms with rotation matrices.
        field: name of the input, for error messages.
        first: the index of ``poses[0]`` in the path they are part of (a pass's first), which
            errors count from.

    Raises:
        InvalidInputError: fewer than 2 waypoints, wrong shape, non-finite values, or a
            rotation block that is not a rotation.
    """
    arr = np.asarray(poses, dtype=float)
    if arr.ndim != 3 or arr.shape[1:] != (4, 4):
        raise InvalidInputError(field, f"{arr.shape=}, needs (N, 4, 4)")
    if arr.shape[0] < 2:
        raise InvalidInputError(field, f"a path needs at least 2 waypoints, got {arr.shape[0]}")
    with np.errstate(invalid="ignore", over="ignore"):
        rotations = arr[:, :3, :3]
        orthonormal = np.abs(np.matmul(rotations.transpose(0, 2, 1), rotations) - np.eye(3))
        bad = (
            ~np.isfinite(arr).all(axis=(1, 2))
            | ~(np.abs(arr[:, :3, 3]).max(axis=1) <= MAX_COORDINATE)
            | ~(orthonormal.max(axis=(1, 2)) <= 1e-6)
            | ~(_determinants(rotations) >= 0)
        )
    if bad.any():  # the first bad pose, with the message of the first check it fails
        k = int(np.argmax(bad))
        pose, i = arr[k], first + k
        if not np.all(np.isfinite(pose)):
            raise InvalidInputError(field, "pose has values that are not finite", waypoint=i)
        if np.max(np.abs(pose[:3, 3])) > MAX_COORDINATE:
            raise InvalidInputError(
                field, f"position is beyond +-{MAX_COORDINATE} m (units are metres)", waypoint=i
            )
        raise InvalidInputError(field, "orientation is not a rotation", waypoint=i)
    return arr


def task_requirements(
    poses: np.ndarray, *, field: str = "path.waypoints", first: int = 0, free_spin: bool = False
) -> TaskRequirements:
    """Spec section 2: u_T, u_R and h of every waypoint of a path.

    Args:
        poses: shape (N, 4, 4), the waypoints (tool point poses), all in one frame.
        field: name of the input, for error messages.
        first: the index of ``poses[0]`` in the path they are part of (a pass's first): the
            waypoints errors name count from it.
        free_spin: the path runs in free spin, which leaves the turn about the tool axis to
            the spin: a segment that only turns about it moves nothing, a repeated waypoint
            too (its free-spin LP had no bound: omega_max 6.6e15 rad/s, audit 24).

    Returns:
        The requirements in that frame.

    Raises:
        InvalidInputError: see :func:`check_waypoints`.
        RepeatedWaypointError: two consecutive waypoints with the same position and
            orientation (in free spin, tool axis); it names the second one.
        InvalidInputError: a segment turning by a half turn (within 1e-6 rad), naming its
            second waypoint (issue 9: the sign of u_R would come from rounding).
    """
    arr = check_waypoints(poses, field=field, first=first)
    displacement = arr[1:, :3, 3] - arr[:-1, :3, 3]
    rotation_vector = rotation_vectors(
        np.einsum("nij,nkj->nik", arr[1:, :3, :3], arr[:-1, :3, :3])  # R_{i+1} R_i^T
    )
    linear = np.linalg.norm(displacement, axis=1)
    angular = np.linalg.norm(rotation_vector, axis=1)
    no_move = (linear < LINEAR_TOLERANCE) & (angular < ANGULAR_TOLERANCE)
    if np.any(no_move):
        raise RepeatedWaypointError(first + int(np.argmax(no_move)) + 1, field=field)
    half_turn = np.flatnonzero(angular > math.pi - HALF_TURN_TOLERANCE)
    if half_turn.size:
        k = int(half_turn[0])
        raise InvalidInputError(
            field,
            f"the orientation turns by {math.degrees(float(angular[k])):.6f} deg from "
            f"waypoint {first + k}: within {HALF_TURN_TOLERANCE:g} rad of a half turn the "
            "direction of rotation is undefined; add a waypoint between them",
            waypoint=first + k + 1,
        )
    if free_spin:
        axis = arr[:-1, :3, 2]  # the tool axis at each segment's start
        about = np.einsum("ni,ni->n", rotation_vector, axis)
        tilted = np.linalg.norm(rotation_vector - about[:, None] * axis, axis=1)
        in_place = (linear < LINEAR_TOLERANCE) & (tilted < ANGULAR_TOLERANCE)
        if np.any(in_place):
            at = first + int(np.argmax(in_place)) + 1
            raise RepeatedWaypointError(at, field=field, free_spin=True)
    u_t, u_r, h = segment_requirements(displacement, rotation_vector)
    last = slice(-1, None)
    return TaskRequirements(
        u_T=np.concatenate([u_t, u_t[last]]),
        u_R=np.concatenate([u_r, u_r[last]]),
        h=np.concatenate([h, h[last]]),
    )
