"""Joint acceleration limits through the API: evaluate, map, optimize, the feed check, errors."""

from __future__ import annotations

import copy
import io
import json
from pathlib import Path
from typing import Any

import matplotlib.image
import pytest
from fastapi.testclient import TestClient

from service.config import Settings
from service.jobs.store import JobStore
from service.jobs.worker import run_job
from tests.cases import (
    EXAMPLES,
    MAP_EVALUATE_RTOL,
    OPTIMUM_EVALUATE_RTOL,
    README_CONSTANT_FEED_TIME_10,
    README_CONSTANT_FEED_TIME_ATOL,
    README_MU_ACC,
    README_MU_ACC_ATOL,
    README_MU_ACC_WAYPOINT,
)
from tests.service.conftest import sent_back

EXAMPLE = json.loads((EXAMPLES / "evaluate_request.json").read_text())
NEW_FIELDS = {"acceleration", "cycle_time"}


def limited(body: dict[str, Any], value: float = 10.0, **ik: Any) -> dict[str, Any]:
    new = copy.deepcopy(body)
    new["robot"]["joint_acceleration_limits"] = [value] * 6
    new.setdefault("ik", {}).update(ik)
    return new


def post(client: TestClient, route: str, body: dict[str, Any]) -> dict[str, Any]:
    response = client.post(route, json=body)
    assert response.status_code == 200, response.text
    result: dict[str, Any] = response.json()
    return result


@pytest.mark.parametrize("value", sorted(README_MU_ACC))
def test_readme_example(client: TestClient, value: float) -> None:
    answer = post(client, "/v1/evaluate", limited(EXAMPLE, value))
    acceleration = answer["acceleration"]
    assert acceleration["mu_acc"] == pytest.approx(README_MU_ACC[value], abs=README_MU_ACC_ATOL)
    assert acceleration["limited_by"] == "acceleration"
    assert acceleration["waypoint"] == README_MU_ACC_WAYPOINT
    assert acceleration["joint_name"] == "wrist_3_joint"
    assert acceleration["blend_length"] == 0.002
    times = answer["cycle_time"]
    assert times["constant_feed_time"] == pytest.approx(
        answer["cycle_time"]["passes"][0]["length"] / acceleration["mu_acc"], rel=1e-12
    )
    assert times["time_optimal"] <= times["ramp"]
    waypoint = answer["waypoints"][README_MU_ACC_WAYPOINT]["qdd_at_mu_acc"]
    assert abs(waypoint[5]) == pytest.approx(value, rel=1e-9)  # wrist_3 on its limit
    assert answer["waypoints"][0]["qdd_at_mu_acc"] is None  # within b of the pass start
    if value == 10.0:
        assert times["constant_feed_time"] == pytest.approx(
            README_CONSTANT_FEED_TIME_10, abs=README_CONSTANT_FEED_TIME_ATOL
        )


def test_without_limits_the_answer_is_as_before(client: TestClient) -> None:
    without = post(client, "/v1/evaluate", EXAMPLE)
    assert without["acceleration"] is None and without["cycle_time"] is None
    assert all(w["qdd_at_mu_acc"] is None for w in without["waypoints"])
    with_limits = post(client, "/v1/evaluate", limited(EXAMPLE))
    for key in set(without) - NEW_FIELDS - {"waypoints"}:
        assert with_limits[key] == without[key], key
    for a, b in zip(with_limits["waypoints"], without["waypoints"], strict=True):
        assert {k: v for k, v in a.items() if k != "qdd_at_mu_acc"} == {
            k: v for k, v in b.items() if k != "qdd_at_mu_acc"
        }


def test_blend_length_is_a_request_option(client: TestClient) -> None:
    short = post(client, "/v1/evaluate", limited(EXAMPLE, blend_length=0.001))
    long = post(client, "/v1/evaluate", limited(EXAMPLE, blend_length=0.005))
    assert short["acceleration"]["blend_length"] == 0.001
    assert long["acceleration"]["blend_length"] == 0.005
    assert short["acceleration"]["mu_acc"] != long["acceleration"]["mu_acc"]


def test_feed_check_is_against_mu_acc(client: TestClient) -> None:
    feed = 0.26  # between mu_acc (0.2388) and mu_path (0.2937)
    without = post(client, "/v1/evaluate", {**EXAMPLE, "feed": feed})
    with_limits = post(client, "/v1/evaluate", {**limited(EXAMPLE), "feed": feed})
    assert without["feed_check"]["feasible"] is True
    assert with_limits["feed_check"]["feasible"] is False
    assert with_limits["feed_check"]["margin"] == pytest.approx(
        with_limits["acceleration"]["mu_acc"] / feed, rel=1e-12
    )


def test_map_cells_carry_mu_acc_and_equal_evaluate(client: TestClient) -> None:
    body = {
        "robot": {"model": "ur5", "joint_acceleration_limits": [10.0] * 6},
        "path": EXAMPLE["path"],
        "grid": {
            "x": {"min": -0.1, "max": 0.1, "step": 0.1},
            "y": {"min": 0.4, "max": 0.5, "step": 0.05},
            "z": 0.1,
            "yaw": [0.0, 0.4],
        },
    }
    answer = post(client, "/v1/map", body)
    feasible = [cell for cell in answer["cells"] if cell["mu_path"] is not None]
    assert len(feasible) >= 4
    for cell in feasible:
        placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"]}
        evaluation = post(
            client,
            "/v1/evaluate",
            {"robot": body["robot"], "path": body["path"], "placement": placement},
        )
        assert cell["mu_acc"] == pytest.approx(
            evaluation["acceleration"]["mu_acc"], rel=MAP_EVALUATE_RTOL
        )
        assert cell["limited_by"] == evaluation["acceleration"]["limited_by"]
    best = max(feasible, key=lambda cell: cell["mu_acc"])
    assert answer["best"]["mu_acc"] == best["mu_acc"]


def test_optimum_maximises_mu_acc(client: TestClient) -> None:
    body = {
        "robot": {"model": "ur5", "joint_acceleration_limits": [10.0] * 6},
        "path": EXAMPLE["path"],
        "bounds": {"x": [-0.1, 0.1], "y": [0.35, 0.55], "yaw": [-0.3, 0.3]},
        "z": 0.1,
    }
    answer = post(client, "/v1/optimize", body)
    assert answer["found"] is True
    evaluation = post(
        client,
        "/v1/evaluate",
        {"robot": body["robot"], "path": body["path"], "placement": sent_back(answer["placement"])},
    )
    assert answer["mu_acc"] == pytest.approx(
        evaluation["acceleration"]["mu_acc"], rel=OPTIMUM_EVALUATE_RTOL
    )
    assert answer["evaluation"]["acceleration"]["mu_acc"] == answer["mu_acc"]
    assert answer["mu_acc"] >= README_MU_ACC[10.0]  # at least the start's
    # The start (the centre of the bounds: the README example) reports the index the
    # improvement is measured in: mu_acc, as /v1/evaluate gives it there.
    start = post(
        client,
        "/v1/evaluate",
        {
            "robot": body["robot"],
            "path": body["path"],
            "placement": sent_back(answer["start"]["placement"]),
        },
    )
    assert answer["start"]["mu_acc"] == pytest.approx(start["acceleration"]["mu_acc"], rel=1e-12)
    assert answer["start"]["mu_path"] == pytest.approx(start["mu_path"], rel=1e-12)
    assert answer["start"]["mu_acc"] < answer["start"]["mu_path"]
    assert answer["improvement_percent"] == pytest.approx(
        100.0 * (answer["mu_acc"] / answer["start"]["mu_acc"] - 1.0), rel=1e-9
    )


def test_the_start_has_no_mu_acc_without_limits(client: TestClient) -> None:
    body = {
        "robot": {"model": "ur5"},
        "path": EXAMPLE["path"],
        "bounds": {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.2, 0.2]},
        "z": 0.1,
    }
    answer = post(client, "/v1/optimize", body)
    assert answer["start"]["mu_acc"] is None and answer["start"]["mu_path"] > 0.0


@pytest.mark.parametrize(
    ("robot", "loc"),
    [
        ({"model": "ur5", "joint_acceleration_limits": [10.0] * 5}, "joint_acceleration_limits"),
        ({"model": "ur5", "joint_acceleration_limits": [10.0, -1.0, 10.0, 10.0, 10.0, 10.0]}, "1"),
        ({"model": "ur5", "joint_acceleration_limits": []}, "joint_acceleration_limits"),
        ({"model": "ur5", "joint_acceleration_limits": "fast"}, "joint_acceleration_limits"),
    ],
)
def test_bad_limits_are_422_naming_the_field(
    client: TestClient, robot: dict[str, Any], loc: str
) -> None:
    response = client.post("/v1/evaluate", json={**EXAMPLE, "robot": robot})
    assert response.status_code == 422, response.text
    locs = [entry["loc"] for entry in response.json()["detail"]]
    assert any("robot" in map(str, at) and loc in map(str, at) for at in locs), locs


@pytest.mark.parametrize("blend", [0.0, -1.0, 1e9, "x"])
def test_bad_blend_length_is_422(client: TestClient, blend: Any) -> None:
    response = client.post("/v1/evaluate", json=limited(EXAMPLE, blend_length=blend))
    assert response.status_code == 422, response.text
    locs = [entry["loc"] for entry in response.json()["detail"]]
    assert any(at[-2:] == ["ik", "blend_length"] for at in locs), locs


def test_opw_and_urdf_robots_take_limits(client: TestClient, panda_urdf: str) -> None:
    opw = {
        "robot": {
            "opw": {
                "a1": 0.025,
                "a2": -0.035,
                "b": 0.0,
                "c1": 0.4,
                "c2": 0.315,
                "c3": 0.365,
                "c4": 0.08,
                "offsets": [0.0, -1.5707963267948966, 0.0, 0.0, 0.0, 0.0],
                "sign_corrections": [-1, 1, 1, -1, 1, -1],
            },
            "joint_position_limits": [
                [-3.2, 3.2],
                [-3.3, 0.8],
                [-2.1, 2.9],
                [-6.1, 6.1],
                [-2.1, 2.1],
                [-6.1, 6.1],
            ],
            "joint_velocity_limits": [6.0, 5.0, 6.0, 6.0, 6.0, 9.0],
            "joint_acceleration_limits": [5.0] * 6,
        },
        "path": {"waypoints": EXAMPLE["path"]["waypoints"][:40]},
        "placement": {"x": 0.45, "y": 0.0, "z": 0.1, "yaw": 0.0},
    }
    response = client.post("/v1/evaluate", json=opw)
    assert response.status_code == 200, response.text
    if response.json()["feasible"]:
        assert response.json()["acceleration"] is not None
    urdf = {
        "robot": {
            "urdf": panda_urdf,
            "base_frame": "panda_link0",
            "tool_frame": "panda_link8",
            "joint_acceleration_limits": [1.0] * 6,
        }
    }
    response = client.post("/v1/evaluate", json={**opw, **urdf})
    assert response.status_code == 422, response.text  # the Panda has 7 joints
    detail = response.json()["detail"]
    assert any("joint_acceleration_limits" in map(str, entry["loc"]) for entry in detail), detail


@pytest.mark.parametrize("kind", ["evaluate", "map"])
def test_jobs_answer_what_the_routes_answer(client: TestClient, tmp_path: Path, kind: str) -> None:
    """A job runs the route's own code: with acceleration limits, the same answer."""
    request = limited(EXAMPLE, 3.0)
    if kind == "map":
        request = {
            "robot": request["robot"],
            "path": request["path"],
            "grid": {
                "x": {"min": -0.05, "max": 0.05, "step": 0.05},
                "y": {"min": 0.45, "max": 0.45, "step": 0.05},
                "z": 0.1,
                "yaw": 0.0,
            },
        }
    store = JobStore(tmp_path / "jobs.sqlite")
    job = store.create(kind, request)  # type: ignore[arg-type]
    run_job(store, job.id, Settings(data_dir=tmp_path, workers=1))
    done = store.get(job.id)
    assert done is not None and done.status == "done", done
    assert done.result == post(client, f"/v1/{kind}", request)


def test_joint_use_picture_has_the_acceleration_panel(client: TestClient) -> None:
    pictures = {}
    for name, body in (("without", EXAMPLE), ("with", limited(EXAMPLE))):
        answer = client.post("/v1/evaluate", json=body, headers={"accept": "image/png"})
        assert answer.status_code == 200, answer.text
        pictures[name] = matplotlib.image.imread(io.BytesIO(answer.content))
    assert pictures["with"].shape[1] == pictures["without"].shape[1]
    assert pictures["with"].shape[0] == pytest.approx(
        pictures["without"].shape[0] * 7 / 4, rel=0.01
    )


def test_the_optimums_evaluation_has_the_cycle_time_evaluate_gives(client: TestClient) -> None:
    """api.md: optimize's evaluation is as /v1/evaluate's; with acceleration limits its
    cycle_time was null where /v1/evaluate at the optimum gives one."""
    fixed = {"x": [0.0, 0.0], "y": [0.45, 0.45], "yaw": [0.0, 0.0]}
    short = {"waypoints": EXAMPLE["path"]["waypoints"][:20]}
    body = limited({"robot": EXAMPLE["robot"], "path": short})
    optimum = post(client, "/v1/optimize", {**body, "bounds": fixed, "z": 0.1})
    assert optimum["found"]
    at = sent_back(optimum["placement"])
    evaluated = post(client, "/v1/evaluate", {**body, "placement": at})
    assert evaluated["cycle_time"] is not None
    assert optimum["evaluation"]["cycle_time"] == evaluated["cycle_time"]
