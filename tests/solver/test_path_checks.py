"""The path checks' joint paths and next branches: the kernel's, and the numpy pipeline run's.

A map with a cell checks each feasible placement's chosen joint path, and the refused
placements' next branches. Where the family has a compiled kernel (fixed spin), the kernel
answers both (:mod:`solver.path.kernel_branches`); its map equals the numpy pipeline route's,
every reason, branch and waypoint identical and mu_path, mu_acc and V_max to 1e-12. On the numpy
route the chunk's own run answers both where it tracked every branch at every placement: no IK
solved again; each cell is then what an evaluation at that placement answers, and a numeric
arm's map with a cell is the closed form's. A numeric arm's map drops the branches that cannot
be the pick, then runs the refused placements again without the refused branches: the same
map as following every branch. The next branch is the one ``auto`` takes among those left
(:func:`tie_order`, against :func:`choose_branch`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest

import solver.path.branch_candidates as branch_candidates
import solver.path.path_checks as path_checks
import solver.path.placements as placements_module
from solver.core.codes import REASONS
from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric.family import NumericFamily
from solver.path.branch_candidates import tie_order
from solver.path.capability_map import capability_map, grid_axis
from solver.path.evaluate import evaluate_path
from solver.path.kernel_branches import KernelBranches
from solver.path.pipeline import run_chunk
from solver.path.placements import evaluate_placements
from solver.path.problem import PathOptions, PathProblem
from solver.path.tracking import choose_branch
from tests.cases import KERNEL_ACC_ULPS
from tests.solver.families.numeric_maps import opw_urdf, ur5_from_urdf
from tests.solver.families.test_numeric_pruned_map import stepped
from tests.solver.test_cell_fast import _arm
from tests.solver.test_cell_pair_tables import ON_TABLE
from tests.solver.test_evaluate import load_path
from tests.solver.test_map_kernel import grid


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


def _numpy_route(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, int, bool, bool]]:
    """Maps on the numpy pipeline from here on; the pipeline runs, as :func:`_spy_runs`."""
    monkeypatch.setattr(placements_module, "kernel_of", lambda problem: None)
    return _spy_runs(monkeypatch)


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
    assert runs and {caller for caller, *_ in runs} == {placements_module.__name__}  # the chunks
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
    # the chunks' runs, then the refused placements' (pruned, then every branch left)
    assert {caller for caller, *_ in runs} == {
        placements_module.__name__,
        path_checks.__name__,
        branch_candidates.__name__,
    }
    assert (reference.reason == 4).any() and (reference.reason == -1).any()
    np.testing.assert_array_equal(cmap.reason, reference.reason)
    np.testing.assert_array_equal(cmap.failed_waypoint, reference.failed_waypoint)
    np.testing.assert_allclose(cmap.mu_path, reference.mu_path, rtol=1e-9)


@pytest.mark.parametrize(
    ("name", "qddot_max", "spin"),
    [
        ("ur5", None, "fixed"),
        ("ur5e", None, "fixed"),
        ("ur5", 4.0, "fixed"),
        ("kr6", None, "fixed"),
        ("ur5", None, "free"),
        ("ur5e", 4.0, "free"),
    ],
)
def test_compiled_path_checks_equal_the_pipeline_route(
    name: str, qddot_max: float | None, spin: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The map with a cell by the kernel's joint paths and branches = by the numpy pipeline; in
    free spin the kernel's paths run along each branch's spin schedule."""
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
    options = PathOptions(cell=cell, spin_mode=spin)  # type: ignore[arg-type]
    problem = PathProblem.of(robot, load_path("curved_line"), options)
    runs: list[int] = []
    run_chunk = branch_candidates.run_chunk

    def spy(*args: object, **kwargs: object) -> object:
        runs.append(1)
        return run_chunk(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(branch_candidates, "run_chunk", spy)
    monkeypatch.setattr(path_checks, "run_chunk", spy)
    left_out: list[np.ndarray] = []  # per call of the kernel's next picks: branches left out
    excluding = KernelBranches.excluding

    def spy_excluding(self: KernelBranches, *args: Any) -> tuple[np.ndarray, ...]:
        left_out.append(args[2].sum(axis=1))
        return excluding(self, *args)

    monkeypatch.setattr(KernelBranches, "excluding", spy_excluding)
    compiled = capability_map(problem, **axes)  # type: ignore[arg-type]
    assert not runs  # no numpy pipeline run: the kernel's answers
    # the next picks: kernel runs without the refused branches, more of them round by round
    assert left_out and all((counts >= 1).all() for counts in left_out)
    assert max(int(counts.max()) for counts in left_out) > 1
    bare = PathOptions(spin_mode=spin)  # type: ignore[arg-type]
    plain = capability_map(dataclasses.replace(problem, options=bare), **axes)  # type: ignore[arg-type]
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


def _spy_runs(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, int, bool, bool]]:
    """The pipeline runs from here on: (caller, placements, pruned asked, branches excluded)."""
    runs: list[tuple[str, int, bool, bool]] = []
    for module in (placements_module, branch_candidates, path_checks):

        def spy(
            problem: PathProblem, rows: np.ndarray, _module: object = module, **kwargs: object
        ) -> object:
            excluded = kwargs.get("excluded")
            runs.append(
                (
                    getattr(_module, "__name__", ""),
                    len(rows),
                    bool(kwargs.get("prune")),
                    excluded is not None,
                )
            )
            return run_chunk(problem, rows, **kwargs)  # type: ignore[arg-type]

        monkeypatch.setattr(module, "run_chunk", spy)
    return runs


@pytest.mark.parametrize("name", ["ur5_urdf", "panda", "panda_in_steps"])
def test_a_pruned_numeric_map_with_a_cell_equals_following_every_branch(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Six and seven joints (each family's bounded pass): the map with a cell, pruned, then
    the refused placements run again without their refused branches, equals the map of runs
    that follow every branch at every placement (the next branches read off those runs), on
    every field; the runs after the chunks' cover only refused placements and exclude their
    refused branches. A family pruned in steps (arms of more joints; the Panda made to) runs
    the refused placements once, every branch left followed."""
    tool = _arm("ur5").transform_tool_to_tcp
    robot = ur5_from_urdf() if name == "ur5_urdf" else get_robot("panda")
    if name == "panda_in_steps":
        robot = stepped(robot, only=True)
    problem = PathProblem.of(
        robot.with_options(transform_tool_to_tcp=tool),
        load_path("curved_line"),
        PathOptions(cell=ON_TABLE),
    )
    axes = {**AXES, "yaws": np.array([0.0])}
    plain = capability_map(dataclasses.replace(problem, options=PathOptions()), **axes)  # type: ignore[arg-type]
    runs = _spy_runs(monkeypatch)
    seeded: list[int] = []  # placements seeded at their first waypoint, call by call
    seed_first = NumericFamily.seed_first

    def counted(self: NumericFamily, *args: Any) -> tuple[np.ndarray, np.ndarray]:
        seeded.append(len(args[0]))
        return seed_first(self, *args)

    monkeypatch.setattr(NumericFamily, "seed_first", counted)
    pruned = capability_map(problem, **axes)  # type: ignore[arg-type]
    chunks = [run for run in runs if run[0] == placements_module.__name__]
    again = [run for run in runs if run[0] != placements_module.__name__]
    assert chunks and all(prune and not excluded for _, _, prune, excluded in chunks)
    assert again and all(excluded for *_, excluded in again)
    # The pruned runs again take the chunk's seeding: a placement is seeded by its chunk's
    # run, and again only by a run of every branch left.
    every_left = sum(count for _, count, prune, _ in again if not prune)
    assert sum(seeded) == pruned.reason.size + every_left
    if name != "panda_in_steps":
        assert any(prune for _, _, prune, _ in again)  # pruned rounds ran, not seeded
    if name == "panda_in_steps":  # no pruned round: one run of the refused placements
        assert len(again) <= len(chunks) and not any(prune for _, _, prune, _ in again)
    feasible = plain.reason == -1
    moved = feasible & ((pruned.branch != plain.branch) | (pruned.reason == 4))
    assert moved.any() and (pruned.reason == -1).any()  # picks refused, next branches taken
    assert max(count for _, count, _, _ in again) <= moved.sum()  # only refused placements
    runs.clear()
    rows = grid(pruned.xs, pruned.ys, pruned.z, pruned.yaws)  # the map's placements, in order
    full = evaluate_placements(problem, rows, prune=False)
    assert runs and not any(prune for _, _, prune, _ in runs)  # every branch followed
    for field in ("mu_path", "reason", "failed_waypoint", "branch", "bottleneck_waypoint",
                  "bottleneck_joint"):  # fmt: skip
        ours, theirs = getattr(pruned, field).ravel(), getattr(full, field)
        np.testing.assert_array_equal(ours, theirs, err_msg=field)


def test_the_next_branch_is_autos_choice_among_those_left() -> None:
    """tie_order against choose_branch (tracking's rule) on the branches left, round by round:
    near ties go to the first branch in order, as auto's first choice does (a sort by falling
    mu_path would take the higher of two tied values)."""
    rng = np.random.default_rng(7)
    tie = 1e-12
    cases = [np.array([1.0, 1.0 + 1e-13, 0.5, 1.0 - 1e-13, 0.25])]
    cases += [np.round(rng.uniform(0.2, 0.3, 8), 2) * (1 + rng.uniform(-1, 1, 8) * 1e-13)
              for _ in range(50)]  # fmt: skip
    for index in cases:
        rows = [b for b in range(len(index)) if b != 2]  # one infeasible branch left out
        order = tie_order(index, rows, tie)
        left = np.array([b in rows for b in range(len(index))])
        expected = []
        while left.any():
            b = int(choose_branch(index, left, np.zeros(len(index), dtype=int), tie))
            expected.append(b)
            left[b] = False
        assert order == expected
    assert tie_order(cases[0], [0, 1, 3, 4], tie) == [0, 1, 3, 4]  # not [1, 0, 3, 4]
