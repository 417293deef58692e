"""The committed openapi/openapi.json is the app's spec (regenerate: scripts/gen_openapi.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from fastapi.testclient import TestClient

from service.main import app

SPEC_PATH = Path(__file__).resolve().parents[1] / "openapi" / "openapi.json"


def test_committed_spec_matches_the_app() -> None:
    committed = json.loads(SPEC_PATH.read_text())
    generated = json.loads(json.dumps(app.openapi()))
    assert committed == generated, "openapi/openapi.json is stale: run scripts/gen_openapi.py"


def test_routes_are_in_the_spec() -> None:
    paths = json.loads(SPEC_PATH.read_text())["paths"]
    routes = {"/healthz", "/v1/robots", "/v1/dtf", "/v1/evaluate", "/v1/map", "/v1/optimize"}
    assert routes <= set(paths)


def test_operation_ids_are_short_and_the_png_is_binary() -> None:
    """Issue 9: generated clients call dtf(), evaluate(), ... and get bytes for the PNG."""
    spec = app.openapi()
    operations = {
        operation["operationId"] for path in spec["paths"].values() for operation in path.values()
    }
    assert operations == {
        "health",
        "list_robots",
        "dtf",
        "evaluate",
        "evaluate_png",
        "map",
        "map_png",
        "import_path",
        "optimize",
        "submit_job",
        "list_jobs",
        "get_job",
        "get_job_result",
        "cancel_job",
        "delete_job",
        "metrics",
    }
    for route in ("/v1/map/png", "/v1/evaluate/png"):
        answer = spec["paths"][route]["post"]["responses"]["200"]["content"]
        assert answer == {"image/png": {"schema": {"type": "string", "format": "binary"}}}
    for route in ("/v1/map", "/v1/evaluate"):  # one content type an operation (Accept unsaid)
        assert list(spec["paths"][route]["post"]["responses"]["200"]["content"]) == [
            "application/json"
        ]


def test_docs_are_served_offline() -> None:
    """Issue 9: /docs and /redoc load their assets from the app, never from a CDN."""
    client = TestClient(app)
    for page in ("/docs", "/redoc"):
        html = client.get(page).text
        assets = re.findall(r'(?:src|href)="([^"]+)"', html)
        assert assets and all(a.startswith("/") for a in assets), (page, assets)
        for asset in assets:
            assert client.get(asset).status_code == 200, asset
    description = app.openapi()["info"]["description"]
    for route in ("/healthz", "/v1/robots", "/v1/dtf", "/v1/evaluate", "/v1/map", "/v1/optimize"):
        assert f" {route}`" in description, route
