"""Why a search found no placement: the failures of the placements it judged and tried (api.md).

Every placement the optimiser judges on the whole path (each candidate, the start included)
that does not run has a reason and a first failing waypoint. When none runs, the most common
reason, and its most common waypoint, say why the bounds hold no placement.

The candidates are few (often the start alone: a coarse map with no feasible cell proposes
none), so the search also keeps what it tried on the whole path (:class:`Tried`: the cells of
the casadi method's coarse map, the members of the scipy method's differential evolution),
and a failure tallies them by reason (:class:`TriedSummary`): which limit closes the bounds,
and where along the path. A long program's maps and evolutions on a set of its waypoints are
not kept (their first failing waypoint is the set's, not the path's): only its placements
evaluated on the whole path are (the samples that make its first set, the best cells or
members checked each round).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from solver.core.codes import FEASIBLE, REASONS
from solver.path.evaluate import PathEvaluation


@dataclass(frozen=True)
class ReasonTally:
    """The placements a search tried that failed for one reason.

    Attributes:
        reason: the reason (``unreachable``, ``joint_limits``, ``collision``, ...).
        count: how many of the placements tried failed for it.
        failed_waypoint: the most common first failing waypoint among them (the lowest of
            equals); None where none was named.
    """

    reason: str
    count: int
    failed_waypoint: int | None


@dataclass(frozen=True)
class TriedSummary:
    """What a search tried on the whole path, by outcome.

    Attributes:
        placements: how many distinct placements it evaluated on the whole path.
        feasible: how many of them run the path.
        reasons: the others by reason, most common first (ties in the order of
            :data:`solver.core.codes.REASONS`).
    """

    placements: int
    feasible: int
    reasons: tuple[ReasonTally, ...]


class Tried:
    """The placements a search evaluated on the whole path, each with its outcome.

    A placement is counted once, by its row (x, y, z, yaw, spin): evaluated again, it has the
    same outcome. Recording keeps the arrays (no work per placement while the search runs);
    they are gathered when asked for. Filled by the search in the thread that runs it.
    """

    def __init__(self) -> None:
        """Nothing tried yet."""
        self._parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []

    def record(self, rows: np.ndarray, reason: np.ndarray, failed_waypoint: np.ndarray) -> None:
        """Keep the outcomes of placements evaluated on the whole path.

        Args:
            rows: shape (P, 5), the placement rows (:meth:`Placement.as_row`).
            reason: shape (P,), reason codes (:data:`FEASIBLE` where the path runs).
            failed_waypoint: shape (P,), the first failing waypoint (-1 where none).
        """
        self._parts.append(
            (
                np.array(rows, dtype=float).reshape(-1, 5),
                np.array(reason, dtype=np.int64),
                np.array(failed_waypoint, dtype=np.int64),
            )
        )

    def outcomes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every distinct placement kept, in the order first met: rows, reasons, waypoints."""
        if not self._parts:
            return np.zeros((0, 5)), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        rows, reason, failed = (np.concatenate(c) for c in zip(*self._parts, strict=True))
        first = np.sort(np.unique(rows, axis=0, return_index=True)[1])
        return rows[first], reason[first], failed[first]

    def summary(self) -> TriedSummary | None:
        """The placements kept, by outcome; None where none was kept."""
        rows, reason, failed = self.outcomes()
        if not len(rows):
            return None
        tallies = []
        codes, counts = np.unique(reason[reason != FEASIBLE], return_counts=True)
        for k in np.lexsort((codes, -counts)):  # most common first, then REASONS' order
            named = failed[(reason == codes[k]) & (failed >= 0)]
            waypoint = None
            if len(named):
                values, times = np.unique(named, return_counts=True)
                waypoint = int(values[np.argmax(times)])  # the lowest of the most common
            tallies.append(ReasonTally(str(REASONS[codes[k]]), int(counts[k]), waypoint))
        return TriedSummary(len(rows), int(np.sum(reason == FEASIBLE)), tuple(tallies))


@dataclass(frozen=True)
class SearchFailure:
    """The most common failure of the placements a search judged, none of them feasible.

    Attributes:
        reason: the most common reason (``unreachable``, ``discontinuous``, ...).
        failed_waypoint: the most common first failing waypoint among those (the lowest of
            equals); None where none was named.
        count: how many judged placements failed for ``reason``.
        judged: how many placements were judged on the whole path (the start included).
        tried: what the search tried on the whole path on its way, by outcome (None where it
            kept nothing: see the module).
    """

    reason: str
    failed_waypoint: int | None
    count: int
    judged: int
    tried: TriedSummary | None = None


def search_failure(
    evaluations: Sequence[PathEvaluation], tried: TriedSummary | None = None
) -> SearchFailure | None:
    """The most common failure of ``evaluations`` (None if there are none, or one ran).

    ``tried``: what the search tried on its way, carried as it is. Ties go to the reason, then
    the waypoint, met first in ``evaluations`` order for the reason (candidates best first,
    the start last) and to the lowest waypoint.
    """
    if not evaluations or any(e.reason is None for e in evaluations):
        return None
    reasons = Counter(str(e.reason) for e in evaluations)
    reason, count = reasons.most_common(1)[0]  # the first met of equals (Counter keeps order)
    waypoints = Counter(
        e.failed_waypoint
        for e in evaluations
        if str(e.reason) == reason and e.failed_waypoint is not None
    )
    top = max(waypoints.values(), default=0)
    failed = min((w for w, n in waypoints.items() if n == top), default=None)
    return SearchFailure(reason, failed, count, len(evaluations), tried)
