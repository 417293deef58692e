"""An optimisation's placement evaluations, counted before it starts (what the limits weigh).

:func:`solver.optimise.optimize.optimize_placement` evaluates mu_path in phases whose size the
code fixes: the start; the coarse map (casadi) or the differential evolution (scipy); the compass
refinement; the Nelder-Mead climbs, one placement a call; the checks of each local solve's
answer on the whole path (the active set); with a cell, the back-off of each local solve's
answer (:mod:`solver.optimise.back_off`); the judging of every candidate; then each narrower
search the request implies (:mod:`solver.optimise.narrower`), phase by phase. :func:`work_of`
gives each phase's placements at most, and :meth:`OptimisationWork.weighed` their work in poses
of a closed-form family (:meth:`solver.path.problem.PathProblem.path_cost`), the unit of the
service's size limits, so that a search whose work is over a limit is refused before it starts.

A placement evaluated on its own costs more than its share of a batch (the numeric family
seeds and follows a whole chunk in one compiled call; the map kernel's inputs are per call):
measured with ``bench/numeric_optimisation.py`` (2026-12-02, loaded machine), one at a time took
1.3 to 2.1 times a batch's share for numeric IK (UR5 as a URDF, the Jaco2; 2 and 133 waypoints)
and 1.8 for the analytic UR5 on 133 waypoints, so such phases weigh SINGLE_PLACEMENT_COST a
placement. The analytic UR5 on 2 waypoints took 3 to 5 times (22-44 us a placement: its
climbs' 1,208 placements take about 50 ms, far below any limit).

IPOPT's own work is counted where its NLP holds the whole path (a spin path, an arm of more
than six joints, no active sets): :func:`ipopt_solve_cost` a solve. Before, a spin path of 1,200
waypoints with acceleration limits was weighed at 0.86 of the limit and ran 55 to 75 s, IPOPT
nearly all of it (the work-bounds audit of stop 55). Not counted: IPOPT on active sets (a few
dozen waypoints a solve), SLSQP's finite differences (bounded by its iterations).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from solver.optimise.active_set import MAX_ROUNDS
from solver.optimise.back_off import BACK_OFF_PLACEMENTS, backs_off
from solver.optimise.coarse_rows import mapped_waypoints
from solver.optimise.coarse_rows import whole_path_checks as map_checks
from solver.optimise.coarse_search import box_edge_points, coarse_map_cells, corner_vectors
from solver.optimise.local_search import N_CLIMBS, REFINE_ROUNDS, climb_evaluations, refined_count
from solver.optimise.methods import casadi_method, method_named, scipy_method
from solver.optimise.methods.placement_scipy import search_placements
from solver.optimise.methods.search_rows import (
    SEARCH_ROUNDS,
    searched_waypoints,
    whole_path_checks,
)
from solver.optimise.narrower import narrower_searches
from solver.optimise.search_space import PlacementBounds
from solver.optimise.symmetry import symmetric_search
from solver.path.problem import PathProblem

COARSE_MAP = "coarse map"
"""The name of the casadi method's coarse map among the phases."""
BOX_CORNERS = "box corners"
"""The box's corners, evaluated beside the coarse map (:func:`coarse_search.box_corners`)."""
BOX_EDGES = "box edges"
"""Points along the box's edges, mapped beside the coarse map (:func:`coarse_search.box_edges`)."""
SINGLE_PLACEMENT_COST = 2.5
"""The weight of a placement evaluated on its own, against one evaluated in a batch."""
IPOPT_SOLVE = (14.0, 1.7)
IPOPT_ACCELERATED_SOLVE = (4.0, 2.0)
"""One IPOPT solve of an NLP over n waypoints weighs scale n^exponent closed-form poses (the
limits' unit, about 2 us); with acceleration limits (their blend rows) the second pair.
Measured by the work-bounds audit of stop 55 (casadi, four starts, loaded machine, 2026-12-05):
the UR5 with a spin path, 300 waypoints 2.4 s and 1,200 waypoints 9 s (the UR10e 16.3 s), with
acceleration limits 3.4 s and 55 to 75 s; the Panda with acceleration limits, 480 waypoints,
10.9 to 13.9 s. With these the three runs over 9 s weigh 2.8, 5.5 and 1.6 times the limit
(DTF_MAX_MAP_POSES' 5 million), the two under 3.5 s 0.74 and 0.85: the placements' own weight,
far above a kernel's time, leaves IPOPT's about its measured share (a solve of 1,200 waypoints
with acceleration limits weighs 11.5 s, measured 15 s)."""


@dataclass(frozen=True)
class Phase:
    """One phase of an optimisation.

    Attributes:
        name: what it is, as a message names it.
        placements: the placements it evaluates at most.
        n_waypoints: the waypoints of each (the coarse map of a long program maps fewer).
        one_at_a_time: whether each placement is a call of its own.
        without_cell: whether its placements are evaluated without the cell (the kinematics
            alone: weighed by the family's cost, not the cell's).
        search: the narrower search it belongs to (:mod:`solver.optimise.narrower`), or "" for
            the request's own.
        solve_cost: where set, what each of its ``placements`` weighs instead of its path's cost
            (an IPOPT solve, :func:`ipopt_solve_cost`).
    """

    name: str
    placements: int
    n_waypoints: int
    one_at_a_time: bool = False
    without_cell: bool = False
    search: str = ""
    solve_cost: float | None = None


@dataclass(frozen=True)
class OptimisationWork:
    """The phases of one optimisation, each with its placements at most."""

    phases: tuple[Phase, ...]

    def placements(self, name: str, search: str | None = None) -> int:
        """The placements of the phases called ``name`` (0 where there is none).

        ``search``: of that search only ("" the request's own); None: of every search.
        """
        return sum(
            phase.placements
            for phase in self.phases
            if phase.name == name and search in (None, phase.search)
        )

    def weighed(self, problem: PathProblem, search: str | None = None) -> float:
        """The work in closed-form poses: each placement weighed by its path's cost.

        ``search``: of that search only ("" the request's own); None: the whole work.
        """
        clear = problem.without_path_checks()
        return sum(
            phase.placements * phase.solve_cost
            if phase.solve_cost is not None
            else phase.placements
            * (clear if phase.without_cell else problem).path_cost(phase.n_waypoints)
            * (SINGLE_PLACEMENT_COST if phase.one_at_a_time else 1.0)
            for phase in self.phases
            if search in (None, phase.search)
        )

    def describe(self) -> str:
        """The phases that evaluate anything, as a message says them."""
        return ", ".join(
            f"{phase.placements} {phase.name}" + (f" ({phase.search})" if phase.search else "")
            for phase in self.phases
            if phase.placements
        )


def _coarse_map_phases(problem: PathProblem, bounds: PlacementBounds) -> tuple[Phase, ...]:
    """The coarse map's phases (:func:`solver.optimise.coarse_search.coarse_cells`).

    Its cells; a long program's map on a set has its sample and best cells checked on the whole
    path (:mod:`solver.optimise.coarse_rows`); the box's corners, on the whole path; the points
    along its edges, mapped as the cells are.
    """
    n = problem.prepared.n_waypoints
    return (
        Phase(
            COARSE_MAP,
            coarse_map_cells(bounds, symmetric=symmetric_search(problem)),
            mapped_waypoints(n),
        ),
        Phase("coarse map's whole-path checks", map_checks(n), n),
        Phase(BOX_CORNERS, len(corner_vectors(bounds)), n),
        Phase(
            BOX_EDGES,
            box_edge_points(bounds, symmetric=symmetric_search(problem)),
            mapped_waypoints(n),
        ),
        Phase("box edges' whole-path checks", map_checks(n), n),
    )


def ipopt_solve_cost(problem: PathProblem, n_waypoints: int) -> float:
    """One IPOPT solve of an NLP over ``n_waypoints``, in closed-form poses (IPOPT_SOLVE)."""
    accelerated = problem.robot.qddot_max is not None
    scale, exponent = IPOPT_ACCELERATED_SOLVE if accelerated else IPOPT_SOLVE
    return float(scale * math.pow(n_waypoints, exponent))


SEEDED_WORK_RATIO = 2.0
"""The scipy method also starts from the coarse map wherever its search with the map weighs at
most this many times its search without: a constant of the method, so that a limit accepts or
refuses the search but never chooses it."""


def seeds_from_map(problem: PathProblem, bounds: PlacementBounds) -> bool:
    """Whether the scipy method also starts from the coarse map's maxima.

    Differential evolution can miss a narrow basin the casadi method's coarse map holds (a
    KR16-2 on a 0.11 x 0.07 m box with any yaw: 0.7188 m/s against the map's 0.7990, 11 %
    below; the optimiser audit, stop 53). The scipy method then also refines and polishes from
    the map's best cells, so its answer too is never below the map's best cell, wherever the
    map at most doubles the search's work (:data:`SEEDED_WORK_RATIO`: every optimiser test
    problem and the long programs, 1.2 to 1.7 times; not the Panda over the ERK box, where the
    map of its numeric IK would be 20 times the evolution). The limits weigh the search chosen
    and refuse it when over. They chose it before (the map where the search with it fit), so
    a synchronous request and a job of one body, whose limits are larger, answered two optima
    (the determinism audit of stop 59: 1.129638 and 1.130841 m/s on a 2,500-move program).
    """
    return map_is_worth_it(problem, *scipy_works(problem, bounds))


def scipy_works(
    problem: PathProblem, bounds: PlacementBounds, *, max_spin_step: float | None = None
) -> tuple[OptimisationWork, OptimisationWork]:
    """The scipy search's work without the coarse map, and with it (:func:`work_of`'s)."""
    without, with_map = (
        work_of(problem, bounds, method="scipy", max_spin_step=max_spin_step, seed_map=seeded)
        for seeded in (False, True)
    )
    return without, with_map


def map_is_worth_it(
    problem: PathProblem, without: OptimisationWork, with_map: OptimisationWork
) -> bool:
    """:func:`seeds_from_map`'s rule on the two works :func:`scipy_works` gives."""
    return with_map.weighed(problem) <= SEEDED_WORK_RATIO * without.weighed(problem)


def work_of(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    method: str = "casadi",
    max_spin_step: float | None = None,
    active_set: bool = True,
    seed_map: bool = False,
) -> OptimisationWork:
    """The placements :func:`solver.optimise.optimize.optimize_placement` evaluates at most.

    Args:
        problem: the problem as the optimiser takes it (its path is prepared here).
        bounds: the box.
        method: ``casadi`` or ``scipy``.
        max_spin_step: as the optimiser takes it (a spin path solves the whole path).
        active_set: as the optimiser takes it.
        seed_map: the scipy method also starts from the coarse map's maxima
            (:func:`seeds_from_map`).

    Raises:
        InvalidInputError: an unknown method (on ``method``), a bad path.
    """
    method_named(method)
    bounds = bounds.within_a_turn()  # as the search is (optimize_placement)
    phases = _search_phases(problem, bounds, method, max_spin_step, active_set, seed_map)
    for search in narrower_searches(bounds, max_spin_step):
        phases += tuple(
            dataclasses.replace(phase, search=search.name)
            for phase in _search_phases(
                problem, search.bounds, method, search.max_spin_step, active_set, seed_map
            )
        )
    return OptimisationWork(phases)


def _search_phases(
    problem: PathProblem,
    bounds: PlacementBounds,
    method: str,
    max_spin_step: float | None,
    active_set: bool,
    seed_map: bool,
) -> tuple[Phase, ...]:
    """The phases of one search (:func:`work_of`'s arguments), without its narrower ones."""
    n = problem.prepared.n_waypoints
    free = int(bounds.free.sum())
    climbs = N_CLIMBS * climb_evaluations(problem, bounds)
    on_active_set = active_set and max_spin_step is None and problem.robot.dof <= 6
    # With a cell each local solve's answer may be backed off towards its start: one more
    # candidate, found by bisection (solver.optimise.back_off).
    backed = backs_off(problem)
    if method == "scipy":
        size = scipy_method.size_of(problem, bounds)
        refined = refined_count(problem, bounds, count=scipy_method.refined_cells(seed_map, size))
        # Each basin polished: its whole-path check before each SLSQP round and after it.
        solves = size.basins * (1 + MAX_ROUNDS) if on_active_set else 0
        # A long program's evolutions run on a set of its waypoints, each round's best placements
        # checked on the whole path (solver.optimise.methods.search_rows).
        on_rows = scipy_method.rows_searched(problem, active_set)
        evolutions = SEARCH_ROUNDS if on_rows else 1
        searched = searched_waypoints(n) if on_rows else n
        verified = whole_path_checks(size.basins) if on_rows else 0
        return (
            Phase("start", 1, n, one_at_a_time=True),
            *(_coarse_map_phases(problem, bounds) if seed_map else ()),
            Phase("differential evolution", evolutions * search_placements(bounds, size), searched),
            Phase(
                "differential evolution's collisions, without the cell",
                backed * evolutions * search_placements(bounds, size),
                searched,
                without_cell=True,
            ),
            Phase("differential evolution's whole-path checks", verified, n),
            Phase("refinement", refined * 2 * free * REFINE_ROUNDS, n),
            Phase("whole-path checks", solves, n, one_at_a_time=True),
            Phase("Nelder-Mead climbs", climbs, n, one_at_a_time=True),
            Phase("back-offs", backed * size.basins * BACK_OFF_PLACEMENTS, n, True),
            Phase("candidates", 2 + (1 + backed) * size.basins + N_CLIMBS, n, True),
        )
    starts = casadi_method.N_STARTS
    # Each IPOPT start: its cell evaluated on its branch, then (on active sets) the first
    # set's whole-path bounds and one whole-path check after each of its solves.
    solves = starts * (1 + (1 + MAX_ROUNDS if on_active_set else 0))
    return (
        Phase("start", 1, n, one_at_a_time=True),
        *_coarse_map_phases(problem, bounds),
        Phase("refinement", refined_count(problem, bounds) * 2 * free * REFINE_ROUNDS, n),
        Phase("IPOPT starts and whole-path checks", solves, n, one_at_a_time=True),
        Phase(
            "IPOPT solves of the whole path",
            0 if on_active_set else starts,
            n,
            solve_cost=ipopt_solve_cost(problem, n),
        ),
        Phase("Nelder-Mead climbs", climbs, n, one_at_a_time=True),
        Phase("back-offs", backed * starts * BACK_OFF_PLACEMENTS, n, one_at_a_time=True),
        Phase("candidates", 2 + (1 + backed) * starts + N_CLIMBS, n, one_at_a_time=True),
    )
