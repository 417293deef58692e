"""A chunk's paths checked in one compiled call give the single checks' verdicts (issue 22).

:meth:`CellChecker.check_many` (:mod:`solver.path.cell.batch`) against the coal-only reference
(:meth:`CellChecker.check` with ``reference=True``), path by path, with ``workpiece`` objects of
every kind (they move with each path's placement); its per-placement obstacle arrays against
the single check's pack; and the checkers shared by content (:mod:`solver.path.cell.cache`).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

from solver.core.family import Branch
from solver.core.spatial import Placement
from solver.path.capability_map import capability_map, grid_axis
from solver.path.cell import sweep
from solver.path.cell.batch import placed_obstacles
from solver.path.cell.cache import checker_for
from solver.path.cell.checker import CellChecker
from solver.path.cell.limit import workpiece_to_base
from solver.path.cell.shapes import Box, Cell, Cylinder, Halfspace, Mesh, Sphere, Tool
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_cell_fast import CELL, _arm, _pose, _same
from tests.solver.test_evaluate import load_path


def _turned(x: float, y: float, z: float, angle: float) -> np.ndarray:
    """A pose at (x, y, z) turned by ``angle`` about (1, 1, 1)."""
    axis = np.ones(3) / np.sqrt(3.0)
    skew = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    pose = _pose(x, y, z)
    pose[:3, :3] = np.eye(3) + np.sin(angle) * skew + (1 - np.cos(angle)) * skew @ skew
    return pose


_TETRAHEDRON = np.array(
    [
        [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]],
        [[0.0, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
        [[0.0, 0.0, 0.0], [0.0, 0.0, 0.1], [0.1, 0.0, 0.0]],
        [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
    ]
)
MOVING = Cell(
    fixed=CELL.fixed,
    workpiece=(
        Box((0.3, 0.12, 0.09), _turned(0.0, 0.06, -0.045, 0.3), name="part"),
        Sphere(0.06, _pose(0.25, 0.1, 0.2), name="ball"),
        Cylinder(0.04, 0.3, _turned(-0.25, 0.1, 0.1, 0.7), name="post"),
        Halfspace((0.3, -0.2, 1.0), -0.35, name="slope"),
        Mesh(_TETRAHEDRON, _turned(0.1, -0.2, 0.3, 1.1), name="wedge"),
    ),
    tool=Tool(radius=0.03, length=0.12),
)


def _paths(count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Seeded smooth joint paths (N, 12, 6), their passes (11,) and placements (N, 5)."""
    rng = np.random.default_rng(seed)
    start = np.array([0.0, -1.6, 1.6, -1.6, -1.6, 0.0]) + rng.uniform(-0.9, 0.9, (count, 6))
    turn = rng.uniform(-0.6, 0.6, (count, 6))
    paths = start[:, None] + np.linspace(0.0, 1.0, 12)[None, :, None] * turn[:, None]
    in_pass = np.ones(11, dtype=bool)
    in_pass[5] = False  # a rapid: no sub-steps across it
    placements = np.column_stack(
        [
            rng.uniform(-0.3, 0.3, (count, 2)),
            np.full(count, 0.1),
            rng.uniform(-1.0, 1.0, count),
            np.zeros(count),
        ]
    )
    return paths, in_pass, placements


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_batched_check_equals_coal_only(name: str) -> None:
    """Every path's verdict from one call equals its own coal-only check, collisions included."""
    checker = CellChecker(_arm(name), MOVING)
    paths, in_pass, placements = _paths(30, seed=11)
    transforms = workpiece_to_base(placements)
    verdicts = checker.check_many(paths, in_pass, transforms)
    for q, transform, verdict in zip(paths, transforms, verdicts, strict=True):
        _same(verdict, checker.check(q, in_pass, transform, closest=False, reference=True))
    collisions = sum(v.collision is not None for v in verdicts)
    assert 4 <= collisions <= len(verdicts) - 4  # both kinds of answer are compared
    assert any(v.collision is not None and v.collision.obstacle_name in ("ball", "post", "slope",
               "wedge") for v in verdicts)  # fmt: skip  # a moved object of another kind hits


def test_transforms_are_the_placements() -> None:
    """T_B_O of the batch: Placement.transform_workpiece_to_base's floats, bit for bit."""
    _, _, placements = _paths(20, seed=5)
    for row, transform in zip(placements, workpiece_to_base(placements), strict=True):
        expected = Placement(*(float(v) for v in row[:4])).transform_workpiece_to_base()
        np.testing.assert_array_equal(transform, expected)


def test_placed_obstacles_equal_the_single_pack() -> None:
    """The per-placement obstacle arrays equal the single check's pack at each placement."""
    checker = CellChecker(_arm("ur5e"), MOVING)
    fast = checker._fast
    assert fast is not None
    _, _, placements = _paths(6, seed=2)
    transforms = workpiece_to_base(placements)
    import pinocchio as pin

    placed = [checker._world_to_base * pin.SE3(t) for t in transforms]
    moved = {gid - checker._n_robot: [at * pose for at in placed]
             for gid, pose in checker._workpiece_ids}  # fmt: skip
    world = {k: np.array([at.homogeneous for at in poses]) for k, poses in moved.items()}
    batch = placed_obstacles(fast, world, len(placements))
    for c in range(len(placements)):
        single = fast.obstacle_pack({k: poses[c] for k, poses in moved.items()})
        for ours, theirs in zip(batch, (single[1], single[2], single[3], single[4], single[8]),
                                strict=True):  # fmt: skip
            np.testing.assert_allclose(ours[c], theirs, rtol=0.0, atol=1e-15)


def test_checkers_are_shared_by_content() -> None:
    """Equal robots and cells (other objects) share a checker; a change of either does not."""
    first = checker_for(_arm("ur5e"), Cell(fixed=CELL.fixed, tool=Tool(0.03, 0.12)))
    again = checker_for(_arm("ur5e"), Cell(fixed=CELL.fixed, tool=Tool(0.03, 0.12)))
    assert again is first
    others = [
        checker_for(_arm("ur5e"), Cell(fixed=CELL.fixed, tool=Tool(0.03, 0.12), clearance=0.01)),
        checker_for(_arm("ur5e"), Cell(fixed=CELL.fixed[:1], tool=Tool(0.03, 0.12))),
        checker_for(_arm("ur5e"), Cell(fixed=CELL.fixed, tool=Tool(0.03, 0.11))),
        checker_for(
            _arm("ur5e").with_options(transform_tool_to_tcp=_pose(0.0, 0.0, 0.15)),
            Cell(fixed=CELL.fixed, tool=Tool(0.03, 0.12)),
        ),
        checker_for(_arm("ur10e"), Cell(fixed=CELL.fixed, tool=Tool(0.03, 0.12))),
    ]
    assert len({id(first), *map(id, others)}) == 1 + len(others)


def _ball_at_the_elbow(problem: PathProblem, placement: Placement, branch: Branch) -> Cell:
    """``problem``'s cell and a ball around ``branch``'s elbow at its first waypoint there.

    The elbow's position from pinocchio's forward kinematics of the branch's joint path (the
    robot's base is its model's world): that branch collides there, others may not.
    """
    run = evaluate_path(problem.with_options(branch=branch, cell=Cell()), placement)
    assert run.q is not None
    model = problem.robot.model
    data = model.createData()
    pin.forwardKinematics(model, data, run.q[0])
    elbow = data.oMi[model.getJointId("elbow_joint")].translation
    ball = Sphere(0.05, _pose(*elbow), name="ball at an elbow")
    return dataclasses.replace(problem.options.cell, fixed=(*problem.options.cell.fixed, ball))


def test_free_spin_map_cells_equal_evaluate() -> None:
    """Free spin (each branch's run: its spin schedule's path): map cells = evaluate's answers.

    The cell's table collides with the elbow-down branches, which tie the elbow-up ones exactly
    in free spin here (the first in the family's order taken: up); a ball around an elbow-up
    branch's elbow makes best branches collide, so that the next one is taken.
    """
    problem = PathProblem.of(
        _arm("ur5e"), load_path("curved_line"), PathOptions(cell=CELL, spin_mode="free")
    )
    xs, ys = grid_axis(-0.2, 0.2, 0.1, field="x"), grid_axis(0.3, 0.6, 0.1, field="y")
    plain = capability_map(
        problem.with_options(cell=Cell()), xs=xs, ys=ys, z=0.1, yaws=np.array([0.0])
    )
    best = problem.family.branches[plain.branch[0, 0, 1, 0]]
    cell = _ball_at_the_elbow(problem, Placement(-0.2, 0.4, 0.1, 0.0), best)
    problem = problem.with_options(cell=cell)
    cells = capability_map(problem, xs=xs, ys=ys, z=0.1, yaws=np.array([0.0]))
    for index in zip(*np.nonzero(np.ones_like(cells.reason, dtype=bool)), strict=True):
        _, _, iy, ix = index
        evaluation = evaluate_path(problem, Placement(float(xs[ix]), float(ys[iy]), 0.1, 0.0))
        assert evaluation.feasible == (cells.reason[index] == -1)
        if evaluation.feasible:
            assert evaluation.branch == problem.family.branches[cells.branch[index]]
            assert evaluation.mu_path == pytest.approx(cells.mu_path[index], rel=1e-12)
        else:
            assert evaluation.failed_waypoint == cells.failed_waypoint[index]
    assert (cells.reason == -1).sum() >= 4
    assert (cells.reason != -1).any()  # every branch collides at the ball's placement
    taken = (cells.reason == -1) & (plain.reason == -1) & (cells.branch != plain.branch)
    assert taken.any()  # a best branch collides: the next one taken
    # The map's batch and evaluate's walk share the sweep's one compiled signature (a second one
    # doubled its compile time, 20 s of CPU, in every process that ran both). Counted in this
    # process and in numba's disk cache: a caller loaded from the cache links the sweep in
    # without the sweep's own dispatcher ever seeing a call.
    assert len(_compiled_signatures(sweep.first_due)) == 1


def _compiled_signatures(kernel: Any) -> set[Any]:
    """The argument types ``kernel`` is compiled for: in this process and in its disk cache."""
    on_disk = kernel._cache._cache_file._load_index()  # numba's index: (signature, target, ...)
    return set(kernel.signatures) | {key[0] for key in on_disk}


def test_a_chunk_without_feasible_placements() -> None:
    """No path to check (nothing feasible in a chunk): no verdict, the map's cells unchanged."""
    checker = CellChecker(_arm("ur5e"), MOVING)
    assert (
        checker.check_many(np.zeros((0, 12, 6)), np.ones(11, dtype=bool), np.zeros((0, 4, 4))) == []
    )
    problem = PathProblem.of(_arm("ur5e"), load_path("curved_line"), PathOptions(cell=CELL))
    far = capability_map(
        problem, xs=np.array([3.0, 3.1]), ys=np.array([3.0]), z=0.1, yaws=np.array([0.0])
    )
    assert (far.reason == 0).all()  # unreachable, as without a cell
