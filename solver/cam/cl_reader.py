"""The state machine that reads CL records into cutting points (solver.cam.cl_data)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from solver.cam.arcs import Circle, arc_cuts
from solver.cam.cam_path import Units
from solver.cam.cl_records import REFUSED, Record, kind_of
from solver.cam.cl_systems import PART, CoordinateSystem, csys, msys
from solver.cam.cl_units import feed_of, stated_units
from solver.cam.read_report import SkippedRecord
from solver.cam.reading import checked_position, is_number, near_unit_vector, parse_numbers
from solver.core.exceptions import InvalidInputError, InvalidLineError, cut
from solver.core.spatial import MAX_COORDINATE
from solver.core.task import ANGULAR_TOLERANCE, LINEAR_TOLERANCE

TOOL_CHANGE = frozenset({"LOADTL", "LOAD"})
"""Words of a tool change: a new pass."""


@dataclass
class ClReader:
    """The state of the program as it is read, and the cutting moves collected so far."""

    field: str
    units: Units
    scale: float
    tolerance: float
    clockwise: bool
    max_waypoints: int | None
    system: CoordinateSystem = PART
    local_axis: np.ndarray = dataclasses.field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    position: np.ndarray | None = None
    axis: np.ndarray | None = None
    feed: float = math.nan
    rapid: bool = False
    pass_id: int = 0
    operation: str | None = None
    circle: Circle | None = None
    finished: Record | None = None
    pass_points: int = 0
    singles: int = 0
    correction: float = 0.0
    repeated: int = 0
    arcs: int = 0
    skipped: dict[str, SkippedRecord] = dataclasses.field(default_factory=dict)
    positions: list[np.ndarray] = dataclasses.field(default_factory=list)
    axes: list[np.ndarray] = dataclasses.field(default_factory=list)
    pass_ids: list[int] = dataclasses.field(default_factory=list)
    lines: list[int] = dataclasses.field(default_factory=list)
    feeds: list[float] = dataclasses.field(default_factory=list)
    operations: list[str | None] = dataclasses.field(default_factory=list)

    def error(self, message: str, record: Record) -> InvalidLineError:
        """An error naming the record's line and echoing it."""
        return InvalidLineError(self.field, message, line=record.line, text=record.text)

    def read(self, record: Record) -> None:
        """Take one record into the state."""
        word = record.word
        if word in ("GOTO", "CIRCLE", "FROM") and self.finished is not None:
            raise self.error(
                f"{word} after FINI (line {self.finished.line}), the end of the program", record
            )
        if word == "FINI":
            self.finished = record
        kind = kind_of(word)
        cycle_off = word == "CYCLE" and "".join(record.rest.split()).upper() == "/OFF"
        if kind in ("skipped", "unknown") or cycle_off:  # CYCLE / OFF as CYCLE/OFF
            self.skip(record, recognised=kind != "unknown")
            return
        if kind == "refused":
            raise self.error(f"{word} ({REFUSED[word]}) is not applied by the reader", record)
        if word in TOOL_CHANGE or word in ("TOOL PATH", "END-OF-PATH"):
            self.tool_change_or_operation(record)
            return
        handler = getattr(self, f"read_{word.lower()}")
        handler(record)

    def skip(self, record: Record, *, recognised: bool) -> None:
        """Count a record that carries no geometry or feed."""
        seen = self.skipped.get(record.word)
        self.skipped[record.word] = (
            SkippedRecord(cut(record.word), 1, record.line, recognised)
            if seen is None
            else dataclasses.replace(seen, count=seen.count + 1)
        )

    def end_pass(self) -> None:
        """Points read from now on start a new pass."""
        self.pass_id += 1

    def in_pass(self) -> bool:
        """Whether the last cutting point belongs to the pass being read."""
        return bool(self.pass_ids) and self.pass_ids[-1] == self.pass_id

    def numbers(self, args: list[str], record: Record) -> np.ndarray:
        """The arguments as finite numbers."""
        return parse_numbers(args, field=self.field, line=record.line, text=record.text)

    def tool_change_or_operation(self, record: Record) -> None:
        """``LOADTL``, ``LOAD/TOOL``, ``TOOL PATH/<name>``, ``END-OF-PATH``: a new pass."""
        args = record.arguments(self.field) if record.word != "LOADTL" else []
        if record.word == "LOAD" and (not args or args[0].upper() != "TOOL"):
            self.skip(record, recognised=False)
            return
        if self.circle is not None:
            raise self.error(f"{record.word} comes between a CIRCLE and its end", record)
        if record.word == "TOOL PATH":
            self.operation = args[0] if args and args[0] else None
        self.end_pass()

    def read_partno(self, record: Record) -> None:
        """``PARTNO`` text: the name of the operations that follow."""
        self.operation = record.rest.lstrip("/").strip() or self.operation

    read_pprint = read_partno

    def read_units(self, record: Record) -> None:
        """``UNITS``/``UNIT``: read before any move (cl_units); it may not change."""
        units = stated_units(record, field=self.field)
        if units != self.units:
            raise self.error(f"the units change from {self.units}", record)

    read_unit = read_units

    def read_multax(self, record: Record) -> None:
        """``MULTAX``, ``MULTAX/ON`` or ``MULTAX/OFF``: GOTOs of 3 or 6 numbers either way."""
        args = record.arguments(self.field)
        if args and (len(args) != 1 or args[0].upper() not in ("ON", "OFF")):
            raise self.error("MULTAX takes ON or OFF", record)

    def read_tlaxis(self, record: Record) -> None:
        """``TLAXIS/i, j, k``: the tool axis of later 3-number GOTOs."""
        args = record.arguments(self.field)
        if len(args) != 3:
            raise self.error(f"TLAXIS needs i, j, k; got {len(args)} arguments", record)
        self.local_axis = self.unit_axis(self.numbers(args, record), record)

    def read_fedrat(self, record: Record) -> None:
        """``FEDRAT``: the feed of the moves that follow, in m/s."""
        self.feed = feed_of(record, units=self.units, field=self.field)

    def read_rapid(self, record: Record) -> None:
        """``RAPID`` (or ``RAPID/``): the next GOTO is a rapid move."""
        if record.arguments(self.field):
            raise self.error("RAPID takes no arguments", record)
        if self.circle is not None:
            raise self.error("RAPID comes between a CIRCLE and its end", record)
        self.rapid = True

    def read_trntyp(self, record: Record) -> None:
        """``TRNTYP/WORLD, 0, 0, 0``: the CSYS that follows is given in the world frame."""
        args = record.arguments(self.field)
        if not args or args[0].upper() != "WORLD" or np.any(self.numbers(args[1:], record)):
            raise self.error(
                "TRNTYP other than WORLD, 0, 0, 0 is a transformation the reader does not apply",
                record,
            )

    def read_msys(self, record: Record) -> None:
        """``MSYS``: NX's coordinate system."""
        values = self.numbers(record.arguments(self.field), record)
        self.change_system(
            msys(values, field=self.field, line=record.line, text=record.text), record
        )

    def read_csys(self, record: Record) -> None:
        """``CSYS``: SolidWorks' coordinate system."""
        values = self.numbers(record.arguments(self.field), record)
        self.change_system(
            csys(values, field=self.field, line=record.line, text=record.text), record
        )

    def change_system(self, system: CoordinateSystem, record: Record) -> None:
        """A new system, followed outside a pass (cam.md section 9)."""
        if system.same_as(self.system):
            return
        if self.circle is not None:
            raise self.error(
                f"the coordinate system changes between a CIRCLE (line {self.circle.record.line}) "
                "and the GOTO of its end; the reader follows a change only between passes",
                record,
            )
        if self.in_pass():
            raise self.error(
                f"the coordinate system changes between two cutting moves (after line "
                f"{self.lines[-1]}); the reader follows a change only between passes",
                record,
            )
        self.system = PART if system.same_as(PART) else system

    def to_part(self, values: np.ndarray, record: Record) -> np.ndarray:
        """A point written in the current system, in the part frame (m), checked."""
        point = values * self.scale
        if self.system is not PART:
            point = self.system.origin * self.scale + self.system.rotation @ point
        if max(abs(point[0]), abs(point[1]), abs(point[2])) > MAX_COORDINATE:
            checked_position(point, field=self.field, line=record.line, text=record.text)
        return point

    def read_from(self, record: Record) -> None:
        """``FROM/x, y, z[, i, j, k]``: where the tool starts; free text is skipped."""
        args = record.arguments(self.field) if record.rest.startswith("/") else []
        if len(args) not in (3, 6) or not all(is_number(a) for a in args):
            self.skip(record, recognised=True)
            return
        if self.circle is not None:
            raise self.error("FROM comes between a CIRCLE and its end", record)
        values = self.numbers(args, record)
        if len(args) == 6:
            self.local_axis = self.unit_axis(values[3:], record)
        self.position = self.to_part(values[:3], record)
        self.axis = self.system.rotation @ self.local_axis
        self.end_pass()

    def read_circle(self, record: Record) -> None:
        """``CIRCLE``: an arc whose end the next GOTO gives."""
        args = record.arguments(self.field)
        turns = 0
        upper = [a.upper() for a in args]
        if "TIMES" in upper:
            at = upper.index("TIMES")
            count = self.numbers(args[at + 1 :], record)
            if not self.clockwise or count.shape != (1,) or count[0] < 1 or count[0] % 1:
                raise self.error("TIMES, n (n >= 1 whole turns) is read in NX files only", record)
            turns, args = int(count[0]) - 1, args[:at]
        if not 6 <= len(args) <= 11:
            raise self.error(f"CIRCLE needs xc, yc, zc, i, j, k[, r, ...]; got {len(args)}", record)
        if self.position is None or self.axis is None or self.circle is not None:
            raise self.error("CIRCLE needs a tool position (a GOTO) before it", record)
        if self.rapid:
            raise self.error(
                "CIRCLE after RAPID: the reader does not interpolate rapid arcs", record
            )
        values = self.numbers(args, record)
        self.circle = Circle(
            record=record,
            start=self.position,
            start_axis=self.axis,
            centre=self.to_part(values[:3], record),
            axis=self.system.rotation @ self.unit_axis(values[3:6], record),
            radius=None if len(values) < 7 else float(values[6]) * self.scale,
            turns=turns,
        )
        self.arcs += 1

    def read_goto(self, record: Record) -> None:
        """``GOTO/x, y, z[, i, j, k]``: a cutting move (an arc's end), or a rapid's target."""
        args = record.arguments(self.field)
        if len(args) not in (3, 6):
            raise self.error(
                f"GOTO needs x, y, z or x, y, z, i, j, k; got {len(args)} numbers", record
            )
        values = self.numbers(args, record)
        if len(args) == 6:
            self.local_axis = self.unit_axis(values[3:], record)
        position = self.to_part(values[:3], record)
        axis = self.system.rotation @ self.local_axis
        if self.rapid:  # the rapid's target belongs to no pass; the next cut starts one
            self.rapid, self.position, self.axis = False, position, axis
            self.end_pass()
            return
        if self.circle is not None:
            self.read_arc_end(self.circle, position, axis)
            self.circle = None
        self.cut(position, axis, record.line)

    def read_arc_end(self, circle: Circle, end: np.ndarray, axis: np.ndarray) -> None:
        """The points of an arc before its end, as cuts; the tool axis blended along it."""
        points, blends = arc_cuts(
            circle, end, axis, tolerance=self.tolerance, clockwise=self.clockwise, field=self.field
        )
        for point, blend in zip(points, blends, strict=True):
            self.cut(point, blend, circle.record.line)

    def cut(self, position: np.ndarray, axis: np.ndarray, line: int) -> None:
        """A cutting point: dropped and counted where it repeats the tool's position."""
        if self.in_pass():
            moved, turned = position - self.positions[-1], axis - self.axes[-1]
            if moved @ moved < LINEAR_TOLERANCE**2 and turned @ turned < ANGULAR_TOLERANCE**2:
                self.repeated += 1
                return
        starts = not self.in_pass()
        if starts:  # the pass before, if of one point, is dropped (cam.md 9: counts are one rule)
            self.singles += self.pass_points == 1
            self.pass_points = 0
        kept = len(self.positions) + 1 - self.singles - starts  # this pass's first point may go
        if self.max_waypoints is not None and kept > self.max_waypoints:
            raise InvalidInputError(
                "path",
                f"more than {self.max_waypoints} waypoints by line {line}; the limit is "
                f"{self.max_waypoints}",
            )
        self.pass_points += 1
        self.position, self.axis = position, axis
        self.positions.append(position)
        self.axes.append(axis)
        self.pass_ids.append(self.pass_id)
        self.lines.append(line)
        self.feeds.append(self.feed)
        self.operations.append(self.operation)

    def unit_axis(self, values: np.ndarray, record: Record) -> np.ndarray:
        """A tool axis normalised (cam.md section 6), its correction kept."""
        axis, correction = near_unit_vector(
            values, name="tool axis", field=self.field, line=record.line, text=record.text
        )
        self.correction = max(self.correction, correction)
        return axis
