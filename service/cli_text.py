"""What ``dtf-place`` prints for people (``--json`` prints the API's answers instead)."""

from __future__ import annotations

import sys
import time
from types import TracebackType

from service.schemas import (
    EvaluateResponse,
    FeedCheckResult,
    MapResponse,
    OptimizeResponse,
    PathRead,
    PlacementResult,
)
from service.schemas.cell import Contact
from service.schemas.ik import NumericBranch
from service.schemas.paths_import import PathImportResponse

_MM_PER_MIN = 60e3
"""mm/min per m/s."""


def _fixed(value: float, digits: int) -> str:
    """``value`` with ``digits`` decimals, never ``-0.00``."""
    return f"{round(value, digits) + 0.0:.{digits}f}"


def _feed(feed: float | None) -> str:
    """A feed in mm/min, or a dash."""
    return "-" if feed is None else f"{feed * _MM_PER_MIN:.1f} mm/min"


def _contact(contact: Contact) -> str:
    """A robot part and what it comes closest to: where, and how far apart or into each other."""
    where = f"at waypoint {contact.waypoint}"
    return f"{contact.robot_part} and {contact.obstacle_name} {where}, {_apart(contact.distance)}"


def _apart(distance: float) -> str:
    """A distance (m) in mm, apart or into it."""
    depth = distance * 1e3
    return f"{_fixed(depth, 1)} mm apart" if depth >= 0.0 else f"{_fixed(-depth, 1)} mm into it"


def _how_it_runs(answer: EvaluateResponse) -> list[str]:
    """The branch; mu_acc and the cycle time (with acceleration limits); the least clearance."""
    lines = []
    branch = answer.branch
    if isinstance(branch, NumericBranch):
        lines.append(f"branch: solution {branch.solution} (numeric IK, in seed order)")
    elif branch is not None:
        lines.append(f"branch: {branch.shoulder}/{branch.elbow}/{branch.wrist}")
    acceleration = answer.acceleration
    if acceleration is not None:
        lines.append(
            f"mu_acc: {acceleration.mu_acc:.4f} m/s (a joint {acceleration.limited_by} limit "
            f"binds: {acceleration.joint_name} at waypoint {acceleration.waypoint})"
        )
    if answer.cycle_time is not None:
        lines.append(
            f"cycle time: {answer.cycle_time.ramp:.2f} s at mu_acc with its ramps "
            f"(time-optimal {answer.cycle_time.time_optimal:.2f} s)"
        )
    if answer.min_clearance is not None:
        lines.append(f"least clearance: {_contact(answer.min_clearance)}")
    return lines + _cell_model(answer)


def _cell_model(answer: EvaluateResponse | MapResponse) -> list[str]:
    """The links given capsules and the parts not checked, where the answer has a cell."""
    lines = []
    if answer.cell_approximated:
        lines.append("cell: approximated by capsules: " + ", ".join(answer.cell_approximated))
    if answer.cell_unchecked:
        pairs = ", ".join(
            f"{pair.robot_part} and {pair.obstacle_name} ({_apart(pair.distance)})"
            for pair in answer.cell_unchecked
        )
        lines.append(f"cell: not checked, no joint moves them relative to each other: {pairs}")
    return lines


def import_text(answer: PathImportResponse, name: str) -> str:
    """The import summary: counts, units and how known, passes and operations, skipped."""
    lines = [
        f"program: {name}",
        f"waypoints: {len(answer.waypoints)} in {_passes(len(answer.passes))} "
        f"({answer.arcs} arcs interpolated; dropped: {answer.repeated_points} repeated point(s), "
        f"{answer.one_point_passes} one-point pass(es))",
        _units(answer.units, answer.units_source, answer.units_note),
        _end(answer.ended, answer.end_note),
        f"feed: {_feed(answer.feed)} (the highest programmed)",
        *_programmed_time(answer),
        "passes:",
    ]
    # Passes from 0, as the waypoints and the API's failed_pass and messages count them (this
    # listing counted from 1, and a failure's "pass 0" was the listing's pass 1).
    for number, part in enumerate(answer.pass_details):
        way = "" if part.length is None else f", {_fixed(part.length * 1e3, 1)} mm"
        took = "" if part.time is None else f" in {_fixed(part.time, 1)} s as programmed"
        lines.append(
            f"  {number:3d}  waypoints {part.start}-{part.stop - 1}  "
            f"{part.operation or '-'}  {_feed(part.feed)}{way}{took}"
        )
    if answer.skipped_records:
        lines.append("skipped records (no geometry, no feed):")
    for record in answer.skipped_records:
        known = "" if record.recognised else "  (not recognised: check it moves nothing)"
        lines.append(f"  {record.word}: {record.count} (first at line {record.first_line}){known}")
    return "\n".join(lines)


def _programmed_time(answer: PathImportResponse) -> list[str]:
    """The program's cutting time at its programmed feeds, where every pass has one."""
    times = [part.time for part in answer.pass_details]
    if not times or any(t is None for t in times):
        return []
    total = sum(t for t in times if t is not None)
    return [
        f"cutting time: {_fixed(total, 1)} s at the programmed feeds (the passes' moves: not the "
        "rapids, nor the moves from their targets into the passes)"
    ]


def _passes(count: int) -> str:
    """``1 pass``, ``2 passes``."""
    return f"{count} pass" if count == 1 else f"{count} passes"


def _units(units: str, source: str, note: str) -> str:
    """The units line: how they are known; the API's "request" is the command's ``--units``.

    The reader's note says "the request's units" where the file states none, which on the
    command line (no request sent) read as if they came from elsewhere (the CLI audit of stop 61).
    """
    if source == "request":
        return f"units: {units} (given with --units: the file states none)"
    return f"units: {units} ({source}: {note})"


def _end(ended: bool | None, note: str) -> str:
    """The end line: the end record found, or a warning that the program may be cut short."""
    return f"end: {note}" if ended is not False else f"end: WARNING: {note}"


def read_text(read: PathRead | None) -> list[str]:
    """How the program was read: its units and how known, passes, what was skipped or dropped.

    No lines for a path of poses or tool axes (``read`` None).
    """
    if read is None:
        return []
    line = (
        f"read: {_passes(len(read.pass_details))} ({read.arcs} arcs interpolated; dropped: "
        f"{read.repeated_points} repeated point(s), {read.one_point_passes} one-point pass(es))"
    )
    if read.skipped_records:
        line += "; skipped (no geometry, no feed): " + ", ".join(
            f"{r.word} {r.count} (line {r.first_line}"
            + (")" if r.recognised else ", not recognised: check it moves nothing)")
            for r in read.skipped_records
        )
    return [
        _units(read.units, read.units_source, read.units_note),
        _end(read.ended, read.end_note),
        line,
    ]


SAID_CORRECTION = 1e-6
"""The least ``axis_correction`` the text says: below it, the rounding of a file's printed
digits (the NX example's tool axes are 5e-8 off unit, the README path's quaternions 6e-13), a
microradian at most; ``--json`` gives every one."""


def normalised_text(correction: float) -> list[str]:
    """The answer's ``axis_correction`` said, where a unit vector or quaternion was corrected."""
    if not correction > SAID_CORRECTION:
        return []
    return [
        f"normalised: the request's tool axes or quaternions, largest correction {correction:.1e}"
    ]


def evaluation_text(answer: EvaluateResponse, clearance: float | None = None) -> str:
    """How the program was read; mu_path, the bottleneck and the feed check, or why not.

    ``clearance``: the cell's (m), named beside a collision.
    """
    lines = read_text(answer.path_read) + normalised_text(answer.axis_correction)
    if not answer.feasible:
        where = "" if answer.failed_waypoint is None else f" at waypoint {answer.failed_waypoint}"
        within = [] if answer.failed_line is None else [f"line {answer.failed_line}"]
        if answer.failed_pass is not None:
            named = "" if answer.failed_operation is None else f", {answer.failed_operation}"
            within.append(f"pass {answer.failed_pass}{named}")
        where += f" ({', '.join(within)})" if within else ""
        lines.append(f"infeasible: {answer.reason}{where}")
        if answer.collision is not None:
            limit = "" if clearance is None else f" (clearance {_fixed(clearance * 1e3, 1)} mm)"
            lines.append(f"collision: {_contact(answer.collision)}{limit}")
        return "\n".join(lines + _cell_model(answer))
    lines.append(f"mu_path: {answer.mu_path:.4f} m/s (spin {answer.spin_mode})")
    if answer.bottleneck is not None:
        line = answer.bottleneck.line
        lines.append(
            f"bottleneck: waypoint {answer.bottleneck.waypoint}"
            + ("" if line is None else f" (line {line})")
            + f", joint {answer.bottleneck.joint_name}"
        )
    lines += _how_it_runs(answer)
    if answer.feed_check is not None:
        lines.append(_feed_check(answer.feed_check))
    if answer.placement is not None:  # the placement given, in controller terms
        lines += _placement(answer.placement)
    return "\n".join(lines)


def _feed_check(check: FeedCheckResult) -> str:
    """Whether the program's feed runs, and mu_path / feed (the margin: 1 or more runs)."""
    verdict = "runs" if check.feasible else "does not run"
    margin = "" if check.margin is None else f", margin {check.margin:.3f} (mu_path / feed)"
    return f"feed {_feed(check.feed)}: {verdict}{margin}"


def _placement(placement: PlacementResult) -> list[str]:
    """A placement and its controller frames."""
    frames = placement.frames
    ur = ", ".join(_fixed(v, 5) for v in frames.ur)
    kuka = ", ".join(f"{k} {_fixed(v, 2)}" for k, v in frames.kuka.items())
    fanuc = ", ".join(f"{k} {_fixed(v, 2)}" for k, v in frames.fanuc.items())
    (position, quaternion) = frames.abb
    abb = (
        f"[[{', '.join(_fixed(v, 2) for v in position)}], "
        f"[{', '.join(_fixed(v, 6) for v in quaternion)}]]"
    )
    return [
        f"placement: x {placement.x:.4f} m, y {placement.y:.4f} m, z {placement.z:.4f} m, "
        f"yaw {placement.yaw:.4f} rad, spin {placement.spin:.4f} rad",
        f"  UR base pose (m, rad): [{ur}]",
        f"  KUKA base (mm, deg): {kuka}",
        f"  ABB wobj uframe (mm): {abb}",
        f"  FANUC user frame (mm, deg): {fanuc}",
    ]


def map_text(answer: MapResponse, png: str) -> str:
    """How the program was read; the map's size, its best placement, the picture's file."""
    lines = read_text(answer.path_read) + normalised_text(answer.axis_correction)
    collide = sum(cell.reason == "collision" for cell in answer.cells)
    collisions = f" ({collide} in collision)" if collide else ""
    feasible = f"{answer.feasible_cells} of {len(answer.cells)} placements feasible"
    lines.append(f"map: {feasible}{collisions}; {png}")
    if answer.best is not None:
        lines.append(f"best: mu_path {answer.best.mu_path:.4f} m/s")
        lines += _placement(answer.best.placement)
    return "\n".join(lines + _cell_model(answer))


def optimum_text(answer: OptimizeResponse) -> str:
    """How the program was read; the optimum with its controller frames, or that none is."""
    correction = 0.0 if answer.evaluation is None else answer.evaluation.axis_correction
    lines = read_text(answer.path_read) + normalised_text(correction)
    if not answer.found or answer.placement is None or answer.mu_path is None:
        why = "" if answer.failure is None else f": {answer.failure.message}"
        return "\n".join([*lines, f"no feasible placement inside the bounds{why}"])
    gain = answer.improvement_percent
    lines += [
        f"optimum: mu_path {answer.mu_path:.4f} m/s"
        + ("" if gain is None else f" ({gain:+.1f} % over the start)"),
        *_placement(answer.placement),
    ]
    if answer.evaluation is not None:
        lines += _how_it_runs(answer.evaluation)
    check = None if answer.evaluation is None else answer.evaluation.feed_check
    if check is not None:
        lines.append(_feed_check(check))
    return "\n".join(lines)


class ProgressBar:
    """A progress callback drawing a bar on stderr (when enabled), cleared at the end."""

    WIDTH = 30
    """Characters of the bar."""
    EVERY = 0.1
    """s between redraws."""

    def __init__(self, *, enabled: bool) -> None:
        """Draw only when ``enabled`` (stderr a terminal, by default)."""
        self.enabled = enabled
        self.drawn = 0.0

    def __call__(self, fraction: float) -> None:
        """Report progress in [0, 1]."""
        now = time.monotonic()
        if not self.enabled or now - self.drawn < self.EVERY:
            return
        self.drawn = now
        done = int(self.WIDTH * min(max(fraction, 0.0), 1.0))
        bar = "#" * done + "-" * (self.WIDTH - done)
        sys.stderr.write(f"\r[{bar}] {100 * fraction:5.1f} %")
        sys.stderr.flush()

    def __enter__(self) -> ProgressBar:
        """The callback."""
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        """Clear the bar's line."""
        if self.enabled and self.drawn:
            sys.stderr.write("\r" + " " * (self.WIDTH + 12) + "\r")
            sys.stderr.flush()
