"""UR lengths read off a chain's forward kinematics: is an arm from a URDF a UR arm?

dtf.md section 8: every UR arm has alpha = [pi/2, 0, 0, pi/2, -pi/2, 0] and six lengths d1, a2,
a3, d4, d5, d6, with no joint offsets. The flange's orientation does not depend on the lengths,
and its position is linear in them: p(q) = sum_k L_k v_k(q), v_k(q) the position of the chain
with length k set to 1 and the others to 0. So the lengths of a chain are the least-squares
solution over sampled configurations; :mod:`solver.families.recognise` keeps them when forward
kinematics then agrees everywhere it is checked.
"""

from __future__ import annotations

import numpy as np

from solver.families.ur.dh import UrDh
from solver.families.ur.ik import forward_kinematics_dh

_ZERO = UrDh(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def fit_ur(q: np.ndarray, rotation: np.ndarray, position: np.ndarray) -> UrDh | None:
    """The UR lengths of a chain from its flange poses at sampled configurations.

    Args:
        q: shape (M, 6), rad, M >= 3 configurations.
        rotation: shape (M, 3, 3), the chain's flange orientations in {B} there.
        position: shape (M, 3), m, its flange positions.

    Returns:
        The least-squares lengths, or None where the orientations are not a UR arm's (the
        caller compares positions).
    """
    zero = forward_kinematics_dh(_ZERO, q)
    if np.abs(zero[:, :3, :3] - rotation).max() > 1e-9:
        return None
    lengths = np.linalg.lstsq(
        np.stack(_length_columns(q), axis=1), position.reshape(-1), rcond=None
    )[0]
    return UrDh(*(float(v) for v in lengths))


def fit_ur_flange(
    q: np.ndarray, rotation: np.ndarray, position: np.ndarray
) -> tuple[UrDh, np.ndarray, np.ndarray] | None:
    """:func:`fit_ur` for a chain whose flange frame is fixed on the DH flange, not it.

    A tool frame turned or moved on the last link (ROS's ``ee_link``, ``wrist_3_link``): the
    chain's flange is the DH flange times a fixed E, so its orientation is R_DH(q) E_R and its
    position p_DH(q) + R_DH(q) E_p, still linear in the lengths and E_p. E_p's part along the
    flange's z is the length d6's (the two are one column): it is taken as none, the DH flange
    on the axis of joint 6 nearest the chain's.

    Args:
        q: shape (M, 6), rad, M >= 3 configurations.
        rotation: shape (M, 3, 3), the chain's flange orientations in {B} there.
        position: shape (M, 3), m, its flange positions.

    Returns:
        The least-squares lengths, E_R (3, 3) and E_p (3,), or None where the orientations are
        not a UR arm's with one fixed E_R (the caller compares positions).
    """
    zero = forward_kinematics_dh(_ZERO, q)
    offset = zero[0, :3, :3].T @ rotation[0]
    if np.abs(zero[:, :3, :3] @ offset - rotation).max() > 1e-9:
        return None
    columns = _length_columns(q) + [zero[:, :3, j].reshape(-1) for j in range(2)]  # E_p x, y
    solved = np.linalg.lstsq(np.stack(columns, axis=1), position.reshape(-1), rcond=None)[0]
    return UrDh(*(float(v) for v in solved[:6])), offset, np.array([solved[6], solved[7], 0.0])


def _length_columns(q: np.ndarray) -> list[np.ndarray]:
    """v_k(q) for the six lengths, each flattened (3 M,): the flange position's columns."""
    columns = []
    for k in range(6):
        unit = np.zeros(6)
        unit[k] = 1.0
        columns.append(forward_kinematics_dh(UrDh(*unit), q)[:, :3, 3].reshape(-1))
    return columns
