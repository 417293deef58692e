"""The families' cost weights, the unit of the service's size limits (robots.md section 4)."""

from __future__ import annotations

import pytest

from solver.families import get_robot
from solver.families.numeric.costs import COST_LINES
from tests.cases import NUMERIC_MODELS, OPW_MODELS, UR_MODELS


@pytest.mark.parametrize("name", [*UR_MODELS, *OPW_MODELS])
def test_a_closed_form_pose_is_the_unit(name: str) -> None:
    family = get_robot(name).family
    assert family is not None
    assert [family.path_cost(n) for n in (1, 2, 133)] == [1.0, 2.0, 133.0]


@pytest.mark.parametrize("name", NUMERIC_MODELS)
def test_numeric_cost_is_seeding_plus_following(name: str) -> None:
    family = get_robot(name).family
    assert family is not None
    lines = COST_LINES[min(family.dof, 7)]
    assert family.path_cost(1) == max(seed for seed, _ in lines)
    assert family.path_cost(133) == max(seed + 132 * track for seed, track in lines)
    assert family.path_cost(133) > 50 * 133  # far above a closed-form path
