"""The scipy placement search: differential evolution, then SLSQP on the epigraph form.

Differential evolution needs no gradients and looks at the whole box; every generation is one
batch through :func:`solver.placements.evaluate_placements`. The best points of the few best
distinct basins it saw are then polished by SLSQP on  maximise s  s.t.  V_i(x, y, yaw) >= s
for every waypoint i, with V_i on the IK branch of that point and its gradient by central
differences (one batch of 7 placements).
"""

from __future__ import annotations

import numpy as np
import scipy.optimize

from solver.families.base import Branch
from solver.pipeline import PreparedPath, SpinMode
from solver.placements import evaluate_placements
from solver.robots import Robot
from solver.symmetry import PlacementBounds

SEED = 0  # differential evolution is seeded: same input, same output
POPULATION = 20  # per dimension
GENERATIONS = 60
DIFFERENCE_STEP = 1e-6  # m and rad, for the polish's gradients
INFEASIBLE = 1.0  # objective of an infeasible placement (feasible ones are -mu_path <= 0)
N_BASINS = 3  # distinct basins polished
BASIN_GAP = (0.05, 0.35)  # m and rad (about 20 degrees): placements closer are one basin


def _placements(points: np.ndarray, z: float) -> np.ndarray:
    """(P, 4) placements [x, y, z, yaw] from points (P, 3) [x, y, yaw]."""
    return np.column_stack([points[:, 0], points[:, 1], np.full(len(points), z), points[:, 2]])


def global_search(
    robot: Robot,
    path: PreparedPath,
    bounds: PlacementBounds,
    *,
    max_joint_step: float,
    symmetric: bool,
    spin_mode: SpinMode = "fixed",
) -> tuple[list[tuple[tuple[float, float, float], float, int]], int]:
    """Differential evolution over (x, y, yaw); the best placement of each distinct basin seen.

    Every placement DE evaluates is kept; the best ones that lie apart (by BASIN_GAP, in
    (r, psi) when ``symmetric``, else in (x, y, yaw)) are returned, up to N_BASINS: DE settles
    in one basin, and the landscape has near-equal mirror-image optima.

    Returns:
        ([((x, y, yaw), mu_path, branch index), ...] best first, generations).
    """
    seen: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []

    def objective(points: np.ndarray) -> np.ndarray:  # points: (3, S)
        result = evaluate_placements(
            robot,
            path,
            _placements(points.T, bounds.z),
            max_joint_step=max_joint_step,
            spin_mode=spin_mode,
        )
        seen.append((points.T.copy(), result.mu_path, result.branch))
        values: np.ndarray = np.where(np.isnan(result.mu_path), INFEASIBLE, -result.mu_path)
        return values

    found = scipy.optimize.differential_evolution(
        objective,
        bounds=[bounds.x, bounds.y, bounds.yaw],
        popsize=POPULATION,
        maxiter=GENERATIONS,
        tol=1e-12,
        atol=0.0,
        seed=SEED,
        polish=False,
        init="sobol",
        updating="deferred",
        vectorized=True,
    )
    points = np.concatenate([s[0] for s in seen])
    mu = np.concatenate([s[1] for s in seen])
    branch = np.concatenate([s[2] for s in seen])
    feasible = np.flatnonzero(~np.isnan(mu))
    order = feasible[np.argsort(-mu[feasible], kind="stable")]
    if symmetric:
        radius = np.hypot(points[:, 0], points[:, 1])
        psi = points[:, 2] - np.arctan2(points[:, 1], points[:, 0])
        coordinates = np.column_stack([radius / BASIN_GAP[0], np.cos(psi), np.sin(psi)])
        scale = np.array([1.0, 1.0 / BASIN_GAP[1], 1.0 / BASIN_GAP[1]])
    else:
        coordinates = np.column_stack(
            [
                points[:, 0] / BASIN_GAP[0],
                points[:, 1] / BASIN_GAP[0],
                np.cos(points[:, 2]),
                np.sin(points[:, 2]),
            ]
        )
        scale = np.array([1.0, 1.0, 1.0 / BASIN_GAP[1], 1.0 / BASIN_GAP[1]])
    chosen: list[int] = []
    for i in order:
        if all(np.max(np.abs(coordinates[i] - coordinates[j]) * scale) > 1.0 for j in chosen):
            chosen.append(int(i))
            if len(chosen) == N_BASINS:
                break
    basins = [
        (
            (float(points[i, 0]), float(points[i, 1]), float(points[i, 2])),
            float(mu[i]),
            int(branch[i]),
        )
        for i in chosen
    ]
    return basins, int(found.nit)


def polish(
    robot: Robot,
    path: PreparedPath,
    bounds: PlacementBounds,
    start: tuple[float, float, float],
    start_speed: float,
    branch: Branch,
    *,
    max_joint_step: float,
    spin_mode: SpinMode = "fixed",
) -> tuple[tuple[float, float, float], str, int]:
    """SLSQP on the epigraph form from a feasible start, on one IK branch.

    Returns:
        (x, y, yaw), SLSQP's message, its iterations.
    """
    offsets = np.vstack([np.zeros(3), np.eye(3) * DIFFERENCE_STEP, -np.eye(3) * DIFFERENCE_STEP])
    cache: dict[tuple[float, ...], np.ndarray] = {}

    def speeds(v: np.ndarray) -> np.ndarray:
        """V_max per waypoint at v and at v +- steps: (7, N), NaN where infeasible."""
        key = tuple(v[:3])
        if key not in cache:
            result = evaluate_placements(
                robot,
                path,
                _placements(v[:3] + offsets, bounds.z),
                branch=branch,
                max_joint_step=max_joint_step,
                spin_mode=spin_mode,
                with_speeds=True,
            )
            if result.v_max is None:  # not reached: asked for with_speeds
                raise RuntimeError("evaluate_placements returned no speeds")
            cache[key] = result.v_max
        return cache[key]

    def margin(v: np.ndarray) -> np.ndarray:
        here = speeds(v)[0]
        values: np.ndarray = np.where(np.isnan(here), -1.0, here) - v[3]
        return values

    def margin_gradient(v: np.ndarray) -> np.ndarray:
        table = speeds(v)
        here, plus, minus = table[0], table[1:4], table[4:7]
        central = (plus - minus) / (2 * DIFFERENCE_STEP)
        forward = (plus - here) / DIFFERENCE_STEP
        backward = (here - minus) / DIFFERENCE_STEP
        gradient = np.where(
            np.isnan(central), np.where(np.isnan(forward), backward, forward), central
        )
        jacobian: np.ndarray = np.column_stack([np.nan_to_num(gradient.T), -np.ones(len(here))])
        return jacobian

    result = scipy.optimize.minimize(
        lambda v: -v[3],
        x0=np.array([*start, start_speed]),
        jac=lambda v: np.array([0.0, 0.0, 0.0, -1.0]),
        bounds=[bounds.x, bounds.y, bounds.yaw, (0.0, None)],
        constraints=[{"type": "ineq", "fun": margin, "jac": margin_gradient}],
        method="SLSQP",
        options={"ftol": 1e-14, "maxiter": 200},
    )
    x, y, yaw = (float(v) for v in result.x[:3])
    return (x, y, yaw), str(result.message), int(result.nit)
