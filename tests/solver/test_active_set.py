"""The optimisers' active sets (issue 23): the same optimum as the whole problem, found by the loop.

IPOPT and SLSQP solve on the waypoints that can bind (solver/optimise/active_set.py), on the
problem restricted to them (solver/path/subset.py), and the whole path is checked at each
answer. The reference is the same optimiser on the whole problem (``active_set=False``, what
every optimiser did before), on every problem the optimiser tests solve.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from solver.families import get_robot
from solver.optimise import active_set, coarse_rows
from solver.optimise.coarse_search import coarse_cells, corner_vectors, edge_lines
from solver.optimise.methods import casadi_method
from solver.optimise.optimize import optimize_placement
from solver.optimise.optimum import PlacementOptimum
from solver.optimise.search_space import PlacementBounds
from solver.path.evaluate import evaluate_path
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem
from solver.path.subset import on_waypoints
from tests.problems import problem
from tests.solver.families.test_opw_paths import KR6
from tests.solver.test_acceleration import WAYPOINTS, ur5
from tests.solver.test_constant_spin import angled_spindle
from tests.solver.test_evaluate import load_path
from tests.solver.test_half_turn import two_waypoints

ACTIVE_SET_RTOL = 1e-9  # issue 23: the active-set answer equals the whole problem's
BOX = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
SMALL = dict(x=(-0.1, 0.1), y=(0.35, 0.55))


def _problems() -> dict[str, tuple[PathProblem, PlacementBounds]]:
    """Every problem an optimiser test solves (the module that solves it in comments).

    The Panda's (test_numeric_optimize) is left out: a redundant arm's solves run on the whole
    path (its answer carries the NLP's joint path), with or without ``active_set``.
    """
    curved = load_path("curved_line")
    return {
        # test_optimize: two arms, two paths, the box of issue 4
        **{
            f"{name} {path}": (problem(get_robot(name), load_path(path)), BOX)
            for name in ("ur5", "ur5e")
            for path in ("curved_line", "s_curve")
        },
        # test_optimize: a free height
        "free height": (
            problem(get_robot("ur5"), curved),
            PlacementBounds(**SMALL, yaw=(-0.5, 0.5), z=(0.0, 0.2)),
        ),
        # test_free_spin
        "free spin": (problem(get_robot("ur5"), curved, spin_mode="free"), BOX),
        # test_acceleration: mu_acc maximised
        "accelerations": (
            PathProblem.of(ur5(10.0), WAYPOINTS),  # type: ignore[arg-type]
            PlacementBounds(**SMALL, yaw=(-0.3, 0.3), z=0.1),
        ),
        # test_opw_paths
        "opw": (
            problem(get_robot(KR6), curved),
            PlacementBounds(x=(0.3, 0.5), y=(-0.1, 0.1), yaw=(-math.pi, math.pi), z=0.1),
        ),
        # test_local_search: the large box of issue 12
        "large box": (
            problem(get_robot("ur5"), curved),
            PlacementBounds(x=(-0.8, 0.8), y=(-0.8, 0.8), yaw=(-math.pi, math.pi), z=0.1),
        ),
        # test_constant_spin: spin bounds and an angled spindle
        "spin bounds": (
            problem(get_robot("ur5e").with_options(transform_tool_to_tcp=angled_spindle()), curved),
            PlacementBounds(**SMALL, yaw=(-math.pi, math.pi), z=0.0, spin=(-math.pi, math.pi)),
        ),
        # test_half_turn: two waypoints 2e-3 rad short of a half turn
        "half turn": (
            problem(get_robot("ur5"), two_waypoints(math.pi - 2e-3), max_joint_step=3.5),
            PlacementBounds(x=(0.0, 0.02), y=(0.4, 0.45), yaw=(0.1, 0.2), z=0.1),
        ),
    }


PROBLEMS = _problems()


@pytest.mark.parametrize("method", ["casadi", "scipy"])
@pytest.mark.parametrize("name", PROBLEMS)
def test_the_active_set_answer_is_the_whole_problems(name: str, method: str) -> None:
    posed, bounds = PROBLEMS[name]
    whole = optimize_placement(posed, bounds=bounds, method=method, active_set=False)
    active = optimize_placement(posed, bounds=bounds, method=method, active_set=True)
    assert whole.found and active.found
    assert active.mu_path == pytest.approx(whole.mu_path, rel=ACTIVE_SET_RTOL)
    if whole.mu_acc is not None:
        assert active.mu_acc == pytest.approx(whole.mu_acc, rel=ACTIVE_SET_RTOL)
    # the answer is the whole path's evaluation at the reported placement
    again = evaluate_path(posed, active.placement)
    assert again.feed_index == active.evaluation.feed_index


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
@pytest.mark.parametrize("accelerations", [None, 10.0])
def test_a_subset_keeps_each_waypoints_bound(spin_mode: str, accelerations: float | None) -> None:
    """A kept waypoint's V_max (and V_acc, where its stencil is kept) is the whole path's."""
    robot = get_robot("ur5")
    if accelerations is not None:
        robot = robot.with_options(qddot_max=[accelerations] * 6)
    posed = problem(robot, load_path("curved_line"), spin_mode=spin_mode)
    branch = posed.family.branches[0]
    rows = np.array([3, 4, 5, 6, 7, 40, 41, 90, 91, 92, 93, 94, 95, 96, 132])
    placement = np.array([[0.0, 0.45, 0.1, 0.3, 0.0]])
    whole = evaluate_placements(posed.with_options(branch=branch), placement, with_speeds=True)
    part = evaluate_placements(
        on_waypoints(posed, rows).with_options(branch=branch), placement, with_speeds=True
    )
    assert np.isfinite(whole.mu_path[0]) and np.isfinite(part.mu_path[0])
    np.testing.assert_allclose(part.v_max[0], whole.v_max[0, rows], rtol=1e-12)
    if accelerations is not None:
        assert part.v_acc is not None and whole.v_acc is not None
        whole_acc = whole.v_acc[0, rows]
        kept = np.isfinite(part.v_acc[0])
        assert kept.any()  # the runs 3..7 and 90..96 hold whole stencils at this blend length
        # in free spin the spin schedule restarts at the subset's breaks: within a kept run
        # the joint path moves by a constant, which moves D_i by rounding only
        rtol = 1e-12 if spin_mode == "fixed" else 1e-9
        np.testing.assert_allclose(part.v_acc[0, kept], whole_acc[kept], rtol=rtol)
    # the subset drops rows: never slower than the whole path
    assert part.mu_path[0] >= whole.mu_path[0]


def _recorded(monkeypatch: pytest.MonkeyPatch) -> list[tuple[np.ndarray, Any]]:
    """Record the first set and the result of every active-set loop of the casadi method."""
    loops: list[tuple[np.ndarray, Any]] = []
    loop = active_set.solve_on_active_set

    def recorded(*args: Any, **kwargs: Any) -> Any:
        result = loop(*args, **kwargs)
        loops.append((np.array(args[3]), result))
        return result

    monkeypatch.setattr(casadi_method, "solve_on_active_set", recorded)
    return loops


def _bottleneck(posed: PathProblem, optimum: PlacementOptimum) -> int:
    assert optimum.placement is not None
    evaluation = evaluate_path(posed, optimum.placement)
    assert evaluation.bottleneck_waypoint is not None
    return evaluation.bottleneck_waypoint


@pytest.mark.parametrize("path", ["curved_line", "s_curve"])
def test_a_bottleneck_the_first_set_misses_is_found_by_the_loop(
    monkeypatch: pytest.MonkeyPatch, path: str
) -> None:
    """First sets of the start's one slowest waypoint (and its neighbours): on these paths the
    optimum is bound elsewhere, so some first set misses its bottleneck; the loop adds it and
    ends at the whole problem's optimum."""
    posed = problem(get_robot("ur5"), load_path(path))
    whole = optimize_placement(posed, bounds=BOX, active_set=False)
    monkeypatch.setattr(active_set, "FIRST_ROWS", 1)
    loops = _recorded(monkeypatch)
    active = optimize_placement(posed, bounds=BOX, active_set=True)
    assert active.mu_path == pytest.approx(whole.mu_path, rel=ACTIVE_SET_RTOL)
    bottleneck = _bottleneck(posed, active)
    assert all(len(first) <= 3 for first, _ in loops)
    assert any(
        bottleneck not in first and bottleneck in result.rows and result.rounds >= 2
        for first, result in loops
    ), "no first set missed the bottleneck: the path no longer tests the loop"


def test_a_first_set_far_from_the_bottleneck_is_grown_to_the_optimum(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A constructed first set: the three fastest waypoints at the start, none binding. The
    loop still ends where the whole problem does, its set holding the optimum's bottleneck."""
    posed = problem(get_robot("ur5e"), load_path("curved_line"))
    whole = optimize_placement(posed, bounds=BOX, active_set=False)

    def fastest(posed: PathProblem, speeds: np.ndarray, failing: np.ndarray) -> np.ndarray:
        return active_set.closure(posed, np.argsort(np.nan_to_num(speeds, nan=-np.inf))[-1:])

    monkeypatch.setattr(casadi_method, "first_rows", fastest)
    loops = _recorded(monkeypatch)
    active = optimize_placement(posed, bounds=BOX, active_set=True)
    assert active.mu_path == pytest.approx(whole.mu_path, rel=ACTIVE_SET_RTOL)
    bottleneck = _bottleneck(posed, active)
    assert all(bottleneck not in first for first, _ in loops)
    assert any(bottleneck in r.rows and r.rounds >= 2 for _, r in loops)


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
def test_a_long_programs_map_reports_whole_path_cells_and_the_best_one(
    monkeypatch: pytest.MonkeyPatch, spin_mode: str
) -> None:
    """The coarse map on a set (a program over MAX_MAP_ROWS, here 40 of the ERK path's 133):
    every cell it hands on is the whole path's (its mu_path, its branch), and its best is the
    best cell of the map of the whole path."""
    posed = problem(get_robot("ur5"), load_path("curved_line"), spin_mode=spin_mode)
    near = math.atan2(0.45, 0.0)
    whole = coarse_cells(posed, BOX, symmetric=True, near=near)
    monkeypatch.setattr(coarse_rows, "MAX_MAP_ROWS", 40)
    on_set = coarse_cells(posed, BOX, symmetric=True, near=near)
    corners = {tuple(v) for v in corner_vectors(BOX)}  # the box's corners: on the whole path
    edges = {tuple(v) for line in edge_lines(BOX) for v in line}  # mapped as the cells are
    mapped = [cell for cell in on_set if tuple(cell.vector) not in corners | edges]
    assert mapped and len(mapped) <= coarse_rows.VERIFIED_CELLS
    on_edges = [cell for cell in on_set if tuple(cell.vector) in edges]
    assert len(on_edges) <= coarse_rows.VERIFIED_CELLS
    rows = BOX.rows(np.array([cell.vector for cell in on_set]))
    again = evaluate_placements(posed, rows)
    # each cell is evaluated at its arc's point at the polar angle `near`, and handed on at the
    # point nearest the start: the same mu_path to rounding (spec section 6's symmetry)
    np.testing.assert_allclose([cell.mu_path for cell in on_set], again.feed_index, rtol=1e-12)
    np.testing.assert_array_equal([cell.branch for cell in on_set], again.branch)
    assert on_set[0].mu_path == whole[0].mu_path
