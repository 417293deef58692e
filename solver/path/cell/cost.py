"""What the collision check weighs in the size limits: its cost per pose of a path (cell.md).

A request's work is estimated before it starts in poses of a closed-form family's map
(:meth:`solver.core.family.KinematicsFamily.path_cost`); a cell multiplies it by
:func:`cell_pose_cost`, so the size limits refuse a map or an optimisation whose collision
check would be too long before any of it runs.
"""

from __future__ import annotations

from solver.path.cell.shapes import DEFAULT_COLLISION_STEP, Cell

# What checking one pose of a path against a cell costs, in poses of a closed-form family's map:
# the ERK map (546 placements x 133 waypoints) with a table, a fixture and the part took 46 to
# 59 times the map without for the UR5 (its meshes) and 20 to 30 times for the UR5e (capsules)
# when this weight was set (bench/cell.py, CPU time, loaded machine, 2026-12-02). 50, within the
# UR5's range then: the optimisers in a cell search (x, y, yaw) past a fixture (no arc symmetry),
# and 80 refused the README's cell optimisation (7.0 million weighted poses; 50 weighs it 4.4
# million). Measured since (the pair tables, the sweep's skips): about 31 to 36 times (UR5) and
# 21 to 24 times (UR5e), so 50 over-weighs the check a little; it is kept, since lowering it
# changes which requests the size limits refuse.
CELL_POSE_COST = 50.0


def cell_pose_cost(cell: Cell) -> float:
    """The collision check's weight per pose: CELL_POSE_COST at the default collision step.

    A finer step checks proportionally more sub-steps between waypoints, so it weighs more
    (at the least step, 0.001 rad, 50 times as much): the size limits see it before the work.
    """
    return CELL_POSE_COST * max(1.0, DEFAULT_COLLISION_STEP / cell.collision_step)
