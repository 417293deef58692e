"""The compiled sweep of a joint path through the cell: link frames and distance bounds.

For every configuration the joints' frames (pinocchio's forward kinematics, recomputed here
from the model's joint placements, revolute and prismatic joints), every robot part's capsule
in the world, and for each checked pair a lower bound on its distance (:mod:`closed_form`):
exact where both shapes are capsules, spheres, boxes or halfspaces; otherwise the distance
between bounding capsules, raised where that is near the clearance to the shapes' separation
along a few directions (support functions of their vertices: convex meshes, boxes, a prism
around a cylinder; exact against a halfspace), after a tabulated bound for the self pairs
whose capsules overlap at most configurations (:mod:`solver.path.cell.pair_tables`).
:func:`first_due` walks a path as
:meth:`solver.path.cell.checker.CellChecker.check` does for a map (conservative advancement,
:mod:`solver.path.cell.bounds`), returning where coal must decide a pair.

The packs (:class:`solver.path.cell.fast.FastCell` builds them):
- robot: parent (J,), joint rotation (J, 3, 3) and translation (J, 3) in the parent, kind (J,)
  (0 fixed, 1 revolute, 2 prismatic), axis (J, 3), q index (J,); part joint (R,), part ends
  (R, 2, 3) in the joint's frame, part radius (R,), exact (R,), vertex offsets (R + 1,),
  vertices (V, 3) in the joint's frame, ball radius (R,) (:class:`capsules.Primitive`).
- obstacles: kind (K,) (0 halfspace: normal ``ends[k, 0]``, offset ``radius[k]``; 1 capsule or
  sphere: ends, radius; 2 box: rotation, centre, half sizes), ends (K, 2, 3), radius (K,),
  rotation (K, 3, 3), centre (K, 3), half sizes (K, 3), exact (K,), vertex offsets (K + 1,),
  vertices (V, 3), ball radius (K,), all in the world.
- pairs: (P, 2), a robot part, then a part (< R) or an obstacle (R + k).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.path.cell.advance import clear_until as advance
from solver.path.cell.closed_form import (
    box_param,
    params,
    segment_box_param,
    segment_halfspace,
    segment_params,
)
from solver.path.cell.kinematics import parts as _parts
from solver.path.cell.pair_tables import table_bound


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _reach(r, u, robot, rot, pos, point):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The largest u . x over robot part r's points (its vertices' plus its ball's radius).

    The vertex reaching farthest goes into ``point`` (world).
    """
    j, offsets, vertices = robot[6][r], robot[10], robot[11]
    u0 = rot[j, 0, 0] * u[0] + rot[j, 1, 0] * u[1] + rot[j, 2, 0] * u[2]
    u1 = rot[j, 0, 1] * u[0] + rot[j, 1, 1] * u[1] + rot[j, 2, 1] * u[2]
    u2 = rot[j, 0, 2] * u[0] + rot[j, 1, 2] * u[1] + rot[j, 2, 2] * u[2]
    best, at = -np.inf, offsets[r]
    for v in range(offsets[r], offsets[r + 1]):
        value = u0 * vertices[v, 0] + u1 * vertices[v, 1] + u2 * vertices[v, 2]
        if value > best:
            best, at = value, v
    for i in range(3):
        point[i] = pos[j, i]
        for k in range(3):
            point[i] += rot[j, i, k] * vertices[at, k]
    return best + u[0] * pos[j, 0] + u[1] * pos[j, 1] + u[2] * pos[j, 2] + robot[12][r]


@njit(cache=True, nogil=True, error_model="numpy")
def _gap(a, b, u, robot, obstacles, rot, pos, work, tries, enough):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """How far part a and object b are apart along the unit u (from a to b): a lower bound.

    Then along the directions of a Frank-Wolfe descent on the least vector of the vertex sets'
    Minkowski difference (b's points less a's): each step takes the support point s (b's lowest
    vertex less a's farthest along the current direction) and moves the vector z towards it,
    with an exact line search; the next direction is z's. ``tries`` directions in all,
    stopping once one exceeds ``enough`` or z stops moving: any direction's separation is a
    lower bound, the largest is kept (for convex shapes it tends to their distance).
    """
    n_robot = len(robot[8])
    near, far, direction, z = work[4], work[5], work[6], work[7]
    for i in range(3):
        direction[i] = u[i]
    best = -np.inf
    for attempt in range(tries):
        if b < n_robot:
            low = -_reach(b, -direction, robot, rot, pos, far)
        else:
            k = b - n_robot
            offsets, vertices = obstacles[7], obstacles[8]
            low, at = np.inf, offsets[k]
            for v in range(offsets[k], offsets[k + 1]):
                value = direction[0] * vertices[v, 0] + direction[1] * vertices[v, 1]
                value += direction[2] * vertices[v, 2]
                if value < low:
                    low, at = value, v
            low -= obstacles[9][k]
            for i in range(3):
                far[i] = vertices[at, i]
        gap = low - _reach(a, direction, robot, rot, pos, near)
        best = max(best, gap)
        if best > enough:
            break
        if attempt == 0:
            for i in range(3):
                z[i] = far[i] - near[i]
        else:  # z + gamma (s - z), gamma in [0, 1] minimising the length
            step_z, step_step = 0.0, 0.0
            for i in range(3):
                step = far[i] - near[i] - z[i]
                step_z += step * z[i]
                step_step += step * step
            if step_step < 1e-24 or step_z >= 0.0:
                break
            gamma = min(-step_z / step_step, 1.0)
            for i in range(3):
                z[i] += gamma * (far[i] - near[i] - z[i])
        length = math.sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2])
        if length < 1e-12:
            break
        for i in range(3):
            direction[i] = z[i] / length
    return best


@njit(cache=True, nogil=True, error_model="numpy")
def _bound(p, pairs, ends, robot, obstacles, work, near, rot, pos, cuts, last):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """A lower bound on pair p's distance (exact for closed-form pairs), m.

    The distance between the capsules (exact where both are the shapes themselves); where that
    is ``near`` or less and a shape is only bounded by its capsule, the larger of it and the
    shapes' separation along the direction between the capsules' closest points (and a box's
    face normals; a halfspace's normal: exact for a convex mesh). ``last`` (P, 3): per pair,
    the direction whose separation last proved it farther than ``near`` (NaN: none), tried
    first (the path moves little between checks: one direction instead of up to 24 steps of
    the descent, the UR5's meshes' sweep 1.15x faster); kept in the world for an obstacle
    pair, in part a's frame for a self pair (the joints before part a turn both parts alike,
    so the wrist pairs' direction still separates them after the arm has moved: the UR5's
    ERK cell map's sweep about 1.1x faster again); any direction's separation is a lower
    bound, so the answer is the same.
    """
    radius, exact = robot[8], robot[9]
    a, b = pairs[p, 0], pairs[p, 1]
    n_robot = len(radius)
    local, u, normal = work[0:2], work[2], work[3]
    if b < n_robot:
        s, t = segment_params(ends[a, 0], ends[a, 1], ends[b, 0], ends[b, 1])
        for i in range(3):
            u[i] = ends[b, 0, i] + t * (ends[b, 1, i] - ends[b, 0, i])
            u[i] -= ends[a, 0, i] + s * (ends[a, 1, i] - ends[a, 0, i])
        both = exact[a] and exact[b]
        value = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) - radius[a] - radius[b]
    else:
        k = b - n_robot
        kind, o_ends, o_radius, o_rot, o_centre, o_half = obstacles[:6]
        both = exact[a] and obstacles[6][k]
        if kind[k] == 0:
            value = segment_halfspace(ends[a, 0], ends[a, 1], radius[a], o_ends[k, 0], o_radius[k])
            if value <= near and not both:  # the part's lowest point along the normal
                u[0], u[1], u[2] = -o_ends[k, 0, 0], -o_ends[k, 0, 1], -o_ends[k, 0, 2]
                value = max(value, -_reach(a, u, robot, rot, pos, local[0]) - o_radius[k])
            return value
        if kind[k] == 1:
            s, t = segment_params(ends[a, 0], ends[a, 1], o_ends[k, 0], o_ends[k, 1])
            for i in range(3):
                u[i] = o_ends[k, 0, i] + t * (o_ends[k, 1, i] - o_ends[k, 0, i])
                u[i] -= ends[a, 0, i] + s * (ends[a, 1, i] - ends[a, 0, i])
            value = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) - radius[a] - o_radius[k]
        else:
            for e in range(2):  # into the box's frame
                for i in range(3):
                    local[e, i] = 0.0
                    for m in range(3):
                        local[e, i] += o_rot[k, m, i] * (ends[a, e, m] - o_centre[k, m])
            squared, t = segment_box_param(local[0], local[1], o_half[k], cuts)
            value = math.sqrt(squared) - radius[a]
            if value <= near and not both:
                for i in range(3):  # the box's closest point less the segment's, in the world
                    x = local[0, i] + t * (local[1, i] - local[0, i])
                    local[0, i] = min(max(x, -o_half[k, i]), o_half[k, i]) - x
                for i in range(3):
                    u[i] = o_rot[k, i, 0] * local[0, 0] + o_rot[k, i, 1] * local[0, 1]
                    u[i] += o_rot[k, i, 2] * local[0, 2]
    ja = robot[6][a]  # a self pair's last direction is kept in part a's frame
    if value <= near and not both and last[p, 0] == last[p, 0]:  # what separated them before
        for i in range(3):
            normal[i] = last[p, i]
            if b < n_robot:
                normal[i] = rot[ja, i, 0] * last[p, 0] + rot[ja, i, 1] * last[p, 1]
                normal[i] += rot[ja, i, 2] * last[p, 2]
        value = max(value, _gap(a, b, normal, robot, obstacles, rot, pos, work, 1, near))
        if value > near:
            return value
    if value <= near and not both:
        length = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
        if length > 1e-12:
            for i in range(3):
                u[i] /= length
            value = max(value, _gap(a, b, u, robot, obstacles, rot, pos, work, 24, near))
    if value <= near and not both and b >= n_robot and obstacles[0][b - n_robot] == 2:
        for i in range(3):  # a box's face normals, towards the part
            for sign in (-1.0, 1.0):
                for m in range(3):
                    normal[m] = -sign * obstacles[3][b - n_robot, m, i]
                gap = _gap(a, b, normal, robot, obstacles, rot, pos, work, 1, near)
                value = max(value, gap)
    if value > near and not both:  # the direction that proved it: tried first next time
        for i in range(3):
            last[p, i] = work[6, i]
            if b < n_robot:  # the joints before part a turn both parts: a's frame keeps it
                last[p, i] = rot[ja, 0, i] * work[6, 0] + rot[ja, 1, i] * work[6, 1]
                last[p, i] += rot[ja, 2, i] * work[6, 2]
    return value


@njit(cache=True, nogil=True, error_model="numpy")
def _capsule_bound(a, b, ends, radius, kind, o_ends, o_radius, o_rot, o_centre, o_half, cuts):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The first value of :func:`_bound`: the distance between part a's capsule and object b.

    Exact where both are the shapes themselves; scalar code on the unpacked packs (a view or
    a pack's tuple made per pair cost 0.3 to 0.6 microseconds, a hundred times the sums).
    """
    n_robot = radius.shape[0]
    a0x, a0y, a0z = ends[a, 0, 0], ends[a, 0, 1], ends[a, 0, 2]
    a1x, a1y, a1z = ends[a, 1, 0], ends[a, 1, 1], ends[a, 1, 2]
    if b < n_robot:
        b0x, b0y, b0z = ends[b, 0, 0], ends[b, 0, 1], ends[b, 0, 2]
        b1x, b1y, b1z = ends[b, 1, 0], ends[b, 1, 1], ends[b, 1, 2]
        other = radius[b]
    else:
        k = b - n_robot
        if kind[k] == 0:
            nx, ny, nz = o_ends[k, 0, 0], o_ends[k, 0, 1], o_ends[k, 0, 2]
            da = nx * a0x + ny * a0y + nz * a0z - o_radius[k]
            db = nx * a1x + ny * a1y + nz * a1z - o_radius[k]
            return min(da, db) - radius[a]
        if kind[k] == 2:  # into the box's frame
            cx, cy, cz = a0x - o_centre[k, 0], a0y - o_centre[k, 1], a0z - o_centre[k, 2]
            ex, ey, ez = a1x - o_centre[k, 0], a1y - o_centre[k, 1], a1z - o_centre[k, 2]
            r = o_rot[k]
            squared, _ = box_param(
                r[0, 0] * cx + r[1, 0] * cy + r[2, 0] * cz,
                r[0, 1] * cx + r[1, 1] * cy + r[2, 1] * cz,
                r[0, 2] * cx + r[1, 2] * cy + r[2, 2] * cz,
                r[0, 0] * ex + r[1, 0] * ey + r[2, 0] * ez,
                r[0, 1] * ex + r[1, 1] * ey + r[2, 1] * ez,
                r[0, 2] * ex + r[1, 2] * ey + r[2, 2] * ez,
                o_half[k, 0], o_half[k, 1], o_half[k, 2], cuts,
            )  # fmt: skip
            return math.sqrt(squared) - radius[a]
        b0x, b0y, b0z = o_ends[k, 0, 0], o_ends[k, 0, 1], o_ends[k, 0, 2]
        b1x, b1y, b1z = o_ends[k, 1, 0], o_ends[k, 1, 1], o_ends[k, 1, 2]
        other = o_radius[k]
    s, t = params(a0x, a0y, a0z, a1x, a1y, a1z, b0x, b0y, b0z, b1x, b1y, b1z)
    ux = b0x + t * (b1x - b0x) - (a0x + s * (a1x - a0x))
    uy = b0y + t * (b1y - b0y) - (a0y + s * (a1y - a0y))
    uz = b0z + t * (b1z - b0z) - (a0z + s * (a1z - a0z))
    return math.sqrt(ux * ux + uy * uy + uz * uz) - radius[a] - other


@njit(cache=True, nogil=True, error_model="numpy")
def first_due(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    configurations,
    robot,
    obstacles,
    pairs,
    weights,
    tables,
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
        tables: the self pairs' tables (:mod:`solver.path.cell.pair_tables`), tried before
            their meshes.
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
    ends, work, cuts, turn = (
        np.empty((n_parts, 2, 3)),
        np.empty((8, 3)),
        np.empty(8),
        np.empty((3, 3)),
    )
    count, n_pairs = len(configurations), len(pairs)
    last = np.full((n_pairs, 3), np.nan)  # per pair, the direction that last separated it
    radius, exact = robot[8], robot[9]
    kind, o_ends, o_radius, o_rot, o_centre, o_half, o_exact = obstacles[:7]
    n_robot = radius.shape[0]
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
                    _parts(configurations[index], robot, rot, pos, ends, turn)
                    placed = True
                a, b = pairs[p, 0], pairs[p, 1]
                distance = _capsule_bound(
                    a, b, ends, radius, kind, o_ends, o_radius, o_rot, o_centre, o_half, cuts
                )
                both = exact[a] and (exact[b] if b < n_robot else o_exact[b - n_robot])
                if distance <= near and not both and tables[0][p] >= 0:  # a tabulated pair
                    bound = table_bound(
                        tables[0][p], configurations[index], tables, near - clearance
                    )
                    distance = max(distance, bound)
                if distance <= near and not both:  # a mesh or a cylinder: its own bounds
                    distance = _bound(
                        p, pairs, ends, robot, obstacles, work, near, rot, pos, cuts, last
                    )
                if distance <= near:
                    need[p] = needed = True
                    continue
            clear_until[p] = advance(configurations, weights, p, index, distance - clearance)
        if needed:
            return index
        index = clear_until.min() + 1
    return count
