"""The UR family's pose kernel for the compiled map (:mod:`solver.map_kernel`), in (cos, sin) pairs.

The same closed forms as :mod:`solver.families.ur.ik` and :mod:`solver.families.ur.jacobian`,
for one flange pose and all eight branches at once, with every angle kept as its (cos, sin)
pair (dtf.md section 9): an atan2 becomes a normalised pair, a sum of angles a complex product,
acos(x) the pair (x, +-sqrt(1 - x^2)). Work is shared per level: the shoulder (2), the wrist
(2 x 2) and the elbow (2 x 2 x 2). The singular and reach tests use the same quantities and
tolerances as the numpy IK, so the statuses agree; the numpy family is the reference the
kernel is tested against (tests/solver/test_map_kernel.py).

Parameters (``par``): d1, a2, a3, d4, d5, d6 (m), as :class:`solver.families.ur.dh.UrDh`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.families.base import OK, SINGULAR, UNREACHABLE
from solver.families.ur.dh import UrDh
from solver.families.ur.ik import REACH_TOLERANCE, SINGULAR_TOLERANCE


def kernel_parameters(dh: UrDh) -> np.ndarray:
    """The kernel's parameter vector of a UR arm."""
    return np.array([dh.d1, dh.a2, dh.a3, dh.d4, dh.d5, dh.d6])


@njit(cache=True, error_model="numpy", nogil=True, inline="always")  # type: ignore[untyped-decorator]
def _unit_pair(x: float, y: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """(cos, sin) of atan2(y, x); (1, 0) where both are 0, as atan2(0, 0) = 0.

    sqrt(x^2 + y^2), not math.hypot: libm's hypot costs about 20 ns, which was most of the
    kernel's time; the lengths here are near 1 or metres, far from over- or underflow.
    """
    norm2 = x * x + y * y
    if norm2 == 0.0:
        return 1.0, 0.0
    inverse = 1.0 / math.sqrt(norm2)
    return x * inverse, y * inverse


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def ur_pose(par, rot, pos, twist, tool, need, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK of one flange pose on all eight branches, and J^-1 t on each.

    Args:
        par: shape (6,), the DH lengths.
        rot: shape (3, 3), R_B_F.
        pos: shape (3,), p_B_F (m).
        twist: shape (6,), the tool point's twist per unit speed in {B}.
        tool: shape (3,), the tool point in {B} (m).
        need: shape (8,), bool, the branches wanted; the others are skipped (the out arrays
            keep what they held).
        cq: shape (8, 6), out: cos of each branch's joint angles.
        sq: shape (8, 6), out: their sines.
        status: shape (8,), out: ``OK``, ``UNREACHABLE`` or ``SINGULAR``.
        qd: shape (8, 6), out: J^-1 t on each branch (meaningless where not ``OK``).
    """
    d1, a2, a3, d4, d5, d6 = par[0], par[1], par[2], par[3], par[4], par[5]
    n_x, n_y, n_z = rot[0, 0], rot[1, 0], rot[2, 0]
    a_x, a_y, a_z = rot[0, 2], rot[1, 2], rot[2, 2]
    w_x = pos[0] - d6 * a_x
    w_y = pos[1] - d6 * a_y
    w_z = pos[2] - d6 * a_z
    radius = math.sqrt(w_x * w_x + w_y * w_y)
    ratio1 = d4 / radius
    reach1 = abs(ratio1) <= 1.0 + REACH_TOLERANCE
    rc = min(max(ratio1, -1.0), 1.0)
    rs = math.sqrt(1.0 - rc * rc)
    c_phi, s_phi = _unit_pair(w_x, w_y)
    v_x, v_y, v_z, om_x, om_y, om_z = twist[0], twist[1], twist[2], twist[3], twist[4], twist[5]
    for shoulder in range(2):
        sign = 1.0 if shoulder == 0 else -1.0
        # q1 = atan2(w_y, w_x) + sign acos(d4 / r) + pi / 2
        c_pa = c_phi * rc - s_phi * sign * rs
        s_pa = s_phi * rc + c_phi * sign * rs
        c1, s1 = -s_pa, c_pa  # products of unit pairs: unit to rounding
        cos5 = a_x * s1 - a_y * c1
        reach5 = abs(cos5) <= 1.0 + REACH_TOLERANCE
        cos5 = min(max(cos5, -1.0), 1.0)
        cross_z = s1 * a_y + c1 * a_x
        sin5_size = math.sqrt(a_z * a_z + cross_z * cross_z)
        lever_ik = w_x * c1 + w_y * s1
        for wrist in range(2):
            sin5 = sin5_size if wrist == 0 else -sin5_size
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
            c6, s6 = _unit_pair(
                n_x * x5_x + n_y * x5_y + n_z * x5_z, -(n_x * z4_x + n_y * z4_y + n_z * z4_z)
            )
            c5, s5 = cos5, sin5  # cos5 = z5 . z1, sin5 = |z1 x z5|: a unit pair
            plane_x = (w_x - d5 * z4_x) * c1 + (w_y - d5 * z4_y) * s1
            plane_y = w_z - d5 * z4_z - d1
            c234, s234 = _unit_pair(-z4_z, z4_x * c1 + z4_y * s1)
            c_to, s_to = _unit_pair(plane_x, plane_y)
            cos3 = (plane_x * plane_x + plane_y * plane_y - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
            reach3 = abs(cos3) <= 1.0 + REACH_TOLERANCE
            cos3 = min(max(cos3, -1.0), 1.0)
            sin3_size = math.sqrt(1.0 - cos3 * cos3)
            for elbow in range(2):
                b = 4 * shoulder + 2 * elbow + wrist
                if not need[b]:
                    continue
                sin3 = sign * sin3_size if elbow == 0 else -sign * sin3_size
                if not (reach1 and reach5 and reach3):
                    status[b] = UNREACHABLE
                    continue
                singular = (
                    abs(lever_ik) < SINGULAR_TOLERANCE
                    or wrist_singular
                    or abs(sin3) < SINGULAR_TOLERANCE
                )
                status[b] = SINGULAR if singular else OK
                c3, s3 = cos3, sin3
                # q2 = atan2(plane_y, plane_x) - atan2(a3 s3, a2 + a3 c3)
                c_in, s_in = _unit_pair(a2 + a3 * cos3, a3 * sin3)
                c2 = c_to * c_in + s_to * s_in
                s2 = s_to * c_in - c_to * s_in
                c23 = c2 * c3 - s2 * s3
                s23 = s2 * c3 + c2 * s3
                cq[b, 0], sq[b, 0] = c1, s1
                cq[b, 1], sq[b, 1] = c2, s2
                cq[b, 2], sq[b, 2] = c3, s3
                cq[b, 3], sq[b, 3] = c234 * c23 + s234 * s23, s234 * c23 - c234 * s23
                cq[b, 4], sq[b, 4] = c5, s5
                cq[b, 5], sq[b, 5] = c6, s6
                # J^-1 t: solver.families.ur.jacobian, from the pairs.
                b_x, b_y = a3 * c23, a3 * s23
                p_x, p_y = a2 * c2 + b_x, a2 * s2 + b_y
                lever = p_x + d5 * s234
                wc_x = lever * c1 + d4 * s1
                wc_y = lever * s1 - d4 * c1
                wc_z = d1 + p_y - d5 * c234
                z5_x = -s5 * c234 * c1 + c5 * s1
                z5_y = -s5 * c234 * s1 - c5 * c1
                z5_z = -s5 * s234
                r_x, r_y, r_z = wc_x - tool[0], wc_y - tool[1], wc_z - tool[2]
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
                g_x1 = vw_x * c1 + vw_y * s1 - qd1 * (wc_x * s1 - wc_y * c1) - qd234 * d5 * c234
                g_y1 = vw_z - qd234 * d5 * s234
                det = p_x * b_y - p_y * b_x
                qd2 = (g_y1 * b_y + g_x1 * b_x) / det
                qd3 = -(g_x1 * p_x + g_y1 * p_y) / det
                qd[b, 0], qd[b, 1], qd[b, 2] = qd1, qd2, qd3
                qd[b, 3], qd[b, 4], qd[b, 5] = qd234 - qd2 - qd3, qd5, qd6
