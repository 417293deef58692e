"""The cell as a limit on the seam of :mod:`solver.path.limits`: a check of whole joint paths."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from solver.core.codes import REASON_COLLISION
from solver.core.spatial import Placement
from solver.path.cell.checker import CellChecker
from solver.path.cell.cost import cell_pose_cost
from solver.path.cell.verdict import CellVerdict
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
        return PathVerdict(failed, verdict, None if failed is None else self.reason)

    def pose_cost(self) -> float:
        """The check's weight a pose: its step and its pairs' (:func:`cell_pose_cost`)."""
        return cell_pose_cost(self.checker.cell, self.checker.pair_count)

    def model(self) -> dict[str, Any]:
        """The links given capsules and the parts not checked (``CapabilityMap``'s fields)."""
        return {
            "cell_approximated": self.checker.approximated,
            "cell_unchecked": self.checker.unchecked,
        }

    def refuses_at(self, q: np.ndarray, placement: np.ndarray, refusal: PathVerdict) -> bool:
        """Whether ``q`` collides on the refusal's pair at its waypoint (``PathCheck.refuses_at``).

        By :meth:`CellChecker.collides_at`: coal's distance of that pair below the clearance
        less a margin at ``q``'s configuration at that waypoint, which the check reaches.
        """
        detail = refusal.detail
        if not isinstance(detail, CellVerdict) or detail.collision is None:
            return False
        contact = detail.collision
        transform = workpiece_to_base(placement[None])[0]
        return self.checker.collides_at(q[contact.waypoint], transform, contact)

    def check_many(self, joint_paths: np.ndarray, placements: np.ndarray) -> list[PathVerdict]:
        """Check N joint paths at their placements in one compiled sweep (a map's chunk)."""
        verdicts = self.checker.check_many(
            joint_paths, self.segment_in_pass, workpiece_to_base(placements)
        )
        return [
            PathVerdict(None, v)
            if v.collision is None
            else PathVerdict(v.collision.waypoint, v, self.reason)
            for v in verdicts
        ]


def workpiece_to_base(placements: np.ndarray) -> np.ndarray:
    """T_B_O of N placements (N, 5), shape (N, 4, 4): :meth:`Placement.transform_workpiece_to_base`.

    The same floats (``math``'s cosine and sine), without making a :class:`Placement` each
    (its checks cost 0.1 ms; a map's placements were checked once).
    """
    transforms = np.zeros((len(placements), 4, 4))
    for transform, (x, y, z, yaw) in zip(transforms, placements[:, :4].tolist(), strict=True):
        c, s = math.cos(yaw), math.sin(yaw)
        transform[0] = c, -s, 0.0, x
        transform[1] = s, c, 0.0, y
        transform[2, 2], transform[2, 3], transform[3, 3] = 1.0, z, 1.0
    return transforms
