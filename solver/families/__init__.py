"""Robot kinematics families behind one seam (:mod:`solver.families.base`), and their registry.

Each family lives in its own folder with its parameters, IK, J^-1 t and catalogue entries. This
registry is the one place that names them: a new family adds its catalogue module here, and no
other solver module imports a family (the qpsolvers pattern of a backend registry).
"""

from __future__ import annotations

import functools
import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pinocchio as pin

    from solver.families.base import KinematicsFamily
    from solver.robots import Robot

# Modules with a ``robots() -> dict[str, Robot]`` function, in catalogue order.
CATALOGUE_MODULES = (
    "solver.families.ur.catalogue",
    "solver.families.opw.catalogue",
    "solver.families.numeric.catalogue",
)
# Numeric IK solves six-dimensional poses: it needs at least six joints (robots.md section 4).
NUMERIC_MIN_DOF = 6


@functools.cache
def catalogue() -> dict[str, Robot]:
    """Every catalogue robot by name, built once (families are imported here, on first use)."""
    robots: dict[str, Robot] = {}
    for module in CATALOGUE_MODULES:
        robots.update(importlib.import_module(module).robots())
    return robots


def default_family(
    model: pin.Model, *, base_frame: str, tool_frame: str
) -> KinematicsFamily | None:
    """The family of an arm that has no analytic one: numeric IK (robots.md section 4).

    ``None`` when the model has fewer than six joints or is not one serial chain to the tool.
    """
    from solver.exceptions import RobotModelError
    from solver.families.numeric.family import NumericFamily

    if model.nv < NUMERIC_MIN_DOF:
        return None
    try:
        return NumericFamily(model, base_frame=base_frame, tool_frame=tool_frame)
    except RobotModelError:
        return None
