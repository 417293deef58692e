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

The cells handed on are the last round's verified maxima, and any cell of the sample or an
earlier round that runs faster on the whole path (there are such only when the best maximum
does not hold), with the whole path's mu_path and branch; every other cell is left out (NaN).
When the best maximum holds, it is the whole path's best cell: no cell's whole-path value is
above its value on the set. Where a maximum does not hold, the waypoints added are those of the
branch the set ran it on as well as the whole path's own (:func:`binding_rows`). The work is
bounded before it starts: MAP_ROUNDS maps of at most MAX_MAP_ROWS waypoints (the set stops growing
there), and at most :func:`whole_path_checks` whole-path placements.
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


def whole_path_checks(n_waypoints: int) -> int:
    """The most placements a coarse map of a path of ``n_waypoints`` evaluates on the whole path.

    None for a path mapped whole (its map is the whole path's); for a longer one, the sample,
    and each round's maxima, twice (on the whole path's branch and on the set's).
    """
    if n_waypoints <= MAX_MAP_ROWS:
        return 0
    return SAMPLE_CELLS + 2 * MAP_ROUNDS * VERIFIED_CELLS


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
    earlier = MapValues(feed_index.copy(), branch.copy())  # the sample's and earlier rounds'
    earlier.feed_index[sample], earlier.branch[sample] = sampled.feed_index, sampled.branch
    for round_ in range(MAP_ROUNDS):
        part = span(progress, round_ / MAP_ROUNDS, (round_ + 1) / MAP_ROUNDS)
        on_set = evaluate_placements(
            on_waypoints(problem, rows), placements, progress=part, runner=runner
        )
        best = np.array(maxima(on_set.feed_index)[:VERIFIED_CELLS], dtype=int)
        added, whole = binding_rows(
            problem, placements[best], on_set.feed_index[best], runner, rows, on_set.branch[best]
        )
        tried.record(placements[best], whole.reason, whole.failed_waypoint)
        _keep(earlier, feed_index, branch)
        feed_index[:] = np.nan
        feed_index[best], branch[best] = whole.feed_index, whole.branch
        grown = closure(problem, np.union1d(rows, added), neighbours=False)
        holds = best.size and whole.feed_index[0] >= on_set.feed_index[best[0]] * (
            1.0 - ACTIVE_SET_RTOL
        )
        if holds or not added.size or len(grown) > MAX_MAP_ROWS:
            break
        rows = grown
    # When the last round's best maximum holds no cell is above it; when it does not (the
    # rounds ran out, or none of its maxima runs on the whole path), a faster cell of the
    # sample or an earlier round is known to run and is handed on too.
    top = np.nanmax(feed_index, initial=-np.inf)
    faster = np.nan_to_num(earlier.feed_index, nan=-np.inf) > top
    feed_index[faster], branch[faster] = earlier.feed_index[faster], earlier.branch[faster]
    return MapValues(feed_index, branch, rows)


def _keep(kept: MapValues, feed_index: np.ndarray, branch: np.ndarray) -> None:
    """Copy a round's whole-path values (finite ``feed_index``) into ``kept``."""
    runs = np.isfinite(feed_index)
    kept.feed_index[runs], kept.branch[runs] = feed_index[runs], branch[runs]


def binding_rows(
    problem: PathProblem,
    placements: np.ndarray,
    on_set: np.ndarray | None,
    runner: TaskRunner,
    rows: np.ndarray | None = None,
    branches: np.ndarray | None = None,
) -> tuple[np.ndarray, PlacementResults]:
    """The waypoints that bind the whole path at ``placements`` and are not in ``rows``.

    Without a set (the sample): each placement's SAMPLE_ROWS slowest waypoints, or its first
    failing one. With one: at each placement whose whole-path value is below ``on_set`` (its
    value on the set) by more than ACTIVE_SET_RTOL, the waypoints below the set's least, or
    where the whole path fails; and, where the set ran it on another branch (``branches``, the
    set's branch indices), the same of the whole path on that branch
    (:func:`_set_branch_rows`).

    Returns:
        the waypoints (whole-path indices) and the whole path's results at the placements.
    """
    whole = evaluate_placements(problem, placements, with_speeds=True, runner=runner)
    speeds = whole.feed_bounds
    if speeds is None:  # not reached: asked for with_speeds
        raise RuntimeError("evaluate_placements returned no speeds")
    found: list[np.ndarray] = []
    other_branch: list[int] = []  # placements the set ran on a branch the whole path did not
    for k in range(len(placements)):
        failed = int(whole.failed_waypoint[k])
        if rows is None or on_set is None:
            found.append(np.array([failed]) if failed >= 0 else lowest(speeds[k], SAMPLE_ROWS))
            continue
        value = whole.feed_index[k]
        if np.isfinite(value) and value >= on_set[k] * (1.0 - ACTIVE_SET_RTOL):
            continue
        found.append(_binding(speeds[k], failed, on_set[k]))
        if branches is not None and branches[k] != whole.branch[k]:
            other_branch.append(k)
    if other_branch:
        assert branches is not None and on_set is not None  # a set's placements only
        chosen = np.array(other_branch)
        found += _set_branch_rows(
            problem, placements[chosen], branches[chosen], on_set[chosen], runner
        )
    added = np.unique(np.concatenate(found)) if found else np.zeros(0, dtype=int)
    if rows is not None:
        added = np.setdiff1d(added, rows)
    return added.astype(np.int64), whole


def _binding(speeds: np.ndarray, failed: int, least: float) -> np.ndarray:
    """Where a placement's whole path fails (the step into it too), or its bounds below ``least``.

    ``speeds`` (N,) the whole path's bounds at the placement on one branch, ``failed`` its
    first failing waypoint (-1: it runs), ``least`` the placement's value on the set.
    """
    if failed >= 0:
        return np.array([max(failed - 1, 0), failed])
    below = np.flatnonzero(np.nan_to_num(speeds, nan=np.inf) < least)
    binding: np.ndarray = below[lowest(speeds[below], FIRST_ROWS)]
    return binding


def _set_branch_rows(
    problem: PathProblem,
    placements: np.ndarray,
    branches: np.ndarray,
    on_set: np.ndarray,
    runner: TaskRunner,
) -> list[np.ndarray]:
    """The waypoints that bind the whole path on the branch the set ran each placement on.

    The set's ``auto`` may run a placement on a branch other than the whole path's: one that
    fails (or is slower) at waypoints the set lacks, which the whole path's own branch does
    not name. Without those the next set runs the placement on that branch again, at the same
    value, and the loop stalls (a 17,000-move program whose every verified cell failed so,
    round after round, was answered with its start). Each placement's whole path is evaluated
    once more, on its set's branch: where it fails there, or its bounds below its set value.
    """
    found: list[np.ndarray] = []
    for branch in np.unique(branches):
        chosen = np.flatnonzero(branches == branch)
        on_branch = problem.with_options(branch=problem.family.branches[int(branch)])
        result = evaluate_placements(on_branch, placements[chosen], with_speeds=True, runner=runner)
        speeds = result.feed_bounds
        if speeds is None:  # not reached: asked for with_speeds
            raise RuntimeError("evaluate_placements returned no speeds")
        for k, index in enumerate(chosen):
            found.append(_binding(speeds[k], int(result.failed_waypoint[k]), on_set[index]))
    return found
