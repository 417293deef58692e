"""A chunk's placements: checked, and the path's flange poses turned and moved to them in {B}.

t_hat and the poses are computed once in {O} (:mod:`solver.path.prepare`) and only turned by
each placement's yaw and moved by its position (dtf.md section 9); the batched layout of
placements is (P, 5) [x, y, z, yaw, spin] (:meth:`solver.core.spatial.Placement.as_row`).
"""

from __future__ import annotations

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import MAX_COORDINATE, rotation_about_z
from solver.path.prepare import PreparedPath
from solver.path.problem import PathProblem


def check_placements(placements: np.ndarray) -> np.ndarray:
    """Placements as a float array (P, 5) of finite [x, y, z, yaw, spin] within MAX_COORDINATE.

    The one batched layout of placements (:meth:`solver.core.spatial.Placement.as_row`); (P, 4)
    arrays without the spin are taken with spin 0.

    Raises:
        InvalidInputError: wrong shape, not finite, or too far.
    """
    arr = np.asarray(placements, dtype=float)
    if arr.ndim == 2 and arr.shape[1] == 4:
        arr = np.column_stack([arr, np.zeros(len(arr))])
    if arr.ndim != 2 or arr.shape[1] != 5:
        raise InvalidInputError("placements", f"{arr.shape=}, needs (P, 5): x, y, z, yaw, spin")
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr[:, :3]) > MAX_COORDINATE):
        raise InvalidInputError(
            "placements", f"need finite values, positions within {MAX_COORDINATE} m"
        )
    return arr


def turn_by_yaw(vectors: np.ndarray, yaws: np.ndarray) -> np.ndarray:
    """Rz(yaw) v for every yaw: vectors (3, ..., W) in {O} -> (3, ..., C, W), C-contiguous.

    Args:
        vectors: shape (3, ..., W), in {O}.
        yaws: shape (C,), rad (C = 1 broadcasts one turn over a chunk).
    """
    cos, sin = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    x, y = vectors[0][..., None, :], vectors[1][..., None, :]
    z = np.broadcast_to(vectors[2][..., None, :], np.broadcast_shapes(x.shape, cos.shape))
    return np.stack([cos * x - sin * y, sin * x + cos * y, z])


def flange_at_spin(path: PreparedPath, spin: float) -> tuple[np.ndarray, np.ndarray]:
    """R_O_F (N, 3, 3) and p_O_F (N, 3) with every tool pose turned by ``spin`` about its z."""
    if spin == 0.0:
        return path.flange_rotation, path.flange_position
    turned = path.tool_rotation @ rotation_about_z(spin)
    rotation = turned @ path.tool_to_flange[:3, :3]
    position = path.tool_position + turned @ path.tool_to_flange[:3, 3]
    return rotation, position


def placed_flange(
    problem: PathProblem, placements: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The yaws and the flange poses in {B} of a chunk's placements (one spin).

    Returns:
        yaws: shape (C,), rad, or (1,) where they are all one (broadcast: less to read);
        R_B_F: shape (3, 3, C, W); p_B_F: shape (3, C, W), m.
    """
    yaws = placements[:, 3]
    if np.all(yaws == yaws[0]):
        yaws = yaws[:1]
    if np.any(placements[:, 4] != placements[0, 4]):
        raise InvalidInputError("placements", "a chunk must have one spin")
    offset = placements[:, :3].T[:, :, None]  # (3, C, 1)
    flange_rotation, flange_position_o = flange_at_spin(problem.prepared, float(placements[0, 4]))
    rotation = turn_by_yaw(flange_rotation.transpose(1, 2, 0), yaws)  # (3, 3, C, W)
    flange_position = turn_by_yaw(flange_position_o.T, yaws) + offset
    return yaws, rotation, flange_position
