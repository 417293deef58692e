"""A numeric branch crossing a wrist singularity between two waypoints fails as the analytic one.

robots.md: a wrist never passes q5 = 0. Sampled sparsely, a path can cross it between two
waypoints with every joint step small: the numeric IK follows the crossing (q5 changes sign,
q4 and q6 hardly move), while the analytic branch, whose label fixes the wrist's sign, jumps
by pi in q4 and q6 (``discontinuous`` at the second waypoint of the step). The numeric family
marks the sign of det J in its statuses (``OK_MIRRORED``) and tracking calls a change of it
between the waypoints of a pass a discontinuity, so both answer the same. The fixtures: a joint
path of the UR5 (its URDF) and of the KR16-2 (a URDF from its OPW parameters) on which q5 runs
from -0.45 to +0.45 rad in eight samples, -0.064 and +0.064 rad at waypoints 3 and 4, the
flange poses by pinocchio's forward kinematics.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from solver.core.codes import OK, OK_MIRRORED, REASON_DISCONTINUOUS, SINGULAR
from solver.core.robots import Robot
from solver.families import get_robot
from solver.path.pipeline import run_chunk
from solver.path.placed import check_placements, placed_flange
from solver.path.placements import PlacementResults, evaluate_placements
from solver.path.problem import PathProblem
from tests.solver.families.numeric_maps import erk_placements, opw_from_urdf, ur5_from_urdf
from tests.solver.families.test_numeric_kernel import MU_RTOL as COMPILED_RTOL
from tests.solver.families.test_numeric_vs_analytic_map import MU_RTOL

CROSSED = 4  # the second waypoint of the step across q5 = 0
CASES = {
    # name: (the numeric arm, base and tool frames, the joint path's ends (rad))
    "ur5": (
        ur5_from_urdf,
        ("base", "tool0"),
        ([0.3, -1.2, 1.5, -1.0, -0.45, 0.4], [0.5, -1.0, 1.3, -0.8, 0.45, 0.6]),
    ),
    "kuka_kr16_2": (
        lambda compiled=True: opw_from_urdf("kuka_kr16_2", compiled=compiled),
        ("base_link", "tool0"),
        ([0.3, 0.2, 0.1, 0.6, -0.45, 0.4], [0.5, 0.4, 0.3, 0.8, 0.45, 0.6]),
    ),
}
PASSES = ((0, CROSSED), (CROSSED, 8))  # the crossing step is the rapid between two passes


def crossing_path(
    robot: Robot, frames: tuple[str, str], ends: tuple[list[float], list[float]]
) -> np.ndarray:
    """Flange poses (8, 4, 4) in the base frame along the straight joint path between ``ends``."""
    model = robot.model
    data = model.createData()
    base, tool = (model.getFrameId(name) for name in frames)
    start, stop = (np.array(end) for end in ends)
    poses = []
    for s in np.linspace(0.0, 1.0, 8):
        pin.framesForwardKinematics(model, data, start + s * (stop - start))
        poses.append((data.oMf[base].inverse() * data.oMf[tool]).homogeneous)
    return np.array(poses)


def grid() -> np.ndarray:
    """3 x 3 placements 1 cm apart around the base, yaw 0 (the path is in the base frame)."""
    return erk_placements(np.array([-0.01, 0.0, 0.01]), np.array([-0.01, 0.0, 0.01]), 0.0)


def maps(
    name: str, passes: tuple[tuple[int, int], ...] | None, **numeric: bool
) -> list[PlacementResults]:
    """The analytic and the numeric map of the case (``evaluate_placements``' results)."""
    make, frames, ends = CASES[name]
    arm = make(**numeric)
    path = crossing_path(arm, frames, ends)
    results = []
    for robot in (get_robot(name), arm):
        problem = PathProblem.of(robot, path, passes=passes)
        results.append(evaluate_placements(problem, grid(), with_speeds=True))
    return results


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "numpy"])
@pytest.mark.parametrize("name", CASES)
def test_crossing_between_waypoints_is_discontinuous_as_analytic(name: str, compiled: bool) -> None:
    analytic, numeric = maps(name, None, compiled=compiled)
    # The fixture means something: no cell is feasible, several jump at the crossing.
    assert not np.isfinite(analytic.mu_path).any()
    assert (
        np.sum((analytic.reason == REASON_DISCONTINUOUS) & (analytic.failed_waypoint == CROSSED))
        >= 3
    )
    np.testing.assert_array_equal(numeric.reason, analytic.reason)
    np.testing.assert_array_equal(numeric.failed_waypoint, analytic.failed_waypoint)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "numpy"])
@pytest.mark.parametrize("name", CASES)
def test_crossing_at_a_pass_break_is_no_step(name: str, compiled: bool) -> None:
    """Between two passes the branch carries on unchecked: both feasible, the same mu_path."""
    analytic, numeric = maps(name, PASSES, compiled=compiled)
    assert np.isfinite(analytic.mu_path).sum() >= 4
    np.testing.assert_array_equal(numeric.reason, analytic.reason)
    np.testing.assert_allclose(numeric.mu_path, analytic.mu_path, rtol=MU_RTOL, atol=0)


@pytest.mark.parametrize("name", CASES)
def test_each_numeric_slot_fails_as_its_analytic_branch(name: str) -> None:
    """Slot by slot at the middle placement: the analytic branch with its first configuration."""
    make, frames, ends = CASES[name]
    arm = make()
    path = crossing_path(arm, frames, ends)
    cell = check_placements(np.zeros((1, 5)))
    ours = run_chunk(PathProblem.of(arm, path), cell)
    theirs = run_chunk(PathProblem.of(get_robot(name), path), cell)
    crossing = 0
    for slot in range(ours.tracked.reason.shape[0]):
        first = ours.tracked.q[:, slot, 0, 0]
        if not np.isfinite(first).all():
            continue
        gap = np.abs(np.angle(np.exp(1j * (theirs.tracked.q[:, :, 0, 0].T - first))))
        twin = int(np.argmin(gap.max(axis=1)))
        assert gap[twin].max() < 1e-8
        assert ours.tracked.reason[slot, 0] == theirs.tracked.reason[twin, 0]
        assert ours.tracked.failed_waypoint[slot, 0] == theirs.tracked.failed_waypoint[twin, 0]
        q5 = ours.tracked.q[4, slot, 0]
        crossing += int(np.sign(q5[CROSSED - 1]) != np.sign(q5[CROSSED]))
    assert crossing > 0  # the numeric IK does follow a wrist across q5 = 0


@pytest.mark.parametrize("name", CASES)
def test_compiled_statuses_equal_numpy(name: str) -> None:
    """The compiled chain's statuses (the sign of det J with them) are the numpy chain's."""
    make, frames, ends = CASES[name]
    path = crossing_path(make(), frames, ends)
    cells = check_placements(grid())
    solved = []
    for compiled in (True, False):
        problem = PathProblem.of(make(compiled=compiled), path)
        _, rotation, position = placed_flange(problem, cells)
        solved.append(problem.family.solve_path(rotation, position))
    np.testing.assert_array_equal(solved[0].status, solved[1].status)
    assert np.any(solved[0].status == OK) and np.any(solved[0].status == OK_MIRRORED)
    assert not np.any(solved[0].status == SINGULAR)
    finite = np.isfinite(solved[1].q)
    np.testing.assert_array_equal(np.isfinite(solved[0].q), finite)
    np.testing.assert_allclose(solved[0].q[finite], solved[1].q[finite], rtol=0, atol=1e-9)


@pytest.mark.parametrize("passes", [None, PASSES], ids=["one_pass", "two_passes"])
@pytest.mark.parametrize("name", CASES)
def test_pruned_equals_unpruned_and_numpy(
    name: str, passes: tuple[tuple[int, int], ...] | None
) -> None:
    make, frames, ends = CASES[name]
    path = crossing_path(make(), frames, ends)
    compiled = PathProblem.of(make(), path, passes=passes)
    pruned = evaluate_placements(compiled, grid(), with_speeds=True)
    every = evaluate_placements(compiled, grid(), with_speeds=True, prune=False)
    for field in ("mu_path", "reason", "failed_waypoint", "branch", "bottleneck_waypoint"):
        np.testing.assert_array_equal(getattr(pruned, field), getattr(every, field), err_msg=field)
    reference = PathProblem.of(make(compiled=False), path, passes=passes)
    theirs = evaluate_placements(reference, grid(), with_speeds=True)
    for field in ("reason", "failed_waypoint", "branch"):
        np.testing.assert_array_equal(getattr(every, field), getattr(theirs, field), err_msg=field)
    np.testing.assert_allclose(every.mu_path, theirs.mu_path, rtol=COMPILED_RTOL, atol=0)
