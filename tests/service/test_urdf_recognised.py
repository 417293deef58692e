"""A URDF that is an OPW arm gets the closed form (issue 27): the FANUC M10iA on a fan path.

Zhang et al. (IJMS 2021) run a fan-shaped 5-axis path on a FANUC M10iA; with numeric IK from 32
Sobol seeds its URDF lost branches and answered ``discontinuous`` where the arm from its OPW
parameters is feasible. Here the URDF is written in the test from the arm's OPW parameters
(ros-industrial/fanuc fanuc_m10ia_support: config/opw_parameters_m10ia.yaml, and the joint
limits and speeds of urdf/m10ia_macro.xacro), the path is a fan of our own with the same
character (25 points, the tool axis tilting 10 to 40 degrees off the normal), and the answers
must be the same: same mu_path, same branch, and the answer says the URDF was recognised.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from solver.cam.csv_path import read_csv_path
from solver.core.robots import chain_from_urdf
from solver.core.spatial import Placement
from solver.core.tool_axis import poses_from_tool_axes
from solver.families import robot_from_urdf
from solver.families.numeric.family import NumericFamily
from solver.families.opw.parameters import OpwParameters
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.cases import MAP_EVALUATE_RTOL
from tests.solver.families.opw_urdf import opw_urdf

M10IA = OpwParameters(
    0.15, -0.20, 0.0, 0.45, 0.60, 0.64, 0.10,
    offsets=(0.0, 0.0, -math.pi / 2, 0.0, 0.0, math.pi),
    sign_corrections=(1, 1, -1, -1, -1, -1),
)  # fmt: skip
M10IA_LIMITS = [[-3.14, 3.14], [-1.57, 2.79], [-3.14, 4.61], [-3.31, 3.31], [-3.31, 3.31],
                [-6.28, 6.28]]  # fmt: skip
M10IA_SPEEDS = [3.67, 3.32, 3.67, 6.98, 6.98, 10.47]
PLACEMENT = {"x": 0.9, "y": -0.2, "z": 0.3, "yaw": math.pi}


def fan_csv(n: int = 25) -> str:
    """A fan-shaped 5-axis path (mm): an arc of 250 degrees, its tool axis leaning outwards."""
    t = np.linspace(0.0, 1.0, n)
    phi = math.radians(80.0) - math.radians(250.0) * t
    radius = 90.0 + 25.0 * np.cos(2 * math.pi * t)
    points = np.column_stack(
        [10 + radius * np.cos(phi), -50 + radius * np.sin(phi), 5.0 * np.sin(3 * math.pi * t)]
    )
    tilt = np.radians(10.0 + 30.0 * np.sin(math.pi * t))
    axes = np.column_stack([np.sin(tilt) * np.cos(phi), np.sin(tilt) * np.sin(phi), np.cos(tilt)])
    rows = [",".join(f"{v:.4f}" for v in (*p, *a)) for p, a in zip(points, axes, strict=True)]
    return "x,y,z,i,j,k\n" + "\n".join(rows) + "\n"


def evaluate(client: TestClient, robot: dict[str, Any]) -> dict[str, Any]:
    body = {"robot": robot, "path": {"csv": fan_csv(), "units": "mm"}, "placement": PLACEMENT}
    response = client.post("/v1/evaluate", json=body)
    assert response.status_code == 200, response.text
    answer: dict[str, Any] = response.json()
    return answer


def test_the_m10ia_urdf_answers_as_its_opw_parameters(client: TestClient) -> None:
    p = M10IA
    opw = {
        "opw": {k: getattr(p, k) for k in ("a1", "a2", "b", "c1", "c2", "c3", "c4")}
        | {"offsets": list(p.offsets), "sign_corrections": list(p.sign_corrections)},
        "joint_position_limits": M10IA_LIMITS,
        "joint_velocity_limits": M10IA_SPEEDS,
    }
    urdf = opw_urdf(
        M10IA,
        limits=np.array(M10IA_LIMITS),
        speeds=np.array(M10IA_SPEEDS),
        joint_names=tuple(f"joint_{i}" for i in range(1, 7)),
    )
    robot = {"urdf": urdf, "base_frame": "base_link", "tool_frame": "tool0"}
    expected, answer = evaluate(client, opw), evaluate(client, robot)
    assert expected["feasible"], expected
    assert answer["mu_path"] == pytest.approx(expected["mu_path"], rel=MAP_EVALUATE_RTOL)
    assert answer["branch"] == expected["branch"]
    assert answer["ik"]["family"] == "opw" and "OPW arm" in answer["ik"]["recognised"]
    assert expected["ik"]["recognised"] is None
    axis = {"min": -0.2, "max": -0.2, "step": 0.1}
    grid = {"x": {"min": 0.85, "max": 0.95, "step": 0.05}, "y": axis, "z": 0.3, "yaw": [math.pi]}
    body = {"robot": robot, "path": {"csv": fan_csv(), "units": "mm"}, "grid": grid}
    response = client.post("/v1/map", json=body)
    assert response.status_code == 200, response.text
    assert "OPW arm" in response.json()["recognised"]


def test_numeric_ik_from_the_covering_seeds_finds_the_opw_answer_too() -> None:
    """The same URDF with the numeric family forced: its seeds find the branch the closed form
    takes, and the same mu_path (32 Sobol seeds lost it on the published path)."""
    urdf = opw_urdf(
        M10IA,
        limits=np.array(M10IA_LIMITS),
        speeds=np.array(M10IA_SPEEDS),
        joint_names=tuple(f"joint_{i}" for i in range(1, 7)),
    )
    chain = chain_from_urdf(urdf, tool_frame="tool0")
    frames = {"base_frame": "base_link", "tool_frame": "tool0"}
    cam = read_csv_path(fan_csv(), units="mm")
    assert cam.axes is not None
    poses, _ = poses_from_tool_axes(cam.positions, cam.axes)
    placement = Placement(**PLACEMENT)
    answers = [
        evaluate_path(PathProblem.of(robot, poses, PathOptions()), placement)
        for robot in (
            robot_from_urdf(urdf, **frames),
            robot_from_urdf(urdf, **frames, family=NumericFamily(chain, **frames)),
        )
    ]
    analytic, numeric = answers
    assert analytic.feasible and numeric.feasible
    assert numeric.mu_path == pytest.approx(analytic.mu_path, rel=1e-9)
    assert numeric.ik_branches_found is not None and numeric.ik_branches_found >= 4
