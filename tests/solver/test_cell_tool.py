"""cell.md section 1: the tool runs along tool z from the flange to the tool point.

The cylinder is laid back ``length`` from the tool point, so the two statements are one only
when the TCP puts the tool point ``length`` out. With the TCP left at the flange the cell audit
(stop 53) found a 12 cm spindle inside the wrist and a box 6 cm in front of the flange, inside
the real spindle, 'clear by 49 mm'. Such a tool is refused, naming the length that fits.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from solver.core.exceptions import InvalidInputError
from solver.families import get_robot
from solver.path.cell.checker import CellChecker
from solver.path.cell.shapes import Box, Cell, Tool

SPINDLE = Tool(radius=0.03, length=0.12)


def _at(x: float, y: float, z: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = [x, y, z]
    return pose


def test_a_tool_behind_the_flange_is_refused() -> None:
    for tcp, behind in ((np.eye(4), "120.0 mm"), (_at(0.0, 0.0, 0.05), "70.0 mm")):
        robot = get_robot("ur5").with_options(transform_tool_to_tcp=tcp)
        with pytest.raises(InvalidInputError) as refused:
            CellChecker(robot, Cell(tool=SPINDLE))
        assert refused.value.field == "cell.tool.length"
        assert f"{behind} behind the flange" in str(refused.value)
    CellChecker(
        get_robot("ur5").with_options(transform_tool_to_tcp=_at(0, 0, 0.12)), Cell(tool=SPINDLE)
    )
    # an angled spindle: tool z across the flange's, the whole tool in front of it
    angled = _at(0.1, 0.0, 0.08)
    angled[:3, :3] = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
    CellChecker(get_robot("ur5").with_options(transform_tool_to_tcp=angled), Cell(tool=SPINDLE))


def test_the_spindle_runs_from_the_flange() -> None:
    """A box 6 cm in front of the flange along tool z is in the spindle: the tool hits it."""
    robot = get_robot("ur5").with_options(transform_tool_to_tcp=_at(0.0, 0.0, 0.12))
    q = np.array([0.3, -1.4, 1.6, -1.8, -1.5, 0.2])
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    flange = data.oMf[robot.model.getFrameId(robot.tool_frame)]
    inside = flange.act(np.array([0.0, 0.0, 0.06]))  # in the model's root frame
    in_base = np.linalg.solve(robot.transform_world_to_base, [*inside, 1.0])[:3]  # {B}
    box = Box((0.01, 0.01, 0.01), _at(*in_base), name="box")
    checker = CellChecker(robot, Cell(fixed=(box,), tool=SPINDLE))
    verdict = checker.check(q[None], np.zeros(0, dtype=bool), np.eye(4), closest=True)
    assert verdict.collision is not None
    assert verdict.collision.robot_part == "tool" and verdict.collision.obstacle_name == "box"


def test_a_tool_turned_back_at_the_flange_is_refused() -> None:
    """A tcp turned over (tool z at the arm) laid the tool beyond its point, away from the arm:
    even a 0.5 m tool was 'feasible' (the contract audit, stop 54)."""
    over = _at(0.0, 0.0, 0.12)
    over[:3, :3] = np.diag([1.0, -1.0, -1.0])  # a half turn about x
    robot = get_robot("ur5").with_options(transform_tool_to_tcp=over)
    with pytest.raises(InvalidInputError, match="turns back at the flange") as refused:
        CellChecker(robot, Cell(tool=SPINDLE))
    assert refused.value.field == "cell.tool.length"
