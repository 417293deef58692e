"""POST /v1/optimize: the answer is the evaluator's, with the start and the improvement."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest
from fastapi.testclient import TestClient

from solver.optimise.local_search import CLIMB_STATUS
from tests.cases import EXAMPLES, OPTIMUM_EVALUATE_RTOL
from tests.service.conftest import sent_back


@pytest.fixture(scope="module")
def body() -> dict[str, Any]:
    path = json.loads((EXAMPLES / "paths" / "curved_line.json").read_text())
    return {
        "robot": {"model": "ur5e"},
        "path": path,
        "bounds": {"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-math.pi, math.pi]},
        "z": 0.1,
    }


@pytest.fixture(scope="module")
def answer(client: TestClient, body: dict[str, Any]) -> dict[str, Any]:
    response = client.post("/v1/optimize", json=body)
    assert response.status_code == 200, response.text
    return response.json()


def test_answer_is_what_evaluate_says(
    client: TestClient, body: dict[str, Any], answer: dict[str, Any]
) -> None:
    assert answer["found"] is True
    placement = sent_back(answer["placement"])
    assert -0.25 <= placement["x"] <= 0.25 and 0.25 <= placement["y"] <= 0.65
    evaluate = {"robot": body["robot"], "path": body["path"], "placement": placement}
    evaluation = client.post("/v1/evaluate", json=evaluate).json()
    assert answer["mu_path"] == pytest.approx(evaluation["mu_path"], rel=OPTIMUM_EVALUATE_RTOL)
    assert answer["evaluation"]["mu_path"] == answer["mu_path"]
    # IPOPT's optimum, or a Nelder-Mead climb's where it is higher (here by about 1e-10: the
    # NLP's tolerance), never the start or a failed solve.
    assert answer["solver"]["status"] in {"Solve_Succeeded", CLIMB_STATUS}
    assert answer["solver"]["iterations"] > 0 and answer["solver"]["seconds"] > 0


@pytest.mark.parametrize("which", ["optimum", "start"])
def test_an_answers_placement_sent_back_as_it_is_is_accepted(
    client: TestClient, body: dict[str, Any], answer: dict[str, Any], which: str
) -> None:
    placement = answer["placement"] if which == "optimum" else answer["start"]["placement"]
    assert "frames" in placement  # as the answer carries it: frames are read-only input
    mu_path = answer["mu_path"] if which == "optimum" else answer["start"]["mu_path"]
    evaluate = {"robot": body["robot"], "path": body["path"], "placement": placement}
    response = client.post("/v1/evaluate", json=evaluate)
    assert response.status_code == 200, response.text
    assert response.json()["mu_path"] == pytest.approx(mu_path, rel=OPTIMUM_EVALUATE_RTOL)
    again = client.post("/v1/optimize", json={**body, "start": placement})
    assert again.status_code == 200, again.text


def test_frames_on_input_are_ignored_as_the_schema_says(
    client: TestClient, body: dict[str, Any], answer: dict[str, Any]
) -> None:
    placement = answer["placement"]
    moved = {**placement, "frames": {**placement["frames"], "ur": [9.0, 9.0, 9.0, 0, 0, 0]}}
    evaluate = {"robot": body["robot"], "path": body["path"]}
    original = client.post("/v1/evaluate", json={**evaluate, "placement": placement}).json()
    edited = client.post("/v1/evaluate", json={**evaluate, "placement": moved}).json()
    assert edited["mu_path"] == original["mu_path"]  # x, y, z, yaw, spin say where it is
    schema = client.get("/openapi.json").json()["components"]["schemas"]["Placement"]
    frames = schema["properties"]["frames"]
    assert frames["readOnly"] is True and "ignored on input" in frames["description"]


def test_start_and_improvement(answer: dict[str, Any]) -> None:
    start = answer["start"]
    assert sent_back(start["placement"]) == {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0, "spin": 0.0}
    expected = 100 * (answer["mu_path"] / start["mu_path"] - 1)
    assert answer["improvement_percent"] == pytest.approx(expected, rel=1e-12)
    assert answer["improvement_percent"] > 10


def test_scipy_method_on_a_short_path(client: TestClient, body: dict[str, Any]) -> None:
    short = {**body, "path": {"waypoints": body["path"]["waypoints"][:30]}, "method": "scipy"}
    answer = client.post("/v1/optimize", json=short).json()
    casadi = client.post("/v1/optimize", json={**short, "method": "casadi"}).json()
    assert answer["found"] and answer["solver"]["name"].startswith("differential_evolution")
    assert answer["mu_path"] == pytest.approx(casadi["mu_path"], rel=1e-5)


def test_nothing_feasible_is_not_an_error(client: TestClient, body: dict[str, Any]) -> None:
    far = {**body, "bounds": {"x": [3.0, 3.2], "y": [3.0, 3.2], "yaw": [0.0, 0.5]}}
    answer = client.post("/v1/optimize", json=far).json()
    assert answer["found"] is False and answer["placement"] is None
    assert answer["start"]["mu_path"] is None and answer["improvement_percent"] is None


@pytest.mark.parametrize(
    ("changes", "loc"),
    [
        ({"bounds": {"x": [0.3, 0.1], "y": [0.2, 0.5], "yaw": [0, 1]}}, ["body", "bounds", "x"]),
        ({"bounds": {"x": [0.1], "y": [0.2, 0.5], "yaw": [0, 1]}}, ["body", "bounds", "x"]),
        ({"start": {"x": 2.0, "y": 0.3, "z": 0.1, "yaw": 0.0}}, ["body", "start"]),
        ({"method": "newton"}, ["body", "method"]),
        ({"ik": {"max_joint_step": 0.0}}, ["body", "ik", "max_joint_step"]),
        (
            {"ik": {"branch": {"shoulder": "left", "elbow": "up", "wrist": "flip"}}},
            ["body", "ik"],
        ),
        ({"z": 5000.0}, ["body", "z"]),
        ({"bounds": {"x": [-900, 900], "y": [-900, 900], "yaw": [0, 1]}}, ["body", "bounds"]),
        (
            {"bounds": {"x": [0, 0.1], "y": [0.3, 0.5], "yaw": [0, 1], "spin": [-3.2, 3.2]}},
            ["body", "bounds", "spin"],
        ),
        (
            {"bounds": {"x": [0, 0.1], "y": [0.3, 0.5], "yaw": [0, 1], "spin": [1.0, 0.5]}},
            ["body", "bounds", "spin"],
        ),
        (
            {"start": {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0, "spin": 0.5}},
            ["body", "start"],
        ),
        ({"spin_mode": "free", "method": "newton"}, ["body", "method"]),
    ],
)
def test_bad_input(client: TestClient, body: dict[str, Any], changes: dict, loc: list) -> None:
    response = client.post("/v1/optimize", json={**body, **changes})
    assert response.status_code == 422, response.text
    assert response.json()["detail"][0]["loc"][: len(loc)] == loc


def test_spin_bounds_reach_the_answer(client: TestClient, body: dict[str, Any]) -> None:
    """A spin range is searched and the answer's placement carries its spin, inside the range."""
    bounds = {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3], "spin": [0.2, 0.6]}
    answer = client.post("/v1/optimize", json={**body, "bounds": bounds}).json()
    assert answer["found"] is True
    assert 0.2 <= answer["placement"]["spin"] <= 0.6
    assert answer["start"]["placement"]["spin"] == pytest.approx(0.4)
    evaluation = client.post(
        "/v1/evaluate",
        json={
            "robot": body["robot"],
            "path": body["path"],
            "placement": sent_back(answer["placement"]),
        },
    ).json()
    assert answer["mu_path"] == pytest.approx(evaluation["mu_path"], rel=OPTIMUM_EVALUATE_RTOL)


def test_spin_path_answers_spins_that_evaluate_confirms(
    client: TestClient, body: dict[str, Any]
) -> None:
    bounds = {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3]}
    request = {**body, "bounds": bounds, "spin_path": {"max_spin_step": 0.05}}
    answer = client.post("/v1/optimize", json=request).json()
    assert answer["found"] is True and len(answer["spins"]) == len(body["path"]["waypoints"])
    steps = [abs(b - a) for a, b in zip(answer["spins"], answer["spins"][1:], strict=False)]
    assert max(steps) <= 0.05
    evaluation = client.post(
        "/v1/evaluate",
        json={
            "robot": body["robot"],
            "path": body["path"],
            "placement": sent_back(answer["placement"]),
            "spins": answer["spins"],
        },
    ).json()
    assert answer["mu_path"] == pytest.approx(evaluation["mu_path"], rel=OPTIMUM_EVALUATE_RTOL)
    constant = client.post("/v1/optimize", json={**body, "bounds": bounds}).json()
    assert answer["mu_path"] >= constant["mu_path"]


@pytest.mark.parametrize(
    ("changes", "loc"),
    [
        ({"spin_path": {"max_spin_step": 0.0}}, ["body", "spin_path", "max_spin_step"]),
        ({"spin_path": {"max_spin_step": 0.1}, "method": "scipy"}, ["body", "spin_path"]),
    ],
)
def test_bad_spin_path(client: TestClient, body: dict[str, Any], changes: dict, loc: list) -> None:
    response = client.post("/v1/optimize", json={**body, **changes})
    assert response.status_code == 422, response.text
    assert response.json()["detail"][0]["loc"][: len(loc)] == loc


def test_spins_of_the_wrong_length_are_refused(client: TestClient, body: dict[str, Any]) -> None:
    request = {
        "robot": body["robot"],
        "path": body["path"],
        "placement": {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0},
        "spins": [0.0, 0.1],
    }
    response = client.post("/v1/evaluate", json=request)
    assert response.status_code == 422, response.text
    assert response.json()["detail"][0]["loc"] == ["body", "spins"]


def test_height_is_z_or_a_range(client: TestClient, body: dict[str, Any]) -> None:
    bounds = {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3], "z": [0.05, 0.15]}
    free = client.post("/v1/optimize", json={**body, "bounds": bounds, "z": None}).json()
    assert free["found"] and 0.05 <= free["placement"]["z"] <= 0.15
    for z in (0.1, None):
        request = {**body, "bounds": bounds if z else {**bounds, "z": None}, "z": z}
        response = client.post("/v1/optimize", json=request)
        assert response.status_code == 422, response.text
        assert response.json()["detail"][0]["loc"][:1] == ["body"]


def test_a_tiny_spin_step_is_not_a_server_error(client: TestClient, body: dict[str, Any]) -> None:
    """Found by schemathesis: max_spin_step 5e-324 made IPOPT's step bounds cross (a 500)."""
    request = {
        **body,
        "path": {"waypoints": body["path"]["waypoints"][:2]},
        "spin_path": {"max_spin_step": 5e-324},
    }
    answer = client.post("/v1/optimize", json=request)
    assert answer.status_code == 200, answer.text
    assert answer.json()["found"] and answer.json()["mu_path"] >= answer.json()["start"]["mu_path"]
