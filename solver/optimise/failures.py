"""Why a search found no placement: the failures of the placements it judged (api.md).

Every placement the optimiser judges on the whole path (each candidate, the start included)
that does not run has a reason and a first failing waypoint. When none runs, the most common
reason, and its most common waypoint, say why the bounds hold no placement.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

from solver.path.evaluate import PathEvaluation


@dataclass(frozen=True)
class SearchFailure:
    """The most common failure of the placements a search judged, none of them feasible.

    Attributes:
        reason: the most common reason (``unreachable``, ``discontinuous``, ...).
        failed_waypoint: the most common first failing waypoint among those (the lowest of
            equals); None where none was named.
        count: how many judged placements failed for ``reason``.
        judged: how many placements were judged on the whole path (the start included).
    """

    reason: str
    failed_waypoint: int | None
    count: int
    judged: int


def search_failure(evaluations: Sequence[PathEvaluation]) -> SearchFailure | None:
    """The most common failure of ``evaluations`` (None if there are none, or one ran).

    Ties go to the reason, then the waypoint, met first in ``evaluations`` order for the
    reason (candidates best first, the start last) and to the lowest waypoint.
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
    return SearchFailure(reason, failed, count, len(evaluations))
