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
# million). Measured since (the pair tables, the sweep's skips, the sweep inlined into its batch
# on 2026-12-04): 35 to 39 times (UR5) and 18 to 19 times (UR5e), wall time, kernels loaded
# from numba's disk cache as the service loads them; 50 over-weighs the check, and is kept, since
# lowering it changes which requests the size limits refuse. A numeric arm's map with a cell
# weighs its family's figure times this: 2,683 a waypoint for the UR5 read as a numeric URDF
# (7,136 a placement without). When that map followed every branch it took 4.2 times its map
# without; since it drops branches as without a cell (2026-12-04) 3.0 to 3.2 times, and a mimic
# arm on the numpy chain (the corpus IRB 5400) about 1.0 times, weighed 23 times over the size
# limit where its map without a cell is under it: the product over-weighs numeric arms, the sum
# (the family's figure plus this) has not been measured since. Kept until it is.
CELL_POSE_COST = 50.0


def cell_pose_cost(cell: Cell) -> float:
    """The collision check's weight per pose: CELL_POSE_COST at the default collision step.

    A finer step checks proportionally more sub-steps between waypoints, so it weighs more
    (at the least step, 0.001 rad, 50 times as much): the size limits see it before the work.
    """
    return CELL_POSE_COST * max(1.0, DEFAULT_COLLISION_STEP / cell.collision_step)
