"""Numeric IK maps equal the analytic maps on every cell of an ERK-size map (issue 27).

The catalogue UR5's URDF read as a user's URDF, and an OPW arm's URDF written from its catalogue
parameters, both with the numeric family, against the same arms' analytic families: the same
reason and failing waypoint on every cell, mu_path to ``MU_RTOL``, and the joint path the
numeric map chooses is one of the analytic branches ``auto`` could choose there (the feasible
branches tied with the best within ``TIE_RTOL``: the numeric slots are numbered in seed order,
the analytic ones by name, so a tie may be broken towards another of the tied paths).
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.robots import Robot
from solver.families import get_robot
from solver.path.capability_map import grid_axis
from tests.solver.families.numeric_maps import (
    erk_placements,
    map_cells,
    opw_from_urdf,
    same_path,
    ur5_from_urdf,
)
from tests.solver.test_evaluate import load_path

# The two IKs agree to ~1e-12 in q; mu_path, a ratio of joint speeds, to ~1e-11 measured.
MU_RTOL = 1e-10
Q_ATOL = 1e-8
STEP = 0.02  # the ERK map's step: 21 x 26 = 546 placements
CASES = {
    # name: (the numeric arm, the analytic arm, x range, y range) of the map
    "ur5": (ur5_from_urdf, "ur5", (-0.25, 0.25), (0.25, 0.65)),
    "abb_irb2400": (lambda: opw_from_urdf("abb_irb2400"), "abb_irb2400", (0.6, 1.0), (-0.25, 0.25)),
}


@pytest.mark.parametrize("name", CASES)
def test_numeric_map_equals_analytic_map_on_every_cell(name: str) -> None:
    make_numeric, analytic_name, (x0, x1), (y0, y1) = CASES[name]
    numeric: Robot = make_numeric()
    placements = erk_placements(
        grid_axis(x0, x1, STEP, field="x"), grid_axis(y0, y1, STEP, field="y"), 0.1
    )
    assert len(placements) == 546
    path = load_path("curved_line")
    analytic = map_cells(get_robot(analytic_name), path, placements)
    ours = map_cells(numeric, path, placements)
    feasible = np.isfinite(analytic.mu_path)
    assert feasible.sum() > 400  # the comparison means something
    np.testing.assert_array_equal(ours.reason, analytic.reason)
    np.testing.assert_array_equal(ours.failed, analytic.failed)
    np.testing.assert_allclose(ours.mu_path, analytic.mu_path, rtol=MU_RTOL, atol=0)
    for cell in np.flatnonzero(feasible):
        assert any(same_path(ours.chosen[cell], q, Q_ATOL) for q in analytic.tied[cell]), cell
