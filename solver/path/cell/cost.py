"""What the collision check weighs in the size limits: its cost per pose of a path (cell.md).

A request's work is estimated before it starts in poses of a closed-form family's map
(:meth:`solver.core.family.KinematicsFamily.path_cost`); a cell adds its check's,
:func:`cell_pose_cost` a pose (:func:`with_cell`), so the size limits refuse a map or an
optimisation whose collision check would be too long before any of it runs.
"""

from __future__ import annotations

from solver.path.cell.shapes import DEFAULT_COLLISION_STEP, Cell

# What checking one pose of a path against a cell costs, in poses of a closed-form family's map:
# the ERK map (546 placements x 133 waypoints) with a table, a fixture and the part took 46 to
# 59 times the map without for the UR5 (its meshes) and 20 to 30 times for the UR5e (capsules)
# when this weight was set (bench/cell.py, CPU time, loaded machine, 2026-12-02). 50, within the
# UR5's range then: the optimisers in a cell search (x, y, yaw) past a fixture (no arc symmetry),
# and 80 refused the README's cell optimisation (7.0 million weighted poses; 50 weighs it 4.4
# million). Measured since (the pair tables, the sweep's skips, the sweep inlined into its batch
# on 2026-12-04): 35 to 39 times (UR5) and 18 to 19 times (UR5e), wall time; 50 over-weighs the
# check, and is kept, since lowering it changes which requests the size limits refuse.
#
# The check's work does not grow with the family's, so it is added to the family's figure, not
# multiplied (until 2026-12-04 it was multiplied: a numeric arm's map with a cell was weighed 14
# to 19 times its measured work, and a mimic arm's refused at 3 x 3 placements where its map
# without a cell ran 9 x 11 in the same time). Measured on 2026-12-04 (scripts not kept, CPU time,
# the ERK grid with bench/cell.py's cell, placements x 133 waypoints, in this unit: the analytic
# UR5 map's 83 ns a pose that day), the cell's extra work a placement against the map without:
# UR5 4,510 (34 a waypoint), UR5e 2,360 (18); numeric arms, whose refused placements follow
# their next branches again: the UR5 as a URDF 16,100 (its map without 9,600), the Panda 35,300
# (41,600), a chain on numpy (no pruning: nothing runs again) within the noise of 251,000. The
# numeric maps with the cell took less than the same maps following every branch without it
# (1.38 s against 1.46 s, 4.27 s against 5.93 s, CPU), whose figure a map with a cell is given
# (:func:`solver.path.capability_map.map_cost`): that figure plus the check's bounds them.
CELL_POSE_COST = 50.0


def cell_pose_cost(cell: Cell) -> float:
    """The collision check's weight per pose: CELL_POSE_COST at the default collision step.

    A finer step checks proportionally more sub-steps between waypoints, so it weighs more
    (at the least step, 0.001 rad, 50 times as much): the size limits see it before the work.
    """
    return CELL_POSE_COST * max(1.0, DEFAULT_COLLISION_STEP / cell.collision_step)


def with_cell(cost: float, n_waypoints: int, cell: Cell | None) -> float:
    """``cost``, a placement's work along ``n_waypoints``, plus ``cell``'s check of its poses.

    Its collision check weighs :func:`cell_pose_cost` a pose whatever the family: the check
    looks at the joint paths the family found, not at how it found them. No cell: ``cost``.
    """
    return cost if cell is None else cost + cell_pose_cost(cell) * n_waypoints
