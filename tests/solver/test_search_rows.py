"""The scipy method's differential evolution of a long program, on a set of its waypoints.

Issue 23: beyond MAX_SEARCH_ROWS waypoints differential evolution runs on the waypoints that
bind (solver/optimise/methods/search_rows.py), its best placements checked on the whole path
and the binding waypoints added until the best holds. The references: the whole-path search
(``active_set=False``, what the scipy method did before) on every optimiser test problem with
the threshold lowered so that they run on sets; the whole path's evaluation at every placement
the last evolution saw; and the work estimate, counted while a long program is searched.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from solver.families import get_robot
from solver.optimise import coarse_rows
from solver.optimise.methods import placement_scipy, scipy_method, search_rows
from solver.optimise.methods.placement_scipy import Seen
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.optimise.work import work_of
from solver.path.evaluate import evaluate_path
from solver.path.placements import evaluate_placements
from solver.path.problem import PathOptions, PathProblem
from tests.problems import problem
from tests.solver.test_active_set import ACTIVE_SET_RTOL, BOX, PROBLEMS
from tests.solver.test_evaluate import load_path

SET_PROBLEMS = [name for name in PROBLEMS if name != "half turn"]  # 2 waypoints: no set
DEFAULT_SEARCH_POSES = 6_100_000  # the service's DTF_MAX_SEARCH_POSES


def long_path(n_waypoints: int) -> np.ndarray:
    """The ERK curved line resampled to ``n_waypoints`` poses (positions and slerped turns)."""
    path = load_path("curved_line")
    at = np.linspace(0.0, len(path) - 1, n_waypoints)
    poses = np.tile(np.eye(4), (n_waypoints, 1, 1))
    poses[:, :3, :3] = Slerp(np.arange(len(path)), Rotation.from_matrix(path[:, :3, :3]))(
        at
    ).as_matrix()
    for k in range(3):
        poses[:, k, 3] = np.interp(at, np.arange(len(path)), path[:, k, 3])
    return poses


@pytest.mark.parametrize("name", SET_PROBLEMS)
def test_the_set_search_answer_is_the_whole_paths(
    monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    """Every optimiser test problem searched on sets: the whole-path search's optimum (1e-9)."""
    posed, bounds = PROBLEMS[name]
    whole = optimize_placement(posed, bounds=bounds, method="scipy", active_set=False)
    monkeypatch.setattr(search_rows, "MAX_SEARCH_ROWS", 8)
    sizes: list[int] = []
    evolve = search_rows.evolve

    def recorded(subset: PathProblem, *args: Any, **keywords: Any) -> tuple[Seen, int]:
        sizes.append(subset.prepared.n_waypoints)
        return evolve(subset, *args, **keywords)

    monkeypatch.setattr(search_rows, "evolve", recorded)
    on_sets = optimize_placement(posed, bounds=bounds, method="scipy", active_set=True)
    assert sizes and max(sizes) < posed.prepared.n_waypoints  # it ran on sets
    assert whole.found and on_sets.found
    assert on_sets.mu_path == pytest.approx(whole.mu_path, rel=ACTIVE_SET_RTOL)
    assert evaluate_path(posed, on_sets.placement).feed_index == on_sets.evaluation.feed_index


@pytest.mark.parametrize("first", ["sampled", "two waypoints"])
def test_the_best_holds_over_every_placement_of_the_last_evolution(
    monkeypatch: pytest.MonkeyPatch, first: str
) -> None:
    """The loop's best is the whole path's best of all the last evolution saw; basins are exact.

    From a first set of two waypoints (the path's first two, which bind nowhere) the loop must
    find the bottleneck itself: more than one round, and the final set holds it.
    """
    posed = problem(get_robot("ur5"), load_path("curved_line"))
    seen: list[Seen] = []
    evolve = search_rows.evolve

    def recorded(*args: Any, **keywords: Any) -> tuple[Seen, int]:
        found = evolve(*args, **keywords)
        seen.append(found[0])
        return found

    monkeypatch.setattr(search_rows, "evolve", recorded)
    if first == "two waypoints":
        monkeypatch.setattr(search_rows, "first_set", lambda *args: (np.array([0, 1]), []))
    found = search_rows.search_on_rows(posed, BOX, symmetric=True)
    best_vector, best_mu, _ = found.basins[0]
    if first == "two waypoints":
        assert found.rounds > 1
    whole = evaluate_placements(posed, BOX.rows(seen[-1].vectors))
    assert np.nanmax(whole.feed_index) <= best_mu * (1.0 + ACTIVE_SET_RTOL)
    for vector, mu, branch in found.basins:
        at = evaluate_placements(posed, BOX.rows(vector[None]))
        assert (at.feed_index[0], at.branch[0]) == (mu, branch)
    bottleneck = evaluate_path(posed, BOX.placement(best_vector)).bottleneck_waypoint
    assert bottleneck in found.rows


class Counted:
    """Placements evaluated, by the waypoints of their path, in the search's two places."""

    def __init__(self) -> None:
        self.evolution: Counter[int] = Counter()
        self.checks: Counter[int] = Counter()

    def wrap(self, counter: Counter[int], function: Callable[..., Any]) -> Callable[..., Any]:
        def counted(posed: PathProblem, rows: np.ndarray, *args: Any, **keywords: Any) -> Any:
            counter[posed.prepared.n_waypoints] += len(rows)
            return function(posed, rows, *args, **keywords)

        return counted


def test_a_long_program_is_searched_within_its_estimate(monkeypatch: pytest.MonkeyPatch) -> None:
    """1,500 waypoints: refused as a whole-path search, within the limit on sets; counted.

    The evolutions on sets of at most SET_ROWS waypoints, the whole-path checks within their
    phase of the estimate (:func:`solver.optimise.work.work_of`).
    """
    n = 1_500
    posed = PathProblem.of(get_robot("ur5"), long_path(n), PathOptions())
    bounds = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
    estimate = work_of(posed, bounds, method="scipy")
    assert estimate.weighed(posed) <= DEFAULT_SEARCH_POSES
    assert work_of(posed, bounds, method="scipy", active_set=False).weighed(posed) > (
        DEFAULT_SEARCH_POSES
    )
    counts = Counted()
    monkeypatch.setattr(
        placement_scipy,
        "evaluate_placements",
        counts.wrap(counts.evolution, placement_scipy.evaluate_placements),
    )
    checks = counts.wrap(counts.checks, coarse_rows.evaluate_placements)
    monkeypatch.setattr(coarse_rows, "evaluate_placements", checks)
    found = search_rows.search_on_rows(posed, bounds, symmetric=True)
    assert found.basins
    evolved = {size: count for size, count in counts.evolution.items() if size < n}
    assert max(evolved) <= search_rows.SET_ROWS
    assert sum(evolved.values()) <= estimate.placements("differential evolution")
    assert set(counts.checks) == {n}
    assert counts.checks[n] <= estimate.placements("differential evolution's whole-path checks")
    optimum = optimize_placement(
        posed, bounds=bounds, method="scipy", max_search_poses=DEFAULT_SEARCH_POSES
    )
    assert optimum.mu_path is not None and optimum.mu_path >= found.basins[0][1]
    assert scipy_method.rows_searched(posed, True)
