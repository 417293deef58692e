from __future__ import annotations

import math

from fastapi.testclient import TestClient

from tests.cases import UR_MODELS


def test_healthz(client: TestClient) -> None:
    response = client.get("/healthz")
    assert response.status_code == 200
    assert response.json() == {"status": "ok"}


def test_robots_lists_every_ur_model(client: TestClient) -> None:
    response = client.get("/v1/robots")
    assert response.status_code == 200
    robots = {robot["name"]: robot for robot in response.json()["robots"]}
    assert sorted(robots) == sorted(UR_MODELS)
    for robot in robots.values():
        assert robot["dof"] == 6
        for key in ("joint_names", "q_lower", "q_upper", "qdot_max"):
            assert len(robot[key]) == 6, key
        assert all(low < high for low, high in zip(robot["q_lower"], robot["q_upper"], strict=True))
        assert all(limit > 0 for limit in robot["qdot_max"])
        assert (robot["base_frame"], robot["tool_frame"]) == ("base", "tool0")


def test_robots_velocity_limits_are_the_datasheet_ones(client: TestClient) -> None:
    robots = {robot["name"]: robot for robot in client.get("/v1/robots").json()["robots"]}
    assert robots["ur5e"]["qdot_max"] == [math.pi] * 6
    assert robots["ur10e"]["qdot_max"] == [2 * math.pi / 3] * 2 + [math.pi] * 4
