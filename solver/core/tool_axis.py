"""Waypoints given by a tool point and a tool axis, as 5-axis CAM writes them (cam.md section 1).

CAM gives (x, y, z, i, j, k): the tool tip and the tool axis from the tip back towards the
holder. The robot's tool z points out of the flange towards the tip, so tool z = -(i, j, k). The
rotation about the axis (the tool spin) is not given; the reference frame is the minimal-rotation
one (parallel transport): x_0 is the workpiece x axis projected onto the plane normal to z_0 (the
workpiece y axis when |x . z_0| > 0.99), x_{i+1} is x_i less its component along z_{i+1},
normalised, and y_i = z_i x x_i. A spin theta turns waypoint i about its own z:
R_i(theta) = R_i^ref Rot_z(theta) (cam.md section 3).
"""

from __future__ import annotations

import math

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import rotation_about_z

# A direction whose norm is within this of 1 is normalised (and the correction reported);
# beyond it, it is an input error (cam.md section 6: CAM writes 4-6 decimals, papers print 4).
NEAR_UNIT_TOLERANCE = 1e-3
_PARALLEL = 0.99  # |x . z_0| above this: start from the workpiece y axis instead


def near_unit(vectors: np.ndarray, *, field: str) -> tuple[np.ndarray, float]:
    """Directions normalised, if each is unit to within NEAR_UNIT_TOLERANCE.

    Args:
        vectors: shape (N, 3), dimensionless.
        field: the input's name, for the error (the waypoint index is added).

    Returns:
        The unit vectors, shape (N, 3), and the largest correction | |v| - 1 |.

    Raises:
        InvalidInputError: a vector that is not finite or is off unit by more than the tolerance.
    """
    arr = np.asarray(vectors, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InvalidInputError(field, f"{arr.shape=}, needs (N, 3)")
    with np.errstate(over="ignore", invalid="ignore"):
        norms = np.linalg.norm(arr, axis=1)
    bad = np.flatnonzero(~np.isfinite(norms) | (np.abs(norms - 1.0) > NEAR_UNIT_TOLERANCE))
    if bad.size:
        i = int(bad[0])
        raise InvalidInputError(
            field,
            f"the vector {arr[i].tolist()} has length {float(norms[i]):.6g}; a unit vector is "
            f"needed (within {NEAR_UNIT_TOLERANCE:g}, where it is normalised)",
            waypoint=i,
        )
    correction = float(np.max(np.abs(norms - 1.0))) if len(arr) else 0.0
    return arr / norms[:, None], correction


def reference_rotations(tool_z: np.ndarray) -> np.ndarray:
    """The parallel-transport frames R_i^ref = [x_i y_i z_i] of unit tool axes.

    Args:
        tool_z: shape (N, 3), unit tool z axes in {O} (towards the tip).

    Returns:
        shape (N, 3, 3), rotation matrices R_O_i (columns x_i, y_i, z_i).

    Raises:
        InvalidInputError: x_i lies along z_{i+1} (the axis turns by a right angle towards x_i
            in one step), so transport is undefined.
    """
    z = np.asarray(tool_z, dtype=float)
    frames = np.empty((len(z), 3, 3))
    start = (1.0, 0.0, 0.0)
    if len(z) and abs(float(z[0, 0])) > _PARALLEL:
        start = (0.0, 1.0, 0.0)
    x0, x1, x2 = start
    xs = np.empty((len(z), 3))
    # Sequential by nature (each x is the last one transported), so in plain floats: numpy's
    # per-call overhead on 3-vectors made this loop most of the time of a 10,000-point import.
    for i, (a0, a1, a2) in enumerate(z.tolist()):
        dot = x0 * a0 + x1 * a1 + x2 * a2
        x0, x1, x2 = x0 - dot * a0, x1 - dot * a1, x2 - dot * a2
        norm = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        if norm < 1e-9:
            raise InvalidInputError(
                "path.tool_axis_waypoints",
                "the tool axis turns by a right angle from the previous waypoint (towards the "
                "reference x axis): the reference frame is undefined there",
                waypoint=i,
            )
        x0, x1, x2 = x0 / norm, x1 / norm, x2 / norm
        xs[i] = x0, x1, x2
    frames[:, :, 0] = xs
    frames[:, :, 1] = np.cross(z, xs)
    frames[:, :, 2] = z
    return frames


def poses_from_tool_axes(
    positions: np.ndarray, axes: np.ndarray, *, spin: float = 0.0
) -> tuple[np.ndarray, float]:
    """Tool point poses T_O_i from CAM tool points and tool axes (cam.md sections 1 and 3).

    Args:
        positions: shape (N, 3), m, tool tips in {O}.
        axes: shape (N, 3), tool axes as CAM writes them (tip towards holder), unit to 1e-3.
        spin: rad, a constant spin about every waypoint's tool z.

    Returns:
        The poses, shape (N, 4, 4), and the largest correction made to an axis's length.

    Raises:
        InvalidInputError: an axis off unit by more than 1e-3, or a right-angle turn between
            neighbours.
    """
    unit, correction = near_unit(axes, field="path.tool_axis_waypoints")
    rotations = reference_rotations(-unit)
    if spin:
        rotations = rotations @ rotation_about_z(spin)
    poses = np.broadcast_to(np.eye(4), (len(unit), 4, 4)).copy()
    poses[:, :3, :3] = rotations
    poses[:, :3, 3] = np.asarray(positions, dtype=float)
    return poses, correction
