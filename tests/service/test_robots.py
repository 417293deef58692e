from __future__ import annotations

import math

import pytest
from fastapi.testclient import TestClient

from tests.cases import NUMERIC_MODELS, OPW_MODELS, UR_MODELS


def test_healthz(client: TestClient) -> None:
    response = client.get("/healthz")
    assert response.status_code == 200
    assert response.json() == {"status": "ok", "jobs": "ok"}


def test_robots_lists_every_ur_and_opw_model(client: TestClient) -> None:
    response = client.get("/v1/robots")
    assert response.status_code == 200
    robots = {robot["name"]: robot for robot in response.json()["robots"]}
    assert sorted(robots) == sorted(UR_MODELS + OPW_MODELS + NUMERIC_MODELS)
    for robot in (robots[name] for name in UR_MODELS + OPW_MODELS):
        assert robot["dof"] == 6
        for key in ("joint_names", "q_lower", "q_upper", "qdot_max"):
            assert len(robot[key]) == 6, key
        assert all(low < high for low, high in zip(robot["q_lower"], robot["q_upper"], strict=True))
        assert all(limit > 0 for limit in robot["qdot_max"])
        ur = robot["name"] in UR_MODELS
        assert robot["family"] == ("ur" if ur else "opw")
        assert (robot["base_frame"], robot["tool_frame"]) == (
            "base" if ur else "base_link",
            "tool0",
        )
        assert robot["branches"] == [
            {"level": "shoulder", "choices": ["left", "right"] if ur else ["front", "back"]},
            {"level": "elbow", "choices": ["up", "down"]},
            {"level": "wrist", "choices": ["noflip", "flip"]},
        ]


@pytest.mark.parametrize(("name", "dof"), [("panda", 7), ("xarm7", 7), ("kinova_jaco2", 6)])
def test_robots_lists_the_numeric_arms(client: TestClient, name: str, dof: int) -> None:
    robot = {robot["name"]: robot for robot in client.get("/v1/robots").json()["robots"]}[name]
    assert robot["family"] == "numeric"
    assert robot["dof"] == dof
    for key in ("joint_names", "q_lower", "q_upper", "qdot_max"):
        assert len(robot[key]) == dof, key
    seeds = 32 if dof == 6 else 64
    assert robot["branches"] == [{"level": "solution", "choices": [str(k) for k in range(seeds)]}]


def test_robots_velocity_limits_are_the_datasheet_ones(client: TestClient) -> None:
    robots = {robot["name"]: robot for robot in client.get("/v1/robots").json()["robots"]}
    assert robots["ur5e"]["qdot_max"] == [math.pi] * 6
    assert robots["ur10e"]["qdot_max"] == [2 * math.pi / 3] * 2 + [math.pi] * 4


def test_opw_limits_are_the_support_packages(client: TestClient) -> None:
    """Two rows checked by hand against the xacro files (KR6 R700 sixx, IRB 2400)."""
    robots = {robot["name"]: robot for robot in client.get("/v1/robots").json()["robots"]}
    kr6 = robots["kuka_kr6_r700_sixx"]
    assert kr6["joint_names"] == [f"joint_a{i}" for i in range(1, 7)]
    assert kr6["qdot_max"] == [math.radians(v) for v in (360, 300, 360, 381, 388, 615)]
    assert kr6["q_lower"][1] == math.radians(-190) and kr6["q_upper"][1] == math.radians(45)
    assert robots["abb_irb2400"]["qdot_max"] == [2.618, 2.618, 2.618, 6.2832, 6.2832, 7.854]
