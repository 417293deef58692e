"""An optimisation's placements, counted while it runs, against the estimate made before it.

Each module that evaluates placements for the optimiser is wrapped with a counter (the call's
placements, and whether it asked for one at a time); the counts per phase must be within
:func:`solver.optimise.work.work_of`'s, and a phase the estimate weighs as batched must not go
one placement a call. Issue 26: the Jaco2 on the README path's first two waypoints (32.8 s
before the compiled chain); the Nelder-Mead climbs, one placement at a time, with the numeric
family too (one case raises the climbs' budget); and the UR5
in a cell whose fixture blocks the velocity-best placement (test_cell's), where local solves'
answers are backed off and differential evolution scores collisions without the cell.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from solver.families import get_robot
from solver.optimise import active_set, back_off, coarse_rows, coarse_search, local_search
from solver.optimise import optimize as front_door
from solver.optimise.coarse_search import coarse_cells
from solver.optimise.methods import casadi_method, placement_scipy
from solver.optimise.search_space import PlacementBounds
from solver.optimise.work import seeds_from_map, work_of
from solver.path.cell.shapes import Cell
from solver.path.placement_evaluator import PlacementEvaluator
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_cell import OPT_BOUNDS, blocking_cell
from tests.solver.test_evaluate import load_path

ISSUE_BOX = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
SMALL_BOX = PlacementBounds(x=(-0.1, 0.1), y=(0.4, 0.5), yaw=(-0.3, 0.3), z=0.1)

# The estimate's phases that each counted place contributes to.
PHASES = {
    "casadi": {
        "front door": ("start", "candidates"),
        "global": ("coarse map", "box corners", "box edges", "box edges' whole-path checks"),
        "refinement": ("refinement",),
        "climbs": ("Nelder-Mead climbs",),
        "solves": ("IPOPT starts and whole-path checks",),
        "back-offs": ("back-offs",),
    },
    "scipy": {
        "front door": ("start", "candidates"),
        "global": (
            "differential evolution",
            "coarse map",
            "box corners",
            "box edges",
            "box edges' whole-path checks",
        ),
        "refinement": ("refinement",),
        "climbs": ("Nelder-Mead climbs",),
        "solves": ("whole-path checks",),
        "back-offs": ("back-offs",),
        "collisions": ("differential evolution's collisions, without the cell",),
    },
}
ONE_AT_A_TIME = {"front door", "climbs", "solves", "back-offs"}


class Counted:
    """Placements evaluated per counted place, and the largest batch of each."""

    def __init__(self) -> None:
        self.placements: Counter[str] = Counter()
        self.largest: Counter[str] = Counter()
        self.in_a_cell = False  # the optimisation's problem has a cell

    def add(self, where: str, placements: int) -> None:
        self.placements[where] += placements
        self.largest[where] = max(self.largest[where], placements)

    def wrap(self, where: str, function: Callable[..., Any]) -> Callable[..., Any]:
        def counted(problem: PathProblem, rows: Any, *args: Any, **keywords: Any) -> Any:
            self.add(where, 1 if not isinstance(rows, np.ndarray) else len(rows))
            return function(problem, rows, *args, **keywords)

        return counted

    def polish_apart(self, function: Callable[..., Any]) -> Callable[..., Any]:
        """Differential evolution counted as the global phase; SLSQP's polish left out."""

        def counted(problem: PathProblem, rows: np.ndarray, **keywords: Any) -> Any:
            where = "polish" if keywords.get("with_speeds") else "global"
            if where == "global" and problem.options.cell is None and self.in_a_cell:
                where = "collisions"  # the kinematics alone at placements in collision
            self.add(where, len(rows))
            return function(problem, rows, **keywords)

        return counted


@pytest.fixture
def counted(monkeypatch: pytest.MonkeyPatch) -> Counted:
    counts = Counted()
    monkeypatch.setattr(
        front_door, "evaluate_path", counts.wrap("front door", front_door.evaluate_path)
    )
    monkeypatch.setattr(
        casadi_method, "evaluate_path", counts.wrap("solves", casadi_method.evaluate_path)
    )
    monkeypatch.setattr(
        active_set, "evaluate_placements", counts.wrap("solves", active_set.evaluate_placements)
    )
    monkeypatch.setattr(
        coarse_rows, "evaluate_placements", counts.wrap("global", coarse_rows.evaluate_placements)
    )
    monkeypatch.setattr(  # the box's corners
        coarse_search,
        "evaluate_placements",
        counts.wrap("global", coarse_search.evaluate_placements),
    )
    monkeypatch.setattr(
        placement_scipy,
        "evaluate_placements",
        counts.polish_apart(placement_scipy.evaluate_placements),
    )
    monkeypatch.setattr(
        local_search,
        "evaluate_placements",
        counts.wrap("refinement", local_search.evaluate_placements),
    )

    class CountedEvaluator(PlacementEvaluator):
        def __call__(self, placements: np.ndarray) -> Any:
            counts.add("climbs", len(placements))
            return super().__call__(placements)

    monkeypatch.setattr(local_search, "PlacementEvaluator", CountedEvaluator)

    class CountedBackOff(PlacementEvaluator):
        def __call__(self, placements: np.ndarray) -> Any:
            counts.add("back-offs", len(placements))
            return super().__call__(placements)

    monkeypatch.setattr(back_off, "PlacementEvaluator", CountedBackOff)
    return counts


CASES = {
    "jaco2 issue 26": ("kinova_jaco2", 2, ISSUE_BOX, None),
    "jaco2 climbing": ("kinova_jaco2", 2, SMALL_BOX, 1e6),
    "ur5 climbing": ("ur5", 10, SMALL_BOX, None),
    "ur5 in a cell": ("ur5", None, OPT_BOUNDS, None),
}


@pytest.fixture(scope="module")
def blocking() -> Cell:
    """test_cell's fixture at the velocity-best placement's elbow, found before any counting."""
    return Cell(fixed=blocking_cell()["shapes"])


@pytest.mark.parametrize("method", ["casadi", "scipy"])
@pytest.mark.parametrize("case", list(CASES))
def test_the_estimate_covers_every_evaluation(
    blocking: Cell, counted: Counted, monkeypatch: pytest.MonkeyPatch, case: str, method: str
) -> None:
    name, n_waypoints, bounds, climb_work = CASES[case]
    if climb_work is not None:
        monkeypatch.setattr(local_search, "CLIMB_WORK", climb_work)
    cell = blocking if case == "ur5 in a cell" else None
    counted.in_a_cell = cell is not None
    path = load_path("curved_line")[:n_waypoints]
    problem = PathProblem.of(get_robot(name), path, PathOptions(cell=cell))
    # the scipy method also starts from the coarse map where it fits, as the front door decides
    seeded = method == "scipy" and seeds_from_map(problem, bounds)
    estimate = work_of(problem, bounds, method=method, seed_map=seeded)
    optimum = front_door.optimize_placement(problem, bounds=bounds, method=method)
    assert optimum.found
    for where, phases in PHASES[method].items():
        allowed = sum(estimate.placements(phase) for phase in phases)
        assert counted.placements[where] <= allowed, (where, counted.placements, estimate)
        if where in ONE_AT_A_TIME:
            assert counted.largest[where] <= 1, (where, counted.largest)
    if cell is not None:  # a local solve climbed into the fixture and was backed off
        assert counted.placements["back-offs"] > 0
        assert (counted.placements["collisions"] > 0) == (method == "scipy")
    else:  # climbs ran exactly where the estimate gives them a budget
        climbs = estimate.placements("Nelder-Mead climbs")
        assert (counted.placements["climbs"] > 0) == (climbs > 0), (climbs, counted.placements)
        if climb_work is not None or name == "ur5":  # the case shows something
            assert counted.placements["climbs"] > 0


def test_a_climb_runs_to_its_budget_one_placement_a_call(
    counted: Counted, monkeypatch: pytest.MonkeyPatch
) -> None:
    """From the ERK box's best coarse cell Nelder-Mead is still climbing at 60 evaluations."""
    monkeypatch.setattr(local_search, "CLIMB_EVALUATIONS", 60)
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line"))
    [best, *_] = coarse_cells(problem, ISSUE_BOX, symmetric=False, near=1.5)
    assert local_search.climb(problem, ISSUE_BOX, best) is not None
    budget = local_search.climb_budget(problem, ISSUE_BOX)
    assert budget == 60  # 60 * 133 waypoints within CLIMB_WORK
    assert counted.largest["climbs"] == 1
    assert (
        budget <= counted.placements["climbs"] <= local_search.climb_evaluations(problem, ISSUE_BOX)
    )


def _there_and_back(n_waypoints: int) -> np.ndarray:
    """The README path run there and back until it has ``n_waypoints`` (no pose twice in a row)."""
    path = load_path("curved_line")
    legs = [path]
    while sum(len(leg) for leg in legs) < n_waypoints:
        legs.append(legs[-1][-2::-1])
    out: np.ndarray = np.concatenate(legs)[:n_waypoints]
    return out


@pytest.mark.parametrize(
    ("n_waypoints", "accelerations", "over"),
    [(1200, True, True), (1200, False, True), (300, False, False), (300, True, False)],
)
def test_a_whole_path_nlp_weighs_its_ipopt_solves(
    n_waypoints: int, accelerations: bool, over: bool
) -> None:
    """A spin path's NLP holds every waypoint: its IPOPT solves are weighed (n^1.7, n^2).

    The work-bounds audit of stop 55: the UR5 with a spin path of 1,200 waypoints ran 55 to 75 s
    with acceleration limits and 9 s without, weighed at 0.86 of DTF_MAX_MAP_POSES' 5 million;
    300 waypoints ran 2.4 s. On active sets (no spin path) nothing is added.
    """
    robot = get_robot("ur5")
    if accelerations:
        robot = robot.with_options(qddot_max=[5.0] * 6)
    problem = PathProblem.of(robot, _there_and_back(n_waypoints), PathOptions())
    box = PlacementBounds(x=(-0.3, 0.3), y=(0.3, 0.6), yaw=(-math.pi, math.pi), z=0.1)
    spun = work_of(problem, box, max_spin_step=0.05)
    assert spun.placements("IPOPT solves of the whole path") == casadi_method.N_STARTS
    assert (spun.weighed(problem) > 5_000_000) == over
    assert work_of(problem, box).placements("IPOPT solves of the whole path") == 0
