"""Closed-form inverse kinematics of OPW arms, batched (Brandstotter, Angerer, Hofbaur 2014).

The wrist centre c = p - c4 z_F (z_F the flange z axis) fixes joints 1-3; the wrist then gives
joints 4-6 as the ZYZ angles of R_0c^T R_F, R_0c = Rz(theta1) Ry(theta2 + theta3). In the
paper's angles theta (theta = s q - o for the maker's q, sign corrections s, offsets o), with
lever = sqrt(cx^2 + cy^2 - b^2) the distance of c from axis 1 in the arm's plane:

    theta1 = atan2(cy, cx) - atan2(b, lever)                  (shoulder front)
             atan2(cy, cx) + atan2(b, lever) - pi             (shoulder back)
    theta3 = +-acos((s^2 - c2^2 - k^2) / (2 c2 k)) - atan2(a2, c3),   k^2 = a2^2 + c3^2
    theta2 = -+acos((s^2 + c2^2 - k^2) / (2 s c2)) + atan2(x, cz - c1)
    theta5 = +-atan2(|z_0c x z_F|, z_0c . z_F)
    theta4, theta6: the ZYZ angles of R_0c^T R_F (+pi and -pi on the flipped wrist)

where x = lever - a1 (front) or -(lever + a1) (back) is the wrist centre's reach beyond the
axis of joint 2 in the arm's plane and s^2 = x^2 + (cz - c1)^2.

Branch labels, each a sign choice above that changes along a path only through a singularity
(so a branch can be followed):

- shoulder ``front``: joint 1 faces the wrist centre (its x axis points to c, x' = +lever);
  ``back``: the arm reaches over backwards (x' = -lever). They meet on the shoulder singularity
  lever = 0 (c on axis 1; with b != 0 the cylinder of radius b around it).
- elbow ``up``: theta3 + atan2(a2, c3) = +acos >= 0, ``down``: -acos. Seen with x' to the
  right and z up, the ``up`` elbow is left of the line from joint 2 to c: above it where c is
  ahead of joint 2 (as on the front shoulder), below it on the back shoulder, whose line points
  to -x'. They meet where the arm is stretched or folded (acos argument +-1).
- wrist ``noflip``: theta5 >= 0 (paper's angle; the maker's q5 = s5 (theta5 + o5)); ``flip``:
  theta5 <= 0, theta4 + pi, theta6 - pi. They meet at the wrist singularity theta5 = 0.

Index b = 4 shoulder + 2 elbow + wrist with 0 for front / up / noflip; opw_kinematics and
py-opw-kinematics' ``reach`` make the same sign choices but put them in slot 4 wrist + 2 shoulder
+ elbow (tests compare slot by slot). Angles come back in the maker's convention
(q = s (theta + o)), wrapped to [-pi, pi); tracking adds the 2 pi copies. The work is shared per
level: joint 1 on (2, *batch), joints 2-3 and the wrist's angles on (2, 2, *batch), the flipped
wrist as a half turn of those; only the last assembly is (6, 8, *batch).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.core.family import Branch
from solver.core.spatial import rotation_about_z, wrap_angle
from solver.families.opw.parameters import OpwParameters

N_BRANCHES = 8
# A solution whose |sin theta5|, elbow sine or shoulder lever (m) is below this is singular
# (acos near +-1 resolves angles only to ~1.5e-8, as for UR arms).
SINGULAR_TOLERANCE = 1e-7
# A cosine computed as 1 + rounding error still has its (singular) solution.
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
        rotation: shape (3, 3, *batch), R_B_F of the flange (tool0) poses, columns its x, y, z
            axes in {B} (base_link); batch axes broadcast with those of ``position``.
        position: shape (3, *batch), flange positions in {B} (m).

    Returns:
        q: shape (6, 8, *batch), rad in the maker's convention, in [-pi, pi), NaN where
        unreachable;
        status: shape (8, *batch), ``OK``, ``UNREACHABLE`` or ``SINGULAR`` (shoulder, elbow or
        wrist singularity; q is still a solution there).
    """
    # NaN and inf (a pose far beyond reach overflows) are unreachable: said in the answer, not
    # as numpy warnings in the service's log (audit 22).
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return _solve(parameters, rotation, position)


def _solve(
    p: OpwParameters, rotation: np.ndarray, position: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The body of :func:`solve_components`."""
    batch = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
    r = rotation
    cx = position[0] - p.c4 * r[0, 2]
    cy = position[1] - p.c4 * r[1, 2]
    height = position[2] - p.c4 * r[2, 2] - p.c1
    radial2 = cx * cx + cy * cy - p.b * p.b
    lever = np.sqrt(np.maximum(radial2, 0.0))
    heading = np.arctan2(cy, cx)
    side = np.arctan2(p.b, lever)
    # Shoulder level (2, *batch): front, back.
    theta1 = np.stack([heading - side, heading + side - math.pi])
    forward = np.stack([lever - p.a1, lever + p.a1])  # |x|: reach beyond joint 2's axis
    s2 = forward * forward + height * height
    k2 = p.a2 * p.a2 + p.c3 * p.c3
    cos_elbow = (s2 - p.c2 * p.c2 - k2) / (2 * p.c2 * math.sqrt(k2))
    cos_shoulder = (s2 + p.c2 * p.c2 - k2) / (2 * p.c2 * np.sqrt(s2))
    reach = (
        (radial2 >= -REACH_TOLERANCE)
        & (np.abs(cos_elbow) <= 1 + REACH_TOLERANCE)
        & (np.abs(cos_shoulder) <= 1 + REACH_TOLERANCE)
    )
    # NaN where unreachable: it flows from theta1 and the acos into every joint.
    theta1 = np.where(reach, theta1, np.nan)
    cos_elbow = np.where(reach, np.clip(cos_elbow, -1.0, 1.0), np.nan)
    acos_elbow = np.arccos(cos_elbow)
    acos_shoulder = np.arccos(np.where(reach, np.clip(cos_shoulder, -1.0, 1.0), np.nan))
    angle_to = np.arctan2(forward, height)
    angle_to[1] *= -1.0  # the back shoulder reaches towards -x'
    # Elbow level (2 shoulder, 2 elbow, *batch): up takes +acos in theta3, -acos in theta2.
    psi3 = math.atan2(p.a2, p.c3)
    theta3 = np.stack([acos_elbow - psi3, -acos_elbow - psi3], axis=1)
    theta2 = np.stack([angle_to - acos_shoulder, angle_to + acos_shoulder], axis=1)
    # Flange axes in the arm's plane frame (x' along the arm, y' = axis 2, z), shoulder level.
    c1, s1 = np.cos(theta1), np.sin(theta1)
    ux, uy, uz = (r[0, j] * c1 + r[1, j] * s1 for j in range(3))  # x' . x_F, y_F, z_F
    y_z = r[1, 2] * c1 - r[0, 2] * s1  # y' . z_F
    angle23 = theta2 + theta3
    c23, s23 = np.cos(angle23), np.sin(angle23)
    # Columns of R_0c (x_c = c23 x' - s23 z, z_c = s23 x' + c23 z) dotted with the flange axes.
    m = s23 * uz[:, None] + c23 * r[2, 2]  # z_c . z_F = cos theta5
    x_z = c23 * uz[:, None] - s23 * r[2, 2]  # x_c . z_F
    z_y = s23 * uy[:, None] + c23 * r[2, 1]  # z_c . y_F
    z_x = s23 * ux[:, None] + c23 * r[2, 0]  # z_c . x_F
    y_z = np.broadcast_to(y_z[:, None], m.shape)
    sin5 = np.hypot(x_z, y_z)  # exact near 0, where sqrt(1 - m^2) loses half the digits
    theta5 = np.arctan2(sin5, m)
    theta4 = np.arctan2(y_z, x_z)
    theta6 = np.arctan2(z_y, -z_x)
    wrist_singular = sin5 < SINGULAR_TOLERANCE
    if wrist_singular.any():
        # Only theta4 +- theta6 is fixed: take theta6 = 0 and theta4 from the flange y axis
        # (Rz(theta4) Ry(0 or pi) has y column (-sin theta4, cos theta4, 0)).
        x_y = c23 * uy[:, None] - s23 * r[2, 1]  # x_c . y_F
        y_y = np.broadcast_to((r[1, 1] * c1 - r[0, 1] * s1)[:, None], m.shape)  # y' . y_F
        theta4 = np.where(wrist_singular, np.arctan2(-x_y, y_y), theta4)
        theta6 = np.where(wrist_singular, 0.0, theta6)
    # The maker's angles, per level; the flipped wrist's q4 and q6 are half turns of noflip's.
    o, s = p.offsets, p.sign_corrections
    q4 = wrap_angle((theta4 + o[3]) * s[3])
    q6 = wrap_angle((theta6 + o[5]) * s[5])
    q = np.empty((6, 2, 2, 2, *batch))
    q[0] = wrap_angle((theta1 + o[0]) * s[0])[:, None, None]
    q[1] = wrap_angle((theta2 + o[1]) * s[1])[:, :, None]
    q[2] = wrap_angle((theta3 + o[2]) * s[2])[:, :, None]
    q[3, :, :, 0], q[3, :, :, 1] = q4, _half_turn(q4)
    q[4, :, :, 0] = wrap_angle((theta5 + o[4]) * s[4])
    q[4, :, :, 1] = wrap_angle((o[4] - theta5) * s[4])
    q[5, :, :, 0], q[5, :, :, 1] = q6, _half_turn(q6)
    # Singular: c on axis 1 (shoulder), the arm stretched or folded (elbow), theta5 = 0.
    elbow_singular = 1.0 - cos_elbow * cos_elbow < SINGULAR_TOLERANCE**2
    singular = wrist_singular | (elbow_singular | (lever < SINGULAR_TOLERANCE))[:, None]
    status = np.where(reach[:, None], np.where(singular, SINGULAR, OK), UNREACHABLE)
    status = np.broadcast_to(status[:, :, None], (2, 2, 2, *batch))
    return q.reshape((6, N_BRANCHES, *batch)), status.reshape((N_BRANCHES, *batch))


def _half_turn(angle: np.ndarray) -> np.ndarray:
    """Angles in [-pi, pi) turned by pi, back in [-pi, pi)."""
    turned: np.ndarray = np.where(angle >= 0.0, angle - math.pi, angle + math.pi)
    return turned


def forward_kinematics(parameters: OpwParameters, q: np.ndarray) -> np.ndarray:
    """Flange pose in {B} by the paper's forward formula, batched: q (..., 6) -> (..., 4, 4).

    Args:
        parameters: the arm's geometry.
        q: shape (..., 6), rad, maker's convention.

    Returns:
        shape (..., 4, 4), T_B_F (m): R = Rz(t1) Ry(t2 + t3) Rz(t4) Ry(t5) Rz(t6) and the flange
        c4 along its z axis from the wrist centre, as opw_kinematics' ``forward``.
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
    rotation = (
        rotation_about_z(t1) @ _ry(t2 + t3) @ rotation_about_z(t4) @ _ry(t5) @ rotation_about_z(t6)
    )
    out = np.zeros(t.shape[:-1] + (4, 4))
    out[..., :3, :3] = rotation
    out[..., :3, 3] = centre + p.c4 * rotation[..., :, 2]
    out[..., 3, 3] = 1.0
    return out


def _ry(angle: np.ndarray) -> np.ndarray:
    """Rotations about y, shape (*angle.shape, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., 0, 0], out[..., 0, 2], out[..., 2, 0], out[..., 2, 2] = c, s, -s, c
    out[..., 1, 1] = 1.0
    return out
