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

Angles come back in [-pi, pi] (q3, q5 and q6 straight from atan2 may be pi); each joint of
range +-2pi also has a copy 2 pi away (:func:`joint_copies`). Shapes: poses (N, 4, 4) with the
flange {F} in the base frame {B} (metres); solutions (N, 8, 6) in radians, branch index
b = 4 shoulder + 2 elbow + wrist with 0 for left / up / noflip.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.core.family import Branch
from solver.core.spatial import wrap_angle
from solver.families.ur.dh import UrDh

N_BRANCHES = 8
# A solution whose |sin q5|, |sin q3| or shoulder lever (m) is below this is singular. acos near
# +-1 resolves angles only to ~sqrt(machine epsilon) = 1.5e-8, so an exactly singular pose comes
# back with |sin q5| up to ~1e-8; 1e-7 catches it (V_max there would be ~1e-7 of its usual size).
SINGULAR_TOLERANCE = 1e-7
# A cosine computed as 1 + rounding error still has its (singular) solution.
REACH_TOLERANCE = 1e-10

_SHOULDERS = ("left", "right")
_ELBOWS = ("up", "down")
_WRISTS = ("noflip", "flip")
BRANCHES: tuple[Branch, ...] = tuple(
    Branch.named(shoulder=s, elbow=e, wrist=w)
    for s, e, w in itertools.product(_SHOULDERS, _ELBOWS, _WRISTS)
)


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
        q: shape (N, 8, 6), rad in [-pi, pi], NaN where a branch has no solution;
        status: shape (N, 8), ``OK``, ``UNREACHABLE`` or ``SINGULAR`` (q5 or q3 at 0 or pi, or
        the wrist centre on the shoulder's singular surface; q is still filled there).
    """
    poses = np.asarray(flange_in_base, dtype=float)
    rotation = np.moveaxis(poses[:, :3, :3], 0, -1)
    position = np.moveaxis(poses[:, :3, 3], 0, -1)
    q, status = solve_components(dh, rotation, position)
    return np.moveaxis(q, 0, -1).swapaxes(0, 1), status.T


def solve_components(
    dh: UrDh, rotation: np.ndarray, position: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """All eight analytic IK branches, component-first layout (the fast path of the map).

    Args:
        dh: the arm's DH parameters.
        rotation: shape (3, 3, *batch), R_B_F of the flange poses (columns: flange x, y, z
            axes); batch axes broadcast with those of ``position``.
        position: shape (3, *batch), flange positions in {B} (m).

    Returns:
        q: shape (6, 8, *batch), rad in [-pi, pi], NaN where unreachable;
        status: shape (8, *batch).
    """
    # A pose metres beyond any reach overflows to inf and NaN, which the reach tests make
    # unreachable: said in the answer, not as numpy warnings in the service's log (audit 22).
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return _solve(dh, rotation, position)


def _solve(dh: UrDh, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The body of :func:`solve_components`."""
    batch = np.broadcast_shapes(rotation.shape[2:], position.shape[1:])
    ones = (1,) * len(batch)
    n_x, n_y = rotation[0, 0], rotation[1, 0]  # flange x axis
    a_x, a_y, a_z = rotation[0, 2], rotation[1, 2], rotation[2, 2]  # flange z axis (= z5)
    w_x = position[0] - dh.d6 * a_x  # wrist centre: the origin of frame 5
    w_y = position[1] - dh.d6 * a_y
    w_z = position[2] - dh.d6 * a_z
    radius = np.hypot(w_x, w_y)
    ratio1 = dh.d4 / radius
    reach1 = np.abs(ratio1) <= 1.0 + REACH_TOLERANCE
    sign = np.array([1.0, -1.0]).reshape((2, *ones))
    # Shoulder level, shape (2, M): w . z1 = d4 with z1 = (sin q1, -cos q1, 0).
    q1 = np.arctan2(w_y, w_x) + sign * np.arccos(np.clip(ratio1, -1.0, 1.0)) + math.pi / 2
    q1 = wrap_angle(q1)
    c1, s1 = np.cos(q1), np.sin(q1)
    cos5 = a_x * s1 - a_y * c1  # z5 . z1
    reach5 = np.abs(cos5) <= 1.0 + REACH_TOLERANCE
    cos5 = np.clip(cos5, -1.0, 1.0)
    # Wrist level, shape (2, 2, M): sin q5 = +-|z1 x z5| (the wrist sign), exact near 0 where
    # sqrt(1 - cos^2) would lose half the digits.
    cross_z = s1 * a_y + c1 * a_x
    sin5 = sign[:, None] * np.sqrt(a_z * a_z + cross_z * cross_z)[None]
    sin5 = np.swapaxes(sin5, 0, 1)  # (shoulder, wrist, M)
    q5 = np.arctan2(sin5, cos5[:, None])
    wrist_singular = np.abs(sin5) < SINGULAR_TOLERANCE
    inv5 = 1.0 / np.where(wrist_singular, 1.0, sin5)
    c1w, s1w = c1[:, None], s1[:, None]
    # z4 = (z1 x z5) / sin q5; x5 = -(z4 x z5) and y5 = -z4 give q6 from the flange x axis.
    # Where sin q5 = 0 the wrist has a continuum of solutions: take the one with q6 = 0,
    # z4 = x6 x z5 (it is flagged singular).
    n_z = rotation[2, 0]
    z4_x = np.where(wrist_singular, n_y * a_z - n_z * a_y, -c1w * a_z * inv5)
    z4_y = np.where(wrist_singular, n_z * a_x - n_x * a_z, -s1w * a_z * inv5)
    z4_z = np.where(wrist_singular, n_x * a_y - n_y * a_x, cross_z[:, None] * inv5)
    x5_x = -(z4_y * a_z - z4_z * a_y)
    x5_y = -(z4_z * a_x - z4_x * a_z)
    x5_z = -(z4_x * a_y - z4_y * a_x)
    q6 = np.arctan2(-(n_x * z4_x + n_y * z4_y + n_z * z4_z), n_x * x5_x + n_y * x5_y + n_z * x5_z)
    # Planar arm in frame 1 (x1 = (c1, s1, 0), y1 = z0): frame 3 origin o3 = w - d5 z4 - d4 z1.
    plane_x = (w_x - dh.d5 * z4_x) * c1w + (w_y - dh.d5 * z4_y) * s1w
    plane_y = w_z - dh.d5 * z4_z - dh.d1
    q234 = np.arctan2(z4_x * c1w + z4_y * s1w, -z4_z)
    cos3 = (plane_x * plane_x + plane_y * plane_y - dh.a2**2 - dh.a3**2) / (2 * dh.a2 * dh.a3)
    reach3 = np.abs(cos3) <= 1.0 + REACH_TOLERANCE
    # Elbow level, shape (2, 2, 2, M): "up" takes sign(q3) = shoulder sign.
    elbow_sign = sign[:, None, None] * np.array([1.0, -1.0]).reshape((1, 1, 2, *ones))
    sin3 = elbow_sign * np.sqrt(1.0 - np.clip(cos3, -1.0, 1.0) ** 2)[:, :, None]
    cos3_e = np.clip(cos3, -1.0, 1.0)[:, :, None]
    q3 = np.arctan2(sin3, cos3_e)
    q2 = np.arctan2(plane_y, plane_x)[:, :, None] - np.arctan2(dh.a3 * sin3, dh.a2 + dh.a3 * cos3_e)
    q4 = q234[:, :, None] - q2 - q3
    shape = q3.shape  # (shoulder, wrist, elbow, M)
    q = np.stack(
        [
            np.broadcast_to(q1[:, None, None], shape),
            q2,
            q3,
            q4,
            np.broadcast_to(q5[:, :, None], shape),
            np.broadcast_to(q6[:, :, None], shape),
        ]
    )
    # (6, shoulder, wrist, elbow, M) -> (6, shoulder, elbow, wrist, M) -> (6, 8, M)
    q = np.swapaxes(q, 2, 3).reshape((6, N_BRANCHES, *batch))
    for joint in (1, 3):  # q1 is wrapped above; q3, q5 and q6 come from atan2, in range
        q[joint] = wrap_angle(q[joint])
    reach = np.broadcast_to(reach1 & reach5[:, None, None] & reach3[:, :, None], shape)
    reach = np.swapaxes(reach, 1, 2).reshape((N_BRANCHES, *batch))
    # det J = a2 a3 sin q3 sin q5 (w . x1): the elbow, wrist and shoulder singularities.
    lever = w_x * c1 + w_y * s1
    singular = (
        (np.abs(lever) < SINGULAR_TOLERANCE)[:, None, None]
        | (np.abs(sin5) < SINGULAR_TOLERANCE)[:, :, None]
        | (np.abs(sin3) < SINGULAR_TOLERANCE)
    )
    singular = np.swapaxes(singular, 1, 2).reshape((N_BRANCHES, *batch))
    status = np.where(reach, np.where(singular, SINGULAR, OK), UNREACHABLE)
    q[:, ~reach] = np.nan
    return q, status


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
