"""One placement of the free-spin map kernel with joint acceleration limits.

The branches pruned by mu_acc as in fixed spin (:mod:`solver.kernels.acc_cells`, whose
docstring says how, and why each call names its arrays); :func:`free_cell` serves
:func:`solver.kernels.free_spin.free_cells`, and the tuples are theirs.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.core.codes import ACC_TIE_RTOL
from solver.kernels.acc_scan import scan_row
from solver.kernels.accelerations import (
    left_at_probes,
    probe_free_acc_rows,
    probed_before,
    spin_rate_of,
)
from solver.kernels.cell import PRUNED, choice_holds, next_row, set_limits, start_again, write_cell
from solver.kernels.fixed_follow import fail_first_rows
from solver.kernels.free_follow import follow_free_rows, moved_check, probe_free_rows
from solver.kernels.spin_schedule import spin_moves


@njit(cache=True, error_model="numpy", nogil=True)
def free_cell(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    c, guess, work, posed, steps_tests, found, kept, spun_args, qddot_max, stencil, acc, answer
):
    """Placement c in free spin with acceleration limits; returns the chosen branch's row.

    As :func:`solver.kernels.acc_cells.fixed_cell`; a row followed to the end is probed, then
    tracked along its spin schedule at its mu_path
    (:func:`solver.kernels.free_follow.moved_check`, the spin's moves made once for it and the
    scan), then scanned.
    Before a row is followed its V_acc is known only where its spin is none
    (:func:`solver.kernels.accelerations.probe_free_acc_rows`).

    Args:
        c: the placement.
        guess: the row to follow first.
        work: (todo, limit, remaining, bound, reach), per row; ``reach`` the least V_max
            probed, a bound of mu_path (``bound`` that of mu_acc).
        posed: (family, par, poses, spin_poses, branches, pure_rotation).
        steps_tests: (segment_checked, qdot_max, max_joint_step).
        found: (scratch, cq, sq, qd, qs, status, need, alive, why, where, slowest).
        kept: (slowest_at, slowest_joint, speeds, hint).
        spun_args: the arguments of :func:`solver.kernels.free_follow.spun_check` after i.
        qddot_max: shape (6,), rad/s^2.
        stencil: (index, c, waypoints, rows), the blend stencil in step form and in row form
            (:func:`solver.kernels.acc_scan.scan_work`).
        acc: from :func:`solver.kernels.accelerations.acc_work`.
        answer: the answer arrays :func:`solver.kernels.cell.write_cell` fills.
    """
    todo, limit, remaining, bound, reach = work
    family, par, poses, spin_poses, branches, pure_rotation = posed
    segment_checked, qdot_max, max_joint_step = steps_tests
    scratch, cq, sq, qd, qs, status, need, alive, why, where, slowest = found
    slowest_at, slowest_joint, speeds, hint = kept
    _, _, _, _, _, _, length, _, lower, upper, _, _, spun, _, _, _ = spun_args
    index, steps_c, waypoints, rows = stencil
    feed, acc_at, acc_joint, acc_speeds, acc_hint, steps, moves = acc
    _, _, _, _, mu, reason, failed, branch, bottleneck_waypoint, bottleneck_joint, v_out = answer
    limit[:] = -np.inf
    bound[:] = np.inf
    reach[:] = np.inf
    remaining[:] = True
    best, row = -1, guess
    while row >= 0:
        remaining[row] = False
        todo[:] = False
        todo[row] = True
        follow_free_rows(
            todo, limit, family, par, poses, spin_poses, branches, pure_rotation, segment_checked,
            qdot_max, max_joint_step, scratch, cq, sq, qd, qs, status, need, alive, why, where,
            slowest, slowest_at, slowest_joint, speeds, hint,
        )  # fmt: skip
        if row == guess and where[row] == 0:  # out of reach, most likely: all at once
            fail_first_rows(
                remaining, family, par, poses, branches, scratch, cq, sq, qd, status, need,
                alive, why, where,
            )  # fmt: skip
        followed = alive[row]
        if followed:
            probes = (acc_hint[best] if best >= 0 else -1, acc_hint[row])
            b, rate = branches[row], spin_rate_of(slowest[row], True)
            if best < 0 or not left_at_probes(  # the first row has no bar to be left under
                row, limit[row], probes, b, rate, cq, sq, qd, qs, length, qdot_max, index,
                steps_c, qddot_max, steps, alive, why, where, slowest, acc_hint,
            ):  # fmt: skip
                spin_moves(qd, qs, b, rate, length, qdot_max, moves)
                moved_check(
                    row, moves, cq, sq, qd, qs, branches, slowest, length, segment_checked,
                    lower, upper, qdot_max, max_joint_step, spun, alive, why, where,
                )  # fmt: skip
                if alive[row]:
                    scan_row(
                        row, limit[row], b, cq, sq, qs, moves, rows, waypoints, qddot_max,
                        feed, acc_at, acc_joint, acc_speeds, acc_hint, alive, why, where,
                        slowest,
                    )  # fmt: skip
        if followed and why[row] == PRUNED:  # left by its V_acc: the others probed there
            probe_free_acc_rows(
                remaining, limit, acc_hint[row], family, par, poses, branches, qdot_max,
                scratch, cq, sq, qd, status, need, alive, why, where, slowest, acc_hint, bound,
                reach, index, steps_c, qddot_max, steps,
            )  # fmt: skip
        if alive[row] and (best < 0 or feed[row] > feed[best]):
            best = row
            set_limits(limit, row, feed[row], ACC_TIE_RTOL)
            probe_free_rows(
                remaining, limit, slowest_at[row], family, par, poses, spin_poses, branches,
                pure_rotation, qdot_max, scratch, cq, sq, qd, qs, status, need, alive, why,
                where, slowest, hint, reach,
            )  # fmt: skip
            todo[:] = False  # the rows whose hint was probed
            for i in range(branches.shape[0]):
                if remaining[i] and alive[i] and not probed_before(i, hint, todo, slowest_at[row]):
                    probe_free_rows(
                        remaining, limit, hint[i], family, par, poses, spin_poses, branches,
                        pure_rotation, qdot_max, scratch, cq, sq, qd, qs, status, need, alive,
                        why, where, slowest, hint, reach,
                    )  # fmt: skip
                    todo[i] = True
            for i in range(branches.shape[0]):
                bound[i] = min(bound[i], reach[i])
            k = acc_hint[row]
            if k >= 0:
                probe_free_acc_rows(
                    remaining, limit, k, family, par, poses, branches, qdot_max, scratch, cq, sq,
                    qd, status, need, alive, why, where, slowest, acc_hint, bound, reach, index,
                    steps_c, qddot_max, steps,
                )  # fmt: skip
            todo[:] = False  # the rows whose acc_hint was probed
            for i in range(branches.shape[0]):
                if remaining[i] and alive[i] and not probed_before(i, acc_hint, todo, k):
                    probe_free_acc_rows(
                        remaining, limit, acc_hint[i], family, par, poses, branches, qdot_max,
                        scratch, cq, sq, qd, status, need, alive, why, where, slowest, acc_hint,
                        bound, reach, index, steps_c, qddot_max, steps,
                    )  # fmt: skip
                    todo[i] = True
        row = next_row(remaining, alive, bound)
    pick = write_cell(
        c, branches, alive, why, where, feed, ACC_TIE_RTOL, slowest, slowest_at, slowest_joint,
        speeds, mu, reason, failed, branch, bottleneck_waypoint, bottleneck_joint, v_out,
    )  # fmt: skip
    if choice_holds(alive, why, slowest, feed, ACC_TIE_RTOL, pick):
        return pick
    # a left row might change the answer: follow the left rows to the end
    for i in range(branches.shape[0]):
        todo[i] = why[i] == PRUNED
    start_again(todo, alive, why, where)
    limit[:] = -np.inf
    follow_free_rows(
        todo, limit, family, par, poses, spin_poses, branches, pure_rotation, segment_checked,
        qdot_max, max_joint_step, scratch, cq, sq, qd, qs, status, need, alive, why, where,
        slowest, slowest_at, slowest_joint, speeds, hint,
    )  # fmt: skip
    for i in range(branches.shape[0]):
        if todo[i] and alive[i]:
            rate = spin_rate_of(slowest[i], True)
            spin_moves(qd, qs, branches[i], rate, length, qdot_max, moves)
            moved_check(
                i, moves, cq, sq, qd, qs, branches, slowest, length, segment_checked, lower,
                upper, qdot_max, max_joint_step, spun, alive, why, where,
            )  # fmt: skip
            if alive[i]:
                scan_row(
                    i, -np.inf, branches[i], cq, sq, qs, moves, rows, waypoints, qddot_max, feed,
                    acc_at, acc_joint, acc_speeds, acc_hint, alive, why, where, slowest,
                )  # fmt: skip
    return write_cell(
        c, branches, alive, why, where, feed, ACC_TIE_RTOL, slowest, slowest_at, slowest_joint,
        speeds, mu, reason, failed, branch, bottleneck_waypoint, bottleneck_joint, v_out,
    )  # fmt: skip
