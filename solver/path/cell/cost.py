"""What the collision check weighs in the size limits: its cost per pose of a path (cell.md).

A request's work is estimated before it starts in poses of a closed-form family's map
(:meth:`solver.core.family.KinematicsFamily.path_cost`); each path check adds its own weight a
pose (:meth:`solver.path.limits.PathCheck.pose_cost`), the cell's :func:`cell_pose_cost`, so
the size limits refuse a map or an optimisation whose collision check would be too long before
any of it runs.
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


# The checked pairs (robot part against obstacle, and robot part against robot part) that
# CELL_POSE_COST covers: a cell with more weighs proportionally more. Each pair is a bound or a
# coal distance at every configuration, so the check's work grows with their number, and 50
# held only for a few objects: measured (2026-12-06, CPU time of the extra work a pose against
# the analytic UR5 map's, 36 placements of the ERK path, every placement collision-free, so no
# check stopped early; a second process at nice 19 on the other core), the UR5 (8 meshes and the
# tool) 47 units a pose with 3 objects (56 pairs) and 145 with 100 (929 pairs), the UR5e
# (capsules) 14 and 95 (63 and 1,033 pairs), the UR5 with 42 more collision spheres on its
# links 116 with 3 objects (860 pairs) and 287 with 20 (1,727), with 92 more 247 with 3 (2,920)
# and 1,327 with 100 (12,717 pairs): from 300 to 960 pairs a 50 units; 250 weighs every one of
# them above what it took (by up to 2.2 times), where a weight of 50 whatever the pairs weighed
# the last 26 times below it. A cell of up to 250 pairs (the catalogue's arms with up to about
# 25 objects) weighs what it did. bench/cell.py prints the check's work against its weight.
PAIRS_IN_WEIGHT = 250


def cell_pose_cost(cell: Cell, pairs: int) -> float:
    """The collision check's weight per pose: CELL_POSE_COST at the default step, 250 pairs.

    A finer step checks proportionally more sub-steps between waypoints, so it weighs more
    (at the least step, 0.001 rad, 50 times as much), and more than PAIRS_IN_WEIGHT checked
    pairs weigh proportionally more: the size limits see both before the work.

    Args:
        cell: the cell (its collision step).
        pairs: how many pairs its check computes (:attr:`CellChecker.pair_count`).
    """
    steps = max(1.0, DEFAULT_COLLISION_STEP / cell.collision_step)
    return CELL_POSE_COST * steps * max(1.0, pairs / PAIRS_IN_WEIGHT)
