"""The cell as a limit on the seam of :mod:`solver.path.limits`: a check of whole joint paths."""

from __future__ import annotations

import numpy as np

from solver.core.codes import REASON_COLLISION
from solver.core.spatial import Placement
from solver.path.cell.checker import CellChecker
from solver.path.limits import PathCheck, PathVerdict


class CellLimit(PathCheck):
    """No robot part nearer than the clearance to an obstacle or another part (cell.md s. 3)."""

    name = "collision"
    reason = REASON_COLLISION

    def __init__(self, checker: CellChecker, segment_in_pass: np.ndarray) -> None:
        """Hold the checker and the path's passes (no sub-steps across a rapid).

        Args:
            checker: the robot and the cell.
            segment_in_pass: shape (W - 1,), False where a rapid joins two passes.
        """
        self.checker = checker
        self.segment_in_pass = np.asarray(segment_in_pass, dtype=bool)

    def check(self, q: np.ndarray, placement: np.ndarray, *, thorough: bool) -> PathVerdict:
        """Check ``q`` at ``placement`` (see :meth:`PathCheck.check`)."""
        x, y, z, yaw = (float(v) for v in placement[:4])
        transform = Placement(x, y, z, yaw).transform_workpiece_to_base()
        verdict = self.checker.check(q, self.segment_in_pass, transform, closest=thorough)
        failed = None if verdict.collision is None else verdict.collision.waypoint
        return PathVerdict(failed, verdict)
