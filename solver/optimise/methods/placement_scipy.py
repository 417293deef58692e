"""The scipy placement search: differential evolution, then SLSQP on the epigraph form.

Differential evolution needs no gradients and looks at the whole box; every generation is one
batch through :func:`solver.path.placements.evaluate_placements`. The best points of the few best
distinct basins it saw are then polished by SLSQP on the epigraph form
(:mod:`solver.optimise.methods.slsqp_polish`). Both work on the free variables of the decision
vector (:mod:`solver.optimise.search_space`: x, y, yaw and the tool spin when its range is not
one value).

The search's size (population, generations, polish iterations) is the full one for a
closed-form family, whose placement costs one unit of work a waypoint. A family whose placement
costs more (:meth:`KinematicsFamily.path_cost`: numeric IK on a short path, about a thousand
times more) gets a smaller search, so that its work stays near SEARCH_WORK (:func:`search_size`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.optimize

from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress
from solver.optimise.failures import Tried
from solver.optimise.search_space import PlacementBounds, variables_of
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem

SEED = 0  # differential evolution is seeded: same input, same output
POLISH_ITERATIONS = 200  # SLSQP iterations at most from one start
POPULATION = 20  # per dimension
GENERATIONS = 60
INFEASIBLE = 1.0  # objective of an infeasible placement (feasible ones are -mu_path <= 0)
N_BASINS = 3  # distinct basins polished
BASIN_GAP = (0.05, 0.35)  # m and rad (about 20 degrees): placements closer are one basin

Basin = tuple[np.ndarray, float, int]  # decision vector, mu_path, branch index
# Work of a costly family's search, in poses of a closed-form family (the unit of
# KinematicsFamily.path_cost): about 8 s of work on the 2-core development machine (3.8 us a
# pose). The Panda on 10 waypoints (path_cost 10,000) then gets the floors below: about 20 s
# for the whole search instead of about 200 s at the full size.
SEARCH_WORK = 2e6
MIN_POPULATION = 5  # per dimension: scipy's least useful population
MIN_GENERATIONS = 10
MIN_POLISH_ITERATIONS = 15


@dataclass(frozen=True)
class SearchSize:
    """The size of the scipy search.

    Attributes:
        population: differential evolution's population per free variable.
        generations: its generations at most.
        polish_iterations: SLSQP's iterations at most from each start.
        basins: how many distinct basins are polished.
    """

    population: int = POPULATION
    generations: int = GENERATIONS
    polish_iterations: int = POLISH_ITERATIONS
    basins: int = N_BASINS


FULL_SEARCH = SearchSize()


def search_size(bounds: PlacementBounds, *, path_cost: float, n_waypoints: int) -> SearchSize:
    """The search's size for a family whose placement of the path costs ``path_cost``.

    A closed-form family (``path_cost <= n_waypoints``: one unit a waypoint) gets the full
    search, whatever the path's length. A costlier one gets the full search's work scaled by
    f = SEARCH_WORK / (full placements * path_cost) (at most 1): the population and the
    generations each by sqrt(f), so that the placements scale by f, and the polish iterations
    and the basins polished by f; each no less than its floor (MIN_POPULATION,
    MIN_GENERATIONS, MIN_POLISH_ITERATIONS, one basin).

    Args:
        bounds: the box (its free variables are the search's dimensions).
        path_cost: the family's work for one placement of the path, in closed-form poses.
        n_waypoints: N.
    """
    if path_cost <= n_waypoints:
        return FULL_SEARCH
    # The full search's nominal placements (Sobol's rounding aside): the sizes as calibrated.
    full = (GENERATIONS + 1) * POPULATION * max(int(bounds.free.sum()), 1)
    fraction = min(1.0, SEARCH_WORK / (full * path_cost))
    return SearchSize(
        population=max(MIN_POPULATION, round(POPULATION * math.sqrt(fraction))),
        generations=max(MIN_GENERATIONS, round(GENERATIONS * math.sqrt(fraction))),
        polish_iterations=max(MIN_POLISH_ITERATIONS, round(POLISH_ITERATIONS * fraction)),
        basins=max(1, round(N_BASINS * fraction)),
    )


def search_placements(bounds: PlacementBounds, size: SearchSize = FULL_SEARCH) -> int:
    """How many placements differential evolution evaluates in ``bounds`` (at most).

    The first population and one a generation. scipy makes a population of
    max(5, population * free variables) members, and a Sobol start (``init="sobol"``, as
    :func:`global_search` asks) rounds that up to a power of two: 3 free variables at 20 each
    are 64 members, not 60 (the Jaco2's smallest search, 7 each: 32, not 21).
    """
    n_free = int(bounds.free.sum())
    if not n_free:
        return 1
    members = max(5, size.population * n_free)
    return (size.generations + 1) * (1 << (members - 1).bit_length())


def full_vectors(bounds: PlacementBounds, free_values: np.ndarray) -> np.ndarray:
    """Decision vectors (P, N_VARIABLES) from the free variables' values (P, F); the rest fixed."""
    vectors = np.tile(bounds.lower, (len(free_values), 1))
    vectors[:, bounds.free] = free_values
    return vectors


def _basin_coordinates(vectors: np.ndarray, symmetric: bool) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates in which basins are BASIN_GAP apart, and their scale (angles as cos, sin)."""
    x, y, yaw, spin, z = variables_of(vectors.T)
    angles = [np.cos(spin), np.sin(spin)]
    if symmetric:
        psi = yaw - np.arctan2(y, x)
        columns = [np.hypot(x, y) / BASIN_GAP[0], z / BASIN_GAP[0], np.cos(psi), np.sin(psi)]
        scale = [1.0, 1.0] + [1.0 / BASIN_GAP[1]] * 4
    else:
        columns = [x / BASIN_GAP[0], y / BASIN_GAP[0], z / BASIN_GAP[0], np.cos(yaw), np.sin(yaw)]
        scale = [1.0, 1.0, 1.0] + [1.0 / BASIN_GAP[1]] * 4
    return np.column_stack([*columns, *angles]), np.array(scale)


def global_search(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    symmetric: bool,
    size: SearchSize = FULL_SEARCH,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> tuple[list[Basin], int]:
    """Differential evolution over the free variables; the best point of each distinct basin.

    Every placement DE evaluates is kept (in ``tried`` too, with its outcome); the best ones
    that lie apart (:func:`distinct_best`) are returned, up to ``size.basins``: DE settles in
    one basin, and the landscape has near-equal mirror-image optima.

    Returns:
        ([(decision vector, mu_path, branch index), ...] best first, generations).
    """
    seen, generations = evolve(
        problem, bounds, size=size, progress=progress, runner=runner, tried=tried
    )
    chosen = distinct_best(seen, symmetric, size.basins)
    return [(seen.vectors[i].copy(), float(seen.mu[i]), int(seen.branch[i])) for i in chosen], (
        generations
    )


@dataclass(frozen=True)
class Seen:
    """Every placement a differential evolution evaluated, in order.

    Attributes:
        vectors: shape (P, N_VARIABLES), the decision vectors.
        mu: shape (P,), m/s, the index DE maximised (mu_path, or mu_acc), NaN where infeasible.
        branch: shape (P,), the branch index at each.
    """

    vectors: np.ndarray
    mu: np.ndarray
    branch: np.ndarray


def evolve(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    size: SearchSize = FULL_SEARCH,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
    tried: Tried | None = None,
) -> tuple[Seen, int]:
    """Differential evolution over the free variables of ``bounds``, on ``problem``'s path.

    ``tried`` keeps every placement evaluated with its outcome (pass it only where
    ``problem`` is the whole path: :mod:`solver.optimise.failures`).

    With a cell, a placement in collision scores worse than any feasible one but by its
    mu_path without the cell (``collisions_scored``), not as flat as the kinematics'
    refusals.

    Returns:
        every placement evaluated, and DE's generations.
    """
    seen: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    clear = problem.without_path_checks()  # the kinematics alone, for placements refused

    def objective(points: np.ndarray) -> np.ndarray:  # points: (F, S)
        vectors = full_vectors(bounds, points.T)
        rows = bounds.rows(vectors)
        result = evaluate_placements(problem, rows, runner=runner)
        if tried is not None:
            tried.record(rows, result.reason, result.failed_waypoint)
        seen.append((vectors, result.feed_index, result.branch))
        if progress is not None:
            progress(len(seen) / (size.generations + 1))
        values: np.ndarray = np.where(np.isnan(result.feed_index), INFEASIBLE, -result.feed_index)
        if problem.path_checks:
            values = collisions_scored(values, vectors, result.reason)
        return values

    def collisions_scored(
        values: np.ndarray, vectors: np.ndarray, reasons: np.ndarray
    ) -> np.ndarray:
        """Each placement the cell refuses scored by its mu_path without the cell.

        1 / (2 + mu_path): worse than any feasible placement (<= 0), better than one the
        kinematics refuse (INFEASIBLE), and better the faster the arm would be there: the
        population keeps moving towards the fast placements, whose edge against the obstacles
        is where the cell's optimum lies, instead of settling in the first clear basin.
        """
        refused = np.flatnonzero(np.isin(reasons, [c.reason for c in problem.path_checks]))
        if len(refused):
            kinematic = evaluate_placements(clear, bounds.rows(vectors[refused]), runner=runner)
            values[refused] = 1.0 / (2.0 + np.nan_to_num(kinematic.feed_index))
        return values

    free = bounds.free
    if not free.any():  # nothing to search: the one placement of the box
        objective(np.zeros((0, 1)))
        generations = 0
    else:
        found = scipy.optimize.differential_evolution(
            objective,
            bounds=list(zip(bounds.lower[free], bounds.upper[free], strict=True)),
            popsize=size.population,
            maxiter=size.generations,
            tol=1e-12,
            atol=0.0,
            seed=SEED,
            polish=False,
            init="sobol",
            updating="deferred",
            vectorized=True,
        )
        generations = int(found.nit)
    return Seen(
        np.concatenate([s[0] for s in seen]),
        np.concatenate([s[1] for s in seen]),
        np.concatenate([s[2] for s in seen]),
    ), generations


def distinct_best(seen: Seen, symmetric: bool, count: int) -> list[int]:
    """The indices of the best feasible placements that lie apart, best first, ``count`` at most.

    Apart: by BASIN_GAP, in (r, psi) when ``symmetric``, else in (x, y, yaw); spins as angles.
    """
    feasible = np.flatnonzero(~np.isnan(seen.mu))
    order = feasible[np.argsort(-seen.mu[feasible], kind="stable")]
    coordinates, scale = _basin_coordinates(seen.vectors, symmetric)
    chosen: list[int] = []
    for i in order:
        if all(np.max(np.abs(coordinates[i] - coordinates[j]) * scale) > 1.0 for j in chosen):
            chosen.append(int(i))
            if len(chosen) == count:
                break
    return chosen
