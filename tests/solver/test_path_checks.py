"""The path checks' joint paths and next branches: compiled, and the numpy route's IK reuse.

A map with a cell checks each feasible placement's chosen joint path, and the refused
placements' next branches. Where the family has a compiled kernel (fixed spin), the kernel
answers both (:mod:`solver.path.kernel_branches`); its map equals the numpy pipeline route's,
every reason, branch and waypoint identical and mu_path, mu_acc and V_max to 1e-12. On the numpy
route the refused placements run the pipeline again, taking the IK already solved for the chunk
(:func:`solver.path.chosen_paths.chunk_solutions`). That rests on an analytic family solving
each placement on its own: a subset's solutions equal to the bit the full set's columns
(checked here against the family solving the subset alone); and the map is the map without the
reuse, every field to the bit.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import solver.path.branch_candidates as branch_candidates
import solver.path.chosen_paths as chosen_paths
import solver.path.path_checks as path_checks
import solver.path.placements as placements_module
from solver.core.robots import Robot
from solver.families import get_robot, robot_from_urdf
from solver.path.capability_map import capability_map, grid_axis
from solver.path.placed import placed_flange
from solver.path.problem import PathOptions, PathProblem
from tests.cases import KERNEL_ACC_ULPS
from tests.solver.families.numeric_maps import opw_urdf
from tests.solver.test_cell_fast import _arm
from tests.solver.test_cell_pair_tables import ON_TABLE
from tests.solver.test_evaluate import load_path


def _robot(name: str) -> Robot:
    if name == "kr6":  # an OPW arm's closed form, recognised in its URDF
        urdf = opw_urdf("kuka_kr6_r700_sixx")
        return robot_from_urdf(urdf, base_frame="base_link", tool_frame="tool0")
    return get_robot(name)


@pytest.mark.parametrize("name", ["ur5", "ur5e", "kr6"])
def test_subset_solutions_are_the_full_sets_columns(name: str) -> None:
    """Seeded random placements and subsets: the same floats and statuses."""
    problem = PathProblem.of(_robot(name), load_path("curved_line"), PathOptions())
    rng = np.random.default_rng(5)
    for _ in range(10):
        count = int(rng.integers(5, 40))
        placements = np.column_stack(
            [
                rng.uniform(-0.3, 0.3, count),
                rng.uniform(0.2, 0.7, count),
                np.full(count, 0.1),
                rng.uniform(-1.0, 1.0, count),
                np.zeros(count),
            ]
        )
        solutions = chosen_paths.chunk_solutions(problem, placements)
        assert solutions is not None and chosen_paths.per_placement(solutions)
        subset = np.sort(rng.choice(count, int(rng.integers(1, count + 1)), replace=False))
        _, rotation, position = placed_flange(problem, placements[subset])
        alone = problem.family.solve_path(rotation, position)
        np.testing.assert_array_equal(solutions.q[:, :, subset], alone.q)
        np.testing.assert_array_equal(solutions.status[:, subset], alone.status)


AXES = {
    "xs": grid_axis(-0.25, 0.25, 0.05, field="x"),
    "ys": grid_axis(0.25, 0.65, 0.05, field="y"),
    "z": 0.1,
    "yaws": np.array([0.0, 0.6]),
}


@pytest.mark.parametrize("name", ["ur5", "ur5e"])
def test_map_reusing_the_ik_equals_without(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The ERK path's map with a cell on the numpy route, every field to the bit, next branches."""
    monkeypatch.setattr(placements_module, "_compiled", lambda *args: None)
    given: list[bool] = []  # per pipeline run of refused placements: was the IK handed over?
    run_chunk = branch_candidates.run_chunk

    def spy(*args: object, **kwargs: object) -> object:
        given.append(kwargs.get("solutions") is not None)
        return run_chunk(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(branch_candidates, "run_chunk", spy)
    problem = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions(cell=ON_TABLE))
    plain = PathProblem.of(_arm(name), load_path("curved_line"), PathOptions())
    reused = capability_map(problem, **AXES)  # type: ignore[arg-type]
    assert given and all(given)
    given.clear()
    free = capability_map(plain, **AXES)  # type: ignore[arg-type]
    assert ((reused.branch != free.branch) & (reused.reason == -1)).any()  # next branches
    monkeypatch.setattr(path_checks, "per_placement", lambda solutions: False)
    again = capability_map(problem, **AXES)  # type: ignore[arg-type]
    assert given and not any(given)
    fields = [k for k, v in vars(reused).items() if isinstance(v, np.ndarray)]
    assert "mu_path" in fields and "branch" in fields
    for field in fields:
        np.testing.assert_array_equal(getattr(reused, field), getattr(again, field), field)


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
    monkeypatch.setattr(placements_module, "_compiled", lambda *args: None)
    reference = capability_map(problem, **axes)  # type: ignore[arg-type]
    assert runs  # the numpy route ran the pipeline for the refused placements
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
