"""Closed-form inverse kinematics of OPW arms, batched (Brandstotter, Angerer, Hofbaur 2014).

The wrist centre c = p - c4 z_F (z_F the flange z axis) fixes joints 1-3; the wrist then gives
joints 4-6 as the ZYZ angles of R_0c^T R_F. In the paper's angles theta (q_paper = s q - o for
the maker's q, sign corrections s, offsets o):

    theta1 = atan2(cy, cx) - atan2(b, nx1 + a1)           (shoulder front)
             atan2(cy, cx) + atan2(b, nx1 + a1) - pi      (shoulder back)
    theta3 = +-acos((s^2 - c2^2 - k^2) / (2 c2 k)) - atan2(a2, c3),   k^2 = a2^2 + c3^2
    theta2 = -+acos((s^2 + c2^2 - k^2) / (2 s c2)) + atan2(nx1, cz - c1)     (front; back with
             nx1 + 2 a1 and the atan2 negated)
    theta5 = +-atan2(sqrt(1 - m^2), m),  m = z_0c . z_F
    theta4, theta6 from the wrist's ZYZ angles (+pi and -pi on the flipped wrist)

Branch labels (mean the same thing at every pose, so a branch can be followed along a path):
shoulder ``front`` / ``back`` (the two theta1 above), elbow ``up`` / ``down`` (+ / - before the
acos in theta3), wrist ``noflip`` / ``flip`` (theta5 >= 0 / <= 0). Index b = 4 shoulder +
2 elbow + wrist with 0 for front / up / noflip. Angles come back in the maker's convention,
wrapped to [-pi, pi]; tracking adds the 2 pi copies.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from solver.families.base import OK, SINGULAR, UNREACHABLE, Branch
from solver.families.opw.parameters import OpwParameters
from solver.spatial import wrap_angle

N_BRANCHES = 8
# A solution whose |sin theta5|, elbow sine or shoulder lever (m) is below this is singular
# (acos near +-1 resolves angles only to ~1.5e-8, as for UR arms).
SINGULAR_TOLERANCE = 1e-7
REACH_TOLERANCE = 1e-10

BRANCHES: tuple[Branch, ...] = tuple(
    Branch.named(shoulder=s, elbow=e, wrist=w)
    for s, e, w in itertools.product(("front", "back"), ("up", "down"), ("noflip", "flip"))
)


def solve_components(
    parameters: OpwParameters, rotation: np.ndarray, position: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """All eight branches for flange poses, component-first.

    Args:
        parameters: the arm's geometry.
        rotation: shape (3, 3, *batch), R_B_F of the flange poses.
        position: shape (3, *batch), flange positions in {B} (m).

    Returns:
        q: shape (6, 8, *batch), rad in the maker's convention, NaN where unreachable;
        status: shape (8, *batch), ``OK``, ``UNREACHABLE`` or ``SINGULAR``.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        return _solve(parameters, rotation, position)


def _solve(
    p: OpwParameters, rotation: np.ndarray, position: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The body of :func:`solve_components`."""
    batch = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
    ones = (1,) * len(batch)
    cx = position[0] - p.c4 * rotation[0, 2]
    cy = position[1] - p.c4 * rotation[1, 2]
    cz = position[2] - p.c4 * rotation[2, 2]
    radial2 = cx * cx + cy * cy - p.b * p.b
    lever = np.sqrt(np.maximum(radial2, 0.0))  # distance of the wrist centre from axis 1, in-plane
    reach_shoulder = radial2 >= -REACH_TOLERANCE
    nx1 = lever - p.a1
    height = cz - p.c1
    heading = np.arctan2(cy, cx)
    side = np.arctan2(p.b, nx1 + p.a1)
    # Shoulder level (2, *batch): front and back.
    theta1 = np.stack([heading - side, heading + side - math.pi])
    forward = np.stack([nx1, nx1 + 2 * p.a1])  # in-plane reach beyond the shoulder offset
    angle_to = np.stack(
        [np.arctan2(nx1, height), -np.arctan2(nx1 + 2 * p.a1, height)]
    )  # the atan2 term of theta2
    s2 = forward * forward + height * height
    k2 = p.a2 * p.a2 + p.c3 * p.c3
    psi3 = math.atan2(p.a2, p.c3)
    cos_elbow = (s2 - p.c2 * p.c2 - k2) / (2 * p.c2 * math.sqrt(k2))
    cos_shoulder = (s2 + p.c2 * p.c2 - k2) / (2 * np.sqrt(s2) * p.c2)
    reach_arm = (np.abs(cos_elbow) <= 1 + REACH_TOLERANCE) & (
        np.abs(cos_shoulder) <= 1 + REACH_TOLERANCE
    )
    acos_elbow = np.arccos(np.clip(cos_elbow, -1.0, 1.0))
    acos_shoulder = np.arccos(np.clip(cos_shoulder, -1.0, 1.0))
    # Elbow level (2 shoulder, 2 elbow, *batch): "up" takes +acos in theta3 and -acos in
    # theta2, as the paper pairs them.
    elbow_sign = np.array([1.0, -1.0]).reshape((1, 2, *ones))
    theta3 = elbow_sign * acos_elbow[:, None] - psi3
    theta2 = -elbow_sign * acos_shoulder[:, None] + angle_to[:, None]
    t1 = theta1[:, None]
    c1, s1 = np.cos(t1), np.sin(t1)
    c23, s23 = np.cos(theta2 + theta3), np.sin(theta2 + theta3)
    r = rotation
    # Columns of R_0c = Rz(theta1) Ry(theta2 + theta3) dotted with the flange axes.
    m = r[0, 2] * s23 * c1 + r[1, 2] * s23 * s1 + r[2, 2] * c23  # z_0c . z_F = cos theta5
    x_z = r[0, 2] * c23 * c1 + r[1, 2] * c23 * s1 - r[2, 2] * s23  # x_0c . z_F
    y_z = r[1, 2] * c1 - r[0, 2] * s1  # y_0c . z_F
    z_y = r[0, 1] * s23 * c1 + r[1, 1] * s23 * s1 + r[2, 1] * c23  # z_0c . y_F
    z_x = r[0, 0] * s23 * c1 + r[1, 0] * s23 * s1 + r[2, 0] * c23  # z_0c . x_F
    sin5 = np.hypot(x_z, y_z)  # exact near 0, where sqrt(1 - m^2) loses half the digits
    wrist_singular = sin5 < SINGULAR_TOLERANCE
    theta5 = np.arctan2(sin5, m)
    theta4 = np.arctan2(y_z, x_z)
    theta6 = np.arctan2(z_y, -z_x)
    # At the wrist singularity only theta4 +- theta6 is fixed: take theta6 = 0, and theta4 from
    # the flange y axis (Rz(theta4) Ry(0 or pi) has y column (-sin theta4, cos theta4, 0)).
    x_y = r[0, 1] * c23 * c1 + r[1, 1] * c23 * s1 - r[2, 1] * s23  # x_0c . y_F
    y_y = r[1, 1] * c1 - r[0, 1] * s1  # y_0c . y_F
    theta4 = np.where(wrist_singular, np.arctan2(-x_y, y_y), theta4)
    theta6 = np.where(wrist_singular, 0.0, theta6)
    # Wrist level (..., 2, *batch): noflip theta5 >= 0, flip: -theta5, theta4 + pi, theta6 - pi.
    flip = np.array([0.0, 1.0]).reshape((1, 1, 2, *ones))
    shape = (2, 2, 2, *batch)
    q_paper = np.stack(
        [
            np.broadcast_to(t1[:, :, None], shape),
            np.broadcast_to(theta2[:, :, None], shape),
            np.broadcast_to(theta3[:, :, None], shape),
            theta4[:, :, None] + math.pi * flip,
            theta5[:, :, None] * (1 - 2 * flip),
            theta6[:, :, None] - math.pi * flip,
        ]
    ).reshape((6, N_BRANCHES, *batch))
    offsets = np.array(p.offsets).reshape((6, 1, *ones))
    signs = np.array(p.sign_corrections, dtype=float).reshape((6, 1, *ones))
    q = wrap_angle((q_paper + offsets) * signs)
    reach = np.broadcast_to((reach_shoulder & reach_arm)[:, None, None], shape)
    reach = reach.reshape((N_BRANCHES, *batch))
    elbow_sine = np.sqrt(np.maximum(1.0 - np.clip(cos_elbow, -1.0, 1.0) ** 2, 0.0))
    singular = (
        (np.abs(nx1 + p.a1) < SINGULAR_TOLERANCE)[None, None, None]
        | (elbow_sine < SINGULAR_TOLERANCE)[:, None, None]
        | wrist_singular[:, :, None]
    )
    singular = np.broadcast_to(singular, shape).reshape((N_BRANCHES, *batch))
    status = np.where(reach, np.where(singular, SINGULAR, OK), UNREACHABLE)
    q[:, ~reach] = np.nan
    return q, status


def forward_kinematics(parameters: OpwParameters, q: np.ndarray) -> np.ndarray:
    """Flange pose in {B} by the paper's forward formula, batched: q (..., 6) -> (..., 4, 4).

    Args:
        parameters: the arm's geometry.
        q: shape (..., 6), rad, maker's convention.
    """
    p = parameters
    t = np.asarray(q, dtype=float) * np.array(p.sign_corrections) - np.array(p.offsets)
    t1, t2, t3, t4, t5, t6 = np.moveaxis(t, -1, 0)
    k = math.hypot(p.a2, p.c3)
    psi3 = math.atan2(p.a2, p.c3)
    cx1 = p.c2 * np.sin(t2) + k * np.sin(t2 + t3 + psi3) + p.a1
    cz1 = p.c2 * np.cos(t2) + k * np.cos(t2 + t3 + psi3)
    centre = np.stack(
        [cx1 * np.cos(t1) - p.b * np.sin(t1), cx1 * np.sin(t1) + p.b * np.cos(t1), cz1 + p.c1],
        axis=-1,
    )
    rotation = _rz(t1) @ _ry(t2 + t3) @ _rz(t4) @ _ry(t5) @ _rz(t6)
    out = np.zeros(t.shape[:-1] + (4, 4))
    out[..., :3, :3] = rotation
    out[..., :3, 3] = centre + p.c4 * rotation[..., :, 2]
    out[..., 3, 3] = 1.0
    return out


def _rz(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = 1.0
    return out


def _ry(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., 0, 0], out[..., 0, 2], out[..., 2, 0], out[..., 2, 2] = c, s, -s, c
    out[..., 1, 1] = 1.0
    return out
