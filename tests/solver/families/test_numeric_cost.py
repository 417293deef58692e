"""The families' cost weights, the unit of the service's size limits (robots.md section 4)."""

from __future__ import annotations

import pytest

import solver.core.dtf_redundant as redundant_module
from solver.core.dtf import lp_speed
from solver.core.robots import example_robot_data_dir
from solver.core.spatial import Placement
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric.costs import COST_LINES, GENERAL_LP_COST
from tests.cases import NUMERIC_MODELS, OPW_MODELS, UR_MODELS
from tests.problems import evaluate_path
from tests.solver.test_evaluate import load_path


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


def _ur5_with_two_more_joints() -> str:
    """The UR5's URDF with two revolute joints after tool0: an arm of eight joints."""
    ur5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    extra = (
        '<link name="extra_1"/><link name="extra_2"/>'
        '<joint name="extra_joint_1" type="revolute"><parent link="tool0"/>'
        '<child link="extra_1"/><origin xyz="0 0 0.05" rpy="0 0 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-3" upper="3" effort="1" velocity="3"/></joint>'
        '<joint name="extra_joint_2" type="revolute"><parent link="extra_1"/>'
        '<child link="extra_2"/><origin xyz="0 0 0.05" rpy="0 0 0"/><axis xyz="1 0 0"/>'
        '<limit lower="-3" upper="3" effort="1" velocity="3"/></joint>'
    )
    return ur5.replace("</robot>", extra + "</robot>")


def test_an_eight_joint_arms_estimate_covers_its_lps(monkeypatch: pytest.MonkeyPatch) -> None:
    """Beyond seven joints every slot's V_max is a general LP (1.2 ms each): the estimate weighs
    them.

    It was the seven-joint line scaled by (dof / 7)^2: a 20-joint evaluation the limit
    admitted ran 286 s (the robots audit of stop 55).
    """
    robot = robot_from_urdf(_ur5_with_two_more_joints(), base_frame="base", tool_frame="extra_2")
    assert robot.dof == 8 and robot.family is not None
    calls = []

    def counted(*args: object, **kwargs: object) -> object:
        calls.append(1)
        return lp_speed(*args, **kwargs)

    monkeypatch.setattr(redundant_module, "lp_speed", counted)
    path = load_path("curved_line")[:10]
    answer = evaluate_path(robot, path, Placement(0.0, 0.45, 0.1, 0.0))
    assert answer.ik_branches_found is not None and answer.ik_branches_found > 1
    assert len(calls) >= answer.ik_branches_found * len(path)  # every slot, every waypoint
    assert robot.family.path_cost(len(path)) >= len(calls) * GENERAL_LP_COST
