"""The optimisers' own pieces for a cell: where the (r, psi) symmetry holds, and the back-off."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.optimise.back_off import BACK_OFF_STEPS, back_off
from solver.optimise.candidate import Candidate
from solver.optimise.search_space import decision_vector
from solver.optimise.symmetry import symmetric_search
from solver.path.cell.shapes import Box, Cell, Halfspace
from solver.path.evaluate import evaluate_path
from tests.solver.test_cell import OPT_BOUNDS, TABLE, blocking_cell, pose, problem


def vector(x: float, y: float, yaw: float) -> np.ndarray:
    """A decision vector at the height of OPT_BOUNDS, spin 0."""
    return decision_vector(x=x, y=y, yaw=yaw, spin=0.0, z=0.1)


@pytest.fixture(scope="module")
def blocked() -> Cell:
    """test_cell's table and fixture at the velocity-best placement's elbow."""
    return Cell(fixed=blocking_cell()["shapes"])


TILTED = Halfspace((0.0, 0.1, 1.0), 0.0, name="a tilted floor")
UPSIDE_DOWN = Halfspace((0.0, 0.0, 1.0), -2.0, pose=np.diag([1.0, -1.0, -1.0, 1.0]))


@pytest.mark.parametrize(
    ("cell", "symmetric"),
    [
        (None, True),
        (Cell(), True),
        (Cell(fixed=(TABLE,)), True),
        (Cell(fixed=(UPSIDE_DOWN,)), True),  # its posed normal is -z: still about the axis
        (Cell(fixed=(TILTED,)), False),
        (Cell(fixed=(TABLE, Box((0.1, 0.1, 0.1), pose(0.3, 0.0, 0.3)))), False),
        (Cell(workpiece=(Box((0.1, 0.1, 0.1), pose(0.0, 0.0, -0.1)),)), True),  # turns along
    ],
)
def test_a_fixed_object_off_the_axis_breaks_the_symmetry(
    cell: Cell | None, symmetric: bool
) -> None:
    assert symmetric_search(problem(cell)) is symmetric


def test_a_fixture_makes_two_placements_of_one_arc_differ(blocked: Cell) -> None:
    """Why the symmetry is dropped: the same (r, psi), turned by -0.3 rad, hits the fixture."""
    best = vector(-0.1, 0.41, -0.3)  # the best collision-free cell of the 20 mm / 15 deg map
    r, theta = math.hypot(-0.1, 0.41), math.atan2(0.41, -0.1) - 0.3
    turned = vector(r * math.cos(theta), r * math.sin(theta), -0.6)
    table = [
        evaluate_path(problem(Cell(fixed=(TABLE,))), OPT_BOUNDS.placement(v))
        for v in (best, turned)
    ]
    assert table[0].mu_path == pytest.approx(table[1].mu_path, rel=1e-12)  # one arc
    here = evaluate_path(problem(blocked), OPT_BOUNDS.placement(best))
    there = evaluate_path(problem(blocked), OPT_BOUNDS.placement(turned))
    assert here.feasible and there.reason == "collision"
    assert there.collision is not None and there.collision.obstacle_name == "fixture"


def test_a_colliding_answer_is_backed_off_to_the_edge_of_the_fixture(blocked: Cell) -> None:
    cell = blocked
    start, end = vector(-0.1, 0.41, -0.3), vector(-0.1, 0.55, -0.3)
    assert evaluate_path(problem(cell), OPT_BOUNDS.placement(start)).feasible
    assert evaluate_path(problem(cell), OPT_BOUNDS.placement(end)).reason == "collision"
    backed = back_off(problem(cell), OPT_BOUNDS, start, Candidate(end, "IPOPT"))
    assert backed is not None
    assert evaluate_path(problem(cell), OPT_BOUNDS.placement(backed.vector)).feasible
    beyond = backed.vector + 2 * (end - start) / 2**BACK_OFF_STEPS
    assert evaluate_path(problem(cell), OPT_BOUNDS.placement(beyond)).reason == "collision"
    assert back_off(problem(None), OPT_BOUNDS, start, Candidate(end, "IPOPT")) is None
    assert back_off(problem(cell), OPT_BOUNDS, start, Candidate(start, "IPOPT")) is None
