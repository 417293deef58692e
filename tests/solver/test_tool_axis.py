"""Tool-axis waypoints (cam.md section 1): the parallel-transport frame, near-unit axes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from solver.core.exceptions import InvalidInputError
from solver.core.task import task_requirements
from solver.core.tool_axis import near_unit, poses_from_tool_axes


def _tilting_about_y(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points along x with the tool axis tilting in the x-z plane (a great circle)."""
    positions = np.column_stack([np.linspace(0.0, 0.1, len(angles)), np.zeros((len(angles), 2))])
    axes = np.column_stack([-np.sin(angles), np.zeros(len(angles)), np.cos(angles)])
    return positions, axes


def test_frames_are_rotations_with_tool_z_against_the_axis() -> None:
    rng = np.random.default_rng(5)
    axes = rng.normal(size=(50, 3)) * 0.05 + np.array([0.0, 0.0, 1.0])
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    poses, correction = poses_from_tool_axes(rng.normal(size=(50, 3)), axes)
    rotations = poses[:, :3, :3]
    np.testing.assert_allclose(
        rotations @ rotations.transpose(0, 2, 1), np.broadcast_to(np.eye(3), (50, 3, 3)), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(rotations), 1.0, atol=1e-12)
    np.testing.assert_allclose(rotations[:, :, 2], -axes, atol=1e-12)
    assert correction < 1e-12


def test_first_frame_takes_the_workpiece_x_axis() -> None:
    poses, _ = poses_from_tool_axes(
        np.zeros((2, 3)),
        np.array([[0, 0, 1.0], [0, 0.1, 1.0]])
        / [
            [1.0],
            [np.hypot(0.1, 1.0)],
        ],
    )
    np.testing.assert_allclose(poses[0, :3, 0], [1.0, 0.0, 0.0], atol=1e-15)
    # A first axis along workpiece x: start from workpiece y instead.
    poses, _ = poses_from_tool_axes(np.zeros((2, 3)), np.array([[1.0, 0, 0], [1.0, 0, 0]]))
    np.testing.assert_allclose(poses[0, :3, 0], [0.0, 1.0, 0.0], atol=1e-15)


def test_parallel_transport_along_a_great_circle_is_the_turn_about_its_normal() -> None:
    """Geometry: the minimal-rotation frame along a tilt about y is Rot_y(tilt) of the first."""
    angles = np.linspace(0.0, 0.8, 40)
    positions, axes = _tilting_about_y(angles)
    poses, _ = poses_from_tool_axes(positions, axes)
    turns = Rotation.from_euler("y", (angles[0] - angles)[:, None]).as_matrix()
    np.testing.assert_allclose(poses[:, :3, :3], turns @ poses[0, :3, :3], atol=1e-12)
    # No spin about the tool axis anywhere: every segment's rotation vector is along y.
    requirements = task_requirements(poses)
    np.testing.assert_allclose(np.abs(requirements.u_R[:-1, 1]), 1.0, atol=1e-12)


def test_constant_spin_turns_each_frame_about_its_own_z_and_keeps_the_requirements() -> None:
    """cam.md section 3: R_i(theta) = R_i^ref Rot_z(theta); u_T, u_R and h do not change."""
    angles = np.linspace(0.0, 0.6, 25)
    positions, axes = _tilting_about_y(angles)
    reference, _ = poses_from_tool_axes(positions, axes)
    spun, _ = poses_from_tool_axes(positions, axes, spin=1.1)
    turn = Rotation.from_euler("z", 1.1).as_matrix()
    np.testing.assert_allclose(spun[:, :3, :3], reference[:, :3, :3] @ turn, atol=1e-12)
    before, after = task_requirements(reference), task_requirements(spun)
    np.testing.assert_allclose(after.u_T, before.u_T, atol=1e-12)
    np.testing.assert_allclose(after.u_R, before.u_R, atol=1e-12)
    np.testing.assert_allclose(after.h, before.h, rtol=1e-12)


def test_near_unit_axes_are_normalised_and_the_correction_reported() -> None:
    axes = np.array([[0.0, 0.0, 1.0004], [0.0, 0.0, 0.9999]])
    unit, correction = near_unit(axes, field="path.tool_axis_waypoints")
    np.testing.assert_allclose(np.linalg.norm(unit, axis=1), 1.0, atol=1e-15)
    assert correction == pytest.approx(4e-4, rel=1e-9)


@pytest.mark.parametrize(
    ("axis", "waypoint"),
    [([0.0, 0.0, 1.002], 1), ([0.0, 0.0, 0.0], 1), ([np.nan, 0.0, 1.0], 1)],
    ids=["off by 2e-3", "zero", "nan"],
)
def test_bad_axes_name_the_waypoint(axis: list[float], waypoint: int) -> None:
    axes = np.array([[0.0, 0.0, 1.0], axis, [0.0, 0.0, 1.0]])
    with pytest.raises(InvalidInputError) as error:
        poses_from_tool_axes(np.zeros((3, 3)), axes)
    assert (error.value.field, error.value.waypoint) == ("path.tool_axis_waypoints", waypoint)


def test_right_angle_turn_between_neighbours_is_refused() -> None:
    positions, axes = _tilting_about_y(np.array([0.0, np.pi / 2]))
    with pytest.raises(InvalidInputError) as error:
        poses_from_tool_axes(positions, axes)
    assert error.value.waypoint == 1


@pytest.mark.parametrize("along_x", [0.6, 0.985, 0.995])
def test_the_first_frame_leaves_the_workpiece_x_axis_beyond_0_99(along_x: float) -> None:
    """cam.md section 1: x_0 is the workpiece x axis projected onto the plane normal to z_0, the
    workpiece y axis where |x . z_0| > 0.99 (only 0 and 1 were tested: 0.999 passed them all;
    audit 24). The projection written here."""
    axis = np.array([along_x, 0.0, math.sqrt(1.0 - along_x**2)])
    poses, _ = poses_from_tool_axes(np.array([[0.0, 0, 0], [0.0, 0, 0.01]]), np.array([axis, axis]))
    z0 = -axis
    start = np.array([1.0, 0, 0]) if along_x <= 0.99 else np.array([0.0, 1, 0])
    projected = start - (start @ z0) * z0
    np.testing.assert_allclose(poses[0, :3, 0], projected / np.linalg.norm(projected), atol=1e-12)
