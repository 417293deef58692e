"""Task requirements: geometry of lines, arcs and rotations; repeated waypoints."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from solver.core.exceptions import InvalidInputError, RepeatedWaypointError
from solver.core.spatial import Placement, pose_matrix
from solver.core.task import task_requirements


def _pose(position, rotation=None) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = position
    if rotation is not None:
        pose[:3, :3] = rotation
    return pose


def test_straight_line_is_pure_translation() -> None:
    poses = np.array([_pose([0.01 * i, 0.02 * i, 0.0]) for i in range(5)])
    req = task_requirements(poses)
    assert np.all(np.isinf(req.h))
    np.testing.assert_allclose(req.u_T, np.tile([1, 2, 0], (5, 1)) / math.sqrt(5), atol=1e-15)
    np.testing.assert_allclose(req.u_R, 0.0)
    np.testing.assert_allclose(req.twists()[:, 3:], 0.0)


@pytest.mark.parametrize(("radius", "step"), [(0.05, 0.01), (0.5, 0.1), (2.0, 0.3)])
def test_arc_with_tool_normal_to_it(radius: float, step: float) -> None:
    """On a circle of radius r, tool normal to it: |dp| = 2 r sin(d/2), |dphi| = d, about y."""
    angles = step * np.arange(6)
    poses = np.array(
        [
            _pose([radius * math.sin(a), 0.0, radius * math.cos(a)], pin.utils.rotate("y", a))
            for a in angles
        ]
    )
    req = task_requirements(poses)
    np.testing.assert_allclose(req.h, 2 * radius * math.sin(step / 2) / step, rtol=1e-12)
    np.testing.assert_allclose(req.u_R, np.tile([0.0, 1.0, 0.0], (6, 1)), atol=1e-12)
    chord = (poses[1:, :3, 3] - poses[:-1, :3, 3]) / (2 * radius * math.sin(step / 2))
    np.testing.assert_allclose(req.u_T[:-1], chord, atol=1e-12)
    np.testing.assert_allclose(req.u_T[-1], req.u_T[-2])  # the last reuses segment N-2
    twists = req.twists()
    np.testing.assert_allclose(twists[:, 3:], req.u_R / req.h[:, None], rtol=1e-12)


def test_pure_reorientation_has_h_zero() -> None:
    poses = np.array([_pose([0.1, 0.2, 0.3], pin.utils.rotate("z", 0.1 * i)) for i in range(3)])
    req = task_requirements(poses)
    np.testing.assert_array_equal(req.h, 0.0)
    np.testing.assert_allclose(req.u_T, 0.0)
    np.testing.assert_allclose(req.u_R, np.tile([0, 0, 1.0], (3, 1)), atol=1e-12)
    np.testing.assert_allclose(req.twists(), np.tile([0, 0, 0, 0, 0, 1.0], (3, 1)), atol=1e-12)


def test_requirements_rotate_with_yaw_and_h_does_not() -> None:
    rng = np.random.default_rng(4)
    poses = np.array(
        [_pose(rng.normal(size=3) * 0.1, pin.utils.rotate("x", rng.normal())) for _ in range(6)]
    )
    yaw = 0.7
    turned = Placement(0.3, -0.2, 0.1, yaw).transform_workpiece_to_base() @ poses
    original, rotated = task_requirements(poses), task_requirements(turned)
    rot = pin.utils.rotate("z", yaw)
    # log3 recovers a rotation angle from the trace of R, to ~1e-12 relative at these angles.
    np.testing.assert_allclose(rotated.h, original.h, rtol=1e-10)
    np.testing.assert_allclose(rotated.u_T, original.u_T @ rot.T, atol=1e-12)
    np.testing.assert_allclose(rotated.u_R, original.u_R @ rot.T, atol=1e-12)


def test_repeated_waypoint_names_its_index() -> None:
    quaternion = [0.0, 0.0, 0.38268343236509, 0.923879532511287]
    flipped = [-v for v in quaternion]  # -q is the same rotation
    poses = np.array(
        [
            pose_matrix([0, 0, 0], quaternion, field="w"),
            pose_matrix([0.01, 0, 0], quaternion, field="w"),
            pose_matrix([0.02, 0, 0], quaternion, field="w"),
            pose_matrix([0.02, 0, 0], flipped, field="w"),
        ]
    )
    with pytest.raises(RepeatedWaypointError) as info:
        task_requirements(poses)
    assert info.value.waypoint == 3
    assert info.value.field == "path.waypoints"
    assert "waypoint 3" in str(info.value)


@pytest.mark.parametrize(
    ("poses", "waypoint"),
    [
        (np.eye(4)[None], None),
        (np.array([np.eye(4), np.full((4, 4), np.nan)]), 1),
        (np.array([np.eye(4), np.diag([1.0, 1.0, -1.0, 1.0])]), 1),
    ],
)
def test_bad_path(poses: np.ndarray, waypoint: int | None) -> None:
    with pytest.raises(InvalidInputError) as info:
        task_requirements(poses)
    assert info.value.waypoint == waypoint


def test_a_quaternion_off_unit_by_more_than_1e_3_is_refused_within_it_normalised() -> None:
    """cam.md section 6: papers print 4 decimals, CAM writes 4-6."""
    with pytest.raises(InvalidInputError, match="norm"):
        pose_matrix([0, 0, 0], [0, 0, 0, 1.0011], field="path.waypoints")
    pose = pose_matrix([0, 0, 0], [0, 0, 0, 1.0009], field="path.waypoints")
    np.testing.assert_allclose(pose[:3, :3], np.eye(3), atol=1e-15)
    half = 0.7071  # cos 45 deg as printed: the turn about z by 90 deg, normalised
    pose = pose_matrix([0, 0, 0], [0, 0, half, half], field="path.waypoints")
    np.testing.assert_allclose(pose[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)


def test_far_positions_are_refused() -> None:
    """Positions beyond 1 km are an input error (metres were probably meant to be mm)."""
    poses = np.array([_pose([0.0, 0.0, 0.0]), _pose([1e308, 0.0, 0.0])])
    with pytest.raises(InvalidInputError, match="metres") as info:
        task_requirements(poses)
    assert info.value.waypoint == 1
    with pytest.raises(InvalidInputError) as placement:
        Placement(0.0, 2e3, 0.0, 0.0)
    assert placement.value.field == "placement"
