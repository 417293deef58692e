"""Analytic inverse kinematics of UR arms, batched over poses (numpy).

The UR geometry (joints 2, 3, 4 parallel; axes 5 and 6 meeting at the wrist) gives up to eight
closed-form solutions per flange pose: two shoulder choices for q1, two wrist choices for q5 and
two elbow choices for q3. The derivation follows the standard DH treatment of the UR family
(Hawkins 2013, "Analytic inverse kinematics for the Universal Robots UR-5/UR-10 arms"):

    p05 = p - d6 z6                       wrist centre (origin of frame 5)
    q1  = atan2(p05_y, p05_x) +- acos(d4 / |p05_xy|) + pi/2
    q5  = +- acos((p_x sin q1 - p_y cos q1 - d4) / d6)
    q6  from the flange axes projected on frame 1
    q3  = +- acos((|p14_xy|^2 - a2^2 - a3^2) / (2 a2 a3))    planar 2R arm in frame 1
    q2  = atan2(p14_y, p14_x) - atan2(a3 sin q3, a2 + a3 cos q3)
    q4  = atan2(R14_yx, R14_xx) - q2 - q3

Branch labels (the API's names), from the signs chosen above:

- shoulder ``left`` / ``right``: + / - before acos in q1;
- elbow ``up`` / ``down``: sign(q3) equal / opposite to the shoulder sign. In the usual working
  posture (upper arm and wrist on the same side of the shoulder) this is the elbow above / below
  the line from shoulder to wrist; unlike that geometric test, the sign never changes along a
  path except through the elbow singularity q3 = 0, so a branch can be followed;
- wrist ``noflip`` / ``flip``: + / - before acos in q5.

Angles come back in [-pi, pi); each joint of range +-2pi also has a copy 2 pi away
(:func:`joint_copies`). Shapes: poses (N, 4, 4) with the flange {F} in the base frame {B}
(metres); solutions (N, 8, 6) in radians, branch index b = 4 shoulder + 2 elbow + wrist with
0 for left / up / noflip.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from solver.robots import UrDh

N_BRANCHES = 8
# A solution whose |sin q5|, |sin q3| or shoulder lever (m) is below this is singular. acos near
# +-1 resolves angles only to ~sqrt(machine epsilon) = 1.5e-8, so an exactly singular pose comes
# back with |sin q5| up to ~1e-8; 1e-7 catches it (V_max there would be ~1e-7 of its usual size).
SINGULAR_TOLERANCE = 1e-7
# A cosine computed as 1 + rounding error still has its (singular) solution.
REACH_TOLERANCE = 1e-10

# Status codes of a (pose, branch) solution.
OK = 0
UNREACHABLE = 1
SINGULAR = 2


@dataclass(frozen=True)
class Branch:
    """Name of an IK branch of a UR arm."""

    shoulder: str
    elbow: str
    wrist: str


BRANCHES: tuple[Branch, ...] = tuple(
    Branch(s, e, w)
    for s, e, w in itertools.product(("left", "right"), ("up", "down"), ("noflip", "flip"))
)


def branch_index(label: Branch) -> int:
    """Index 0..7 of a branch label, as used on axis 1 of :func:`solve_batch`."""
    return BRANCHES.index(label)


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def _inverse(transform: np.ndarray) -> np.ndarray:
    """Inverse of homogeneous transforms, shape (..., 4, 4)."""
    rotation_t = np.swapaxes(transform[..., :3, :3], -1, -2)
    out = np.zeros_like(transform)
    out[..., :3, :3] = rotation_t
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", rotation_t, transform[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def dh_transform(theta: np.ndarray, d: float, a: float, alpha: float) -> np.ndarray:
    """Standard DH link transforms Rz(theta) Tz(d) Tx(a) Rx(alpha), shape theta.shape + (4, 4)."""
    c, s = np.cos(theta), np.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    out = np.zeros(np.shape(theta) + (4, 4))
    out[..., 0, 0] = c
    out[..., 0, 1] = -s * ca
    out[..., 0, 2] = s * sa
    out[..., 0, 3] = a * c
    out[..., 1, 0] = s
    out[..., 1, 1] = c * ca
    out[..., 1, 2] = -c * sa
    out[..., 1, 3] = a * s
    out[..., 2, 1] = sa
    out[..., 2, 2] = ca
    out[..., 2, 3] = d
    out[..., 3, 3] = 1.0
    return out


def forward_kinematics_dh(dh: UrDh, q: np.ndarray) -> np.ndarray:
    """Flange pose in {B} from DH parameters, batched: q (..., 6) -> (..., 4, 4)."""
    transform = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4)).copy()
    for i in range(6):
        transform = transform @ dh_transform(q[..., i], dh.d[i], dh.a[i], dh.alpha[i])
    return transform


def solve_batch(dh: UrDh, flange_in_base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All eight analytic IK branches for N flange poses.

    Args:
        dh: the arm's DH parameters.
        flange_in_base: shape (N, 4, 4), T_B_F (metres).

    Returns:
        q: shape (N, 8, 6), rad in [-pi, pi), NaN where a branch has no solution;
        status: shape (N, 8), ``OK``, ``UNREACHABLE`` or ``SINGULAR`` (q5 or q3 at 0 or pi, or
        the wrist centre on the shoulder's singular surface; q is still filled there).
    """
    poses = np.asarray(flange_in_base, dtype=float)
    n_poses = poses.shape[0]
    rot, pos = poses[:, :3, :3], poses[:, :3, 3]
    wrist = pos - dh.d6 * rot[:, :, 2]
    radius = np.hypot(wrist[:, 0], wrist[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio1 = dh.d4 / radius
    reach1 = np.abs(ratio1) <= 1.0 + REACH_TOLERANCE
    shoulder_sign = np.array([1.0, -1.0])
    q1 = (
        np.arctan2(wrist[:, 1], wrist[:, 0])[:, None]
        + shoulder_sign * np.arccos(np.clip(ratio1, -1.0, 1.0))[:, None]
        + math.pi / 2
    )  # (N, 2)
    c1, s1 = np.cos(q1), np.sin(q1)
    cos5 = (pos[:, 0, None] * s1 - pos[:, 1, None] * c1 - dh.d4) / dh.d6
    reach5 = np.abs(cos5) <= 1.0 + REACH_TOLERANCE
    wrist_sign = np.array([1.0, -1.0])
    q5 = wrist_sign * np.arccos(np.clip(cos5, -1.0, 1.0))[:, :, None]  # (N, 2, 2)
    # x and y axes of the flange seen from frame 1 give q6 (divided by sin q5 -> its sign).
    nx, ny = rot[:, 0, 0, None], rot[:, 1, 0, None]
    ox, oy = rot[:, 0, 1, None], rot[:, 1, 1, None]
    q6 = np.arctan2(
        wrist_sign * (-ox * s1 + oy * c1)[:, :, None],
        wrist_sign * (nx * s1 - ny * c1)[:, :, None],
    )
    q1_b = np.broadcast_to(q1[:, :, None], q5.shape)
    t01 = dh_transform(q1_b, dh.d1, 0.0, dh.alpha[0])
    t45 = dh_transform(q5, dh.d5, 0.0, dh.alpha[4])
    t56 = dh_transform(q6, dh.d6, 0.0, 0.0)
    t14 = _inverse(t01) @ poses[:, None, None] @ _inverse(t56) @ _inverse(t45)
    px, py = t14[..., 0, 3], t14[..., 1, 3]
    cos3 = (px * px + py * py - dh.a2**2 - dh.a3**2) / (2 * dh.a2 * dh.a3)
    reach3 = np.abs(cos3) <= 1.0 + REACH_TOLERANCE
    # Elbow "up" (index 0) takes sign(q3) = shoulder sign: axis order (N, shoulder, wrist, elbow)
    elbow_sign = shoulder_sign[:, None, None] * np.array([1.0, -1.0])
    q3 = elbow_sign * np.arccos(np.clip(cos3, -1.0, 1.0))[..., None]  # (N, 2, 2, 2)
    q2 = np.arctan2(py, px)[..., None] - np.arctan2(dh.a3 * np.sin(q3), dh.a2 + dh.a3 * np.cos(q3))
    q234 = np.arctan2(t14[..., 1, 0], t14[..., 0, 0])[..., None]
    q4 = q234 - q2 - q3
    shape = (n_poses, 2, 2, 2)
    q = np.stack(
        [
            np.broadcast_to(q1[:, :, None, None], shape),
            q2,
            q3,
            q4,
            np.broadcast_to(q5[..., None], shape),
            np.broadcast_to(q6[..., None], shape),
        ],
        axis=-1,
    )
    # (N, shoulder, wrist, elbow, 6) -> (N, shoulder, elbow, wrist, 6) -> (N, 8, 6)
    q = wrap_angle(np.swapaxes(q, 2, 3).reshape(n_poses, N_BRANCHES, 6))
    reach = (
        reach1[:, None, None, None]
        & reach5[:, :, None, None]
        & np.broadcast_to(reach3[..., None], shape)
    )
    reach = np.swapaxes(reach, 2, 3).reshape(n_poses, N_BRANCHES)
    singular = singular_mask(dh, q)
    status = np.where(reach, np.where(singular, SINGULAR, OK), UNREACHABLE)
    q[~reach] = np.nan
    return q, status


def singular_mask(dh: UrDh, q: np.ndarray) -> np.ndarray:
    """Where the UR Jacobian is singular, batched: q (..., 6) -> bool (...).

    det J = a2 a3 sin q3 sin q5 (a2 cos q2 + a3 cos(q2 + q3) + d5 sin(q2 + q3 + q4)) up to sign:
    the elbow, wrist and shoulder singularities.
    """
    q2, q3, q4, q5 = q[..., 1], q[..., 2], q[..., 3], q[..., 4]
    lever = dh.a2 * np.cos(q2) + dh.a3 * np.cos(q2 + q3) + dh.d5 * np.sin(q2 + q3 + q4)
    mask: np.ndarray = (
        (np.abs(np.sin(q3)) < SINGULAR_TOLERANCE)
        | (np.abs(np.sin(q5)) < SINGULAR_TOLERANCE)
        | (np.abs(lever) < SINGULAR_TOLERANCE)
    )
    return mask


def joint_copies(q: np.ndarray, *, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Every copy of one solution shifted by multiples of 2 pi that lies within the limits.

    Args:
        q: shape (6,), rad.
        lower: shape (6,), rad, lower position limits.
        upper: shape (6,), rad, upper position limits.

    Returns:
        shape (K, 6): all combinations, K = 0 when some joint has no copy within its limits.
    """
    per_joint = []
    for value, low, high in zip(q, lower, upper, strict=True):
        k_min = math.ceil((low - value) / (2 * math.pi) - 1e-12)
        k_max = math.floor((high - value) / (2 * math.pi) + 1e-12)
        per_joint.append([value + 2 * math.pi * k for k in range(k_min, k_max + 1)])
    copies: np.ndarray = np.array(list(itertools.product(*per_joint)), dtype=float)
    return copies.reshape(-1, 6)
