"""The compiled sweep of a joint path through the cell: link frames and distance bounds.

For every configuration the joints' frames (pinocchio's forward kinematics, recomputed here
from the model's joint placements, revolute and prismatic joints), every robot part's capsule
in the world, and for each checked pair a lower bound on its distance (:mod:`closed_form`):
exact where both shapes are capsules, spheres, boxes or halfspaces, the distance between the
bounding capsules otherwise. :func:`first_due` walks a path as
:meth:`solver.path.cell.checker.CellChecker.check` does for a map (conservative advancement,
:mod:`solver.path.cell.bounds`), returning where coal must decide a pair; :func:`bounds` gives
every configuration's bounds at once (an evaluation).

The packs (:class:`solver.path.cell.fast.FastCell` builds them):
- robot: parent (J,), joint rotation (J, 3, 3) and translation (J, 3) in the parent, kind (J,)
  (0 fixed, 1 revolute, 2 prismatic), axis (J, 3), q index (J,); part joint (R,), part ends
  (R, 2, 3) in the joint's frame, part radius (R,).
- obstacles: kind (K,) (0 halfspace: normal ``ends[k, 0]``, offset ``radius[k]``; 1 capsule or
  sphere: ends, radius; 2 box: rotation, centre, half sizes), ends (K, 2, 3), radius (K,),
  rotation (K, 3, 3), centre (K, 3), half sizes (K, 3), all in the world.
- pairs: (P, 2), a robot part, then a part (< R) or an obstacle (R + k).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.path.cell.closed_form import (
    segment_box,
    segment_halfspace,
    segment_segment,
)


@njit(cache=True, nogil=True, error_model="numpy")
def _frames(q, robot, rot, pos):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The joints' world rotations (J, 3, 3) and origins (J, 3) at q, into rot and pos."""
    parent, jrot, jpos, kind, axis, qi = robot[0], robot[1], robot[2], robot[3], robot[4], robot[5]
    for i in range(3):
        pos[0, i] = 0.0
        for k in range(3):
            rot[0, i, k] = 1.0 if i == k else 0.0
    turn = np.empty((3, 3))
    for j in range(1, len(parent)):
        p = parent[j]
        for i in range(3):
            pos[j, i] = pos[p, i]
            for k in range(3):
                pos[j, i] += rot[p, i, k] * jpos[j, k]
                rot[j, i, k] = 0.0
                for m in range(3):
                    rot[j, i, k] += rot[p, i, m] * jrot[j, m, k]
        value = q[qi[j]]
        if kind[j] == 2:
            for i in range(3):
                for k in range(3):
                    pos[j, i] += rot[j, i, k] * axis[j, k] * value
        elif kind[j] == 1:
            c, s = math.cos(value), math.sin(value)
            x, y, z = axis[j, 0], axis[j, 1], axis[j, 2]
            turn[0, 0], turn[0, 1], turn[0, 2] = (
                c + x * x * (1 - c),
                x * y * (1 - c) - z * s,
                x * z * (1 - c) + y * s,
            )
            turn[1, 0], turn[1, 1], turn[1, 2] = (
                y * x * (1 - c) + z * s,
                c + y * y * (1 - c),
                y * z * (1 - c) - x * s,
            )
            turn[2, 0], turn[2, 1], turn[2, 2] = (
                z * x * (1 - c) - y * s,
                z * y * (1 - c) + x * s,
                c + z * z * (1 - c),
            )
            for i in range(3):
                r0, r1, r2 = rot[j, i, 0], rot[j, i, 1], rot[j, i, 2]
                for k in range(3):
                    rot[j, i, k] = r0 * turn[0, k] + r1 * turn[1, k] + r2 * turn[2, k]


@njit(cache=True, nogil=True, error_model="numpy")
def _parts(q, robot, rot, pos, ends):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Every robot part's capsule ends in the world at q, into ends (R, 2, 3)."""
    _frames(q, robot, rot, pos)
    joint, local = robot[6], robot[7]
    for r in range(len(joint)):
        j = joint[r]
        for e in range(2):
            for i in range(3):
                ends[r, e, i] = (
                    pos[j, i]
                    + rot[j, i, 0] * local[r, e, 0]
                    + rot[j, i, 1] * local[r, e, 1]
                    + rot[j, i, 2] * local[r, e, 2]
                )


@njit(cache=True, nogil=True, error_model="numpy")
def _bound(p, pairs, ends, robot, obstacles, local):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """A lower bound on pair p's distance (exact for closed-form pairs), m."""
    radius = robot[8]
    a, b = pairs[p, 0], pairs[p, 1]
    n_robot = len(radius)
    if b < n_robot:
        gap = segment_segment(ends[a, 0], ends[a, 1], ends[b, 0], ends[b, 1])
        return gap - radius[a] - radius[b]
    k = b - n_robot
    kind, o_ends, o_radius, o_rot, o_centre, o_half = obstacles
    if kind[k] == 0:
        return segment_halfspace(ends[a, 0], ends[a, 1], radius[a], o_ends[k, 0], o_radius[k])
    if kind[k] == 1:
        gap = segment_segment(ends[a, 0], ends[a, 1], o_ends[k, 0], o_ends[k, 1])
        return gap - radius[a] - o_radius[k]
    for e in range(2):  # into the box's frame
        for i in range(3):
            local[e, i] = 0.0
            for m in range(3):
                local[e, i] += o_rot[k, m, i] * (ends[a, e, m] - o_centre[k, m])
    return segment_box(local[0], local[1], o_half[k]) - radius[a]


@njit(cache=True, nogil=True, error_model="numpy")
def bounds(configurations, robot, obstacles, pairs):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Every pair's distance bound at every configuration: shape (M, P), m."""
    n_joints, n_parts = len(robot[0]), len(robot[8])
    rot, pos = np.empty((n_joints, 3, 3)), np.empty((n_joints, 3))
    ends, local = np.empty((n_parts, 2, 3)), np.empty((2, 3))
    out = np.empty((len(configurations), len(pairs)))
    for m in range(len(configurations)):
        _parts(configurations[m], robot, rot, pos, ends)
        for p in range(len(pairs)):
            out[m, p] = _bound(p, pairs, ends, robot, obstacles, local)
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def first_due(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    configurations,
    robot,
    obstacles,
    pairs,
    weights,
    near,
    clearance,
    clear_until,
    start,
    known,
    need,
):
    """Walk the path from ``start`` to the first configuration where coal must decide a pair.

    A pair is due at a configuration its last distance does not prove clear; a due pair whose
    bound is ``near`` (m) or less needs coal there. A due pair at ``start`` with a finite
    ``known`` distance (coal's, from the caller) takes that. Every pair's clear configurations
    are advanced as in :mod:`solver.path.cell.bounds`: from a distance d at configuration i the
    pair is clear up to the last m with sum_j w_pj |q_mj - q_ij| < d - clearance.

    Args:
        configurations: shape (M, n), the path's configurations.
        robot: the robot pack.
        obstacles: the obstacle pack.
        pairs: shape (P, 2).
        weights: shape (P, n), how fast each pair can close in (:mod:`bounds`).
        near: m, a bound at or below this goes to coal.
        clearance: m, the cell's clearance.
        clear_until: shape (P,), in and out: the last configuration each pair is proven clear.
        start: the configuration to start at.
        known: shape (P,), coal's distances at ``start`` (NaN where none).
        need: shape (P,), bool, out: the pairs coal must decide at the returned configuration.

    Returns:
        That configuration's index, or M when the path is clear.
    """
    n_joints, n_parts = len(robot[0]), len(robot[8])
    rot, pos = np.empty((n_joints, 3, 3)), np.empty((n_joints, 3))
    ends, local = np.empty((n_parts, 2, 3)), np.empty((2, 3))
    count, n_pairs = len(configurations), len(pairs)
    index = start
    while index < count:
        placed, needed = False, False
        for p in range(n_pairs):
            need[p] = False
            if clear_until[p] >= index:
                continue
            if index == start and np.isfinite(known[p]):
                distance = known[p]
            else:
                if not placed:
                    _parts(configurations[index], robot, rot, pos, ends)
                    placed = True
                distance = _bound(p, pairs, ends, robot, obstacles, local)
                if distance <= near:
                    need[p] = needed = True
                    continue
            slack = distance - clearance
            m = index + 1
            while m < count:
                moved = 0.0
                for j in range(configurations.shape[1]):
                    moved += weights[p, j] * abs(configurations[m, j] - configurations[index, j])
                if moved >= slack:
                    break
                m += 1
            clear_until[p] = m - 1
        if needed:
            return index
        index = clear_until.min() + 1
    return count
