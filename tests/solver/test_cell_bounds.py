"""The pairs' closing rates (:func:`solver.path.cell.bounds.pair_weights`) bound coal's distances.

Conservative advancement skips a configuration only where sum_j w_pj |dq_j| is below the
slack, so every weight must bound how fast its pair's coal distance changes: checked here on
seeded random configuration pairs against coal (independent of the bounds), for the UR5
(meshes) and the UR5e (capsules), a tilted table and an upright one. The upright table's
factor |n x k| makes the first joint's weight zero for every part: the shoulder's coal
distance to it is the same at every configuration. The UR5's meshes are
not centred on their joints: a part's extent is taken about its bounding box's centre (the
weights of the upper arm and forearm were 0.29 and 0.26 m/rad for the elbow where their
points reach 0.50 and 0.44 m, and the first test failed on them).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from solver.core.robots import Robot
from solver.families import get_robot
from solver.path.cell.checker import CellChecker
from solver.path.cell.shapes import Box, Cell, Halfspace, Tool


def _pose(x: float, y: float, z: float) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, 3] = [x, y, z]
    return matrix


def _tooled(name: str) -> Robot:
    """The arm with its tool point at the end of _cell's 12 cm tool."""
    return get_robot(name).with_options(transform_tool_to_tcp=_pose(0.0, 0.0, 0.12))


def _cell(normal: tuple[float, float, float]) -> Cell:
    return Cell(
        fixed=(
            Halfspace(normal, -0.05, name="table"),
            Box((0.1, 0.1, 0.3), _pose(-0.3, 0.2, 0.15), name="fixture"),
        ),
        workpiece=(Box((0.3, 0.12, 0.09), _pose(0.0, 0.06, -0.045), name="part"),),
        tool=Tool(radius=0.03, length=0.12),
    )


def _distances(checker: CellChecker, q: np.ndarray) -> np.ndarray:
    """Coal's distance of every checked pair at q, the workpiece at the origin of {B}."""
    model, geometry = checker.robot.model, checker.geometry
    data, gdata = model.createData(), geometry.createData()
    pin.updateGeometryPlacements(model, data, geometry, gdata, q)
    found = [geometry.findCollisionPair(pin.CollisionPair(a, b)) for a, b in checker._pairs]
    return np.array([pin.computeDistance(geometry, gdata, k).min_distance for k in found])


@pytest.mark.parametrize("name", ["ur5e", "ur5"])
@pytest.mark.parametrize("normal", [(0.0, 0.0, 1.0), (0.3, 0.0, 1.0)])
def test_weights_bound_coal_distances(name: str, normal: tuple[float, float, float]) -> None:
    """|d(q') - d(q)| <= sum_j w_pj |q'_j - q_j| for every pair, on random nearby pairs."""
    checker = CellChecker(_tooled(name), _cell(normal))
    weights = checker._weights
    rng = np.random.default_rng(7)
    for _ in range(40):
        q = rng.uniform(-np.pi, np.pi, 6)
        moved = q + rng.normal(0.0, 0.05, 6) * (rng.random(6) < 0.5)
        before, after = _distances(checker, q), _distances(checker, moved)
        clear = (before > 0.0) & (after > 0.0)  # advancement starts from a distance, not a depth
        bound = weights @ np.abs(moved - q)
        assert np.all(np.abs(after - before)[clear] <= bound[clear] + 1e-6)


def test_first_joint_cannot_move_a_part_towards_an_upright_table() -> None:
    """The table's normal is the first joint's axis: no weight there, and coal agrees."""
    checker = CellChecker(_tooled("ur5e"), _cell((0.0, 0.0, 1.0)))
    table = checker._n_robot  # the first obstacle
    rows = [p for p, (_, b) in enumerate(checker._pairs) if b == table]
    assert rows and np.all(checker._weights[rows, 0] == 0.0)
    tilted = CellChecker(_tooled("ur5e"), _cell((0.3, 0.0, 1.0)))
    assert np.all(tilted._weights[rows, 0] > 0.0)  # the same pairs, a table the turn tilts to
    q = np.array([0.0, -1.2, 1.0, -0.5, 1.3, 0.2])
    turned = q + np.array([2.0, 0, 0, 0, 0, 0])
    before, after = _distances(checker, q)[rows], _distances(checker, turned)[rows]
    assert np.allclose(before, after, atol=1e-9)
    before, after = _distances(tilted, q)[rows], _distances(tilted, turned)[rows]
    assert not np.allclose(before, after, atol=1e-3)
