"""A request's path as the solver takes it: poses, passes, feed, units and what was read.

Every path form of a request (:mod:`service.schemas.path`, :mod:`service.schemas.path_cam`)
converts itself to one :class:`PathInput`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from service.schemas.common import SpinMode
from solver.cam.cam_path import CamPath
from solver.cam.read_report import ReadReport, UnitsSource


@dataclass(frozen=True)
class PathInput:
    """A request's path as the solver takes it.

    Attributes:
        poses: shape (N, 4, 4), T_O_i (m).
        axis_correction: the largest correction made to a tool axis's length (0 for poses).
        default_spin_mode: ``free`` for a path given by tool axes, ``fixed`` for poses.
        passes: index ranges [start, stop) of the passes (cam.md section 5); None: one pass.
        feed: the program's feed (m/s), its highest FEDRAT; None when it programs none.
        units: the length unit the path was written in.
        units_source: how the units were known: ``stated``, ``inferred`` (CL data, from an
            inch feed) or ``request`` (the request's units, or metres by the API).
        units_note: the evidence for the units.
        pass_operations: each pass's operation name (CL data), ``None`` where none is named;
            empty for other forms.
        pass_feeds: each pass's highest feed (m/s) or ``None``; empty for poses and axes.
        one_point_passes: passes of one point dropped (CL data).
        report: what the CL reader skipped, dropped and inferred; ``None`` for other forms.
        cam_form: the CAM form the path came in (``cl_data``, ``csv``); ``None`` for poses
            and tool axes.
        source: the request's field the path came in (``path.waypoints``,
            ``path.tool_axis_waypoints``, ``path.cl_data``, ``path.csv``): the path's errors
            name it.
        lines: shape (N,), int, the line of the program (from 1) each waypoint was read from
            (CAM input: an arc's inner points the CIRCLE's line, its end the GOTO's); ``None``
            for poses and tool axes.
        segment_feeds: shape (N,), m/s, the programmed feed of each waypoint's move to the next
            (:attr:`solver.cam.cam_path.CamPath.feeds`), NaN where none; ``None`` for poses and
            tool axes.
    """

    poses: np.ndarray
    axis_correction: float
    default_spin_mode: SpinMode
    passes: tuple[tuple[int, int], ...] | None = None
    feed: float | None = None
    units: str = "m"
    units_source: UnitsSource = "request"
    units_note: str = "the API's unit (m)"
    pass_operations: tuple[str | None, ...] = ()
    pass_feeds: tuple[float | None, ...] = ()
    one_point_passes: int = 0
    report: ReadReport | None = None
    cam_form: Literal["cl_data", "csv"] | None = None
    source: str = "path.waypoints"
    lines: np.ndarray | None = None
    segment_feeds: np.ndarray | None = None

    @classmethod
    def from_cam(
        cls, cam: CamPath, *, form: Literal["cl_data", "csv"], units_note: str
    ) -> PathInput:
        """The solver's path of a CAM program: its poses, passes, feed, units and read report.

        Args:
            cam: the program as read.
            form: its form in the request; errors name the field ``path.<form>``.
            units_note: the evidence for the units where the reader gives none (a CSV).
        """
        field = f"path.{form}"
        report = cam.report
        return cls(
            poses=cam.waypoints_in_workpiece(field=field),
            axis_correction=cam.axis_correction,
            default_spin_mode=cam.default_spin_mode,
            passes=cam.passes,
            feed=cam.feed,
            units=cam.units,
            units_source="request" if report is None else report.units_source,
            units_note=units_note if report is None else report.units_note,
            pass_operations=cam.pass_operations,
            pass_feeds=cam.pass_feeds,
            one_point_passes=cam.one_point_passes,
            report=report,
            cam_form=form,
            source=field,
            lines=cam.lines,
            segment_feeds=cam.feeds,
        )
