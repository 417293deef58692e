"""The box's corners and edges as coarse cells (coarse_search.box_corners, box_edges).

A yaw range of a whole turn has its two ends one placement; before, both ends were corners,
and such pairs (and corners that were the map's own maxima) filled the refinement's starts
with the same placement twice (the optimiser audit, stop 53). And an optimum the bounds stop
on an edge, which the polar map samples poorly: the audit's UR5 box with two maxima along its
edge at the largest y and yaw, the casadi method on the worse one, 0.63 % below.
"""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest

from solver.core.spatial import Placement
from solver.families import get_robot
from solver.optimise.coarse_search import coarse_cells, corner_vectors, edge_lines
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
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


def test_the_coarse_cells_are_the_decimals_the_box_is_written_in() -> None:
    """A coarse cell (or edge point) may itself be the answer: its x and y are the floats nearest
    the box's lower bound plus whole steps of 0.02 in exact decimal arithmetic (Fractions of the
    numbers as written), as a map's grid is: -0.23, not -0.22999999999999998. In floats, 16 of
    the 26 values from -0.25 differ in their last bit, 18 of 26 from -0.3."""
    bounds = PlacementBounds(x=(-0.25, 0.25), y=(-0.3, 0.2), yaw=(2.5, 3.5), z=0.1)
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    cells = coarse_cells(problem, bounds, symmetric=False, near=math.pi / 2)
    step = Fraction("0.02")
    for variable, (low, high) in enumerate((bounds.x, bounds.y)):
        written = {float(Fraction(repr(low)) + i * step) for i in range(26)} | {low, high}
        values = {float(cell.vector[variable]) for cell in cells}
        assert len(values) > 3, values  # cells inside the box, not only its corners
        assert values <= written, values - written


def test_the_edge_lines_run_along_one_variable_from_each_corner() -> None:
    bounds = PlacementBounds(x=(0.0, 0.1), y=(0.4, 0.45), yaw=(-1.0, 1.0), z=0.1)
    lines = edge_lines(bounds)
    # 4 lines along each of x, y, yaw (the other two at either bound): 12 edges
    assert len(lines) == 12
    lower, upper = bounds.lower, bounds.upper
    for line in lines:
        inside = (line > lower + 1e-9) & (line < upper - 1e-9)
        assert np.all(inside.sum(axis=1) == 1)  # one variable inside, the others at a bound
        [variable] = set(np.flatnonzero(inside.any(axis=0)))
        steps = np.diff(line[:, variable])
        assert np.all(steps > 0) and np.all(steps <= (0.02 if variable < 2 else 0.2618) + 1e-9)
    # x: 0.02 .. 0.08 (4); y: 0.42, 0.44 (2); yaw: -1 + 15 deg k up to 0.833 (7); not the ends
    assert sorted(len(line) for line in lines) == [2] * 4 + [4] * 4 + [7] * 4
    turn = PlacementBounds(x=(0.0, 0.1), y=(0.4, 0.45), yaw=(-math.pi, math.pi), z=0.1)
    circles = [line for line in edge_lines(turn) if np.ptp(line[:, 2]) > 0]
    assert len(circles) == 4 and all(len(c) == 23 for c in circles)  # 24 steps less the corner


def test_an_optimum_on_an_edge_is_found() -> None:
    """The audit's box: the edge at the largest y and yaw holds two maxima along x."""
    problem = PathProblem.of(
        get_robot("ur5"), load_path("curved_line")[::4], PathOptions(max_joint_step=0.35)
    )
    bounds = PlacementBounds(
        x=(-0.4854, 0.066), y=(-0.7908, -0.4034), yaw=(0.953, 4.2744), z=0.2466
    )
    on_edge = evaluate_path(problem, Placement(-0.12364169718149783, -0.4034, 0.2466, 4.2744))
    assert on_edge.mu_path is not None
    optimum = optimize_placement(problem, bounds=bounds, method="casadi")
    assert optimum.mu_path is not None
    assert optimum.mu_path >= on_edge.mu_path * (1 - 1e-9)
