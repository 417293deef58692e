"""The OPW family's pose kernel for the compiled map (:mod:`solver.map_kernel`): (cos, sin) pairs.

The same closed forms as :mod:`solver.families.opw.ik` and :mod:`solver.families.opw.jacobian`
for one flange pose and all eight branches, with every angle kept as its (cos, sin) pair
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

from solver.families.base import OK, SINGULAR, UNREACHABLE
from solver.families.opw.ik import REACH_TOLERANCE, SINGULAR_TOLERANCE
from solver.families.opw.parameters import OpwParameters
from solver.families.ur.kernel import _unit_pair


def kernel_parameters(p: OpwParameters) -> np.ndarray:
    """The kernel's parameter vector of an OPW arm."""
    lengths = [p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4]
    offsets = np.array(p.offsets, dtype=float)
    signs = np.array(p.sign_corrections, dtype=float)
    return np.concatenate([lengths, np.cos(offsets), np.sin(offsets), signs])


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def opw_pose(par, rot, pos, twist, tool, need, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK of one flange pose on all eight branches, and J^-1 t on each.

    Arguments as :func:`solver.families.ur.kernel.ur_pose`; ``cq``, ``sq`` and ``qd`` are in
    the maker's convention (q = s (theta + o)).
    """
    a1, a2, b, c1_len, c2_len, c3_len, c4 = par[0], par[1], par[2], par[3], par[4], par[5], par[6]
    r = rot
    cx = pos[0] - c4 * r[0, 2]
    cy = pos[1] - c4 * r[1, 2]
    height = pos[2] - c4 * r[2, 2] - c1_len
    radial2 = cx * cx + cy * cy - b * b
    lever = math.sqrt(max(radial2, 0.0))
    c_head, s_head = _unit_pair(cx, cy)
    c_side, s_side = _unit_pair(lever, b)
    k2 = a2 * a2 + c3_len * c3_len
    k = math.sqrt(k2)
    c_psi, s_psi = _unit_pair(c3_len, a2)  # psi3 = atan2(a2, c3)
    k_h = math.hypot(a2, c3_len)
    v_x, v_y, v_z, om_x, om_y, om_z = twist[0], twist[1], twist[2], twist[3], twist[4], twist[5]
    theta_c = np.empty(6)
    theta_s = np.empty(6)
    for shoulder in range(2):
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
            radial2 >= -REACH_TOLERANCE
            and abs(cos_elbow) <= 1.0 + REACH_TOLERANCE
            and abs(cos_shoulder) <= 1.0 + REACH_TOLERANCE
        )
        if not reach:
            for j in range(4):
                status[4 * shoulder + j] = UNREACHABLE
            continue
        ce = min(max(cos_elbow, -1.0), 1.0)
        se = math.sqrt(1.0 - ce * ce)
        cs = min(max(cos_shoulder, -1.0), 1.0)
        ss = math.sqrt(1.0 - cs * cs)
        c_to, s_to = _unit_pair(height, forward)  # angle_to = atan2(forward, height)
        if shoulder == 1:
            s_to = -s_to
        singular_arm = 1.0 - ce * ce < SINGULAR_TOLERANCE**2 or lever < SINGULAR_TOLERANCE
        ux = r[0, 0] * c1 + r[1, 0] * s1
        uy = r[0, 1] * c1 + r[1, 1] * s1
        uz = r[0, 2] * c1 + r[1, 2] * s1
        y_z = r[1, 2] * c1 - r[0, 2] * s1
        y_y = r[1, 1] * c1 - r[0, 1] * s1
        for elbow in range(2):
            first = 4 * shoulder + 2 * elbow
            if not (need[first] or need[first + 1]):
                continue
            e_sign = 1.0 if elbow == 0 else -1.0
            # theta3 = +-acos_elbow - psi3; theta2 = angle_to -+ acos_shoulder
            c3 = ce * c_psi + e_sign * se * s_psi
            s3 = e_sign * se * c_psi - ce * s_psi
            c2 = c_to * cs + e_sign * s_to * ss
            s2 = s_to * cs - e_sign * c_to * ss
            c23 = c2 * c3 - s2 * s3
            s23 = s2 * c3 + c2 * s3
            m = s23 * uz + c23 * r[2, 2]
            x_z = c23 * uz - s23 * r[2, 2]
            z_y = s23 * uy + c23 * r[2, 1]
            z_x = s23 * ux + c23 * r[2, 0]
            sin5 = math.sqrt(x_z * x_z + y_z * y_z)
            c5, s5 = _unit_pair(m, sin5)
            wrist_singular = sin5 < SINGULAR_TOLERANCE
            if wrist_singular:
                x_y = c23 * uy - s23 * r[2, 1]
                c4a, s4a = _unit_pair(y_y, -x_y)
                c6a, s6a = 1.0, 0.0
            else:
                c4a, s4a = _unit_pair(x_z, y_z)
                c6a, s6a = _unit_pair(-z_x, z_y)
            singular = singular_arm or wrist_singular
            # J^-1 t of the noflip wrist (solver.families.opw.jacobian, paper's angles); the
            # flipped wrist has theta4 + pi, -theta5, theta6 - pi.
            elbow_x = a1 + c2_len * s2
            elbow_z = c1_len + c2_len * c2
            wrist_x = elbow_x + k_h * (s23 * c_psi + c23 * s_psi)
            wrist_z = elbow_z + k_h * (c23 * c_psi - s23 * s_psi)
            r_x = wrist_x * c1 - b * s1 - tool[0]
            r_y = wrist_x * s1 + b * c1 - tool[1]
            r_z = wrist_z - tool[2]
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
                index = 4 * shoulder + 2 * elbow + wrist
                status[index] = SINGULAR if singular else OK
                flip = 1.0 if wrist == 0 else -1.0
                c4, s4 = flip * c4a, flip * s4a
                s5w = flip * s5
                theta_c[0], theta_s[0] = c1, s1
                theta_c[1], theta_s[1] = c2, s2
                theta_c[2], theta_s[2] = c3, s3
                theta_c[3], theta_s[3] = c4, s4
                theta_c[4], theta_s[4] = c5, s5w
                theta_c[5], theta_s[5] = flip * c6a, flip * s6a
                turned_x = c4 * wc_x + s4 * wy
                qd5 = c4 * wy - s4 * wc_x
                qd6 = turned_x / s5w
                qd4 = wc_z - c5 * qd6
                qd[index, 0], qd[index, 1], qd[index, 2] = qd1, qd2, qd3
                qd[index, 3], qd[index, 4], qd[index, 5] = qd4, qd5, qd6
                for j in range(6):  # the maker's angle s (theta + o)
                    c_o, s_o, sign = par[7 + j], par[13 + j], par[19 + j]
                    cq[index, j] = theta_c[j] * c_o - theta_s[j] * s_o
                    sq[index, j] = sign * (theta_s[j] * c_o + theta_c[j] * s_o)
                    qd[index, j] *= sign
