"""The joint paths of chosen branches in fixed spin, compiled (for the path checks: the cell).

A map with a cell checks each feasible placement's joint path on the branch the speed limits
chose (:mod:`solver.path.path_checks`). The map kernel (:mod:`solver.kernels.fixed_spin`) keeps
no joint path; :func:`branch_paths` makes them for a chunk's placements in one call: the path
turned and moved (:func:`solver.kernels.cell.turned_poses`), the family's pose kernel on that
one branch over every waypoint, the angles of its (cos, sin) pairs unwrapped
(:func:`solver.kernels.positions.unwrapped`) and moved to the 2 pi copy
:func:`solver.path.tracking.track` reports (:func:`solver.kernels.positions.shift_to_copy`).
The numpy pipeline's IK and tracking stay the reference (tests/solver/test_joint_paths_kernel.py:
the same paths to 1e-12).
"""

from __future__ import annotations

from numba import njit

from solver.families.kernels import pose_block
from solver.kernels.cache import drop_stale_compiled_code
from solver.kernels.cell import BLOCK, pose_work, turned_poses
from solver.kernels.positions import shift_to_copy, unwrapped

drop_stale_compiled_code(__name__)


@njit(cache=True, error_model="numpy", nogil=True)
def branch_paths(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    family,
    par,
    cos_yaw,
    sin_yaw,
    offset,
    flange_rotation,
    flange_position,
    tool_position,
    twist,
    rows,
    lower,
    upper,
    out,
):
    """The joint path of branch ``rows[c]`` at each placement c, into ``out`` (C, W, 6), rad.

    Args:
        family: the family's kernel code (:mod:`solver.families.kernels`).
        par: the family's kernel parameters.
        cos_yaw: shape (C,), cos of each placement's yaw.
        sin_yaw: shape (C,), its sine.
        offset: shape (C, 3), each placement's position (m).
        flange_rotation: shape (W, 3, 3), R_O_F at the chunk's spin.
        flange_position: shape (W, 3), m, in {O}.
        tool_position: shape (W, 3), m, in {O}.
        twist: shape (W, 6), t_hat in {O}.
        rows: shape (C,), the family's branch index of each placement.
        lower: shape (6,), rad, lower position limits.
        upper: shape (6,), rad, upper position limits.
        out: shape (C, W, 6), out: each path as ``track`` reports a feasible one (only a
            branch feasible at its placement has a meaningful path).
    """
    n_waypoints = flange_rotation.shape[0]
    cq, sq, qd, status, poses, scratch, need = pose_work(n_waypoints)
    for c in range(cos_yaw.shape[0]):
        turned_poses(
            c, cos_yaw, sin_yaw, offset, flange_rotation, flange_position, tool_position, twist,
            poses,
        )  # fmt: skip
        need[:] = False
        need[rows[c]] = True
        for w0 in range(0, n_waypoints, BLOCK):
            w1 = min(w0 + BLOCK, n_waypoints)
            pose_block(family, par, poses, w0, w1, need, scratch, cq, sq, status, qd)
        path = unwrapped(cq, sq, rows[c])
        shift_to_copy(path, lower, upper)
        out[c] = path
