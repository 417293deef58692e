"""``GET /v1/limits``: the limits a request meets are the ones the service enforces."""

from __future__ import annotations

import json
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.config import INVALID_SETTINGS, Settings, get_settings, settings_or_exit
from service.main import app
from service.schemas import LimitsResponse
from tests.cases import ROOT
from tests.service.conftest import served_with

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())


def test_the_limits_said_are_the_settings_served_and_enforced() -> None:
    # the body limit is the middleware's, read from the environment (its default here)
    settings = Settings(max_path_waypoints=7, max_mesh_triangles=3)
    with served_with(settings), TestClient(app) as client:
        limits = client.get("/v1/limits").json()
        assert set(limits) == set(LimitsResponse.model_fields)
        for name in set(limits) & set(Settings.model_fields):  # each setting as served
            assert limits[name] == getattr(settings, name), name
        assert limits["job_ttl_seconds"] == settings.job_ttl
        assert (limits["max_body_bytes"], limits["max_path_waypoints"]) == (2_000_000, 7)
        waypoints = EXAMPLE["path"]["waypoints"]
        at = client.post("/v1/evaluate", json={**EXAMPLE, "path": {"waypoints": waypoints[:7]}})
        assert at.status_code == 200, at.text
        over = client.post("/v1/evaluate", json={**EXAMPLE, "path": {"waypoints": waypoints[:8]}})
        assert over.status_code == 422 and "DTF_MAX_PATH_WAYPOINTS" in over.text
        short = json.dumps({**EXAMPLE, "pad": ""})
        for size, refused in ((limits["max_body_bytes"], 422), (limits["max_body_bytes"] + 1, 413)):
            body = json.dumps({**EXAMPLE, "pad": "x" * (size - len(short))})
            assert len(body.encode()) == size
            answer = client.post(
                "/v1/evaluate", content=body, headers={"Content-Type": "application/json"}
            )
            assert answer.status_code == refused, answer.text[:200]  # 422: the pad is no field


def test_each_limit_says_its_setting_or_that_it_has_none() -> None:
    schema = app.openapi()["components"]["schemas"]["LimitsResponse"]
    for name, field in schema["properties"].items():
        said = field["description"]
        setting = "job_ttl" if name == "job_ttl_seconds" else name
        if setting in Settings.model_fields:
            assert said.endswith(f"(DTF_{setting.upper()})"), (name, said)
        else:
            assert said.endswith("(the schema's; no setting)"), (name, said)


@pytest.mark.parametrize(
    ("variable", "value", "bound"),
    [
        ("DTF_MAX_PATH_WAYPOINTS", "30000", 20_000),
        ("DTF_MAX_OPTIMIZE_WAYPOINTS", "20001", 20_000),
        ("DTF_MAX_CELL_OBJECTS", "5000", 1_000),
    ],
)
def test_a_setting_above_the_schemas_bound_stops_the_start(
    variable: str, value: str, bound: int, monkeypatch: pytest.MonkeyPatch, capsys: Any
) -> None:
    """DTF_MAX_PATH_WAYPOINTS=30000 was capped at the schema's 20,000 without a word (the
    limits route said 20,000, a CLI user's 20,500-move program was refused at 20,000: stop
    61's CLI audit): a setting above its schema's bound now stops the start, named."""
    monkeypatch.setenv(variable, value)
    get_settings.cache_clear()
    try:
        with pytest.raises(SystemExit) as stopped:
            settings_or_exit()
    finally:
        get_settings.cache_clear()
    assert stopped.value.code == INVALID_SETTINGS
    assert capsys.readouterr().err == (
        f"error: {variable}={value!r}: Input should be less than or equal to {bound}\n"
    )


def test_the_schemas_own_bounds_are_said_as_the_limits_in_force() -> None:
    """The most cell objects and grid values a request meets, at their settings' bounds."""
    settings = Settings(max_path_waypoints=20_000, max_cell_objects=1_000)
    with served_with(settings), TestClient(app) as client:
        limits = client.get("/v1/limits").json()
        assert (limits["max_path_waypoints"], limits["max_cell_objects"]) == (20_000, 1_000)
        box = {"shape": "box", "size": [0.1, 0.1, 0.1], "pose": {"position": [2, 2, 2]}}
        cell = {"fixed": [box] * (limits["max_cell_objects"] + 1)}
        over = client.post("/v1/evaluate", json={**EXAMPLE, "cell": cell})
        assert over.status_code == 422 and "at most 1000 items" in over.text, over.text[:300]
        yaws = [0.0] * (limits["max_grid_values"] + 1)
        grid = {"x": {"min": 0, "max": 0, "step": 1}, "y": {"min": 0.4, "max": 0.4, "step": 1}}
        body = {**EXAMPLE, "grid": {**grid, "z": 0.1, "yaw": yaws}}
        del body["placement"]
        answer = client.post("/v1/map", json=body)
        assert answer.status_code == 422 and f"at most {len(yaws) - 1} items" in answer.text
