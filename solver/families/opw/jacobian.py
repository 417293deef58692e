"""Closed-form J(q)^-1 t for OPW arms, batched (no 6x6 solve; robots.md section 3).

Joints 4, 5 and 6 turn about axes through the wrist centre w, so for a twist (v, omega) of the
tool point p the wrist centre moves with v_w = v + omega x (w - p), to which the wrist adds
nothing. Written in the frame turned by theta1 about z (x' out along the arm, y' the axis of
joints 2 and 3), with w = (w_x, b, w_z), the shoulder o2 = (a1, b, c1) and the elbow
o3 = (e_x, b, e_z):

1. joint 1 is the only one that moves w along y': qd1 = v_w.y' / w_x;
2. joints 2 and 3 (columns (w_z - c1, 0, a1 - w_x) and (w_z - e_z, 0, e_x - w_x)) solve a
   2x2 system for the rest of v_w, whose determinant is the planar cross product of the upper
   arm (o3 - o2) and the forearm (w - o3): the elbow factor of det J;
3. the wrist: omega - qd1 z - (qd2 + qd3) y', in the frame R_0c = Rz(theta1) Ry(theta2 +
   theta3), is qd4 z + qd5 Rz(theta4) y + qd6 Rz(theta4) Ry(theta5) z: the ZYZ rates, with
   sin theta5 the wrist factor of det J.

A maker joint with sign correction -1 turns the other way, so its speed changes sign. Layout is
component-first: q (6, ...).
"""

from __future__ import annotations

import math

import numpy as np

from solver.families.opw.parameters import OpwParameters


def joint_speeds_per_unit_twist(
    parameters: OpwParameters, q: np.ndarray, twist: np.ndarray, tool_point: np.ndarray
) -> np.ndarray:
    """Qd = J(q)^-1 t for an OPW arm, with J the Jacobian at ``tool_point`` in {B} axes.

    Args:
        parameters: the arm's geometry.
        q: shape (6, ...), joint positions (rad, maker's convention), non-singular.
        twist: shape (6, ...) broadcastable to q, [v (m/s); omega (rad/s)] of the tool point.
        tool_point: shape (3, ...) broadcastable to q, the tool point in {B} (m).

    Returns:
        shape (6, ...), joint speeds (rad/s, maker's convention); inf or NaN where singular.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        return _joint_speeds(parameters, q, twist, tool_point)


def _joint_speeds(
    p: OpwParameters, q: np.ndarray, twist: np.ndarray, tool_point: np.ndarray
) -> np.ndarray:
    """The body of :func:`joint_speeds_per_unit_twist`."""
    q = np.asarray(q, dtype=float)
    shape = (6,) + (1,) * (q.ndim - 1)
    signs = np.array(p.sign_corrections, dtype=float)
    theta = q * signs.reshape(shape) - np.array(p.offsets).reshape(shape)
    c1, s1 = np.cos(theta[0]), np.sin(theta[0])
    c2, s2 = np.cos(theta[1]), np.sin(theta[1])
    angle23 = theta[1] + theta[2]
    c23, s23 = np.cos(angle23), np.sin(angle23)
    c4, s4 = np.cos(theta[3]), np.sin(theta[3])
    c5, s5 = np.cos(theta[4]), np.sin(theta[4])
    k = math.hypot(p.a2, p.c3)
    psi3 = math.atan2(p.a2, p.c3)
    elbow_x = p.a1 + p.c2 * s2  # in the turned plane
    elbow_z = p.c1 + p.c2 * c2
    wrist_x = elbow_x + k * np.sin(angle23 + psi3)
    wrist_z = elbow_z + k * np.cos(angle23 + psi3)
    v_x, v_y, v_z, om_x, om_y, om_z = twist
    # v_w = v + omega x (w - p), w in {B}.
    r_x = wrist_x * c1 - p.b * s1 - tool_point[0]
    r_y = wrist_x * s1 + p.b * c1 - tool_point[1]
    r_z = wrist_z - tool_point[2]
    vw_x = v_x + om_y * r_z - om_z * r_y
    vw_y = v_y + om_z * r_x - om_x * r_z
    vw_z = v_z + om_x * r_y - om_y * r_x
    along = vw_x * c1 + vw_y * s1  # x' component
    across = vw_y * c1 - vw_x * s1  # y' component
    qd1 = across / wrist_x
    # [dz ez; -dx -ex] [qd2; qd3] = [along + b qd1; vw_z]
    d_x, d_z = wrist_x - p.a1, wrist_z - p.c1
    e_x, e_z = wrist_x - elbow_x, wrist_z - elbow_z
    rhs_x = along + p.b * qd1
    det = e_z * d_x - d_z * e_x
    qd2 = -(rhs_x * e_x + e_z * vw_z) / det
    qd3 = (d_z * vw_z + d_x * rhs_x) / det
    # The wrist: omega less the arm's turn, in frame c.
    qd23 = qd2 + qd3
    w_x = om_x * c1 + om_y * s1  # x'
    w_y = om_y * c1 - om_x * s1 - qd23  # y'
    w_z = om_z - qd1
    wc_x = c23 * w_x - s23 * w_z
    wc_z = s23 * w_x + c23 * w_z
    turned_x = c4 * wc_x + s4 * w_y  # Rz(-theta4) omega_c
    qd5 = c4 * w_y - s4 * wc_x
    qd6 = turned_x / s5
    qd4 = wc_z - c5 * qd6
    paper = np.stack(np.broadcast_arrays(qd1, qd2, qd3, qd4, qd5, qd6))
    # The signs again on paper's own axes: twist or tool_point may carry more than q.
    speeds: np.ndarray = paper * signs.reshape((6,) + (1,) * (paper.ndim - 1))
    return speeds
