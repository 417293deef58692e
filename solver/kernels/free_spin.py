"""The map's compiled kernel in free spin: the pipeline's free mode per placement, in one loop.

cam.md section 2. For the closed-form families with the tool spin rate free,
:func:`solver.path.placements.evaluate_placements` runs this kernel instead of the numpy pipeline
(:func:`solver.path.pipeline.run_chunk` with ``spin_mode="free"``), which stays the reference it is
tested against (tests/solver/test_free_spin_kernel.py). Per placement:

1. the path turned by the yaw and moved (:func:`solver.kernels.cell.turned_poses`); IK and
   J^-1 t_hat on the branches still alive, then J^-1 [0; z_tool] (the family's pose kernel run
   a second time with the spin twist), blocks of waypoints as in :mod:`solver.kernels.cell`;
2. each branch: unreachable, singular, then the step test against the previous waypoint, no
   position limits (they hold along the spin schedule); V_max by the exact two-variable LP
   (:func:`solver.kernels.limits.two_variable_speed`, as
   :func:`solver.core.two_variable_lp.two_variable_speed`) and its running minimum, mu_path;
3. without acceleration limits, the branches pruned (:mod:`solver.kernels.cell`,
   :mod:`solver.kernels.free_follow`): the branch the previous placement chose first, then the
   most promising, each followed to the end tracked again along its spin schedule (the spin
   rate nearest zero at the feed mu_path,
   :func:`solver.core.two_variable_lp.spin_rate_nearest_zero`; the joints moved by the spin,
   :func:`solver.path.spin_schedule.spin_schedule`; that joint path tracked with the position
   limits and the step test, :func:`solver.path.tracking.track`, in
   :mod:`solver.kernels.spin_schedule`); the others probed and left once they cannot be chosen,
   and followed to the end after all where the answer might depend on them;
4. with joint acceleration limits, the branches pruned likewise by mu_acc
   (:mod:`solver.kernels.acc_cells`): each followed to the end is tracked along its spin
   schedule and its mu_acc formed from the spun path's steps;
5. the branch: :func:`solver.path.tracking.choose_branch`'s rule, by mu_acc where computed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import FEASIBLE, TIE_RTOL
from solver.families.kernels import N_JOINTS
from solver.kernels.acc_free import free_cell
from solver.kernels.acc_scan import scan_work
from solver.kernels.accelerations import acc_work, write_acc
from solver.kernels.borrow import borrowed_all, keep
from solver.kernels.cache import drop_stale_compiled_code
from solver.kernels.cell import (
    PRUNED,
    branch_work,
    choice_holds,
    next_row,
    pose_work,
    set_limits,
    spin_poses_of,
    start_again,
    start_cell,
    turned_poses,
    warm_up_accelerations,
    warm_up_answers,
    warm_up_placement,
    write_cell,
)
from solver.kernels.fixed_follow import fail_first_rows
from solver.kernels.free_follow import follow_free_rows, probe_free_rows, spun_check
from solver.kernels.limits import step_stencil

_TWO_PI = 2 * math.pi
drop_stale_compiled_code(__name__)


@njit(cache=True, error_model="numpy", nogil=True)
def free_cells(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
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
    length,
    pure_rotation,
    segment_checked,
    branches,
    lower,
    upper,
    qdot_max,
    max_joint_step,
    qddot_max,
    stencil_index,
    stencil_weight,
    stencil_waypoints,
    mu,
    reason,
    failed,
    branch,
    bottleneck_waypoint,
    bottleneck_joint,
    v_out,
    mu_acc,
    limited_by,
    acc_waypoint,
    acc_joint,
    v_acc,
):
    """Evaluate C placements in free spin; the answers go to the arrays after ``max_joint_step``.

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
        tool_axis: shape (W, 3), z of the tool in {O}.
        length: shape (W - 1,), m, the segments' lengths.
        pure_rotation: shape (W,), bool, where h = 0.
        segment_checked: shape (W - 1,), bool, where the step bound applies (within a pass).
        branches: shape (B,), the branch indices to follow.
        lower: shape (6,), rad, lower position limits.
        upper: shape (6,), rad, upper position limits.
        qdot_max: shape (6,), rad/s.
        max_joint_step: rad.
        qddot_max: shape (6,), rad/s^2, or (0,) without acceleration limits.
        stencil_index: shape (K, 5), the blend stencil's waypoints (as
            :func:`solver.kernels.fixed_spin.map_cells` takes it).
        stencil_weight: shape (K, 5), their weights.
        stencil_waypoints: shape (K,), the constrained waypoints.
        mu: shape (C,), out, m/s, NaN where infeasible.
        reason: shape (C,), out, as :class:`solver.path.placements.PlacementResults`.
        failed: shape (C,), out, the failed waypoint.
        branch: shape (C,), out, the branch index.
        bottleneck_waypoint: shape (C,), out.
        bottleneck_joint: shape (C,), out.
        v_out: shape (C, W), out, V_max on the chosen branch, or (C, 0) when not wanted.
        mu_acc: shape (C,), out, as :func:`solver.kernels.fixed_spin.map_cells` fills it.
        limited_by: shape (C,), out, likewise.
        acc_waypoint: shape (C,), out, likewise.
        acc_joint: shape (C,), out, likewise.
        v_acc: shape (C, W), out, V_acc on the chosen branch, or (C, 0) when not wanted.
    """
    n_cells = cos_yaw.shape[0]
    n_waypoints = flange_rotation.shape[0]
    n_branches = branches.shape[0]
    # Every array goes down the loop's calls as a view without a reference count
    # (solver.kernels.borrow): the arguments are the caller's, the work arrays kept to the end.
    (par, offset, flange_rotation, flange_position, tool_position, twist, tool_axis, length,
     pure_rotation, segment_checked, branches, lower, upper, qdot_max, mu, reason, failed,
     branch, bottleneck_waypoint, bottleneck_joint, v_out) = borrowed_all((
        par, offset, flange_rotation, flange_position, tool_position, twist, tool_axis, length,
        pure_rotation, segment_checked, branches, lower, upper, qdot_max, mu, reason, failed,
        branch, bottleneck_waypoint, bottleneck_joint, v_out,
    ))  # fmt: skip
    work_poses = pose_work(n_waypoints)
    cq, sq, qd, status, poses, scratch, need = borrowed_all(work_poses)  # qd: J^-1 t_hat
    work_branches = branch_work(n_branches, n_waypoints, v_out.shape[1] > 0)
    alive, why, where, slowest, slowest_at, slowest_joint, speeds = borrowed_all(work_branches)
    work_spin = (
        np.empty_like(work_poses[2]),  # qs: J^-1 [0; z_tool]
        np.empty_like(work_poses[4]),  # spin_poses
        np.empty((n_waypoints, N_JOINTS)),  # spun
    )
    qs, spin_poses, spun = borrowed_all(work_spin)
    accelerations = qddot_max.shape[0] > 0
    keep_acc = v_acc.shape[1] > 0
    acc = acc_work(n_branches, n_waypoints, keep_acc)
    feed, acc_at, acc_by, acc_speeds = acc[0], acc[1], acc[2], acc[3]
    steps_c = step_stencil(stencil_index, stencil_weight)
    rows = scan_work(
        stencil_index, steps_c, n_waypoints, segment_checked, max_joint_step, qddot_max
    )
    stencil = (stencil_index, steps_c, stencil_waypoints, rows)
    work_rows = (
        np.empty(n_branches, dtype=np.bool_),  # todo
        np.empty(n_branches, dtype=np.bool_),  # remaining
        np.full(n_branches, -1),  # hint
        np.empty(n_branches),  # limit
        np.empty(n_branches),  # bound
        np.empty(n_branches),  # reach (solver.kernels.acc_free.free_cell)
    )
    todo, remaining, hint, limit, bound, reach = borrowed_all(work_rows)
    work = (todo, limit, remaining, bound, reach)
    guess = np.int64(0)  # not the literal 0: the callees get one compiled signature, not two
    for c in range(n_cells):
        ca, sa = cos_yaw[c], sin_yaw[c]
        turned_poses(
            c, cos_yaw, sin_yaw, offset, flange_rotation, flange_position, tool_position, twist,
            poses,
        )  # fmt: skip
        spin_poses_of(poses, tool_axis, ca, sa, spin_poses)  # the spin twist [0; z_tool]
        start_cell(alive, why, where)
        posed = (family, par, poses, spin_poses, branches, pure_rotation)
        found = (scratch, cq, sq, qd, qs, status, need, alive, why, where, slowest)
        kept = (slowest_at, slowest_joint, speeds, hint)
        steps_tests = (segment_checked, qdot_max, max_joint_step)
        spun_args = (cq, sq, qd, qs, branches, slowest, length, segment_checked, lower, upper,
                     qdot_max, max_joint_step, spun, alive, why, where)  # fmt: skip
        answer = (slowest, slowest_at, slowest_joint, speeds, mu, reason, failed, branch,
                  bottleneck_waypoint, bottleneck_joint, v_out)  # fmt: skip
        if accelerations:  # pruned by mu_acc (solver.kernels.acc_free)
            pick = free_cell(
                c, guess, work, posed, steps_tests, found, kept, spun_args, qddot_max, stencil,
                acc, answer,
            )  # fmt: skip
        else:
            # Pruning (solver.kernels.cell): the previous placement's branch first, then the
            # most promising; each followed to the end is tracked along its spin schedule
            # (the joints moved by the spin at the spin rate nearest zero at the feed
            # mu_path, with the position limits and the step test), which decides whether
            # it is feasible.
            limit[:] = -np.inf
            bound[:] = np.inf
            remaining[:] = True
            best = np.int64(-1)
            row = guess
            while row >= 0:
                remaining[row] = False
                todo[:] = False
                todo[row] = True
                follow_free_rows(todo, limit, *posed, *steps_tests, *found, *kept)
                if alive[row]:
                    spun_check(row, *spun_args)
                if row == guess and where[row] == 0:  # out of reach, most likely: all at once
                    fail_first_rows(
                        remaining, family, par, poses, branches, scratch, cq, sq, qd, status,
                        need, alive, why, where,
                    )  # fmt: skip
                if alive[row] and (best < 0 or slowest[row] > slowest[best]):
                    best = row
                    set_limits(limit, row, slowest[row], TIE_RTOL)
                    w = slowest_at[row]
                    probe_free_rows(remaining, limit, w, *posed, qdot_max, *found, hint, bound)
                    for i in range(n_branches):
                        if remaining[i] and alive[i] and hint[i] >= 0:
                            w = hint[i]
                            probe_free_rows(
                                remaining, limit, w, *posed, qdot_max, *found, hint, bound
                            )
                row = next_row(remaining, alive, bound)
            pick = write_cell(c, branches, alive, why, where, slowest, TIE_RTOL, *answer)
            if not choice_holds(alive, why, slowest, slowest, TIE_RTOL, pick):
                # a pruned row might change the answer: follow the pruned rows to the end
                for i in range(n_branches):
                    todo[i] = why[i] == PRUNED
                start_again(todo, alive, why, where)
                limit[:] = -np.inf
                follow_free_rows(todo, limit, *posed, *steps_tests, *found, *kept)
                for i in range(n_branches):
                    if todo[i] and alive[i]:
                        spun_check(i, *spun_args)
                pick = write_cell(c, branches, alive, why, where, slowest, TIE_RTOL, *answer)
        if reason[c] == FEASIBLE:
            guess = pick
        if accelerations:
            write_acc(
                c, pick, reason, slowest, slowest_at, slowest_joint, feed, acc_at, acc_by,
                acc_speeds, mu_acc, limited_by, acc_waypoint, acc_joint, v_acc,
            )  # fmt: skip
    keep(work_poses)  # the work arrays live until the loop has ended
    keep(work_branches)
    keep(work_spin)
    keep(work_rows)


def warm_up() -> None:
    """Compile the kernel, or load it from the disk cache, so that no request pays for it.

    One placement of a two-waypoint path of the families' warm-up arm (a UR5): the kernel has
    one signature for every family.
    """
    free_cells(
        *warm_up_placement(),
        np.tile([0.0, 0.0, -1.0], (2, 1)),
        np.full(1, 0.01),
        np.zeros(2, dtype=np.bool_),
        np.ones(1, dtype=np.bool_),
        np.arange(8, dtype=np.int64),
        np.full(6, -_TWO_PI),
        np.full(6, _TWO_PI),
        np.full(6, math.pi),
        0.35,
        *warm_up_accelerations(),
        *warm_up_answers(),
    )
