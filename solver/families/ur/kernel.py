"""The UR family's pose kernel for the compiled maps (:mod:`solver.kernels`), in (cos, sin) pairs.

The same closed forms as :mod:`solver.families.ur.ik` and :mod:`solver.families.ur.jacobian`,
for a block of flange poses and all eight branches at once, with every angle kept as its
(cos, sin) pair (dtf.md section 9): an atan2 becomes a normalised pair, a sum of angles a
complex product, acos(x) the pair (x, +-sqrt(1 - x^2)). Work is shared per level: the
shoulder (2), the wrist (2 x 2) and the elbow (2 x 2 x 2). The singular and reach tests use
the same quantities and tolerances as the numpy IK, so the statuses agree; the numpy family
is the reference the kernel is tested against (tests/solver/test_map_kernel.py).

Parameters (``par``): d1, a2, a3, d4, d5, d6 (m), as :class:`solver.families.ur.dh.UrDh`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.families.pairs import unit_pair
from solver.families.ur.dh import UrDh
from solver.families.ur.ik import REACH_TOLERANCE, SINGULAR_TOLERANCE


def kernel_parameters(dh: UrDh) -> np.ndarray:
    """The kernel's parameter vector of a UR arm."""
    return np.array([dh.d1, dh.a2, dh.a3, dh.d4, dh.d5, dh.d6])


SCRATCH_ROWS = 29  # rows of the scratch array ur_block needs


@njit(cache=True, error_model="numpy", nogil=True)
def ur_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK on all eight branches and J^-1 t on each, for the waypoints w0..w1 of a path.

    Level by level (the shoulder, the wrist, the elbow), each level one loop over the
    waypoints: short loop bodies whose iterations are independent, which the processor
    overlaps (one loop body over all levels per waypoint was three times slower).

    Args:
        par: shape (6,), the DH lengths.
        poses: shape (21, W): R_B_F row by row (9), p_B_F (3, m), the tool point's twist per
            unit speed (6) and the tool point (3, m), all in {B}.
        w0: the first waypoint to solve.
        w1: one past the last.
        need: shape (8,), bool, the branches wanted; the others are skipped (the out arrays
            keep what they held).
        scratch: shape (SCRATCH_ROWS, W), work space.
        cq: shape (8, 6, W), out: cos of each branch's joint angles.
        sq: shape (8, 6, W), out: their sines.
        status: shape (8, W), out: ``OK``, ``UNREACHABLE`` or ``SINGULAR``.
        qd: shape (8, 6, W), out: J^-1 t on each branch (meaningless where not ``OK``).
    """
    d1, a2, a3, d4, d5, d6 = par[0], par[1], par[2], par[3], par[4], par[5]
    t = scratch
    for w in range(w0, w1):
        a_x, a_y, a_z = poses[2, w], poses[5, w], poses[8, w]
        w_x = poses[9, w] - d6 * a_x
        w_y = poses[10, w] - d6 * a_y
        w_z = poses[11, w] - d6 * a_z
        radius = math.sqrt(w_x * w_x + w_y * w_y)
        ratio1 = d4 / radius
        t[7, w] = 1.0 if abs(ratio1) <= 1.0 + REACH_TOLERANCE else 0.0
        rc = min(max(ratio1, -1.0), 1.0)
        t[0, w], t[1, w], t[2, w] = w_x, w_y, w_z
        t[3, w], t[4, w] = rc, math.sqrt(1.0 - rc * rc)
        t[5, w], t[6, w] = unit_pair(w_x, w_y)
    for shoulder in range(2):
        if not need[4 * shoulder : 4 * shoulder + 4].any():
            continue
        sign = 1.0 if shoulder == 0 else -1.0
        for w in range(w0, w1):
            a_x, a_y, a_z = poses[2, w], poses[5, w], poses[8, w]
            c_phi, s_phi, rc, rs = t[5, w], t[6, w], t[3, w], sign * t[4, w]
            # q1 = atan2(w_y, w_x) + sign acos(d4 / r) + pi / 2
            c_pa = c_phi * rc - s_phi * rs
            s_pa = s_phi * rc + c_phi * rs
            c1, s1 = -s_pa, c_pa  # products of unit pairs: unit to rounding
            cos5 = a_x * s1 - a_y * c1
            t[11, w] = 1.0 if abs(cos5) <= 1.0 + REACH_TOLERANCE else 0.0
            cross_z = s1 * a_y + c1 * a_x
            t[8, w], t[9, w] = c1, s1
            t[10, w] = min(max(cos5, -1.0), 1.0)
            t[12, w] = cross_z
            t[13, w] = math.sqrt(a_z * a_z + cross_z * cross_z)
            t[14, w] = t[0, w] * c1 + t[1, w] * s1
        for wrist in range(2):
            first = 4 * shoulder + wrist
            if not (need[first] or need[first + 2]):
                continue
            for w in range(w0, w1):
                n_x, n_y, n_z = poses[0, w], poses[3, w], poses[6, w]
                a_x, a_y, a_z = poses[2, w], poses[5, w], poses[8, w]
                c1, s1, cross_z = t[8, w], t[9, w], t[12, w]
                sin5 = t[13, w] if wrist == 0 else -t[13, w]
                wrist_singular = abs(sin5) < SINGULAR_TOLERANCE
                if wrist_singular:
                    z4_x = n_y * a_z - n_z * a_y
                    z4_y = n_z * a_x - n_x * a_z
                    z4_z = n_x * a_y - n_y * a_x
                else:
                    inv5 = 1.0 / sin5
                    z4_x = -c1 * a_z * inv5
                    z4_y = -s1 * a_z * inv5
                    z4_z = cross_z * inv5
                x5_x = -(z4_y * a_z - z4_z * a_y)
                x5_y = -(z4_z * a_x - z4_x * a_z)
                x5_z = -(z4_x * a_y - z4_y * a_x)
                t[19, w], t[20, w] = unit_pair(
                    n_x * x5_x + n_y * x5_y + n_z * x5_z, -(n_x * z4_x + n_y * z4_y + n_z * z4_z)
                )
                plane_x = (t[0, w] - d5 * z4_x) * c1 + (t[1, w] - d5 * z4_y) * s1
                plane_y = t[2, w] - d5 * z4_z - d1
                t[21, w], t[22, w] = unit_pair(-z4_z, z4_x * c1 + z4_y * s1)
                t[23, w], t[24, w] = unit_pair(plane_x, plane_y)
                cos3 = (plane_x * plane_x + plane_y * plane_y - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
                t[26, w] = 1.0 if abs(cos3) <= 1.0 + REACH_TOLERANCE else 0.0
                cos3 = min(max(cos3, -1.0), 1.0)
                t[25, w] = cos3
                t[27, w] = math.sqrt(1.0 - cos3 * cos3)
                t[28, w] = sin5
                t[15, w] = 1.0 if wrist_singular else 0.0
            for elbow in range(2):
                b = 4 * shoulder + 2 * elbow + wrist
                if not need[b]:
                    continue
                e_sign = sign if elbow == 0 else -sign
                for w in range(w0, w1):
                    c1, s1, c5, s5 = t[8, w], t[9, w], t[10, w], t[28, w]
                    c3, s3 = t[25, w], e_sign * t[27, w]
                    c234, s234, c_to, s_to = t[21, w], t[22, w], t[23, w], t[24, w]
                    reach = t[7, w] * t[11, w] * t[26, w] > 0.0
                    singular = (
                        abs(t[14, w]) < SINGULAR_TOLERANCE
                        or t[15, w] > 0.0
                        or abs(s3) < SINGULAR_TOLERANCE
                    )
                    status[b, w] = UNREACHABLE if not reach else (SINGULAR if singular else OK)
                    # q2 = atan2(plane_y, plane_x) - atan2(a3 s3, a2 + a3 c3)
                    c_in, s_in = unit_pair(a2 + a3 * c3, a3 * s3)
                    c2 = c_to * c_in + s_to * s_in
                    s2 = s_to * c_in - c_to * s_in
                    c23 = c2 * c3 - s2 * s3
                    s23 = s2 * c3 + c2 * s3
                    cq[b, 0, w], sq[b, 0, w] = c1, s1
                    cq[b, 1, w], sq[b, 1, w] = c2, s2
                    cq[b, 2, w], sq[b, 2, w] = c3, s3
                    cq[b, 3, w] = c234 * c23 + s234 * s23
                    sq[b, 3, w] = s234 * c23 - c234 * s23
                    cq[b, 4, w], sq[b, 4, w] = c5, s5
                    cq[b, 5, w], sq[b, 5, w] = t[19, w], t[20, w]
                    # J^-1 t: solver.families.ur.jacobian, from the pairs.
                    v_x, v_y, v_z = poses[12, w], poses[13, w], poses[14, w]
                    om_x, om_y, om_z = poses[15, w], poses[16, w], poses[17, w]
                    b_x, b_y = a3 * c23, a3 * s23
                    p_x, p_y = a2 * c2 + b_x, a2 * s2 + b_y
                    lever = p_x + d5 * s234
                    wc_x = lever * c1 + d4 * s1
                    wc_y = lever * s1 - d4 * c1
                    wc_z = d1 + p_y - d5 * c234
                    z5_x = -s5 * c234 * c1 + c5 * s1
                    z5_y = -s5 * c234 * s1 - c5 * c1
                    z5_z = -s5 * s234
                    r_x = wc_x - poses[18, w]
                    r_y = wc_y - poses[19, w]
                    r_z = wc_z - poses[20, w]
                    vw_x = v_x + om_y * r_z - om_z * r_y
                    vw_y = v_y + om_z * r_x - om_x * r_z
                    vw_z = v_z + om_x * r_y - om_y * r_x
                    qd1 = -(vw_x * s1 - vw_y * c1) / lever
                    omp_z = om_z - qd1
                    qd5 = om_x * s234 * c1 + om_y * s234 * s1 - omp_z * c234
                    along_z1 = om_x * s1 - om_y * c1
                    along_z5 = om_x * z5_x + om_y * z5_y + omp_z * z5_z
                    sin2 = s5 * s5
                    qd234 = (along_z1 - c5 * along_z5) / sin2
                    qd6 = (along_z5 - c5 * along_z1) / sin2
                    g_x1 = vw_x * c1 + vw_y * s1 - qd1 * (wc_x * s1 - wc_y * c1)
                    g_x1 -= qd234 * d5 * c234
                    g_y1 = vw_z - qd234 * d5 * s234
                    det = p_x * b_y - p_y * b_x
                    qd2 = (g_y1 * b_y + g_x1 * b_x) / det
                    qd3 = -(g_x1 * p_x + g_y1 * p_y) / det
                    qd[b, 0, w], qd[b, 1, w], qd[b, 2, w] = qd1, qd2, qd3
                    qd[b, 3, w], qd[b, 4, w], qd[b, 5, w] = qd234 - qd2 - qd3, qd5, qd6
