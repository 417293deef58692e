"""A pair's separation along directions: the sweep's bound where a capsule is not the shape.

Compiled (numba, ``nogil``) for the cell sweep (:mod:`solver.path.cell.sweep`): where the
distance between two bounding capsules is near the clearance and a shape is only bounded by its
capsule (a convex mesh, a prism around a cylinder, a box), the shapes' separation along a few
directions raises it: support functions of their vertices (exact against a halfspace), a
Frank-Wolfe descent on the least vector of their Minkowski difference, a box's face normals,
and per pair the direction that last separated it. Any direction's separation is a lower bound
on the distance. The packs are :mod:`solver.path.cell.sweep`'s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.path.cell.closed_form import segment_box_param, segment_halfspace, segment_params
from solver.path.cell.kernel_cache import drop_stale_cell_kernels

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in


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
def separation_bound(p, pairs, ends, robot, obstacles, work, near, rot, pos, cuts, last):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
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
