"""The path checks' joint paths and next branches: the kernel's, and the numpy pipeline run's.

A map with a cell checks each feasible placement's chosen joint path, and the refused
placements' next branches. Where the family has a compiled kernel (fixed spin), the kernel
answers both (:mod:`solver.path.kernel_branches`); its map equals the numpy pipeline route's,
every reason, branch and waypoint identical and mu_path, mu_acc and V_max to 1e-12. On the numpy
route the chunk's own run answers both (every branch tracked at every placement): no IK solved
again; each cell is then what an evaluation at that placement answers, and a numeric arm's map
with a cell is the closed form's.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import solver.path.branch_candidates as branch_candidates
import solver.path.path_checks as path_checks
import solver.path.placements as placements_module
from solver.core.codes import REASONS
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import get_robot, robot_from_urdf
from solver.path.capability_map import capability_map, grid_axis
from solver.path.evaluate import evaluate_path
from solver.path.pipeline import run_chunk
from solver.path.problem import PathOptions, PathProblem
from tests.cases import KERNEL_ACC_ULPS
from tests.solver.families.numeric_maps import opw_urdf, ur5_from_urdf
from tests.solver.test_cell_fast import _arm
from tests.solver.test_cell_pair_tables import ON_TABLE
from tests.solver.test_evaluate import load_path


def _robot(name: str) -> Robot:
    if name == "kr6":  # an OPW arm's closed form, recognised in its URDF
        urdf = opw_urdf("kuka_kr6_r700_sixx")
        return robot_from_urdf(urdf, base_frame="base_link", tool_frame="tool0")
    return get_robot(name)


AXES = {
    "xs": grid_axis(-0.25, 0.25, 0.05, field="x"),
    "ys": grid_axis(0.25, 0.65, 0.05, field="y"),
    "z": 0.1,
    "yaws": np.array([0.0, 0.6]),
}


def _numpy_route(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Maps on the numpy pipeline from here on; the pipeline runs' callers, as they run."""
    monkeypatch.setattr(placements_module, "kernel_of", lambda problem: None)
    runs: list[str] = []
    for module in (placements_module, branch_candidates, path_checks):

        def spy(*args: object, _module: object = module, **kwargs: object) -> object:
            runs.append(getattr(_module, "__name__", ""))
            return run_chunk(*args, **kwargs)  # type: ignore[arg-type]

        monkeypatch.setattr(module, "run_chunk", spy)
    return runs


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_the_numpy_routes_map_checks_its_own_runs_joint_paths(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On the numpy pipeline a map with a cell checks the joint paths its run tracked, and takes
    next branches from the same run: one run a chunk, no IK solved again; every cell is what
    an evaluation of that placement answers (:func:`clear_pick` on its own run)."""
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    plain = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions())
    runs = _numpy_route(monkeypatch)
    cmap = capability_map(problem, **AXES)  # type: ignore[arg-type]
    assert runs and set(runs) == {placements_module.__name__}  # the chunks' runs alone
    free = capability_map(plain, **AXES)  # type: ignore[arg-type]
    feasible = cmap.reason == -1
    assert ((cmap.branch != free.branch) & feasible).any()  # next branches were taken
    assert (cmap.reason == 4).any()  # and some cells refused
    for index in zip(*np.nonzero(np.ones_like(feasible)), strict=True):
        _, w, iy, ix = index
        placement = Placement(float(cmap.xs[ix]), float(cmap.ys[iy]), cmap.z, float(cmap.yaws[w]))
        answer = evaluate_path(problem, placement)
        if feasible[index]:
            assert answer.feasible, placement
            assert answer.mu_path == pytest.approx(cmap.mu_path[index], rel=1e-12), placement
            assert answer.branch == problem.family.branches[int(cmap.branch[index])], placement
        else:
            assert not answer.feasible and answer.reason == REASONS[cmap.reason[index]]
            assert answer.failed_waypoint == cmap.failed_waypoint[index], placement


def test_a_numeric_arms_map_with_a_cell_is_the_closed_forms(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The UR5 read from its URDF as a numeric arm (its map on the numpy pipeline, its joint
    paths numeric IK's) against the catalogue UR5 (closed form, compiled) in the same cell:
    the same feasibility, reasons and mu_path on every cell."""
    tool = _arm("ur5").transform_tool_to_tcp
    numeric = ur5_from_urdf().with_options(transform_tool_to_tcp=tool)
    path = load_path("curved_line")
    reference = capability_map(
        PathProblem.of(_arm("ur5"), path, PathOptions(cell=ON_TABLE)),
        **AXES,  # type: ignore[arg-type]
    )
    runs = _numpy_route(monkeypatch)
    cmap = capability_map(PathProblem.of(numeric, path, PathOptions(cell=ON_TABLE)), **AXES)  # type: ignore[arg-type]
    assert set(runs) == {placements_module.__name__}
    assert (reference.reason == 4).any() and (reference.reason == -1).any()
    np.testing.assert_array_equal(cmap.reason, reference.reason)
    np.testing.assert_array_equal(cmap.failed_waypoint, reference.failed_waypoint)
    np.testing.assert_allclose(cmap.mu_path, reference.mu_path, rtol=1e-9)


@pytest.mark.parametrize(
    ("name", "qddot_max"), [("ur5", None), ("ur5e", None), ("ur5", 4.0), ("kr6", None)]
)
def test_compiled_path_checks_equal_the_pipeline_route(
    name: str, qddot_max: float | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The map with a cell by the kernel's joint paths and branches = by the numpy pipeline."""
    robot, cell, axes = _robot(name), ON_TABLE, AXES
    robot = robot.with_options(transform_tool_to_tcp=_arm("ur5").transform_tool_to_tcp)
    if name == "kr6":  # in front of the KR6, turned; its URDF's base reaches below the table
        cell = dataclasses.replace(ON_TABLE, fixed=ON_TABLE.fixed[1:])
        axes = {
            "xs": grid_axis(0.2, 0.7, 0.05, field="x"),
            "ys": grid_axis(-0.3, 0.3, 0.05, field="y"),
            "z": 0.2,
            "yaws": np.array([1.57]),
        }
    if qddot_max is not None:
        robot = robot.with_options(qddot_max=[qddot_max] * 6)
    problem = PathProblem.of(robot, load_path("curved_line"), PathOptions(cell=cell))
    runs: list[int] = []
    run_chunk = branch_candidates.run_chunk

    def spy(*args: object, **kwargs: object) -> object:
        runs.append(1)
        return run_chunk(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(branch_candidates, "run_chunk", spy)
    compiled = capability_map(problem, **axes)  # type: ignore[arg-type]
    assert not runs  # no numpy pipeline run: the kernel's answers
    plain = capability_map(dataclasses.replace(problem, options=PathOptions()), **axes)  # type: ignore[arg-type]
    feasible = compiled.reason == -1
    assert ((compiled.branch != plain.branch) & feasible).any()  # next branches were taken
    assert (compiled.reason == 4).any()  # and some cells refused
    monkeypatch.setattr(placements_module, "kernel_of", lambda problem: None)
    reference = capability_map(problem, **axes)  # type: ignore[arg-type]
    for field, value in vars(reference).items():
        if not isinstance(value, np.ndarray):
            continue
        if field == "mu_acc" and qddot_max is not None:  # to the rounding through D_i
            rounding = KERNEL_ACC_ULPS * np.spacing(2 * math.pi) * 4 / 0.002**2 / qddot_max
            ours = compiled.mu_acc
            np.testing.assert_array_equal(np.isnan(ours), np.isnan(value))
            np.testing.assert_allclose(ours**-2.0, value**-2.0, rtol=2e-12, atol=rounding)
        elif value.dtype.kind == "f":
            np.testing.assert_allclose(getattr(compiled, field), value, rtol=1e-12, err_msg=field)
        else:
            np.testing.assert_array_equal(getattr(compiled, field), value, field)
