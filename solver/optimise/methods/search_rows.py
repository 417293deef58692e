"""The scipy method's differential evolution of a long program, on the waypoints that bind.

Differential evolution evaluates every placement of its populations (3,904 of them for x, y
and yaw) on the whole path: 10,000 waypoints make 39 million poses, which the service refused
(issue 23). Beyond MAX_SEARCH_ROWS waypoints it therefore runs on a subset
(:func:`solver.path.subset.on_waypoints`: each kept waypoint's bound is the whole path's, so a
placement's mu_path on the set is at or above the whole path's; in free spin up to the spin
schedule, which restarts at the set's breaks), made exact where it matters, as the casadi
method's coarse map of a long program is (:mod:`solver.optimise.coarse_rows`):

1. the first set: the whole path evaluated at SAMPLE_CELLS placements spread over the box,
   their slowest waypoints (or where they fail);
2. differential evolution on the set; its best VERIFIED distinct placements evaluated on the
   whole path;
3. until the best of them holds (its whole-path value is its value on the set), the waypoints
   that bind them are added (on the whole path's branch and on the set's:
   :func:`solver.optimise.coarse_rows.binding_rows`) and the evolution made again,
   SEARCH_ROUNDS times at most.

When the best holds, it is the best whole-path placement of all that the last evolution
evaluated: none has a whole-path value above its value on the set. The basins handed on are
the last round's verified placements that run, and any faster placement the sample or an
earlier round found running, with the whole path's mu_path and branch (never a value of the
set). The work is bounded
before it starts (:mod:`solver.optimise.work`): SEARCH_ROUNDS evolutions on at most SET_ROWS
waypoints, and :func:`whole_path_checks` whole-path placements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress, span
from solver.optimise.active_set import ACTIVE_SET_RTOL, closure
from solver.optimise.coarse_rows import binding_rows
from solver.optimise.failures import Tried
from solver.optimise.methods.placement_scipy import (
    FULL_SEARCH,
    Basin,
    SearchSize,
    distinct_best,
    evolve,
)
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathProblem
from solver.path.subset import on_waypoints

MAX_SEARCH_ROWS = 1_000  # a longer program's differential evolution runs on a set
SET_ROWS = 300  # the most waypoints an evolution runs on (the set stops growing there)
SEARCH_ROUNDS = 3  # evolutions at most
SAMPLE_CELLS = 16  # placements of the box whose slowest waypoints make the first set
VERIFIED = 6  # distinct best placements of an evolution checked on the whole path


def on_rows(n_waypoints: int) -> bool:
    """Whether a program of ``n_waypoints`` is searched on a set of its waypoints."""
    return n_waypoints > MAX_SEARCH_ROWS


def whole_path_checks(basins: int) -> int:
    """The most whole-path placements a search on sets evaluates, keeping ``basins`` a round.

    The sample, and each round's verified placements twice (on the whole path's branch and on
    the set's).
    """
    return SAMPLE_CELLS + 2 * SEARCH_ROUNDS * max(VERIFIED, basins)


def searched_waypoints(n_waypoints: int) -> int:
    """The most waypoints one evolution of a path of ``n_waypoints`` evaluates a placement on."""
    return min(n_waypoints, SET_ROWS) if on_rows(n_waypoints) else n_waypoints


@dataclass(frozen=True)
class RowsSearch:
    """What the search on a set found.

    Attributes:
        basins: the verified placements, (decision vector, whole-path mu_path, branch index),
            best first, feasible on the whole path.
        generations: the evolutions' generations, summed.
        rows: the final set (whole-path waypoint indices).
        rounds: the evolutions made.
    """

    basins: list[Basin]
    generations: int
    rows: np.ndarray
    rounds: int


def sample(bounds: PlacementBounds) -> np.ndarray:
    """SAMPLE_CELLS decision vectors over the box: the centre, then a seeded uniform draw."""
    draw = np.random.default_rng(0).uniform(size=(SAMPLE_CELLS - 1, len(bounds.lower)))
    vectors = bounds.lower + draw * (bounds.upper - bounds.lower)
    return np.vstack([bounds.centre(), vectors])


def first_set(
    problem: PathProblem, bounds: PlacementBounds, runner: TaskRunner, tried: Tried | None = None
) -> tuple[np.ndarray, list[Basin]]:
    """The slowest waypoints of the whole path (or where it fails) at :func:`sample`'s placements.

    With their acceleration stencils (:func:`solver.optimise.active_set.closure`); where that
    is over SET_ROWS (long stencils), the first half along the path is kept until it is not:
    the rounds add what binds.

    Returns:
        the set, and the sample's placements that run on the whole path, as basins.
    """
    vectors = sample(bounds)
    placements = bounds.rows(vectors)
    found, whole = binding_rows(problem, placements, None, runner)
    if tried is not None:  # whole-path evaluations: kept for a failure's tally
        tried.record(placements, whole.reason, whole.failed_waypoint)
    rows = closure(problem, found, neighbours=False)
    while len(rows) > SET_ROWS and len(found) > 1:
        found = found[: len(found) // 2]
        rows = closure(problem, found, neighbours=False)
    return rows, _runs(vectors, whole.feed_index, whole.branch)


def _basins(last: list[Basin], earlier: list[Basin], count: int) -> list[Basin]:
    """The last round's placements that run, and any found before that is faster, best first.

    When the last round's best holds, nothing found before is above it (its value on the set
    is above every placement's whole-path value), so the basins are the last round's. When it
    does not (the rounds ran out, or none of them ran on the whole path), a faster placement
    of the sample or an earlier round is known to run and is handed on too.
    """
    top = max((value for _, value, _ in last), default=-np.inf)
    kept = last + [basin for basin in earlier if basin[1] > top]
    order = np.argsort([-value for _, value, _ in kept], kind="stable")
    return [kept[k] for k in order[:count]]


def _runs(vectors: np.ndarray, feed_index: np.ndarray, branch: np.ndarray) -> list[Basin]:
    """The placements whose whole-path value is finite, as basins (in their order)."""
    return [
        (vectors[k].copy(), float(feed_index[k]), int(branch[k]))
        for k in np.flatnonzero(np.isfinite(feed_index))
    ]


def search_on_rows(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    symmetric: bool,
    size: SearchSize = FULL_SEARCH,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> RowsSearch:
    """Differential evolution on a set of the waypoints, grown until its best holds (module doc).

    Args:
        problem: the whole problem (``auto`` branch).
        bounds: the box.
        symmetric: whether basins are told apart in (r, psi) (the arc symmetry).
        size: the evolution's size.
        progress: called with the fraction done.
        runner: where the placements run.
        tried: keeps the placements evaluated on the whole path (the sample that makes the
            first set, each round's best; not the evolutions on the set).
    """
    rows, earlier = first_set(problem, bounds, runner, tried)
    last: list[Basin] = []
    generations = 0
    for round_ in range(1, SEARCH_ROUNDS + 1):
        part = span(progress, (round_ - 1) / SEARCH_ROUNDS, round_ / SEARCH_ROUNDS)
        seen, steps = evolve(
            on_waypoints(problem, rows), bounds, size=size, progress=part, runner=runner
        )
        generations += steps
        best = np.array(distinct_best(seen, symmetric, max(VERIFIED, size.basins)), dtype=int)
        on_set = seen.mu[best]
        checked = bounds.rows(seen.vectors[best])
        added, whole = binding_rows(problem, checked, on_set, runner, rows, seen.branch[best])
        if tried is not None:
            tried.record(checked, whole.reason, whole.failed_waypoint)
        earlier += last
        last = _runs(seen.vectors[best], whole.feed_index, whole.branch)
        holds = best.size and whole.feed_index[0] >= on_set[0] * (1.0 - ACTIVE_SET_RTOL)
        grown = closure(problem, np.union1d(rows, added), neighbours=False)
        if holds or not added.size or round_ == SEARCH_ROUNDS or len(grown) > SET_ROWS:
            break
        rows = grown
    basins = _basins(last, earlier, size.basins)
    return RowsSearch(basins, generations, rows, round_)
