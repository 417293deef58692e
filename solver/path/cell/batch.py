"""The fast cell check of many joint paths in one compiled call (a map's chunk at once).

:func:`first_due_paths` runs :func:`solver.path.cell.sweep.first_due` from the start of every
path, its sub-steps made inside (:func:`solver.path.cell.kinematics.substeps`, the same floats)
and each path against the obstacles at its own placement: one call for a chunk's paths, where
one call a path cost about 20 microseconds of dispatch and a few hundred of Python each. The
paths it leaves at a configuration where coal must decide go on one by one
(:func:`solver.path.cell.fast.resume`), as a single check does, so every answer is the single
check's (:meth:`solver.path.cell.checker.CellChecker.check`).

:func:`placed_obstacles` gives the obstacle arrays of many placements at once: the ``fixed``
objects as built, the ``workpiece`` ones moved (:meth:`solver.path.cell.capsules.Primitive.placed`
done for every placement in one array operation).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numpy as np
import pinocchio as pin
from numba import njit

from solver.path.cell.capsules import HALFSPACE
from solver.path.cell.fast import MARGIN, CoalDistances, FastCell, resume
from solver.path.cell.kernel_cache import drop_stale_cell_kernels
from solver.path.cell.kinematics import substeps
from solver.path.cell.sweep import first_due

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in

V = TypeVar("V")  # a verdict


def placed_obstacles(
    fast: FastCell, moved: dict[int, np.ndarray], count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The obstacle arrays a placement changes, for N placements.

    Args:
        fast: the compiled side of the checker.
        moved: obstacle index k -> shape (N, 4, 4), its pose in the world at each placement.
        count: N.

    Returns:
        ends (N, K, 2, 3), radius (N, K), rotation (N, K, 3, 3), centre (N, K, 3), vertices
        (N, V, 3): the obstacle pack's (:mod:`solver.path.cell.sweep`), per placement.
    """
    _, ends, radius, rotations, centres, _, _, offsets, vertices, _ = fast.obstacle_pack({})
    out = [np.repeat(a[None], count, axis=0) for a in (ends, radius, rotations, centres, vertices)]
    ends_n, radius_n, rotations_n, centres_n, vertices_n = out
    for k, at in moved.items():
        shape = fast.obstacles[k]
        rotation, translation = at[:, :3, :3], at[:, :3, 3]
        rotations_n[:, k], centres_n[:, k] = rotation, translation
        if shape.kind == HALFSPACE:
            normal = rotation @ shape.ends[0]
            ends_n[:, k, 0], ends_n[:, k, 1] = normal, 0.0
            radius_n[:, k] = shape.radius + np.einsum("ni,ni->n", normal, translation)
            continue
        ends_n[:, k] = shape.ends @ rotation.transpose(0, 2, 1) + translation[:, None]
        at_vertices = shape.vertices @ rotation.transpose(0, 2, 1) + translation[:, None]
        vertices_n[:, offsets[k] : offsets[k + 1]] = at_vertices
    return ends_n, radius_n, rotations_n, centres_n, vertices_n


@njit(cache=True, nogil=True, error_model="numpy")
def first_due_paths(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    joint_paths,
    segment_in_pass,
    collision_step,
    robot,
    kind,
    ends,
    radius,
    rotation,
    centre,
    half,
    exact,
    offsets,
    vertices,
    ball,
    pairs,
    weights,
    tables,
    near,
    clearance,
    clear_until,
    index,
    need,
):
    """:func:`solver.path.cell.sweep.first_due` from the start of each of N joint paths.

    Args:
        joint_paths: shape (N, W, n), rad, the tracked joint paths.
        segment_in_pass: shape (W - 1,), bool, False where a rapid joins two passes.
        collision_step: rad, the sub-steps' largest joint move.
        robot: the sweep's robot pack.
        kind: shape (K,), the obstacle pack's, shared by the placements (as the next four).
        ends: shape (N, K, 2, 3), per path (as the next four; :func:`placed_obstacles`).
        radius: shape (N, K).
        rotation: shape (N, K, 3, 3).
        centre: shape (N, K, 3).
        half: shape (K, 3).
        exact: shape (K,).
        offsets: shape (K + 1,).
        vertices: shape (N, V, 3).
        ball: shape (K,).
        pairs: shape (P, 2).
        weights: shape (P, n), :func:`first_due`'s.
        tables: :func:`first_due`'s.
        near: m, :func:`first_due`'s.
        clearance: m.
        clear_until: shape (N, P), out, as :func:`first_due` leaves it for each path.
        index: shape (N,), out, the configuration where coal must decide, or -1 where the
            path is clear.
        need: shape (N, P), bool, out, the pairs coal must decide there.
    """
    known = np.full(pairs.shape[0], np.nan)
    start = np.int64(0)  # not the literal 0: first_due's one compiled signature, fast.py's too
    for c in range(joint_paths.shape[0]):
        configurations, _ = substeps(joint_paths[c], segment_in_pass, collision_step)
        obstacles = (kind, ends[c], radius[c], rotation[c], centre[c], half, exact, offsets,
                     vertices[c], ball)  # fmt: skip
        clear_until[c, :] = -1
        at = first_due(
            configurations, robot, obstacles, pairs, weights, tables, near, clearance,
            clear_until[c], start, known, need[c],
        )  # fmt: skip
        index[c] = -1 if at >= configurations.shape[0] else at


def check_paths(
    fast: FastCell,
    joint_paths: np.ndarray,
    segment_in_pass: np.ndarray,
    moved: dict[int, list[pin.SE3]],
    settings: tuple[np.ndarray, float, float],
    coal_of: Callable[[int, np.ndarray], CoalDistances],
    finish: Callable[[tuple[int, int, float] | None, int, np.ndarray], V],
) -> list[V]:
    """The first collision of each of N joint paths, as the single check finds it.

    Args:
        fast: the compiled side of the checker.
        joint_paths: shape (N, W, n), rad.
        segment_in_pass: shape (W - 1,), bool.
        moved: workpiece obstacle k -> its pose in the world at each path's placement (N).
        settings: the pairs' weights (P, n), the clearance (m), the collision step (rad).
        coal_of: path c and its configurations -> coal's distances at its placement.
        finish: the verdict of an answer (configuration, pair, distance; the coal checks; the
            configurations' waypoints).
    """
    weights, clearance, step = settings
    count, n_pairs = len(joint_paths), len(fast.pairs)
    world = {k: np.array([at.homogeneous for at in poses]) for k, poses in moved.items()}
    ends, radius, rotation, centre, vertices = placed_obstacles(fast, world, count)
    kind, _, _, _, _, half, exact, offsets, _, ball = fast.obstacle_pack({})
    clear_until = np.empty((count, n_pairs), dtype=np.int64)
    index = np.empty(count, dtype=np.int64)
    need = np.zeros((count, n_pairs), dtype=np.bool_)
    first_due_paths(
        joint_paths, segment_in_pass, step, fast.robot, kind, ends, radius, rotation, centre,
        half, exact, offsets, vertices, ball, fast.pairs, weights, fast.tables, clearance + MARGIN,
        clearance, clear_until, index, need,
    )  # fmt: skip
    verdicts = []
    clear = np.empty(0, dtype=np.int64)  # no configuration's waypoint is asked for
    for c in range(count):
        if index[c] < 0:
            verdicts.append(finish(None, 0, clear))
            continue
        configurations, owners = substeps(joint_paths[c], segment_in_pass, step)
        obstacles = (kind, ends[c], radius[c], rotation[c], centre[c], half, exact, offsets,
                     vertices[c], ball)  # fmt: skip
        hit, checks = resume(
            fast, configurations, obstacles, weights, clearance, coal_of(c, configurations),
            (int(index[c]), clear_until[c], need[c]),
        )  # fmt: skip
        verdicts.append(finish(hit, checks, owners))
    return verdicts
