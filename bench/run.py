"""Benchmark of the capability map: prints figures, asserts nothing (timing is never a test).

Run from the repository root::

    python bench/run.py           # the ERK-size problem (about a minute, most of it the baseline)
    python bench/run.py --smoke   # a tiny grid, to check that the script runs (CI)

It prints the vectorised map's time on the ERK 2021 problem (UR5, x = -0.25..0.25 m,
y = 0.25..0.65 m, step 0.02 m, z = 0.1 m, 133 waypoints, all IK branches), the same map by a
scalar loop (ur-analytic-ik IK, pinocchio Jacobian and numpy solve per pose and branch) timed
on a subset in the same run (each cell the best of three, as every figure here is a best of
several) and extrapolated, their ratio, the time per pose and branch, and
the 8-yaw map against the 1-yaw map; the numeric IK family's map on the same grid (UR5 read as a
plain URDF, checked equal to the analytic map, and the Panda) against the analytic one, and
the UR5 read from a frame 1 mrad off level (its closed form, tilted, on the kernels and on the
numpy pipeline); the
2-waypoint optimisation of the Jaco2 (numeric IK) against the UR5's
(``bench/numeric_optimisation.py``); the map and the optimisers with joint acceleration limits
(``bench/acceleration.py``); the map's picture on a new figure and on a kept one
(``bench/pictures.py``); the optimisation of
published-size programs on active sets (``bench/active_set.py``). Then the
placement optimisation of the same problem
(yaw free): each method's time and optimum, against the best cell of a fine grid (10 mm,
5 degrees) computed in the same run.
"""

from __future__ import annotations

import argparse
import copy
import http.client
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import httpx
import memory  # bench/memory.py, parallel.py, acceleration.py, active_set.py, cell.py, beside it
import numpy as np
import parallel
import ur_analytic_ik
from acceleration import acceleration_lines
from active_set import active_set_lines
from arms import UR5_FRAMES, ur5_as_numeric, ur5_urdf
from cell import cell_lines
from numeric_optimisation import numeric_optimisation_lines
from pictures import picture_lines
from timing import best_time, phase_seconds, phase_text, plain_post

from solver.core.kinematics import jacobian_in_base
from solver.core.parallel import SERIAL, ThreadRunner
from solver.core.robots import Robot
from solver.core.spatial import Placement, pose_matrix
from solver.core.task import task_requirements
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric import (
    bounded_kernel,
    bounded_redundant_kernel,
    chain_kernel,
    redundant_kernel,
    seed_kernel,
)
from solver.families.numeric.family import NumericFamily
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.path.capability_map import capability_map, grid_axis
from solver.path.placements import evaluate_placements
from solver.path.problem import PathOptions, PathProblem

ROOT = Path(__file__).resolve().parents[1]


def load_path(name: str) -> np.ndarray:
    """Waypoint poses of examples/paths/<name>.json, shape (N, 4, 4)."""
    waypoints = json.loads((ROOT / "examples" / "paths" / f"{name}.json").read_text())["waypoints"]
    return np.array([pose_matrix(w["position"], w["orientation"], field="w") for w in waypoints])


def scalar_cell(robot: Robot, path: np.ndarray, placement: Placement) -> float:
    """One map cell the plain way: IK, Jacobian and solve per pose and branch.

    Per pose ur-analytic-ik, per solution a pinocchio Jacobian and a 6x6 solve; the best
    branch's min over waypoints (no tracking: less work than the vectorised map does).
    """
    poses = placement.transform_workpiece_to_base() @ path
    twists = task_requirements(poses).twists()
    solver = getattr(ur_analytic_ik, robot.name)
    per_branch: dict[int, float] = {}
    for i, pose in enumerate(poses):
        for b, q in enumerate(solver.inverse_kinematics(pose)):
            joint_speeds = np.linalg.solve(jacobian_in_base(robot, q), twists[i])
            speed = 1.0 / float(np.max(np.abs(joint_speeds) / robot.qdot_max))
            per_branch[b] = min(per_branch.get(b, math.inf), speed)
    return max(per_branch.values(), default=math.nan)


def scalar_loop_seconds(
    robot: Robot,
    path: np.ndarray,
    grid: tuple[np.ndarray, np.ndarray, float],
    *,
    subset: int,
    repeats: int = 3,
) -> float:
    """The scalar loop's time over ``subset`` cells of the grid (xs, ys, z), drawn by a seed.

    Each cell the best of ``repeats``, summed: the same statistic as the maps it is set
    against (best of several runs), after one cell run once to warm up. Timed once and cold,
    24 cells read 47 s extrapolated and then 44.5, 41.4, 41.1 and 40.7 s in the same process,
    where the best of five a cell gave 40.0 s (2026-12-07), so a ratio taken against one cold
    pass was up to a sixth too high.
    """
    xs, ys, z = grid
    picks = np.random.default_rng(0).choice(len(xs) * len(ys), size=subset, replace=False)
    placements = [Placement(float(xs[p % len(xs)]), float(ys[p // len(xs)]), z, 0.0) for p in picks]
    scalar_cell(robot, path, placements[0])
    total = 0.0
    for placement in placements:
        total += best_time(lambda p=placement: scalar_cell(robot, path, p), repeats)
    return total


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="tiny grid: check the script runs")
    args = parser.parse_args()
    robot = get_robot("ur5")
    path = load_path("curved_line")
    if args.smoke:
        xs, ys = grid_axis(-0.1, 0.1, 0.1, field="x"), grid_axis(0.3, 0.5, 0.1, field="y")
        repeats, subset = 1, 2
    else:
        xs, ys = grid_axis(-0.25, 0.25, 0.02, field="x"), grid_axis(0.25, 0.65, 0.02, field="y")
        repeats, subset = 5, 12
    z = 0.1
    cells = len(xs) * len(ys)
    pose_branches = cells * len(path) * 8

    def one_yaw() -> object:
        return capability_map(PathProblem.of(robot, path), xs=xs, ys=ys, z=z, yaws=np.array([0.0]))

    yaws8 = np.linspace(0.0, 2 * math.pi, 8, endpoint=False)

    def eight_yaws() -> object:
        return capability_map(PathProblem.of(robot, path), xs=xs, ys=ys, z=z, yaws=yaws8)

    kr6 = get_robot("kuka_kr6_r700_sixx")
    opw_xs = grid_axis(0.2, 0.6, 0.02, field="x") if not args.smoke else xs + 0.4
    opw_ys = grid_axis(-0.25, 0.25, 0.02, field="y") if not args.smoke else ys - 0.4

    def opw_map(compiled: bool = True) -> object:
        return capability_map(
            PathProblem.of(kr6, path),
            xs=opw_xs,
            ys=opw_ys,
            z=z,
            yaws=np.array([0.0]),
            compiled=compiled,
        )

    def numpy_map() -> object:
        return capability_map(
            PathProblem.of(robot, path), xs=xs, ys=ys, z=z, yaws=np.zeros(1), compiled=False
        )

    def free_spin(compiled: bool = True) -> object:
        free = PathProblem.of(robot, path, PathOptions(spin_mode="free"))
        return capability_map(free, xs=xs, ys=ys, z=z, yaws=np.zeros(1), compiled=compiled)

    one_yaw()  # warm up (imports, first allocations)
    t_map = best_time(one_yaw, repeats)
    t_numpy = best_time(numpy_map, repeats)
    t_map8 = best_time(eight_yaws, max(1, repeats // 2))
    free_spin()  # warm up (the free-spin kernel from numba's cache)
    t_free = best_time(free_spin, repeats)
    t_free_numpy = best_time(lambda: free_spin(compiled=False), repeats)
    opw_map()  # warm up (the catalogue's OPW models)
    t_opw = best_time(opw_map, repeats)
    t_opw_numpy = best_time(lambda: opw_map(compiled=False), repeats)
    opw_cells = len(opw_xs) * len(opw_ys)
    t_scalar_subset = scalar_loop_seconds(
        robot, path, (xs, ys, z), subset=subset, repeats=1 if args.smoke else 3
    )
    t_scalar = t_scalar_subset / subset * cells

    print(
        f"ERK-size map: UR5, {cells} placements x {len(path)} waypoints x 8 IK branches "
        f"= {pose_branches:,} pose-branches{' (smoke grid)' if args.smoke else ''}"
    )
    print(
        f"  compiled kernel (best of {repeats}):  {t_map:8.3f} s   "
        f"{t_map / pose_branches * 1e9:6.0f} ns per pose-branch"
    )
    print(
        f"  numpy pipeline (the reference):   {t_numpy:8.3f} s   "
        f"{t_numpy / pose_branches * 1e9:6.0f} ns per pose-branch, "
        f"{t_numpy / t_map:.2f}x the kernel"
    )
    print(
        f"  scalar loop, {subset} cells:           {t_scalar_subset:8.3f} s   "
        f"-> {cells} cells: {t_scalar:.1f} s (extrapolated)"
    )
    print(f"  speed-up over the scalar loop:     {t_scalar / t_map:8.0f}x")
    print(
        f"8-yaw map ({8 * cells} placements):     {t_map8:8.3f} s   "
        f"{t_map8 / t_map:.2f}x the 1-yaw map"
    )
    print(
        f"free-spin map ({cells} placements):  {t_free:8.3f} s   "
        f"{t_free / t_map:.2f}x the fixed-spin map; numpy pipeline (the reference) "
        f"{t_free_numpy:.3f} s, {t_free_numpy / t_free:.2f}x the kernel"
    )
    print(
        f"OPW map: KR6 R700 sixx, {opw_cells} placements x {len(path)} waypoints x 8 branches "
        f"(x {opw_xs[0]:.2f}..{opw_xs[-1]:.2f}, y {opw_ys[0]:.2f}..{opw_ys[-1]:.2f}, z {z})"
    )
    opw_pose_branches = opw_cells * len(path) * 8
    print(
        f"  compiled kernel (best of {repeats}):  {t_opw:8.3f} s   "
        f"{t_opw / opw_pose_branches * 1e9:6.0f} ns per pose-branch, "
        f"{t_opw / t_map * cells / opw_cells:.2f}x the UR5 map per placement"
    )
    print(
        f"  numpy pipeline (the reference):   {t_opw_numpy:8.3f} s   "
        f"{t_opw_numpy / opw_pose_branches * 1e9:6.0f} ns per pose-branch, "
        f"{t_opw_numpy / t_opw:.2f}x the kernel"
    )
    acceleration_lines(robot, path, xs, ys, z, repeats=repeats, smoke=args.smoke)
    cell_lines(robot, path, xs, ys, z, repeats=repeats, smoke=args.smoke)
    picture_lines(robot, path, xs, ys, z, smoke=args.smoke)
    numeric_maps(path, xs, ys, z, t_map, repeats=1 if args.smoke else 3)
    numeric_branches(poses=200 if args.smoke else 3000)
    numeric_optimisation_lines(path, smoke=args.smoke)
    optimisation(robot, path, smoke=args.smoke)
    active_set_lines(smoke=args.smoke)
    evaluate_over_http(requests=20 if args.smoke else 200)
    parallel.threads(robot, path, xs, ys, z)
    parallel.map_job(smoke=args.smoke)
    parallel.worker_starts(smoke=args.smoke)
    memory.peak_rss(smoke=args.smoke)


def evaluate_over_http(*, requests: int) -> None:
    """p50 and p95 of /v1/evaluate of the README example against a live uvicorn (issue 12).

    Timed from the standard library's ``http.client`` on one keep-alive connection, the
    thinnest client there is, so that the figure is the service's; the same requests from
    httpx, interleaved with them, are printed beside it (httpx's own work is about 2 ms of a
    74 kB answer).
    """
    port = 8731
    server = subprocess.Popen(
        [sys.executable, "-m", "uvicorn", "service.main:app", "--port", str(port)],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    body = (ROOT / "examples" / "evaluate_request.json").read_bytes()
    headers = {"Content-Type": "application/json"}
    times: dict[str, list[float]] = {"http.client": [], "httpx": []}
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=30) as client:
            for _ in range(300):  # wait for the server, up to 30 s
                try:
                    client.get("/healthz")
                    break
                except httpx.TransportError:
                    time.sleep(0.1)
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)

            def plain() -> None:
                plain_post(connection, "/v1/evaluate", body)

            def with_httpx() -> None:
                client.post("/v1/evaluate", content=body, headers=headers).raise_for_status()

            for _ in range(5):  # warm up
                plain()
                with_httpx()
            for _ in range(requests):
                for name, send in (("http.client", plain), ("httpx", with_httpx)):
                    began = time.perf_counter()
                    send()
                    times[name].append(time.perf_counter() - began)
            connection.close()
    finally:
        server.terminate()
        server.wait()
    figures = []
    for name, taken in times.items():
        taken.sort()
        p50, p95 = taken[len(taken) // 2], taken[int(0.95 * (len(taken) - 1))]
        figures.append(f"{name} p50 {1000 * p50:.1f} ms, p95 {1000 * p95:.1f} ms")
    print(
        f"/v1/evaluate of the README example over HTTP ({requests} requests, keep-alive): "
        + "; ".join(figures)
    )


NUMERIC_PHASES = {
    6: {
        "seeding": (seed_kernel, "seed_paths"),
        "bounded following": (bounded_kernel, "follow_bounded"),
        "speeds": (chain_kernel, "speeds_per_twist"),
    },
    7: {
        "seeding": (seed_kernel, "seed_paths"),
        "bounded following": (bounded_redundant_kernel, "follow_bounded"),
        "speeds": (redundant_kernel, "redundant_speeds"),
    },
}
"""The numeric family's compiled phases of a map (solver/families/numeric/following.py and
velocity.py call them through their modules), six joints and more: issue 27's lines say where
the map's time goes, the rest being the pipeline's Python and numpy around them."""


def numeric_maps(
    path: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float, t_map: float, *, repeats: int
) -> None:
    """The numeric family's map on the same grid: UR5 as a plain URDF, and the Panda.

    Each the best of ``repeats`` runs, as the analytic map it is set against (``t_map``).

    The UR5's URDF is given the numeric family explicitly (robots.md section 4), whatever the
    registry would give a URDF it recognises; its map must equal the analytic one, which is
    checked here too. Both numeric maps run the compiled chain
    (``solver/families/numeric/*_kernel.py``); issue 27's goals are 30x and 60x the analytic UR5
    map of the same run. Read without a family the URDF is recognised as a UR arm
    (solver.families.recognise): that line shows what a user sending the URDF gets.
    """
    analytic = get_robot("ur5")
    urdf = ur5_urdf()
    arms = {
        "UR5 as a URDF": (ur5_as_numeric(urdf), "goal <= 30x"),
        "UR5 recognised": (robot_from_urdf(urdf, **UR5_FRAMES), "the UR closed form"),
        "Panda": (get_robot("panda"), "goal <= 60x"),
    }
    grid = {"xs": xs, "ys": ys, "z": z, "yaws": np.zeros(1)}
    reference = capability_map(PathProblem.of(analytic, path), **grid).mu_path
    print(f"numeric IK maps ({len(xs) * len(ys)} placements, best of {repeats} each):")
    for label, (arm, goal) in arms.items():
        capability_map(PathProblem.of(arm, path[:3]), xs=xs[:1], ys=ys[:1], z=z, yaws=np.zeros(1))
        problem, seconds = PathProblem.of(arm, path), math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            cmap = capability_map(problem, **grid)
            seconds = min(seconds, time.perf_counter() - start)
        line = (
            f"  {label:14s} {seconds:8.3f} s   {seconds / t_map:6.1f}x the analytic UR5 map "
            f"({goal})"
        )
        if arm.dof == 6:
            same = np.isclose(cmap.mu_path, reference, rtol=1e-10, atol=0) | (
                np.isnan(cmap.mu_path) & np.isnan(reference)
            )
            line += f"; equal to it on {same.mean():.1%} of the cells"
        print(line)
        if isinstance(arm.family, NumericFamily):  # where its time goes: what the goal has to cut
            phases = NUMERIC_PHASES[6 if arm.dof == 6 else 7]  # following.py's choice of kernels
            split = phase_seconds(lambda problem=problem: capability_map(problem, **grid), phases)
            print(f"    one more run: {phase_text(split)}")
    # Read from a frame 1 mrad off level (a cell measured a little out of true) the UR5 keeps
    # its closed form, tilted (solver.families.recognise.first_axis_tilt); the kernels write
    # each block's poses in its tilted frame (solver.families.kernels.pose_block). Against it,
    # the same map on the numpy pipeline, which mapped tilted arms before.
    mount = '<link name="cell"/><joint name="mount" type="fixed"><parent link="cell"/>'
    mount += '<child link="world"/><origin xyz="0 0 0" rpy="0.001 0 0"/></joint></robot>'
    tilted = robot_from_urdf(urdf.replace("</robot>", mount), base_frame="cell", tool_frame="tool0")
    tilted_problem = PathProblem.of(tilted, path)
    capability_map(tilted_problem, xs=xs[:2], ys=ys[:2], z=z, yaws=np.zeros(1))
    start = time.perf_counter()
    capability_map(tilted_problem, xs=xs, ys=ys, z=z, yaws=np.zeros(1))
    seconds = time.perf_counter() - start
    rows_y, rows_x = np.meshgrid(ys, xs, indexing="ij")
    rows = np.column_stack(
        [rows_x.ravel(), rows_y.ravel(), np.full(rows_x.size, z), np.zeros(rows_x.size)]
    )
    start = time.perf_counter()
    evaluate_placements(tilted_problem, rows, compiled=False)
    numpy_seconds = time.perf_counter() - start
    label = "UR5 tilted"
    print(
        f"  {label:14s} {seconds:8.3f} s   {seconds / t_map:6.1f}x the analytic UR5 map "
        f"(1 mrad off level: the closed form tilted, compiled; on the numpy pipeline "
        f"{numpy_seconds:.3f} s, {numpy_seconds / seconds:.1f}x it)"
    )
    # The Panda's map prunes branches that cannot be a cell's best in one compiled pass
    # (solver/families/numeric/bounded_redundant_kernel.py): the same map following every
    # branch, for the ratio.
    panda = PathProblem.of(get_robot("panda"), path)
    grid_y, grid_x = np.meshgrid(ys, xs, indexing="ij")
    cells = np.column_stack([grid_x.ravel(), grid_y.ravel(), np.full(grid_x.size, z)])
    start = time.perf_counter()
    evaluate_placements(panda, np.column_stack([cells, np.zeros((len(cells), 2))]), prune=False)
    seconds = time.perf_counter() - start
    label = "Panda unpruned"
    print(f"  {label:14s} {seconds:8.3f} s   {seconds / t_map:6.1f}x (every branch followed)")


def numeric_branches(*, poses: int) -> None:
    """How many of the closed form's IK solutions numeric IK finds (issue 27: every branch).

    The UR5 read as a URDF with the numeric family at random poses (configurations within a
    turn of zero, seeded), against ur-analytic-ik's solutions (a library of its own), with the
    more seeds tried where the first found an odd number (ik.more_seeds) and without them.
    """
    numeric = ur5_as_numeric(ur5_urdf())
    family = numeric.family
    assert isinstance(family, NumericFamily)
    q = np.random.default_rng(5).uniform(-math.pi, math.pi, (poses, 6))
    rotation, position = family.chain.forward(q)
    closed = []
    for r, p in zip(rotation, position, strict=True):
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = r, p
        solutions = np.array(ur_analytic_ik.ur5.inverse_kinematics(pose)).reshape(-1, 6)
        closed.append(int(np.isfinite(solutions).all(axis=1).sum()))
    analytic = np.array(closed)
    first_only = copy.copy(family)
    first_only.more_seeds = np.empty((0, 6))
    figures = []
    for label, seeded in (("with the more seeds", family), ("the 32 seeds alone", first_only)):
        seeded.seed_first(rotation[:2], position[:2])  # compiled or loaded before the clock
        start = time.perf_counter()
        _, count = seeded.seed_first(rotation, position)
        seconds = time.perf_counter() - start
        short = int(np.sum(count < analytic))
        figures.append(
            f"{label}: {int(np.minimum(count, analytic).sum()):,} of {int(analytic.sum()):,}, "
            f"{short} poses short, {seconds / poses * 1e6:.0f} us a pose"
        )
    print(f"numeric IK branches, UR5 as a URDF, {poses:,} random poses against ur-analytic-ik: "
          + "; ".join(figures))  # fmt: skip


def optimisation(robot: Robot, path: np.ndarray, *, smoke: bool) -> None:
    """Time each method to the optimum; compare with the best cell of a fine grid."""
    if smoke:
        bounds = PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(-0.2, 0.2), z=0.1)
        step, yaw_step, methods, repeats = 0.05, math.radians(10), ("casadi",), 1
    else:
        bounds = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
        step, yaw_step, methods, repeats = 0.01, math.radians(5), ("casadi", "scipy"), 3
    print(
        f"ERK-size optimisation: UR5, x {bounds.x}, y {bounds.y}, yaw "
        f"({bounds.yaw[0]:.3f}, {bounds.yaw[1]:.3f}), z {bounds.z}"
    )
    results = {}
    for method in methods:
        seconds = {}
        for threads, runner in ((1, SERIAL), (2, ThreadRunner(2))):  # the service: DTF_THREADS
            times = []
            for _ in range(repeats):  # the best of a few, as for the maps
                start = time.perf_counter()
                optimum = optimize_placement(
                    PathProblem.of(robot, path), bounds=bounds, method=method, runner=runner
                )
                times.append(time.perf_counter() - start)
            seconds[threads] = min(times)
        ratio = seconds[1] / seconds[2]
        timing = (
            f"{seconds[2]:6.3f} s on 2 threads ({seconds[1]:.3f} s on 1, {ratio:.2f}x; "
            f"best of {repeats})"
        )
        if not optimum.found or optimum.mu_path is None or optimum.placement is None:
            print(f"  {method:7s} {timing}   no feasible placement")
            continue
        results[method] = optimum.mu_path
        p = optimum.placement
        print(
            f"  {method:7s} {timing}   mu_path {optimum.mu_path:.6f} m/s at x {p.x:.4f}, "
            f"y {p.y:.4f}, yaw {p.yaw:.4f}; {optimum.improvement_percent:+.2f} % over the centre "
            f"of the bounds ({optimum.solver.iterations} iterations)"
        )
    yaws = np.arange(bounds.yaw[0], bounds.yaw[1] - 1e-9, yaw_step)
    start = time.perf_counter()
    grid = capability_map(
        PathProblem.of(robot, path),
        xs=grid_axis(*bounds.x, step, field="x"),
        ys=grid_axis(*bounds.y, step, field="y"),
        z=bounds.z,
        yaws=yaws,
    )
    seconds = time.perf_counter() - start
    best = float(np.nanmax(grid.mu_path))
    print(
        f"  fine grid ({step * 1000:.0f} mm, {math.degrees(yaw_step):.0f} deg, "
        f"{grid.mu_path.size:,} placements, {seconds:.1f} s): best cell {best:.6f} m/s"
    )
    for method, value in results.items():
        print(f"  {method} optimum vs the fine grid's best cell: {100 * (value / best - 1):+.3f} %")


if __name__ == "__main__":
    main()
