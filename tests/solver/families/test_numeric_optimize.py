"""The optimisers on a seven-joint arm of the numeric family (issue 11): the Panda."""

from __future__ import annotations

import json

import numpy as np
import pytest

from solver.evaluate import evaluate_path
from solver.optimize import optimize_placement
from solver.robots import get_robot
from solver.search_space import PlacementBounds
from solver.spatial import pose_matrix
from tests.cases import EXAMPLES, OPTIMUM_EVALUATE_RTOL
from tests.solver.test_optimize import best_coarse_cell

BOUNDS = PlacementBounds(x=(-0.05, 0.05), y=(0.4, 0.5), yaw=(-0.3, 0.3), z=0.1)


@pytest.fixture(scope="module")
def path() -> np.ndarray:
    """The first ten waypoints of the example path, (10, 4, 4)."""
    waypoints = json.loads((EXAMPLES / "evaluate_request.json").read_text())["path"]["waypoints"]
    return np.array(
        [pose_matrix(w["position"], w["orientation"], field="w") for w in waypoints[:10]]
    )


def test_casadi_on_the_panda_reaches_the_coarse_map_and_is_the_evaluators(
    path: np.ndarray,
) -> None:
    robot = get_robot("panda")
    optimum = optimize_placement(robot, path, bounds=BOUNDS, method="casadi")
    assert optimum.found and optimum.placement is not None and optimum.mu_path is not None
    assert optimum.mu_path >= best_coarse_cell(robot, path, BOUNDS) * (1 - 1e-9)
    evaluation = evaluate_path(robot, path, optimum.placement)
    assert optimum.mu_path == pytest.approx(evaluation.mu_path, rel=OPTIMUM_EVALUATE_RTOL)
