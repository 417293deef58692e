"""SLSQP's polish of a placement on the epigraph form, the scipy method's local solve.

From a feasible start on one IK branch: maximise s  s.t.  V_i(v) >= s  for every waypoint i,
with V_i on that branch and its gradient by central differences (one batch of placements),
over the free variables of the decision vector (:mod:`solver.optimise.search_space`). Called
on the whole path or, on active sets, on the waypoints that bind
(:mod:`solver.optimise.methods.scipy_method`).
"""

from __future__ import annotations

import numpy as np
import scipy.optimize

from solver.core.family import Branch
from solver.core.progress import Progress
from solver.optimise.methods.placement_scipy import FULL_SEARCH, SearchSize, full_vectors
from solver.optimise.search_space import PlacementBounds
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem

DIFFERENCE_STEP = 1e-6  # m and rad, for the polish's gradients


def polish(
    problem: PathProblem,
    bounds: PlacementBounds,
    start: np.ndarray,
    start_speed: float,
    branch: Branch,
    *,
    size: SearchSize = FULL_SEARCH,
    progress: Progress | None = None,
) -> tuple[np.ndarray, str, int]:
    """SLSQP on the epigraph form over the free variables, from a feasible start, on one branch.

    Returns:
        the decision vector, SLSQP's message, its iterations.
    """
    free = bounds.free
    n_free = int(free.sum())
    steps = np.eye(n_free) * DIFFERENCE_STEP
    offsets = np.vstack([np.zeros(n_free), steps, -steps])
    cache: dict[tuple[float, ...], np.ndarray] = {}
    on_branch = problem.with_options(branch=branch)

    def speeds(v: np.ndarray) -> np.ndarray:
        """V_max per waypoint at v and at v +- steps: (1 + 2F, N), NaN where infeasible."""
        key = tuple(v[:n_free])
        if key not in cache:
            result = evaluate_placements(
                on_branch, bounds.rows(full_vectors(bounds, v[:n_free] + offsets)), with_speeds=True
            )
            bounds_per_waypoint = result.feed_bounds  # V_max, or with V_acc the least of both
            if bounds_per_waypoint is None:  # not reached: asked for with_speeds
                raise RuntimeError("evaluate_placements returned no speeds")
            cache[key] = bounds_per_waypoint
            if progress is not None:
                progress(len(cache) / (size.polish_iterations + 1))
        return cache[key]

    def margin(v: np.ndarray) -> np.ndarray:
        here = speeds(v)[0]
        values: np.ndarray = np.where(np.isnan(here), -1.0, here) - v[n_free]
        return values

    def margin_gradient(v: np.ndarray) -> np.ndarray:
        table = speeds(v)
        here, plus, minus = table[0], table[1 : 1 + n_free], table[1 + n_free :]
        central = (plus - minus) / (2 * DIFFERENCE_STEP)
        forward = (plus - here) / DIFFERENCE_STEP
        backward = (here - minus) / DIFFERENCE_STEP
        gradient = np.where(
            np.isnan(central), np.where(np.isnan(forward), backward, forward), central
        )
        jacobian: np.ndarray = np.column_stack([np.nan_to_num(gradient.T), -np.ones(len(here))])
        return jacobian

    if n_free == 0:
        return np.asarray(start, dtype=float), "nothing to polish: every variable is fixed", 0
    objective_gradient = np.zeros(n_free + 1)
    objective_gradient[-1] = -1.0
    result = scipy.optimize.minimize(
        lambda v: -v[n_free],
        x0=np.array([*np.asarray(start)[free], start_speed]),
        jac=lambda v: objective_gradient,
        bounds=[*zip(bounds.lower[free], bounds.upper[free], strict=True), (0.0, None)],
        constraints=[{"type": "ineq", "fun": margin, "jac": margin_gradient}],
        method="SLSQP",
        options={"ftol": 1e-14, "maxiter": size.polish_iterations},
    )
    vector = full_vectors(bounds, result.x[None, :n_free])[0]
    return vector, str(result.message), int(result.nit)
