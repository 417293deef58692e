"""Local searches on mu_path itself, through the evaluator: no gradient, any branch.

mu_path is the minimum over waypoints of V_max, maximised over IK branches: not smooth, and
its best point often lies where the best branch changes, which a solver that follows one
branch (IPOPT, SLSQP on the epigraph form) cannot cross. Measured on the large box of issue 12
(UR5, x and y in +-0.8 m, yaw free, the README path): IPOPT from the coarse map's maxima gave
0.39967 m/s, differential evolution and SLSQP 0.41016; a compass search from the coarse maxima
0.41385, and Nelder-Mead from there 0.41776, where the best branch changes from wrist
``noflip`` to ``flip``.

- :func:`refine_cells`: a batched compass search from many cells at once, to rank basins by
  how high they climb rather than where they start;
- :func:`climb`: Nelder-Mead from one point, to its top.

Both evaluate with :func:`solver.path.placements.evaluate_placements` on the ``auto`` branch, so
their answers are what the evaluator says, and their work is bounded by the family's cost.
"""

from __future__ import annotations

import numpy as np
import scipy.optimize

from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress
from solver.optimise.candidate import Candidate
from solver.optimise.coarse_search import COARSE_STEP, COARSE_YAW_STEP, Cell
from solver.optimise.search_space import (
    N_VARIABLES,
    PlacementBounds,
    decision_vector,
    placement_rows,
)
from solver.path.placement_evaluator import PlacementEvaluator
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem

# Half the coarse map's step of each variable: the first steps of both searches.
_HALF_STEPS = decision_vector(
    x=COARSE_STEP, y=COARSE_STEP, yaw=COARSE_YAW_STEP, spin=COARSE_YAW_STEP, z=COARSE_STEP
)
_HALF_STEPS /= 2
REFINED_CELLS = 16  # the coarse maxima refined before the IPOPT starts are chosen
REFINE_ROUNDS = 12
# The refinement's work at most, in poses of a closed-form family (KinematicsFamily.path_cost):
# 16 cells of the ERK path (133 waypoints) with x, y and yaw free take 153,216; a family whose
# placement costs more refines fewer cells, or none (numeric IK: about 1,000 times more).
REFINE_WORK = 3e5


def refined_count(
    problem: PathProblem,
    bounds: PlacementBounds,
    *,
    count: int = REFINED_CELLS,
    rounds: int = REFINE_ROUNDS,
) -> int:
    """How many cells :func:`refine_cells` climbs at most: ``count``, fewer within REFINE_WORK.

    Each climbed cell evaluates 2 placements a free variable a round, each weighed by the
    problem's ``path_cost``.
    """
    cost = problem.path_cost(problem.prepared.n_waypoints)
    per_cell = 2 * int(bounds.free.sum()) * rounds * cost
    return min(count, int(REFINE_WORK // max(per_cell, 1.0)))


def refine_cells(
    problem: PathProblem,
    bounds: PlacementBounds,
    cells: list[Cell],
    *,
    count: int = REFINED_CELLS,
    rounds: int = REFINE_ROUNDS,
    progress: Progress | None = None,
    runner: TaskRunner = SERIAL,
) -> list[Cell]:
    """The cells, the best ``count`` of them climbed by a compass search; best first.

    Fewer are climbed where their work would pass REFINE_WORK, none where one cell's would
    (the cells then come back as they were).

    A coarse cell's mu_path says how high its basin starts, not how high it goes: on a large
    box the basin that holds the optimum may start at the sixth maximum. Each round moves every
    cell to its best neighbour half a coarse step away along one free variable (x, y, z:
    COARSE_STEP / 2; yaw, spin: COARSE_YAW_STEP / 2), clipped to the bounds, or halves its
    steps where no neighbour is better. All cells' neighbours are one batch of
    :func:`solver.path.placements.evaluate_placements`: 16 cells x 6 neighbours x 12 rounds is
    1,152 placements, about as many as the coarse map of the ERK box. ``progress`` hears
    after each round (and may stop the work there).
    """
    free = np.flatnonzero(bounds.free)
    count = refined_count(problem, bounds, count=count, rounds=rounds)
    rest, cells = cells[count:], cells[:count]
    if not cells:
        return rest
    vectors = np.array([cell.vector for cell in cells])  # (K, N_VARIABLES)
    mu = np.array([cell.mu_path for cell in cells])
    branch = np.array([cell.branch for cell in cells])
    lower, upper = bounds.lower, bounds.upper
    steps = np.tile(
        _HALF_STEPS,
        (len(cells), 1),
    )
    for round_ in range(rounds):
        moves = []
        for variable in free:
            for sign in (1.0, -1.0):
                moved = vectors.copy()
                moved[:, variable] = np.clip(
                    moved[:, variable] + sign * steps[:, variable],
                    lower[variable],
                    upper[variable],
                )
                moves.append(moved)
        if not moves:
            break
        trial = np.stack(moves)  # (M, K, N_VARIABLES)
        result = evaluate_placements(
            problem, placement_rows(trial.reshape(-1, N_VARIABLES)), runner=runner
        )
        values = np.nan_to_num(result.feed_index, nan=-np.inf).reshape(len(moves), len(cells))
        best = values.argmax(axis=0)
        best_value = values[best, np.arange(len(cells))]
        better = best_value > mu
        rows = np.flatnonzero(better)
        vectors[rows] = trial[best[rows], rows]
        mu[rows] = best_value[rows]
        branch[rows] = result.branch.reshape(len(moves), len(cells))[best[rows], rows]
        steps[~better] /= 2
        if progress is not None:
            progress((round_ + 1) / rounds)
    refined = [
        Cell(vectors[k], float(mu[k]), int(branch[k]), coarse=cells[k]) for k in range(len(cells))
    ]
    return sorted(refined + rest, key=lambda cell: -cell.mu_path)  # stable: ties keep order


CLIMB_EVALUATIONS = 600  # Nelder-Mead's placements at most from one start
# Its work at most, in poses of a closed-form family: 600 placements of 133 waypoints take
# 79,800; a costlier family gets fewer evaluations, and none below CLIMB_MIN_EVALUATIONS.
CLIMB_WORK = 2e5
CLIMB_MIN_EVALUATIONS = 50
_TOLERANCE = 1e-7  # m and rad, of Nelder-Mead's simplex


def climb_budget(problem: PathProblem, bounds: PlacementBounds) -> int:
    """The evaluations one :func:`climb` asks Nelder-Mead for: 0 where it does not climb.

    CLIMB_EVALUATIONS, fewer within CLIMB_WORK (each placement weighed by the problem's
    ``path_cost``); 0 below CLIMB_MIN_EVALUATIONS or with nothing free.
    """
    cost = problem.path_cost(problem.prepared.n_waypoints)
    budget = min(CLIMB_EVALUATIONS, int(CLIMB_WORK // max(cost, 1.0)))
    return budget if budget >= CLIMB_MIN_EVALUATIONS and bounds.free.any() else 0


def climb_evaluations(problem: PathProblem, bounds: PlacementBounds) -> int:
    """The placements one :func:`climb` evaluates at most, one at a time.

    scipy 1.17 stops Nelder-Mead at its budget exactly; releases before it checked the budget
    between iterations, and one iteration evaluates up to F + 2 points (a reflection, a
    contraction, then a shrink of F vertices) for F free variables: at most budget + F + 1
    (0 where it does not climb).
    """
    budget = climb_budget(problem, bounds)
    return budget + int(bounds.free.sum()) + 1 if budget else 0


def climb(problem: PathProblem, bounds: PlacementBounds, start: Cell) -> Cell | None:
    """Nelder-Mead on mu_path (mu_acc with acceleration limits) from ``start``, in the bounds.

    The first simplex spans half a coarse step along each free variable. Deterministic.

    Returns:
        the best point found (never worse than ``start``), or None where the family's cost
        leaves fewer than CLIMB_MIN_EVALUATIONS or nothing is free.
    """
    free = np.flatnonzero(bounds.free)
    budget = climb_budget(problem, bounds)
    if not budget:
        return None
    best = [start]
    evaluate = PlacementEvaluator(problem)

    def negative_mu(values: np.ndarray) -> float:
        vector = start.vector.copy()
        vector[free] = np.clip(values, bounds.lower[free], bounds.upper[free])
        result = evaluate(placement_rows(vector[None]))
        mu = float(result.feed_index[0])
        if np.isnan(mu):
            return 1.0
        if mu > best[0].mu_path:
            best[0] = Cell(vector, mu, int(result.branch[0]))
        return -mu

    origin = start.vector[free]
    simplex = np.vstack([origin, origin + np.diag(_HALF_STEPS[free])])
    scipy.optimize.minimize(
        negative_mu,
        origin,
        method="Nelder-Mead",
        bounds=list(zip(bounds.lower[free], bounds.upper[free], strict=True)),
        options={
            "initial_simplex": np.clip(simplex, bounds.lower[free], bounds.upper[free]),
            "xatol": _TOLERANCE,
            "fatol": 1e-12,
            "maxfev": budget,
        },
    )
    return best[0]


N_CLIMBS = 2  # Nelder-Mead climbs on mu_path, from the best refined cells
CLIMB_STATUS = "Nelder-Mead on mu_path, from a refined cell"  # a climb's candidate status
CLIMB_STATUS_ACC = "Nelder-Mead on mu_acc, from a refined cell"  # with acceleration limits


def climb_status(problem: PathProblem) -> str:
    """A climb's candidate status: the index it climbed (mu_acc with acceleration limits)."""
    return CLIMB_STATUS if problem.robot.qddot_max is None else CLIMB_STATUS_ACC


def climbs(problem: PathProblem, bounds: PlacementBounds, cells: list[Cell]) -> list[Candidate]:
    """Nelder-Mead on mu_path (mu_acc) from the best N_CLIMBS cells: across branches, to tops."""
    candidates = []
    for cell in cells[:N_CLIMBS]:
        top = climb(problem, bounds, cell)
        if top is not None:
            candidates.append(Candidate(top.vector, climb_status(problem)))
    return candidates
