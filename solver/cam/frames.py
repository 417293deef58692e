"""A placement in the terms of robot controllers (cam.md section 8), and back.

A placement is where the workpiece frame {O} sits in the robot base frame {B}, T_B_O.
Controllers call it the base, user or work-object frame and each writes it its own way:

| key | units | convention |
|---|---|---|
| ``matrix`` | m | 4x4 homogeneous T_B_O, row-major |
| ``ur`` | m, rad | [x, y, z, rx, ry, rz], rotation vector (pendant "pose") |
| ``kuka`` | mm, deg | {X, Y, Z, A, B, C}, R = Rz(A) Ry(B) Rx(C) |
| ``abb`` | mm | wobj uframe: [[x, y, z], [q1, q2, q3, q4]], q1 the scalar part |
| ``fanuc`` | mm, deg | {X, Y, Z, W, P, R}, R = Rz(R) Ry(P) Rx(W) |

Every conversion is closed-form numpy, accurate to rounding everywhere: the Z-Y-X angles take
the third angle from the first (not both from a vanishing cos B), and at the gimbal lock
(|cos B| < 1e-12, B = +-90 degrees) the last angle (KUKA C, FANUC W) is set to 0 and the first
carries the whole turn about z. The quaternion is Shepperd's, with q1 >= 0; the rotation
vector has length in [0, pi]. The tool spin of a placement is not part of T_B_O (it turns the
tool about its own axis), so it is not in these frames.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import Placement, check_position, rotation_from_quaternion

GIMBAL_LOCK_TOLERANCE = 1e-12  # |cos B| below this: B = +-90 degrees, C (or W) set to 0
ROTATION_TOLERANCE = 1e-9  # |R^T R - I| of a transform accepted as rigid
_MM = 1e3


@dataclass(frozen=True)
class ControllerFrames:
    """One placement, T_B_O, as each controller writes it (cam.md section 8).

    Attributes:
        matrix: 4 rows of 4, m, row-major T_B_O.
        ur: [x, y, z, rx, ry, rz], m and rad (rotation vector).
        kuka: {X, Y, Z, A, B, C}, mm and deg, R = Rz(A) Ry(B) Rx(C).
        abb: [[x, y, z], [q1, q2, q3, q4]], mm, q1 the scalar part (>= 0).
        fanuc: {X, Y, Z, W, P, R}, mm and deg, R = Rz(R) Ry(P) Rx(W).
    """

    matrix: list[list[float]]
    ur: list[float]
    kuka: dict[str, float]
    abb: list[list[float]]
    fanuc: dict[str, float]


def controller_frames(transform_workpiece_to_base: np.ndarray) -> ControllerFrames:
    """Every controller's form of T_B_O.

    Args:
        transform_workpiece_to_base: shape (4, 4), T_B_O, m.

    Raises:
        InvalidInputError: not a finite rigid transform.
    """
    return _frames_of_rigid(check_transform(transform_workpiece_to_base, field="placement"))


def frames_of_placement(placement: Placement) -> ControllerFrames:
    """:func:`controller_frames` of a placement's T_B_O (its spin is not part of it).

    Its transform is rigid by construction (a turn about z, a checked position), so it is not
    checked again: the map's best and worst cells take this at every request.
    """
    return _frames_of_rigid(placement.transform_workpiece_to_base())


def _frames_of_rigid(transform: np.ndarray) -> ControllerFrames:
    """:func:`controller_frames` of a transform already known to be rigid.

    Every number is given with its zero unsigned (adding 0.0 to -0.0 gives 0.0 and changes no
    other float): an unturned placement's sin(0) entries and B were -0.0, which a post-processor
    writes as "B -0.000".
    """
    transform = transform + 0.0
    rotation, position = transform[:3, :3], transform[:3, 3]
    yaw, pitch, roll = (math.degrees(v) + 0.0 for v in zyx_angles(rotation))
    pitch = min(max(pitch, -90.0), 90.0)  # degrees(pi / 2) is 90.00000000000001
    x, y, z = (float(v) * _MM + 0.0 for v in position)
    quaternion = quaternion_wxyz(rotation) + 0.0
    return ControllerFrames(
        matrix=transform.tolist(),
        ur=[*map(float, position), *(float(v) + 0.0 for v in _vector_of_quaternion(quaternion))],
        kuka={"X": x, "Y": y, "Z": z, "A": yaw, "B": pitch, "C": roll},
        abb=[[x, y, z], [float(v) for v in quaternion]],
        fanuc={"X": x, "Y": y, "Z": z, "W": roll, "P": pitch, "R": yaw},
    )


def check_transform(transform: np.ndarray, *, field: str) -> np.ndarray:
    """A 4x4 rigid transform as a float array: finite, a rotation block, bottom row 0 0 0 1.

    Raises:
        InvalidInputError: wrong shape, not finite, or not rigid (to ROTATION_TOLERANCE).
    """
    arr = np.asarray(transform, dtype=float)
    if arr.shape != (4, 4) or not np.all(np.isfinite(arr)):
        raise InvalidInputError(field, f"needs a finite 4x4 transform, got shape {arr.shape}")
    rotation = arr[:3, :3]
    rigid = np.abs(rotation.T @ rotation - np.eye(3)).max() <= ROTATION_TOLERANCE
    if not rigid or np.linalg.det(rotation) < 0 or np.any(arr[3] != [0.0, 0.0, 0.0, 1.0]):
        raise InvalidInputError(field, "the transform is not rigid (a rotation and a position)")
    check_position(arr[:3, 3], field=field)
    return arr


def zyx_angles(rotation: np.ndarray) -> tuple[float, float, float]:
    """(a, b, c), rad, with R = Rz(a) Ry(b) Rx(c); b in [-pi/2, pi/2], c = 0 at the lock.

    With a known, Rz(a)^T R = Ry(b) Rx(c) gives b and c from entries of size 1, so the angles
    reproduce R to rounding even where cos b is tiny.
    """
    r = rotation
    locked = math.hypot(r[0, 0], r[1, 0]) < GIMBAL_LOCK_TOLERANCE
    if locked:
        yaw = math.atan2(-r[0, 1], r[1, 1])  # Rz(a) Ry(+-90): the turn about z is all in a
    else:
        yaw = math.atan2(r[1, 0], r[0, 0])
    ca, sa = math.cos(yaw), math.sin(yaw)
    pitch = math.atan2(-r[2, 0], ca * r[0, 0] + sa * r[1, 0])
    roll = 0.0 if locked else math.atan2(sa * r[0, 2] - ca * r[1, 2], ca * r[1, 1] - sa * r[0, 1])
    return yaw, pitch, roll


def rotation_from_zyx(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """Rz(yaw) Ry(pitch) Rx(roll), shape (3, 3); angles in rad."""
    ca, sa = math.cos(yaw), math.sin(yaw)
    cb, sb = math.cos(pitch), math.sin(pitch)
    cc, sc = math.cos(roll), math.sin(roll)
    return np.array(
        [
            [ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc],
            [sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc],
            [-sb, cb * sc, cb * cc],
        ]
    )


def quaternion_wxyz(rotation: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation, w >= 0 (Shepperd's method), shape (4,)."""
    m = rotation
    trace = float(np.trace(m))
    if trace > max(m[0, 0], m[1, 1], m[2, 2]):
        s = 2.0 * math.sqrt(1.0 + trace)
        q = [s / 4, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [(m[k, j] - m[j, k]) / s, 0.0, 0.0, 0.0]
        q[1 + i], q[1 + j], q[1 + k] = s / 4, (m[j, i] + m[i, j]) / s, (m[k, i] + m[i, k]) / s
    quat: np.ndarray = np.array(q) / np.linalg.norm(q)
    # q and -q are one rotation: w >= 0, and at w = 0 the largest component positive.
    if quat[0] < 0.0 or (quat[0] == 0.0 and quat[1 + int(np.argmax(np.abs(quat[1:])))] < 0.0):
        quat = -quat
    return quat


def quaternions_wxyz(rotations: np.ndarray) -> np.ndarray:
    """:func:`quaternion_wxyz` of many rotations at once, shape (N, 3, 3) -> (N, 4).

    The same branches and the same sign rule, row by row, without a Python call per rotation
    (an imported program has up to 20,000 waypoints).
    """
    m = np.asarray(rotations, dtype=float)
    diag = np.diagonal(m, axis1=1, axis2=2)
    trace = diag.sum(axis=1)
    quats = np.empty((len(m), 4))
    by_trace = trace > diag.max(axis=1)
    t = m[by_trace]
    s = 2.0 * np.sqrt(1.0 + trace[by_trace])
    quats[by_trace] = np.column_stack(
        [
            s / 4,
            (t[:, 2, 1] - t[:, 1, 2]) / s,
            (t[:, 0, 2] - t[:, 2, 0]) / s,
            (t[:, 1, 0] - t[:, 0, 1]) / s,
        ]
    )
    largest = np.argmax(diag, axis=1)
    for i in range(3):
        rows = ~by_trace & (largest == i)
        j, k = (i + 1) % 3, (i + 2) % 3
        r = m[rows]
        s = 2.0 * np.sqrt(1.0 + r[:, i, i] - r[:, j, j] - r[:, k, k])
        quats[rows, 0] = (r[:, k, j] - r[:, j, k]) / s
        quats[rows, 1 + i] = s / 4
        quats[rows, 1 + j] = (r[:, j, i] + r[:, i, j]) / s
        quats[rows, 1 + k] = (r[:, k, i] + r[:, i, k]) / s
    quats /= np.linalg.norm(quats, axis=1)[:, None]
    vector = quats[:, 1:]
    lead = vector[np.arange(len(quats)), np.argmax(np.abs(vector), axis=1)]
    flip = (quats[:, 0] < 0.0) | ((quats[:, 0] == 0.0) & (lead < 0.0))
    quats[flip] = -quats[flip]
    return quats


def rotation_vector(rotation: np.ndarray) -> np.ndarray:
    """The rotation vector (axis times angle, rad) of a rotation, length in [0, pi], (3,)."""
    return _vector_of_quaternion(quaternion_wxyz(rotation))


def _vector_of_quaternion(quaternion: np.ndarray) -> np.ndarray:
    """The rotation vector (rad) of a unit quaternion (w, x, y, z) with w >= 0, shape (3,)."""
    w, *v = quaternion
    vector = np.array(v)
    sine = float(np.linalg.norm(vector))  # sin(angle / 2)
    scale = 2.0 * math.atan2(sine, w) / sine if sine > 0.0 else 2.0
    return scale * vector


def rotation_from_vector(vector: Sequence[float] | np.ndarray) -> np.ndarray:
    """The rotation of a rotation vector (rad), shape (3, 3): its exponential, via a quaternion."""
    v = np.asarray(vector, dtype=float)
    angle = float(np.linalg.norm(v))
    half_sinc = 0.5 * float(np.sinc(angle / (2.0 * math.pi)))  # sin(angle / 2) / angle
    x, y, z = v * half_sinc
    return rotation_from_quaternion([x, y, z, math.cos(angle / 2.0)], field="frames.ur")


def _transform(
    rotation: np.ndarray, position: Sequence[float] | np.ndarray, *, field: str
) -> np.ndarray:
    """A 4x4 transform from a rotation and a position in m."""
    transform = np.eye(4)
    transform[:3, :3] = rotation
    transform[:3, 3] = check_position(np.asarray(position, dtype=float), field=field)
    return transform


def _numbers(values: Sequence[float] | np.ndarray, count: int, *, field: str) -> np.ndarray:
    """``count`` finite numbers; InvalidInputError otherwise."""
    arr = np.asarray(values, dtype=float)
    if arr.shape != (count,) or not np.all(np.isfinite(arr)):
        raise InvalidInputError(field, f"needs {count} finite numbers, got {arr.tolist()}")
    return arr


def _keyed(frame: Mapping[str, float], keys: str, *, field: str) -> np.ndarray:
    """The values of ``frame`` under the one-letter ``keys``, in that order."""
    missing = [key for key in keys if key not in frame]
    if missing:
        raise InvalidInputError(field, f"needs the keys {', '.join(keys)}; missing {missing}")
    return _numbers([frame[key] for key in keys], len(keys), field=field)


def matrix_from_rows(rows: Sequence[Sequence[float]]) -> np.ndarray:
    """T_B_O from the ``matrix`` form (row-major, m), checked rigid."""
    return check_transform(np.asarray(rows, dtype=float), field="frames.matrix")


def matrix_from_ur(pose: Sequence[float]) -> np.ndarray:
    """T_B_O from the ``ur`` form [x, y, z, rx, ry, rz] (m, rad)."""
    values = _numbers(pose, 6, field="frames.ur")
    return _transform(rotation_from_vector(values[3:]), values[:3], field="frames.ur")


def matrix_from_kuka(frame: Mapping[str, float]) -> np.ndarray:
    """T_B_O from the ``kuka`` form {X, Y, Z, A, B, C} (mm, deg), R = Rz(A) Ry(B) Rx(C)."""
    x, y, z, a, b, c = _keyed(frame, "XYZABC", field="frames.kuka")
    rotation = rotation_from_zyx(math.radians(a), math.radians(b), math.radians(c))
    return _transform(rotation, [x / _MM, y / _MM, z / _MM], field="frames.kuka")


def matrix_from_abb(wobj: Sequence[Sequence[float]]) -> np.ndarray:
    """T_B_O from the ``abb`` form [[x, y, z], [q1, q2, q3, q4]] (mm, q1 scalar, unit to 1e-6)."""
    if len(wobj) != 2:
        raise InvalidInputError("frames.abb", "needs [[x, y, z], [q1, q2, q3, q4]]")
    position = _numbers(wobj[0], 3, field="frames.abb")
    w, x, y, z = _numbers(wobj[1], 4, field="frames.abb")
    rotation = rotation_from_quaternion([x, y, z, w], field="frames.abb")
    return _transform(rotation, position / _MM, field="frames.abb")


def matrix_from_fanuc(frame: Mapping[str, float]) -> np.ndarray:
    """T_B_O from the ``fanuc`` form {X, Y, Z, W, P, R} (mm, deg), R = Rz(R) Ry(P) Rx(W)."""
    x, y, z, w, p, r = _keyed(frame, "XYZWPR", field="frames.fanuc")
    rotation = rotation_from_zyx(math.radians(r), math.radians(p), math.radians(w))
    return _transform(rotation, [x / _MM, y / _MM, z / _MM], field="frames.fanuc")
