"""Rules on one field are in the spec's JSON Schema, exactly as the service checks them (issue 26).

Each rule is checked both ways: the committed spec's schema (read by jsonschema_rs, the
validator schemathesis uses) and the service agree on a value at the rule's edge.
"""

from __future__ import annotations

import json
from typing import Any

import jsonschema_rs
import pytest
from fastapi.testclient import TestClient

from tests.cases import ROOT

SCHEMAS = json.loads((ROOT / "openapi" / "openapi.json").read_text())["components"]["schemas"]
EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())


def _valid(schema: dict[str, Any], value: Any) -> bool:
    return bool(jsonschema_rs.validator_for(schema).is_valid(value))


@pytest.mark.parametrize(
    ("component", "field", "zero"),
    [
        ("Pose", "orientation", [0.0, 0.0, 0.0, 0.0]),
        ("ToolAxisWaypoint", "axis", [0.0, -0.0, 0.0]),
        ("DtfRequest", "u_T", [0, 0, 0]),
    ],
)
def test_a_zero_vector_is_outside_the_schema(component: str, field: str, zero: list[float]) -> None:
    schema = SCHEMAS[component]["properties"][field]
    schema = next((s for s in schema.get("anyOf", []) if s.get("type") == "array"), schema)
    assert not _valid(schema, zero)
    tiny = [0.0] * (len(zero) - 1) + [1e-300]  # not zero: in the schema, refused by its norm
    assert _valid(schema, tiny) and _valid(schema, [0.0] * (len(zero) - 1) + [1.0])


def test_a_zero_quaternion_is_refused(client: TestClient) -> None:
    body = json.loads(json.dumps(EXAMPLE))
    body["path"]["waypoints"][1]["orientation"] = [0.0, 0.0, 0.0, 0.0]
    answer = client.post("/v1/evaluate", json=body)
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"][0]["loc"] == ["body", "path", "waypoints", 1, "orientation"]


@pytest.mark.parametrize(("solution", "whole"), [(24.0, True), (24, True), (24.5, False)])
def test_solution_is_any_whole_number(client: TestClient, solution: float, whole: bool) -> None:
    """JSON Schema's integer includes 24.0; the service refused it (strict int)."""
    assert _valid(SCHEMAS["NumericBranch"], {"solution": solution}) is whole
    body = {**EXAMPLE, "robot": {"model": "panda"}, "ik": {"branch": {"solution": solution}}}
    body["path"] = {"waypoints": EXAMPLE["path"]["waypoints"][:2]}
    answer = client.post("/v1/evaluate", json={**body, "detail": "summary"})
    assert answer.status_code == (200 if whole else 422), answer.text


@pytest.mark.parametrize(
    ("z", "bounds_z", "says"),
    [(None, None, "no height"), (0.1, [0.05, 0.15], "are both given")],
)
def test_the_height_message_says_which(
    client: TestClient, z: float | None, bounds_z: list[float] | None, says: str
) -> None:
    """Both missing was answered "give z or bounds.z, not both"."""
    bounds = {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3], "z": bounds_z}
    body = {"robot": EXAMPLE["robot"], "path": EXAMPLE["path"], "bounds": bounds, "z": z}
    answer = client.post("/v1/optimize", json=body)
    assert answer.status_code == 422, answer.text
    assert says in answer.json()["detail"][0]["msg"]
