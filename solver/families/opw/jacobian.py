"""Closed-form J(q)^-1 t for OPW arms, batched (no 6x6 solve; robots.md section 3).

Joints 4, 5 and 6 turn about axes through the wrist centre w, so for a twist (v, omega) of the
tool point p:

1. the wrist centre moves with v_w = v + omega x (w - p), to which the wrist adds nothing: joints
   1-3 solve [a_1 x (w - o_1), a_2 x (w - o_2), a_3 x (w - o_3)] qd_123 = v_w;
2. the wrist solves [a_4 a_5 a_6] qd_456 = omega - qd_1 a_1 - (qd_2 + qd_3) a_2.

Both 3x3 systems are solved by Cramer's rule (the rows of the inverse are cross products of the
columns over the determinant). In the paper's angles theta, a_1 = z, a_2 = a_3 = Rz(theta1) y,
a_4 = R_0c z, a_5 = R_0c Rz(theta4) y, a_6 = the flange z; a maker joint with sign correction
-1 turns the other way, so its speed changes sign. Layout is component-first: q (6, ...).
"""

from __future__ import annotations

import math

import numpy as np

from solver.families.opw.parameters import OpwParameters


def _cramer(
    columns: tuple[np.ndarray, np.ndarray, np.ndarray], rhs: np.ndarray
) -> tuple[np.ndarray, ...]:
    """X with [c0 c1 c2] x = rhs, each of shape (3, ...), by Cramer's rule."""
    c0, c1, c2 = columns
    r0, r1, r2 = np.cross(c1, c2, axis=0), np.cross(c2, c0, axis=0), np.cross(c0, c1, axis=0)
    det = np.sum(c0 * r0, axis=0)
    return tuple(np.sum(r * rhs, axis=0) / det for r in (r0, r1, r2))


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
    shape = (6,) + (1,) * (q.ndim - 1)
    signs = np.array(p.sign_corrections, dtype=float).reshape(shape)
    theta = q * signs - np.array(p.offsets).reshape(shape)
    c1, s1 = np.cos(theta[0]), np.sin(theta[0])
    c2, s2 = np.cos(theta[1]), np.sin(theta[1])
    c23, s23 = np.cos(theta[1] + theta[2]), np.sin(theta[1] + theta[2])
    c4, s4 = np.cos(theta[3]), np.sin(theta[3])
    zero, one = np.zeros_like(c1), np.ones_like(c1)
    axis1 = np.stack([zero, zero, one])
    axis2 = np.stack([-s1, c1, zero])  # Rz(theta1) y, joints 2 and 3
    # Joint origins on their axes (any point of an axis will do) and the wrist centre.
    k = math.hypot(p.a2, p.c3)
    psi3 = math.atan2(p.a2, p.c3)
    elbow_x = p.a1 + p.c2 * s2  # in the plane turned by theta1 (x out, z up)
    elbow_z = p.c1 + p.c2 * c2
    wrist_x = elbow_x + k * np.sin(theta[1] + theta[2] + psi3)
    wrist_z = elbow_z + k * np.cos(theta[1] + theta[2] + psi3)

    def in_base(x: np.ndarray, z: np.ndarray | float) -> np.ndarray:
        """The point (x, b, z) of the turned plane, in {B}."""
        return np.stack([x * c1 - p.b * s1, x * s1 + p.b * c1, z + zero])

    shoulder = in_base(p.a1 + zero, p.c1)
    elbow = in_base(elbow_x, elbow_z)
    wrist = in_base(wrist_x, wrist_z)
    v, omega = twist[:3], twist[3:]
    v_wrist = v + np.cross(omega, wrist - tool_point, axis=0)
    qd1, qd2, qd3 = _cramer(
        (
            np.cross(axis1, wrist, axis=0),  # axis 1 passes through the origin
            np.cross(axis2, wrist - shoulder, axis=0),
            np.cross(axis2, wrist - elbow, axis=0),
        ),
        v_wrist,
    )
    # R_0c = Rz(theta1) Ry(theta2 + theta3): its z axis is joint 4's.
    axis4 = np.stack([c1 * s23, s1 * s23, c23])
    x_c = np.stack([c1 * c23, s1 * c23, -s23])
    axis5 = -s4 * x_c + c4 * axis2  # R_0c Rz(theta4) y
    c5, s5 = np.cos(theta[4]), np.sin(theta[4])
    axis6 = c5 * axis4 + s5 * (c4 * x_c + s4 * axis2)  # R_0c Rz(theta4) Ry(theta5) z
    rest = omega - qd1 * axis1 - (qd2 + qd3) * axis2
    qd4, qd5, qd6 = _cramer((axis4, axis5, axis6), rest)
    paper = np.stack(np.broadcast_arrays(qd1, qd2, qd3, qd4, qd5, qd6))
    speeds: np.ndarray = paper * signs
    return speeds
