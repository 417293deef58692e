"""OPW arms as a kinematics family: closed-form IK with 8 branches, decoupled J^-1 t."""

from __future__ import annotations

from solver.families.base import ClosedFormFamily
from solver.families.kernels import OPW_KERNEL
from solver.families.opw.ik import BRANCHES, solve_components
from solver.families.opw.jacobian import joint_speeds_per_unit_twist
from solver.families.opw.kernel import kernel_parameters


class OpwFamily(ClosedFormFamily):
    """An OPW arm; ``parameters`` is its :class:`solver.families.opw.parameters.OpwParameters`."""

    name = "opw"
    branch_labels = BRANCHES
    solve_function = staticmethod(solve_components)
    speeds_function = staticmethod(joint_speeds_per_unit_twist)
    kernel_code = OPW_KERNEL
    kernel_parameters_function = staticmethod(kernel_parameters)
