"""Exceptions raised by the solver for invalid input.

Every exception carries the data that locates the problem (``field``, and ``waypoint`` where a
waypoint is at fault), so the service can name them in its ``422`` answer. An expected failure
(an unreachable placement, a singular configuration along a path) is never an exception: it comes
back as data in the result.
"""

from __future__ import annotations

from collections.abc import Sequence


def cut(text: str, *, limit: int = 100) -> str:
    """``text`` as an answer echoes it: cut to ``limit`` characters (a request may send 2 MB)."""
    return text if len(text) <= limit else text[:limit] + "..."


def quoted(text: str, *, limit: int = 100) -> str:
    """``text`` in quotes for a message, cut to ``limit`` characters (a request may send 2 MB)."""
    return repr(cut(text, limit=limit))


MAX_LISTED_NAMES = 20
"""Names listed in one message at most (a URDF may hold thousands of links)."""


def quoted_names(names: Sequence[str]) -> str:
    """Names for a message: each quoted and cut to 100 characters, at most 20 of them."""
    listed = ", ".join(quoted(name) for name in names[:MAX_LISTED_NAMES])
    more = len(names) - MAX_LISTED_NAMES
    return listed + (f" and {more} more" if more > 0 else "")


class SolverError(Exception):
    """Base class of every input error the solver raises.

    Attributes:
        field: dotted name of the offending input, as a caller would spell it
            (``"path.waypoints"``, ``"robot.joint_velocity_limits"``, ``"q"``).
        waypoint: index of the offending waypoint, or ``None``.
        message: what is wrong, naming the offending value.
    """

    def __init__(self, field: str, message: str, *, waypoint: int | None = None) -> None:
        """Store where the error is and what it is."""
        self.field = field
        self.waypoint = waypoint
        self.message = message
        where = field if waypoint is None else f"{field}[{waypoint}]"
        super().__init__(f"{where}: {message}")


class InvalidInputError(SolverError):
    """A value has the wrong shape, is not finite, or is out of its allowed range."""


class RepeatedWaypointError(SolverError):
    """Two consecutive waypoints are the same pose: the segment between them has no direction."""

    def __init__(
        self, index: int, *, field: str = "path.waypoints", free_spin: bool = False
    ) -> None:
        """Name the second waypoint of the repeated pair.

        ``free_spin``: the pair differs by a turn about the tool axis alone, which free spin
        leaves to the spin (the same position and tool axis).
        """
        same = (
            "same position and tool axis: in free spin a turn about the tool axis alone is the "
            "spin's, no motion"
            if free_spin
            else "same position and orientation"
        )
        super().__init__(
            field,
            f"waypoint {index} repeats waypoint {index - 1} ({same}): a segment needs a "
            "displacement or a rotation",
            waypoint=index,
        )


class UnknownRobotError(SolverError):
    """A robot name that is not in the catalogue."""

    def __init__(self, name: str, known: list[str]) -> None:
        """Name the robot asked for and the ones that exist."""
        super().__init__(
            "robot.model", f"unknown robot {quoted(name)}; known robots: {', '.join(known)}"
        )
        self.name = name


class RobotModelError(SolverError):
    """A URDF that cannot be parsed, or whose frames or chain do not fit the request."""


class NoAnalyticIkError(SolverError):
    """Path evaluation needs an arm with a kinematics family (a UR or OPW arm)."""


class InvalidLineError(InvalidInputError):
    """A line of a text file (CL data, a CSV path) that cannot be read as it stands.

    Attributes:
        line: the line number, from 1 (where the record starts, for a continued record).
        text: the record or line as read (the message echoes at most 100 characters of it), or
            ``None`` when it is not at hand.
    """

    def __init__(
        self,
        field: str,
        message: str,
        *,
        line: int,
        text: str | None = None,
        waypoint: int | None = None,
    ) -> None:
        """Name the line and echo its text."""
        echo = "" if text is None else f" (in {quoted(text)})"
        super().__init__(field, f"line {line}: {message}{echo}", waypoint=waypoint)
        self.line = line
        self.text = text
