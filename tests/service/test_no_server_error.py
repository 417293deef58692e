"""No input gives a 5xx: seeded mutations of every route's example body (api.md, Errors)."""

from __future__ import annotations

import copy
import random
from collections.abc import Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.main import app
from service.schemas import DtfRequest, EvaluateRequest, MapRequest, OptimizeRequest
from tests.service.test_errors import DELETE, changed

VALUES: list[Any] = [
    0,
    -1,
    1e308,
    -1e308,
    1e-320,
    1e30,
    10**30,
    -0.0,
    3.5,
    True,
    None,
    "x",
    "NaN",
    [],
    {},
    [0, 0, 0],
    [1, 0, 0, 0],
    [[1]],
    DELETE,
    DELETE,
]
ROUTES = {
    "/v1/dtf": DtfRequest,
    "/v1/evaluate": EvaluateRequest,
    "/v1/map": MapRequest,
    "/v1/optimize": OptimizeRequest,
}


def _paths(value: Any, prefix: tuple = ()) -> Iterator[tuple]:
    yield prefix
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for index, item in enumerate(value[:3]):
            yield from _paths(item, (*prefix, index))


def _mutate(body: Any, path: tuple, value: Any) -> Any:
    """``body`` with the value at ``path`` replaced or deleted; the root path swaps the body."""
    if not path:
        return body if value is DELETE else value
    return changed(body, {path: value})


@pytest.mark.parametrize("route", sorted(ROUTES))
def test_mutated_bodies_never_give_a_server_error(route: str) -> None:
    client = TestClient(app, raise_server_exceptions=False)
    example = copy.deepcopy(ROUTES[route].model_config["json_schema_extra"]["examples"][0])
    rng = random.Random(route)
    statuses = set()
    for _ in range(60):
        body = example
        for _ in range(rng.randint(1, 2)):
            body = _mutate(body, rng.choice(list(_paths(body))), rng.choice(VALUES))
        response = client.post(route, json=body)
        assert response.status_code < 500, (body, response.text)
        statuses.add(response.status_code)
    assert 422 in statuses
