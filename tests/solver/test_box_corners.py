"""The box's corners as coarse cells (coarse_search.box_corners): each placement once.

A yaw range of a whole turn has its two ends one placement; before, both ends were corners,
and such pairs (and corners that were the map's own maxima) filled the refinement's starts
with the same placement twice (the optimiser audit, stop 53).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from solver.families import get_robot
from solver.optimise.coarse_search import coarse_cells, corner_vectors
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathProblem
from tests.solver.test_evaluate import load_path


def _one_placement(a: np.ndarray, b: np.ndarray) -> bool:
    """x, y, z within 0.1 mm; yaw and spin within 1e-4 rad modulo a turn (decision vectors)."""
    x, y, yaw, spin, z = np.abs(a - b)
    turned = [abs(math.remainder(angle, 2 * math.pi)) for angle in (yaw, spin)]
    return max(x, y, z, *turned) <= 1e-4


@pytest.mark.parametrize(
    ("yaw", "spin", "count"),
    [
        ((-1.0, 1.0), (0.0, 0.0), 8),
        ((-math.pi, math.pi), (0.0, 0.0), 4),
        ((-3.1416, 3.1416), (0.0, 0.0), 4),  # a whole turn as typed
        ((0.0, 4 * math.pi), (0.0, 0.0), 4),
        ((-math.pi, math.pi), (-math.pi, math.pi), 4),
        ((-1.0, 1.0), (-0.5, 0.5), 16),
    ],
)
def test_the_corners_are_distinct_placements(
    yaw: tuple[float, float], spin: tuple[float, float], count: int
) -> None:
    bounds = PlacementBounds(x=(0.0, 0.1), y=(0.4, 0.5), yaw=yaw, z=0.1, spin=spin)
    corners = corner_vectors(bounds)
    assert len(corners) == count
    for a, b in itertools.combinations(corners, 2):
        assert not _one_placement(a, b)
    assert all(bounds.contains(corner) for corner in corners)


@pytest.mark.parametrize("symmetric", [False, True])
def test_the_coarse_cells_hold_each_placement_once(symmetric: bool) -> None:
    bounds = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    cells = coarse_cells(problem, bounds, symmetric=symmetric, near=math.pi / 2)
    assert len(cells) > 4
    for a, b in itertools.combinations(cells, 2):
        assert not _one_placement(a.vector, b.vector), (a, b)
