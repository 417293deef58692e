"""The ``scipy`` method: differential evolution, compass refinement, SLSQP, Nelder-Mead climbs.

Differential evolution over the free variables, every generation one batch through
:mod:`solver.path.placements`; each basin it saw is climbed by the compass search, then
polished by SLSQP on the epigraph form with finite-difference gradients on the branch it ends
on (:mod:`solver.optimise.methods.placement_scipy`); Nelder-Mead climbs mu_path from the best.
"""

from __future__ import annotations

from solver.core.exceptions import InvalidInputError
from solver.core.progress import span
from solver.optimise.candidate import ZERO_SPEED, Candidate, Search
from solver.optimise.coarse_search import Cell
from solver.optimise.local_search import climbs, refine_cells
from solver.optimise.methods.placement_scipy import (
    SearchSize,
    global_search,
    polish,
    search_placements,
    search_size,
)
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathProblem

DESCRIPTION = "differential_evolution + SLSQP (scipy)"


def _size(problem: PathProblem, bounds: PlacementBounds) -> SearchSize:
    """The search's size for the problem's family (smaller for a costlier placement)."""
    n_waypoints = len(problem.waypoints)
    return search_size(bounds, path_cost=problem.path_cost(n_waypoints), n_waypoints=n_waypoints)


def check(problem: PathProblem, bounds: PlacementBounds, settings: Search) -> None:
    """Refuse a differential evolution whose weighed work is over ``max_search_poses``.

    Runs before the path is prepared (a search too large is refused before any work).

    Raises:
        InvalidInputError: on ``bounds``, saying the size asked for and the limit.
    """
    family, n_waypoints = problem.family, len(problem.waypoints)
    size = _size(problem, bounds)
    max_poses = settings.max_search_poses
    if max_poses is None:
        return
    placements = search_placements(bounds, size)
    work = placements * problem.path_cost(n_waypoints)
    if work > max_poses:
        raise InvalidInputError(
            "bounds",
            f"the scipy search of {int(bounds.free.sum())} free variables evaluates "
            f"{placements} placements * {n_waypoints} waypoints = {placements * n_waypoints} "
            f"poses, as work {work:.4g} closed-form poses ({family.name} IK); the limit is "
            f"{max_poses}; fix a variable, shorten the path, or use method casadi",
        )


def search(
    problem: PathProblem, bounds: PlacementBounds, settings: Search
) -> tuple[list[Candidate], int]:
    """Candidates: DE's best placement, SLSQP's polishes, Nelder-Mead climbs; DE's generations.

    Each basin DE saw is climbed first by the compass search, then polished by SLSQP on the
    branch it ends on. The search is sized by :func:`_size` (smaller for a family whose
    placement costs more).
    """
    progress, size = settings.progress, _size(problem, bounds)
    basins, iterations = global_search(
        problem,
        bounds,
        symmetric=settings.symmetric,
        size=size,
        progress=span(progress, 0.0, 0.6),
        runner=settings.runner,
    )
    if not basins:
        return [], iterations
    if problem.prepared.pure_rotation.any() or basins[0][1] <= 0.0:
        return [Candidate(basins[0][0], ZERO_SPEED)], iterations
    candidates = [Candidate(basins[0][0], "best placement of differential evolution")]
    # Each basin's best point climbed by the compass search (which may change the branch),
    # then polished on the branch it ends on.
    refined = refine_cells(
        problem,
        bounds,
        [Cell(vector, mu, branch) for vector, mu, branch in basins],
        runner=settings.runner,
    )
    if refined:
        basins = [(cell.vector, cell.mu_path, cell.branch) for cell in refined]
    for k, (placement, mu_path, branch) in enumerate(basins):
        polished, status, steps = polish(
            problem,
            bounds,
            placement,
            mu_path,
            problem.family.branches[branch],
            size=size,
            progress=span(
                progress, 0.6 + 0.35 * k / len(basins), 0.6 + 0.35 * (k + 1) / len(basins)
            ),
        )
        candidates.append(Candidate(polished, f"SLSQP: {status}"))
        iterations += steps
    candidates += climbs(problem, bounds, refined)
    return candidates, iterations
