"""OPW arms over REST: catalogue and user-defined arms, branches, map, optimise, bad input."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.spatial.transform import Rotation

from solver.core.kinematics import tool_pose_in_base
from solver.families import get_robot
from tests.cases import EXAMPLES, MAP_EVALUATE_RTOL
from tests.service.test_errors import assert_names

KR6 = "kuka_kr6_r700_sixx"
PLACEMENT = {"x": 0.45, "y": 0.0, "z": 0.1, "yaw": 0.0}


@pytest.fixture(scope="module")
def path() -> dict[str, Any]:
    return json.loads((EXAMPLES / "paths" / "curved_line.json").read_text())


def kr6_as_user_arm() -> dict[str, Any]:
    """The catalogue's KR6 R700 sixx written out as a request's own OPW arm."""
    robot = get_robot(KR6)
    p = robot.family.parameters
    return {
        "opw": {
            "a1": p.a1,
            "a2": p.a2,
            "b": p.b,
            "c1": p.c1,
            "c2": p.c2,
            "c3": p.c3,
            "c4": p.c4,
            "offsets": list(p.offsets),
            "sign_corrections": list(p.sign_corrections),
        },
        "joint_position_limits": np.column_stack([robot.q_lower, robot.q_upper]).tolist(),
        "joint_velocity_limits": robot.qdot_max.tolist(),
    }


def test_catalogue_and_user_arm_agree(client: TestClient, path: dict[str, Any]) -> None:
    body = {"robot": {"model": KR6}, "path": path, "placement": PLACEMENT}
    catalogue = client.post("/v1/evaluate", json=body).json()
    user = client.post("/v1/evaluate", json={**body, "robot": kr6_as_user_arm()}).json()
    assert catalogue["feasible"] and user["feasible"]
    assert user["mu_path"] == pytest.approx(catalogue["mu_path"], rel=1e-12)
    assert catalogue["branch"]["shoulder"] in ("front", "back")
    named = client.post("/v1/evaluate", json={**body, "ik": {"branch": catalogue["branch"]}})
    assert named.json()["mu_path"] == catalogue["mu_path"]


def test_ur_branch_name_on_an_opw_arm_lists_the_valid_ones(
    client: TestClient, path: dict[str, Any]
) -> None:
    branch = {"shoulder": "left", "elbow": "up", "wrist": "noflip"}
    body = {"robot": {"model": KR6}, "path": path, "placement": PLACEMENT, "ik": {"branch": branch}}
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", "ik", "branch"])
    assert "{shoulder=back, elbow=down, wrist=flip}" in response.json()["detail"][0]["msg"]


def test_wrist_singularity_is_an_answer(client: TestClient) -> None:
    """A path with q5 = 0 all along, on its own branch: singular at waypoint 0, a 200."""
    robot = get_robot(KR6)
    waypoints = []
    seed = np.array([0.0, -1.2, 1.4, 0.3, 0.0, 0.2])
    pose = tool_pose_in_base(robot, seed)
    solutions, _ = robot.family.solve(pose[:3, :3, None], pose[:3, 3, None])
    arm = np.max(np.abs(solutions[:3, :, 0].T - seed[:3]), axis=1) < 1e-9
    branch = robot.family.branches[int(np.flatnonzero(arm)[0])].as_dict()
    for t in np.linspace(0.0, 0.2, 5):
        pose = tool_pose_in_base(robot, seed + [t, 0, 0, 0, 0, 0])
        quaternion = Rotation.from_matrix(pose[:3, :3]).as_quat()
        waypoints.append({"position": pose[:3, 3].tolist(), "orientation": quaternion.tolist()})
    body = {
        "robot": {"model": KR6},
        "path": {"waypoints": waypoints},
        "placement": {"x": 0.0, "y": 0.0, "z": 0.0, "yaw": 0.0},
        "ik": {"branch": branch, "max_joint_step": 1.0},
    }
    answer = client.post("/v1/evaluate", json=body)
    assert answer.status_code == 200, answer.text
    assert (answer.json()["reason"], answer.json()["failed_waypoint"]) == ("singular", 0)


def test_map_and_optimize(client: TestClient, path: dict[str, Any]) -> None:
    grid = {
        "x": {"min": 0.35, "max": 0.55, "step": 0.1},
        "y": {"min": -0.1, "max": 0.1, "step": 0.1},
        "z": 0.1,
        "yaw": [0.0, 1.0],
    }
    answer = client.post("/v1/map", json={"robot": {"model": KR6}, "path": path, "grid": grid})
    assert answer.status_code == 200, answer.text
    cells = answer.json()["cells"]
    assert len(cells) == 18 and answer.json()["feasible_cells"] > 0
    for cell in cells[:4]:
        placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"]}
        expected = client.post(
            "/v1/evaluate", json={"robot": {"model": KR6}, "path": path, "placement": placement}
        ).json()
        if expected["feasible"]:
            assert cell["mu_path"] == pytest.approx(expected["mu_path"], rel=MAP_EVALUATE_RTOL)
        else:
            assert cell["reason"] == expected["reason"]
    bounds = {"x": [0.4, 0.5], "y": [-0.05, 0.05], "yaw": [-0.5, 0.5]}
    body = {"robot": kr6_as_user_arm(), "path": path, "bounds": bounds, "z": 0.1}
    optimum = client.post("/v1/optimize", json=body).json()
    assert optimum["found"] and optimum["mu_path"] >= optimum["start"]["mu_path"]


def _opw(**change: Any) -> dict[str, Any]:
    robot = kr6_as_user_arm()
    robot["opw"].update(change)
    return robot


BAD_ARMS = [
    ("c2 zero", _opw(c2=0.0), ["robot", "opw", "c2"]),
    ("c3 negative", _opw(c3=-0.3), ["robot", "opw", "c3"]),
    ("length beyond 100 m", _opw(a1=150.0), ["robot", "opw", "a1"]),
    ("five offsets", _opw(offsets=[0.0] * 5), ["robot", "opw", "offsets"]),
    ("sign 0.5", _opw(sign_corrections=[1, 1, 1, 1, 1, 0.5]), ["robot", "opw", "sign_corrections"]),
    ("sign 2", _opw(sign_corrections=[1, 1, 1, 1, 1, 2]), ["robot", "opw", "sign_corrections"]),
    (
        "limits reversed",
        {**kr6_as_user_arm(), "joint_position_limits": [[-3.0, 3.0]] * 5 + [[1.0, -1.0]]},
        ["robot", "joint_position_limits"],
    ),
    (
        "five limit pairs",
        {**kr6_as_user_arm(), "joint_position_limits": [[-3.0, 3.0]] * 5},
        ["robot", "joint_position_limits"],
    ),
    (
        "no position limits",
        {k: v for k, v in kr6_as_user_arm().items() if k != "joint_position_limits"},
        ["robot"],
    ),
    ("opw and model", {**kr6_as_user_arm(), "model": KR6}, ["robot"]),
]


@pytest.mark.parametrize(("robot", "loc"), [c[1:] for c in BAD_ARMS], ids=[c[0] for c in BAD_ARMS])
def test_bad_user_arm_names_the_field(
    client: TestClient, path: dict[str, Any], robot: dict[str, Any], loc: list[Any]
) -> None:
    body = {"robot": robot, "path": path, "placement": PLACEMENT}
    assert_names(client.post("/v1/evaluate", json=body), 422, ["body", *loc])


def test_dtf_on_an_opw_arm(client: TestClient) -> None:
    body = {
        "robot": {"model": "fanuc_m20ia"},
        "q": [0.2, 0.3, -0.4, 0.5, 0.6, 0.7],
        "u_T": [1.0, 0.0, 0.0],
        "u_R": [0.0, 0.0, 1.0],
        "h": 0.5,
    }
    answer = client.post("/v1/dtf", json=body).json()
    assert answer["method"] == "closed_form" and answer["v_max"] > 0
    assert max(
        abs(v) / m for v, m in zip(answer["qdot"], get_robot("fanuc_m20ia").qdot_max, strict=True)
    ) == pytest.approx(1.0, rel=1e-12)
    assert math.isfinite(answer["omega_max"])


def test_the_lp_of_an_arm_of_hundreds_of_metres_is_answered(client: TestClient) -> None:
    # The contract test's case (stop 63): an OPW arm of hundreds of metres with speed limits of
    # thousands of rad/s, the LP asked for: J times the limits spans 4e3 to 6e6 a row, and
    # HiGHS stopped without proving its answer (RuntimeError, a 500). Rows and s are scaled now.
    body = {
        "h": None,
        "robot": {
            "joint_velocity_limits": [
                7745.001146803348,
                5970.242942909562,
                5442.392486786082,
                7609.0512262792545,
                6527.931929964032,
                1094.124756067725,
            ],
            "opw": {
                "a2": -2.00001,
                "a1": 34.26244237711285,
                "sign_corrections": [-1, -1, 1, -1, -1, -1],
                "c2": 69.86701692529121,
                "c4": -57.243484255191646,
                "offsets": [
                    -2.6853948407507237e-288,
                    -0.3333333333333333,
                    237.6407492482399,
                    -2.2250738585e-313,
                    3.532225612617526e-111,
                    754.97924833105,
                ],
                "c1": -12.679311543250392,
                "c3": 1.1754943508222875e-38,
                "b": -49.90304627927918,
            },
            "tcp": {
                "orientation": [
                    -0.9661985494144,
                    1.0618976554111744e-227,
                    -0.25779907507496824,
                    8.90312684744586e-218,
                ],
                "position": [1.302015, -661.4113262784862, 610.0530783044462],
            },
            "joint_position_limits": [
                [-467.6717315462947, 1.192092896e-07],
                [-1.347854691030735e-245, 796.4831141009593],
                [-977.3966368704898, -197.10771297553117],
                [-446.6612180158894, 707.3327966653028],
                [-2.225073858507e-311, 439.3019225305916],
                [-253.65591304715792, 939.1384091828363],
            ],
        },
        "u_R": None,
        "u_T": [1.0, 0.0, 0.0],
        "method": "lp",
        "q": [
            1.192092896e-07,
            796.4831141009593,
            -197.10771297553117,
            -1.0742289508517208e-54,
            -2.225073858507e-311,
            939.1384091828363,
        ],
    }
    response = client.post("/v1/dtf", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["method"] == "lp" and answer["v_max"] >= 0.0
    limits = body["robot"]["joint_velocity_limits"]
    assert all(abs(v) <= m * (1 + 1e-9) for v, m in zip(answer["qdot"], limits, strict=True))
