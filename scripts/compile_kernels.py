"""Compile the numba kernels into their disk cache before the tests, one group a process.

On a fresh clone every kernel is compiled on its first call (``cache=True``: then loaded from
``__pycache__``). Left to the tests, the two pytest workers and the live servers they start
compile the same kernels at the same time when they meet them together (the map kernels in a
server's warm-up and in the other worker's first test), and a test's own time includes
them. ``scripts/run_tests.py`` runs this first, its groups in parallel processes (the cores),
so each kernel is compiled once and every later process loads it. Each group calls the solver
as a request would, on a two-cell grid of a short path: what is compiled is what the tests and
the service call, with the same argument types. A kernel missed here is compiled by its first
test as before: nothing depends on this but the time.

Run from the repository root: ``python scripts/compile_kernels.py [group ...]`` (all groups in
this one process without arguments).
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from solver.core.spatial import Placement, pose_matrix  # noqa: E402
from solver.families import get_robot  # noqa: E402
from solver.kernels import feed_profile  # noqa: E402
from solver.path.capability_map import capability_map  # noqa: E402
from solver.path.cell.shapes import Box, Cell, Halfspace, Tool  # noqa: E402
from solver.path.evaluate import evaluate_path  # noqa: E402
from solver.path.problem import PathOptions, PathProblem  # noqa: E402

XS, YS, Z, YAWS = np.array([-0.05, 0.05]), np.array([0.45]), 0.1, np.zeros(1)
AT = Placement(0.0, 0.45, 0.1, 0.0)


def _path() -> np.ndarray:
    """The first eight waypoints of the README example, shape (8, 4, 4), in {O}."""
    data = json.loads((ROOT / "examples" / "paths" / "curved_line.json").read_text())
    return np.array(
        [pose_matrix(w["position"], w["orientation"], field="w") for w in data["waypoints"][:8]]
    )


def _tool(length: float) -> np.ndarray:
    matrix = np.eye(4)
    matrix[2, 3] = length
    return matrix


def _run(name: str, **options: object) -> None:
    """A map and an evaluation of ``name`` with ``options`` (PathOptions), fixed and free spin."""
    robot = get_robot(name)
    cell = options.pop("cell", None)
    if cell is not None:
        robot = robot.with_options(transform_tool_to_tcp=_tool(0.12))
    for spin_mode in ("fixed", "free"):
        problem = PathProblem.of(robot, _path(), PathOptions(spin_mode=spin_mode, cell=cell))  # type: ignore[arg-type]
        capability_map(problem, xs=XS, ys=YS, z=Z, yaws=YAWS)
        evaluate_path(problem, AT)
        limited = PathProblem.of(
            robot.with_options(qddot_max=[10.0] * robot.dof),
            _path(),
            PathOptions(spin_mode=spin_mode, cell=cell),  # type: ignore[arg-type]
        )
        capability_map(limited, xs=XS, ys=YS, z=Z, yaws=YAWS)


def _cell() -> Cell:
    """A table, a box beside the work and a part under it: every shape kind a map meets."""
    box = np.eye(4)
    box[:3, 3] = [-0.3, 0.2, 0.15]
    part = np.eye(4)
    part[:3, 3] = [0.0, 0.06, -0.045]
    return Cell(
        fixed=(Halfspace((0.0, 0.0, 1.0), 0.0, name="table"), Box((0.1, 0.1, 0.3), box)),
        workpiece=(Box((0.3, 0.12, 0.09), part, name="part"),),
        tool=Tool(radius=0.03, length=0.12),
    )


def _analytic() -> None:
    for name in ("ur5", "kuka_kr6_r700_sixx"):
        _run(name)
    feed_profile.warm_up()  # the cycle time's (an evaluation with acceleration limits)
    angled = _tool(0.12)  # a tool 3 cm off the flange's axis: free spin's spun paths
    angled[0, 3] = 0.03
    robot = get_robot("ur5").with_options(transform_tool_to_tcp=angled)
    problem = PathProblem.of(robot, _path(), PathOptions(spin_mode="free"))
    capability_map(problem, xs=XS, ys=YS, z=Z, yaws=YAWS)


def _with_cell() -> None:
    for name in ("ur5", "ur5e"):  # meshes from the URDF, capsules from the parameters
        _run(name, cell=_cell())


GROUPS: dict[str, Callable[[], None]] = {
    "analytic": _analytic,
    "cell": _with_cell,
    "numeric6": lambda: _run("kinova_jaco2"),
    "numeric7": lambda: _run("panda"),
}
"""The kernels of the analytic families' maps and paths, of the cell, of the numeric chain (6
and 7 joints). On a cold cache, on the development machine, in scripts/run_tests.py's two
processes (2026-12-06): about 50, 28 (after the first), 71 and 26 s (after numeric6; 45 s
without)."""


def main(groups: list[str]) -> int:
    """Run ``groups`` (all when empty), printing each one's time; 2 on an unknown group."""
    unknown = sorted(set(groups) - set(GROUPS))
    if unknown:
        print(f"unknown group(s) {unknown}; the groups are {sorted(GROUPS)}", file=sys.stderr)
        return 2
    for group in groups or list(GROUPS):
        start = time.perf_counter()
        GROUPS[group]()
        seconds = time.perf_counter() - start
        print(f"compiled or loaded the {group} kernels in {seconds:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
