"""UR arms as a kinematics family: analytic IK with 8 branches, closed-form J^-1 t."""

from __future__ import annotations

import numpy as np

from solver.families.base import Branch, KinematicsFamily
from solver.families.ur.dh import UrDh
from solver.families.ur.ik import BRANCHES, solve_components
from solver.families.ur.jacobian import joint_speeds_per_unit_twist


class UrFamily(KinematicsFamily):
    """A UR arm of given DH parameters (:mod:`solver.families.ur.ik` names the branches)."""

    name = "ur"

    def __init__(self, dh: UrDh) -> None:
        """Hold the arm's DH parameters."""
        self.dh = dh

    @property
    def dof(self) -> int:
        """Six joints."""
        return 6

    @property
    def branches(self) -> tuple[Branch, ...]:
        """Shoulder left/right x elbow up/down x wrist noflip/flip."""
        return BRANCHES

    def solve(self, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All eight analytic branches (:func:`solver.families.ur.ik.solve_components`)."""
        return solve_components(self.dh, rotation, position)

    def joint_speeds_per_unit_twist(
        self, q: np.ndarray, twist: np.ndarray, tool_point: np.ndarray
    ) -> np.ndarray:
        """Closed-form J^-1 t (:func:`solver.families.ur.jacobian.joint_speeds_per_unit_twist`)."""
        return joint_speeds_per_unit_twist(self.dh, q, twist, tool_point)
