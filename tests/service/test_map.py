"""POST /v1/map: cells equal /v1/evaluate, best/worst, the picture, the size limit."""

from __future__ import annotations

import io
import json
import re
import time
from collections.abc import Iterator
from typing import Any

import matplotlib.image
import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.config import get_settings
from service.render import figure_pixels
from tests.cases import EXAMPLES, MAP_EVALUATE_RTOL
from tests.service.conftest import sent_back


@pytest.fixture(scope="module")
def path() -> dict[str, Any]:
    return json.loads((EXAMPLES / "paths" / "curved_line.json").read_text())


def map_body(path: dict[str, Any], **grid: Any) -> dict[str, Any]:
    default = {
        "x": {"min": -0.9, "max": 0.9, "step": 0.15},
        "y": {"min": -0.9, "max": 0.9, "step": 0.15},
        "z": 0.1,
        "yaw": [0.0, 2.0],
    }
    return {"robot": {"model": "ur5"}, "path": path, "grid": {**default, **grid}}


@pytest.fixture(scope="module")
def answer(client: TestClient, path: dict[str, Any]) -> dict[str, Any]:
    response = client.post("/v1/map", json=map_body(path))
    assert response.status_code == 200, response.text
    return response.json()


def test_cells_are_in_yaw_y_x_order(answer: dict[str, Any]) -> None:
    cells = answer["cells"]
    assert len(cells) == 2 * 13 * 13
    assert [(c["yaw"], c["y"], c["x"]) for c in cells] == sorted(
        (c["yaw"], c["y"], c["x"]) for c in cells
    )
    assert answer["feasible_cells"] == sum(c["mu_path"] is not None for c in cells)
    assert 0 < answer["feasible_cells"] < len(cells)


def test_cells_and_extremes_are_at_the_grid_values_as_written(
    client: TestClient, path: dict[str, Any]
) -> None:
    """-0.25 + 15 x 0.02 is answered 0.05 (not 0.04999999999999999), and 50 mm in the
    controllers' frames (not 49.999999999999986): the grid's values are the decimals of its
    min and step, read by a regex from the answer's own text."""
    x = {"min": -0.25, "max": 0.25, "step": 0.02}
    body = map_body(path, x=x, y={"min": 0.45, "max": 0.45, "step": 0.1}, yaw=0.0)
    response = client.post("/v1/map", json=body)
    assert response.status_code == 200, response.text
    written = re.findall(r'"x":\s*(-?[0-9.eE+-]+)', response.text)[:26]  # the cells' first
    assert written == [f"{i / 100:.2f}".rstrip("0") for i in range(-25, 27, 2)]
    for extreme in ("best", "worst"):
        kuka = response.json()[extreme]["placement"]["frames"]["kuka"]
        assert re.fullmatch(r"-?[0-9]+\.0", repr(kuka["X"])), kuka


def test_random_cells_equal_evaluate(
    client: TestClient, answer: dict[str, Any], path: dict[str, Any]
) -> None:
    """Issue 3: random cells equal /v1/evaluate at those placements, infeasible ones included."""
    cells = answer["cells"]
    rng = np.random.default_rng(5)
    feasible = [c for c in cells if c["mu_path"] is not None]
    infeasible = [c for c in cells if c["mu_path"] is None]
    for cell in [*rng.choice(feasible, 10), *rng.choice(infeasible, 10)]:
        placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"]}
        body = {"robot": {"model": "ur5"}, "path": path, "placement": placement}
        evaluation = client.post("/v1/evaluate", json=body).json()
        if evaluation["feasible"]:
            assert cell["mu_path"] == pytest.approx(evaluation["mu_path"], rel=MAP_EVALUATE_RTOL)
            assert cell["bottleneck_waypoint"] == evaluation["bottleneck"]["waypoint"]
            assert cell["bottleneck_joint"] == evaluation["bottleneck"]["joint"]
            assert cell["branch"] == evaluation["branch"]
        else:
            assert cell["mu_path"] is None
            assert cell["bottleneck_joint"] is None and cell["branch"] is None
            assert cell["reason"] == evaluation["reason"]
            assert cell["failed_waypoint"] == evaluation["failed_waypoint"]


def test_best_and_worst_are_the_extreme_cells(answer: dict[str, Any]) -> None:
    values = [c["mu_path"] for c in answer["cells"] if c["mu_path"] is not None]
    assert answer["best"]["mu_path"] == max(values)
    assert answer["worst"]["mu_path"] == min(values)
    best = next(c for c in answer["cells"] if c["mu_path"] == max(values))
    assert sent_back(answer["best"]["placement"]) == {
        "x": best["x"],
        "y": best["y"],
        "z": 0.1,
        "yaw": best["yaw"],
        "spin": best["spin"],
    }


@pytest.mark.parametrize("yaws", [[0.0], [0.0, 0.5, 1.0, 1.5]])
def test_png_decodes_at_the_expected_size(
    client: TestClient, path: dict[str, Any], yaws: list[float]
) -> None:
    response = client.post(
        "/v1/map",
        json=map_body(path, yaw=yaws, x={"min": -0.3, "max": 0.3, "step": 0.05}),
        headers={"accept": "image/png"},
    )
    assert response.status_code == 200
    assert response.headers["content-type"] == "image/png"
    image = matplotlib.image.imread(io.BytesIO(response.content), format="png")
    width, height = figure_pixels(len(yaws))
    assert image.shape[:2] == (height, width)
    assert np.ptp(image[..., :3]) > 0.5  # not a blank canvas


def test_no_feasible_cell(client: TestClient, path: dict[str, Any]) -> None:
    far = {"min": 5.0, "max": 5.2, "step": 0.1}
    answer = client.post("/v1/map", json=map_body(path, x=far, yaw=0.0)).json()
    assert answer["best"] is None and answer["worst"] is None
    assert {c["reason"] for c in answer["cells"]} == {"unreachable"}
    png = client.post("/v1/map", json=map_body(path, x=far), headers={"accept": "image/png"})
    assert png.status_code == 200


@pytest.fixture
def small_limits(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setenv("DTF_MAX_MAP_CELLS", "100")
    monkeypatch.setenv("DTF_MAX_MAP_POSES", "10000")
    get_settings.cache_clear()
    yield
    get_settings.cache_clear()


def test_size_limit_names_the_limit_and_the_size(
    client: TestClient, path: dict[str, Any], small_limits: None
) -> None:
    response = client.post("/v1/map", json=map_body(path))
    assert response.status_code == 422
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "grid"]
    assert "338 placements" in detail["msg"] and "limit is 100" in detail["msg"]
    assert detail["msg"].endswith("POST /v1/jobs runs bigger maps")
    small = {"min": 0.0, "max": 0.8, "step": 0.1}
    response = client.post("/v1/map", json=map_body(path, x=small, y=small, yaw=0.0))
    detail = response.json()["detail"][0]
    assert "81 placements * 133 waypoints = 10773 poses" in detail["msg"]
    assert "limit is 10000" in detail["msg"] and "POST /v1/jobs" in detail["msg"]


@pytest.mark.parametrize(
    ("grid", "loc"),
    [
        ({"x": {"min": 0.0, "max": 1.0, "step": 0.0}}, ["body", "grid", "x", "step"]),
        ({"x": {"min": 1.0, "max": 0.0, "step": 0.1}}, ["body", "grid", "x"]),
        ({"x": {"min": 0.0, "max": 1.0, "step": 1e-300}}, ["body", "grid", "x"]),
        ({"yaw": []}, ["body", "grid", "yaw"]),
        ({"z": "high"}, ["body", "grid", "z"]),
    ],
)
def test_bad_grid(
    client: TestClient, path: dict[str, Any], grid: dict[str, Any], loc: list
) -> None:
    response = client.post("/v1/map", json=map_body(path, **grid))
    assert response.status_code == 422, response.text
    assert response.json()["detail"][0]["loc"][: len(loc)] == loc


def test_a_map_says_what_it_normalised_as_an_evaluation_does(
    client: TestClient, path: dict[str, Any]
) -> None:
    """Quaternions 5e-4 off unit are normalised (api.md, Pose): /v1/evaluate and /v1/optimize
    said so in axis_correction, the map said nothing. Its answer (and a map job's, and the PNG
    route's JSON twin) now carries the largest correction: here the path's (|1.0005 - 1|) and a
    tcp's 2e-4 below it."""
    stretched = json.loads(json.dumps(path))
    for waypoint in stretched["waypoints"]:
        waypoint["orientation"] = [1.0005 * v for v in waypoint["orientation"]]
    grid = {"x": {"min": 0.0, "max": 0.1, "step": 0.1}, "y": {"min": 0.4, "max": 0.4, "step": 0.1}}
    body = map_body(stretched, **grid, yaw=0.0)
    body["robot"] = {
        "model": "ur5",
        "tcp": {"position": [0, 0, 0.1], "orientation": [0, 0, 0, 0.9998]},
    }
    stretched_map = client.post("/v1/map", json=body).json()
    norm = float(np.linalg.norm(stretched["waypoints"][0]["orientation"]))
    assert stretched_map["axis_correction"] == pytest.approx(norm - 1.0, abs=1e-12)
    placement = {"x": 0.0, "y": 0.4, "z": 0.1, "yaw": 0.0}
    evaluation = client.post(
        "/v1/evaluate", json={"robot": body["robot"], "path": stretched, "placement": placement}
    ).json()
    assert stretched_map["axis_correction"] == evaluation["axis_correction"]
    plain = client.post("/v1/map", json=map_body(path, **grid, yaw=0.0)).json()
    assert plain["axis_correction"] < 1e-12  # the file's own digits: its norms 1 to 6e-13
    unit = client.post("/v1/map", json={**body, "path": path}).json()
    assert unit["axis_correction"] == pytest.approx(2e-4, abs=1e-12)  # the tcp's alone
    job = client.post("/v1/jobs", json={"kind": "map", "request": body}).json()
    deadline = time.monotonic() + 300  # behind other tests' jobs on a loaded machine
    while job["status"] in ("queued", "running") and time.monotonic() < deadline:
        time.sleep(0.05)
        job = client.get(f"/v1/jobs/{job['id']}").json()
    assert job["status"] == "done", job
    assert job["result"]["axis_correction"] == stretched_map["axis_correction"]


def test_the_png_of_a_cell_at_a_subnormal_y_is_drawn(client: TestClient) -> None:
    """The body the contract test found a 500 with (the picture's tick at y = -2.2e-311)."""
    body = {
        "grid": {
            "x": {"min": 0.5, "step": 1111.7968065590455, "max": 356.58047128571},
            "y": {"max": 0.0, "min": -2.225073858507e-311, "step": 1.0000000000000002e-06},
            "yaw": 0.0,
            "z": 0.0,
        },
        "path": {"cl_data": "UNITS/MM\nGOTO/0, 0, 0, 0, 0, 1\nGOTO/5, 0, 0, 0, 0.6, 0.8\n"},
        "robot": {"model": "ur3"},
    }
    answer = client.post("/v1/map/png", json=body)
    assert answer.status_code == 200, answer.text
    assert answer.headers["content-type"] == "image/png"
