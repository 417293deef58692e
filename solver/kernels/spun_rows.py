"""Free spin's spun paths on a closed-form family, compiled: each row's poses solved by its label.

cam.md section 2 and :mod:`solver.path.exact_spin`: where the spin moves more than the last joint
(an angled or offset spindle), each branch is solved again at its spun poses R_i Rz(phi_i) and
judged as that path. :func:`solver.path.exact_spin.spun_exactly` did it with numpy: every
branch's IK at every spun pose (eight where one is wanted), the spun path's twists, and J^-1 of
three vectors, each a pass over arrays of every row: the UR5 with an angled tool mapped the
ERK-size grid in 4.1-4.2 s of CPU where the straight spindle's kernel takes 0.022 s; with this
kernel 1.7 s (the schedules, the tracking and the LPs stay numpy's). Here, per row (a branch
at a placement, its spins along the path), in one loop over the waypoints: the spun tool and
flange poses, the spun path's t_hat (:func:`solver.core.task.task_requirements`' arithmetic:
the rotation vector of R'_{i+1} R'_i^T by :func:`solver.core.spatial.rotation_vectors`' formula,
then u_T, u_R, h and t_hat), then the family's pose kernel on that one branch
(:func:`solver.families.kernels.pose_block`) with three twists at the tool point: the spun
path's t_hat (its V_max), and for the next round's LP at these joints the unspun t_hat and the
spin [0; z_tool]. The numpy pipeline stays the reference (tests/solver/test_spun_rows_kernel.py:
the same spun paths and answers).

A segment whose spun rotation is within 1e-2 rad of a half turn takes its rotation vector from
pinocchio's ``log3`` in numpy (:func:`solver.core.spatial.rotation_vectors`): the row is marked
in ``near_half_turn`` and the caller solves it there.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import UNREACHABLE
from solver.core.spatial import NEAR_HALF_TURN
from solver.core.task import ANGULAR_TOLERANCE, LINEAR_TOLERANCE
from solver.families.kernels import N_JOINTS, pose_block, warm_up_arm
from solver.kernels.cache import drop_stale_compiled_code
from solver.kernels.cell import BLOCK, pose_work

drop_stale_compiled_code(__name__)


@njit(cache=True, error_model="numpy", nogil=True)
def spun_rows(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    family,
    par,
    tool_rotation,
    tool_position,
    tool_to_flange,
    own_flange,
    twist,
    cos_yaw,
    sin_yaw,
    offset,
    angles,
    rows,
    q,
    status,
    qd_spun,
    qd_unit,
    qd_spin,
    near_half_turn,
):
    """Solve K rows at their spun poses; the answers go to the arrays after ``rows``.

    Args:
        family: the family's kernel code (:mod:`solver.families.kernels`).
        par: the family's kernel parameters.
        tool_rotation: shape (W, 3, 3), R_O_T, the path's tool rotations in {O}.
        tool_position: shape (W, 3), m, the tool points in {O}.
        tool_to_flange: shape (4, 4), T_T_F: the flange is T_O_T Rz(phi) T_T_F.
        own_flange: shape (4, 4), E, where the flange sits on the family's own
            (:class:`solver.core.spatial.FlangeOffset`; the identity where it is the family's).
        twist: shape (W, 6), the unspun path's t_hat in {O}.
        cos_yaw: shape (K,), cos of each row's placement yaw (in the family's frame).
        sin_yaw: shape (K,), its sine.
        offset: shape (K, 3), m, each row's placement position.
        angles: shape (K, W), rad, each row's spin at each waypoint.
        rows: shape (K,), the family's branch index of each row.
        q: shape (6, K, W), out: the joint angles (atan2 of the kernel's pairs; NaN where
            unreachable), rad.
        status: shape (K, W), out: ``OK``, ``UNREACHABLE`` or ``SINGULAR``.
        qd_spun: shape (6, K, W), out: J^-1 of the spun path's t_hat, at the tool point.
        qd_unit: shape (6, K, W), out: J^-1 of the unspun t_hat there (the LP's, at these
            joints).
        qd_spin: shape (6, K, W), out: J^-1 [0; z_tool] there.
        near_half_turn: shape (K,), out: a segment of the row turns within 1e-2 rad of a half
            turn (its other outputs are not meaningful).
    """
    n_waypoints = tool_rotation.shape[0]
    cq, sq, qd, found, poses, scratch, need = pose_work(n_waypoints)
    spun = np.empty((n_waypoints, 3, 3))  # R_O_T Rz(phi) of the row
    flange, point = np.empty((3, 3)), np.empty(3)  # a waypoint's flange pose
    spun_twist = np.empty((n_waypoints, 6))  # its t_hat in {O}
    for k in range(rows.shape[0]):
        ca, sa = cos_yaw[k], sin_yaw[k]
        b = rows[k]
        near_half_turn[k] = False
        for w in range(n_waypoints):
            c, s = math.cos(angles[k, w]), math.sin(angles[k, w])
            for i in range(3):
                x, y = tool_rotation[w, i, 0], tool_rotation[w, i, 1]
                spun[w, i, 0] = c * x + s * y
                spun[w, i, 1] = c * y - s * x
                spun[w, i, 2] = tool_rotation[w, i, 2]
            # the flange in {O}, turned by the yaw and moved, then the family's own flange on
            # it: rows 0-11 of the poses, in the numpy arithmetic's order (the same roundings)
            for i in range(3):
                r0, r1, r2 = spun[w, i, 0], spun[w, i, 1], spun[w, i, 2]
                for m in range(3):
                    flange[i, m] = (
                        r0 * tool_to_flange[0, m]
                        + r1 * tool_to_flange[1, m]
                        + r2 * tool_to_flange[2, m]
                    )
                point[i] = tool_position[w, i] + (
                    r0 * tool_to_flange[0, 3]
                    + r1 * tool_to_flange[1, 3]
                    + r2 * tool_to_flange[2, 3]
                )
            for m in range(3):  # R_B_F = Rz(yaw) R_O_F, column by column
                x, y = flange[0, m], flange[1, m]
                flange[0, m] = ca * x - sa * y
                flange[1, m] = sa * x + ca * y
            x, y = point[0], point[1]
            point[0] = ca * x - sa * y + offset[k, 0]
            point[1] = sa * x + ca * y + offset[k, 1]
            point[2] = point[2] + offset[k, 2]
            for i in range(3):  # R_B_F' = R_B_F E_R^T, p_B_F' = p_B_F - R_B_F' E_p
                for m in range(3):
                    poses[3 * i + m, w] = (
                        flange[i, 0] * own_flange[m, 0]
                        + flange[i, 1] * own_flange[m, 1]
                        + flange[i, 2] * own_flange[m, 2]
                    )
            for i in range(3):
                poses[9 + i, w] = point[i] - (
                    poses[3 * i, w] * own_flange[0, 3]
                    + poses[3 * i + 1, w] * own_flange[1, 3]
                    + poses[3 * i + 2, w] * own_flange[2, 3]
                )
            x, y = tool_position[w, 0], tool_position[w, 1]
            poses[18, w] = ca * x - sa * y + offset[k, 0]
            poses[19, w] = sa * x + ca * y + offset[k, 1]
            poses[20, w] = tool_position[w, 2] + offset[k, 2]
        for w in range(n_waypoints - 1):
            if not segment_twist(spun, tool_position, w, spun_twist):
                near_half_turn[k] = True
        if near_half_turn[k]:
            continue
        spun_twist[n_waypoints - 1, :] = spun_twist[n_waypoints - 2, :]  # its segment's
        need[:] = False
        need[b] = True
        for vector in range(3):  # the spun t_hat, the unspun t_hat, the spin [0; z_tool]
            for w in range(n_waypoints):
                for part in range(2):
                    if vector == 0:
                        x = spun_twist[w, 3 * part]
                        y = spun_twist[w, 3 * part + 1]
                        z = spun_twist[w, 3 * part + 2]
                    elif vector == 1:
                        x, y, z = twist[w, 3 * part], twist[w, 3 * part + 1], twist[w, 3 * part + 2]
                    elif part == 0:
                        x, y, z = 0.0, 0.0, 0.0
                    else:
                        x, y, z = (
                            tool_rotation[w, 0, 2],
                            tool_rotation[w, 1, 2],
                            tool_rotation[w, 2, 2],
                        )
                    poses[12 + 3 * part, w] = ca * x - sa * y
                    poses[13 + 3 * part, w] = sa * x + ca * y
                    poses[14 + 3 * part, w] = z
            for w0 in range(0, n_waypoints, BLOCK):
                w1 = min(w0 + BLOCK, n_waypoints)
                pose_block(family, par, poses, w0, w1, need, scratch, cq, sq, found, qd)
            out = qd_spun if vector == 0 else (qd_unit if vector == 1 else qd_spin)
            for j in range(N_JOINTS):
                for w in range(n_waypoints):
                    out[j, k, w] = qd[b, j, w]
        for w in range(n_waypoints):
            status[k, w] = found[b, w]
            for j in range(N_JOINTS):
                unreachable = found[b, w] == UNREACHABLE  # NaN there, as the numpy IK gives
                q[j, k, w] = np.nan if unreachable else math.atan2(sq[b, j, w], cq[b, j, w])


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def segment_twist(spun, tool_position, w, spun_twist):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """t_hat of the spun path's segment from waypoint w into ``spun_twist[w]``, in {O}.

    :func:`solver.core.spatial.rotation_vectors` of R'_{w+1} R'_w^T (the skew part's formula),
    then :func:`solver.core.task.segment_requirements` and
    :func:`solver.core.task.twists_of`. Returns False where the rotation is within
    NEAR_HALF_TURN of a half turn (the numpy formula then reads pinocchio's log3).
    """
    r = np.empty((3, 3))
    for i in range(3):
        for m in range(3):
            r[i, m] = (
                spun[w + 1, i, 0] * spun[w, m, 0]
                + spun[w + 1, i, 1] * spun[w, m, 1]
                + spun[w + 1, i, 2] * spun[w, m, 2]
            )
    wx = 0.5 * (r[2, 1] - r[1, 2])
    wy = 0.5 * (r[0, 2] - r[2, 0])
    wz = 0.5 * (r[1, 0] - r[0, 1])
    sine = math.sqrt(wx * wx + wy * wy + wz * wz)
    theta = math.atan2(sine, (r[0, 0] + r[1, 1] + r[2, 2] - 1.0) / 2.0)
    if theta >= NEAR_HALF_TURN:
        return False
    ratio = theta / sine if theta > 1e-4 else 1.0 + theta**2 / 6.0
    vx, vy, vz = ratio * wx, ratio * wy, ratio * wz
    dx = tool_position[w + 1, 0] - tool_position[w, 0]
    dy = tool_position[w + 1, 1] - tool_position[w, 1]
    dz = tool_position[w + 1, 2] - tool_position[w, 2]
    linear = math.sqrt(dx * dx + dy * dy + dz * dz)
    angular = math.sqrt(vx * vx + vy * vy + vz * vz)
    moving = linear >= LINEAR_TOLERANCE
    turning = angular >= ANGULAR_TOLERANCE
    if moving:
        spun_twist[w, 0], spun_twist[w, 1], spun_twist[w, 2] = dx / linear, dy / linear, dz / linear
    else:
        spun_twist[w, 0], spun_twist[w, 1], spun_twist[w, 2] = 0.0, 0.0, 0.0
    if not turning:  # h = inf: pure translation, no angular part
        spun_twist[w, 3], spun_twist[w, 4], spun_twist[w, 5] = 0.0, 0.0, 0.0
    elif not moving:  # h = 0: pure reorientation, u_R itself
        spun_twist[w, 3], spun_twist[w, 4], spun_twist[w, 5] = (
            vx / angular,
            vy / angular,
            vz / angular,
        )
    else:  # u_R / h, h = |dp| / |dtheta|
        h = linear / angular
        spun_twist[w, 3] = vx / angular / h
        spun_twist[w, 4] = vy / angular / h
        spun_twist[w, 5] = vz / angular / h
    return True


def warm_up() -> None:
    """Compile the kernel, or load it from the disk cache, so that no request pays for it.

    One row of a two-waypoint path of the families' warm-up arm (a UR5), its tool the flange.
    """
    code, parameters = warm_up_arm()
    rotation = np.tile(np.diag([1.0, -1.0, -1.0]), (2, 1, 1))
    position = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]])
    twist = np.tile([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], (2, 1))
    speeds = [np.empty((6, 1, 2)) for _ in range(4)]
    spun_rows(
        code, parameters, rotation, position, np.eye(4), np.eye(4), twist, np.ones(1),
        np.zeros(1), np.array([[0.0, 0.4, 0.2]]), np.zeros((1, 2)), np.zeros(1, dtype=np.int64),
        speeds[0], np.empty((1, 2), dtype=np.int64), *speeds[1:], np.empty(1, dtype=np.bool_),
    )  # fmt: skip
