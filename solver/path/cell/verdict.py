"""What a cell check answers: the first contact closer than the clearance, or the closest.

The records :class:`solver.path.cell.checker.CellChecker` gives for a joint path at a placement;
an evaluation reports them (:mod:`solver.path.evaluate`, the service's ``Contact``).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Contact:
    """The closest pair at one configuration of a path.

    Attributes:
        waypoint: the waypoint, or the one a sub-step after it follows.
        robot_part: the robot's geometry object (a link's name with ``_0``, a capsule, ``tool``).
        obstacle: the obstacle's index (``fixed`` first, then ``workpiece``), None for a robot
            part (self-collision).
        obstacle_name: its name, its place (``fixed[0]``), or the other robot part's name.
        distance: m, the coal distance (negative: penetration depth as coal gives it).
        obstacle_slot: the obstacle's geometry object among the cell's (a mesh has one per
            separate part, :meth:`solver.path.cell.shapes.Mesh.parts`); None for a robot part.
    """

    waypoint: int
    robot_part: str
    obstacle: int | None
    obstacle_name: str
    distance: float
    obstacle_slot: int | None = None


@dataclass(frozen=True)
class Unchecked:
    """A robot part not checked against a ``fixed`` object: no joint moves it relative to it.

    Attributes:
        robot_part: the robot's geometry object (the base's, or a link only joint 1 turns about
            a fixed halfspace's normal).
        obstacle: the obstacle's index among the ``fixed`` objects.
        obstacle_name: its name, or its place (``fixed[0]``).
        distance: m, coal's distance at the zero configuration, the same at every one
            (negative: they overlap, as a base stands on its table).
    """

    robot_part: str
    obstacle: int
    obstacle_name: str
    distance: float


@dataclass(frozen=True)
class CellVerdict:
    """A joint path against the cell: the first contact closer than the clearance, or the closest.

    Attributes:
        collision: the first configuration (in path order) closer than the clearance; None if
            there is none.
        closest: the closest pair over every checked configuration (None when the check
            stopped at the first collision).
        checks: how many configurations were checked (by coal, in a fast map check).

    The checker's model (the links given capsules, the parts not checked) is the same for
    every verdict: answers take it from the check (:meth:`solver.path.cell.limit.CellLimit.model`).
    """

    collision: Contact | None
    closest: Contact | None
    checks: int
