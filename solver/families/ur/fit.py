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
    columns = []
    for k in range(6):
        unit = np.zeros(6)
        unit[k] = 1.0
        columns.append(forward_kinematics_dh(UrDh(*unit), q)[:, :3, 3].reshape(-1))
    lengths = np.linalg.lstsq(np.stack(columns, axis=1), position.reshape(-1), rcond=None)[0]
    return UrDh(*(float(v) for v in lengths))
