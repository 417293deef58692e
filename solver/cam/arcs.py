"""Circular and helical moves of CL data (``CIRCLE`` + its end ``GOTO``) as points (cam.md 9).

An arc turns about the axis (i, j, k) through the centre, from the tool position to the end
``GOTO``; the distance along the axis and the radius change linearly with the angle (a helix
when the end lies above or below the start, as NX writes helical ramps). The points are spaced
so that no chord is farther than ``tolerance`` from the arc: for a radius r the largest angle
step is 2 acos(1 - tolerance / r) (the sagitta), and at most a quarter turn.

The sense of the turn:

- ``clockwise_about_axis`` given (NX: "i,j,k is the circle or helix axis vector ... assuming a
  clockwise direction", NX CLSF documentation): that sense, plus ``extra_turns`` whole turns
  (NX's ``TIMES,n`` is n turns, the partial one included: n - 1 extra);
- else (no caller of the CL reader: it gives every file a sense, cam.md section 9) the
  shorter way; a half turn (within :data:`HALF_TURN`), where the shorter way is not
  defined, and a full circle turn counter-clockwise about the axis (APT's right-hand rule).

A full circle is an arc whose end equals its start (seen along the axis).

The reader (:mod:`solver.cam.cl_reader`) holds a :class:`Circle` until its end ``GOTO``, and
:func:`arc_cuts` turns it into cutting points, the tool axis blended along them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.cam.cl_records import Record
from solver.core.exceptions import InvalidLineError
from solver.core.task import LINEAR_TOLERANCE

HALF_TURN = 1e-3
"""rad: an arc this close to a half turn has no shorter way."""
RADIUS_MISMATCH = 1e-3
"""Relative: start, end and stated radius may differ by this much (files round to 4 decimals),
or by :data:`RADIUS_MISMATCH_ABSOLUTE`, whichever is larger."""
RADIUS_MISMATCH_ABSOLUTE = 1e-5
"""m."""
MAX_STEP = math.pi / 2
"""rad: the largest angle between two points of an arc."""
MAX_ARC_POINTS = 1_000_000
"""Points one arc may become (more than any route takes): an arc needing more is refused."""


def arc_points(
    start: np.ndarray,
    end: np.ndarray,
    centre: np.ndarray,
    axis: np.ndarray,
    *,
    radius: float | None,
    tolerance: float,
    clockwise_about_axis: bool | None,
    extra_turns: int = 0,
    field: str,
    line: int,
    text: str,
) -> np.ndarray:
    """The points of an arc after its start, its end last.

    Args:
        start: shape (3,), m, the tool position where the arc starts.
        end: shape (3,), m, the arc's end (the ``GOTO`` after ``CIRCLE``).
        centre: shape (3,), m, a point of the axis.
        axis: shape (3,), unit.
        radius: m, the radius the file states, or ``None`` (SolidWorks writes none).
        tolerance: m, the largest chordal distance from the arc.
        clockwise_about_axis: the sense the dialect states, or ``None`` (the shorter way).
        extra_turns: whole turns added in that sense.
        field: the input's name, for the errors.
        line: the CIRCLE's line, for the errors.
        text: the CIRCLE record, for the errors.

    Returns:
        Shape (k, 3), m, k >= 1; the last row is ``end`` exactly.

    Raises:
        InvalidLineError: the start on the axis, or start, end and stated radius that differ.
    """
    offset_start, offset_end = start - centre, end - centre
    height_start, height_end = float(offset_start @ axis), float(offset_end @ axis)
    in_plane_start = offset_start - height_start * axis
    in_plane_end = offset_end - height_end * axis
    r_start, r_end = float(np.linalg.norm(in_plane_start)), float(np.linalg.norm(in_plane_end))
    if r_start <= LINEAR_TOLERANCE:
        raise InvalidLineError(
            field, "the arc starts on its axis: no circle to follow", line=line, text=text
        )
    _check_radii(r_start, r_end, radius, field=field, line=line, text=text)
    e1 = in_plane_start / r_start
    e2 = np.array(
        [
            axis[1] * e1[2] - axis[2] * e1[1],
            axis[2] * e1[0] - axis[0] * e1[2],
            axis[0] * e1[1] - axis[1] * e1[0],
        ]
    )  # axis x e1, written out: np.cross costs more than the arc on 3-vectors
    angle = _sweep(
        math.atan2(float(in_plane_end @ e2), float(in_plane_end @ e1)),
        clockwise_about_axis,
        extra_turns,
    )
    r_most = max(r_start, r_end)
    step = MAX_STEP if tolerance >= r_most else 2.0 * math.acos(1.0 - tolerance / r_most)
    if not abs(angle) < MAX_ARC_POINTS * min(step, MAX_STEP):
        raise InvalidLineError(
            field,
            f"the arc ({abs(angle):.6g} rad, radius {r_most:.6g} m) needs more than "
            f"{MAX_ARC_POINTS} points within {tolerance:.3g} m",
            line=line,
            text=text,
        )
    count = max(1, math.ceil(abs(angle) / min(step, MAX_STEP)))
    t = np.arange(1, count + 1) / count
    phi, r = angle * t, r_start + (r_end - r_start) * t
    h = height_start + (height_end - height_start) * t
    points: np.ndarray = (
        centre + np.outer(h, axis) + np.outer(r * np.cos(phi), e1) + np.outer(r * np.sin(phi), e2)
    )
    points[-1] = end
    return points


def _sweep(end_angle: float, clockwise: bool | None, extra_turns: int) -> float:
    """rad, signed about the axis: the turn from the start to the end angle (-pi, pi]."""
    ccw = end_angle % (2.0 * math.pi)
    full = min(ccw, 2.0 * math.pi - ccw) <= 1e-12
    if clockwise is True:
        turn = -(2.0 * math.pi if full else 2.0 * math.pi - ccw)
        return turn - 2.0 * math.pi * extra_turns
    if clockwise is False:
        turn = 2.0 * math.pi if full else ccw
        return turn + 2.0 * math.pi * extra_turns
    if full or abs(ccw - math.pi) <= HALF_TURN or ccw < math.pi:
        return 2.0 * math.pi if full else ccw
    return ccw - 2.0 * math.pi


def _check_radii(
    r_start: float, r_end: float, stated: float | None, *, field: str, line: int, text: str
) -> None:
    """Raise InvalidLineError unless start, end and stated radius agree."""
    radii = [r_start, r_end] + ([] if stated is None else [stated])
    allowed = max(RADIUS_MISMATCH_ABSOLUTE, RADIUS_MISMATCH * max(radii))
    if max(radii) - min(radii) > allowed:
        stated_text = "" if stated is None else f", the stated radius {stated:.6g} m"
        raise InvalidLineError(
            field,
            f"the arc's start is {r_start:.6g} m from its axis, its end {r_end:.6g} m"
            f"{stated_text}: they must agree within {allowed:.3g} m",
            line=line,
            text=text,
        )


@dataclass(frozen=True)
class Circle:
    """A CIRCLE waiting for its end.

    Attributes:
        record: the CIRCLE record.
        start: shape (3,), m, the tool position where the arc starts.
        start_axis: shape (3,), the tool axis there.
        centre: shape (3,), m.
        axis: shape (3,), the arc's unit axis.
        radius: m, as stated, or None.
        turns: whole turns added (NX's TIMES, n).
    """

    record: Record
    start: np.ndarray
    start_axis: np.ndarray
    centre: np.ndarray
    axis: np.ndarray
    radius: float | None
    turns: int


def arc_cuts(
    circle: Circle,
    end: np.ndarray,
    axis: np.ndarray,
    *,
    tolerance: float,
    clockwise: bool | None,
    field: str,
) -> tuple[np.ndarray, np.ndarray]:
    """The cutting points of an arc before its end, and the tool axis blended along them.

    Args:
        circle: the CIRCLE, with where the arc starts.
        end: shape (3,), m, the arc's end (the ``GOTO`` after ``CIRCLE``).
        axis: shape (3,), the unit tool axis at the end.
        tolerance: m, the largest distance of a chord from the arc.
        clockwise: the sense of the turn about the arc's axis (NX), or None (the shorter way).
        field: the request field the errors name.

    Returns:
        points: shape (k, 3), m, the arc's points after its start and before its end;
        blends: shape (k, 3), the unit tool axis at each, blended linearly from the start's.

    Raises:
        InvalidLineError: an arc :func:`arc_points` refuses, or a tool axis that turns by a
            right angle or more along it (naming the CIRCLE's line).
    """
    record = circle.record
    points = arc_points(
        circle.start,
        end,
        circle.centre,
        circle.axis,
        radius=circle.radius,
        tolerance=tolerance,
        clockwise_about_axis=clockwise,
        extra_turns=circle.turns,
        field=field,
        line=record.line,
        text=record.text,
    )
    if float(circle.start_axis @ axis) <= 0.0:
        raise InvalidLineError(
            field,
            "the tool axis turns by a right angle or more along the arc; the reader "
            "blends it only across smaller turns",
            line=record.line,
            text=record.text,
        )
    t = (np.arange(1, len(points)) / len(points))[:, None]
    blends = (1.0 - t) * circle.start_axis + t * axis
    blends /= np.linalg.norm(blends, axis=1)[:, None]
    return points[:-1], blends
