"""Benchmark lines of joint acceleration limits (issue 24): the map and the optimisers with them.

Run by ``bench/run.py``, or alone from the repository root: ``python bench/acceleration.py``.
The ERK-size map (UR5, 546 placements, 133 waypoints) with every joint limited to 10 rad/s^2
against the same map without, in the same run, both by the compiled kernel (the goal: at most
1.3x), in fixed and in free spin; and, for scale, the numpy pipeline with the limits. Then the
ERK optimisation with the limits (each method's time and mu_acc), against the velocity-only
optimum evaluated with the limits.
"""

from __future__ import annotations

import math
import time

import numpy as np
from timing import best_time

from solver.core.robots import Robot
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.path.capability_map import capability_map
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem

LIMIT = 10.0  # rad/s^2, every joint


def acceleration_lines(
    robot: Robot,
    path: np.ndarray,
    xs: np.ndarray,
    ys: np.ndarray,
    z: float,
    *,
    repeats: int,
    smoke: bool = False,
) -> None:
    """Print the map with acceleration limits against the map without, and the optimisers.

    ``smoke``: the optimisers on a small box (to check that the script runs).
    """
    limited = robot.with_options(qddot_max=[LIMIT] * robot.dof)
    yaws = np.zeros(1)
    cells = len(xs) * len(ys)
    print(f"ERK-size map with joint acceleration limits ({LIMIT:g} rad/s^2, {cells} placements):")
    for spin_mode in ("fixed", "free"):
        options = PathOptions(spin_mode=spin_mode)  # type: ignore[arg-type]

        def run_map(arm: Robot, compiled: bool = True, options: PathOptions = options) -> object:
            problem = PathProblem.of(arm, path, options)
            return capability_map(problem, xs=xs, ys=ys, z=z, yaws=yaws, compiled=compiled)

        run_map(robot)
        run_map(limited)  # warm up
        t_without, t_with = math.inf, math.inf
        for _ in range(repeats):  # alternated, so that a swing of the machine's load hits both
            t_without = min(t_without, best_time(lambda: run_map(robot), 1))
            t_with = min(t_with, best_time(lambda: run_map(limited), 1))
        t_numpy = best_time(lambda: run_map(limited, compiled=False), 1)
        print(
            f"  {spin_mode:5s} spin, compiled kernel: with the limits {t_with:7.3f} s, without "
            f"{t_without:7.3f} s: {t_with / t_without:.2f}x (goal <= 1.3x); the numpy pipeline "
            f"with the limits {t_numpy:.3f} s ({t_numpy / t_with:.1f}x the kernel)"
        )
    bounds = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-np.pi, np.pi), z=z)
    if smoke:
        bounds = PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(-0.2, 0.2), z=z)
    problem = PathProblem.of(limited, path)
    for method in ("casadi", "scipy"):
        start = time.perf_counter()
        speed_only = optimize_placement(PathProblem.of(robot, path), bounds=bounds, method=method)
        t_speed = time.perf_counter() - start
        start = time.perf_counter()
        optimum = optimize_placement(problem, bounds=bounds, method=method)
        seconds = time.perf_counter() - start
        if optimum.placement is None or optimum.mu_acc is None or speed_only.placement is None:
            print(f"  {method}: nothing feasible")
            continue
        judged = evaluate_path(problem, speed_only.placement)
        p = optimum.placement
        print(
            f"  {method:6s} with the limits {seconds:6.2f} s ({seconds / t_speed:.1f}x the "
            f"velocity-only search, {t_speed:.2f} s): mu_acc {optimum.mu_acc:.6f} m/s (mu_path "
            f"{optimum.mu_path:.6f}) at x {p.x:.4f}, y {p.y:.4f}, yaw {p.yaw:.4f}; the "
            f"velocity-only optimum (mu_path {speed_only.mu_path:.6f}) runs at mu_acc "
            f"{judged.feed_index:.6f}"
        )


if __name__ == "__main__":
    import run  # bench/run.py, beside this script

    from solver.families import get_robot
    from solver.path.capability_map import grid_axis

    acceleration_lines(
        get_robot("ur5"),
        run.load_path("curved_line"),
        grid_axis(-0.25, 0.25, 0.02, field="x"),
        grid_axis(0.25, 0.65, 0.02, field="y"),
        0.1,
        repeats=5,
    )
