"""The self pairs' tabulated bounds (solver.path.cell.pair_tables, issue 22).

Independent check: coal's distance of the two parts at seeded random configurations (the
reference's own call on the full geometry) is never below the table's bound; and the map with
the tables is the map without them and the coal-only map, cell for cell.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import solver.path.cell.cache as cache_module
import solver.path.cell.fast as fast_module
import solver.path.cell.pair_tables as pair_tables_module
from solver.path.capability_map import capability_map, grid_axis
from solver.path.cell import kept_tables
from solver.path.cell.checker import CellChecker
from solver.path.cell.fast import MARGIN
from solver.path.cell.kept import Kept
from solver.path.cell.pair_tables import build_tables, empty_tables, table_bound
from solver.path.cell.robot_geometry import robot_geometry
from solver.path.cell.shapes import Halfspace, Tool
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_cell_fast import CELL, _arm
from tests.solver.test_evaluate import load_path


def test_table_bounds_are_below_coal() -> None:
    """UR5 meshes: each tabulated pair's bound <= coal's distance at 3000 random configurations.

    The configurations span two turns (the tables wrap) and include grid points and the
    midpoints between them (where the bound's margin is largest).
    """
    checker = CellChecker(_arm("ur5"), CELL)
    assert checker._fast is not None
    tables, pairs = checker._fast.tables, checker._fast.pairs
    objects = checker.geometry.geometryObjects
    names = {
        (objects[int(pairs[p, 0])].name, objects[int(pairs[p, 1])].name)
        for p in np.flatnonzero(tables[0] >= 0)
    }
    assert {
        ("base_link_0", "upper_arm_link_0"),
        ("forearm_link_0", "wrist_2_link_0"),
        ("wrist_1_link_0", "wrist_3_link_0"),
        ("forearm_link_0", "wrist_3_link_0"),  # three joints: wrist 3 as its swept cylinder
    } <= names
    model = checker.robot.model
    geometry, gdata, data = checker._coal_data.at(pin.SE3.Identity())
    rng = np.random.default_rng(11)
    near = CELL.clearance + MARGIN
    for p in np.flatnonzero(tables[0] >= 0):
        t = int(tables[0][p])
        step = 2.0 * np.pi / tables[2][t]
        q_all = rng.uniform(-2.0 * np.pi, 2.0 * np.pi, (3000, model.nq))
        for d in range(2):  # a third on grid points, a third half-way between
            if tables[2][t, d] == 1:
                continue  # a one-joint table
            k = int(tables[1][t, d])
            grid = rng.integers(-2 * tables[2][t, d], 2 * tables[2][t, d], 3000) * step[d]
            q_all[:1000, k] = grid[:1000]
            q_all[1000:2000, k] = grid[1000:2000] + step[d] / 2.0
        proven = 0
        for q in q_all:
            pin.updateGeometryPlacements(model, data, geometry, gdata, q)
            distance = pin.computeDistance(geometry, gdata, int(p)).min_distance
            bound = table_bound(t, q, tables, MARGIN)
            assert bound <= distance
            proven += bound > near
        assert proven > 0  # the bound is not vacuous


# The robot on the table top (z = 0, as bench/cell.py's): the UR5's upper arm comes within the
# clearance of its base at some cells (collisions a table decides against).
ON_TABLE = dataclasses.replace(
    CELL, fixed=(Halfspace((0.0, 0.0, 1.0), 0.0, name="table"), *CELL.fixed[1:])
)


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_map_with_tables_equals_without(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The ERK path's map with the cell: the same answer with the tables, without, coal only."""
    axes = {
        "xs": grid_axis(-0.25, 0.25, 0.05, field="x"),
        "ys": grid_axis(0.25, 0.65, 0.05, field="y"),
        "z": 0.1,
        "yaws": np.array([0.0, 0.6]),
    }
    monkeypatch.setattr(cache_module, "_checkers", Kept(cache_module.MAX_CHECKERS))
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    tabled = capability_map(problem, **axes)  # type: ignore[arg-type]
    assert (problem.path_checks[0].checker._fast.tables[0] >= 0).any() == (name == "ur5")

    def no_tables(*args: object, **kwargs: object) -> tuple[np.ndarray, ...]:
        return empty_tables(len(args[3]))  # type: ignore[arg-type]

    monkeypatch.setattr(fast_module, "build_tables", no_tables)
    monkeypatch.setattr(cache_module, "_checkers", Kept(cache_module.MAX_CHECKERS))
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    plain = capability_map(problem, **axes)  # type: ignore[arg-type]
    assert not (problem.path_checks[0].checker._fast.tables[0] >= 0).any()

    def coal_only(*args: object, **kwargs: object) -> None:
        raise NotImplementedError

    monkeypatch.setattr(fast_module, "FastCell", coal_only)
    monkeypatch.setattr(cache_module, "_checkers", Kept(cache_module.MAX_CHECKERS))
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    reference = capability_map(problem, **axes)  # type: ignore[arg-type]
    assert problem.path_checks[0].checker._fast is None
    for field in ("reason", "mu_path", "branch", "failed_waypoint"):
        np.testing.assert_array_equal(getattr(tabled, field), getattr(plain, field))
        np.testing.assert_array_equal(getattr(tabled, field), getattr(reference, field))
    assert (tabled.reason == 4).any() or name == "ur5e"


def test_tables_made_at_first_use_and_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    """An evaluation makes no table; a map makes the UR5's once; other cells reuse them.

    Another cell (other obstacles, so other checked pairs) makes none; a larger clearance checks
    the same pairs (the self pairs are those apart at q = 0 by more than a fixed TOUCH, not by
    the clearance) and makes only the tables of the pairs it tabulates anew (capsules within
    the clearance more often). The kept tables equal those each checker makes with nothing
    kept, bit for bit.
    """
    made: list[int] = []
    tabulate = pair_tables_module._tabulate

    def counted(*args: object) -> np.ndarray:
        made.append(1)
        return tabulate(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(pair_tables_module, "_tabulate", counted)
    kept_tables.forget()
    arm = _arm("ur5")
    first = CellChecker(arm, CELL)
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (6, 6))
    first.check(q, np.ones(5, dtype=np.bool_), np.eye(4), closest=True)  # coal alone
    assert first._fast is not None and not made
    seen = _tabled(first)
    assert len(seen) >= 4 and len(made) == len(seen)
    for cell in (
        dataclasses.replace(ON_TABLE, workpiece=()),
        dataclasses.replace(ON_TABLE, clearance=CELL.clearance + 0.05),
    ):
        before = len(made)
        checker = CellChecker(arm, cell)
        assert checker._fast is not None
        if cell.clearance == ON_TABLE.clearance:
            assert len(checker._fast.pairs) != len(first._fast.pairs)
        else:  # the same pairs as at the table's own clearance
            at_own = CellChecker(arm, ON_TABLE)._fast
            assert at_own is not None
            np.testing.assert_array_equal(checker._fast.pairs, at_own.pairs)
        kept = checker._fast.tables
        assert len(made) - before == len(_tabled(checker) - seen)
        seen |= _tabled(checker)
        model, geometry, weights, near, _ = checker._fast._table_inputs
        pairs = checker._fast.pairs
        fresh = build_tables(model, geometry, checker._fast.robot, pairs, weights, near)
        for ours, theirs in zip(kept, fresh, strict=True):
            np.testing.assert_array_equal(ours, theirs)
    assert len(seen) > len(_tabled(first))  # the larger clearance tabulates more pairs


def _tabled(checker: CellChecker) -> set[tuple[str, str]]:
    """The names of the checker's tabulated pairs (its tables made here)."""
    assert checker._fast is not None
    objects, pairs = checker.geometry.geometryObjects, checker._fast.pairs
    return {
        (objects[int(pairs[p, 0])].name, objects[int(pairs[p, 1])].name)
        for p in np.flatnonzero(checker._fast.tables[0] >= 0)
    }


def test_part_keys_name_the_arm_and_the_tool() -> None:
    """The arm's parts' keys do not change with the tool; the tool's do; another arm's differ."""
    short = robot_geometry(_arm("ur5"), tool=Tool(radius=0.03, length=0.12), link_radii=None)
    long = robot_geometry(_arm("ur5"), tool=Tool(radius=0.03, length=0.1), link_radii=None)
    other = robot_geometry(_arm("ur10"), tool=Tool(radius=0.03, length=0.12), link_radii=None)
    arm = short.geometry.ngeoms - 2  # the tool: a holder and a cutting part, last
    assert short.keys[:arm] == long.keys[:arm]
    assert not set(short.keys[arm:]) & set(long.keys[arm:])
    assert not set(short.keys) & set(other.keys)
    assert len(set(short.keys)) == len(short.keys)
