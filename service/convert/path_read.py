"""How a path was read (units, passes, records skipped), for every answer that shows it.

``POST /v1/paths/import`` shows it with the waypoints; the answers computed from a CAM program
(CL data or CSV) give it as ``path_read`` (:class:`service.schemas.PathRead`), from the same
function, so the two never differ.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from service import schemas
from service.schemas.path_input import PathInput

NO_END_RECORD = {
    "csv": "a CSV has no end record: a file cut at the end of a line cannot be told from a whole "
    "one",
    None: "waypoints sent as JSON have no end record: the path is taken as sent",
}
"""``end_note`` of the forms with no end record (``ended`` null), by ``cam_form``."""


def _time(moves: np.ndarray, path: PathInput, start: int, stop: int) -> float | None:
    """The moves of the pass [start, stop) at their programmed feeds (s); None where one has none.

    ``moves``: every move's length (m), move i from waypoint i to i + 1.
    """
    if path.segment_feeds is None:
        return None
    feeds = path.segment_feeds[start : stop - 1]
    if not np.all(feeds > 0.0):  # NaN: no feed programmed
        return None
    return float((moves[start : stop - 1] / feeds).sum())


def read_fields(path: PathInput) -> dict[str, Any]:
    """The fields the import answer and ``path_read`` share: units, feed, passes, skipped.

    Args:
        path: the path as the solver takes it, of any form (poses: one pass, metres).
    """
    passes = path.passes or ((0, len(path.poses)),)
    operations = path.pass_operations or (None,) * len(passes)
    feeds = path.pass_feeds or (path.feed,) * len(passes)
    report = path.report
    moves = np.linalg.norm(np.diff(path.poses[:, :3, 3], axis=0), axis=-1)  # move i: i -> i + 1
    return {
        "units": path.units,
        "units_source": path.units_source,
        "units_note": path.units_note,
        "feed": path.feed,
        "pass_details": [
            schemas.PassOut(
                start=start,
                stop=stop,
                operation=operation,
                feed=feed,
                length=float(moves[start : stop - 1].sum()),
                time=_time(moves, path, start, stop),
            )
            for (start, stop), operation, feed in zip(passes, operations, feeds, strict=True)
        ],
        "skipped_records": []
        if report is None
        else [
            schemas.SkippedRecordOut(
                word=s.word, count=s.count, first_line=s.first_line, recognised=s.recognised
            )
            for s in report.skipped_records
        ],
        "repeated_points": 0 if report is None else report.repeated_points,
        "one_point_passes": path.one_point_passes,
        "arcs": 0 if report is None else report.arcs,
        "ended": None if report is None else report.ended,
        "end_note": NO_END_RECORD[path.cam_form] if report is None else report.end_note,
    }


def path_read_of(path: PathInput) -> schemas.PathRead | None:
    """How a CAM program was read; ``None`` for a path of poses or tool axes."""
    if path.cam_form is None:
        return None
    return schemas.PathRead(form=path.cam_form, **read_fields(path))


def pass_at(path: PathInput, waypoint: int | None) -> tuple[int | None, str | None]:
    """The pass (its index, from 0) holding ``waypoint`` and its operation's name, of CAM input.

    ``(None, None)`` for poses and tool axes, without a waypoint, or for one in no pass; the
    operation is None where the file names none.
    """
    if path.cam_form is None or waypoint is None:
        return None, None
    passes = path.passes or ((0, len(path.poses)),)
    for k, (start, stop) in enumerate(passes):
        if start <= waypoint < stop:
            operations = path.pass_operations
            return k, operations[k] if k < len(operations) else None
    return None, None
