"""A limit of its own plugs into the problem's limits, and every route honours it.

The compiled map kernels compute the joint speed limits' DTF themselves: a waypoint limit they
do not know was silently dropped by the maps and every optimiser while the evaluator applied
it (the seams audit: a 0.1 m/s feed cap, 0.294 m/s on the map). A problem with one runs on the
numpy pipeline, which loops over the limits.
"""

from __future__ import annotations

import numpy as np

from solver.families import get_robot
from solver.path.capability_map import capability_map
from solver.path.evaluate import evaluate_path
from solver.path.limits import JointMotion, Limit
from solver.path.problem import PathProblem
from tests.solver.test_evaluate import load_path

CAP = 0.1  # m/s, below the README example's mu_path everywhere on the grid


class FeedCap(Limit):
    """A spindle's largest feed: the same bound at every waypoint, on no joint (-1)."""

    name = "feed cap"

    def speed_bound(self, motion: JointMotion) -> tuple[np.ndarray, np.ndarray]:
        shape = motion.qd_unit.shape[1:]
        return np.full(shape, CAP), np.full(shape, -1)


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
