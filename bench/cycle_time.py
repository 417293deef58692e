"""The cycle time of a published-size program under joint acceleration limits (motion.md s. 4).

Run by ``bench/real_size.py``, or alone from the repository root: ``python bench/cycle_time.py``
(``--smoke``: 1,000 moves). The synthetic NX-like program of ``bench/programs.py`` (10,487
moves in 34 passes) on a UR5e with every joint limited to 10 rad/s^2, free spin, at the
optimum ``bench/active_set.py`` finds: the evaluation, then the cycle time
(:func:`solver.path.cycle_time.cycle_time`: its TOPP-RA and ramps compiled,
``solver/kernels/feed_profile.py``) against toppra's TOPP-RA on the same passes' grids, in the
same run, with the two time-optimal totals.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from programs import pocket_program  # noqa: E402 - bench/programs.py, beside this script
from timing import best_time  # noqa: E402

from solver.cam.cl_data import read_cl_data  # noqa: E402
from solver.core.spatial import Placement  # noqa: E402
from solver.families import get_robot  # noqa: E402
from solver.path.blended_path import blended_path  # noqa: E402
from solver.path.cycle_time import cycle_time  # noqa: E402
from solver.path.evaluate import evaluate_path  # noqa: E402
from solver.path.prepare import check_passes  # noqa: E402
from solver.path.problem import PathOptions, PathProblem  # noqa: E402
from tests.toppra_grid import duration, toppra_speeds  # noqa: E402

LIMIT = 10.0  # rad/s^2, every joint
AT = Placement(-0.107, 0.428, 0.0, -0.8)  # bench/active_set.py's optimum, rounded


def _toppra_total(problem: PathProblem, q: np.ndarray, blend: float) -> float:
    """The time-optimal time of every pass by toppra, rest to rest, on the cycle time's grids."""
    robot, positions = problem.robot, problem.prepared.tool_position
    assert robot.qddot_max is not None
    total = 0.0
    for start, stop in check_passes(problem.passes, len(positions)):
        steps = np.linalg.norm(np.diff(positions[start:stop], axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(steps)])
        grid, q_s, q_ss = blended_path(q[start:stop], s, blend)
        speeds = toppra_speeds(grid, q_s, q_ss, robot.qdot_max, robot.qddot_max)
        total += duration(grid, speeds)
    return total


def cycle_time_lines(*, smoke: bool = False) -> None:
    """Print the cycle time's figures, compiled against toppra on the same grids."""
    moves = 1_000 if smoke else 10_487
    program = read_cl_data(pocket_program(moves))
    robot = get_robot("ur5e").with_options(qddot_max=[LIMIT] * 6)
    problem = PathProblem.of(
        robot,
        program.waypoints_in_workpiece(),
        PathOptions(spin_mode="free"),
        passes=program.passes,
    )
    began = time.perf_counter()
    evaluation = evaluate_path(problem, AT)
    evaluated = time.perf_counter() - began
    if evaluation.q is None or evaluation.acceleration is None:
        print(f"cycle time: the program does not run at {AT} ({evaluation.reason})")
        return
    times = cycle_time(problem, evaluation)
    assert times is not None
    compiled = best_time(lambda: cycle_time(problem, evaluation), 1 if smoke else 3)
    began = time.perf_counter()
    reference = _toppra_total(problem, evaluation.q, evaluation.acceleration.blend_length)
    with_toppra = time.perf_counter() - began
    print(
        f"cycle time of a {moves}-move program ({len(program.passes)} passes, UR5e, "
        f"{LIMIT:g} rad/s^2, free spin; its evaluation {evaluated:.2f} s): {compiled:.3f} s "
        f"with TOPP-RA compiled, toppra on the same grids {with_toppra:.2f} s for its TOPP-RA "
        f"alone ({with_toppra / compiled:.0f}x); time-optimal {times.time_optimal:.3f} s "
        f"against toppra's {reference:.3f} s (relative difference "
        f"{abs(times.time_optimal - reference) / reference:.1e}), ramps {times.ramp_time:.3f} s"
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="1,000 moves: check the script runs")
    cycle_time_lines(smoke=parser.parse_args().smoke)
