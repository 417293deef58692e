"""OPW arms through the path pipeline: evaluate, map and both optimisers, as for UR arms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.core.codes import REASONS
from solver.core.dtf import lp_speed
from solver.core.family import Branch
from solver.core.kinematics import jacobian_in_base
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.optimise.search_space import PlacementBounds, vector_of
from solver.path.capability_map import grid_axis
from tests.cases import (
    DTF_LP_RTOL,
    MAP_EVALUATE_RTOL,
    OPTIMUM_EVALUATE_RTOL,
    OPTIMUM_METHODS_RTOL,
)
from tests.problems import capability_map, evaluate_path, optimize_placement
from tests.solver.test_evaluate import load_path
from tests.solver.test_optimize import best_coarse_cell

KR6 = "kuka_kr6_r700_sixx"
PLACEMENT = Placement(0.45, 0.0, 0.1, 0.0)


def test_evaluate_speeds_equal_an_lp_along_its_joint_path() -> None:
    """Each waypoint's V_max from the closed-form J^-1 t = HiGHS on pinocchio's Jacobian."""
    robot, path = get_robot(KR6), load_path("curved_line")
    evaluation = evaluate_path(robot, path, PLACEMENT)
    assert evaluation.feasible and evaluation.q is not None and evaluation.v_max is not None
    twists = np.column_stack(
        [
            evaluation.u_T,
            evaluation.u_R / np.where(np.isinf(evaluation.h), np.inf, evaluation.h)[:, None],
        ]
    )
    for i in range(0, len(path), 7):
        speed, _ = lp_speed(
            jacobian_in_base(robot, evaluation.q[i]), twists[i], qdot_max=robot.qdot_max
        )
        assert evaluation.v_max[i] == pytest.approx(speed, rel=DTF_LP_RTOL)
    # Joint positions within the catalogue's limits, with the 2 pi copy that fits.
    assert np.all((evaluation.q >= robot.q_lower) & (evaluation.q <= robot.q_upper))


def test_named_branches_and_foreign_names() -> None:
    robot, path = get_robot(KR6), load_path("curved_line")
    auto = evaluate_path(robot, path, PLACEMENT)
    assert auto.branch is not None and auto.branch.as_dict()["shoulder"] in ("front", "back")
    named = evaluate_path(robot, path, PLACEMENT, branch=auto.branch)
    assert named.mu_path == auto.mu_path
    with pytest.raises(Exception) as error:
        evaluate_path(
            robot, path, PLACEMENT, branch=Branch.named(shoulder="left", elbow="up", wrist="flip")
        )
    assert error.value.field == "ik.branch" and "shoulder=front" in error.value.message


def test_map_cells_equal_evaluate_for_every_reason() -> None:
    robot, path = get_robot(KR6), load_path("curved_line")
    cmap = capability_map(
        robot,
        path,
        xs=grid_axis(0.2, 0.7, 0.05, field="x"),
        ys=grid_axis(-0.25, 0.25, 0.05, field="y"),
        z=0.2,
        yaws=np.array([0.0, math.pi / 2]),
    )
    seen = set()
    for index in np.ndindex(cmap.mu_path.shape):
        expected = evaluate_path(robot, path, cmap.placement(index))
        if expected.feasible:
            assert cmap.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
            assert cmap.bottleneck_joint[index] == expected.bottleneck_joint
            seen.add("feasible")
        else:
            assert np.isnan(cmap.mu_path[index])
            assert REASONS[cmap.reason[index]] == expected.reason
            assert cmap.failed_waypoint[index] == expected.failed_waypoint
            seen.add(expected.reason)
        assert robot.family.branches[cmap.branch[index]] == expected.branch
    assert {"feasible", "unreachable", "joint_limits", "discontinuous"} <= seen


def test_turning_a_placement_about_the_base_axis_keeps_mu_path() -> None:
    """Joint 1 turns about base z: a turn by alpha (within joint 1's limits) changes nothing."""
    robot, path = get_robot(KR6), load_path("curved_line")
    base = evaluate_path(robot, path, PLACEMENT)
    for alpha in (0.3, -0.5):
        c, s = math.cos(alpha), math.sin(alpha)
        turned = Placement(c * PLACEMENT.x, s * PLACEMENT.x, PLACEMENT.z, alpha)
        assert evaluate_path(robot, path, turned).mu_path == pytest.approx(base.mu_path, rel=1e-9)


@pytest.fixture(scope="module")
def optima() -> dict:
    robot, path = get_robot(KR6), load_path("curved_line")
    bounds = PlacementBounds(x=(0.3, 0.5), y=(-0.1, 0.1), yaw=(-math.pi, math.pi), z=0.1)
    return {
        "robot": robot,
        "path": path,
        "bounds": bounds,
        "best_cell": best_coarse_cell(robot, path, bounds),
        **{
            m: optimize_placement(robot, path, bounds=bounds, method=m) for m in ("casadi", "scipy")
        },
    }


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_optimisers_on_an_opw_arm(optima: dict, method: str) -> None:
    optimum = optima[method]
    assert optimum.found and optimum.mu_path >= optima["best_cell"]
    assert optima["bounds"].contains(vector_of(optimum.placement))
    evaluation = evaluate_path(optima["robot"], optima["path"], optimum.placement)
    assert optimum.mu_path == pytest.approx(evaluation.mu_path, rel=OPTIMUM_EVALUATE_RTOL)
    other = optima["scipy" if method == "casadi" else "casadi"]
    assert optimum.mu_path == pytest.approx(other.mu_path, rel=OPTIMUM_METHODS_RTOL)


def test_free_spin_on_an_opw_arm() -> None:
    """The two-variable LP serves every family: map = evaluate, and never below fixed spin."""
    robot, path = get_robot(KR6), load_path("curved_line")
    xs, ys = np.array([0.35, 0.45, 0.55]), np.array([-0.1, 0.1])
    free = capability_map(robot, path, xs=xs, ys=ys, z=0.1, yaws=np.zeros(1), spin_mode="free")
    fixed = capability_map(robot, path, xs=xs, ys=ys, z=0.1, yaws=np.zeros(1))
    for index in np.ndindex(free.mu_path.shape):
        expected = evaluate_path(robot, path, free.placement(index), spin_mode="free")
        if expected.mu_path is None:
            assert np.isnan(free.mu_path[index])
            continue
        assert free.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
        if not np.isnan(fixed.mu_path[index]):
            assert free.mu_path[index] >= fixed.mu_path[index] * (1 - 1e-12)
    assert np.isfinite(free.mu_path).sum() >= 3
