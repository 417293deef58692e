"""What a search tried on the whole path, tallied by reason for a failure (issue 23's findings).

The outcome kept for each placement a search tried is checked against the evaluator
(``evaluate_path``, the numpy pipeline) at the same placement; the tally by construction.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from solver.core.codes import FEASIBLE, REASONS
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.optimise import coarse_rows
from solver.optimise.coarse_search import (
    coarse_cells,
    coarse_map_cells,
    corner_vectors,
    edge_lines,
)
from solver.optimise.failures import ReasonTally, Tried
from solver.optimise.methods import search_rows
from solver.optimise.methods.placement_scipy import FULL_SEARCH, global_search
from solver.optimise.search_space import PlacementBounds
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathProblem
from tests.solver.test_evaluate import load_path

# A UR5e whose first joint turns 2.5 rad only, around a box reaching past its arm: some
# placements run the path, others are out of reach or outside joint 1's range.
BOUNDS = PlacementBounds(x=(0.0, 0.6), y=(-0.4, 0.4), yaw=(-0.5, 0.5), z=0.1)


@pytest.fixture(scope="module")
def problem() -> PathProblem:
    robot = get_robot("ur5e")
    lower, upper = robot.q_lower.copy(), robot.q_upper.copy()
    lower[0], upper[0] = -0.5, 2.0
    limited = dataclasses.replace(robot, q_lower=lower, q_upper=upper)
    return PathProblem.of(limited, load_path("curved_line"))


def _agrees_with_the_evaluator(problem: PathProblem, tried: Tried, every: int) -> set[str]:
    """Each ``every``-th placement kept: its outcome is the evaluator's. The reasons met."""
    rows, reasons, waypoints = tried.outcomes()
    assert len(rows)
    met = set()
    picked = zip(rows[::every], reasons[::every], waypoints[::every], strict=True)
    for row, code, waypoint in picked:
        evaluation = evaluate_path(problem, Placement(*row.tolist()))
        expected = None if code == FEASIBLE else REASONS[code]
        assert (evaluation.reason, evaluation.failed_waypoint) == (
            expected,
            None if waypoint < 0 else waypoint,
        ), row
        met.add(str(evaluation.reason))
    return met


def test_the_coarse_maps_placements_are_kept_with_the_evaluators_outcome(
    problem: PathProblem,
) -> None:
    tried = Tried()
    coarse_cells(problem, BOUNDS, symmetric=False, near=0.0, tried=tried)
    met = _agrees_with_the_evaluator(problem, tried, every=17)
    assert {"None", "unreachable", "joint_limits"} <= met
    summary = tried.summary()
    assert summary is not None
    # 31 x 41 x 5 cells of 20 mm and 15 degrees (yaws -0.5 + 15 deg * k <= 0.5: k = 0..3, and
    # the range's end, 0.5)
    assert summary.placements == len(tried.outcomes()[0]) == 31 * 41 * 5
    assert summary.feasible + sum(t.count for t in summary.reasons) == summary.placements
    assert 0 < summary.feasible < summary.placements


def test_a_long_programs_map_on_a_set_keeps_only_what_it_evaluated_on_the_whole_path(
    problem: PathProblem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A program over MAX_MAP_ROWS (here 40 of the path's 133) is mapped on a set: its cells'
    first failing waypoints are the set's, so only the sample and verified cells are kept."""
    monkeypatch.setattr(coarse_rows, "MAX_MAP_ROWS", 40)
    tried = Tried()
    coarse_cells(problem, BOUNDS, symmetric=False, near=0.0, tried=tried)
    _agrees_with_the_evaluator(problem, tried, every=1)
    most = coarse_rows.SAMPLE_CELLS + coarse_rows.MAP_ROUNDS * coarse_rows.VERIFIED_CELLS
    assert coarse_rows.SAMPLE_CELLS <= len(tried.outcomes()[0]) <= most


def test_a_long_programs_evolution_on_a_set_keeps_only_what_it_checked_on_the_whole_path(
    problem: PathProblem,
) -> None:
    """The scipy method on a long program evolves on a set of its waypoints (here called on the
    path's 133 directly): only its sample and each round's best, checked on the whole path, are
    kept."""
    tried = Tried()
    search_rows.search_on_rows(problem, BOUNDS, symmetric=False, tried=tried)
    _agrees_with_the_evaluator(problem, tried, every=1)
    rounds, verified = search_rows.SEARCH_ROUNDS, search_rows.VERIFIED
    most = search_rows.SAMPLE_CELLS + rounds * max(verified, FULL_SEARCH.basins)
    assert search_rows.SAMPLE_CELLS <= len(tried.outcomes()[0]) <= most


def test_differential_evolutions_members_are_kept_with_the_evaluators_outcome(
    problem: PathProblem,
) -> None:
    tried = Tried()
    global_search(problem, BOUNDS, symmetric=False, tried=tried)
    met = _agrees_with_the_evaluator(problem, tried, every=7)
    assert {"None", "unreachable"} <= met


def test_the_tally_by_construction() -> None:
    assert Tried().summary() is None
    tried = Tried()
    rows = np.column_stack([np.arange(6.0), np.zeros((6, 4))])
    codes = [FEASIBLE, 1, 1, 0, 1, 0]  # joint_limits three times, unreachable twice
    tried.record(rows, np.array(codes), np.array([-1, 7, 5, 0, 5, 3]))
    tried.record(rows[:1], np.array([FEASIBLE]), np.array([-1]))  # again: kept once
    summary = tried.summary()
    assert summary is not None
    assert (summary.placements, summary.feasible) == (6, 1)
    assert summary.reasons == (
        ReasonTally("joint_limits", 3, 5),  # waypoint 5 twice, 7 once
        ReasonTally("unreachable", 2, 0),  # 0 and 3 once each: the lowest
    )
    ties = Tried()
    ties.record(rows[:2], np.array([3, 2]), np.array([-1, 4]))
    summary = ties.summary()
    assert summary is not None  # equal counts: in the order of REASONS; no waypoint: None
    assert summary.reasons == (ReasonTally("singular", 1, 4), ReasonTally("discontinuous", 1, None))


def test_the_coarse_map_samples_the_far_end_of_the_yaw_range() -> None:
    """A yaw range that is no whole number of coarse steps (15 degrees) ends in a sample of
    its own (an optimum the bounds stop lies on an edge); the lengths' 20 mm steps do not."""
    bounds = PlacementBounds(x=(-0.25, 0.26), y=(0.25, 0.655), yaw=(-0.5, 0.5), z=0.1)
    tried = Tried()
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line"))
    coarse_cells(problem, bounds, symmetric=False, near=0.0, tried=tried)
    rows = tried.outcomes()[0]
    beside = [corner_vectors(bounds), *edge_lines(bounds)]  # tried too, beside the map
    corners = bounds.rows(np.concatenate(beside))
    rows = rows[~(rows[:, None, :] == corners[None]).all(axis=2).any(axis=1)]
    xs, ys, yaws = (np.unique(rows[:, k].round(12)) for k in (0, 1, 3))
    # -0.25 + 0.02 k up to 0.25 (26); 0.25 + 0.02 k up to 0.65 (21); -0.5 + 15 deg k up to
    # 0.285 (4), then 0.5
    assert (len(xs), len(ys), len(yaws)) == (26, 21, 5)
    assert (xs[-1], ys[-1], yaws[-1]) == pytest.approx((0.25, 0.65, 0.5))
    # Where the last step stops within half a step (7.5 degrees) of the end, no sample is added:
    # -0.3, -0.038, 0.224 (0.076 rad short of 0.3); -0.5 .. 0.285 (0.215 short of 0.5), then 0.5
    # A whole turn adds nothing to its 24 steps (-pi to pi, both ends: 25).
    for yaw, samples in (((-0.3, 0.3), 3), ((-0.5, 0.5), 5), ((-math.pi, math.pi), 25)):
        box = PlacementBounds(x=(0.0, 0.0), y=(0.4, 0.4), yaw=yaw, z=0.1)
        assert coarse_map_cells(box, symmetric=False) == samples
