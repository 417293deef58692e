"""A long program's searches on sets of its waypoints, where the set runs a placement otherwise.

The coarse map of a long program (solver/optimise/coarse_rows.py) and the scipy method's
differential evolution (solver/optimise/methods/search_rows.py) run on a set of the waypoints,
check their best placements on the whole path and add the waypoints that bind there. The set's
``auto`` may run a placement on a branch other than the whole path's: one that fails at a
waypoint the set lacks. Found with a published 17,073-move program on a KUKA KR16 (the issue's
acceptance corpus): every placement both searches checked failed so, round after round, the
set never learnt why, and both answered the start (1.5924 m/s, '+0.0 %') where placements of
1.77-1.79 m/s run. The references: the whole path evaluated on one branch (the evaluator, not
the loop), and the whole path at the sample's placements.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from solver.core.parallel import SERIAL
from solver.core.spatial import Placement
from solver.core.tool_axis import poses_from_tool_axes
from solver.families import get_robot
from solver.optimise import coarse_rows
from solver.optimise.coarse_rows import binding_rows, map_values
from solver.optimise.methods import search_rows
from solver.optimise.methods.placement_scipy import Seen
from solver.optimise.search_space import PlacementBounds
from solver.path.evaluate import evaluate_path
from solver.path.placements import evaluate_placements
from solver.path.problem import PathOptions, PathProblem

# A placement of the KR16 where the whole path runs on branch 0 and the branches shoulder back,
# elbow down fail (a step over the bound, 'discontinuous') at waypoint 98 of the boss path.
PLACEMENT = np.array([[0.789, -0.14, 0.0, -0.112, 0.0]])
FAILING_BRANCH = 6
BOSS_BOX = PlacementBounds(x=(0.5, 0.8), y=(-0.2, 0.2), yaw=(-math.pi, math.pi), z=0.0)
# The same box reaching out to 3 m, where the KR16 (1.6 m) reaches nothing.
FAR_BOX = PlacementBounds(x=(0.5, 3.0), y=(-0.2, 0.2), yaw=(-math.pi, math.pi), z=0.0)


def boss_path() -> np.ndarray:
    """Three quarters of a turn around a 50 mm boss, the tool tilted 0.4 rad towards its axis."""
    turn = np.linspace(0.0, 1.5 * math.pi, 150, endpoint=False)
    tips = np.column_stack([0.05 * np.cos(turn), 0.05 * np.sin(turn), np.zeros_like(turn)])
    tilt = math.sin(0.4)
    axes = np.column_stack(
        [tilt * np.cos(turn), tilt * np.sin(turn), np.full_like(turn, math.cos(0.4))]
    )
    poses, _ = poses_from_tool_axes(tips, axes)
    return poses


@pytest.fixture(scope="module")
def boss() -> PathProblem:
    return PathProblem.of(get_robot("kuka_kr16_2"), boss_path(), PathOptions(spin_mode="fixed"))


def test_a_placement_the_set_ran_on_a_failing_branch_adds_where_that_branch_fails(
    boss: PathProblem,
) -> None:
    """The set ran the placement on a branch that fails on the whole path at waypoint 98; the
    whole path runs it on branch 0 and names other waypoints. The rows added name 97 and 98 (the
    step into 98), so the next set fails that branch there too."""
    whole = evaluate_placements(boss, PLACEMENT)
    assert np.isfinite(whole.feed_index[0]) and whole.branch[0] != FAILING_BRANCH
    branch = boss.family.branches[FAILING_BRANCH]
    failing = evaluate_path(boss.with_options(branch=branch), boss_placement())
    assert (failing.reason, failing.failed_waypoint) == ("discontinuous", 98)
    rows = np.array([0, 1, 2])
    above = np.array([10.0])  # its value on the set: above any on the whole path
    own, _ = binding_rows(boss, PLACEMENT, above, SERIAL, rows)
    assert 98 not in own, "the whole path's own branch names 98: the case no longer tests this"
    added, _ = binding_rows(boss, PLACEMENT, above, SERIAL, rows, np.array([FAILING_BRANCH]))
    assert {97, 98} <= set(added.tolist())
    assert set(own.tolist()) <= set(added.tolist())


def boss_placement() -> Placement:
    """PLACEMENT (a placement row: x, y, z, yaw, spin) as a Placement."""
    x, y, z, yaw, spin = PLACEMENT[0]
    return Placement(x, y, z, yaw, spin=spin)


def test_the_searchs_basins_are_the_samples_when_no_verified_placement_runs(
    boss: PathProblem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every placement the evolutions propose fails on the whole path (out of reach, with a
    made-up value on the set): the basins are the sample's placements that run, best first,
    each with its whole-path value and branch (before: none, and the answer was the start)."""
    far = FAR_BOX.upper.copy()

    def unreachable(problem: PathProblem, bounds: PlacementBounds, **_: Any) -> tuple[Seen, int]:
        vectors = np.repeat(far[None], 3, axis=0)
        vectors[:, 1] = [-0.2, 0.0, 0.2]
        return Seen(vectors, np.full(3, 9.0), np.zeros(3, dtype=int)), 1

    monkeypatch.setattr(search_rows, "evolve", unreachable)
    found = search_rows.search_on_rows(boss, FAR_BOX, symmetric=True)
    sample = search_rows.sample(FAR_BOX)
    at_sample = evaluate_placements(boss, FAR_BOX.rows(sample))
    runs = np.flatnonzero(np.isfinite(at_sample.feed_index))
    assert runs.size and runs.size < len(sample)  # some of the box runs, some does not
    assert found.basins
    values = [mu for _, mu, _ in found.basins]
    assert values == sorted(values, reverse=True)
    assert values[0] == np.nanmax(at_sample.feed_index)
    for vector, mu, branch in found.basins:
        at = evaluate_placements(boss, FAR_BOX.rows(vector[None]))
        assert (at.feed_index[0], at.branch[0]) == (mu, branch)


def test_the_coarse_maps_cells_are_the_samples_when_no_maximum_runs(
    boss: PathProblem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A map on a set whose maxima all fail on the whole path (here: the cells out of reach):
    the cells handed on are the sample's that run, with their whole-path values (before: none)."""
    monkeypatch.setattr(coarse_rows, "MAX_MAP_ROWS", 20)
    xs = np.linspace(0.5, 3.0, 11)
    grid = np.array([[x, y, 0.0, yaw, 0.0] for x in xs for y in (-0.2, 0.2) for yaw in (0.0, 2.0)])
    far = np.flatnonzero(grid[:, 0] > 2.5)

    def far_maxima(values: np.ndarray) -> list[int]:
        return [int(k) for k in far]

    mapped = map_values(boss, grid, far_maxima)
    whole = evaluate_placements(boss, grid)
    assert not np.isfinite(whole.feed_index[far]).any()
    kept = np.flatnonzero(np.isfinite(mapped.feed_index))
    assert kept.size
    assert np.array_equal(mapped.feed_index[kept], whole.feed_index[kept])
    assert np.array_equal(mapped.branch[kept], whole.branch[kept])
    sample = np.unique(np.linspace(0, len(grid) - 1, coarse_rows.SAMPLE_CELLS).round().astype(int))
    assert np.nanmax(mapped.feed_index) == np.nanmax(whole.feed_index[sample])
