"""One :class:`CellChecker` per robot and cell content, kept across problems.

Building a checker (the URDF's meshes read and made convex hulls, the compiled side's packs,
the pair weights, the self-collision probe at the zero configuration) took 0.07 to 0.1 s for
the UR5 (the hulls are now kept per arm too, by ``robot_geometry._urdf_geometry``), ten times
the ERK map without a cell (its self pairs' tables, about 0.4 s more, are made at a map's first
use and kept per arm, :mod:`solver.path.cell.kept_tables`): every
request, map and optimisation builds its own :class:`solver.path.problem.PathProblem`, and
each asked for a new checker. A checker is
read-only once built (a placement's geometry is a copy, :meth:`CellChecker.check`), so
problems with the same robot and cell share one, across threads.

The key is the content, not the objects: the pinocchio model as pickled (its joints, frames
and the tool point), the URDF text, the robot's name (its published capsule radii), its base
transform, and the cell as pickled (every shape, the tool, the clearance, the step and the
link radii); and the compiled side the checker was built with (a test or a benchmark that
takes it away gets a checker of coal alone, not a cached one).
"""

from __future__ import annotations

import pickle

from solver.core.robots import Robot
from solver.path.cell import fast
from solver.path.cell.checker import CellChecker
from solver.path.cell.kept import Kept
from solver.path.cell.robot_geometry import content_digest
from solver.path.cell.shapes import Cell

# Checkers kept, the least recently used dropped first (a UR5's holds its link hulls, ~1 MB, and
# its self pairs' tables, 0.65 MB).
MAX_CHECKERS = 8

_checkers: Kept[tuple[object, str], CellChecker] = Kept(MAX_CHECKERS)


def _content(robot: Robot, cell: Cell) -> str:
    """A digest of everything a checker is built from."""
    return content_digest(
        pickle.dumps(robot.model),
        (robot.urdf or "").encode(),
        robot.name.encode(),
        robot.transform_world_to_base.tobytes(),
        pickle.dumps(cell),
    )


def checker_for(robot: Robot, cell: Cell) -> CellChecker:
    """The checker of ``robot`` in ``cell``: a kept one of the same content, or a new one.

    Raises:
        InvalidInputError: as :class:`CellChecker` (a bad cell field or link radii).
    """
    key = (fast.FastCell, _content(robot, cell))
    checker = _checkers.get(key)
    if checker is None:
        checker = CellChecker(robot, cell)  # outside the lock: another thread may build its own
        _checkers.keep(key, checker)
    return checker
