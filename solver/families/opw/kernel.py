"""The OPW family's pose kernel for the compiled maps (:mod:`solver.kernels`): (cos, sin) pairs.

The same closed forms as :mod:`solver.families.opw.ik` and :mod:`solver.families.opw.jacobian`
for a block of flange poses and all eight branches, with every angle kept as its (cos, sin) pair
(dtf.md section 9) and the work shared per level: the shoulder (2), the elbow (2 x 2), the
flipped wrist as a half turn. The singular and reach tests use the same quantities and
tolerances as the numpy IK; the numpy family is the reference the kernel is tested against.

Parameters (``par``, :func:`kernel_parameters`): a1, a2, b, c1, c2, c3, c4 (m), then the six
offsets as cosines, their sines, and the six sign corrections.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.families.opw.ik import REACH_TOLERANCE, SINGULAR_TOLERANCE
from solver.families.opw.parameters import OpwParameters
from solver.families.pairs import unit_pair


def kernel_parameters(p: OpwParameters) -> np.ndarray:
    """The kernel's parameter vector of an OPW arm."""
    lengths = [p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4]
    offsets = np.array(p.offsets, dtype=float)
    signs = np.array(p.sign_corrections, dtype=float)
    return np.concatenate([lengths, np.cos(offsets), np.sin(offsets), signs])


SCRATCH_ROWS = 24  # rows of the scratch array opw_block needs


@njit(cache=True, error_model="numpy", nogil=True)
def opw_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK on all eight branches and J^-1 t on each, for the waypoints w0..w1 of a path.

    Arguments as :func:`solver.families.ur.kernel.ur_block`; ``cq``, ``sq`` and ``qd`` in the
    maker's convention (q = s (theta + o)). Level by level: the shoulder, then the elbow, whose
    loop writes both wrists (the flipped one is a half turn).
    """
    a1, a2, b, c1_len, c2_len, c3_len, c4 = par[0], par[1], par[2], par[3], par[4], par[5], par[6]
    k2 = a2 * a2 + c3_len * c3_len
    k = math.sqrt(k2)
    c_psi, s_psi = unit_pair(c3_len, a2)  # psi3 = atan2(a2, c3)
    k_h = math.hypot(a2, c3_len)
    t = scratch[: SCRATCH_ROWS * poses.shape[1]].reshape((SCRATCH_ROWS, poses.shape[1]))
    for w in range(w0, w1):
        cx = poses[9, w] - c4 * poses[2, w]
        cy = poses[10, w] - c4 * poses[5, w]
        radial2 = cx * cx + cy * cy - b * b
        lever = math.sqrt(max(radial2, 0.0))
        t[0, w] = poses[11, w] - c4 * poses[8, w] - c1_len  # height
        t[1, w] = radial2
        t[2, w] = lever
        t[3, w], t[4, w] = unit_pair(cx, cy)  # heading
        t[5, w], t[6, w] = unit_pair(lever, b)  # side
    for shoulder in range(2):
        if not need[4 * shoulder : 4 * shoulder + 4].any():
            continue
        for w in range(w0, w1):
            c_head, s_head, c_side, s_side = t[3, w], t[4, w], t[5, w], t[6, w]
            height, lever = t[0, w], t[2, w]
            if shoulder == 0:  # theta1 = heading - side
                c1 = c_head * c_side + s_head * s_side
                s1 = s_head * c_side - c_head * s_side
                forward = lever - a1
            else:  # heading + side - pi
                c1 = -(c_head * c_side - s_head * s_side)
                s1 = -(s_head * c_side + c_head * s_side)
                forward = lever + a1
            s2sq = forward * forward + height * height
            cos_elbow = (s2sq - c2_len * c2_len - k2) / (2.0 * c2_len * k)
            cos_shoulder = (s2sq + c2_len * c2_len - k2) / (2.0 * c2_len * math.sqrt(s2sq))
            reach = (
                t[1, w] >= -REACH_TOLERANCE
                and abs(cos_elbow) <= 1.0 + REACH_TOLERANCE
                and abs(cos_shoulder) <= 1.0 + REACH_TOLERANCE
            )
            ce = min(max(cos_elbow, -1.0), 1.0)
            cs = min(max(cos_shoulder, -1.0), 1.0)
            c_to, s_to = unit_pair(height, forward)  # angle_to = atan2(forward, height)
            t[7, w], t[8, w] = c1, s1
            t[9, w], t[10, w] = ce, math.sqrt(1.0 - ce * ce)
            t[11, w], t[12, w] = cs, math.sqrt(1.0 - cs * cs)
            t[13, w], t[14, w] = c_to, -s_to if shoulder == 1 else s_to
            t[15, w] = 1.0 if reach else 0.0
            arm = 1.0 - ce * ce < SINGULAR_TOLERANCE**2 or lever < SINGULAR_TOLERANCE
            t[16, w] = 1.0 if arm else 0.0
            t[17, w] = poses[0, w] * c1 + poses[3, w] * s1  # ux
            t[18, w] = poses[1, w] * c1 + poses[4, w] * s1  # uy
            t[19, w] = poses[2, w] * c1 + poses[5, w] * s1  # uz
            t[20, w] = poses[5, w] * c1 - poses[2, w] * s1  # y' . z_F
            t[21, w] = poses[4, w] * c1 - poses[1, w] * s1  # y' . y_F
        for elbow in range(2):
            first = 4 * shoulder + 2 * elbow
            if not (need[first] or need[first + 1]):
                continue
            e_sign = 1.0 if elbow == 0 else -1.0
            for w in range(w0, w1):
                c1, s1 = t[7, w], t[8, w]
                ce, se, cs, ss = t[9, w], e_sign * t[10, w], t[11, w], e_sign * t[12, w]
                c_to, s_to = t[13, w], t[14, w]
                ux, uy, uz, y_z, y_y = t[17, w], t[18, w], t[19, w], t[20, w], t[21, w]
                # theta3 = +-acos_elbow - psi3; theta2 = angle_to -+ acos_shoulder
                c3 = ce * c_psi + se * s_psi
                s3 = se * c_psi - ce * s_psi
                c2 = c_to * cs + s_to * ss
                s2 = s_to * cs - c_to * ss
                c23 = c2 * c3 - s2 * s3
                s23 = s2 * c3 + c2 * s3
                m = s23 * uz + c23 * poses[8, w]
                x_z = c23 * uz - s23 * poses[8, w]
                z_y = s23 * uy + c23 * poses[7, w]
                z_x = s23 * ux + c23 * poses[6, w]
                sin5 = math.sqrt(x_z * x_z + y_z * y_z)
                c5, s5 = unit_pair(m, sin5)
                wrist_singular = sin5 < SINGULAR_TOLERANCE
                if wrist_singular:
                    x_y = c23 * uy - s23 * poses[7, w]
                    c4a, s4a = unit_pair(y_y, -x_y)
                    c6a, s6a = 1.0, 0.0
                else:
                    c4a, s4a = unit_pair(x_z, y_z)
                    c6a, s6a = unit_pair(-z_x, z_y)
                if t[15, w] == 0.0:
                    code = UNREACHABLE
                elif t[16, w] > 0.0 or wrist_singular:
                    code = SINGULAR
                else:
                    code = OK
                # J^-1 t (solver.families.opw.jacobian, paper's angles); the flipped wrist has
                # theta4 + pi, -theta5, theta6 - pi.
                v_x, v_y, v_z = poses[12, w], poses[13, w], poses[14, w]
                om_x, om_y, om_z = poses[15, w], poses[16, w], poses[17, w]
                elbow_x = a1 + c2_len * s2
                elbow_z = c1_len + c2_len * c2
                wrist_x = elbow_x + k_h * (s23 * c_psi + c23 * s_psi)
                wrist_z = elbow_z + k_h * (c23 * c_psi - s23 * s_psi)
                r_x = wrist_x * c1 - b * s1 - poses[18, w]
                r_y = wrist_x * s1 + b * c1 - poses[19, w]
                r_z = wrist_z - poses[20, w]
                vw_x = v_x + om_y * r_z - om_z * r_y
                vw_y = v_y + om_z * r_x - om_x * r_z
                vw_z = v_z + om_x * r_y - om_y * r_x
                along = vw_x * c1 + vw_y * s1
                across = vw_y * c1 - vw_x * s1
                qd1 = across / wrist_x
                d_x, d_z = wrist_x - a1, wrist_z - c1_len
                e_x, e_z = wrist_x - elbow_x, wrist_z - elbow_z
                rhs_x = along + b * qd1
                det = e_z * d_x - d_z * e_x
                qd2 = -(rhs_x * e_x + e_z * vw_z) / det
                qd3 = (d_z * vw_z + d_x * rhs_x) / det
                qd23 = qd2 + qd3
                wx = om_x * c1 + om_y * s1
                wy = om_y * c1 - om_x * s1 - qd23
                wz = om_z - qd1
                wc_x = c23 * wx - s23 * wz
                wc_z = s23 * wx + c23 * wz
                for wrist in range(2):
                    index = first + wrist
                    status[index, w] = code
                    flip = 1.0 if wrist == 0 else -1.0
                    c4, s4 = flip * c4a, flip * s4a
                    s5w = flip * s5
                    turned_x = c4 * wc_x + s4 * wy
                    qd5 = c4 * wy - s4 * wc_x
                    qd6 = turned_x / s5w
                    qd4 = wc_z - c5 * qd6
                    _maker(par, index, w, 0, c1, s1, qd1, cq, sq, qd)
                    _maker(par, index, w, 1, c2, s2, qd2, cq, sq, qd)
                    _maker(par, index, w, 2, c3, s3, qd3, cq, sq, qd)
                    _maker(par, index, w, 3, c4, s4, qd4, cq, sq, qd)
                    _maker(par, index, w, 4, c5, s5w, qd5, cq, sq, qd)
                    _maker(par, index, w, 5, flip * c6a, flip * s6a, qd6, cq, sq, qd)


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def _maker(par, index, w, j, c, s, speed, cq, sq, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint j of a branch in the maker's convention: angle s (theta + o), speed s qd."""
    c_o, s_o, sign = par[7 + j], par[13 + j], par[19 + j]
    cq[index, j, w] = c * c_o - s * s_o
    sq[index, j, w] = sign * (s * c_o + c * s_o)
    qd[index, j, w] = sign * speed
