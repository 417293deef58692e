"""The ``scipy`` method: differential evolution, compass refinement, SLSQP, Nelder-Mead climbs.

Differential evolution over the free variables, every generation one batch through
:mod:`solver.path.placements`, beside the casadi method's coarse map (where it at most doubles
the search's work; its maxima ranked with the evolution's basins:
:func:`solver.optimise.work.seeds_from_map`); each basin is climbed by the compass search, then
polished by SLSQP on the epigraph form with finite-difference gradients on the branch it ends
on (:mod:`solver.optimise.methods.placement_scipy`); Nelder-Mead climbs mu_path from the best.
With a cell, a polish that is not clear of it is also backed off towards its start
(:mod:`solver.optimise.back_off`).
"""

from __future__ import annotations

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.family import Branch
from solver.core.progress import Progress, span
from solver.optimise.active_set import (
    MAX_ROUNDS,
    first_rows,
    solve_on_active_set,
    whole_path_bounds,
)
from solver.optimise.back_off import back_off
from solver.optimise.candidate import ZERO_SPEED, Candidate, Search
from solver.optimise.coarse_search import Cell, coarse_map_cells, search_cells
from solver.optimise.local_search import REFINED_CELLS, climbs, refine_cells
from solver.optimise.methods.placement_scipy import (
    Basin,
    SearchSize,
    global_search,
    search_placements,
    search_size,
)
from solver.optimise.methods.search_rows import (
    SEARCH_ROUNDS,
    on_rows,
    search_on_rows,
    searched_waypoints,
)
from solver.optimise.methods.slsqp_polish import polish
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathProblem

DESCRIPTION = "differential_evolution + SLSQP (scipy)"


def size_of(problem: PathProblem, bounds: PlacementBounds) -> SearchSize:
    """The search's size for the problem's family (smaller for a costlier placement)."""
    n_waypoints = len(problem.waypoints)
    return search_size(bounds, path_cost=problem.path_cost(n_waypoints), n_waypoints=n_waypoints)


def check(problem: PathProblem, bounds: PlacementBounds, settings: Search) -> None:
    """Refuse a scipy search too large: its evolution's work, its coarse map's cells.

    Differential evolution whose weighed work is over ``max_search_poses``, and a search that
    starts from a coarse map (``seed_map``) of more than ``max_coarse_cells`` cells. Runs
    before any placement is evaluated (a search too large is refused before any work).

    Raises:
        InvalidInputError: on ``bounds``, saying the size asked for and the limit.
    """
    family, n_waypoints = problem.family, len(problem.waypoints)
    if settings.seed_map:  # its coarse map too, checked before the evolution, not after it
        cells = coarse_map_cells(bounds, symmetric=settings.symmetric)
        if cells > settings.max_coarse_cells:
            raise InvalidInputError(
                "bounds",
                f"the scipy search starts from a coarse map of {cells} cells (20 mm, 15 deg) "
                f"too; the limit is {settings.max_coarse_cells}",
            )
    size = size_of(problem, bounds)
    max_poses = settings.max_search_poses
    if max_poses is None:
        return
    placements = search_placements(bounds, size)
    searched = n_waypoints
    if rows_searched(problem, settings.active_set):
        placements *= SEARCH_ROUNDS
        searched = searched_waypoints(n_waypoints)
    work = placements * problem.path_cost(searched)
    if work > max_poses:
        raise InvalidInputError(
            "bounds",
            f"the scipy search of {int(bounds.free.sum())} free variables evaluates "
            f"{placements} placements * {searched} waypoints = {placements * searched} "
            f"poses, as work {work:.4g} closed-form poses ({family.name} IK); the limit is "
            f"{max_poses}; fix a variable, shorten the path, or use method casadi",
        )


def rows_searched(problem: PathProblem, active_set: bool) -> bool:
    """Whether differential evolution runs on a set of the waypoints (a long program's).

    :mod:`solver.optimise.methods.search_rows`, unless ``active_set`` is off (the reference).
    """
    return active_set and on_rows(len(problem.waypoints))


def search(
    problem: PathProblem, bounds: PlacementBounds, settings: Search
) -> tuple[list[Candidate], int]:
    """Candidates: DE's best placement, SLSQP's polishes, Nelder-Mead climbs; DE's generations.

    Each basin DE saw is climbed first by the compass search, then polished by SLSQP on the
    branch it ends on. The search is sized by :func:`size_of` (smaller for a family whose
    placement costs more).
    """
    progress, size = settings.progress, size_of(problem, bounds)
    evolved = span(progress, 0.0, 0.5 if settings.seed_map else 0.6)
    basins, iterations = _global(problem, bounds, size, evolved, settings)
    best = "best placement of differential evolution"
    if settings.seed_map:
        basins, best = _with_map(problem, bounds, basins, size, span(progress, 0.5, 0.6), settings)
    if not basins:
        return [], iterations
    if problem.prepared.pure_rotation.any() or basins[0][1] <= 0.0:
        return [Candidate(basins[0][0], ZERO_SPEED)], iterations
    candidates = [Candidate(basins[0][0], best)]
    # Each basin's best point climbed by the compass search (which may change the branch),
    # then polished on the branch it ends on.
    refined = refine_cells(
        problem,
        bounds,
        [Cell(vector, mu, branch) for vector, mu, branch in basins],
        count=refined_cells(settings.seed_map, size),
        runner=settings.runner,
    )
    if refined:  # the best size.basins polished (a coarse map's basin may start low)
        basins = [(cell.vector, cell.mu_path, cell.branch) for cell in refined]
    basins = basins[: size.basins]
    for k, (placement, mu_path, branch) in enumerate(basins):
        part = span(progress, 0.6 + 0.35 * k / len(basins), 0.6 + 0.35 * (k + 1) / len(basins))
        on_branch = problem.family.branches[branch]
        candidate, steps = _polished(
            problem, bounds, placement, mu_path, on_branch, size, part, settings
        )
        candidates.append(candidate)
        iterations += steps
        backed = back_off(problem, bounds, placement, candidate)
        if backed is not None:  # SLSQP, blind to the cell, went into it
            candidates.append(backed)
    candidates += climbs(problem, bounds, refined)
    return candidates, iterations


def refined_cells(seed_map: bool, size: SearchSize) -> int:
    """How many basins the compass search climbs: the casadi method's count with the map."""
    return REFINED_CELLS if seed_map else size.basins


def _with_map(
    problem: PathProblem,
    bounds: PlacementBounds,
    basins: list[Basin],
    size: SearchSize,
    progress: Progress | None,
    settings: Search,
) -> tuple[list[Basin], str]:
    """Differential evolution's basins and the coarse map's maxima, best first.

    The map is the casadi method's (:func:`solver.optimise.coarse_search.coarse_cells`), its
    size checked before the search (:func:`solver.optimise.work.seeds_from_map`). Returns the
    basins, best first (evolution's first among equals), and what the best one is. All go to
    the compass search (its best REFINED_CELLS, as the casadi method's): a map's basin that
    holds the optimum may start at its sixth maximum.
    """
    cells = search_cells(problem, bounds, settings, progress=progress)
    mapped = [(cell.vector, cell.mu_path, cell.branch) for cell in cells]
    merged = sorted(
        [(basin, True) for basin in basins] + [(basin, False) for basin in mapped],
        key=lambda item: -item[0][1],
    )
    if not merged:
        return [], ""
    evolved = merged[0][1]
    best = "best placement of differential evolution" if evolved else "best cell of the coarse map"
    return [basin for basin, _ in merged], best


def _global(
    problem: PathProblem,
    bounds: PlacementBounds,
    size: SearchSize,
    progress: Progress | None,
    settings: Search,
) -> tuple[list[Basin], int]:
    """Differential evolution's basins (their whole-path mu_path) and its generations.

    On the whole path, or for a long program on a set of its waypoints
    (:mod:`solver.optimise.methods.search_rows`).
    """
    if not rows_searched(problem, settings.active_set):
        return global_search(
            problem,
            bounds,
            symmetric=settings.symmetric,
            size=size,
            progress=progress,
            runner=settings.runner,
            tried=settings.tried,
        )
    found = search_on_rows(
        problem,
        bounds,
        symmetric=settings.symmetric,
        size=size,
        progress=progress,
        runner=settings.runner,
        tried=settings.tried,
    )
    return found.basins, found.generations


def _polished(
    problem: PathProblem,
    bounds: PlacementBounds,
    placement: np.ndarray,
    mu_path: float,
    branch: Branch,
    size: SearchSize,
    progress: Progress | None,
    settings: Search,
) -> tuple[Candidate, int]:
    """SLSQP's polish from a basin's point, with its iterations.

    On the active set of the point's binding waypoints (:mod:`solver.optimise.active_set`)
    unless ``settings.active_set`` is off or the arm is redundant; the candidate then carries
    the final set.
    """
    if not settings.active_set or problem.robot.dof > 6:
        polished, status, steps = polish(
            problem, bounds, placement, mu_path, branch, size=size, progress=progress
        )
        return Candidate(polished, f"SLSQP: {status}"), steps
    steps_made: list[int] = []

    def solve(subset: PathProblem, rows: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, str]]:
        round_ = span(progress, len(steps_made) / MAX_ROUNDS, (len(steps_made) + 1) / MAX_ROUNDS)
        polished, status, steps = polish(
            subset, bounds, placement, mu_path, branch, size=size, progress=round_
        )
        steps_made.append(steps)
        return polished, (polished, status)

    speeds, failing = whole_path_bounds(problem, bounds, placement, branch)
    first = first_rows(problem, speeds, failing)
    looped = solve_on_active_set(problem, bounds, branch, first, solve)
    vector, status = looped.solved
    return Candidate(vector, f"SLSQP: {status}", rows=looped.rows), sum(steps_made)
