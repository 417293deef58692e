"""Free spin on a seven-joint arm: the compiled spin LPs against their numpy reference (issue 27).

    python bench/free_spin_lp.py            # 20,000 configurations, the Panda along 2,000 waypoints
    python bench/free_spin_lp.py --smoke

Prints, from one run: the three-variable spin LP (solver.kernels.spin_lp.spin_speed) and the spin
rates at a feed on random directions, compiled against solver.core.dtf_redundant's numpy vertex
enumeration (the same answers, checked here to 1e-9); then the Panda's evaluation along a line in
fixed and in free spin (CPU time), against the ratio of their work weights (PathProblem.path_cost:
FREE_SPIN_REDUNDANT_COST, times the spun paths solved again, PathProblem.exact_spin_weight).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from functools import partial

import numpy as np

from solver.core import dtf_redundant
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.kernels import spin_lp
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem


def cpu(work: Callable[[], object], repeats: int = 2) -> float:
    """The least CPU time of ``repeats`` calls of ``work``."""
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        work()
        best = min(best, time.process_time() - start)
    return float(best)


def line(n: int) -> np.ndarray:
    """``n`` waypoints 10 um apart along x, the tool pointing down."""
    poses = np.tile(np.diag([1.0, -1.0, -1.0, 1.0]), (n, 1, 1))
    poses[:, 0, 3] = 1e-5 * np.arange(n)
    return poses


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--smoke", action="store_true", help="small sizes (CI)")
    args = parser.parse_args()
    count, waypoints = (2_000, 200) if args.smoke else (20_000, 2_000)
    rng = np.random.default_rng(27)
    a, c, b = (rng.normal(size=(7, count)) for _ in range(3))
    limits = rng.uniform(1.0, 3.0, 7)
    spin_lp.spin_speed(a[:, :2], c[:, :2], b[:, :2], limits)  # compile
    spin_lp.spin_rate_at_feed(a[:, :2], c[:, :2], b[:, :2], limits, np.zeros(2))
    speed, _ = dtf_redundant.spin_speed(a, c, b, limits)
    ours, _ = spin_lp.spin_speed(a, c, b, limits)
    np.testing.assert_allclose(ours, speed, rtol=1e-9)
    feed = 0.5 * speed
    lp_numpy = cpu(lambda: dtf_redundant.spin_speed(a, c, b, limits))
    lp_compiled = cpu(lambda: spin_lp.spin_speed(a, c, b, limits))
    rates_numpy = cpu(lambda: dtf_redundant.spin_rate_at_feed(a, c, b, limits, feed))
    rates_compiled = cpu(lambda: spin_lp.spin_rate_at_feed(a, c, b, limits, feed))
    print(f"spin LP, {count} configurations (CPU, best of 2):")
    for label, numpy_time, compiled_time in (
        ("s, sigma, lam", lp_numpy, lp_compiled),
        ("rates at a feed", rates_numpy, rates_compiled),
    ):
        print(
            f"  {label}: numpy {numpy_time:.3f} s, compiled {compiled_time:.4f} s "
            f"({numpy_time / compiled_time:.0f}x)"
        )
    robot, placement = get_robot("panda"), Placement(0.0, 0.45, 0.1, 0.0)
    evaluate_path(PathProblem.of(robot, line(20), PathOptions(spin_mode="free")), placement)
    times, weights = {}, {}
    for mode in ("fixed", "free"):
        problem = PathProblem.of(robot, line(waypoints), PathOptions(spin_mode=mode))
        times[mode] = cpu(partial(evaluate_path, problem, placement))
        weights[mode] = problem.path_cost(waypoints)
    print(
        f"Panda evaluate, {waypoints} waypoints (CPU, best of 2): fixed {times['fixed']:.3f} s, "
        f"free {times['free']:.3f} s, {times['free'] / times['fixed']:.2f}x "
        f"(weighed {weights['free'] / weights['fixed']:g}x)"
    )


if __name__ == "__main__":
    main()
