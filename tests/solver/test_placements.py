"""mu_path at arbitrary placements (each its own yaw) equals evaluate_path there."""

from __future__ import annotations

import math
import platform

import numpy as np
import pytest

from solver.core.codes import REASONS
from solver.core.exceptions import InvalidInputError
from solver.core.malloc import raise_malloc_thresholds
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.families.ur.ik import BRANCHES
from solver.path.placement_evaluator import PlacementEvaluator
from tests.cases import MAP_EVALUATE_RTOL
from tests.problems import evaluate_path, evaluate_placements, prepare_path
from tests.solver.test_evaluate import load_path


def random_placements(seed: int, n: int, *, z: tuple[float, float]) -> np.ndarray:
    """n placements (x, y, z, yaw), x and y in +-0.8 m, yaw over a turn; reachable or not."""
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [
            rng.uniform(-0.8, 0.8, n),
            rng.uniform(-0.8, 0.8, n),
            rng.uniform(*z, n),
            rng.uniform(-math.pi, math.pi, n),
        ]
    )


def test_random_placements_equal_evaluate() -> None:
    robot = get_robot("ur5e")
    path = load_path("s_curve")
    placements = random_placements(8, 60, z=(-0.2, 0.3))
    result = evaluate_placements(robot, prepare_path(robot, path), placements, with_speeds=True)
    feasible = 0
    for p, row in enumerate(placements):
        expected = evaluate_path(robot, path, Placement(*row))
        assert BRANCHES[result.branch[p]] == expected.branch
        if expected.feasible:
            feasible += 1
            assert result.mu_path[p] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
            np.testing.assert_allclose(result.v_max[p], expected.v_max, rtol=MAP_EVALUATE_RTOL)
        else:
            assert REASONS[result.reason[p]] == expected.reason
            assert result.failed_waypoint[p] == expected.failed_waypoint
            assert np.all(np.isnan(result.v_max[p]))
    assert 10 <= feasible <= 50


@pytest.mark.parametrize("placements", [np.zeros((3, 3)), np.array([[0, 0, 0, math.nan]])])
def test_bad_placements(placements: np.ndarray) -> None:
    robot = get_robot("ur5")
    with pytest.raises(InvalidInputError):
        evaluate_placements(robot, prepare_path(robot, load_path("curved_line")), placements)


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="mallopt is glibc's")
def test_malloc_thresholds_are_set_on_glibc() -> None:
    assert raise_malloc_thresholds() is True


@pytest.mark.parametrize(
    ("robot_name", "spin_mode"),
    [("ur5", "fixed"), ("kuka_kr6_r700_sixx", "fixed"), ("ur5", "free")],
)
def test_the_placement_evaluator_is_the_numpy_pipeline_one_placement_at_a_time(
    robot_name: str, spin_mode: str
) -> None:
    """The local searches' evaluator, one placement per call, spins changing between calls."""
    robot = get_robot(robot_name)
    path = prepare_path(robot, load_path("curved_line"))
    spins = np.repeat([0.0, 0.7, 0.0, -1.2], 6)  # a spin asked for again after another
    placements = np.column_stack([random_placements(3, 24, z=(-0.1, 0.3)), spins])
    reference = evaluate_placements(robot, path, placements, spin_mode=spin_mode, compiled=False)
    evaluate = PlacementEvaluator(path.with_options(spin_mode=spin_mode))
    answers = [evaluate(row[None]) for row in placements]
    mu = np.concatenate([a.mu_path for a in answers])
    np.testing.assert_allclose(mu, reference.mu_path, rtol=1e-12, equal_nan=True)
    for column in ("reason", "failed_waypoint", "branch", "bottleneck_waypoint"):
        got = np.concatenate([getattr(a, column) for a in answers])
        np.testing.assert_array_equal(got, getattr(reference, column))
    assert 4 <= np.count_nonzero(np.isfinite(mu)) <= 20  # feasible and infeasible cells both
