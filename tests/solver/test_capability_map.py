"""Capability map: every cell is what evaluate_path gives there, feasible or not."""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction

import numpy as np
import pytest

from solver.core.codes import REASONS
from solver.core.exceptions import InvalidInputError
from solver.core.family import Branch
from solver.core.written import stepped_as_written
from solver.families import get_robot
from solver.families.ur.ik import BRANCHES
from solver.path.capability_map import grid_axis, serpentine
from tests.cases import MAP_EVALUATE_RTOL
from tests.problems import capability_map, evaluate_path, evaluate_placements, prepare_path
from tests.solver.test_evaluate import load_path, wrist_singular_path


def _compare_cells(robot, path, cmap, cells, **kwargs) -> set[str]:
    """Assert each cell [spin, yaw, y, x] equals evaluate_path there; return the reasons seen."""
    seen = set()
    for index in cells:
        expected = evaluate_path(robot, path, cmap.placement(index), **kwargs)
        if expected.feasible:
            assert cmap.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
            assert cmap.bottleneck_waypoint[index] == expected.bottleneck_waypoint
            assert cmap.bottleneck_joint[index] == expected.bottleneck_joint
            seen.add("feasible")
        else:
            assert math.isnan(cmap.mu_path[index])
            assert REASONS[cmap.reason[index]] == expected.reason
            assert cmap.failed_waypoint[index] == expected.failed_waypoint
            seen.add(expected.reason)
        assert BRANCHES[cmap.branch[index]] == expected.branch
    return seen


@pytest.mark.parametrize(
    ("robot_name", "path_name"), [("ur5", "curved_line"), ("ur10e", "s_curve")]
)
def test_random_cells_equal_evaluate(robot_name: str, path_name: str) -> None:
    """Issue 3: random cells equal /v1/evaluate there (rel 1e-9), infeasible ones included."""
    robot = get_robot(robot_name)
    path = load_path(path_name)
    step = 0.1
    cmap = capability_map(
        robot,
        path,
        xs=grid_axis(-1.0, 1.0, step, field="x"),
        ys=grid_axis(-1.0, 1.0, step, field="y"),
        z=0.1,
        yaws=np.array([0.0, 1.2, -2.5]),
    )
    rng = np.random.default_rng(12)
    shape = cmap.mu_path.shape
    feasible = np.argwhere(~np.isnan(cmap.mu_path))
    infeasible = np.argwhere(np.isnan(cmap.mu_path))
    picks = [*feasible[rng.choice(len(feasible), 25, replace=False)]]
    # Every reason that occurs, twice each, and random infeasible cells.
    for code in np.unique(cmap.reason[cmap.reason >= 0]):
        where = np.argwhere(cmap.reason == code)
        picks += [*where[rng.choice(len(where), min(2, len(where)), replace=False)]]
    picks += [*infeasible[rng.choice(len(infeasible), 10, replace=False)]]
    seen = _compare_cells(robot, path, cmap, [tuple(int(v) for v in p) for p in picks])
    assert {"feasible", "unreachable"} <= seen
    assert len(picks) >= 35 and shape == (1, 3, 21, 21)


def test_a_named_branch_and_a_small_step() -> None:
    robot = get_robot("ur5e")
    path = load_path("curved_line")
    kwargs = {
        "branch": Branch.named(shoulder="right", elbow="down", wrist="flip"),
        "max_joint_step": 0.05,
    }
    cmap = capability_map(
        robot,
        path,
        xs=np.array([-0.3, 0.0, 0.3]),
        ys=np.array([0.3, 0.5]),
        z=0.0,
        yaws=np.array([0.0, math.pi / 2]),
        **kwargs,
    )
    cells = [tuple(int(v) for v in c) for c in np.ndindex(cmap.mu_path.shape)]
    _compare_cells(robot, path, cmap, cells, **kwargs)


def test_best_and_worst_are_the_extreme_cells() -> None:
    cmap = capability_map(
        get_robot("ur5"),
        load_path("curved_line"),
        xs=grid_axis(-0.6, 0.6, 0.1, field="x"),
        ys=grid_axis(0.0, 0.8, 0.1, field="y"),
        z=0.1,
        yaws=np.array([0.0, 0.5]),
    )
    best, worst = cmap.extreme(best=True), cmap.extreme(best=False)
    assert cmap.mu_path[best] == np.nanmax(cmap.mu_path)
    assert cmap.mu_path[worst] == np.nanmin(cmap.mu_path)
    assert np.isnan(cmap.mu_path).any()  # the grid reaches beyond the arm


def test_progress_is_reported_per_chunk() -> None:
    fractions: list[float] = []
    capability_map(
        get_robot("ur5"),
        load_path("curved_line")[:20],
        xs=np.linspace(-0.2, 0.2, 10),
        ys=np.linspace(0.3, 0.5, 10),
        z=0.1,
        yaws=np.array([0.0, 1.0]),
        chunk=30,
        progress=fractions.append,
    )
    # 200 placements in chunks of 30: the compiled kernel takes chunks across two yaws.
    done = [30, 60, 90, 120, 150, 180, 200]
    np.testing.assert_allclose(fractions, np.array(done) / 200)


def test_infeasible_everywhere() -> None:
    cmap = capability_map(
        get_robot("ur3"),
        load_path("curved_line"),
        xs=np.array([3.0]),
        ys=np.array([3.0]),
        z=0.0,
        yaws=np.array([0.0]),
    )
    assert cmap.extreme(best=True) is None and REASONS[cmap.reason[0, 0, 0, 0]] == "unreachable"


@pytest.mark.parametrize(
    ("lower", "upper", "step", "expected"),
    [(-0.25, 0.25, 0.02, 26), (0.25, 0.65, 0.02, 21), (0.0, 0.0, 0.1, 1), (0.0, 0.35, 0.1, 4)],
)
def test_grid_axis(lower: float, upper: float, step: float, expected: int) -> None:
    axis = grid_axis(lower, upper, step, field="grid.x")
    assert len(axis) == expected and axis[0] == lower and axis[-1] <= upper + 1e-12


@pytest.mark.parametrize(
    ("lower", "upper", "step"),
    [
        (-0.25, 0.25, 0.02),
        (0.25, 0.65, 0.02),
        (-1.2, 3.7, 0.15),
        (0.0, 1e-3, 1e-5),
        (-7.5, 12.25, 0.125),
    ],
)
def test_grid_values_are_the_decimals_the_axis_is_written_in(
    lower: float, upper: float, step: float
) -> None:
    """Each value is the float nearest lower + i step in exact decimal arithmetic (Fractions of
    the numbers as written): 0.05 on the ERK grid, not 0.04999999999999999."""
    axis = grid_axis(lower, upper, step, field="grid.x")
    exact = [Fraction(repr(lower)) + i * Fraction(repr(step)) for i in range(len(axis))]
    assert axis.tolist() == [float(value) for value in exact]
    assert 0.05 in grid_axis(-0.25, 0.25, 0.02, field="grid.x").tolist()


def test_grid_values_past_exact_integers_are_the_floats_sums() -> None:
    """A bound written in 17 digits (0.1 + 0.2) cannot be summed exactly in integers: the floats'
    own sum, as before."""
    lower = 0.1 + 0.2
    axis = grid_axis(lower, 1.0, 0.1, field="grid.x")
    assert axis.tolist() == [lower + 0.1 * i for i in range(len(axis))]


@pytest.mark.parametrize(
    ("value", "step"), [(1e-16, 1000.0), (1e-21, 0.02), (1e-21, 0.2617993877991494), (0.3, 1e19)]
)
def test_a_one_value_axis_is_its_value_whatever_the_step(value: float, step: float) -> None:
    """An axis narrower than its step, its bound written to many decimals: the stride in the
    last decimal (10^19 and more) passed int64 and was an OverflowError, a 500 (audit 22)."""
    assert grid_axis(value, value, step, field="grid.x").tolist() == [value]
    assert stepped_as_written(value, step, 1).tolist() == [value]
    assert stepped_as_written(value, step, 0).tolist() == []


@pytest.mark.parametrize(("lower", "upper", "step"), [(0, 1, 0), (1, 0, 0.1), (0, math.inf, 1)])
def test_bad_grid_axis(lower: float, upper: float, step: float) -> None:
    with pytest.raises(InvalidInputError) as info:
        grid_axis(lower, upper, step, field="grid.x")
    assert info.value.field == "grid.x"


def test_a_bad_grid_axis_is_told_in_the_request_s_words() -> None:
    """The grid's fields are min, max and step (the message said lower=0.1, upper=-0.1)."""
    with pytest.raises(InvalidInputError) as info:
        grid_axis(0.1, -0.1, 0.05, field="grid.x")
    assert info.value.message == "needs step > 0 and max >= min; got min 0.1, max -0.1, step 0.05"


def test_joint_limit_and_singular_cells_equal_evaluate() -> None:
    limited = dataclasses.replace(
        get_robot("ur5e"), q_lower=np.full(6, -math.pi / 2), q_upper=np.full(6, math.pi)
    )
    path = load_path("curved_line")
    cmap = capability_map(
        limited,
        path,
        xs=grid_axis(-0.4, 0.4, 0.2, field="x"),
        ys=grid_axis(-0.6, 0.6, 0.2, field="y"),
        z=0.1,
        yaws=np.array([0.0, 2.0]),
    )
    cells = [tuple(int(v) for v in c) for c in np.ndindex(cmap.mu_path.shape)]
    assert "joint_limits" in _compare_cells(limited, path, cmap, cells)
    # A path through the wrist singularity at the placement (0, 0, 0, 0).
    robot = get_robot("ur5e")
    singular_path = wrist_singular_path(robot)
    kwargs = {"branch": Branch.named(shoulder="left", elbow="up", wrist="flip")}
    cmap = capability_map(
        robot,
        singular_path,
        xs=np.array([-0.05, 0.0, 0.05]),
        ys=np.array([0.0, 0.05]),
        z=0.0,
        yaws=np.array([0.0, 0.2]),
        **kwargs,
    )
    assert REASONS[cmap.reason[0, 0, 0, 1]] == "singular"
    cells = [tuple(int(v) for v in c) for c in np.ndindex(cmap.mu_path.shape)]
    assert "singular" in _compare_cells(robot, singular_path, cmap, cells, **kwargs)


def test_serpentine_order_is_its_own_inverse() -> None:
    """Rows alternate direction, so each cell follows a neighbour; applied twice: the identity."""
    order = serpentine(3, 4)
    assert order.tolist() == [0, 1, 2, 3, 7, 6, 5, 4, 8, 9, 10, 11]
    assert order[order].tolist() == list(range(12))


@pytest.mark.parametrize("robot_name", ["ur5", "kuka_kr6_r700_sixx", "panda"])
def test_map_cells_equal_the_placements_in_grid_order(robot_name: str) -> None:
    """The map evaluates its cells in serpentine order; each answer lands on its own cell.

    Against ``evaluate_placements`` of the placements in C order (x fastest), two yaws and an
    odd number of rows: every column equal bit for bit (a cell's answer does not depend on
    the order, only the kernels' work does).
    """
    robot, path = get_robot(robot_name), load_path("curved_line")
    xs, ys, yaws = np.linspace(-0.3, 0.3, 7), np.linspace(0.3, 0.6, 5), np.array([0.0, 2.0])
    cmap = capability_map(robot, path, xs=xs, ys=ys, z=0.1, yaws=yaws)
    rows = np.array([[x, y, 0.1, yaw, 0.0] for yaw in yaws for y in ys for x in xs])
    expected = evaluate_placements(robot, prepare_path(robot, path), rows)
    for name in ("mu_path", "reason", "failed_waypoint", "branch"):
        assert np.array_equal(getattr(cmap, name).ravel(), getattr(expected, name), equal_nan=True)
    for name in ("bottleneck_waypoint", "bottleneck_joint"):
        assert np.array_equal(getattr(cmap, name).ravel(), getattr(expected, name))
    assert len(np.unique(cmap.branch[cmap.branch >= 0])) >= 2  # the order changes the work
