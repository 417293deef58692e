"""OPW arms as a kinematics family: closed-form IK with 8 branches, decoupled J^-1 t."""

from __future__ import annotations

import numpy as np

from solver.families.base import Branch, KinematicsFamily
from solver.families.opw.ik import BRANCHES, solve_components
from solver.families.opw.jacobian import joint_speeds_per_unit_twist
from solver.families.opw.parameters import OpwParameters


class OpwFamily(KinematicsFamily):
    """An OPW arm of given parameters (:mod:`solver.families.opw.ik` names the branches)."""

    name = "opw"

    def __init__(self, parameters: OpwParameters) -> None:
        """Hold the arm's geometry."""
        self.parameters = parameters

    @property
    def dof(self) -> int:
        """Six joints."""
        return 6

    @property
    def branches(self) -> tuple[Branch, ...]:
        """Shoulder front/back x elbow up/down x wrist noflip/flip."""
        return BRANCHES

    def solve(self, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All eight branches (:func:`solver.families.opw.ik.solve_components`)."""
        return solve_components(self.parameters, rotation, position)

    def joint_speeds_per_unit_twist(
        self, q: np.ndarray, twist: np.ndarray, tool_point: np.ndarray
    ) -> np.ndarray:
        """Decoupled closed-form J^-1 t (:mod:`solver.families.opw.jacobian`)."""
        return joint_speeds_per_unit_twist(self.parameters, q, twist, tool_point)
