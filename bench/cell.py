"""Benchmark lines of the cell (issue 22): the map and an optimisation with collisions checked.

Run by ``bench/run.py``, or alone from the repository root: ``python bench/cell.py``.
The ERK-size map (546 placements, 133 waypoints) with a table top, a fixture box and the
workpiece box, against the same map without a cell in the same run (the goal: at most 3x), for
the UR5 (its URDF's meshes, as convex hulls) and the UR5e (capsules), the tool point at the end
of a 12 cm tool; the compiled check (:mod:`solver.path.cell.fast`) and the coal-only reference
it must agree with (``CellChecker.check(reference=True)``: here by taking the compiled sweep
away, as tests/solver/test_cell_fast.py does), and the checker's build time with its self
pairs' tables made (:mod:`solver.path.cell.pair_tables`, once per arm) and with them kept (a
new cell for the same arm, :mod:`solver.path.cell.kept_tables`); then an
optimisation with the cell: its time, its answer's clearance, and the best collision-free cell
of a map of its box.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from arms import ur5_as_numeric, ur5_urdf
from timing import best_time, phase_seconds, phase_text

import solver.path.cell.batch as batch_module
import solver.path.cell.checker as checker_module
import solver.path.kernel_cells as kernel_cells_module
from solver.core.robots import Robot
from solver.families import get_robot
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.path.capability_map import capability_map, grid_axis
from solver.path.cell import kept_tables
from solver.path.cell.cache import checker_for
from solver.path.cell.robot_geometry import forget_urdf_geometries
from solver.path.cell.shapes import Box, Cell, Halfspace, Sphere, Tool
from solver.path.problem import PathOptions, PathProblem


def _pose(x: float, y: float, z: float) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, 3] = [x, y, z]
    return matrix


# The robot stands on the table (its top z = 0 in {B}); a fixture box beside the work; the part
# (a block under the path, in {O}); a 12 cm spindle of 3 cm radius, the tool point at its end.
TOOL_LENGTH = 0.12
CELL = Cell(
    fixed=(
        Halfspace((0.0, 0.0, 1.0), 0.0, name="table"),
        Box((0.1, 0.1, 0.3), _pose(-0.3, 0.2, 0.15), name="fixture"),
    ),
    workpiece=(Box((0.3, 0.12, 0.09), _pose(0.0, 0.06, -0.045), name="part"),),
    tool=Tool(radius=0.03, length=TOOL_LENGTH),
)


CELL_PHASES: dict[str, tuple[object, str]] = {
    "the map kernel": (kernel_cells_module, "map_cells"),
    "compiled sweep": (batch_module, "first_due_paths"),
    "coal after the sweep": (batch_module, "resume"),
    "coal at a refusal's waypoint": (checker_module.CellChecker, "collides_at"),
    "refused placements' other branches": (kernel_cells_module, "branch_paths"),
}
"""Where a map with the cell spends its time (issue 22: the goal's line says what stands between
it and 3x): the analytic map's kernel, the check's compiled sweep of every path
(solver.path.cell.batch), coal where the sweep's bounds cannot decide a pair, coal's quick test
of a refused pair on another branch (solver.path.cell.limit), and the kernel that gives a
refused placement its other branches; the rest is the pipeline's Python and numpy."""


def _build_seconds(arm: Robot) -> float:
    """Seconds to build a checker of ``arm`` in CELL and its compiled side's tables."""
    start = time.perf_counter()
    checker = checker_module.CellChecker(arm, CELL)
    if checker._fast is not None:
        checker._fast.tables  # noqa: B018 - made at first use: what a map pays
    return time.perf_counter() - start


@contextmanager
def _coal_only() -> Iterator[None]:
    """Checkers made inside check with coal alone (the reference), as before the sweep."""
    compiled = checker_module.fast.FastCell

    def refuse(*args: object, **kwargs: object) -> None:
        raise NotImplementedError

    checker_module.fast.FastCell = refuse  # type: ignore[assignment,misc]
    try:
        yield
    finally:
        checker_module.fast.FastCell = compiled  # type: ignore[misc]


def _numeric_line(path: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float) -> None:
    """Numeric IK arms, the UR5 read from its URDF and the Panda: maps with the cell and without.

    One run each, after a run of the whole map: the kernels a refused placement's next branches
    take are compiled at the first collision, which a one-cell warm-up need not meet (on a cold
    disk cache the line then said 15 s with the cell against 1.1 s). Their maps run the numpy
    pipeline, dropping the branches that cannot be the pick; with a cell the refused placements
    run again without their refused branches (solver.path.path_checks.refuse_colliding).
    """
    tool = _pose(0.0, 0.0, TOOL_LENGTH)
    arms = {"UR5 as a numeric URDF": ur5_as_numeric(ur5_urdf()), "Panda": get_robot("panda")}
    for name, bare in arms.items():
        arm = bare.with_options(transform_tool_to_tcp=tool)
        seconds = {}
        for cell in (None, CELL):
            problem = PathProblem.of(arm, path, PathOptions(cell=cell))
            capability_map(problem, xs=xs, ys=ys, z=z, yaws=np.zeros(1))  # all compiled
            start = time.perf_counter()
            capability_map(problem, xs=xs, ys=ys, z=z, yaws=np.zeros(1))
            seconds[cell is not None] = time.perf_counter() - start
        print(
            f"  {name}: with the cell {seconds[True]:7.3f} s, without "
            f"{seconds[False]:7.3f} s (one run each): {seconds[True] / seconds[False]:.1f}x"
        )


def _weight_line(
    robot: Robot, path: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float, *, smoke: bool
) -> None:
    """The check's work a pose against its weight in the size limits, as the objects grow.

    CELL with 0, 47 and 97 more spheres of 2 cm behind the robot (none touched: nothing stops
    early), on a 6 x 6 grid (2 x 2 with --smoke): the extra time a pose over the map without a
    cell, in poses of that bare analytic map (the size limits' unit, the same run), against
    :meth:`PathProblem.checks_cost` a waypoint (50, more above 250 checked pairs).
    """
    arm = robot.with_options(transform_tool_to_tcp=_pose(0.0, 0.0, TOOL_LENGTH))
    step = 4 if smoke else 1
    grid = {"xs": xs[::step][:6], "ys": ys[::step][:6], "z": z, "yaws": np.zeros(1)}
    poses = len(grid["xs"]) * len(grid["ys"]) * len(path)
    bare = PathProblem.of(arm, path)
    capability_map(bare, **grid)
    unit = best_time(lambda: capability_map(bare, **grid), 3) / poses
    figures = []
    for extra in (0, 47, 97):
        spheres = tuple(
            Sphere(0.02, _pose(-0.6 + 1.2 * k / extra, -0.55, 0.2 + 0.3 * (k % 3)), name=f"s{k}")
            for k in range(extra)
        )
        cell = Cell(fixed=CELL.fixed + spheres, workpiece=CELL.workpiece, tool=CELL.tool)
        problem = PathProblem.of(arm, path, PathOptions(cell=cell))
        capability_map(problem, **grid)
        seconds = best_time(lambda problem=problem: capability_map(problem, **grid), 2)
        pairs = checker_for(arm, cell).pair_count
        took = (seconds / poses - unit) / unit
        figures.append(
            f"{3 + extra} objects ({pairs} pairs) took {took:.0f}, weighed "
            f"{problem.checks_cost(1):.0f}"
        )
    print(f"  the check's work a pose, in bare-map poses ({robot.name}): " + "; ".join(figures))


def cell_lines(
    robot: Robot,
    path: np.ndarray,
    xs: np.ndarray,
    ys: np.ndarray,
    z: float,
    *,
    repeats: int,
    smoke: bool = False,
) -> None:
    """Print the map with the cell against the map without, and an optimisation with it."""
    cells = len(xs) * len(ys)
    print(f"ERK-size map with a cell (table, fixture box, part box, tool; {cells} placements):")
    for bare in (robot, get_robot("ur5e")):
        arm = bare.with_options(transform_tool_to_tcp=_pose(0.0, 0.0, TOOL_LENGTH))

        def run_map(cell: Cell | None, arm: Robot = arm) -> object:
            problem = PathProblem.of(arm, path, PathOptions(cell=cell))
            return capability_map(problem, xs=xs, ys=ys, z=z, yaws=np.zeros(1))

        run_map(None)
        run_map(CELL)  # the compiled sweep's first call compiles nothing more, loads its cache
        t_without = best_time(lambda: run_map(None), repeats)
        t_with = best_time(lambda: run_map(CELL), repeats)
        cmap = run_map(CELL)
        with _coal_only():
            start = time.perf_counter()
            run_map(CELL)
            t_coal = time.perf_counter() - start
        reason = getattr(cmap, "reason")  # noqa: B009 - an object typed loosely above
        kept_tables.forget()
        forget_urdf_geometries()
        t_build = _build_seconds(arm)  # what the first map of the arm pays once
        t_kept = _build_seconds(arm)  # a new cell for the same arm: its tables, hulls kept
        print(
            f"  {arm.name}: with the cell {t_with:7.3f} s, without {t_without:7.3f} s (best of "
            f"{repeats} each): {t_with / t_without:.1f}x (goal <= 3x); coal only (one run) "
            f"{t_coal:7.3f} s: {t_coal / t_without:.1f}x; "
            f"{int((reason == -1).sum())} feasible, {int((reason == 4).sum())} collision cells; "
            f"the checker's build (pair tables made, once per arm) {t_build:.2f} s, with the "
            f"arm's tables and hulls kept (another cell) {t_kept:.3f} s"
        )
        split = phase_seconds(lambda run_map=run_map: run_map(CELL), CELL_PHASES)
        print(f"    one more run with the cell: {phase_text(split)}")
    _numeric_line(path, xs, ys, z)
    _weight_line(robot, path, xs, ys, z, smoke=smoke)
    bounds = (
        PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(-0.2, 0.2), z=z)
        if smoke
        else PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-0.3, 0.3), z=z)
    )
    tooled = robot.with_options(transform_tool_to_tcp=_pose(0.0, 0.0, TOOL_LENGTH))
    problem = PathProblem.of(tooled, path, PathOptions(cell=CELL))
    start = time.perf_counter()
    optimum = optimize_placement(problem, bounds=bounds, method="casadi")
    seconds = time.perf_counter() - start
    grid = capability_map(
        problem,
        xs=grid_axis(*bounds.x, 0.02, field="x"),
        ys=grid_axis(*bounds.y, 0.02, field="y"),
        z=z,
        yaws=grid_axis(*bounds.yaw, math.radians(15), field="yaw"),
    )
    best = float(np.nanmax(grid.mu_path)) if np.isfinite(grid.mu_path).any() else math.nan
    clearance = None if optimum.evaluation is None else optimum.evaluation.min_clearance
    print(
        f"ERK optimisation with the cell (UR5, casadi, x {bounds.x}, y {bounds.y}, yaw "
        f"{bounds.yaw}): {seconds:.1f} s; mu_path {optimum.mu_path} m/s, min clearance "
        f"{None if clearance is None else round(clearance.distance, 4)} m "
        f"({None if clearance is None else clearance.robot_part} to "
        f"{None if clearance is None else clearance.obstacle_name}); the best collision-free "
        f"cell of a 20 mm / 15 deg map: {best:.6f} m/s"
    )


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))
    from run import load_path

    smoke = "--smoke" in sys.argv
    step = 0.1 if smoke else 0.02
    cell_lines(
        get_robot("ur5"),
        load_path("curved_line"),
        grid_axis(-0.25, 0.25, step, field="x"),
        grid_axis(0.25, 0.65, step, field="y"),
        0.1,
        repeats=1 if smoke else 3,
        smoke=smoke,
    )
