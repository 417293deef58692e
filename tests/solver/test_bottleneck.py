"""The bottleneck waypoint: ties in the last bits go to the earlier waypoint, alike everywhere.

A CAM program that cuts the same contour on several levels limits its feed at the same corner
on each (joint 1 turns alike whatever the depth): V_max ties there to the last bits, and a
map's kernel and the evaluator, which round apart in the last bit, named different levels'
corners for one placement (14 of 117 cells of a 2,500-move pocket program, before
solver.path.bottleneck).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from solver.cam.cl_data import read_cl_data
from solver.core.robots import Robot, example_robot_data_dir
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric.family import NumericFamily
from solver.path.bottleneck import bottleneck_waypoints
from solver.path.capability_map import capability_map
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem


@pytest.mark.parametrize(
    ("v_max", "expected"),
    [
        ([2.0, 1.0, 3.0, 1.0 - 1e-15, 5.0], 1),  # a tie in the last bits: the earlier
        ([2.0, 1.0 + 1e-15, 3.0, 1.0, 5.0], 1),  # the earlier even a bit above
        ([2.0, 1.0, 3.0, 1.0 - 2e-12, 5.0], 3),  # more than 1e-12 below: the later
        ([1.0, 1.0, 1.0], 0),
        ([3.0, 2.0, 1.0], 2),
        ([3.0, math.nan, 2.0], 2),  # NaN is never the least
        ([math.nan, 2.0, 1.0], 0),  # as the kernels: the first waypoint's NaN stays
        ([math.inf, 2.0], 1),
        ([5.0], 0),
    ],
)
def test_the_earlier_of_a_tie_is_the_bottleneck(v_max: list[float], expected: int) -> None:
    assert int(bottleneck_waypoints(np.array(v_max))) == expected


def test_rows_each_have_their_bottleneck() -> None:
    rows = np.array([[2.0, 1.0, 1.0 - 1e-15], [2.0, 1.0, 0.5], [1.0, 2.0, 3.0]])
    assert bottleneck_waypoints(rows).tolist() == [1, 2, 0]


def _levels_program(levels: int = 3) -> str:
    """A 40 mm square with 3 mm corner arcs (chords within 0.01 mm) cut on ``levels`` levels."""
    radius, half, centre = 3.0, 20.0, 60.0
    count = math.ceil((math.pi / 2) / (2.0 * math.acos(1.0 - 0.01 / radius)))
    inner = half - radius
    contour = []
    for k, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        cx, cy = centre + sx * inner, centre + sy * inner
        start = k * math.pi / 2
        contour += [
            (cx + radius * math.cos(start + i * math.pi / 2 / count),
             cy + radius * math.sin(start + i * math.pi / 2 / count))
            for i in range(count + 1)
        ]  # fmt: skip
    lines = ["UNITS/MM", "FEDRAT/MMPM,1000"]
    for level in range(levels):
        z = -5.0 * level
        lines.append(f"GOTO/{contour[0][0]:.4f},{contour[0][1]:.4f},{z + 10:.4f},0,0,1")
        lines.append("RAPID")
        lines += [f"GOTO/{x:.4f},{y:.4f},{z:.4f},0,0,1" for x, y in contour]
    return "\n".join(lines)


def _numeric_ur5() -> Robot:
    """The UR5 from its URDF on the numeric family (not the closed form it is recognised as)."""
    urdf = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    numeric = NumericFamily(
        pin.buildModelFromXML(urdf), base_frame="base_link", tool_frame="ee_link"
    )
    return robot_from_urdf(urdf, base_frame="base_link", tool_frame="ee_link", family=numeric)


@pytest.mark.parametrize(
    ("robot_name", "spin_mode"),
    [("ur5e", "free"), ("ur5e", "fixed"), ("numeric ur5", "fixed")],
)
def test_a_map_cell_and_its_evaluation_name_the_same_bottleneck(
    robot_name: str, spin_mode: str
) -> None:
    """The same corner on three levels: every feasible cell names the waypoint the evaluation
    of its placement names, the earliest of the tie (the map kernels of the closed forms; the
    numeric family's pipeline)."""
    program = read_cl_data(_levels_program())
    problem = PathProblem.of(
        _numeric_ur5() if robot_name == "numeric ur5" else get_robot(robot_name),
        program.waypoints_in_workpiece(),
        PathOptions(spin_mode=spin_mode),
        passes=program.passes,
    )
    xs, ys = np.arange(-0.4, 0.201, 0.05).round(10), np.arange(0.2, 0.601, 0.05).round(10)
    cmap = capability_map(problem, xs=xs, ys=ys, z=0.0, yaws=np.array([0.0]))
    feasible = [i for i in np.ndindex(cmap.mu_path.shape) if np.isfinite(cmap.mu_path[i])]
    assert len(feasible) > 50
    tied = 0
    for index in feasible:
        evaluation = evaluate_path(problem, cmap.placement(index))
        assert evaluation.bottleneck_waypoint == cmap.bottleneck_waypoint[index], index
        v, mu = evaluation.v_max, evaluation.mu_path
        assert mu is not None and v is not None
        ties = np.flatnonzero(v <= mu * (1 + 1e-12))
        assert evaluation.bottleneck_waypoint == ties[0]
        tied += len(ties) > 1
    assert tied >= 20  # the premise: cells whose V_max ties on several levels
