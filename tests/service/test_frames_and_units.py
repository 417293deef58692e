"""Placements in controller terms, and vectors typed as papers and CAM print them (issue 10).

The frames are checked against scipy's Rotation (an independent implementation of the Euler
and rotation-vector conventions); the near-unit rule against the same request with the vectors
normalised by numpy.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.spatial.transform import Rotation

from tests.cases import EXAMPLES

REQUEST = json.loads((EXAMPLES / "evaluate_request.json").read_text())


def check_frames(placement: dict[str, Any]) -> None:
    """Every controller form of an answer's placement is Trans(x, y, z) Rot_z(yaw)."""
    frames = placement["frames"]
    expected = np.eye(4)
    expected[:3, :3] = Rotation.from_euler("z", placement["yaw"]).as_matrix()
    expected[:3, 3] = [placement["x"], placement["y"], placement["z"]]
    np.testing.assert_allclose(frames["matrix"], expected, atol=1e-12)
    ur = frames["ur"]
    np.testing.assert_allclose(
        Rotation.from_rotvec(ur[3:]).as_matrix(), expected[:3, :3], atol=1e-9
    )
    np.testing.assert_allclose(ur[:3], expected[:3, 3], atol=1e-12)
    kuka, fanuc = frames["kuka"], frames["fanuc"]
    kuka_rotation = Rotation.from_euler("ZYX", [kuka["A"], kuka["B"], kuka["C"]], degrees=True)
    fanuc_rotation = Rotation.from_euler("ZYX", [fanuc["R"], fanuc["P"], fanuc["W"]], degrees=True)
    for rotation, frame in ((kuka_rotation, kuka), (fanuc_rotation, fanuc)):
        np.testing.assert_allclose(rotation.as_matrix(), expected[:3, :3], atol=1e-9)
        np.testing.assert_allclose(
            [frame["X"], frame["Y"], frame["Z"]], 1000 * expected[:3, 3], atol=1e-9
        )
    (position, (w, x, y, z)) = frames["abb"]
    np.testing.assert_allclose(
        Rotation.from_quat([x, y, z, w]).as_matrix(), expected[:3, :3], atol=1e-9
    )
    np.testing.assert_allclose(position, 1000 * expected[:3, 3], atol=1e-9)


def test_every_placement_in_every_answer_comes_in_controller_terms(client: TestClient) -> None:
    grid = {"x": {"min": -0.1, "max": 0.1, "step": 0.1}, "y": {"min": 0.4, "max": 0.5, "step": 0.1}}
    body = {**REQUEST, "grid": {**grid, "z": 0.1, "yaw": [0.0, 2.5]}}
    del body["placement"]
    cmap = client.post("/v1/map", json=body).json()
    for extreme in (cmap["best"], cmap["worst"]):
        check_frames(extreme["placement"])
    bounds = {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [2.0, 2.6]}
    optimum = client.post(
        "/v1/optimize",
        json={"robot": REQUEST["robot"], "path": REQUEST["path"], "bounds": bounds, "z": 0.1},
    ).json()
    check_frames(optimum["placement"])
    check_frames(optimum["start"]["placement"])
    # the placement evaluated, in /v1/optimize's evaluation the optimum's (audit 25: a placement
    # a CAM tool chose itself had no controller frames)
    assert optimum["evaluation"]["placement"] == optimum["placement"]
    at = {"x": 0.03, "y": 0.47, "z": 0.12, "yaw": 2.4, "spin": 0.2}
    evaluation = client.post("/v1/evaluate", json={**REQUEST, "placement": at}).json()
    assert {k: evaluation["placement"][k] for k in at} == at
    check_frames(evaluation["placement"])


# Sensors 2022 table 3, typed as printed (4 decimals): u_T, u_R, h of three UR5e path segments.
TABLE_3 = [
    ([0.9999, 0, 0.0117], [0.6209, 0.7625, -0.1820], 4.4632),
    ([-0.9893, 0, 0.1459], [0.0865, -0.9761, -0.1994], 0.0360),
    ([0.9992, 0, 0.0411], [0.9997, -0.0249, 0.0011], 0.7454),
]


@pytest.mark.parametrize(("u_T", "u_R", "h"), TABLE_3)
def test_directions_typed_as_printed_are_normalised_and_reported(
    client: TestClient, u_T: list[float], u_R: list[float], h: float
) -> None:
    q = [0.1, -1.2, 1.3, -1.5, -1.4, 0.2]
    typed = {"robot": {"model": "ur5e"}, "q": q, "u_T": u_T, "u_R": u_R, "h": h}
    unit = {
        **typed,
        "u_T": (np.array(u_T) / np.linalg.norm(u_T)).tolist(),
        "u_R": (np.array(u_R) / np.linalg.norm(u_R)).tolist(),
    }
    as_typed, normalised = client.post("/v1/dtf", json=typed), client.post("/v1/dtf", json=unit)
    assert as_typed.status_code == 200, as_typed.text
    correction = max(abs(np.linalg.norm(u_T) - 1), abs(np.linalg.norm(u_R) - 1))
    assert 0 < as_typed.json()["correction"] == pytest.approx(correction, rel=1e-9)
    assert as_typed.json()["v_max"] == pytest.approx(normalised.json()["v_max"], rel=1e-12)
    assert as_typed.json()["omega_max"] == pytest.approx(as_typed.json()["v_max"] / h, rel=1e-12)


def test_a_direction_off_by_more_than_1e_3_is_refused(client: TestClient) -> None:
    body = {
        "robot": {"model": "ur5e"},
        "q": [0.1, -1.2, 1.3, -1.5, -1.4, 0.2],
        "u_T": [1.0, 0.07, 0],
    }
    answer = client.post("/v1/dtf", json=body)
    assert answer.status_code == 422 and answer.json()["detail"][0]["loc"] == ["body", "u_T"]


def test_quaternions_typed_with_four_decimals_evaluate_as_exact_ones(client: TestClient) -> None:
    typed = json.loads(json.dumps(REQUEST))
    exact = json.loads(json.dumps(REQUEST))
    for waypoint in typed["path"]["waypoints"]:
        waypoint["orientation"] = [round(v, 4) for v in waypoint["orientation"]]
    for waypoint in exact["path"]["waypoints"]:
        q = np.array([round(v, 4) for v in waypoint["orientation"]])
        waypoint["orientation"] = (q / np.linalg.norm(q)).tolist()
    norms = [np.linalg.norm(w["orientation"]) for w in typed["path"]["waypoints"]]
    as_typed = client.post("/v1/evaluate", json=typed).json()
    assert as_typed["axis_correction"] == pytest.approx(max(abs(n - 1) for n in norms), rel=1e-9)
    assert as_typed["mu_path"] == pytest.approx(
        client.post("/v1/evaluate", json=exact).json()["mu_path"], rel=1e-12
    )


def test_a_tcp_or_cell_quaternion_normalised_is_reported(client: TestClient) -> None:
    """api.md: a Pose within 1e-3 of unit is normalised and the response reports the largest
    correction. The robot's tcp and the cell's object poses were normalised unsaid (the path's
    own quaternions were reported). The corrections are the norms given, less 1."""
    tcp = {"position": [0.0, 0.0, 0.05], "orientation": [0.0, 0.0, 0.0, 1.0009]}
    box = {
        "shape": "box",
        "size": [0.1, 0.1, 0.1],
        "pose": {"position": [3.0, 3.0, 3.0], "orientation": [0.0, 0.0, 0.9994, 0.0]},
    }
    robot = {**REQUEST["robot"], "tcp": tcp}
    with_tcp = client.post("/v1/evaluate", json={**REQUEST, "robot": robot}).json()
    assert with_tcp["axis_correction"] == pytest.approx(9e-4, rel=1e-9)
    with_cell = client.post("/v1/evaluate", json={**REQUEST, "cell": {"fixed": [box]}}).json()
    assert with_cell["axis_correction"] == pytest.approx(6e-4, rel=1e-9)
    fixed = {"x": [0.0, 0.0], "y": [0.45, 0.45], "yaw": [0.0, 0.0]}
    short = {"waypoints": REQUEST["path"]["waypoints"][:10]}
    optimum = client.post(
        "/v1/optimize", json={"robot": robot, "path": short, "bounds": fixed, "z": 0.1}
    ).json()
    assert optimum["found"] and optimum["evaluation"]["axis_correction"] == pytest.approx(
        9e-4, rel=1e-9
    )
