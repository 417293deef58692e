"""The map's compiled kernel: the whole pipeline per placement in one loop (dtf.md section 9).

For the closed-form families in fixed spin, :func:`solver.path.placements.evaluate_placements` runs
this kernel instead of the numpy pipeline (:func:`solver.path.pipeline.run_chunk`), which stays the
reference it is tested against (tests/solver/test_map_kernel.py: the same reasons, failed
waypoints, branches and bottlenecks, mu_path to 1e-12). Per placement, in blocks of 32
waypoints:

1. turn the prepared path by the placement's yaw and move it
   (:func:`solver.kernels.cell.turned_poses`, the arithmetic of
   :func:`solver.path.placed.turn_by_yaw`);
2. IK of the flange poses on the branches still alive and J^-1 t on each (the family's pose
   kernel, :mod:`solver.families.kernels`, level by level), every angle a (cos, sin) pair;
3. each branch still alive, waypoint by waypoint: unreachable, then singular, then the step test
   cos(dq) >= cos(max_joint_step) against the previous waypoint (no angle, no unwrapping);
   then its DTF, 1 / max_j |qd_j| / qdot_max_j (:func:`solver.kernels.limits.joint_speed_bound`),
   and the running minimum;
4. after the path, position limits (:func:`solver.kernels.positions.first_outside_pairs`): a
   joint whose limits span more than 2 pi fits when the path's total turning (bounded from the
   squared chords of the (cos, sin) steps) leaves a full turn of room; a joint whose range is a
   turn or less fits when every waypoint is inside its arc and no step's short arc passes
   through the gap opposite. Only a branch that neither test clears forms its angles (atan2)
   and runs the exact test of :func:`solver.path.tracking.track`;
5. with joint acceleration limits, mu_acc of the branches the choice can take, from their
   joint paths' steps (:func:`solver.kernels.positions.pair_step`: the angle between
   neighbouring pairs, by a series where small), the branches pruned by mu_acc as below
   (:mod:`solver.kernels.acc_cells`);
6. the branch: :func:`solver.path.tracking.choose_branch`'s rule, by mu_acc where it is
   computed (:func:`solver.kernels.cell.write_cell`).

The branches are pruned (:mod:`solver.kernels.cell`; with acceleration limits by mu_acc,
:mod:`solver.kernels.acc_cells`): the branch the
previous placement chose is followed first; once a branch is feasible, every other is probed at
its bottleneck (and where each was least before) and followed, most promising first, only while
its running minimum can still be chosen; a final check follows the pruned branches to the end
where one might change the answer, so every reported field is the full loop's (the ERK-size
map: about a third of the CPU time of the loop over every branch, 2026-12-02).

A branch stops at its first failure and a placement at its last live branch. Why compiled:
the fused loops keep a waypoint's values in registers, where numpy makes and reads back an
array per formula, and no atan2 is taken (it was a third of the kernel's time while the
exact limit test still ran on every branch); measured in ``bench/run.py``. The per-waypoint
body of step 3 is written out here rather than called from shared helpers, and the step test
folded with the sums of the fast position tests: under numba that is what keeps the loop fast
(calls there made the map 1.2x to 3x slower).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import FEASIBLE, TIE_RTOL
from solver.families.kernels import N_JOINTS
from solver.kernels.acc_cells import fixed_cell
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
    start_again,
    start_cell,
    turned_poses,
    warm_up_accelerations,
    warm_up_answers,
    warm_up_placement,
    write_cell,
)
from solver.kernels.fixed_follow import fail_first_rows, follow_rows, probe_rows
from solver.kernels.limits import step_stencil
from solver.kernels.positions import limit_modes

_TWO_PI = 2 * math.pi

drop_stale_compiled_code(__name__)


@njit(cache=True, error_model="numpy", nogil=True)
def map_cells(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    family,
    par,
    cos_yaw,
    sin_yaw,
    offset,
    flange_rotation,
    flange_position,
    tool_position,
    twist,
    pure_rotation,
    segment_checked,
    branches,
    lower,
    upper,
    modes,
    arc,
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
    """Evaluate C placements; the answers go to the arrays after ``max_joint_step``.

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
        pure_rotation: shape (W,), bool, where h = 0.
        segment_checked: shape (W - 1,), bool, where the step bound applies.
        branches: shape (B,), the branch indices to follow.
        lower: shape (6,), rad, lower position limits.
        upper: shape (6,), rad, upper position limits.
        modes: from :func:`solver.kernels.positions.limit_modes`.
        arc: from :func:`solver.kernels.positions.limit_modes`.
        qdot_max: shape (6,), rad/s.
        max_joint_step: rad.
        qddot_max: shape (6,), rad/s^2, or (0,) without acceleration limits (then the blend
            stencil and the acceleration answers are not read).
        stencil_index: shape (K, 5), :class:`solver.path.blend_stencil.BlendStencil`'s ``index``.
        stencil_weight: shape (K, 5), its ``weight``.
        stencil_waypoints: shape (K,), its ``waypoints``.
        mu: shape (C,), out, m/s, NaN where infeasible.
        reason: shape (C,), out, as :class:`solver.path.placements.PlacementResults`.
        failed: shape (C,), out, the failed waypoint.
        branch: shape (C,), out, the branch index.
        bottleneck_waypoint: shape (C,), out.
        bottleneck_joint: shape (C,), out.
        v_out: shape (C, W), out, V_max on the chosen branch, or (C, 0) when not wanted.
        mu_acc: shape (C,), out, m/s, as :class:`solver.path.placements.PlacementResults`;
            written only with acceleration limits, as the next three.
        limited_by: shape (C,), out, 0 the speed limits bind, 1 the accelerations, -1 none.
        acc_waypoint: shape (C,), out, where mu_acc binds.
        acc_joint: shape (C,), out, the joint that binds there.
        v_acc: shape (C, W), out, V_acc on the chosen branch, or (C, 0) when not wanted.
    """
    n_cells = cos_yaw.shape[0]
    n_waypoints = flange_rotation.shape[0]
    n_branches = branches.shape[0]
    # Every array goes down the loop's calls as a view without a reference count
    # (solver.kernels.borrow): the arguments are the caller's, the work arrays kept to the end.
    (par, offset, flange_rotation, flange_position, tool_position, twist, pure_rotation,
     segment_checked, branches, lower, upper, modes, arc, mu, reason, failed, branch,
     bottleneck_waypoint, bottleneck_joint, v_out) = borrowed_all((
        par, offset, flange_rotation, flange_position, tool_position, twist, pure_rotation,
        segment_checked, branches, lower, upper, modes, arc, mu, reason, failed, branch,
        bottleneck_waypoint, bottleneck_joint, v_out,
    ))  # fmt: skip
    work_poses = pose_work(n_waypoints)
    cq, sq, qd, status, poses, scratch, need = borrowed_all(work_poses)
    work_branches = branch_work(n_branches, n_waypoints, v_out.shape[1] > 0)
    alive, why, where, slowest, slowest_at, slowest_joint, speeds = borrowed_all(work_branches)
    work_rows = (
        np.empty((n_branches, N_JOINTS)),  # chords2
        np.empty((n_branches, N_JOINTS)),  # largest2
        np.empty((n_branches, N_JOINTS)),  # inside
        np.empty((n_branches, N_JOINTS), dtype=np.bool_),  # crossed
        np.empty(n_branches, dtype=np.bool_),  # todo
        np.full(n_branches, -1),  # hint
        np.empty(n_branches),  # limit
        np.empty(n_branches),  # bound
        np.empty(n_branches, dtype=np.bool_),  # remaining
        1.0 / qdot_max,  # inverse_qdot
    )
    (chords2, largest2, inside, crossed, todo, hint, limit, bound, remaining,
     inverse_qdot) = borrowed_all(work_rows)  # fmt: skip
    probed = (slowest, hint, bound)
    accelerations = qddot_max.shape[0] > 0
    acc = acc_work(n_branches, n_waypoints, v_acc.shape[1] > 0)
    feed, acc_at, acc_by, acc_speeds = acc[0], acc[1], acc[2], acc[3]
    steps_c = step_stencil(stencil_index, stencil_weight)
    rows = scan_work(
        stencil_index, steps_c, n_waypoints, segment_checked, max_joint_step, qddot_max
    )
    stencil = (stencil_index, steps_c, stencil_waypoints, rows)
    work = (todo, limit, remaining, bound)
    guess = np.int64(0)  # not the literal 0: the callees get one compiled signature, not two
    for c in range(n_cells):
        start_cell(alive, why, where)
        turned_poses(
            c, cos_yaw, sin_yaw, offset, flange_rotation, flange_position, tool_position, twist,
            poses,
        )  # fmt: skip
        posed = (family, par, poses, branches, pure_rotation)
        found = (scratch, cq, sq, qd, status, need, alive, why, where)
        path_tests = (segment_checked, lower, upper, modes, arc, inverse_qdot, max_joint_step)
        kept = (slowest, slowest_at, slowest_joint, speeds, chords2, largest2, inside, crossed)
        answer = (slowest, slowest_at, slowest_joint, speeds, mu, reason, failed, branch,
                  bottleneck_waypoint, bottleneck_joint, v_out)  # fmt: skip
        if accelerations:  # pruned by mu_acc (solver.kernels.acc_cells)
            pick = fixed_cell(
                c, guess, work, posed, path_tests, found, kept, hint, qddot_max, stencil, acc,
                answer,
            )  # fmt: skip
        else:  # pruning: the previous placement's branch first, then the most promising
            limit[:] = -np.inf
            bound[:] = np.inf
            remaining[:] = True
            best = np.int64(-1)
            row = guess
            while row >= 0:
                remaining[row] = False
                todo[:] = False
                todo[row] = True
                follow_rows(todo, limit, *posed, *path_tests, *found, *kept, hint)
                if row == guess and where[row] == 0:  # out of reach, most likely: all at once
                    fail_first_rows(remaining, family, par, poses, branches, *found)
                if alive[row] and (best < 0 or slowest[row] > slowest[best]):
                    best = row
                    set_limits(limit, row, slowest[row], TIE_RTOL)
                    w = slowest_at[row]
                    probe_rows(remaining, limit, w, *posed, inverse_qdot, *found, *probed)
                    for i in range(n_branches):
                        if remaining[i] and alive[i] and hint[i] >= 0:
                            w = hint[i]
                            probe_rows(remaining, limit, w, *posed, inverse_qdot, *found, *probed)
                row = next_row(remaining, alive, bound)
            pick = write_cell(c, branches, alive, why, where, slowest, TIE_RTOL, *answer)
            if not choice_holds(alive, why, slowest, slowest, TIE_RTOL, pick):
                # a pruned row might change the answer: follow the pruned rows to the end
                for i in range(n_branches):
                    todo[i] = why[i] == PRUNED
                start_again(todo, alive, why, where)
                limit[:] = -np.inf
                follow_rows(todo, limit, *posed, *path_tests, *found, *kept, hint)
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
    keep(work_rows)


def warm_up() -> None:
    """Compile the kernel, or load it from the disk cache, so that no request pays for it.

    One placement of a two-waypoint path of the families' warm-up arm (a UR5): the kernel has
    one signature for every family.
    """
    modes, arc = limit_modes(np.full(6, -_TWO_PI), np.full(6, _TWO_PI))
    map_cells(
        *warm_up_placement(),
        np.zeros(2, dtype=np.bool_),
        np.ones(1, dtype=np.bool_),
        np.arange(8, dtype=np.int64),
        np.full(6, -_TWO_PI),
        np.full(6, _TWO_PI),
        modes,
        arc,
        np.full(6, math.pi),
        0.35,
        *warm_up_accelerations(),
        *warm_up_answers(),
    )
