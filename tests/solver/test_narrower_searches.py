"""cam.md sections 3 and 4: with spin bounds containing 0 the optimum is never below the optimum
without spin; a spin path's never below the constant spin's (solver.optimise.narrower).

The boxes are the optimiser audit's (stop 53): adding spin bounds [-0.5, 0.5] made casadi's
answer 0.17 % (UR5), 0.61 % (UR10) and 0.99 % (UR5e with acceleration limits) lower than
the answer without spin, its local searches starting elsewhere in the wider box.
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from solver.families import get_robot
from solver.optimise.narrower import CONSTANT_SPIN, WITHOUT_SPIN, narrower_searches
from solver.optimise.search_space import PlacementBounds
from solver.optimise.work import work_of
from tests.cases import OPTIMUM_EVALUATE_RTOL
from tests.problems import evaluate_path, optimize_placement, problem
from tests.solver.test_evaluate import load_path

AUDIT_BOXES = {
    "ur5": (
        get_robot("ur5"),
        PlacementBounds(x=(-0.2274, 0.1694), y=(0.2473, 0.4792), yaw=(-3.1416, 3.1416), z=0.073),
    ),
    "ur10": (
        get_robot("ur10"),
        PlacementBounds(x=(-0.0124, 0.3961), y=(-0.8443, -0.3911), yaw=(0.6394, 4.0894), z=0.0044),
    ),
    "ur5e with acceleration limits": (
        get_robot("ur5e").with_options(qddot_max=[10.0] * 6),
        PlacementBounds(x=(-0.1659, 0.25), y=(0.1272, 0.4181), yaw=(-2.5398, -1.7435), z=0.0652),
    ),
}


@pytest.mark.parametrize("case", list(AUDIT_BOXES))
def test_spin_bounds_never_lose_to_no_spin(case: str) -> None:
    robot, bounds = AUDIT_BOXES[case]
    path = load_path("curved_line")[::4]
    spun = dataclasses.replace(bounds, spin=(-0.5, 0.5))
    without = optimize_placement(robot, path, bounds=bounds, max_joint_step=0.35)
    optimum = optimize_placement(robot, path, bounds=spun, max_joint_step=0.35)
    assert without.found and optimum.found
    index = optimum.mu_acc if optimum.mu_acc is not None else optimum.mu_path
    index_without = without.mu_acc if without.mu_acc is not None else without.mu_path
    assert index >= index_without * (1 - 1e-12)
    assert spun.contains(
        [
            optimum.placement.x,
            optimum.placement.y,
            optimum.placement.yaw,
            optimum.placement.spin,
            optimum.placement.z,
        ]
    )
    again = evaluate_path(robot, path, optimum.placement, max_joint_step=0.35)
    assert optimum.mu_path == pytest.approx(again.mu_path, rel=OPTIMUM_EVALUATE_RTOL)


def test_the_narrower_searches_a_request_implies() -> None:
    box = PlacementBounds(x=(0.0, 0.1), y=(0.4, 0.5), yaw=(0.0, 1.0), z=0.0)
    assert narrower_searches(box, None) == ()
    assert narrower_searches(dataclasses.replace(box, spin=(0.2, 0.5)), None) == ()
    spun = dataclasses.replace(box, spin=(-math.pi, math.pi))
    [without] = narrower_searches(spun, None)
    assert (without.name, without.bounds, without.max_spin_step) == (WITHOUT_SPIN, box, None)
    constant, without = narrower_searches(spun, 0.02)
    assert (constant.name, constant.bounds, constant.max_spin_step) == (CONSTANT_SPIN, spun, None)
    assert without.bounds == box
    [constant] = narrower_searches(box, 0.02)
    assert constant.bounds == box


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_the_estimate_counts_the_search_without_spin(method: str) -> None:
    """The work of a box with spin bounds is its own search's and the search's without spin."""
    robot, bounds = AUDIT_BOXES["ur5"]
    posed = problem(robot, load_path("curved_line")[::4])
    spun = dataclasses.replace(bounds, spin=(-0.5, 0.5))
    alone = work_of(posed, bounds, method=method)
    both = work_of(posed, spun, method=method)
    assert both.weighed(posed, WITHOUT_SPIN) == pytest.approx(alone.weighed(posed), rel=1e-12)
    assert both.weighed(posed) == pytest.approx(
        both.weighed(posed, "") + alone.weighed(posed), rel=1e-12
    )
    assert f"({WITHOUT_SPIN})" in both.describe()
