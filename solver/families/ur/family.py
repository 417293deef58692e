"""UR arms as a kinematics family: analytic IK with 8 branches, closed-form J^-1 t."""

from __future__ import annotations

from solver.families.base import ClosedFormFamily
from solver.families.kernels import UR_KERNEL
from solver.families.ur.ik import BRANCHES, solve_components
from solver.families.ur.jacobian import joint_speeds_per_unit_twist
from solver.families.ur.kernel import kernel_parameters


class UrFamily(ClosedFormFamily):
    """A UR arm; ``parameters`` is its :class:`solver.families.ur.dh.UrDh`."""

    name = "ur"
    branch_labels = BRANCHES
    solve_function = staticmethod(solve_components)
    speeds_function = staticmethod(joint_speeds_per_unit_twist)
    kernel_code = UR_KERNEL
    kernel_parameters_function = staticmethod(kernel_parameters)
