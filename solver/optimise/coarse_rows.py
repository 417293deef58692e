"""The coarse map of a long program, on the waypoints that bind its best cells (issue 23).

A coarse map of a 10,000-waypoint program costs 10,000 poses a cell, though a cell's mu_path
is bound by a few of them. Beyond MAX_MAP_ROWS waypoints the map is therefore computed on a
subset (:func:`solver.path.subset.on_waypoints`, whose mu_path is at or above the whole
path's), and made exact where it matters, for the cells the search goes on from:

1. the first set: the whole path evaluated at SAMPLE_CELLS cells spread over the map, and
   their SAMPLE_ROWS slowest waypoints (or where they fail);
2. the map on the set; its best VERIFIED_CELLS local maxima evaluated on the whole path;
3. until the best maximum's whole-path value is its value on the set: where a maximum's
   whole-path value is below its value on the set (or the whole path fails there), the
   waypoints that bind it are added and the map is made again, MAP_ROUNDS times at most.

The cells handed on are the verified maxima, with the whole path's mu_path and branch; every
other cell is left out (NaN). When the best maximum holds, it is the whole path's best cell:
no cell's whole-path value is above its value on the set. The work is bounded before it
starts: MAP_ROUNDS maps of at most MAX_MAP_ROWS waypoints (the set stops growing there), and
SAMPLE_CELLS + MAP_ROUNDS * VERIFIED_CELLS whole-path placements.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress, span
from solver.optimise.active_set import ACTIVE_SET_RTOL, FIRST_ROWS, closure, lowest
from solver.optimise.failures import Tried
from solver.path.placements import PlacementResults, evaluate_placements
from solver.path.problem import PathProblem
from solver.path.subset import on_waypoints

MAX_MAP_ROWS = 2_000  # a longer program's coarse map runs on a set of at most this many
SAMPLE_CELLS = 16
SAMPLE_ROWS = 8  # the slowest waypoints of each sample cell in the first set
VERIFIED_CELLS = 6
MAP_ROUNDS = 6


def mapped_waypoints(n_waypoints: int) -> int:
    """The most waypoints a coarse map of a path of ``n_waypoints`` evaluates a cell on."""
    return min(n_waypoints, MAX_MAP_ROWS)


@dataclass(frozen=True)
class MapValues:
    """The index and branch of every placement of a coarse map.

    Attributes:
        feed_index: shape (P,), m/s, mu_path (mu_acc with acceleration limits) of the whole
            path; NaN where infeasible, and on a long program wherever it was not verified.
        branch: shape (P,), the branch index at each placement (meaningful where finite).
        rows: the final set of a long program's map (None: the whole path was mapped).
    """

    feed_index: np.ndarray
    branch: np.ndarray
    rows: np.ndarray | None = None


def map_values(
    problem: PathProblem,
    placements: np.ndarray,
    maxima: Callable[[np.ndarray], list[int]],
    *,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> MapValues:
    """The coarse map's values: of the whole path, or of its verified maxima (see the module).

    Args:
        problem: the whole problem (``auto`` branch).
        placements: shape (P, 5), the map's placement rows.
        maxima: from values at the placements (NaN where infeasible), the local maxima's
            placement indices, best first.
        progress: called with the fraction done.
        runner: where the placements run.
        tried: keeps the placements evaluated on the whole path: every one of a whole-path
            map, a long program's sample and verified cells (not its maps on a set).
    """
    tried = Tried() if tried is None else tried
    n = problem.prepared.n_waypoints
    if n <= MAX_MAP_ROWS:
        whole = evaluate_placements(problem, placements, progress=progress, runner=runner)
        tried.record(placements, whole.reason, whole.failed_waypoint)
        return MapValues(whole.feed_index, whole.branch)
    sample = np.unique(np.linspace(0, len(placements) - 1, SAMPLE_CELLS).round().astype(int))
    first, sampled = binding_rows(problem, placements[sample], None, runner)
    tried.record(placements[sample], sampled.reason, sampled.failed_waypoint)
    rows = closure(problem, first, neighbours=False)
    feed_index = np.full(len(placements), np.nan)
    branch = np.zeros(len(placements), dtype=int)
    for round_ in range(MAP_ROUNDS):
        part = span(progress, round_ / MAP_ROUNDS, (round_ + 1) / MAP_ROUNDS)
        on_set = evaluate_placements(
            on_waypoints(problem, rows), placements, progress=part, runner=runner
        )
        best = np.array(maxima(on_set.feed_index)[:VERIFIED_CELLS], dtype=int)
        added, whole = binding_rows(
            problem, placements[best], on_set.feed_index[best], runner, rows
        )
        tried.record(placements[best], whole.reason, whole.failed_waypoint)
        feed_index[:] = np.nan
        feed_index[best], branch[best] = whole.feed_index, whole.branch
        grown = closure(problem, np.union1d(rows, added), neighbours=False)
        holds = best.size and whole.feed_index[0] >= on_set.feed_index[best[0]] * (
            1.0 - ACTIVE_SET_RTOL
        )
        if holds or not added.size or len(grown) > MAX_MAP_ROWS:
            break
        rows = grown
    return MapValues(feed_index, branch, rows)


def binding_rows(
    problem: PathProblem,
    placements: np.ndarray,
    on_set: np.ndarray | None,
    runner: TaskRunner,
    rows: np.ndarray | None = None,
) -> tuple[np.ndarray, PlacementResults]:
    """The waypoints that bind the whole path at ``placements`` and are not in ``rows``.

    Without a set (the sample): each placement's SAMPLE_ROWS slowest waypoints, or its first
    failing one. With one: at each placement whose whole-path value is below ``on_set`` (its
    value on the set) by more than ACTIVE_SET_RTOL, the waypoints below the set's least, or
    where the whole path fails.

    Returns:
        the waypoints (whole-path indices) and the whole path's results at the placements.
    """
    whole = evaluate_placements(problem, placements, with_speeds=True, runner=runner)
    speeds = whole.feed_bounds
    if speeds is None:  # not reached: asked for with_speeds
        raise RuntimeError("evaluate_placements returned no speeds")
    found: list[np.ndarray] = []
    for k in range(len(placements)):
        failed = int(whole.failed_waypoint[k])
        if rows is None or on_set is None:
            found.append(np.array([failed]) if failed >= 0 else lowest(speeds[k], SAMPLE_ROWS))
            continue
        value = whole.feed_index[k]
        if np.isfinite(value) and value >= on_set[k] * (1.0 - ACTIVE_SET_RTOL):
            continue
        if failed >= 0:
            found.append(np.array([max(failed - 1, 0), failed]))
            continue
        least = on_set[k]
        below = np.flatnonzero(np.nan_to_num(speeds[k], nan=np.inf) < least)
        found.append(below[lowest(speeds[k, below], FIRST_ROWS)])
    added = np.unique(np.concatenate(found)) if found else np.zeros(0, dtype=int)
    if rows is not None:
        added = np.setdiff1d(added, rows)
    return added.astype(np.int64), whole
