"""Controller frames (cam.md section 8): each convention against scipy, and back to the matrix."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from solver.cam.frames import (
    GIMBAL_LOCK_TOLERANCE,
    controller_frames,
    frames_of_placement,
    matrix_from_abb,
    matrix_from_fanuc,
    matrix_from_kuka,
    matrix_from_rows,
    matrix_from_ur,
    quaternion_wxyz,
    quaternions_wxyz,
)
from solver.core.exceptions import InvalidInputError
from solver.core.spatial import Placement
from tests.cases import FRAME_ROUND_TRIP_ATOL


def _special_rotations() -> Rotation:
    """Gimbal locks, half turns (rotation vector of length pi), the identity, tiny turns."""
    locks = [[a, b, c] for a in (-170.0, -30.0, 0.0, 45.0, 180.0) for b in (90.0, -90.0)
             for c in (-120.0, 0.0, 60.0)]  # fmt: skip
    near_locks = [[20.0, 90.0 - 1e-7, 10.0], [-20.0, -90.0 + 1e-9, 40.0], [5.0, 90.0 - 1e-12, 7.0]]
    diagonal = math.pi / math.sqrt(2)
    half_turns = [
        [math.pi, 0, 0],
        [0, math.pi, 0],
        [0, 0, math.pi],
        [diagonal, diagonal, 0.0],
        [-math.pi / math.sqrt(3)] * 3,
        [0, 0, -math.pi],
        [0, 0, math.pi - 1e-9],
    ]
    tiny = [[1e-14, 0, 0], [1e-9, -2e-9, 3e-9], [0, 0, 0]]
    return Rotation.concatenate(
        [
            Rotation.from_euler("ZYX", locks + near_locks, degrees=True),
            Rotation.from_rotvec(half_turns + tiny),
        ]
    )


def _transforms() -> list[np.ndarray]:
    """300 seeded random rotations and the special ones, at random positions within 2 m."""
    rng = np.random.default_rng(2024)
    rotations = Rotation.concatenate(
        [Rotation.random(300, random_state=rng), _special_rotations()]
    ).as_matrix()
    out = []
    for rotation in rotations:
        transform = np.eye(4)
        transform[:3, :3] = rotation
        transform[:3, 3] = rng.uniform(-2.0, 2.0, 3)
        out.append(transform)
    return out


TRANSFORMS = _transforms()


def test_round_trips_and_scipy_agree_for_every_convention() -> None:
    for transform in TRANSFORMS:
        frames = controller_frames(transform)
        rotation, position_mm = transform[:3, :3], transform[:3, 3] * 1e3
        # matrix: row-major T_B_O, as given.
        np.testing.assert_array_equal(np.array(frames.matrix), transform)
        np.testing.assert_allclose(
            matrix_from_rows(frames.matrix), transform, atol=FRAME_ROUND_TRIP_ATOL
        )
        # ur: m and a rotation vector of length at most pi.
        ur = np.array(frames.ur)
        np.testing.assert_allclose(ur[:3], transform[:3, 3], rtol=0, atol=1e-15)
        assert np.linalg.norm(ur[3:]) <= math.pi + 1e-12
        np.testing.assert_allclose(
            Rotation.from_rotvec(ur[3:]).as_matrix(), rotation, atol=FRAME_ROUND_TRIP_ATOL
        )
        np.testing.assert_allclose(matrix_from_ur(frames.ur), transform, atol=FRAME_ROUND_TRIP_ATOL)
        # kuka: mm, R = Rz(A) Ry(B) Rx(C) = scipy's intrinsic ZYX.
        k = frames.kuka
        np.testing.assert_allclose([k["X"], k["Y"], k["Z"]], position_mm, rtol=0, atol=1e-12)
        assert -90.0 <= k["B"] <= 90.0
        scipy_kuka = Rotation.from_euler("ZYX", [k["A"], k["B"], k["C"]], degrees=True)
        np.testing.assert_allclose(scipy_kuka.as_matrix(), rotation, atol=FRAME_ROUND_TRIP_ATOL)
        np.testing.assert_allclose(
            matrix_from_kuka(frames.kuka), transform, atol=FRAME_ROUND_TRIP_ATOL
        )
        # abb: mm, unit quaternion scalar first, q1 >= 0.
        position, quaternion = np.array(frames.abb[0]), np.array(frames.abb[1])
        np.testing.assert_allclose(position, position_mm, rtol=0, atol=1e-12)
        assert quaternion[0] >= 0.0 and abs(np.linalg.norm(quaternion) - 1.0) < 1e-15
        scipy_abb = Rotation.from_quat([*quaternion[1:], quaternion[0]])  # scipy: scalar last
        np.testing.assert_allclose(scipy_abb.as_matrix(), rotation, atol=FRAME_ROUND_TRIP_ATOL)
        np.testing.assert_allclose(
            matrix_from_abb(frames.abb), transform, atol=FRAME_ROUND_TRIP_ATOL
        )
        # fanuc: mm, R = Rz(R) Ry(P) Rx(W) = scipy's extrinsic xyz of (W, P, R).
        f = frames.fanuc
        scipy_fanuc = Rotation.from_euler("xyz", [f["W"], f["P"], f["R"]], degrees=True)
        np.testing.assert_allclose(scipy_fanuc.as_matrix(), rotation, atol=FRAME_ROUND_TRIP_ATOL)
        np.testing.assert_allclose(
            matrix_from_fanuc(frames.fanuc), transform, atol=FRAME_ROUND_TRIP_ATOL
        )


def test_euler_angles_match_scipy_away_from_the_lock() -> None:
    for transform in TRANSFORMS[:300]:
        kuka = controller_frames(transform).kuka
        expected = Rotation.from_matrix(transform[:3, :3]).as_euler("ZYX", degrees=True)
        np.testing.assert_allclose([kuka["A"], kuka["B"], kuka["C"]], expected, atol=1e-9)


@pytest.mark.parametrize("pitch", [90.0, -90.0])
@pytest.mark.parametrize(("yaw", "roll"), [(0.0, 0.0), (30.0, 0.0), (30.0, 50.0), (-170.0, 120.0)])
def test_gimbal_lock_is_deterministic(yaw: float, roll: float, pitch: float) -> None:
    """At B = +-90 only A -+ C is defined: C (W) is set to 0 and A (R) takes the turn."""
    rotation = Rotation.from_euler("ZYX", [yaw, pitch, roll], degrees=True).as_matrix()
    transform = np.eye(4)
    transform[:3, :3] = rotation
    assert math.hypot(rotation[0, 0], rotation[1, 0]) < GIMBAL_LOCK_TOLERANCE
    frames = controller_frames(transform)
    assert frames.kuka["C"] == 0.0 and frames.fanuc["W"] == 0.0
    assert frames.kuka["B"] == pytest.approx(pitch, abs=1e-9)
    # Rz(A) Ry(90) Rx(C) = Rz(A - C) Ry(90); Rz(A) Ry(-90) Rx(C) = Rz(A + C) Ry(-90).
    expected = yaw - roll if pitch > 0 else yaw + roll
    difference = (frames.kuka["A"] - expected + 180.0) % 360.0 - 180.0
    assert difference == pytest.approx(0.0, abs=1e-9)
    assert frames.fanuc["R"] == frames.kuka["A"]


def test_kuka_and_fanuc_forward_match_scipy_on_random_angles() -> None:
    rng = np.random.default_rng(7)
    for a, b, c in rng.uniform(-180.0, 180.0, (100, 3)):
        expected = Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix()
        kuka = matrix_from_kuka({"X": 0.0, "Y": 0.0, "Z": 0.0, "A": a, "B": b, "C": c})
        fanuc = matrix_from_fanuc({"X": 0.0, "Y": 0.0, "Z": 0.0, "W": c, "P": b, "R": a})
        np.testing.assert_allclose(kuka[:3, :3], expected, atol=1e-15)
        np.testing.assert_allclose(fanuc[:3, :3], expected, atol=1e-15)


def test_frames_of_a_placement() -> None:
    placement = Placement(x=0.1, y=0.45, z=-0.05, yaw=math.radians(30.0), spin=1.0)
    frames = frames_of_placement(placement)
    assert frames.kuka == pytest.approx({"X": 100.0, "Y": 450.0, "Z": -50.0, "A": 30.0, "B": 0.0,
                                         "C": 0.0})  # fmt: skip
    assert frames.fanuc == pytest.approx({"X": 100.0, "Y": 450.0, "Z": -50.0, "W": 0.0, "P": 0.0,
                                          "R": 30.0})  # fmt: skip
    np.testing.assert_allclose(frames.ur, [0.1, 0.45, -0.05, 0.0, 0.0, math.radians(30.0)])
    half = math.radians(15.0)
    np.testing.assert_allclose(frames.abb[1], [math.cos(half), 0.0, 0.0, math.sin(half)])
    np.testing.assert_array_equal(frames.matrix, placement.transform_workpiece_to_base())


def _numbers(value: Any) -> list[float]:
    """Every number of a frames field, nested lists and dicts flattened."""
    if isinstance(value, dict):
        return [n for v in value.values() for n in _numbers(v)]
    if isinstance(value, list):
        return [n for v in value for n in _numbers(v)]
    return [value]


@pytest.mark.parametrize(("x", "yaw"), [(0.25, 0.0), (0.0, 0.0), (-0.1, math.pi), (0.0, -0.0)])
def test_no_frame_number_is_a_negative_zero(x: float, yaw: float) -> None:
    """An unturned placement's sin(0) entries and B were -0.0 ("B -0.000" in a program)."""
    frames = frames_of_placement(Placement(x=x, y=0.65, z=0.0, yaw=yaw))
    for field in ("matrix", "ur", "kuka", "abb", "fanuc"):
        numbers = _numbers(getattr(frames, field))
        assert not [n for n in numbers if n == 0.0 and math.copysign(1.0, n) < 0.0], field


@pytest.mark.parametrize("yaw", [0.0, 0.3, -2.0, math.pi, -math.pi, 3.0 * math.pi])
def test_a_placement_s_frames_equal_the_checked_transform_s(yaw: float) -> None:
    """frames_of_placement skips the rigidity check; its answer is controller_frames' exactly."""
    placement = Placement(x=-0.3, y=0.52, z=0.11, yaw=yaw, spin=0.4)
    assert frames_of_placement(placement) == controller_frames(
        placement.transform_workpiece_to_base()
    )


@pytest.mark.parametrize(
    "transform",
    [
        np.eye(3),
        np.diag([1.0, 1.0, -1.0, 1.0]),
        np.diag([1.0, 1.0, 1.0001, 1.0]),
        np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1.0]]),
        np.array([[1, 0, 0, np.nan], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]),
        np.array([[1, 0, 0, 5e3], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]),
    ],
)
def test_a_transform_that_is_not_rigid_is_refused(transform: np.ndarray) -> None:
    with pytest.raises(InvalidInputError):
        controller_frames(transform)


@pytest.mark.parametrize(
    ("convert", "value", "field"),
    [
        (matrix_from_ur, [0.0] * 5, "frames.ur"),
        (matrix_from_ur, [0.0, 0.0, 0.0, 0.0, 0.0, math.inf], "frames.ur"),
        (matrix_from_kuka, {"X": 0.0, "Y": 0.0, "Z": 0.0, "A": 0.0, "B": 0.0}, "frames.kuka"),
        (matrix_from_abb, [[0.0, 0.0, 0.0], [0.5, 0.5, 0.5, 0.6]], "frames.abb"),
        (matrix_from_abb, [[0.0, 0.0], [1.0, 0.0, 0.0, 0.0]], "frames.abb"),
        (matrix_from_fanuc, {"X": 0.0, "Y": 0.0, "Z": 0.0, "W": 0.0, "P": math.nan, "R": 0.0},
         "frames.fanuc"),
    ],
)  # fmt: skip
def test_bad_controller_frames_are_refused(
    convert: Callable[[Any], np.ndarray], value: object, field: str
) -> None:
    with pytest.raises(InvalidInputError) as caught:
        convert(value)
    assert caught.value.field == field


def test_many_quaternions_at_once_equal_one_at_a_time() -> None:
    """The batched form (imports of 20,000 waypoints) takes the same branch and sign row by row."""
    rng = np.random.default_rng(25)
    turns = [np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0])]
    rotations = np.concatenate([Rotation.random(500, random_state=rng).as_matrix(), turns])
    batched = quaternions_wxyz(rotations)
    single = np.array([quaternion_wxyz(r) for r in rotations])
    np.testing.assert_allclose(batched, single, rtol=0, atol=1e-15)
    scipy_wxyz = np.roll(Rotation.from_matrix(rotations).as_quat(), 1, axis=1)
    np.testing.assert_allclose(np.abs(np.sum(batched * scipy_wxyz, axis=1)), 1.0, atol=1e-12)
    assert np.all(batched[:, 0] >= 0.0)
