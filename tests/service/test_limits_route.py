"""``GET /v1/limits``: the limits a request meets are the ones the service enforces."""

from __future__ import annotations

import json

from fastapi.testclient import TestClient

from service.config import Settings
from service.main import app
from service.schemas.limits import LIMIT_SETTINGS
from tests.cases import ROOT
from tests.service.conftest import served_with

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())


def test_the_limits_said_are_the_settings_served_and_enforced() -> None:
    # the body limit is the middleware's, read from the environment (its default here)
    settings = Settings(max_path_waypoints=7, max_mesh_triangles=3)
    with served_with(settings), TestClient(app) as client:
        limits = client.get("/v1/limits").json()
        assert set(limits) == set(LIMIT_SETTINGS)
        assert {name: limits[name] for name in LIMIT_SETTINGS} == {
            name: getattr(settings, name) for name in LIMIT_SETTINGS
        }
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


def test_each_limit_says_its_setting() -> None:
    schema = app.openapi()["components"]["schemas"]["LimitsResponse"]
    assert sorted(schema["required"]) == sorted(LIMIT_SETTINGS)
    for name in LIMIT_SETTINGS:
        said = schema["properties"][name]["description"]
        assert said.startswith(f"DTF_{name.upper()}: ") and len(said) > 30, (name, said)
