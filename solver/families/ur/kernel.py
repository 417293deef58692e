"""The UR family's pose kernel for the compiled maps (:mod:`solver.kernels`), in (cos, sin) pairs.

The same closed forms as :mod:`solver.families.ur.ik` and :mod:`solver.families.ur.jacobian`,
for a block of flange poses and all eight branches at once, with every angle kept as its
(cos, sin) pair (dtf.md section 9): an atan2 becomes a normalised pair, a sum of angles a
complex product, acos(x) the pair (x, +-sqrt(1 - x^2)). Work is shared per level: the
shoulder (2), the wrist (2 x 2) and the elbow (2 x 2 x 2). The singular and reach tests use
the same quantities and tolerances as the numpy IK, so the statuses agree; the numpy family
is the reference the kernel is tested against (tests/solver/test_map_kernel.py,
tests/solver/test_pose_kernels.py).

Parameters (``par``): d1, a2, a3, d4, d5, d6 (m), as :class:`solver.families.ur.dh.UrDh`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.families.lanes import ANSWER_ROWS, LANES, POSE_ROWS, lanes_in, lanes_out
from solver.families.pairs import unit_pair
from solver.families.ur.dh import UrDh
from solver.families.ur.ik import REACH_TOLERANCE, SINGULAR_TOLERANCE


def kernel_parameters(dh: UrDh) -> np.ndarray:
    """The kernel's parameter vector of a UR arm."""
    return np.array([dh.d1, dh.a2, dh.a3, dh.d4, dh.d5, dh.d6])


L = LANES  # short, for the row offsets below
P = 29  # the work space's rows from P on: the poses' 21 rows, copied in
Q = P + POSE_ROWS  # from Q on: one branch's answer (ANSWER_ROWS), copied out
SCRATCH_SIZE = (Q + ANSWER_ROWS) * LANES  # the work space ur_block needs (float64 values)


@njit(cache=True, error_model="numpy", nogil=True)
def ur_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK on all eight branches and J^-1 t on each, for the waypoints w0..w1 of a path.

    LANES waypoints at a time (:func:`ur_lanes`, :mod:`solver.families.lanes`).

    Args:
        par: shape (6,), the DH lengths.
        poses: shape (21, W): R_B_F row by row (9), p_B_F (3, m), the tool point's twist per
            unit speed (6) and the tool point (3, m), all in {B}.
        w0: the first waypoint to solve.
        w1: one past the last.
        need: shape (8,), bool, the branches wanted; the others are skipped (the out arrays
            keep what they held).
        scratch: shape (>= SCRATCH_SIZE,), work space.
        cq: shape (8, 6, W), out: cos of each branch's joint angles.
        sq: shape (8, 6, W), out: their sines.
        status: shape (8, W), out: ``OK``, ``UNREACHABLE`` or ``SINGULAR``.
        qd: shape (8, 6, W), out: J^-1 t on each branch (meaningless where not ``OK``).
    """
    for c0 in range(w0, w1, LANES):
        ur_lanes(par, poses, c0, min(LANES, w1 - c0), need, scratch, cq, sq, status, qd)


@njit(cache=True, error_model="numpy", nogil=True)
def ur_lanes(par, poses, c0, n, need, t, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`ur_block` for the n <= LANES waypoints from c0, in the work space ``t``.

    Level by level (the shoulder, the wrist, the elbow), each level one loop over the
    waypoints: short loop bodies whose iterations are independent, which the processor
    overlaps (one loop body over all levels per waypoint was three times slower).
    """
    d1, a2, a3, d4, d5, d6 = par[0], par[1], par[2], par[3], par[4], par[5]
    lanes_in(poses, c0, n, t, P)
    for k in range(n):
        a_x, a_y, a_z = t[(P + 2) * L + k], t[(P + 5) * L + k], t[(P + 8) * L + k]
        w_x = t[(P + 9) * L + k] - d6 * a_x
        w_y = t[(P + 10) * L + k] - d6 * a_y
        w_z = t[(P + 11) * L + k] - d6 * a_z
        radius = math.sqrt(w_x * w_x + w_y * w_y)
        ratio1 = d4 / radius
        t[7 * L + k] = 1.0 if abs(ratio1) <= 1.0 + REACH_TOLERANCE else 0.0
        rc = min(max(ratio1, -1.0), 1.0)
        t[0 * L + k], t[1 * L + k], t[2 * L + k] = w_x, w_y, w_z
        t[3 * L + k], t[4 * L + k] = rc, math.sqrt(1.0 - rc * rc)
        t[5 * L + k], t[6 * L + k] = unit_pair(w_x, w_y)
    for shoulder in range(2):
        if not need[4 * shoulder : 4 * shoulder + 4].any():
            continue
        sign = 1.0 if shoulder == 0 else -1.0
        for k in range(n):
            a_x, a_y, a_z = t[(P + 2) * L + k], t[(P + 5) * L + k], t[(P + 8) * L + k]
            c_phi, s_phi, rc, rs = t[5 * L + k], t[6 * L + k], t[3 * L + k], sign * t[4 * L + k]
            # q1 = atan2(w_y, w_x) + sign acos(d4 / r) + pi / 2
            c_pa = c_phi * rc - s_phi * rs
            s_pa = s_phi * rc + c_phi * rs
            c1, s1 = -s_pa, c_pa  # products of unit pairs: unit to rounding
            cos5 = a_x * s1 - a_y * c1
            t[11 * L + k] = 1.0 if abs(cos5) <= 1.0 + REACH_TOLERANCE else 0.0
            cross_z = s1 * a_y + c1 * a_x
            t[8 * L + k], t[9 * L + k] = c1, s1
            t[10 * L + k] = min(max(cos5, -1.0), 1.0)
            t[12 * L + k] = cross_z
            t[13 * L + k] = math.sqrt(a_z * a_z + cross_z * cross_z)
            t[14 * L + k] = t[0 * L + k] * c1 + t[1 * L + k] * s1
        for wrist in range(2):
            first = 4 * shoulder + wrist
            if not (need[first] or need[first + 2]):
                continue
            for k in range(n):
                n_x, n_y, n_z = t[(P + 0) * L + k], t[(P + 3) * L + k], t[(P + 6) * L + k]
                a_x, a_y, a_z = t[(P + 2) * L + k], t[(P + 5) * L + k], t[(P + 8) * L + k]
                c1, s1, cross_z = t[8 * L + k], t[9 * L + k], t[12 * L + k]
                sin5 = t[13 * L + k] if wrist == 0 else -t[13 * L + k]
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
                t[19 * L + k], t[20 * L + k] = unit_pair(
                    n_x * x5_x + n_y * x5_y + n_z * x5_z, -(n_x * z4_x + n_y * z4_y + n_z * z4_z)
                )
                plane_x = (t[0 * L + k] - d5 * z4_x) * c1 + (t[1 * L + k] - d5 * z4_y) * s1
                plane_y = t[2 * L + k] - d5 * z4_z - d1
                t[21 * L + k], t[22 * L + k] = unit_pair(-z4_z, z4_x * c1 + z4_y * s1)
                t[23 * L + k], t[24 * L + k] = unit_pair(plane_x, plane_y)
                cos3 = (plane_x * plane_x + plane_y * plane_y - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
                t[26 * L + k] = 1.0 if abs(cos3) <= 1.0 + REACH_TOLERANCE else 0.0
                cos3 = min(max(cos3, -1.0), 1.0)
                t[25 * L + k] = cos3
                t[27 * L + k] = math.sqrt(1.0 - cos3 * cos3)
                t[28 * L + k] = sin5
                t[15 * L + k] = 1.0 if wrist_singular else 0.0
            for elbow in range(2):
                b = 4 * shoulder + 2 * elbow + wrist
                if not need[b]:
                    continue
                e_sign = sign if elbow == 0 else -sign
                for k in range(n):
                    c1, s1, c5, s5 = t[8 * L + k], t[9 * L + k], t[10 * L + k], t[28 * L + k]
                    c3, s3 = t[25 * L + k], e_sign * t[27 * L + k]
                    c234, s234, c_to, s_to = (
                        t[21 * L + k],
                        t[22 * L + k],
                        t[23 * L + k],
                        t[24 * L + k],
                    )
                    reach = t[7 * L + k] * t[11 * L + k] * t[26 * L + k] > 0.0
                    singular = (
                        abs(t[14 * L + k]) < SINGULAR_TOLERANCE
                        or t[15 * L + k] > 0.0
                        or abs(s3) < SINGULAR_TOLERANCE
                    )
                    t[(Q + 18) * L + k] = (
                        UNREACHABLE if not reach else (SINGULAR if singular else OK)
                    )
                    # q2 = atan2(plane_y, plane_x) - atan2(a3 s3, a2 + a3 c3)
                    c_in, s_in = unit_pair(a2 + a3 * c3, a3 * s3)
                    c2 = c_to * c_in + s_to * s_in
                    s2 = s_to * c_in - c_to * s_in
                    c23 = c2 * c3 - s2 * s3
                    s23 = s2 * c3 + c2 * s3
                    t[(Q + 0) * L + k], t[(Q + 6) * L + k] = c1, s1
                    t[(Q + 1) * L + k], t[(Q + 7) * L + k] = c2, s2
                    t[(Q + 2) * L + k], t[(Q + 8) * L + k] = c3, s3
                    t[(Q + 3) * L + k] = c234 * c23 + s234 * s23
                    t[(Q + 9) * L + k] = s234 * c23 - c234 * s23
                    t[(Q + 4) * L + k], t[(Q + 10) * L + k] = c5, s5
                    t[(Q + 5) * L + k], t[(Q + 11) * L + k] = t[19 * L + k], t[20 * L + k]
                    # J^-1 t: solver.families.ur.jacobian, from the pairs.
                    v_x, v_y, v_z = t[(P + 12) * L + k], t[(P + 13) * L + k], t[(P + 14) * L + k]
                    om_x, om_y, om_z = t[(P + 15) * L + k], t[(P + 16) * L + k], t[(P + 17) * L + k]
                    b_x, b_y = a3 * c23, a3 * s23
                    p_x, p_y = a2 * c2 + b_x, a2 * s2 + b_y
                    lever = p_x + d5 * s234
                    wc_x = lever * c1 + d4 * s1
                    wc_y = lever * s1 - d4 * c1
                    wc_z = d1 + p_y - d5 * c234
                    z5_x = -s5 * c234 * c1 + c5 * s1
                    z5_y = -s5 * c234 * s1 - c5 * c1
                    z5_z = -s5 * s234
                    r_x = wc_x - t[(P + 18) * L + k]
                    r_y = wc_y - t[(P + 19) * L + k]
                    r_z = wc_z - t[(P + 20) * L + k]
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
                    t[(Q + 12) * L + k], t[(Q + 13) * L + k], t[(Q + 14) * L + k] = qd1, qd2, qd3
                    t[(Q + 15) * L + k], t[(Q + 16) * L + k], t[(Q + 17) * L + k] = (
                        qd234 - qd2 - qd3,
                        qd5,
                        qd6,
                    )
                lanes_out(t, Q, n, c0, b, cq, sq, status, qd)
