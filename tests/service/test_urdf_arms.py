"""Arms of the numeric IK family through the routes: the Panda as a URDF in the request and
from the catalogue (robots.md section 4)."""

from __future__ import annotations

import json
from typing import Any

import pinocchio as pin
import pytest
from fastapi.testclient import TestClient

from service.config import get_settings
from solver.core.robots import example_robot_data_dir
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric.family import NumericFamily
from tests.cases import EXAMPLES, OPTIMUM_EVALUATE_RTOL
from tests.service.conftest import sent_back
from tests.solver.families.test_mimic import arm as mimic_arm
from tests.solver.families.test_mimic import arm_urdf

PLACEMENT = {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}


@pytest.fixture(scope="module")
def waypoints() -> list[dict[str, Any]]:
    """The first ten waypoints of the example path."""
    example = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    waypoints: list[dict[str, Any]] = example["path"]["waypoints"][:10]
    return waypoints


@pytest.fixture(scope="module", params=["urdf", "catalogue"])
def panda(request: pytest.FixtureRequest, panda_urdf: str) -> dict[str, Any]:
    """The Panda as a URDF in the request, or as the catalogue's ``panda``."""
    if request.param == "catalogue":
        return {"model": "panda"}
    return {"urdf": panda_urdf, "base_frame": "panda_link0", "tool_frame": "panda_link8"}


def evaluated(
    client: TestClient,
    robot: dict[str, Any],
    waypoints: list[dict[str, Any]],
    placement: Any,
    **extra: Any,
) -> dict[str, Any]:
    body = {"robot": robot, "path": {"waypoints": waypoints}, "placement": placement, **extra}
    response = client.post("/v1/evaluate", json=body)
    assert response.status_code == 200, response.text
    answer: dict[str, Any] = response.json()
    return answer


def test_evaluate(
    client: TestClient, panda: dict[str, Any], waypoints: list[dict[str, Any]]
) -> None:
    answer = evaluated(client, panda, waypoints, PLACEMENT)
    assert answer["feasible"] and answer["mu_path"] > 0
    assert set(answer["branch"]) == {"solution"}
    assert all(len(waypoint["q"]) == 7 for waypoint in answer["waypoints"])
    assert answer["bottleneck"]["joint_name"].startswith("panda_joint")


def test_map_cells_equal_evaluate(
    client: TestClient, panda: dict[str, Any], waypoints: list[dict[str, Any]]
) -> None:
    grid = {
        "x": {"min": -0.05, "max": 0.05, "step": 0.05},
        "y": {"min": 0.4, "max": 0.5, "step": 0.1},
        "z": 0.1,
        "yaw": [0.0],
    }
    body = {"robot": panda, "path": {"waypoints": waypoints}, "grid": grid}
    response = client.post("/v1/map", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    assert len(answer["cells"]) == 6 and answer["feasible_cells"] > 0
    for cell in answer["cells"][::2]:
        placement = {key: cell[key] for key in ("x", "y", "yaw")} | {"z": 0.1}
        evaluation = evaluated(client, panda, waypoints, placement)
        assert evaluation["mu_path"] == cell["mu_path"]


def test_optimize_answer_is_what_evaluate_says(
    client: TestClient, panda: dict[str, Any], waypoints: list[dict[str, Any]]
) -> None:
    body = {
        "robot": panda,
        "path": {"waypoints": waypoints},
        "bounds": {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3]},
        "z": 0.1,
        "method": "casadi",
    }
    response = client.post("/v1/optimize", json=body)
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["found"] and answer["mu_path"] >= answer["start"]["mu_path"]
    assert answer["evaluation"]["ik"]["family"] == "numeric"
    # The casadi method chose the redundancy too: its joint path is the answer's, and
    # /v1/evaluate with it gives its mu_path; the tracked branches there are no faster.
    joint_path = answer["joint_path"]
    assert len(joint_path) == len(waypoints) and {len(q) for q in joint_path} == {7}
    placement = sent_back(answer["placement"])
    evaluation = evaluated(client, panda, waypoints, placement, joint_path=joint_path)
    assert answer["mu_path"] == pytest.approx(evaluation["mu_path"], rel=1e-9)
    assert evaluation["branch"] is None and evaluation["ik"]["seeds"] is None
    tracked = evaluated(client, panda, waypoints, placement)
    assert answer["mu_path"] >= tracked["mu_path"] * (1 - OPTIMUM_EVALUATE_RTOL)


def test_a_joint_path_off_its_waypoints_is_refused(
    client: TestClient, panda: dict[str, Any], waypoints: list[dict[str, Any]]
) -> None:
    joint_path = [w["q"] for w in evaluated(client, panda, waypoints, PLACEMENT)["waypoints"]]
    body = {"robot": panda, "path": {"waypoints": waypoints}, "placement": PLACEMENT}
    shifted = [q if i != 6 else [q[0] + 1e-3, *q[1:]] for i, q in enumerate(joint_path)]
    short = [q if i != 2 else q[:6] for i, q in enumerate(joint_path)]
    for bad, waypoint in ((shifted, 6), (short, 2)):
        response = client.post("/v1/evaluate", json=body | {"joint_path": bad})
        assert response.status_code == 422, response.text
        [entry] = response.json()["detail"]
        assert entry["loc"] == ["body", "joint_path", waypoint]
    same = client.post("/v1/evaluate", json=body | {"joint_path": joint_path}).json()
    assert same["mu_path"] == pytest.approx(
        evaluated(client, panda, waypoints, PLACEMENT)["mu_path"], rel=1e-12
    )


def test_a_numeric_branch_can_be_named(
    client: TestClient, panda: dict[str, Any], waypoints: list[dict[str, Any]]
) -> None:
    auto = evaluated(client, panda, waypoints, PLACEMENT)
    body = {
        "robot": panda,
        "path": {"waypoints": waypoints},
        "placement": PLACEMENT,
        "ik": {"branch": auto["branch"]},
    }
    named = client.post("/v1/evaluate", json=body).json()
    assert named["branch"] == auto["branch"] and named["mu_path"] == auto["mu_path"]
    body["ik"] = {"branch": {"shoulder": "left", "elbow": "up", "wrist": "noflip"}}
    response = client.post("/v1/evaluate", json=body)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"][:2] == [
        "body",
        "ik",
    ]


def test_answers_say_the_family_and_what_its_seeds_found(
    client: TestClient, panda: dict[str, Any], waypoints: list[dict[str, Any]]
) -> None:
    ik = evaluated(client, panda, waypoints, PLACEMENT)["ik"]
    assert ik["family"] == "numeric" and ik["seeds"] == 64
    assert 1 <= ik["branches_found"] <= 64
    body = {"robot": {"model": "ur5"}, "path": {"waypoints": waypoints}, "placement": PLACEMENT}
    analytic = client.post("/v1/evaluate", json=body).json()["ik"]
    assert analytic == {"family": "ur", "seeds": None, "branches_found": None, "recognised": None}


ERK_GRID = {
    "x": {"min": -0.25, "max": 0.25, "step": 0.02},
    "y": {"min": 0.25, "max": 0.65, "step": 0.02},
    "z": 0.1,
    "yaw": [0.0],
}


@pytest.fixture(scope="module")
def erk_path() -> dict[str, Any]:
    path: dict[str, Any] = json.loads((EXAMPLES / "paths" / "curved_line.json").read_text())
    return path


def test_numeric_map_is_weighed_by_its_cost(
    client: TestClient, panda: dict[str, Any], erk_path: dict[str, Any]
) -> None:
    """The ERK-size map: about 0.13 s analytic, 45 s for the Panda: refused before any work."""
    body = {"robot": panda, "path": erk_path, "grid": ERK_GRID}
    response = client.post("/v1/map", json=body)
    assert response.status_code == 422, response.text
    [entry] = response.json()["detail"]
    assert entry["loc"] == ["body", "grid"]
    assert "546 placements * 133 waypoints = 72618 poses" in entry["msg"]
    assert "numeric IK" in entry["msg"] and "DTF_MAX_MAP_POSES" in entry["msg"]
    analytic = client.post("/v1/map", json={**body, "robot": {"model": "ur5"}})
    assert analytic.status_code == 200, analytic.text


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_numeric_optimize_is_weighed_by_its_cost(
    client: TestClient, panda: dict[str, Any], erk_path: dict[str, Any], method: str
) -> None:
    """The coarse map (casadi) or even the smallest differential evolution (scipy, sized by
    the family's cost) on the ERK path run twice: 165 placements * 55,600 = 9.2 million poses
    of work for scipy, over its 6.1 million (the ERK path once, 4.8 million, is admitted)."""
    twice = {"waypoints": erk_path["waypoints"] * 2}
    body = {
        "robot": panda,
        "path": twice,
        "bounds": {"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-3.14, 3.14]},
        "z": 0.1,
        "method": method,
    }
    response = client.post("/v1/optimize", json=body)
    assert response.status_code == 422, response.text
    [entry] = response.json()["detail"]
    assert entry["loc"] == ["body", "bounds"]
    assert "numeric IK" in entry["msg"] and "the limit is" in entry["msg"]


def test_numeric_evaluate_is_weighed_by_its_cost(
    client: TestClient,
    panda: dict[str, Any],
    waypoints: list[dict[str, Any]],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """One placement of a numeric arm's path is its family's path_cost, against the map limit."""
    limit = 1_000  # above ten closed-form poses, below one numeric seeding
    monkeypatch.setenv("DTF_MAX_MAP_POSES", str(limit))
    get_settings.cache_clear()
    try:
        body = {"robot": panda, "path": {"waypoints": waypoints}, "placement": PLACEMENT}
        response = client.post("/v1/evaluate", json=body)
        analytic = client.post("/v1/evaluate", json={**body, "robot": {"model": "ur5"}})
    finally:
        monkeypatch.undo()
        get_settings.cache_clear()
    assert response.status_code == 422, response.text
    [entry] = response.json()["detail"]
    assert entry["loc"] == ["body", "path"]
    assert "10 waypoints, as work" in entry["msg"] and "(numeric IK)" in entry["msg"]
    assert f"the limit is {limit} (DTF_MAX_MAP_POSES)" in entry["msg"]
    assert analytic.status_code == 200, analytic.text


def test_the_erk_size_map_of_a_six_joint_urdf_is_within_the_map_limit(
    client: TestClient, erk_path: dict[str, Any]
) -> None:
    """Issue 27: the UR5 given as a URDF maps the ERK grid synchronously, as the analytic UR5."""
    urdf = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    robot = {"urdf": urdf, "base_frame": "base", "tool_frame": "tool0"}
    model = robot_from_urdf(urdf, base_frame="base", tool_frame="tool0").model
    numeric = NumericFamily(model, base_frame="base", tool_frame="tool0")
    assert 546 * numeric.path_cost(133) <= get_settings().max_map_poses
    response = client.post("/v1/map", json={"robot": robot, "path": erk_path, "grid": ERK_GRID})
    assert response.status_code == 200, response.text


@pytest.mark.parametrize("route", ["/v1/evaluate", "/v1/map"])
def test_free_spin_on_a_redundant_arm_is_weighed_by_its_lp(
    client: TestClient, waypoints: list[dict[str, Any]], route: str
) -> None:
    """Free spin on seven joints solves the vertex LP at every configuration: about twice the
    fixed spin's work (measured), so a request the fixed spin's limit admits may be refused."""
    n = 10_000  # fixed spin: 2,600 + 200 * 9,999 = 2.0 million poses, within 5 million; free: 3x
    family = get_robot("panda").family
    assert family is not None
    assert family.path_cost(n) <= get_settings().max_map_poses < family.path_cost(n, free_spin=True)
    line = [
        {"position": [1e-5 * i, 0.0, 0.0], "orientation": [1.0, 0.0, 0.0, 0.0]} for i in range(n)
    ]
    body: dict[str, Any] = {"robot": {"model": "panda"}, "path": {"waypoints": line}}
    if route == "/v1/map":
        axis = {"min": -0.1, "max": 0.1, "step": 0.1}
        body["grid"] = {"x": axis, "y": {**axis, "min": 0.3, "max": 0.5}, "z": 0.1, "yaw": 0.0}
    else:
        body["placement"] = PLACEMENT
    free = client.post(route, json={**body, "spin_mode": "free"})
    assert free.status_code == 422, free.text
    [entry] = free.json()["detail"]
    assert entry["loc"] in (["body", "path"], ["body", "grid"])
    assert "DTF_MAX_MAP_POSES" in entry["msg"]


@pytest.mark.parametrize("route", ["/v1/evaluate", "/v1/map", "/v1/optimize"])
def test_an_arm_with_a_mimic_joint_is_answered_on_its_coordinates(
    client: TestClient, route: str
) -> None:
    """Issue 27: a mimic joint between base and tool is honoured (the solver's tests hold the
    coupling and its limits: tests/solver/families/test_mimic.py); the answer names the six
    coordinates. Its numpy IK makes the optimiser's search too much work: a 422 naming the limit."""
    robot, path = mimic_arm(0.5)
    waypoints = [
        {"position": list(pose[:3, 3]), "orientation": list(pin.Quaternion(pose[:3, :3]).coeffs())}
        for pose in (path[:3] if route == "/v1/optimize" else path)
    ]
    body: dict[str, Any] = {
        "robot": {"urdf": arm_urdf(0.5), "base_frame": "l0", "tool_frame": "tool0"},
        "path": {"waypoints": waypoints},
    }
    if route == "/v1/evaluate":
        body["placement"] = {"x": 0.0, "y": 0.0, "z": 0.0, "yaw": 0.0}
    else:
        axis = {"min": -0.01, "max": 0.01, "step": 0.01}
        body["grid" if route == "/v1/map" else "bounds"] = (
            {"x": axis, "y": axis, "z": 0.0, "yaw": 0.0}
            if route == "/v1/map"
            else {"x": [-0.01, 0.01], "y": [-0.01, 0.01], "yaw": [-0.01, 0.01]}
        )
        if route == "/v1/optimize":
            body["method"], body["z"] = "casadi", 0.0
    response = client.post(route, json=body)
    if route == "/v1/optimize":  # numpy IK (35x) over a search: over the work limit
        assert response.status_code == 422, response.text
        assert "DTF_MAX_MAP_POSES" in response.json()["detail"][0]["msg"]
        return
    assert response.status_code == 200, response.text
    answer = response.json()
    if route == "/v1/evaluate":
        assert answer["feasible"], answer
        assert answer["bottleneck"]["joint_name"] in robot.joint_names
        assert {len(w["q"]) for w in answer["waypoints"]} == {6}
