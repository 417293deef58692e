"""A limit or path check of its own plugs into the problem, and every route honours it.

The compiled map kernels compute the joint speed limits' DTF themselves: a waypoint limit they
do not know was silently dropped by the maps and every optimiser while the evaluator applied
it (the seams audit: a 0.1 m/s feed cap, 0.294 m/s on the map). A problem with one runs on the
numpy pipeline, which loops over the limits.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.codes import REASON_COLLISION, REASON_JOINT_LIMITS, REASONS
from solver.core.exceptions import InvalidInputError
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.optimise.symmetry import symmetric_search
from solver.path.capability_map import capability_map
from solver.path.evaluate import evaluate_path
from solver.path.limits import JointMotion, Limit, PathCheck, PathVerdict
from solver.path.problem import PathProblem
from tests.solver.test_evaluate import load_path

CAP = 0.1  # m/s, below the README example's mu_path everywhere on the grid


class FeedCap(Limit):
    """A spindle's largest feed: the same bound at every waypoint, on no joint (-1)."""

    name = "feed cap"

    def speed_bound(self, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        shape = motion.qd_unit.shape[1:]
        return np.full(shape, CAP), np.full(shape, -1)

    def pose_cost(self) -> float:
        return 0.0  # one comparison a waypoint


def test_a_map_honours_a_limit_the_kernels_do_not_know() -> None:
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    problem.__dict__["limits"] = (*problem.limits, FeedCap())  # the problem's own limits
    xs, ys = np.array([-0.1, 0.0, 0.1]), np.array([0.4, 0.5])
    cmap = capability_map(problem, xs=xs, ys=ys, z=0.1, yaws=np.zeros(1))
    feasible = [i for i in np.ndindex(cmap.mu_path.shape) if np.isfinite(cmap.mu_path[i])]
    assert len(feasible) == 6
    for index in feasible:
        assert cmap.mu_path[index] == CAP
        assert evaluate_path(problem, cmap.placement(index)).mu_path == CAP


class Joint1Range(PathCheck):
    """A check of the test's own: joint 1 within +-bound (a cable that must not wind)."""

    name = "joint 1 range"
    reason = REASON_JOINT_LIMITS

    def __init__(self, bound: float) -> None:
        self.bound = bound

    def check(self, q: np.ndarray, placement: np.ndarray, *, thorough: bool) -> PathVerdict:
        outside = np.flatnonzero(np.abs(q[:, 0]) > self.bound)
        if not outside.size:
            return PathVerdict(None, None)
        return PathVerdict(int(outside[0]), None, self.reason)

    def pose_cost(self) -> float:
        return 0.01  # one comparison a pose


class Admits(PathCheck):
    """A check that admits every path, first in the problem's checks."""

    name = "admits"
    reason = REASON_COLLISION

    def check(self, q: np.ndarray, placement: np.ndarray, *, thorough: bool) -> PathVerdict:
        return PathVerdict(None, None)

    def pose_cost(self) -> float:
        return 0.0


def test_a_path_check_of_its_own_refuses_with_its_reason() -> None:
    """The answers took the first check's reason and read a cell's report from any refusal:
    a check other than the cell's crashed evaluate_path (TypeError), and behind another check
    its refusals were called collisions (the seams audit)."""
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    problem.__dict__["path_checks"] = (Admits(), Joint1Range(0.0))  # |q1| > 0: every branch
    evaluation = evaluate_path(problem, Placement(0.0, 0.45, 0.1, 0.0))
    assert (evaluation.reason, evaluation.failed_waypoint) == ("joint_limits", 0)
    assert evaluation.collision is None
    cmap = capability_map(problem, xs=np.array([-0.1, 0.1]), ys=np.array([0.45]), z=0.1,
                          yaws=np.zeros(1))  # fmt: skip
    assert [REASONS[r] for r in cmap.reason.ravel()] == ["joint_limits", "joint_limits"]


def test_a_limit_that_does_not_say_it_keeps_a_base_turn_breaks_the_symmetry() -> None:
    """The (r, psi) search assumes every limit is the same at a placement turned about the base
    z axis; it was decided from the cell alone, and a joint-1 range searched that way was
    silently wrong (the seams audit). A limit is taken to keep the turn only where it says so."""
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    assert symmetric_search(problem)
    problem.__dict__["limits"] = (*problem.limits, FeedCap())
    assert not symmetric_search(problem)


def test_the_casadi_method_refuses_a_limit_its_nlp_has_no_rows_for() -> None:
    """IPOPT's rows are the joint speed and acceleration limits by name: with another limit it
    climbed to the optimum of those alone (the seams audit). The scipy method evaluates every
    limit: its optimum holds the cap."""
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    problem.__dict__["limits"] = (*problem.limits, FeedCap())
    bounds = PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(-0.2, 0.2), z=0.1)
    with pytest.raises(InvalidInputError) as error:
        optimize_placement(problem, bounds=bounds, method="casadi")
    assert error.value.field == "method"
    assert "not for the 'feed cap' limit: use method scipy" in error.value.message
    optimum = optimize_placement(problem, bounds=bounds, method="scipy")
    assert optimum.mu_path == CAP


def test_the_kinematics_alone_are_the_problem_without_any_path_check() -> None:
    """What the scipy method scores a refused placement by: the problem with no path check,
    whichever checks it holds (it was written as ``with_options(cell=None)`` at each use)."""
    problem = PathProblem.of(get_robot("ur5"), load_path("curved_line")[::4])
    problem.__dict__["path_checks"] = (Joint1Range(0.0),)
    at = Placement(0.0, 0.45, 0.1, 0.0)
    assert evaluate_path(problem, at).reason == "joint_limits"
    clear = problem.without_path_checks()
    assert clear.path_checks == ()
    assert evaluate_path(clear, at).feasible
