"""One placement of a map kernel with joint acceleration limits: branches pruned by mu_acc.

motion.md section 3: a cell's branch is the one with the highest mu_acc
(:func:`solver.path.tracking.choose_branch` with ``ACC_TIE_RTOL``). As without the limits
(:mod:`solver.kernels.cell`), the branch the previous placement chose is followed first, and
once a branch is feasible every other is known by a bound of its mu_acc until the bound is below
its limit (:func:`solver.kernels.cell.set_limits`): its running minimum of V_max (mu_acc <=
mu_path), V_max at the best branch's bottleneck, V_acc at the stencil row where the best
branch's mu_acc binds, both where each branch was least at the placement before (each such
row probed once for all the branches left to follow), and V_acc at the stencil row where a
branch followed to the end was left by its V_acc (the branches of one shoulder share joints,
so they are often left there too: the ERK-size map then follows a sixth fewer branches)
(:mod:`solver.kernels.accelerations`). A branch still in the running is followed to the end
(in free spin tracked along its spin schedule), probed there, and scanned
(:func:`solver.kernels.acc_scan.scan_row`), most promising first. Where a left branch
might change the answer (:func:`solver.kernels.cell.choice_holds`) the left branches are
followed and scanned to the end after all, so every reported field is the full loop's.

:func:`fixed_cell` serves :func:`solver.kernels.fixed_spin.map_cells`,
:func:`solver.kernels.acc_free.free_cell` :func:`solver.kernels.free_spin.free_cells`; the tuples
are theirs. Each call in them names its arrays: a call written with ``*tuple`` (or with more than
30 arguments, which Python passes as one tuple) builds a tuple of its arguments, each array's
reference count up and down once per call, and the calls made per branch were most of the
limits' cost (the ERK-size map, 2026-12-02). The two cells themselves keep numba's reference
counting: compiled without it (``_nrt=False``), a cold cache failed to compile the kernels
(functions that allocate, typed from them, were refused).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.core.codes import ACC_TIE_RTOL
from solver.kernels.acc_scan import scan_row
from solver.kernels.accelerations import (
    left_at_probes,
    probe_acc_rows,
    probed_before,
)
from solver.kernels.cell import PRUNED, choice_holds, next_row, set_limits, start_again, write_cell
from solver.kernels.fixed_follow import fail_first_rows, follow_rows, probe_rows


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def any_left(remaining, alive):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether a row is still to be followed (a probe of none would still solve a waypoint)."""
    for i in range(remaining.shape[0]):
        if remaining[i] and alive[i]:
            return True
    return False


@njit(cache=True, error_model="numpy", nogil=True)
def fixed_cell(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    c, guess, work, posed, path_tests, found, kept, hint, qddot_max, stencil, acc, answer
):
    """Placement c in fixed spin with acceleration limits; returns the chosen branch's row.

    Args:
        c: the placement.
        guess: the row to follow first (the previous placement's choice).
        work: (todo, limit, remaining, bound), per row.
        posed: (family, par, poses, branches, pure_rotation), as
            :func:`solver.kernels.fixed_follow.follow_rows` takes them.
        path_tests: (segment_checked, lower, upper, modes, arc, inverse_qdot, max_joint_step).
        found: (scratch, cq, sq, qd, status, need, alive, why, where).
        kept: (slowest, slowest_at, slowest_joint, speeds, chords2, largest2, inside, crossed).
        hint: shape (B,), where each row's V_max was least.
        qddot_max: shape (6,), rad/s^2.
        stencil: (index, c, waypoints, rows), the blend stencil in step form and in row form
            (:func:`solver.kernels.acc_scan.scan_work`).
        acc: from :func:`solver.kernels.accelerations.acc_work`.
        answer: the answer arrays :func:`solver.kernels.cell.write_cell` fills.
    """
    todo, limit, remaining, bound = work
    family, par, poses, branches, pure_rotation = posed
    segment_checked, lower, upper, modes, arc, inverse_qdot, max_joint_step = path_tests
    scratch, cq, sq, qd, status, need, alive, why, where = found
    slowest, slowest_at, slowest_joint, speeds, chords2, largest2, inside, crossed = kept
    index, steps_c, waypoints, rows = stencil
    feed, acc_at, acc_joint, acc_speeds, acc_hint, steps, moves = acc
    _, _, _, _, mu, reason, failed, branch, bottleneck_waypoint, bottleneck_joint, v_out = answer
    limit[:] = -np.inf
    bound[:] = np.inf
    remaining[:] = True
    best, row = -1, guess
    while row >= 0:
        remaining[row] = False
        todo[:] = False
        todo[row] = True
        follow_rows(
            todo, limit, family, par, poses, branches, pure_rotation, segment_checked, lower,
            upper, modes, arc, inverse_qdot, max_joint_step, scratch, cq, sq, qd, status, need,
            alive, why, where, slowest, slowest_at, slowest_joint, speeds, chords2, largest2,
            inside, crossed, hint,
        )  # fmt: skip
        if row == guess and where[row] == 0:  # out of reach, most likely: all at once
            fail_first_rows(
                remaining, family, par, poses, branches, scratch, cq, sq, qd, status, need,
                alive, why, where,
            )  # fmt: skip
        followed = alive[row]
        if followed:
            probes = (acc_hint[best] if best >= 0 else -1, acc_hint[row])
            b = branches[row]
            if best < 0 or not left_at_probes(  # the first row has no bar to be left under
                row, limit[row], probes, b, 0.0, cq, sq, qd, qd, inverse_qdot, inverse_qdot,
                index, steps_c, qddot_max, steps, alive, why, where, slowest, acc_hint,
            ):  # fmt: skip
                scan_row(
                    row, limit[row], b, cq, sq, qd, moves, rows, waypoints, qddot_max, feed,
                    acc_at, acc_joint, acc_speeds, acc_hint, alive, why, where, slowest,
                )  # fmt: skip
        if followed and why[row] == PRUNED:  # left by its V_acc: the others probed there
            probe_acc_rows(
                remaining, limit, acc_hint[row], family, par, poses, branches, scratch, cq, sq,
                qd, status, need, alive, why, where, slowest, acc_hint, bound, index, steps_c,
                qddot_max, steps,
            )  # fmt: skip
        if alive[row] and (best < 0 or feed[row] > feed[best]):
            best = row
            set_limits(limit, row, feed[row], ACC_TIE_RTOL)
            k = acc_hint[row]
            if k >= 0:
                probe_acc_rows(
                    remaining, limit, k, family, par, poses, branches, scratch, cq, sq, qd,
                    status, need, alive, why, where, slowest, acc_hint, bound, index, steps_c,
                    qddot_max, steps,
                )  # fmt: skip
            todo[:] = False  # the rows whose acc_hint was probed
            for i in range(branches.shape[0]):  # where each row was least before, once each
                if remaining[i] and alive[i] and not probed_before(i, acc_hint, todo, k):
                    probe_acc_rows(
                        remaining, limit, acc_hint[i], family, par, poses, branches, scratch,
                        cq, sq, qd, status, need, alive, why, where, slowest, acc_hint, bound,
                        index, steps_c, qddot_max, steps,
                    )  # fmt: skip
                    todo[i] = True
            if any_left(remaining, alive):  # V_max where the best is least, after V_acc
                probe_rows(
                    remaining, limit, slowest_at[row], family, par, poses, branches,
                    pure_rotation, inverse_qdot, scratch, cq, sq, qd, status, need, alive, why,
                    where, slowest, hint, bound,
                )  # fmt: skip
            todo[:] = False  # the rows whose hint was probed
            for i in range(branches.shape[0]):
                if remaining[i] and alive[i] and not probed_before(i, hint, todo, slowest_at[row]):
                    probe_rows(
                        remaining, limit, hint[i], family, par, poses, branches, pure_rotation,
                        inverse_qdot, scratch, cq, sq, qd, status, need, alive, why, where,
                        slowest, hint, bound,
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
    follow_rows(
        todo, limit, family, par, poses, branches, pure_rotation, segment_checked, lower, upper,
        modes, arc, inverse_qdot, max_joint_step, scratch, cq, sq, qd, status, need, alive, why,
        where, slowest, slowest_at, slowest_joint, speeds, chords2, largest2, inside, crossed,
        hint,
    )  # fmt: skip
    for i in range(branches.shape[0]):
        if todo[i] and alive[i]:
            scan_row(
                i, -np.inf, branches[i], cq, sq, qd, moves, rows, waypoints, qddot_max, feed,
                acc_at, acc_joint, acc_speeds, acc_hint, alive, why, where, slowest,
            )  # fmt: skip
    return write_cell(
        c, branches, alive, why, where, feed, ACC_TIE_RTOL, slowest, slowest_at, slowest_joint,
        speeds, mu, reason, failed, branch, bottleneck_waypoint, bottleneck_joint, v_out,
    )  # fmt: skip
