"""Small rigid-body helpers: quaternions, poses, placements (numpy)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from solver.core.exceptions import InvalidInputError

QUATERNION_NORM_TOLERANCE = 1e-3  # cam.md section 6: normalised within it, refused beyond
# Positions and placements farther than this from the origin (m) are input errors: no robot cell
# is that large, and squares of far larger numbers overflow.
MAX_COORDINATE = 1e3


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    wrapped: np.ndarray = (angle + math.pi) % (2 * math.pi) - math.pi
    return wrapped


def check_position(position: np.ndarray | list[float], *, field: str) -> np.ndarray:
    """A position as a float array of shape (3,), finite and within MAX_COORDINATE (m).

    Raises:
        InvalidInputError: wrong shape, not finite, or too far.
    """
    pos = np.asarray(position, dtype=float)
    if pos.shape != (3,) or not np.all(np.isfinite(pos)):
        raise InvalidInputError(field, f"position needs 3 finite numbers, got {pos.tolist()}")
    if np.max(np.abs(pos)) > MAX_COORDINATE:
        raise InvalidInputError(
            field, f"position {pos.tolist()} m is beyond +-{MAX_COORDINATE} m (units are metres)"
        )
    return pos


def rotation_from_quaternion(
    quaternion_xyzw: np.ndarray | list[float], *, field: str
) -> np.ndarray:
    """Rotation matrix of a unit quaternion in ROS order (x, y, z, w).

    Args:
        quaternion_xyzw: shape (4,), unit norm to within 1e-3 (cam.md section 6), normalised.
        field: name of the input, for the error message.

    Returns:
        shape (3, 3), a rotation matrix.

    Raises:
        InvalidInputError: wrong shape, not finite, or a norm off by more than 1e-3.
    """
    quat = np.asarray(quaternion_xyzw, dtype=float)
    if quat.shape != (4,) or not np.all(np.isfinite(quat)):
        raise InvalidInputError(field, f"needs 4 finite numbers (x, y, z, w), got {quat.tolist()}")
    norm = float(np.linalg.norm(quat))
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        raise InvalidInputError(
            field,
            f"quaternion norm is {norm:.6g}; a unit quaternion is needed (within 1e-3, then "
            "normalised)",
        )
    x, y, z, w = quat / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def pose_matrix(
    position: np.ndarray | list[float], quaternion_xyzw: np.ndarray | list[float], *, field: str
) -> np.ndarray:
    """Homogeneous transform of a position (m) and a unit quaternion (x, y, z, w).

    Raises:
        InvalidInputError: a position that is not 3 finite numbers, or a bad quaternion.
    """
    pos = check_position(position, field=field)
    transform = np.eye(4)
    transform[:3, :3] = rotation_from_quaternion(quaternion_xyzw, field=field)
    transform[:3, 3] = pos
    return transform


def pose_matrices(positions: np.ndarray, quaternions_xyzw: np.ndarray, *, field: str) -> np.ndarray:
    """:func:`pose_matrix` of N poses at once, shape (N, 4, 4), metres.

    Args:
        positions: shape (N, 3), m.
        quaternions_xyzw: shape (N, 4), unit to within 1e-3, normalised.
        field: name of the input; the error names ``{field}.{i}`` of the first bad pose.

    Raises:
        InvalidInputError: as :func:`pose_matrix`, for the first pose that fails.
    """
    pos = np.asarray(positions, dtype=float)
    quat = np.asarray(quaternions_xyzw, dtype=float)
    if pos.ndim != 2 or pos.shape[1:] != (3,) or quat.shape != (len(pos), 4):
        raise InvalidInputError(field, f"{pos.shape=} and {quat.shape=}, need (N, 3), (N, 4)")
    with np.errstate(invalid="ignore"):
        norm = np.linalg.norm(quat, axis=1)
        bad = (
            ~np.isfinite(pos).all(axis=1)
            | (np.abs(pos).max(axis=1, initial=0.0) > MAX_COORDINATE)
            | ~np.isfinite(quat).all(axis=1)
            | ~(np.abs(norm - 1.0) <= QUATERNION_NORM_TOLERANCE)
        )
    if bad.any():
        i = int(np.argmax(bad))
        pose_matrix(pos[i], quat[i], field=f"{field}.{i}")  # raises its error
    x, y, z, w = (quat / norm[:, None]).T
    out = np.zeros((len(pos), 4, 4))
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = (
        1 - 2 * (y * y + z * z),
        2 * (x * y - z * w),
        2 * (x * z + y * w),
    )
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = (
        2 * (x * y + z * w),
        1 - 2 * (x * x + z * z),
        2 * (y * z - x * w),
    )
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = (
        2 * (x * z - y * w),
        2 * (y * z + x * w),
        1 - 2 * (x * x + y * y),
    )
    out[:, :3, 3] = pos
    out[:, 3, 3] = 1.0
    return out


def rotation_about_z(angle: np.ndarray | float) -> np.ndarray:
    """Rot_z(angle), batched: shape (*angle.shape, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = 1.0
    return out


def spun_waypoints(waypoints: np.ndarray, spins: np.ndarray) -> np.ndarray:
    """Each waypoint turned about its own tool z axis: T_O_i Rot_z(spins_i) (cam.md section 4).

    Args:
        waypoints: shape (N, 4, 4), T_O_i (m).
        spins: shape (N,), rad.
    """
    spun = np.array(waypoints, dtype=float)
    spun[:, :3, :3] = spun[:, :3, :3] @ rotation_about_z(np.asarray(spins, dtype=float))
    return spun


@dataclass(frozen=True)
class Placement:
    """Where the workpiece frame {O} sits in the base frame {B} (spec section 1), and the spin.

    T_B_O = Trans(x, y, z) * Rot_z(yaw); x, y, z in metres, yaw in radians. ``spin`` (rad) turns
    every waypoint about its own tool z axis, R_i Rot_z(spin) (cam.md section 3): it leaves the
    task requirements as they are and changes only the IK, as a TCP turned about its z would.
    """

    x: float
    y: float
    z: float
    yaw: float
    spin: float = 0.0

    def __post_init__(self) -> None:
        """Check the values.

        Raises:
            InvalidInputError: a value that is not finite, or a position beyond MAX_COORDINATE.
        """
        check_position([self.x, self.y, self.z], field="placement")
        for name in ("yaw", "spin"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise InvalidInputError(f"placement.{name}", f"{name} {value} rad is not finite")

    def as_row(self) -> np.ndarray:
        """The placement as one row of the batched layout, [x, y, z, yaw, spin]."""
        return np.array([self.x, self.y, self.z, self.yaw, self.spin])

    def transform_workpiece_to_base(self) -> np.ndarray:
        """T_B_O, shape (4, 4)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array(
            [
                [c, -s, 0.0, self.x],
                [s, c, 0.0, self.y],
                [0.0, 0.0, 1.0, self.z],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )


# Above this angle (rad) the rotation vector of rotation_vectors comes from pinocchio's log3,
# whose formula near a half turn reads the diagonal; below it both use the skew part.
NEAR_HALF_TURN = math.pi - 1e-2


def rotation_vectors(rotations: np.ndarray) -> np.ndarray:
    """log(R) of many rotations at once: the rotation vectors, shape (..., 3), from (..., 3, 3).

    theta = atan2(|w|, (tr R - 1) / 2) with w the skew part's vector (sin(theta) times the
    axis), and log(R) = w theta / sin(theta) (1 + theta^2 / 6 below 1e-4 rad); near a half
    turn, where w is small and carries little of the axis, pinocchio's ``log3`` (pose by pose).
    Measured against exp3 of known rotation vectors: within 1e-15 below 3 rad, as log3 is
    (tests/solver/test_spatial_batched.py). For the 132 segments of the README example a
    Python loop of log3 and the products took 0.38 ms, this 0.095 ms with the products.
    """
    r = np.asarray(rotations, dtype=float)
    w = 0.5 * np.stack(
        [r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]],
        axis=-1,
    )
    sine = np.linalg.norm(w, axis=-1)
    theta = np.arctan2(sine, (np.trace(r, axis1=-2, axis2=-1) - 1.0) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):  # a half turn: w = 0, log3 below
        ratio = np.where(theta > 1e-4, theta / sine, 1.0 + theta**2 / 6.0)
        vectors: np.ndarray = ratio[..., None] * w
    flat_r, flat_v = r.reshape(-1, 3, 3), vectors.reshape(-1, 3)
    for i in np.flatnonzero(theta.ravel() >= NEAR_HALF_TURN):
        flat_v[i] = pin.log3(flat_r[i])
    return vectors


@dataclass(frozen=True)
class BaseTurn:
    """A frame {A} that is {B} turned by ``angle`` about its z and moved to ``shift``.

    Where a kinematics family solves when its own base frame is not {B}: a UR arm's URDF read
    from ``base_link``, which ROS puts half a turn about z from the arm's DH base frame
    (:mod:`solver.families.recognise`). A turn about z keeps a placement a placement: {O} at
    (x, y, z, yaw) in {B} is at :meth:`placements_in` in {A}, so a map's kernels take it whole.

    A family whose first joint is not upright in {B} (an arm on a wall or a ceiling, read from
    its cell's frame) solves in a frame whose z is that joint's axis: {B} is first tilted by
    ``tilt`` (R_B_T), then turned about the tilted z. A placement is then no placement of {A}
    (its yaw is about {B}'s z; :meth:`placements_in` refuses): the map kernels place the path
    in {B} and write each block's poses in {A} (:func:`solver.families.kernels.pose_block`).

    Attributes:
        angle: rad, about {B}'s z (about the tilted z where there is a tilt).
        shift: m, {A}'s origin in {B}.
        tilt: R_B_T row by row (9 values), where {A}'s z is not {B}'s; None: no tilt.
    """

    angle: float
    shift: tuple[float, float, float]
    tilt: tuple[float, ...] | None = None

    @classmethod
    def read(cls, angle: float, x: float, y: float) -> BaseTurn:
        """The turn by ``angle`` (rad) about z to (x, y, 0) (m), as read off a chain.

        The identity where all three are within 1e-12 (a chain's rounding: {B} itself reads
        as no turn).
        """
        if max(abs(angle), abs(x), abs(y)) <= 1e-12:
            return cls(0.0, (0.0, 0.0, 0.0))
        return cls(float(angle), (float(x), float(y), 0.0))

    def tilted(self, rotation: np.ndarray) -> BaseTurn:
        """This turn, read in {T} = {B} turned by ``rotation`` (R_B_T), as a turn of {B}."""
        shift = np.asarray(rotation, dtype=float) @ np.asarray(self.shift, dtype=float)
        rows = tuple(float(v) for v in np.asarray(rotation, dtype=float).ravel())
        return BaseTurn(self.angle, (float(shift[0]), float(shift[1]), float(shift[2])), rows)

    @property
    def is_identity(self) -> bool:
        """{A} is {B}."""
        return self.angle == 0.0 and not any(self.shift) and self.tilt is None

    @property
    def tilt_matrix(self) -> np.ndarray | None:
        """R_B_T (3, 3), or None without a tilt."""
        return None if self.tilt is None else np.array(self.tilt).reshape(3, 3)

    def _inverse(self) -> np.ndarray:
        """R_A_B (3, 3): Rz(-angle), after R_T_B where there is a tilt."""
        turn = rotation_about_z(-self.angle)
        tilt = self.tilt_matrix
        return turn if tilt is None else turn @ tilt.T

    def vectors_in(self, vectors: np.ndarray) -> np.ndarray:
        """Directions (3, ...) in {B} axes, in {A} axes."""
        return np.tensordot(self._inverse(), vectors, axes=1)

    def points_in(self, points: np.ndarray) -> np.ndarray:
        """Points (3, ...) in {B}, in {A}."""
        shift = np.asarray(self.shift).reshape((3,) + (1,) * (np.ndim(points) - 1))
        return self.vectors_in(points - shift)

    def placements_in(self, placements: np.ndarray) -> np.ndarray:
        """Placements (P, 5) [x, y, z, yaw, spin] of {O} in {B}, as placements in {A}.

        Raises:
            ValueError: the turn has a tilt (no placement of {A} is one of {B}).
        """
        if self.tilt is not None:
            raise ValueError("a tilted base frame takes no placement of {B} whole")
        turned = np.array(placements, dtype=float)
        turned[:, :3] = self.points_in(turned[:, :3].T).T
        turned[:, 3] = turned[:, 3] - self.angle
        return turned


@dataclass(frozen=True, eq=False)
class FlangeOffset:
    """Where a chain's flange frame {F} sits on a kinematics family's own flange {F'}.

    A closed-form family's IK solves for its own flange (an OPW arm's: on joint 6's axis, z
    along it); a URDF's tool frame may be anywhere on the last link (turned, or off the axis, as
    CAD exports write ``tool0``). {F} = {F'} E, E fixed: a pose of {F} is one of {F'}
    (:meth:`family_flange`), the joints the same (:mod:`solver.families.recognise`).

    Attributes:
        rotation: R_F'_F, shape (3, 3).
        translation: m, {F}'s origin in {F'}, shape (3,).

    Compared by identity (its fields are arrays).
    """

    rotation: np.ndarray
    translation: np.ndarray

    @classmethod
    def read(cls, rotation: np.ndarray, translation: np.ndarray) -> FlangeOffset:
        """E as read off a chain: entries within 1e-12 of zero are zero (its rounding)."""
        rotation, translation = (
            np.where(np.abs(a) <= 1e-12, 0.0, np.asarray(a, dtype=float))
            for a in (rotation, translation)
        )
        return cls(rotation, translation)

    @property
    def matrix(self) -> np.ndarray:
        """E as a homogeneous matrix (4, 4)."""
        matrix = np.eye(4)
        matrix[:3, :3], matrix[:3, 3] = self.rotation, self.translation
        return matrix

    def family_flange(
        self, rotation: np.ndarray, position: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Poses of {F}, R_B_F (3, 3, ...) and p_B_F (3, ...): those of {F'}, same shapes.

        R_B_F' = R_B_F E_R^T and p_B_F' = p_B_F - R_B_F' E_p.
        """
        turned = np.einsum("ij...,kj->ik...", rotation, self.rotation)
        return turned, position - np.einsum("ik...,k->i...", turned, self.translation)

    def family_flange_rows(
        self, rotation: np.ndarray, position: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`family_flange` of poses in rows: R (W, 3, 3) and p (W, 3)."""
        turned, moved = self.family_flange(np.moveaxis(rotation, 0, -1), position.T)
        return np.ascontiguousarray(np.moveaxis(turned, -1, 0)), np.ascontiguousarray(moved.T)
