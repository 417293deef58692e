"""A seven-joint map's work estimate counts the following its pruning leaves (issue 27).

A pruned map follows only the branches that can still be a cell's best, so its placement costs
less than an evaluation's (:meth:`NumericFamily.map_cost` against ``path_cost``). Seven joints
are pruned in one compiled pass (:mod:`solver.families.numeric.bounded_redundant_kernel`), its
share of the following (BOUNDED_MAP_SHARE) calibrated on CPU time, each waypoint it follows
FOLLOW_WITH_V_MAX times a plain one; arms of more joints in steps (:mod:`solver.path.pruning`:
every branch for its first piece of waypoints, then MAP_TAIL_SHARE past it). Here the
estimates are held, in counts, against the branch-waypoints the map really follows: the pass's
solutions, or every call of the family's ``follow_ranges`` (no timing), on seeded grids of the
Panda and the xArm7 (made to prune in steps for the latter).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from solver.core.codes import UNREACHABLE
from solver.families import get_robot
from solver.families.numeric.costs import (
    BOUNDED_MAP_SHARE,
    COST_LINES,
    FIRST_PIECE,
    FOLLOW_WITH_V_MAX,
    MAP_TAIL_SHARE,
)
from solver.families.numeric.family import NumericFamily
from solver.path import pruning
from solver.path.capability_map import map_cost
from solver.path.cell.cost import CELL_POSE_COST
from solver.path.cell.shapes import Cell, Halfspace
from solver.path.placements import evaluate_placements
from solver.path.problem import PathOptions, PathProblem
from tests.solver.families.test_numeric_pruned_map import stepped
from tests.solver.test_evaluate import load_path


def long_path(n: int) -> np.ndarray:
    """The curved line there and back, repeated to ``n`` waypoints."""
    line = load_path("curved_line")
    loop = np.concatenate([line, line[::-1][1:-1]])
    return np.concatenate([loop] * (n // len(loop) + 1))[:n]


def placements(seed: int) -> np.ndarray:
    """24 seeded placements around the arm's front, (24, 5)."""
    rng = np.random.default_rng(seed)
    xy = np.column_stack([rng.uniform(-0.25, 0.25, 24), rng.uniform(0.25, 0.65, 24)])
    return np.column_stack([xy, np.full(24, 0.1), rng.uniform(-0.5, 0.5, 24), np.zeros(24)])


def test_the_first_piece_is_the_prunings() -> None:
    assert FIRST_PIECE == pruning.PIECE


@pytest.mark.parametrize("name", ["panda", "xarm7"])
@pytest.mark.parametrize("n_waypoints", [133, 400])
def test_a_map_pruned_in_one_pass_follows_no_more_than_its_estimate_counts(
    name: str, n_waypoints: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = get_robot(name)
    family = robot.family
    assert isinstance(family, NumericFamily) and family.follows_bounded
    followed: list[int] = []
    found: list[int] = []
    follow_bounded = NumericFamily.follow_bounded

    def counted(self: NumericFamily, *args: Any) -> tuple[np.ndarray, ...]:
        result = follow_bounded(self, *args)
        status = result[1]  # (K, P, W): UNREACHABLE where not followed (or lost)
        followed.append(int(np.count_nonzero(status[..., 1:] != UNREACHABLE)))
        found.append(int(np.count_nonzero(status[..., 0] != UNREACHABLE)))
        return result

    monkeypatch.setattr(NumericFamily, "follow_bounded", counted)
    problem = PathProblem.of(robot, long_path(n_waypoints))
    evaluate_placements(problem, placements(seed=n_waypoints), prune=True)
    assert sum(found) > 0 and sum(followed) > 0
    share = sum(followed) / (sum(found) * (n_waypoints - 1))  # against every branch to the end
    assert 0.0 < share * FOLLOW_WITH_V_MAX <= BOUNDED_MAP_SHARE
    # The estimate budgets that share of the seven-joint line's following, and no less.
    [(seed, track)] = COST_LINES[7]
    budget = (map_cost(problem) - seed) / track
    assert budget >= share * FOLLOW_WITH_V_MAX * (n_waypoints - 1)
    assert map_cost(problem) < family.path_cost(n_waypoints)


@pytest.mark.parametrize("name", ["panda", "xarm7"])
@pytest.mark.parametrize("n_waypoints", [133, 400])
def test_a_map_pruned_in_steps_follows_no_more_than_its_estimate_counts(
    name: str, n_waypoints: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = stepped(get_robot(name), only=True)
    family = robot.family
    assert isinstance(family, NumericFamily)
    followed: list[int] = []
    found: list[int] = []
    follow_ranges, seed_first = NumericFamily.follow_ranges, NumericFamily.seed_first

    def counted_follow(self: NumericFamily, *args: Any) -> None:
        start, stop = args[3], args[4]
        followed.append(int(np.maximum(stop - np.maximum(start, 1), 0).sum()))
        follow_ranges(self, *args)

    def counted_seed(self: NumericFamily, *args: Any) -> tuple[np.ndarray, np.ndarray]:
        current, count = seed_first(self, *args)
        found.append(int(count.sum()))
        return current, count

    monkeypatch.setattr(NumericFamily, "follow_ranges", counted_follow)
    monkeypatch.setattr(NumericFamily, "seed_first", counted_seed)
    problem = PathProblem.of(robot, long_path(n_waypoints))
    cells = placements(seed=n_waypoints)
    evaluate_placements(problem, cells, prune=True)
    assert sum(found) > 0 and sum(followed) > 0
    first = sum(found) * (FIRST_PIECE - 1)  # waypoints 1..31 of every branch
    every = sum(found) * (n_waypoints - 1)  # following every branch to the end
    share = (sum(followed) - first) / (every - first)
    assert 0.0 < share <= MAP_TAIL_SHARE  # the following past the first piece, counted
    # The estimate budgets that share of the seven-joint line's following, and no less.
    [(seed, track)] = COST_LINES[7]
    budget = (map_cost(problem) - seed) / track - (FIRST_PIECE - 1)
    assert budget >= share * (n_waypoints - FIRST_PIECE)
    assert map_cost(problem) < family.path_cost(n_waypoints)


@pytest.mark.parametrize(
    "options",
    [
        {"spin_mode": "free"},
        {"cell": Cell(fixed=(Halfspace(normal=(0.0, 0.0, 1.0), offset=-1.0),))},
    ],
)
def test_a_map_that_cannot_prune_is_weighed_as_an_evaluation(options: dict[str, Any]) -> None:
    robot = get_robot("panda")
    family = robot.family
    assert family is not None
    problem = PathProblem.of(robot, long_path(133), PathOptions(**options))
    assert map_cost(problem) == problem.path_cost(133)
    if "cell" in options:
        # The check is added to the IK's work, not multiplied by it: far below the product.
        assert map_cost(problem) == family.path_cost(133) + CELL_POSE_COST * 133
        assert map_cost(problem) < 1.3 * family.path_cost(133)
