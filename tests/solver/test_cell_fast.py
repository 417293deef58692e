"""The compiled cell check gives the coal-only check's answers (issue 22).

The reference is :meth:`CellChecker.check` with ``reference=True`` (coal at every checked
configuration); the compiled sweep (a map's check) must give the same first collision
(configuration, robot part, obstacle, coal's distance), for the UR5 (its
URDF's meshes as convex hulls, bounded by capsules) and the UR5e (capsules, closed form), on
seeded random joint paths and placements in a cell with every primitive kind; and the same map
cell for cell.
"""

from __future__ import annotations

import numpy as np
import pytest

import solver.path.cell.checker as checker_module
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.path.capability_map import capability_map, grid_axis
from solver.path.cell.checker import CellChecker
from solver.path.cell.kinematics import substeps
from solver.path.cell.shapes import Box, Cell, Cylinder, Halfspace, Sphere, Tool
from solver.path.cell.verdict import CellVerdict
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_evaluate import load_path


def _pose(x: float, y: float, z: float) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, 3] = [x, y, z]
    return matrix


CELL = Cell(
    fixed=(
        Halfspace((0.0, 0.0, 1.0), -0.02, name="table"),
        Box((0.1, 0.1, 0.3), _pose(-0.3, 0.2, 0.15), name="fixture"),
        Sphere(0.08, _pose(0.35, -0.3, 0.3), name="ball"),
        Cylinder(0.05, 0.4, _pose(-0.2, -0.45, 0.2), name="post"),
    ),
    workpiece=(Box((0.3, 0.12, 0.09), _pose(0.0, 0.06, -0.045), name="part"),),
    tool=Tool(radius=0.03, length=0.12),
)


def _arm(name: str) -> Robot:
    return get_robot(name).with_options(transform_tool_to_tcp=_pose(0.0, 0.0, 0.12))


def _same(fast: CellVerdict, reference: CellVerdict) -> None:
    """The same contacts: waypoint, robot part, obstacle, and the distance to 1e-6 m.

    1e-6 m (cell.md s. 5): coal's GJK distances of meshes and cylinders depend on its warm start,
    which differs between ``computeDistances`` over every pair (the reference's evaluation)
    and ``computeDistance`` on one (here 3e-7 m apart on the same pair and configuration).
    """
    for ours, theirs in ((fast.collision, reference.collision), (fast.closest, reference.closest)):
        assert (ours is None) == (theirs is None)
        if ours is not None and theirs is not None:
            assert (ours.waypoint, ours.robot_part, ours.obstacle, ours.obstacle_name) == (
                theirs.waypoint,
                theirs.robot_part,
                theirs.obstacle,
                theirs.obstacle_name,
            )
            assert ours.distance == pytest.approx(theirs.distance, abs=1e-6)


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_fast_check_equals_coal_only(name: str) -> None:
    """Random smooth joint paths at random placements: identical verdicts, collisions included."""
    checker = CellChecker(_arm(name), CELL)
    rng = np.random.default_rng(7)
    collisions = clear = 0
    for _ in range(24):
        start = np.array([0.0, -1.6, 1.6, -1.6, -1.6, 0.0]) + rng.uniform(-0.9, 0.9, 6)
        turn = rng.uniform(-0.6, 0.6, 6)
        q = start + np.linspace(0.0, 1.0, 12)[:, None] * turn
        in_pass = np.ones(len(q) - 1, dtype=bool)
        in_pass[5] = False  # a rapid: no sub-steps across it
        placement = Placement(*rng.uniform(-0.3, 0.3, 2), 0.1, float(rng.uniform(-1, 1)))
        transform = placement.transform_workpiece_to_base()
        fast = checker.check(q, in_pass, transform, closest=False)
        _same(fast, checker.check(q, in_pass, transform, closest=False, reference=True))
        if fast.collision is not None:  # an evaluation (coal alone) finds the same collision
            _same(fast, checker.check(q, in_pass, transform, closest=True))
        collisions += fast.collision is not None
        clear += fast.collision is None
    assert collisions >= 4 and clear >= 4  # both kinds of answer are compared


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_fast_map_equals_coal_only(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The ERK path's map with the cell, cell for cell, against the coal-only map."""
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=CELL))
    axes = {
        "xs": grid_axis(-0.25, 0.25, 0.05, field="x"),
        "ys": grid_axis(0.25, 0.65, 0.05, field="y"),
        "z": 0.1,
        "yaws": np.array([0.0, 0.6]),
    }
    fast = capability_map(problem, **axes)  # type: ignore[arg-type]

    def coal_only(*args: object, **kwargs: object) -> None:
        raise NotImplementedError

    monkeypatch.setattr(checker_module.fast, "FastCell", coal_only)
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=CELL))
    reference = capability_map(problem, **axes)  # type: ignore[arg-type]
    np.testing.assert_array_equal(fast.reason, reference.reason)
    np.testing.assert_array_equal(fast.mu_path, reference.mu_path)
    assert (fast.reason == 4).any() or name == "ur5"


def test_compiled_substeps_equal_the_checkers() -> None:
    """The compiled sub-steps are CellChecker.configurations', float for float."""
    checker = CellChecker(_arm("ur5e"), CELL)
    rng = np.random.default_rng(3)
    q = np.cumsum(rng.uniform(-0.2, 0.2, (30, 6)), axis=0)
    in_pass = rng.uniform(size=29) > 0.2
    rows, owners = checker.configurations(q, in_pass)
    compiled_rows, compiled_owners = substeps(q, in_pass, CELL.collision_step)
    assert len(rows) > 60  # sub-steps were made
    np.testing.assert_array_equal(compiled_rows, rows)
    np.testing.assert_array_equal(compiled_owners, owners)


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_map_cells_taking_the_next_branch_equal_evaluate(name: str) -> None:
    """A map's cells whose best branch collides: the branch taken, as /v1/evaluate takes it.

    The map checks the refused cells of a chunk together (one pipeline run); evaluate checks
    one placement on its own, with coal alone (its own code path): same reason, branch,
    failed waypoint and mu_path.
    """
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=CELL))
    plain = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=Cell()))
    axes = {
        "xs": grid_axis(-0.25, 0.25, 0.1, field="x"),
        "ys": grid_axis(0.25, 0.65, 0.1, field="y"),
        "z": 0.1,
        "yaws": np.array([0.0, 0.6, 1.2, -0.6]),
    }
    cells = capability_map(problem, **axes)  # type: ignore[arg-type]
    free = capability_map(plain, **axes)  # type: ignore[arg-type]
    moved = (cells.reason == -1) & (free.reason == -1) & (cells.branch != free.branch)
    assert moved.any()  # some cell's best branch collides and another is taken
    refused = (cells.reason == 4) & (free.reason == -1)
    for index in zip(*np.nonzero(moved | refused), strict=True):
        _, yaw, iy, ix = index
        yaw_of = float(axes["yaws"][yaw])  # type: ignore[index]
        placement = Placement(float(axes["xs"][ix]), float(axes["ys"][iy]), 0.1, yaw_of)
        evaluation = evaluate_path(problem, placement)
        if cells.reason[index] == -1:
            assert evaluation.feasible
            assert evaluation.branch == problem.family.branches[cells.branch[index]]
            assert evaluation.mu_path == pytest.approx(cells.mu_path[index], rel=1e-12)
        else:
            assert (evaluation.reason, evaluation.failed_waypoint) == (
                "collision",
                cells.failed_waypoint[index],
            )
