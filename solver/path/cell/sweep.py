"""The compiled sweep of a joint path through the cell: link frames and distance bounds.

For every configuration the joints' frames (pinocchio's forward kinematics, recomputed here
from the model's joint placements, revolute and prismatic joints,
:mod:`solver.path.cell.kinematics`), every robot part's capsule in the world, and for each
checked pair a lower bound on its distance (:mod:`closed_form`): exact where both shapes are
capsules, spheres, boxes or halfspaces; otherwise the distance between bounding capsules,
raised where that is near the clearance to the shapes' separation along a few directions
(:mod:`solver.path.cell.separation`), after a tabulated bound for the self pairs whose
capsules overlap at most configurations (:mod:`solver.path.cell.pair_tables`).
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
from solver.path.cell.advance import travelled
from solver.path.cell.closed_form import box_param, params
from solver.path.cell.kernel_cache import drop_stale_cell_kernels
from solver.path.cell.kinematics import parts as _parts
from solver.path.cell.pair_tables import table_bound
from solver.path.cell.separation import separation_bound

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in


@njit(cache=True, nogil=True, error_model="numpy")
def _capsule_bound(a, b, ends, radius, kind, o_ends, o_radius, o_rot, o_centre, o_half, cuts):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The first bound on a pair: the distance between part a's capsule and object b.

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


# Inlined into its compiled caller (solver.path.cell.batch.first_due_paths, a map's chunk of
# paths): called there as a function of its own, with its packs as tuples of arrays, the batch
# ran 1.7x to 2.8x slower (157 to 190 ms against 57 ms for the UR5e's ERK-size map with a cell,
# the same verdicts); from Python (fast.first_collision) it is compiled as before.
@njit(cache=True, nogil=True, error_model="numpy", inline="always")
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
    travel = travelled(configurations)  # each joint's running travel (advance.py's search)
    # Each pair waits in the bucket of the configuration it is next due at (a linked list per
    # configuration: head, then following): a configuration costs its due pairs, not a look at
    # every pair and their minimum (the UR5e's ERK-size map's sweep 74 -> 65 ms on one thread;
    # its map with 100 objects 536 -> 428 ms, most of their pairs far at most configurations).
    head = np.full(count + 1, -1, dtype=np.int64)
    following = np.empty(n_pairs, dtype=np.int64)
    for p in range(n_pairs - 1, -1, -1):
        need[p] = False
        due = max(clear_until[p] + 1, start)
        if due < count:
            following[p], head[due] = head[due], p
    index = start
    while index < count:
        p = head[index]
        head[index] = -1
        placed, needed = False, False
        while p >= 0:
            after = following[p]
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
                    distance = separation_bound(
                        p, pairs, ends, robot, obstacles, work, near, rot, pos, cuts, last
                    )
                if distance <= near:
                    need[p] = needed = True
                    p = after
                    continue
            clear_until[p] = advance(
                configurations, travel, weights, p, index, distance - clearance
            )
            due = clear_until[p] + 1
            if due < count:
                following[p], head[due] = head[due], p
            p = after
        if needed:
            return index
        index += 1
    return count
