"""A numeric-IK optimisation against the analytic UR5's of the same size (issue 26).

The Jaco2 (numeric IK, 6 joints, non-spherical wrist) on the README path's first two waypoints,
x -0.25..0.25 m, y 0.25..0.65 m, any yaw, z 0.1 m: 32.8 s before the compiled chain. Each
method's time (best of a few) and optimum, beside the analytic UR5 on the same problem in the
same run (the baseline; the ratio is what holds on a loaded machine), and the work the service
weighs it as (:mod:`solver.optimise.work`). Then the weight of a placement evaluated on its own
against one in a batch (``SINGLE_PLACEMENT_COST``), measured on both arms.
"""

from __future__ import annotations

import math

import numpy as np
from timing import best_time

from solver.families import get_robot
from solver.optimise.optimize import optimize_placement
from solver.optimise.optimum import PlacementOptimum
from solver.optimise.search_space import PlacementBounds
from solver.optimise.work import SINGLE_PLACEMENT_COST, work_of
from solver.path.placement_evaluator import PlacementEvaluator
from solver.path.placements import evaluate_placements
from solver.path.problem import PathProblem

ARMS = ("ur5", "kinova_jaco2")  # the baseline first


def numeric_optimisation_lines(path: np.ndarray, *, smoke: bool) -> None:
    """Print each method's time and optimum on both arms, and the one-at-a-time weight."""
    if smoke:
        bounds = PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(-0.2, 0.2), z=0.1)
        repeats = 1
    else:
        bounds = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
        repeats = 3
    waypoints = path[:2]
    print(
        f"2-waypoint optimisation (issue 26): x {bounds.x}, y {bounds.y}, yaw "
        f"({bounds.yaw[0]:.3f}, {bounds.yaw[1]:.3f}), z {bounds.z}, best of {repeats}"
    )
    for method in ("casadi", "scipy"):
        seconds: dict[str, float] = {}
        for name in ARMS:
            problem = PathProblem.of(get_robot(name), waypoints)
            found: list[PlacementOptimum] = []

            def run(
                problem: PathProblem = problem,
                method: str = method,
                found: list[PlacementOptimum] = found,
            ) -> None:
                found.append(optimize_placement(problem, bounds=bounds, method=method))

            run()  # warm up (the kernels)
            seconds[name] = best_time(run, repeats)
            optimum = found[-1]
            work = work_of(problem, bounds, method=method).weighed(problem)
            value = (
                "no feasible placement"
                if optimum.mu_path is None
                else f"mu_path {optimum.mu_path:.6f} m/s"
            )
            line = f"  {method:6s} {name:13s} {seconds[name]:7.3f} s   {value}, "
            line += f"weighed as {work:.3g} closed-form poses"
            if name != ARMS[0]:
                line += f"; {seconds[name] / seconds[ARMS[0]]:.1f}x the {ARMS[0]}"
            print(line)
    _single_placement_weight(waypoints, bounds)


def _single_placement_weight(waypoints: np.ndarray, bounds: PlacementBounds) -> None:
    """One placement a call against a batch of 32, per placement, on both arms."""
    rng = np.random.default_rng(0)
    count = 32
    rows = np.column_stack(
        [
            rng.uniform(*bounds.x, count),
            rng.uniform(*bounds.y, count),
            np.full(count, bounds.z),
            rng.uniform(*bounds.yaw, count),
            np.zeros(count),
        ]
    )
    ratios = []
    for name in ARMS:
        problem = PathProblem.of(get_robot(name), waypoints)
        evaluate = PlacementEvaluator(problem)
        evaluate(rows[:1])  # warm up
        batch = best_time(lambda problem=problem: evaluate_placements(problem, rows), 3) / count
        single = best_time(lambda evaluate=evaluate: [evaluate(row[None]) for row in rows], 3)
        single /= count
        ratios.append(f"{name} {single / batch:.2f}x ({1e3 * single:.3f} ms a placement)")
    print(
        "  one placement a call against a batch of 32: "
        + "; ".join(ratios)
        + f" (weighed as {SINGLE_PLACEMENT_COST:g}x)"
    )
