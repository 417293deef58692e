from __future__ import annotations

import json
import math
from typing import Any

import pytest
from fastapi.testclient import TestClient

from tests.cases import EXAMPLES

PER_WAYPOINT_IF_FEASIBLE = ("q", "v_max", "omega_max", "qdot", "limiting_joint")


def post(client: TestClient, body: dict[str, Any]) -> dict[str, Any]:
    response = client.post("/v1/evaluate", json=body)
    assert response.status_code == 200, response.text
    result: dict[str, Any] = response.json()
    return result


def test_example_request_is_feasible_and_consistent(client: TestClient) -> None:
    body = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    result = post(client, body)
    assert result["feasible"] is True
    assert result["reason"] is None and result["failed_waypoint"] is None
    waypoints = result["waypoints"]
    assert [w["index"] for w in waypoints] == list(range(len(body["path"]["waypoints"])))
    speeds = [w["v_max"] for w in waypoints]
    assert result["mu_path"] == min(speeds)
    bottleneck = result["bottleneck"]
    assert bottleneck["waypoint"] == speeds.index(min(speeds))
    slowest = waypoints[bottleneck["waypoint"]]
    assert bottleneck["joint"] == slowest["limiting_joint"]
    assert bottleneck["joint_name"] == slowest["limiting_joint_name"]
    for waypoint in waypoints:
        assert waypoint["omega_max"] == pytest.approx(waypoint["v_max"] / waypoint["h"], rel=1e-9)


def test_named_branch_is_followed_and_echoed(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    auto = post(client, evaluate_body)
    evaluate_body["ik"]["branch"] = auto["branch"]
    named = post(client, evaluate_body)
    assert named["branch"] == auto["branch"]
    assert named["mu_path"] == auto["mu_path"]


def test_unreachable_placement_is_an_answer_not_an_error(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    evaluate_body["placement"]["x"] = 5.0
    result = post(client, evaluate_body)
    assert result["feasible"] is False
    assert result["reason"] == "unreachable"
    assert result["failed_waypoint"] == 0
    assert result["mu_path"] is None and result["bottleneck"] is None
    for waypoint in result["waypoints"]:
        assert all(waypoint[key] is None for key in PER_WAYPOINT_IF_FEASIBLE)
        assert len(waypoint["u_T"]) == 3 and len(waypoint["u_R"]) == 3


def test_pure_translation_has_null_h(client: TestClient, evaluate_body: dict[str, Any]) -> None:
    first, second = evaluate_body["path"]["waypoints"]
    second["orientation"] = first["orientation"]
    result = post(client, evaluate_body)
    assert result["feasible"] is True
    assert all(w["h"] is None and w["omega_max"] == 0 for w in result["waypoints"])
    assert all(w["u_R"] == [0.0, 0.0, 0.0] for w in result["waypoints"])


def _turned_about_z(quaternion: list[float], angle: float) -> list[float]:
    """``quaternion`` (x, y, z, w) turned by ``angle`` about its own z axis (q * (0, 0, s, c))."""
    x, y, z, w = quaternion
    s, c = math.sin(angle / 2), math.cos(angle / 2)
    return [x * c + y * s, y * c - x * s, z * c + w * s, w * c - z * s]


def test_spins_that_undo_a_segment_are_named_not_the_path(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    """A segment that only spins the tool by 0.1 rad, given spins 0 and -0.1: the spun poses
    repeat, and the 422 named path.waypoints[1] of a path valid as sent (audit 23). A path that
    repeats itself is still named."""
    first = evaluate_body["path"]["waypoints"][0]
    turned = {
        "position": first["position"],
        "orientation": _turned_about_z(first["orientation"], 0.1),
    }
    body = {**evaluate_body, "path": {"waypoints": [first, turned]}}
    assert client.post("/v1/evaluate", json=body).status_code == 200
    refused = client.post("/v1/evaluate", json={**body, "spins": [0.0, -0.1]})
    assert refused.status_code == 422
    (detail,) = refused.json()["detail"]
    assert (
        detail["loc"] == ["body", "spins", 1] and "waypoint 1 repeats waypoint 0" in detail["msg"]
    )
    repeated = {**evaluate_body, "path": {"waypoints": [first, first]}, "spins": [0.0, 0.0]}
    (detail,) = client.post("/v1/evaluate", json=repeated).json()["detail"]
    assert detail["loc"] == ["body", "path", "waypoints", 1]
