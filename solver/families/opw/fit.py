"""OPW parameters read off a chain's geometry: is an arm from a URDF an OPW arm?

robots.md section 3. At the maker's zero (q = 0) the paper's angles are theta = -offset, and
the joint axes are the lines of the paper's chain there:

- axis 1 is {B}'s z axis (direction s1 z);
- axes 2 and 3 are parallel to R1 y (R1 = Rz(theta1)), axis 2 through R1 (a1, ., c1), axis 3
  c2 further along R1 Ry(theta2) z;
- axes 4, 5 and 6 meet in the wrist centre C = P3 + R3 (a2, 0, c3) (R3 = R1 Ry(theta2 +
  theta3)); b is C's coordinate along R1 y; axis 4 is R3 z, axis 5 R3 Rz(theta4) y, axis 6
  R5 z with R5 = R3 Rz(theta4) Ry(theta5);
- the flange is c4 along R5 z from C, turned by Rz(theta6).

A chain whose flange frame is not there (a tool frame turned on the last link, or off joint
6's axis, as CAD exports write ``tool0``) is the OPW arm up to a fixed offset E: the OPW flange
is then the point of axis 6 nearest the chain's, with theta6 = 0, and E the chain's flange in
it (:class:`solver.core.spatial.FlangeOffset`).

Each step reads one angle or length; the sign corrections are the signs that make the URDF's
axis directions those of the paper's axes. Where a choice is free (joint 2's sign with
theta1 + pi, joint 5's with theta4 + pi) the angle nearer zero is taken; where it is forced
(joint 4: c3 > 0; joint 6: its axis is the flange's z axis) it is. The fit only proposes:
:mod:`solver.families.recognise` keeps it when forward kinematics agrees at random
configurations.
"""

from __future__ import annotations

import math

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import FlangeOffset
from solver.families.opw.parameters import OpwParameters

# Lines closer than this (m), or directions within this (rad), are taken as meeting or
# parallel; the forward-kinematics check decides in the end.
GEOMETRY_TOLERANCE = 1e-9
_X, _Y, _Z = np.eye(3)


def _rz(angle: float) -> np.ndarray:
    """Rotation about z by ``angle`` (rad)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(angle: float) -> np.ndarray:
    """Rotation about y by ``angle`` (rad)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _least_turn(angle: float) -> tuple[float, int]:
    """A free joint sign: the angle (rad) with sign 1, or the angle + pi with sign -1.

    Whichever is within pi / 2 of zero: the makers' offsets are small, and the branch labels
    then read as theirs.
    """
    if abs(angle) <= math.pi / 2 + GEOMETRY_TOLERANCE:
        return angle, 1
    return math.remainder(angle + math.pi, 2 * math.pi), -1


def _clean(angle: float) -> float:
    """An angle with the rounding of a half or quarter turn (|angle| < 1e-15 rad) made 0."""
    return 0.0 if abs(angle) < 1e-15 else angle


def _meeting_point(points: np.ndarray, directions: np.ndarray) -> np.ndarray | None:
    """The point nearest to every line (least squares), if all pass within the tolerance."""
    projectors = np.eye(3) - directions[:, :, None] * directions[:, None, :]  # (k, 3, 3)
    point = np.linalg.lstsq(
        projectors.sum(axis=0), np.einsum("kij,kj->i", projectors, points), rcond=None
    )[0]
    distances = np.linalg.norm(np.einsum("kij,kj->ki", projectors, point - points), axis=-1)
    return point if np.all(distances < GEOMETRY_TOLERANCE) else None


def fit_opw(
    axes: np.ndarray,
    origins: np.ndarray,
    flange_rotation: np.ndarray,
    flange_position: np.ndarray,
) -> tuple[OpwParameters, FlangeOffset | None] | None:
    """The OPW parameters of a six-joint revolute chain at q = 0, or None if it is not one.

    Args:
        axes: shape (6, 3), unit joint axes in {B} at q = 0.
        origins: shape (6, 3), m, a point of each joint axis in {B} at q = 0.
        flange_rotation: shape (3, 3), R_B_F at q = 0.
        flange_position: shape (3,), m in {B} at q = 0.

    Returns:
        Parameters whose geometry is the chain's line by line, and where the chain's flange
        sits on the OPW flange (None: it is the OPW flange); forward kinematics must still be
        compared (the caller does), since lines do not fix every sign.
    """
    tol = GEOMETRY_TOLERANCE
    u = np.asarray(axes, dtype=float)
    p = np.asarray(origins, dtype=float)
    if abs(abs(u[0, 2]) - 1.0) > tol or np.linalg.norm(np.cross(u[0], p[0])) > tol:
        return None  # axis 1 is not {B}'s z axis
    signs = [int(np.sign(u[0, 2]))]
    if abs(u[1, 2]) > tol:
        return None
    theta1, sign2 = _least_turn(math.atan2(-u[1, 0], u[1, 1]))  # R1 y = s2 u2
    signs.append(sign2)
    r1 = _rz(theta1)
    local = p @ r1  # points in R1's axes
    direction = u @ r1
    if abs(abs(direction[2, 1]) - 1.0) > tol:
        return None  # axis 3 not parallel to axis 2
    signs.append(int(np.sign(direction[2, 1])))
    a1, c1 = float(local[1, 0]), float(local[1, 2])
    reach = local[2, [0, 2]] - (a1, c1)
    c2 = float(np.hypot(*reach))
    theta2 = math.atan2(reach[0], reach[1])
    centre = _meeting_point(local[3:], direction[3:])
    if centre is None or c2 <= tol or abs(direction[3, 1]) > tol:
        return None
    b = float(centre[1])
    theta23 = math.atan2(direction[3, 0], direction[3, 2])  # R3 z = u4 (sign +1)
    a2, c3 = _ry(-theta23)[[0, 2]][:, [0, 2]] @ (centre[[0, 2]] - local[2, [0, 2]])
    sign4 = 1
    if c3 < 0.0:  # the other sign of joint 4 turns the forearm by pi
        theta23, a2, c3, sign4 = theta23 + math.pi, -a2, -c3, -1
    signs.append(sign4)
    r3 = _ry(theta23)
    wrist = direction[4:] @ r3  # axes 5 and 6 in R3's axes
    if abs(wrist[0, 2]) > tol:
        return None
    theta4, sign5 = _least_turn(math.atan2(-wrist[0, 0], wrist[0, 1]))  # R4 y = s5 u5
    signs.append(sign5)
    r4 = r3 @ _rz(theta4)
    sixth = wrist[1] @ _rz(theta4)  # axis 6 in R4's axes
    if abs(sixth[1]) > tol:
        return None
    flange_local = r1.T @ flange_rotation  # the flange's axes in R1's
    # R5 z is the flange's z axis: joint 6's sign is the one that makes its axis that.
    sign6 = 1 if float(direction[5] @ flange_local[:, 2]) >= 0.0 else -1
    theta5 = math.atan2(sign6 * sixth[0], sign6 * sixth[2])  # R5 z = s6 u6
    signs.append(sign6)
    r5 = r4 @ _ry(theta5)
    lever = r1.T @ flange_position - centre
    c4 = float(lever @ r5[:, 2])
    turn = r5.T @ flange_local
    offset = None
    if np.linalg.norm(lever - c4 * r5[:, 2]) > tol or np.linalg.norm(turn[2] - _Z) > tol:
        # The chain's flange in the OPW flange (theta6 = 0: its axes are R5's): E
        offset = FlangeOffset.read(turn, r5.T @ (lever - c4 * r5[:, 2]))
        turn = np.eye(3)
    theta6 = math.atan2(turn[1, 0], turn[0, 0])
    # Paper angle = s q - offset; at q = 0 it is theta, so offset = -theta (wrapped).
    thetas = (theta1, theta2, theta23 - theta2, theta4, theta5, theta6)
    offsets = tuple(_clean(-math.remainder(t, 2 * math.pi)) for t in thetas)
    try:
        parameters = OpwParameters(
            a1, float(a2), b, c1, c2, float(c3), c4, offsets=offsets, sign_corrections=tuple(signs)
        )
    except InvalidInputError:  # a length beyond the parameters' range: not an arm we model
        return None
    return parameters, offset
