"""A map's quick refusal of a refused pick's next branches where the pick collided (issue 22).

:meth:`solver.path.cell.limit.CellLimit.refuses_at` refuses a joint path when coal finds the
refused pick's pair closer than the clearance less a margin at that waypoint: it must never
refuse a path the whole check admits (checked against :meth:`CellChecker.check` with
``reference=True``, coal at every configuration, on every feasible branch of the refused
placements), and the map must be the map without it, every field to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.spatial import Placement
from solver.path.capability_map import capability_map, grid_axis
from solver.path.limits import PathCheck
from solver.path.pipeline import run_chunk
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_cell_fast import _arm
from tests.solver.test_cell_pair_tables import ON_TABLE
from tests.solver.test_evaluate import load_path

AXES = {
    "xs": grid_axis(-0.25, 0.25, 0.05, field="x"),
    "ys": grid_axis(0.25, 0.65, 0.05, field="y"),
    "z": 0.1,
    "yaws": np.array([0.0, 0.6]),
}


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_quick_refusals_are_the_checks(name: str) -> None:
    """Every branch the hint refuses, coal at every configuration refuses too."""
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    limit = problem.path_checks[0]
    checker = limit.checker  # type: ignore[attr-defined]
    grid = np.array(np.meshgrid(AXES["xs"], AXES["ys"], [0.1], [0.0, 0.6], [0.0], indexing="ij"))
    placements = grid.reshape(5, -1).T
    run = run_chunk(problem, placements)
    quick = 0
    for c, placement in enumerate(placements):
        pick = int(run.pick[c])
        if run.tracked.reason[pick, c] != -1:
            continue
        refusal = limit.check(run.tracked.q[:, pick, c].T, placement, thorough=False)
        if refusal.failed_waypoint is None:
            continue
        transform = Placement(*placement[:4]).transform_workpiece_to_base()
        for b in np.flatnonzero(run.tracked.reason[:, c] == -1):
            q = run.tracked.q[:, b, c].T
            if limit.refuses_at(q, placement, refusal):
                quick += 1
                verdict = checker.check(
                    q, limit.segment_in_pass, transform, closest=False, reference=True
                )
                assert verdict.collision is not None
    assert quick >= 5  # the test saw the hint refuse


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_map_with_hints_equals_without(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The ERK path's map with the cell, every field to the bit, with and without the hint."""
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    hinted = capability_map(problem, **AXES)  # type: ignore[arg-type]
    limit = type(problem.path_checks[0])
    monkeypatch.setattr(limit, "refuses_at", PathCheck.refuses_at)
    plain = capability_map(problem, **AXES)  # type: ignore[arg-type]
    fields = [k for k, v in vars(hinted).items() if isinstance(v, np.ndarray)]
    assert "mu_path" in fields and "branch" in fields
    assert (hinted.reason == 4).any()  # some placements refused on every branch
    for field in fields:
        np.testing.assert_array_equal(getattr(hinted, field), getattr(plain, field), field)
