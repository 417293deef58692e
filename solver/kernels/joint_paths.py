"""The joint paths of chosen branches, compiled (for the path checks: the cell).

A map with a cell checks each feasible placement's joint path on the branch the speed limits
chose (:mod:`solver.path.path_checks`). The map kernel (:mod:`solver.kernels.fixed_spin`) keeps
no joint path; :func:`branch_paths` makes them for a chunk's placements in one call: the path
turned and moved (:func:`solver.kernels.cell.turned_poses`), the family's pose kernel on that
one branch over every waypoint, the angles of its (cos, sin) pairs unwrapped
(:func:`solver.kernels.positions.unwrapped`) and moved to the 2 pi copy
:func:`solver.path.tracking.track` reports (:func:`solver.kernels.positions.shift_to_copy`).
In free spin :func:`spun_branch_paths` moves each along its spin schedule, as the free-spin map
kernel tracks it. The numpy pipeline's IK and tracking stay the reference
(tests/solver/test_joint_paths_kernel.py: the same paths to 1e-12).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.families.kernels import pose_block
from solver.kernels.cache import drop_stale_compiled_code
from solver.kernels.cell import BLOCK, pose_work, spin_poses_of, turned_poses
from solver.kernels.positions import shift_to_copy, unwrapped
from solver.kernels.spin_schedule import spun_failure

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


@njit(cache=True, error_model="numpy", nogil=True)
def spun_branch_paths(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    family,
    par,
    cos_yaw,
    sin_yaw,
    offset,
    flange_rotation,
    flange_position,
    tool_position,
    twist,
    tool_axis,
    rows,
    feeds,
    length,
    segment_checked,
    lower,
    upper,
    qdot_max,
    max_joint_step,
    out,
):
    """:func:`branch_paths` in free spin: each joint path along its spin schedule at its feed.

    cam.md section 2, as the free-spin map kernel tracks a branch followed to the end
    (:func:`solver.kernels.free_follow.spun_check`) and the numpy pipeline reports it
    (:func:`solver.path.spin_schedule.spin_schedule`): J^-1 t_hat and J^-1 [0; z_tool] on the
    branch, the spin rate nearest zero at the feed held over each segment, the joints moved by
    the spin (:func:`solver.kernels.spin_schedule.spun_failure`), then the 2 pi copy ``track``
    reports.

    Args:
        family: as :func:`branch_paths`.
        par: as :func:`branch_paths`.
        cos_yaw: as :func:`branch_paths`.
        sin_yaw: as :func:`branch_paths`.
        offset: as :func:`branch_paths`.
        flange_rotation: as :func:`branch_paths`.
        flange_position: as :func:`branch_paths`.
        tool_position: as :func:`branch_paths`.
        twist: as :func:`branch_paths`.
        tool_axis: shape (W, 3), z of the tool in {O}, the spin's axis.
        rows: as :func:`branch_paths`.
        feeds: shape (C,), m/s, each branch's mu_path at its placement (no spin where it is
            not a positive number).
        length: shape (W - 1,), m, the segments' lengths.
        segment_checked: shape (W - 1,), bool, the segments within a pass.
        lower: as :func:`branch_paths`.
        upper: as :func:`branch_paths`.
        qdot_max: shape (6,), rad/s.
        max_joint_step: rad.
        out: shape (C, W, 6), out: each path as the pipeline tracks a feasible one along its
            spin schedule (meaningful where the branch is feasible at its placement).
    """
    n_waypoints = flange_rotation.shape[0]
    cq, sq, qd, status, poses, scratch, need = pose_work(n_waypoints)
    qs = np.empty_like(qd)
    spin_poses = np.empty_like(poses)
    spun = np.empty((n_waypoints, qd.shape[1]))
    for c in range(cos_yaw.shape[0]):
        ca, sa = cos_yaw[c], sin_yaw[c]
        turned_poses(
            c, cos_yaw, sin_yaw, offset, flange_rotation, flange_position, tool_position, twist,
            poses,
        )  # fmt: skip
        spin_poses_of(poses, tool_axis, ca, sa, spin_poses)  # as free_cells makes them
        need[:] = False
        need[rows[c]] = True
        for w0 in range(0, n_waypoints, BLOCK):
            w1 = min(w0 + BLOCK, n_waypoints)
            pose_block(family, par, spin_poses, w0, w1, need, scratch, cq, sq, status, qs)
            pose_block(family, par, poses, w0, w1, need, scratch, cq, sq, status, qd)
        feed = feeds[c] if feeds[c] > 0.0 and math.isfinite(feeds[c]) else 0.0
        path = unwrapped(cq, sq, rows[c])
        spun_failure(
            path, qd, qs, rows[c], feed, length, segment_checked, lower, upper, qdot_max,
            max_joint_step, spun,
        )  # fmt: skip
        shift_to_copy(spun, lower, upper)
        out[c] = spun
