"""UR5 as a plain URDF through the numeric family against the analytic UR family (robots.md 4).

A numeric family cannot promise every branch; measured on a map it must give the analytic
``auto`` mu_path on nearly every cell, and never more.
"""

from __future__ import annotations

import numpy as np

from solver.families import get_robot
from solver.path.capability_map import grid_axis
from tests.cases import NUMERIC_VS_ANALYTIC_AGREEMENT, NUMERIC_VS_ANALYTIC_RTOL
from tests.problems import capability_map
from tests.solver.families.test_numeric_ik import ur5_as_urdf
from tests.solver.test_evaluate import load_path


def test_ur5_urdf_map_equals_the_analytic_map() -> None:
    """The ERK map's extent (x -0.25..0.25, y 0.25..0.65, z 0.1) at 40 mm, two yaws."""
    path = load_path("curved_line")
    grid = {
        "xs": grid_axis(-0.25, 0.25, 0.04, field="x"),
        "ys": grid_axis(0.25, 0.65, 0.04, field="y"),
        "z": 0.1,
        "yaws": np.array([0.0, np.pi / 2]),
    }
    analytic = capability_map(get_robot("ur5"), path, **grid).mu_path.ravel()
    numeric = capability_map(ur5_as_urdf(), path, **grid, chunk=64).mu_path.ravel()
    feasible = np.isfinite(analytic)
    assert feasible.sum() > 100  # the comparison means something
    assert np.mean(feasible == np.isfinite(numeric)) >= NUMERIC_VS_ANALYTIC_AGREEMENT
    both = feasible & np.isfinite(numeric)
    relative = (numeric[both] - analytic[both]) / analytic[both]
    assert relative.max() <= NUMERIC_VS_ANALYTIC_RTOL  # never above
    equal = np.zeros(feasible.sum(), dtype=bool)
    equal[both[feasible]] = np.abs(relative) <= NUMERIC_VS_ANALYTIC_RTOL
    assert equal.mean() >= NUMERIC_VS_ANALYTIC_AGREEMENT
