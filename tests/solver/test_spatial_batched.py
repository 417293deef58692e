"""Batched poses and waypoint checks equal their one-at-a-time definitions, errors included."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import pose_matrices, pose_matrix, rotation_vectors
from solver.core.task import check_waypoints


def random_poses(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    quaternions = rng.normal(size=(n, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    quaternions *= 1.0 + rng.uniform(-9e-4, 9e-4, size=(n, 1))  # within the 1e-3 tolerance
    return rng.uniform(-1, 1, size=(n, 3)), quaternions


def test_pose_matrices_equal_scipy_and_the_scalar_pose() -> None:
    positions, quaternions = random_poses(200, 1)
    batched = pose_matrices(positions, quaternions, field="path.waypoints")
    expected = Rotation.from_quat(quaternions).as_matrix()  # scipy normalises too
    np.testing.assert_allclose(batched[:, :3, :3], expected, atol=1e-14)
    np.testing.assert_array_equal(batched[:, :3, 3], positions)
    for i in (0, 57, 199):
        np.testing.assert_allclose(
            batched[i], pose_matrix(positions[i], quaternions[i], field="f"), atol=1e-15
        )


@pytest.mark.parametrize(
    ("row", "position", "quaternion", "message"),
    [
        (3, [0.0, math.nan, 0.0], [0, 0, 0, 1], "position needs 3 finite numbers"),
        (5, [2000.0, 0.0, 0.0], [0, 0, 0, 1], "is beyond"),
        (7, [0.0, 0.0, 0.0], [0, 0, 0, 1.01], "quaternion norm is 1.01"),
        (9, [0.0, 0.0, 0.0], [0, 0, math.inf, 1], "needs 4 finite numbers"),
    ],
)
def test_the_first_bad_pose_gives_the_scalar_error(
    row: int, position: list[float], quaternion: list[float], message: str
) -> None:
    positions, quaternions = random_poses(12, 2)
    positions[row], quaternions[row] = position, quaternion
    positions[row + 1], quaternions[row + 1] = [0.0, 0.0, math.nan], [0, 0, 0, 2]  # later
    with pytest.raises(InvalidInputError, match=message) as error:
        pose_matrices(positions, quaternions, field="path.waypoints")
    assert error.value.field == f"path.waypoints.{row}"


def test_check_waypoints_names_the_first_bad_waypoint() -> None:
    positions, quaternions = random_poses(10, 3)
    poses = pose_matrices(positions, quaternions, field="p")
    np.testing.assert_array_equal(check_waypoints(poses), poses)
    for row, change, message in [
        (4, lambda p: p.__setitem__((0, 0), math.nan), "not finite"),
        (6, lambda p: p.__setitem__((1, 3), 5000.0), "is beyond"),
        (2, lambda p: p.__setitem__((0, 1), 0.1), "not a rotation"),
        (8, lambda p: p.__setitem__((slice(0, 3), 0), -p[:3, 0]), "not a rotation"),  # det < 0
    ]:
        bad = poses.copy()
        change(bad[row])
        bad[9, 0, 0] = math.nan  # a later bad waypoint is not the one named
        with pytest.raises(InvalidInputError, match=message) as error:
            check_waypoints(bad)
        assert error.value.waypoint == row


ANGLES = [1e-12, 1e-7, 1e-4 - 1e-12, 1e-4 + 1e-12, 0.1, 1.0, 3.0, math.pi - 1e-2, math.pi - 1e-6]


@pytest.mark.parametrize("angle", ANGLES)
def test_rotation_vectors_are_the_known_ones_and_log3s(angle: float) -> None:
    """Geometry: R = exp(theta u) for known unit axes u (scipy builds R); log(R) = theta u."""
    rng = np.random.default_rng(7)
    axes = rng.normal(size=(50, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    known = angle * axes
    rotations = Rotation.from_rotvec(known).as_matrix()
    vectors = rotation_vectors(rotations)
    # Near a half turn the skew part holds the axis only to eps / sin(theta): 1e-11 at 1e-2.
    tolerance = 1e-14 if angle < 3.0 else 1e-11
    np.testing.assert_allclose(vectors, known, rtol=0, atol=tolerance)
    np.testing.assert_allclose(
        vectors, [pin.log3(r) for r in rotations], rtol=0, atol=max(tolerance, 1e-15)
    )
    # Batch axes are kept: (5, 10, 3, 3) -> (5, 10, 3), the same vectors.
    np.testing.assert_array_equal(
        rotation_vectors(rotations.reshape(5, 10, 3, 3)), vectors.reshape(5, 10, 3)
    )
