"""A path read from a CAM file: waypoints, passes, feeds, and the line each waypoint came from.

cam.md section 5: the waypoints are the passes' points in order; a pass is a run of cutting
moves between two rapids, and no segment joins two passes. Each pass starts its parallel
transport afresh (section 1), so the poses of a tool-axis path are built pass by pass.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from solver.cam.read_report import ReadReport
from solver.core.exceptions import InvalidInputError, InvalidLineError
from solver.core.spatial import rotation_about_z
from solver.core.task import ANGULAR_TOLERANCE, LINEAR_TOLERANCE
from solver.core.tool_axis import poses_from_tool_axes

Units = Literal["mm", "inches", "m"]
METRES_PER_UNIT: dict[str, float] = {"mm": 1e-3, "inches": 0.0254, "m": 1.0}
FEED_RANGE = (1e-6, 100.0)
"""m/s, the feeds taken: a program's FEDRAT and a request's ``feed`` (0.06 mm/min to 6 km/min).
A FEDRAT of 1e-310 mm/min was taken, the feed check's margin (mu_path over it) then infinite:
a 500 where the answer was written."""


@dataclass(frozen=True)
class CamPath:
    """Waypoints of a CAM program in the workpiece frame {O}, split into passes.

    Exactly one of ``axes`` (CL data, CSV with i, j, k) and ``rotations`` (CSV with a
    quaternion) is given.

    Attributes:
        positions: shape (N, 3), m, tool tips in {O}.
        axes: shape (N, 3), unit tool axes in {O} as CAM writes them (tip towards holder), or
            ``None``.
        rotations: shape (N, 3, 3), tool orientations R_O_i, or ``None``.
        passes: each pass's waypoints as a range ``(start, stop)`` into the N waypoints, in
            order, covering them all; every pass has at least 2 waypoints.
        lines: shape (N,), int, the line (from 1) each waypoint was read from.
        feeds: shape (N,), m/s, the programmed feed of each waypoint's segment as the task
            requirements pair them (waypoint i: the move i -> i+1; a pass's last waypoint: the
            move into it), NaN where no feed was programmed. The move into a pass's first
            waypoint starts at a rapid's target, outside every pass, so its feed is not used.
        units: the length unit the file was written in.
        axis_correction: the largest | |v| - 1 | of the axes or quaternions normalised
            (cam.md section 6).
        pass_operations: the operation each pass belongs to (its name in the file), one per
            pass, ``None`` where the file names none; empty for a reader without operations.
        one_point_passes: passes of one point dropped (cam.md section 9).
        report: what a CL reader skipped, counted and inferred; ``None`` for a CSV.
    """

    positions: np.ndarray
    axes: np.ndarray | None
    rotations: np.ndarray | None
    passes: tuple[tuple[int, int], ...]
    lines: np.ndarray
    feeds: np.ndarray
    units: Units
    axis_correction: float
    pass_operations: tuple[str | None, ...] = ()
    one_point_passes: int = 0
    report: ReadReport | None = None

    @property
    def n_waypoints(self) -> int:
        """N."""
        return len(self.positions)

    @property
    def feed(self) -> float | None:
        """m/s, the program's feed: the highest feed programmed for a cutting move, or None.

        When FEDRAT changes within the program, the highest feed is the one the path must
        sustain to run as programmed everywhere: mu_path >= feed is sufficient, and the check
        per waypoint (V_max_i >= feeds_i) is the exact one.
        """
        return _nan_max(self.feeds)

    @property
    def pass_feeds(self) -> tuple[float | None, ...]:
        """m/s, the highest programmed feed within each pass, or None where it has none."""
        return tuple(_nan_max(self.feeds[start:stop]) for start, stop in self.passes)

    @property
    def pass_starts(self) -> np.ndarray:
        """Where passes start: shape (N,), bool, True at the first waypoint of every pass."""
        starts = np.zeros(self.n_waypoints, dtype=bool)
        starts[[start for start, _ in self.passes]] = True
        return starts

    @property
    def default_spin_mode(self) -> Literal["fixed", "free"]:
        """cam.md section 2: ``free`` when CAM gave tool axes only, ``fixed`` for full poses."""
        return "free" if self.axes is not None else "fixed"

    def waypoints_in_workpiece(self, *, spin: float = 0.0, field: str = "path") -> np.ndarray:
        """T_O_i of every waypoint, shape (N, 4, 4), m; tool-axis paths pass by pass.

        Args:
            spin: rad, a constant turn of every waypoint about its tool z (cam.md section 3).
            field: the input's name, for the error.

        Raises:
            InvalidLineError: the tool axis turns by a right angle towards the reference x axis
                within a pass (the parallel transport is undefined there), naming its line.
        """
        if self.rotations is not None:
            poses = np.broadcast_to(np.eye(4), (self.n_waypoints, 4, 4)).copy()
            poses[:, :3, :3] = self.rotations @ rotation_about_z(spin)
            poses[:, :3, 3] = self.positions
            return poses
        if self.axes is None:
            raise InvalidInputError(field, "a CAM path needs tool axes or rotations")
        parts = []
        for start, stop in self.passes:
            try:
                poses, _ = poses_from_tool_axes(
                    self.positions[start:stop], self.axes[start:stop], spin=spin
                )
            except InvalidInputError as error:
                if error.waypoint is None:
                    raise
                index = start + error.waypoint
                raise InvalidLineError(
                    field, error.message, line=int(self.lines[index]), waypoint=index
                ) from error
            parts.append(poses)
        return np.concatenate(parts)


def _nan_max(values: np.ndarray) -> float | None:
    """The largest finite value, or None where there is none."""
    finite = values[np.isfinite(values)]
    return float(finite.max()) if finite.size else None


def assemble_cam_path(
    *,
    positions: Sequence[np.ndarray],
    directions: Sequence[np.ndarray],
    pass_ids: Sequence[int],
    lines: Sequence[int],
    arrival_feeds: Sequence[float],
    units: Units,
    axis_correction: float,
    field: str,
    operations: Sequence[str | None] | None = None,
    drop_one_point_passes: bool = False,
) -> CamPath:
    """A CamPath from the cutting moves a reader collected, checked.

    Args:
        positions: each shape (3,), m.
        directions: each shape (3,) (a unit tool axis) or (3, 3) (a rotation), all alike.
        pass_ids: the pass of each point, non-decreasing.
        lines: the line of each point, from 1.
        arrival_feeds: m/s, the feed in force when each point was read (NaN for none).
        units: the length unit of the file.
        axis_correction: the largest correction made to a unit vector's length.
        field: the input's name, for the errors.
        operations: the operation in force at each point, or ``None``.
        drop_one_point_passes: drop a pass of one point and count it (CL data, cam.md
            section 9) instead of refusing it.

    Raises:
        InvalidInputError: no cutting move at all.
        InvalidLineError: a pass of one point (unless dropped); a point that repeats the one
            before it in its pass (same position and direction), naming its line.
    """
    passes = _passes(pass_ids)
    dropped = 0
    if drop_one_point_passes:
        keep = [i for start, stop in passes if stop - start >= 2 for i in range(start, stop)]
        dropped = sum(1 for start, stop in passes if stop - start < 2)
        positions, directions = [positions[i] for i in keep], [directions[i] for i in keep]
        pass_ids, lines = [pass_ids[i] for i in keep], [lines[i] for i in keep]
        arrival_feeds = [arrival_feeds[i] for i in keep]
        operations = None if operations is None else [operations[i] for i in keep]
        passes = _passes(pass_ids)
    if not positions:
        raise InvalidInputError(
            field, "no cutting move: a path needs at least one pass of 2 or more points"
        )
    for number, (start, stop) in enumerate(passes):
        if stop - start < 2:
            raise InvalidLineError(
                field,
                f"pass {number + 1} has one point: a pass (the cutting moves between two "
                "rapids) needs at least 2",
                line=int(lines[start]),
                waypoint=start,
            )
    position = np.array(positions, dtype=float)
    direction = np.array(directions, dtype=float)
    _check_repeats(position, direction, passes, lines, field=field)
    arrival = np.asarray(arrival_feeds, dtype=float)
    feeds = np.empty(len(arrival))
    for start, stop in passes:
        feeds[start : stop - 1] = arrival[start + 1 : stop]
        feeds[stop - 1] = arrival[stop - 1]
    return CamPath(
        positions=position,
        axes=direction if direction.ndim == 2 else None,
        rotations=direction if direction.ndim == 3 else None,
        passes=passes,
        lines=np.asarray(lines, dtype=int),
        feeds=feeds,
        units=units,
        axis_correction=axis_correction,
        pass_operations=() if operations is None else tuple(operations[a] for a, _ in passes),
        one_point_passes=dropped,
    )


def _passes(pass_ids: Sequence[int]) -> tuple[tuple[int, int], ...]:
    """The index ranges of the runs of equal pass ids."""
    if not pass_ids:
        return ()
    ids = np.asarray(pass_ids)
    cuts = np.flatnonzero(np.diff(ids)) + 1
    bounds = np.concatenate([[0], cuts, [len(ids)]])
    return tuple((int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:], strict=True))


def _check_repeats(
    positions: np.ndarray,
    directions: np.ndarray,
    passes: tuple[tuple[int, int], ...],
    lines: Sequence[int],
    *,
    field: str,
) -> None:
    """Raise InvalidLineError at the first point that repeats its predecessor in a pass."""
    moved = np.linalg.norm(np.diff(positions, axis=0), axis=1) >= LINEAR_TOLERANCE
    change = np.diff(directions, axis=0).reshape(len(positions) - 1, -1)
    # The chord of a unit vector (the angle, to first order) or of a rotation's columns
    # (sqrt(2) times the angle): either way no turn below ANGULAR_TOLERANCE counts.
    turned = np.linalg.norm(change, axis=1) >= ANGULAR_TOLERANCE
    still = ~(moved | turned)
    for start, stop in passes:
        repeats = np.flatnonzero(still[start : stop - 1])
        if repeats.size:
            index = start + int(repeats[0]) + 1
            raise InvalidLineError(
                field,
                f"the point repeats the one before it (line {lines[index - 1]}): same position "
                "and tool direction, so the segment between them has no direction",
                line=int(lines[index]),
                waypoint=index,
            )
