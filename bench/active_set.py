"""Benchmark lines of real-size programs (issue 23): a published-size program optimised.

Run by ``bench/run.py``, or alone from the repository root: ``python bench/active_set.py``
(``--smoke``: a 300-move program only). A synthetic NX-like program
(:func:`programs.pocket_program`: 10,487 moves, then 20,000) is read as CL data and optimised
on a UR5e over x in [-0.4, 0.2] m, y in [0.2, 0.6] m, any yaw, free spin, z = 0, by the casadi
method on two threads, as ``POST /v1/optimize`` does it: the read, the optimisation's time, its
mu_path and the waypoints in the final active set. Then, for scale, a 1,000-move program
(its coarse map of the whole path) optimised on active sets against the whole problem (what
every solve did before), same run.
"""

from __future__ import annotations

import argparse
import math
import time

from programs import pocket_program

from solver.cam.cl_data import read_cl_data
from solver.core.parallel import ThreadRunner
from solver.families import get_robot
from solver.optimise.optimize import optimize_placement
from solver.optimise.optimum import PlacementOptimum
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathOptions, PathProblem

BOUNDS = PlacementBounds(x=(-0.4, 0.2), y=(0.2, 0.6), yaw=(-math.pi, math.pi), z=0.0)
MAX_MAP_POSES = 5_000_000  # the service's default DTF_MAX_MAP_POSES
MAX_SEARCH_POSES = 6_100_000  # the service's default DTF_MAX_SEARCH_POSES
MAX_SOLVER_SECONDS = 20.0  # the service's default DTF_MAX_SOLVER_SECONDS


def _optimised(
    moves: int, *, active_set: bool = True, method: str = "casadi"
) -> tuple[float, float, PlacementOptimum]:
    """Read a program of ``moves`` moves and optimise it: read time, optimise time, answer.

    With the service's default limits (``active_set=False`` lifts the scipy search's).
    """
    began = time.perf_counter()
    program = read_cl_data(pocket_program(moves))
    waypoints = program.waypoints_in_workpiece()
    problem = PathProblem.of(
        get_robot("ur5e"), waypoints, PathOptions(spin_mode="free"), passes=program.passes
    )
    _ = problem.prepared
    read = time.perf_counter() - began
    began = time.perf_counter()
    optimum = optimize_placement(
        problem,
        bounds=BOUNDS,
        method=method,
        max_coarse_poses=MAX_MAP_POSES,
        max_search_poses=MAX_SEARCH_POSES if active_set else None,
        max_solver_seconds=MAX_SOLVER_SECONDS,
        runner=ThreadRunner(2),
        active_set=active_set,
    )
    return read, time.perf_counter() - began, optimum


def _line(
    label: str, moves: int, read: float | None, seconds: float, optimum: PlacementOptimum
) -> str:
    """One line: the program's size, its read (None: not shown), the optimisation."""
    n = optimum.evaluation.mu_path if optimum.evaluation is not None else None
    mu = "infeasible" if n is None else f"mu_path {n:.6f} m/s"
    active = optimum.active_waypoints
    rows = "the whole path" if active is None else f"{active} waypoints in the final set"
    read_in = "" if read is None else f" read in {read:.2f} s,"
    return (
        f"  {label}: {moves} moves{read_in} optimised in {seconds:.2f} s "
        f"({optimum.solver.iterations} iterations), {mu}, {rows}"
    )


def active_set_lines(*, smoke: bool = False) -> None:
    """Print the optimisation of published-size programs, and the active sets' gain.

    A 200-move program is optimised first: the robot catalogue and the compiled kernels load
    once per process (a running service has them loaded), not inside the figures.
    """
    _optimised(200)
    print("Real-size programs (UR5e, x -0.4..0.2 m, y 0.2..0.6 m, any yaw, free spin, casadi):")
    for moves in () if smoke else (10_487, 20_000):
        read, seconds, optimum = _optimised(moves)
        goal = "goal <= 10 s" if moves < 15_000 else "goal <= 30 s"
        print(_line(f"synthetic NX-like program ({goal})", moves, read, seconds, optimum))
    moves = 300 if smoke else 1_000
    _, whole_seconds, whole = _optimised(moves, active_set=False)
    _, seconds, optimum = _optimised(moves)
    print(_line("whole problem", moves, None, whole_seconds, whole))
    print(_line("active sets  ", moves, None, seconds, optimum))
    if whole.mu_path is not None and optimum.mu_path is not None:
        print(
            f"  active sets / whole problem: {seconds / whole_seconds:.2f}x the time, mu_path "
            f"relative difference {abs(optimum.mu_path / whole.mu_path - 1):.1e}"
        )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="a 300-move program only")
    active_set_lines(smoke=parser.parse_args().smoke)
