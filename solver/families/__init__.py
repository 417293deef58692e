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
    from solver.robots import Robot

# Modules with a ``robots() -> dict[str, Robot]`` function, in catalogue order.
CATALOGUE_MODULES = ("solver.families.ur.catalogue", "solver.families.opw.catalogue")


@functools.cache
def catalogue() -> dict[str, Robot]:
    """Every catalogue robot by name, built once (families are imported here, on first use)."""
    robots: dict[str, Robot] = {}
    for module in CATALOGUE_MODULES:
        robots.update(importlib.import_module(module).robots())
    return robots
