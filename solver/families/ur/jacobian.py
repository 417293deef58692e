"""Closed-form J(q)^-1 t for UR arms, batched (no 6x6 solve; spec section 9).

Joints 5 and 6 of a UR arm turn about axes through the wrist centre w (the origin of DH frame
5), and joints 2, 3, 4 about parallel axes z1. So, for a twist (v, omega) of the tool point p:

1. the wrist centre moves with v_w = v + omega x (w - p), to which joints 5 and 6 add nothing;
2. only joint 1 moves w along z1:  qd1 = -(v_w . z1) / (w . x1);
3. omega - qd1 z0 = (qd2 + qd3 + qd4) z1 + qd5 z4 + qd6 z5 with z4 orthogonal to z1 and z5:
   qd5 = omega' . z4, and a 2x2 system in (z1, z5) with determinant sin^2 q5;
4. the planar arm: z1 x (qd2 (o3 - o1) + qd3 (o3 - o2)) = v_w - qd1 z0 x w - qd234 z1 x (w - o3),
   a 2x2 system with determinant a2 a3 sin q3.

The three divisors are the shoulder lever w . x1, sin^2 q5 and a2 a3 sin q3: the factors of
det J. Layout is component-first: q (6, ...), twists (6, ...), points (3, ...).
"""

from __future__ import annotations

import numpy as np

from solver.families.ur.dh import UrDh


def joint_speeds_per_unit_twist(
    dh: UrDh, q: np.ndarray, twist: np.ndarray, tool_point: np.ndarray
) -> np.ndarray:
    """Qd = J(q)^-1 t for a UR arm, with J the Jacobian at ``tool_point`` in {B} axes.

    Args:
        dh: the arm's DH parameters.
        q: shape (6, ...), joint positions (rad), non-singular.
        twist: shape (6, ...) broadcastable to q, [v (m/s); omega (rad/s)] of the tool point,
            {B} axes.
        tool_point: shape (3, ...) broadcastable to q, the tool point's position in {B} (m).

    Returns:
        shape (6, ...), joint speeds (rad/s); inf or NaN at an exactly singular q.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        return _joint_speeds(dh, q, twist, tool_point)


def _joint_speeds(dh: UrDh, q: np.ndarray, twist: np.ndarray, tool_point: np.ndarray) -> np.ndarray:
    """The body of :func:`joint_speeds_per_unit_twist`."""
    c1, s1 = np.cos(q[0]), np.sin(q[0])
    q23 = q[1] + q[2]
    q234 = q23 + q[3]
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    c23, s23 = np.cos(q23), np.sin(q23)
    c234, s234 = np.cos(q234), np.sin(q234)
    c5, s5 = np.cos(q[4]), np.sin(q[4])
    # Planar coordinates (along x1 = (c1, s1, 0) and y1 = z0) of o3 - o1 and of o3 - o2.
    b_x, b_y = dh.a3 * c23, dh.a3 * s23
    a_x, a_y = dh.a2 * c2 + b_x, dh.a2 * s2 + b_y
    # Wrist centre w = o1 + a_x x1 + a_y y1 + d4 z1 + d5 z4 with z1 = (s1, -c1, 0) and
    # z4 = s234 x1 - c234 y1.
    lever = a_x + dh.d5 * s234  # w . x1
    w_x = lever * c1 + dh.d4 * s1
    w_y = lever * s1 - dh.d4 * c1
    w_z = dh.d1 + a_y - dh.d5 * c234
    z4_x, z4_y, z4_z = s234 * c1, s234 * s1, -c234
    z5_x = -s5 * c234 * c1 + c5 * s1
    z5_y = -s5 * c234 * s1 - c5 * c1
    z5_z = -s5 * s234
    v_x, v_y, v_z, om_x, om_y, om_z = twist
    r_x, r_y, r_z = w_x - tool_point[0], w_y - tool_point[1], w_z - tool_point[2]
    vw_x = v_x + om_y * r_z - om_z * r_y
    vw_y = v_y + om_z * r_x - om_x * r_z
    vw_z = v_z + om_x * r_y - om_y * r_x
    qd1 = -(vw_x * s1 - vw_y * c1) / lever
    # Wrist: omega' = omega - qd1 z0 = qd234 z1 + qd5 z4 + qd6 z5.
    omp_z = om_z - qd1
    qd5 = om_x * z4_x + om_y * z4_y + omp_z * z4_z
    along_z1 = om_x * s1 - om_y * c1
    along_z5 = om_x * z5_x + om_y * z5_y + omp_z * z5_z
    sin2 = s5 * s5
    qd234 = (along_z1 - c5 * along_z5) / sin2
    qd6 = (along_z5 - c5 * along_z1) / sin2
    # Planar arm: g = v_w - qd1 z0 x w - qd234 z1 x (w - o3), with w - o3 = d4 z1 + d5 z4 and
    # z1 x z4 = c234 x1 + s234 y1; z0 x w has no y1 part.
    g_x1 = vw_x * c1 + vw_y * s1 - qd1 * (w_x * s1 - w_y * c1) - qd234 * dh.d5 * c234
    g_y1 = vw_z - qd234 * dh.d5 * s234
    # z1 x (p x1 + r y1) = -r x1 + p y1  =>  [a_x b_x; a_y b_y] [qd2; qd3] = [g_y1; -g_x1].
    det = a_x * b_y - a_y * b_x
    qd2 = (g_y1 * b_y + g_x1 * b_x) / det
    qd3 = -(g_x1 * a_x + g_y1 * a_y) / det
    qd4 = qd234 - qd2 - qd3
    return np.stack(np.broadcast_arrays(qd1, qd2, qd3, qd4, qd5, qd6))
