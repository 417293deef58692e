"""The numeric family's work model: a path's and a map's placement in closed-form poses.

robots.md section 4; :meth:`solver.core.family.KinematicsFamily.path_cost` and ``map_cost``.
The lines are measured (the comments below say how and when); tests/solver/families/
test_numeric_cost.py and test_numeric_map_work.py hold them against measured work.
"""

from __future__ import annotations

# Work of one placement in poses of a closed-form family (KinematicsFamily.path_cost), measured
# with the compiled chain (ik_kernel) on the 2-core development machine against the analytic
# UR5 map of the same run (ERK grid, 546 placements, 133 waypoints; CPU time, the machine
# loaded, 2026-12-02, after seeds were given up on a stall, ik.STALL_STEPS): seeding the first
# waypoint (K seeds) and following each branch found to each next waypoint, the whole map's
# time per placement and per waypoint, from maps of 2 and 133 waypoints. Each size has the
# lines (seeding, following per waypoint) of its measured arms, about 25 % above the
# measurement, and a path costs the highest. Six joints: UR5 as a URDF 618 and 38.7, the Jaco2
# 742 and 13.0; placements out of reach (z 5 m) seed for less now (596 and 504: their seeds
# stall early). Seven: the Panda 2,021 and 125, the xArm7 1,388 and 177 (the following line
# kept at the 200 measured before, which the free spin's weight was measured against).
# Seeding includes the more seeds a six-joint chain tries where its seeds found an odd number of
# solutions (ik.more_seeds): 15 % more on 3,000 random poses of the UR5 as a URDF (212 against
# 184 us a pose, best of 2 or 3, 2026-12-07), up to 48 % on an OPW arm as a URDF (the M20iA's
# random poses), nothing measurable on the ERK map; within the margin.
# Maps share these lines with evaluations, which follow every branch: a six-joint map pruned
# in one pass (solver/path/bounded.py) costs about a quarter of its line (UR5 as a URDF, ERK
# map, 2026-12-02), so its estimate is an upper bound; the lines are not lowered for it.
COST_LINES: dict[int, tuple[tuple[float, float], ...]] = {
    6: ((800.0, 48.0), (1_000.0, 17.0)),
    7: ((2_600.0, 200.0),),
}
FREE_SPIN_REDUNDANT_COST = 3.0
"""A seven-joint path's work in free spin against the fixed spin's cost line (the vertex LPs of
:mod:`solver.kernels.spin_lp`, the QR's null space). Evaluations, CPU time, best of 2, loaded
machine, 2026-12-02, same run: the Panda along 2,000 waypoints free 0.246 s against fixed
0.120 s (2.05 times), 20,000: 2.75 s against 1.28 s (2.15); the xArm7 2.29 and 1.87 times.
Maps (ERK path, 99 placements; a free-spin map is not pruned): the Panda's free map 3.0 times
its pruned fixed map, the xArm7's 2.5 times, about 2 times the unpruned line this weighs.
(Before the LPs were compiled: 50, measured 35-57 times.)"""
NUMPY_CHAIN_COST = 35.0
"""The numpy chain's work against the compiled one's (a chain with mimic joints runs on numpy):
the UR5 as a URDF, ERK path (133 waypoints), CPU time, loaded machine, 2026-12-02, same run:
an evaluation 0.164 s against 0.005 s (33 times), a 30-placement map 0.93 s against 0.10 s."""
NUMPY_MAP_COST = 12.0
"""The numpy chain's map against the compiled chain's line: measured 9.3 times (the UR5 as a
URDF, 30 placements of the ERK path, the run of NUMPY_CHAIN_COST)."""
FIRST_PIECE = 32
"""Waypoints every branch of a pruned map is followed before any is dropped (the pruning's
``solver.path.pruning.PIECE``, held equal by a test)."""
MAP_TAIL_SHARE = 0.5
"""A pruned map's work after the first piece against following every branch (the seven-joint
line). Measured: the CPU time of the following and the bounds past the first piece, pruned
against unpruned, 99 placements, ERK path (133 waypoints) and 600 (the ERK path there and back),
loaded machine, 2026-12-02, same run: Panda 0.19 and 0.11, xArm7 0.38 and 0.29 (the whole map
0.46 / 0.18 and 0.60 / 0.34 of the unpruned one). In counts (tests/solver/families/
test_numeric_map_work.py), the branch-waypoints followed past the first piece: 0.09 to 0.16."""


BOUNDED_MAP_SHARE = 0.55
"""A seven-joint map pruned in one pass (:mod:`solver.families.numeric.bounded_redundant_kernel`):
its work past the seeding against the line's following (every branch), about 25 % above the
pass's measured share. CPU time, best of 3, loaded machine, 2026-12-02, same run, 20 x 11
placements of the ERK grid: the pass against following every slot, the ERK path (133
waypoints) and 400 (there and back), Panda 0.43 and 0.21, xArm7 0.41 and 0.20; the whole map
past the seeding against the unpruned one's (133 waypoints, serial) Panda 0.29, xArm7 0.35 (the
pipeline tracks and bounds only the slots kept), so the figure is an upper bound. In counts
(tests/solver/families/test_numeric_map_work.py): the pass follows 0.10 to 0.25 of every
branch's waypoints, each FOLLOW_WITH_V_MAX times a plain one's work (V_max, the exact LP, at
every waypoint followed)."""
FOLLOW_WITH_V_MAX = 2.0
"""A waypoint followed by the one-pass pruning (V_max at it) against one followed plainly:
the pass's time share over its counted share (BOUNDED_MAP_SHARE's runs): Panda 1.8 and 1.8, xArm7
1.8 and 2.0."""


GENERAL_LP_COST = 800.0
"""Arms of more than seven joints: one slot's V_max at one waypoint, a general LP (the null space
of J has two or more dimensions: scipy's HiGHS, :func:`solver.core.dtf.lp_speed`), in
closed-form poses (the limits' unit, about 2 us). Measured 1.2 ms (8 joints) and 1.3 ms (20) of
CPU an LP, the machine loaded, 2026-12-05; an 8-joint chain along 200 waypoints, about 50 slots
found: 12.5 s of CPU. Before, the seven-joint figures scaled by (dof / 7)^2 weighed a 20-joint
evaluation of 3,000 waypoints under the limit, and it ran 286 s (the robots audit of stop 55:
8 joints took 113 times the estimate, 20 joints 26)."""
GENERAL_LP_SLOTS = 64
"""The slots an arm of more than seven joints may follow (its seeds,
:func:`solver.families.numeric.family.seed_count`): each may be a branch with its LPs."""


def _scale(dof: int) -> float:
    """Arms of more than seven joints: the seven-joint figures times (dof / 7)^2."""
    return max(dof / 7, 1.0) ** 2


def path_cost(dof: int, compiled: bool, n_waypoints: int, *, free_spin: bool = False) -> float:
    """Seeding plus following, in closed-form poses: the highest line of COST_LINES.

    In free spin an arm of more than six joints also solves the three-variable LP at every
    configuration (:func:`solver.kernels.spin_lp.spin_speeds`): times
    :data:`FREE_SPIN_REDUNDANT_COST`.

    Arms of more than seven joints scale the seven-joint figures by (dof / 7)^2 (the
    Jacobian products and solves grow about so) and add their LPs (:data:`GENERAL_LP_COST` a
    slot and a waypoint); the numpy chain (mimic joints) costs :data:`NUMPY_CHAIN_COST` times
    the compiled one.

    Args:
        dof: the arm's joints.
        compiled: the compiled chain (False: the numpy chain).
        n_waypoints: the path's waypoints.
        free_spin: the seven-joint free spin.
    """
    size = min(max(dof, 6), 7)
    following = max(n_waypoints - 1, 0)
    cost = _scale(dof) * max(seed + following * track for seed, track in COST_LINES[size])
    cost = cost if compiled else cost * NUMPY_CHAIN_COST
    if dof > 7:  # every slot's V_max a general LP at every waypoint
        cost += GENERAL_LP_COST * GENERAL_LP_SLOTS * n_waypoints
    return cost * FREE_SPIN_REDUNDANT_COST if free_spin and dof > 6 else cost


def map_cost(
    dof: int,
    compiled: bool,
    n_waypoints: int,
    *,
    free_spin: bool = False,
    pruned: bool = False,
    bounded: bool = False,
) -> float:
    """A map's placement, in the unit of :func:`path_cost`.

    A pruned map (``pruned``: the compiled chain followed in steps, fixed spin) follows every
    branch for FIRST_PIECE waypoints, then about MAP_TAIL_SHARE of them; a seven-joint map
    pruned in one pass (``bounded``) BOUNDED_MAP_SHARE of the following; the numpy chain
    weighs NUMPY_MAP_COST.

    Args:
        dof: the arm's joints.
        compiled: the compiled chain (False: the numpy chain).
        n_waypoints: the path's waypoints.
        free_spin: the seven-joint free spin.
        pruned: the map prunes branches in steps (``FollowsInSteps.follows_in_steps``).
        bounded: the map prunes a seven-joint arm's branches in one pass
            (``FollowsInSteps.follows_bounded``).
    """
    if not compiled:
        return path_cost(dof, compiled, n_waypoints, free_spin=free_spin) * (
            NUMPY_MAP_COST / NUMPY_CHAIN_COST
        )
    if free_spin or not (pruned or bounded) or dof > 7:  # more than seven: its LPs, unpruned
        return path_cost(dof, compiled, n_waypoints, free_spin=free_spin)
    following = max(n_waypoints - 1, 0)
    if bounded:
        share = BOUNDED_MAP_SHARE * following
        return _scale(dof) * max(seed + share * track for seed, track in COST_LINES[7])
    tail = max(following - FIRST_PIECE, 0)
    followed = following - tail + MAP_TAIL_SHARE * tail
    return _scale(dof) * max(seed + followed * track for seed, track in COST_LINES[7])
