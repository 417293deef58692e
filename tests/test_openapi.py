"""The committed openapi/openapi.json is the app's spec (regenerate: scripts/gen_openapi.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
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
        "get_limits",
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
        "get_job_request",
        "get_job_png",
        "cancel_job",
        "delete_job",
        "metrics",
    }
    for route, method in (
        ("/v1/map/png", "post"),
        ("/v1/evaluate/png", "post"),
        ("/v1/jobs/{job_id}/png", "get"),
    ):
        answer = spec["paths"][route][method]["responses"]["200"]["content"]
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


WORD_RULES = {
    # Issue 26: rules the JSON Schema cannot state (one field against another, a length or a
    # name that depends on the robot), stated where a client's author reads the field; the
    # contract test's hooks (tests/contract_hooks.py) meet them in the generated requests.
    "lower == upper joint limits": ("OpwRobot", "joint_position_limits", "lower < upper"),
    "a catalogue arm's lists of another length": (
        "CatalogueRobot",
        "joint_velocity_limits",
        "one per joint",
    ),
    "a URDF arm's lists of another length": ("UrdfRobot", "joint_velocity_limits", "one per joint"),
    "spins of another length": ("EvaluateRequest", "spins", "one per waypoint"),
    "repeated poses": ("PosePath", "waypoints", "consecutive ones distinct"),
    "repeated tool points": ("ToolAxisPath", "tool_axis_waypoints", "consecutive ones distinct"),
    "a string that is no URDF": ("UrdfRobot", "urdf", "URDF document"),
    "a UR branch on an OPW arm": (
        "IkPolicy",
        "branch",
        "GET /v1/robots lists each robot's branches",
    ),
    "a start outside the bounds": ("OptimizeRequest", "start", "inside the bounds"),
}


@pytest.mark.parametrize("rule", list(WORD_RULES))
def test_each_rule_in_words_is_in_the_committed_spec(rule: str) -> None:
    component, field, words = WORD_RULES[rule]
    spec = json.loads(SPEC_PATH.read_text())
    description = spec["components"]["schemas"][component]["properties"][field]["description"]
    assert words in re.sub(r"\s+", " ", description), (rule, description)


def test_the_height_rule_is_in_the_optimize_description() -> None:
    """z and bounds.z both given or both missing: the one rule kept out of the contract test."""
    description = json.loads(SPEC_PATH.read_text())["paths"]["/v1/optimize"]["post"]["description"]
    assert "exactly one of them (both or neither is a 422)" in re.sub(r"\s+", " ", description)


def test_every_error_answer_declares_its_json_body() -> None:
    """Every 4xx and 5xx of every operation declares the ErrorResponse it sends (audit 25: a 409
    declared without a body was parsed as None by the generated client, its reason lost)."""
    spec = json.loads(SPEC_PATH.read_text())
    bare = [
        (method.upper(), path, code)
        for path, operations in spec["paths"].items()
        for method, operation in operations.items()
        for code, answer in operation["responses"].items()
        if code[0] in "45"
        and answer.get("content", {}).get("application/json", {}).get("schema")
        != {"$ref": "#/components/schemas/ErrorResponse"}
    ]
    assert not bare


def test_every_schema_has_a_description_and_an_example_and_every_parameter_a_description() -> None:
    """api.md: every schema has a description and an example (audit 25: seven enums had none,
    two query parameters of GET /v1/jobs no description)."""
    spec = json.loads(SPEC_PATH.read_text())
    schemas = spec["components"]["schemas"]
    bare = [
        name
        for name, schema in schemas.items()
        if "description" not in schema or not schema.get("examples", [schema.get("example")])[0]
    ]
    assert not bare
    unsaid = [
        (method.upper(), path, parameter["name"])
        for path, operations in spec["paths"].items()
        for method, operation in operations.items()
        for parameter in operation.get("parameters", [])
        if not parameter.get("description")
    ]
    assert not unsaid


def test_a_jobs_id_is_typed_as_the_job_routes_take_it() -> None:
    """JobInfo.id has the format of every {job_id} path parameter, so a generated client passes
    a submitted job's id to the job routes as it is (audit 25: a str against a UUID)."""
    spec = json.loads(SPEC_PATH.read_text())
    formats = {
        parameter["schema"].get("format")
        for operations in spec["paths"].values()
        for operation in operations.values()
        for parameter in operation.get("parameters", [])
        if parameter["name"] == "job_id"
    }
    assert formats == {"uuid"}
    assert spec["components"]["schemas"]["JobInfo"]["properties"]["id"]["format"] == "uuid"
