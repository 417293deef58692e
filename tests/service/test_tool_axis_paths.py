"""Tool-axis paths and spin modes over REST (cam.md sections 1-2, 6)."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.spatial.transform import Rotation

from tests.cases import EXAMPLES, MAP_EVALUATE_RTOL, SPIN_SCHEDULE_RTOL
from tests.service.test_errors import assert_names


@pytest.fixture(scope="module")
def readme_request() -> dict[str, Any]:
    return json.loads((EXAMPLES / "evaluate_request.json").read_text())


def _as_tool_axes(waypoints: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The same tool points with the axis CAM would write: minus the tool z axis."""
    axes = -Rotation.from_quat([w["orientation"] for w in waypoints]).as_matrix()[:, :, 2]
    return [
        {"position": w["position"], "axis": axis.tolist()}
        for w, axis in zip(waypoints, axes, strict=True)
    ]


def test_tool_axis_path_defaults_to_free_spin(
    client: TestClient, readme_request: dict[str, Any]
) -> None:
    """The README path as tool axes: free spin by default, near the poses' free-spin mu_path.

    For a straight spindle the free spin rate absorbs any spin about the tool axis, so the two
    frames give the same mu_path up to the discretisation of each segment's rotation (the
    rotation vector of a finite turn is not the sum of its tilt and its spin).
    """
    body = {
        **readme_request,
        "path": {"tool_axis_waypoints": _as_tool_axes(readme_request["path"]["waypoints"])},
    }
    answer = client.post("/v1/evaluate", json=body).json()
    assert answer["spin_mode"] == "free"
    assert len(answer["spins"]) == len(body["path"]["tool_axis_waypoints"])
    poses = client.post("/v1/evaluate", json={**readme_request, "spin_mode": "free"}).json()
    assert poses["mu_path"] == pytest.approx(1.248073, abs=1e-6)
    assert answer["mu_path"] == pytest.approx(poses["mu_path"], rel=SPIN_SCHEDULE_RTOL)
    fixed = client.post("/v1/evaluate", json=readme_request).json()
    assert (fixed["spin_mode"], fixed["spins"]) == ("fixed", None)


def test_tool_axis_path_in_fixed_mode_is_the_transported_pose_path(
    client: TestClient, readme_request: dict[str, Any]
) -> None:
    """Fixed mode on tool axes = the pose path of the parallel-transport frames (cam.md 1)."""
    axes = _as_tool_axes(readme_request["path"]["waypoints"])
    body = {**readme_request, "path": {"tool_axis_waypoints": axes}, "spin_mode": "fixed"}
    answer = client.post("/v1/evaluate", json=body).json()
    z = -np.array([a["axis"] for a in axes])
    x = np.array([1.0, 0.0, 0.0])
    waypoints = []
    for point, axis in zip(axes, z, strict=True):  # transport written out here, independently
        x = x - (x @ axis) * axis
        x /= np.linalg.norm(x)
        matrix = np.column_stack([x, np.cross(axis, x), axis])
        quaternion = Rotation.from_matrix(matrix).as_quat()
        waypoints.append({"position": point["position"], "orientation": quaternion.tolist()})
    poses = client.post(
        "/v1/evaluate", json={**readme_request, "path": {"waypoints": waypoints}}
    ).json()
    assert answer["feasible"] and poses["feasible"]
    assert answer["mu_path"] == pytest.approx(poses["mu_path"], rel=1e-9)


def test_near_unit_axis_is_normalised_and_reported(
    client: TestClient, readme_request: dict[str, Any]
) -> None:
    axes = _as_tool_axes(readme_request["path"]["waypoints"])
    exact = client.post(
        "/v1/evaluate", json={**readme_request, "path": {"tool_axis_waypoints": axes}}
    ).json()
    axes[7]["axis"] = [round(v, 4) * 1.0006 for v in axes[7]["axis"]]
    answer = client.post(
        "/v1/evaluate", json={**readme_request, "path": {"tool_axis_waypoints": axes}}
    ).json()
    assert 5e-4 < answer["axis_correction"] < 7e-4
    assert answer["mu_path"] == pytest.approx(exact["mu_path"], rel=1e-2)
    assert exact["axis_correction"] < 1e-12


BAD_PATHS = [
    ("axis off unit by 2e-3", {"axis": [0.0, 0.0, 1.002]}, ["tool_axis_waypoints", 3]),
    ("zero axis", {"axis": [0.0, 0.0, 0.0]}, ["tool_axis_waypoints", 3]),
    ("axis of 2 numbers", {"axis": [0.0, 1.0]}, ["tool_axis_waypoints", 3, "axis"]),
    ("position far away", {"position": [0.0, 5e3, 0.0]}, ["tool_axis_waypoints", 3]),
    ("repeated waypoint", "repeat", ["tool_axis_waypoints", 3]),
]


@pytest.mark.parametrize(
    ("change", "loc"), [c[1:] for c in BAD_PATHS], ids=[c[0] for c in BAD_PATHS]
)
def test_bad_tool_axis_paths_name_the_waypoint(
    client: TestClient, readme_request: dict[str, Any], change: Any, loc: list[Any]
) -> None:
    axes = _as_tool_axes(readme_request["path"]["waypoints"][:6])
    if change == "repeat":
        axes[3] = axes[2]
    else:
        axes[3] = {**axes[3], **change}
    body = {**readme_request, "path": {"tool_axis_waypoints": axes}}
    assert_names(client.post("/v1/evaluate", json=body), 422, ["body", "path", *loc])


@pytest.mark.parametrize("route", ["evaluate", "map", "optimize"])
def test_path_needs_exactly_one_form(client: TestClient, route: str) -> None:
    both = {
        "waypoints": [{"position": [0, 0, 0], "orientation": [1, 0, 0, 0]}] * 2,
        "tool_axis_waypoints": [{"position": [0, 0, 0], "axis": [0, 0, 1]}] * 2,
    }
    response = client.post(f"/v1/{route}", json={"robot": {"model": "ur5"}, "path": both})
    assert_names(response, 422, ["body", "path"])


def test_unknown_spin_mode_is_refused(client: TestClient, readme_request: dict[str, Any]) -> None:
    response = client.post("/v1/evaluate", json={**readme_request, "spin_mode": "spinning"})
    assert_names(response, 422, ["body", "spin_mode"])


def test_map_in_free_spin_mode(client: TestClient, readme_request: dict[str, Any]) -> None:
    axes = _as_tool_axes(readme_request["path"]["waypoints"])
    grid = {
        "x": {"min": 0.0, "max": 0.0, "step": 0.1},
        "y": {"min": 0.45, "max": 0.45, "step": 0.1},
    }
    body = {
        "robot": {"model": "ur5"},
        "path": {"tool_axis_waypoints": axes},
        "grid": {**grid, "z": 0.1, "yaw": 0.0},
    }
    answer = client.post("/v1/map", json=body).json()
    assert answer["spin_mode"] == "free"
    placement = {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}
    evaluation = client.post(
        "/v1/evaluate", json={"robot": body["robot"], "path": body["path"], "placement": placement}
    ).json()
    assert answer["cells"][0]["mu_path"] == pytest.approx(
        evaluation["mu_path"], rel=MAP_EVALUATE_RTOL
    )
