"""The cell skeleton both map kernels share: one placement's poses, tests and answer.

A map kernel (:mod:`solver.kernels.fixed_spin`, :mod:`solver.kernels.free_spin`) evaluates a
placement, a cell of the map, as the numpy pipeline does (dtf.md section 9): the path turned by
the placement's yaw and moved (:func:`turned_poses`); the family's pose kernel over blocks of
:data:`BLOCK` waypoints; per branch the IK and step tests and the running minimum of the speed
bound; then the branch, by :func:`solver.path.tracking.choose_branch`'s rule, written to the
answer arrays (:func:`write_cell`). Pruning: with a feasible branch at ``best``, a branch whose
mu_path bound (a probe's or its running minimum) cannot be chosen is left (:func:`set_limits`,
:func:`prune`, :func:`next_row`), and :func:`choice_holds` says whether the answer stands
whatever the pruned branches' mu_path. What differs between the kernels (the speed bound, the
position limits' tests, the spin schedule) stays in each.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.core.codes import FEASIBLE
from solver.families.kernels import N_BRANCHES, N_JOINTS, scratch_size, warm_up_arm

# A pruned branch's ``why``: never reported (see :func:`prune`).
PRUNED = -2
# Waypoints solved together: the pose kernels run level by level over a block, and a block is
# the unit of the early stop when every branch has failed.
BLOCK = 32


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def pose_work(n_waypoints):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The arrays of a path of W waypoints that :func:`solver.families.kernels.pose_block` fills.

    Returns:
        cq, sq, qd: shape (8, 6, W), the joints' (cos, sin) pairs and J^-1 t per branch;
        status: shape (8, W); poses: shape (21, W), as :func:`turned_poses`; scratch; need:
        shape (8,), bool, the branches to solve.
    """
    cq = np.empty((N_BRANCHES, N_JOINTS, n_waypoints))
    sq = np.empty((N_BRANCHES, N_JOINTS, n_waypoints))
    qd = np.empty((N_BRANCHES, N_JOINTS, n_waypoints))
    status = np.empty((N_BRANCHES, n_waypoints), dtype=np.int64)
    poses = np.empty((21, n_waypoints))
    scratch = np.empty(scratch_size(n_waypoints))
    need = np.empty(N_BRANCHES, dtype=np.bool_)
    return cq, sq, qd, status, poses, scratch, need


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def branch_work(n_branches, n_waypoints, keep_speeds):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Per branch followed: alive, why and where it failed, its mu_path and where it binds.

    Returns:
        alive, why, where, slowest (mu_path so far), slowest_at, slowest_joint: shape (B,);
        speeds: shape (B, W), V_max per waypoint, or (0, 0) when not ``keep_speeds``.
    """
    alive = np.empty(n_branches, dtype=np.bool_)
    why = np.empty(n_branches, dtype=np.int64)
    where = np.empty(n_branches, dtype=np.int64)
    slowest = np.empty(n_branches)
    slowest_at = np.empty(n_branches, dtype=np.int64)
    slowest_joint = np.empty(n_branches, dtype=np.int64)
    speeds = np.empty((n_branches, n_waypoints)) if keep_speeds else np.empty((0, 0))
    return alive, why, where, slowest, slowest_at, slowest_joint, speeds


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def start_cell(alive, why, where):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Every branch alive, none failed, before a placement."""
    alive[:] = True
    why[:] = FEASIBLE
    where[:] = -1


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def start_again(rows, alive, why, where):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The rows marked in ``rows`` alive again, none failed, to be followed from the start."""
    for i in range(rows.shape[0]):
        if rows[i]:
            alive[i] = True
            why[i] = FEASIBLE
            where[i] = -1


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def wanted_branches(branches, alive, need):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Mark in ``need`` (8,) the branch indices of ``branches`` that are still ``alive``."""
    need[:] = False
    for i in range(branches.shape[0]):
        need[branches[i]] = need[branches[i]] or alive[i]


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def fail(i, code, w, alive, why, where):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch row i fails for reason ``code`` at waypoint w."""
    alive[i] = False
    why[i] = code
    where[i] = w


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def prune(i, w, bound, alive, why, where, slowest, hint):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Branch row i is left at waypoint w, its mu_path known to be at most ``bound``.

    The row keeps ``bound`` in ``slowest`` (-inf where it fails) for :func:`choice_holds`;
    its ``why`` and ``where`` are never reported (the cell is feasible: see
    :func:`set_limits`).
    """
    alive[i] = False
    why[i] = PRUNED
    where[i] = -1
    slowest[i] = bound
    hint[i] = w


@njit(cache=True, error_model="numpy", nogil=True)
def set_limits(limit, g, best, tie):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Per row, the mu_path bound under which it is pruned, once row g is feasible at ``best``.

    :func:`write_cell` takes the first row within the relative ``tie`` of the highest, which is
    at least ``best``: a row before g below best - tie |best| is never chosen (twice the tie
    leaves the rounding aside); a row after g at most ``best`` is not chosen before g, and
    one a hair above (half the tie) moves the highest by less than the tie. Whether the cell's
    answer holds with every pruned row at its bound is checked after (:func:`choice_holds`).
    """
    for i in range(limit.shape[0]):
        if i < g:
            limit[i] = best - 2.0 * tie * abs(best)
        elif i > g:
            limit[i] = best + 0.5 * tie * abs(best)
        else:
            limit[i] = -np.inf


@njit(cache=True, error_model="numpy", nogil=True)
def next_row(remaining, alive, bound):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The row to follow next, or -1: the first remaining alive row whose bound is about the top.

    ``bound`` is the least speed bound a row's probes saw. The first of a near tie, as the
    choice prefers it: rows after it then go at their probes.
    """
    top = -np.inf
    for i in range(remaining.shape[0]):
        if remaining[i] and alive[i]:
            top = max(top, bound[i])
    near = top - 1e-9 * abs(top) if np.isfinite(top) else top
    for i in range(remaining.shape[0]):
        if remaining[i] and alive[i] and bound[i] >= near:
            return i
    return -1


@njit(cache=True, error_model="numpy", nogil=True)
def choice_holds(alive, why, slowest, feed, tie, pick):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Whether row ``pick`` is the cell's answer whatever the pruned rows' mu_path.

    ``pick`` is chosen among the rows followed to the end; each pruned row's mu_path is at most
    its bound in ``slowest``, or it is infeasible. The highest index may rise from T (the rows
    followed) up to U (the largest bound): the pick must stay within the tie of U, and no
    pruned row before it may reach the tie of T (the rows followed before it do not: it is
    the first that does). Margins of half and
    twice the tie leave the rounding of the tie test aside.
    """
    top = -np.inf
    for i in range(alive.shape[0]):
        if alive[i]:
            top = max(top, feed[i])
    upper = top
    for i in range(alive.shape[0]):
        if why[i] == PRUNED:
            upper = max(upper, slowest[i])
            if i < pick and not slowest[i] < top - 2.0 * tie * abs(top):
                return False
    return feed[pick] >= upper - 0.5 * tie * abs(upper)


@njit(cache=True, error_model="numpy", nogil=True)
def turned_poses(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    c, cos_yaw, sin_yaw, offset, flange_rotation, flange_position, tool_position, twist, poses
):  # fmt: skip
    """Fill ``poses`` (21, W) for placement c: the path turned by its yaw and moved.

    Rows: R_B_F row by row (0-8), p_B_F (9-11), t_hat in {B} (12-17), the tool point (18-20);
    the same arithmetic as :func:`solver.path.placed.turn_by_yaw`. Called for the placements
    in order, ``poses`` holding placement c - 1's when c > 0: where c - 1 had the same yaw (a
    map's cells share one), the rows only the yaw sets (the rotation and the twist) are kept
    and only the positions written (the turn was 0.3 ms of the ERK-size map's 5.4 ms on one
    thread, 2026-12-03).
    """
    ca, sa = cos_yaw[c], sin_yaw[c]
    if c == 0 or ca != cos_yaw[c - 1] or sa != sin_yaw[c - 1]:
        for w in range(flange_rotation.shape[0]):
            for k in range(3):  # R_B_F = Rz(yaw) R_O_F, row by row
                x, y = flange_rotation[w, 0, k], flange_rotation[w, 1, k]
                poses[k, w] = ca * x - sa * y
                poses[3 + k, w] = sa * x + ca * y
                poses[6 + k, w] = flange_rotation[w, 2, k]
            for k in range(0, 6, 3):
                x, y = twist[w, k], twist[w, k + 1]
                poses[12 + k, w] = ca * x - sa * y
                poses[13 + k, w] = sa * x + ca * y
                poses[14 + k, w] = twist[w, k + 2]
    for w in range(flange_rotation.shape[0]):
        x, y = flange_position[w, 0], flange_position[w, 1]
        poses[9, w] = ca * x - sa * y + offset[c, 0]
        poses[10, w] = sa * x + ca * y + offset[c, 1]
        poses[11, w] = flange_position[w, 2] + offset[c, 2]
        x, y = tool_position[w, 0], tool_position[w, 1]
        poses[18, w] = ca * x - sa * y + offset[c, 0]
        poses[19, w] = sa * x + ca * y + offset[c, 1]
        poses[20, w] = tool_position[w, 2] + offset[c, 2]


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def spin_poses_of(poses, tool_axis, ca, sa, spin_poses):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``poses`` (21, W) with the twist rows the spin's, [0; z_tool] in {B}, into ``spin_poses``.

    The path turned by the placement's yaw (cos ``ca``, sin ``sa``): the pose kernel then gives
    J^-1 [0; z_tool] (free spin, cam.md section 2). ``tool_axis``: shape (W, 3), z of the tool
    in {O}.
    """
    spin_poses[:] = poses
    for w in range(poses.shape[1]):
        x, y = tool_axis[w, 0], tool_axis[w, 1]
        spin_poses[12, w] = 0.0
        spin_poses[13, w] = 0.0
        spin_poses[14, w] = 0.0
        spin_poses[15, w] = ca * x - sa * y
        spin_poses[16, w] = sa * x + ca * y
        spin_poses[17, w] = tool_axis[w, 2]


@njit(cache=True, error_model="numpy", nogil=True)
def write_cell(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    c, branches, alive, why, where, feed, tie, slowest, slowest_at, slowest_joint, speeds,
    mu, reason, failed, branch, bottleneck_waypoint, bottleneck_joint, v_out,
):  # fmt: skip
    """Placement c's answer from its branches: :func:`solver.path.tracking.choose_branch`'s rule.

    The highest ``feed`` (mu_path, ``slowest``; mu_acc with acceleration limits) among the
    branches ``alive``, ties (within the relative ``tie``: ``TIE_RTOL``, for mu_acc
    ``ACC_TIE_RTOL``) to the first; where none is, the one that failed furthest along
    (``why`` and ``where``, the first at a tie). Returns the row of the branch chosen.
    """
    n_branches = branches.shape[0]
    top = -np.inf
    for i in range(n_branches):
        if alive[i] and feed[i] > top:
            top = feed[i]
    pick = -1
    for i in range(n_branches):
        if alive[i] and feed[i] >= top - tie * abs(top):
            pick = i
            break
    if pick >= 0:
        mu[c] = slowest[pick]
        reason[c] = FEASIBLE
        failed[c] = -1
        bottleneck_waypoint[c] = slowest_at[pick]
        bottleneck_joint[c] = slowest_joint[pick]
        for w in range(v_out.shape[1]):
            v_out[c, w] = speeds[pick, w]
    else:
        furthest = -1
        for i in range(n_branches):
            furthest = max(furthest, where[i])
        for i in range(n_branches):
            if where[i] == furthest:
                pick = i
                break
        mu[c] = np.nan
        reason[c] = why[pick]
        failed[c] = where[pick]
        bottleneck_waypoint[c] = -1
        bottleneck_joint[c] = -1
        for w in range(v_out.shape[1]):
            v_out[c, w] = np.nan
    branch[c] = branches[pick]
    return pick


def warm_up_answers() -> tuple[np.ndarray, ...]:
    """The kernels' twelve answer arrays for one placement, V_max and accelerations not wanted."""
    speeds = (np.empty(1), *(np.empty(1, dtype=np.int64) for _ in range(5)), np.empty((1, 0)))
    integer = np.empty(0, dtype=np.int64)
    return (*speeds, np.empty(0), integer, integer, integer, np.empty((1, 0)))


def warm_up_accelerations() -> tuple[np.ndarray, ...]:
    """The kernels' acceleration inputs without acceleration limits: qddot_max and stencil."""
    return (np.empty(0), np.zeros((0, 5), dtype=np.int64), np.zeros((0, 5)),
            np.zeros(0, dtype=np.int64))  # fmt: skip


def warm_up_placement() -> tuple[object, ...]:
    """The kernels' first nine arguments for one placement of a two-waypoint path.

    The arm is the families' warm-up arm (:func:`solver.families.kernels.warm_up_arm`).
    """
    rotation = np.tile(np.diag([1.0, -1.0, -1.0]), (2, 1, 1))
    position = np.array([[0.0, 0.4, 0.2], [0.01, 0.4, 0.2]])
    twist = np.tile([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], (2, 1))
    code, parameters = warm_up_arm()
    return (code, parameters, np.ones(1), np.zeros(1), np.zeros((1, 3)), rotation, position,
            position.copy(), twist)  # fmt: skip
