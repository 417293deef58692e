"""Segments that turn by a half turn (issue 9): refused at pi, consistent just below it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from solver.core.exceptions import InvalidInputError
from solver.core.task import task_requirements
from solver.families import get_robot
from solver.optimise.search_space import PlacementBounds
from tests.cases import MAP_EVALUATE_RTOL
from tests.problems import capability_map, evaluate_path, optimize_placement


def two_waypoints(turn: float) -> np.ndarray:
    """The issue's path: tool z down, then turned by ``turn`` about tool z, 10 mm along x."""
    first = Rotation.from_quat([1.0, 0.0, 0.0, 0.0]).as_matrix()
    poses = np.array([np.eye(4), np.eye(4)])
    poses[0, :3, :3] = first
    poses[1, :3, :3] = first @ Rotation.from_euler("z", turn).as_matrix()
    poses[1, :3, 3] = [0.01, 0.0, 0.0]
    return poses


@pytest.mark.parametrize("turn", [math.pi, math.pi - 5e-7])
def test_a_half_turn_is_refused_naming_the_waypoint(turn: float) -> None:
    with pytest.raises(InvalidInputError) as error:
        task_requirements(two_waypoints(turn))
    assert (error.value.field, error.value.waypoint) == ("path.waypoints", 1)
    assert "half turn" in error.value.message


def test_just_below_a_half_turn_map_equals_evaluate_and_the_optimum_keeps_its_start() -> None:
    """The issue's case 2e-3 rad below pi: every yaw of the map = evaluate, and the optimiser
    never answers below its start."""
    robot, path = get_robot("ur5"), two_waypoints(math.pi - 2e-3)
    yaws = np.linspace(0.1, 0.2, 21)
    cmap = capability_map(
        robot,
        path,
        xs=np.array([0.0, 0.02]),
        ys=np.array([0.4, 0.45]),
        z=0.1,
        yaws=yaws,
        max_joint_step=3.5,
    )
    for index in np.ndindex(cmap.mu_path.shape):
        expected = evaluate_path(robot, path, cmap.placement(index), max_joint_step=3.5)
        assert expected.feasible
        assert cmap.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
    bounds = PlacementBounds(x=(0.0, 0.02), y=(0.4, 0.45), yaw=(0.1, 0.2), z=0.1)
    for method in ("casadi", "scipy"):
        optimum = optimize_placement(robot, path, bounds=bounds, method=method, max_joint_step=3.5)
        assert optimum.found and optimum.mu_path >= optimum.start_mu_path
