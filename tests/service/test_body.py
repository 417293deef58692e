"""Large bodies validated in pieces: the same model or the same 422 as one whole validation."""

from __future__ import annotations

import gzip
import json
from typing import Any

import pytest
from fastapi.testclient import TestClient
from pydantic import TypeAdapter, ValidationError

from service import body
from service.body import PIECE_WAYPOINTS, validated_in_pieces
from service.schemas import EvaluateRequest, MapRequest, OptimizeRequest, PathImportRequest
from service.schemas.jobs import JobRequest
from tests.cases import ROOT

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
N = 2 * PIECE_WAYPOINTS + 345  # three pieces, the last one short
DOWN = [1.0, 0.0, 0.0, 0.0]
POSES = {"waypoints": [{"position": [1e-5 * i, 0.0, 0.0], "orientation": DOWN} for i in range(N)]}
AXES = {
    "tool_axis_waypoints": [{"position": [1e-5 * i, 0.0, 0.0], "axis": [0, 0, 1]} for i in range(N)]
}
ROBOT, PLACEMENT = EXAMPLE["robot"], EXAMPLE["placement"]
AXIS = {"min": -0.1, "max": 0.1, "step": 0.1}
GRID = {"x": AXIS, "y": AXIS, "z": 0.1, "yaw": [0.0, 0.5]}
BOUNDS = {"x": [-0.1, 0.1], "y": [0.4, 0.5], "yaw": [-1.0, 1.0]}
BODIES: list[tuple[Any, dict[str, Any]]] = [
    (EvaluateRequest, {"robot": ROBOT, "placement": PLACEMENT}),
    (EvaluateRequest, {"robot": ROBOT, "placement": PLACEMENT, "spins": [0.0] * N}),
    (MapRequest, {"robot": ROBOT, "grid": GRID}),
    (OptimizeRequest, {"robot": ROBOT, "bounds": BOUNDS, "z": 0.1}),
    (PathImportRequest, {}),
    (JobRequest, {"kind": "evaluate", "request": {"robot": ROBOT, "placement": PLACEMENT}}),
    (JobRequest, {"kind": "map", "request": {"robot": ROBOT, "grid": GRID}}),
]


class Counted:
    """A piece validator that keeps the size of every piece it is given."""

    def __init__(self, adapter: TypeAdapter[Any]) -> None:
        self.adapter, self.sizes = adapter, []

    def validate_python(self, items: list[Any]) -> Any:
        self.sizes.append(len(items))
        return self.adapter.validate_python(items)


class Watched(TypeAdapter[Any]):
    """A TypeAdapter that counts its whole validations of JSON (the fall-back)."""

    whole = 0

    def validate_json(self, *args: Any, **kwargs: Any) -> Any:
        self.whole += 1
        return super().validate_json(*args, **kwargs)


def with_path(body: dict[str, Any], path: dict[str, Any]) -> dict[str, Any]:
    """The body with its path (a job's inside its request)."""
    if "request" in body:
        return {**body, "request": {**body["request"], "path": path}}
    return {**body, "path": path}


@pytest.mark.parametrize("path", [POSES, AXES], ids=["poses", "tool_axes"])
@pytest.mark.parametrize(("model", "rest"), BODIES, ids=[f"{i}" for i in range(len(BODIES))])
def test_a_body_in_pieces_is_the_whole_validations_model(
    model: Any, rest: dict[str, Any], path: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    raw = json.dumps(with_path(rest, path)).encode()
    counted = {name: Counted(adapter) for name, adapter in body.PIECES.items()}
    monkeypatch.setattr(body, "PIECES", counted)
    adapter = Watched(model)
    assert validated_in_pieces(adapter, raw) == TypeAdapter(model).validate_json(raw)
    assert adapter.whole == 0  # no fall-back to the whole validation
    (name,) = path
    assert counted[name].sizes == [PIECE_WAYPOINTS, PIECE_WAYPOINTS, N - 2 * PIECE_WAYPOINTS]


@pytest.mark.parametrize(
    ("where", "value", "loc"),
    [
        (1700, {"position": [0.0, 0.0], "orientation": DOWN}, [1700, "position"]),
        (2300, {"position": [0.0, 0.0, 0.0], "orientation": DOWN, "extra": 1}, [2300, "extra"]),
        (999, {"position": [0.0, 0.0, "a"], "orientation": DOWN}, [999, "position", 2]),
    ],
)
def test_a_bad_waypoint_in_a_piece_is_the_same_422(
    client: TestClient, where: int, value: dict[str, Any], loc: list[Any]
) -> None:
    waypoints = [*POSES["waypoints"]]
    waypoints[where] = value
    sent = {
        "robot": EXAMPLE["robot"],
        "placement": EXAMPLE["placement"],
        "path": {"waypoints": waypoints},
    }
    raw = json.dumps(sent).encode()
    with pytest.raises(ValidationError) as pieces:
        validated_in_pieces(EvaluateRequest, raw)
    with pytest.raises(ValidationError) as whole:
        EvaluateRequest.model_validate_json(raw)
    assert pieces.value.errors() == whole.value.errors()
    answer = client.post("/v1/evaluate", content=raw, headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"][0]["loc"][-len(loc) :] == loc
    assert answer.json()["detail"][0]["loc"][:3] == ["body", "path", "waypoints"]


def test_bad_json_is_the_same_error() -> None:
    raw = json.dumps({"path": POSES}).encode()[:-7]
    with pytest.raises(ValidationError) as pieces:
        validated_in_pieces(PathImportRequest, raw)
    with pytest.raises(ValidationError) as whole:
        PathImportRequest.model_validate_json(raw)
    assert pieces.value.errors() == whole.value.errors()


ROUTES = ["/v1/evaluate", "/v1/evaluate/png", "/v1/map", "/v1/map/png", "/v1/optimize"]
ROUTES += ["/v1/paths/import", "/v1/jobs", "/v1/dtf"]


@pytest.mark.parametrize("route", ROUTES)
def test_json_nested_too_deep_is_a_422_on_every_route(client: TestClient, route: str) -> None:
    """17,000 nested arrays (34 kB, over INLINE_BODY_BYTES): json.loads raised RecursionError."""
    raw = b"[" * 17_000 + b"]" * 17_000
    answer = client.post(route, content=raw, headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text[:300]
    assert answer.json()["detail"][0]["type"] == "json_invalid"


@pytest.mark.parametrize("route", ROUTES)
@pytest.mark.parametrize("large", [False, True], ids=["small", "large"])
def test_a_lone_surrogate_is_a_422_on_every_route(
    client: TestClient, route: str, large: bool
) -> None:
    r"""A string holding "\ud800" (no UTF-8 for it): /v1/dtf answered 500 (its error not writable).

    Large: the README example's path with 300 waypoints more (over INLINE_BODY_BYTES), whose
    pieces json.loads read, surrogate and all.
    """
    path = EXAMPLE["path"]
    if large:
        path = {"waypoints": path["waypoints"] + POSES["waypoints"][:300]}
    sent = json.dumps({"robot": {"model": "ur5"}, "path": path, "q": [0.0] * 6})
    raw = sent.replace('"ur5"', '"ur5\\ud800"').encode()
    assert (len(raw) > body.INLINE_BODY_BYTES) == large
    answer = client.post(route, content=raw, headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text[:300]
    assert answer.json()["detail"][0]["type"] == "json_invalid"


@pytest.mark.parametrize("large", [False, True], ids=["small", "large"])
def test_a_body_after_a_utf8_byte_order_mark_is_read(client: TestClient, large: bool) -> None:
    """RFC 8259 lets a parser ignore one (Windows tools write it); the answer was a 422 "Invalid
    JSON: expected value at line 1 column 1". Small (validated on the loop) and large (in
    pieces, in a thread) bodies alike: the same answer as without it."""
    example = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
    if large:
        example["path"] = {"waypoints": example["path"]["waypoints"] + POSES["waypoints"][:300]}
    raw = json.dumps(example).encode()
    assert (len(raw) > body.INLINE_BODY_BYTES) == large
    headers = {"content-type": "application/json"}
    plain = client.post("/v1/evaluate", content=raw, headers=headers)
    marked = client.post("/v1/evaluate", content=b"\xef\xbb\xbf" + raw, headers=headers)
    assert plain.status_code == 200, plain.text[:300]
    assert marked.status_code == 200, marked.text[:300]
    assert marked.json() == plain.json()


def test_a_compressed_body_is_a_415_naming_the_encoding(client: TestClient) -> None:
    """A gzip body was read as JSON: 422 'Invalid JSON', the encoding never named."""
    example = (ROOT / "examples" / "evaluate_request.json").read_bytes()
    answer = client.post(
        "/v1/evaluate",
        content=gzip.compress(example),
        headers={"content-type": "application/json", "content-encoding": "gzip"},
    )
    assert answer.status_code == 415
    detail = answer.json()["detail"][0]
    assert detail["loc"] == ["header", "content-encoding"] and "'gzip'" in detail["msg"]
    plain = client.post(
        "/v1/evaluate",
        content=example,
        headers={"content-type": "application/json", "content-encoding": "identity"},
    )
    assert plain.status_code == 200


@pytest.mark.parametrize(
    ("method", "url", "name"),
    [
        ("POST", "/v1/evaluate?detail=summary", "detail"),
        ("GET", "/v1/robots?family=ur", "family"),
        ("GET", "/v1/jobs?limit=2&stauts=done", "stauts"),
    ],
)
def test_a_query_parameter_an_operation_does_not_take_is_a_422(
    client: TestClient, method: str, url: str, name: str
) -> None:
    """FastAPI drops them: POST /v1/evaluate?detail=summary answered every waypoint."""
    example = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
    answer = client.request(method, url, json=example if method == "POST" else None)
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert [d["loc"] for d in detail] == [["query", name]]
    assert f"takes no query parameter {name!r}" in detail[0]["msg"]


@pytest.mark.parametrize(
    ("url", "name", "times"),
    [
        ("/v1/jobs?limit=1&limit=2", "limit", 2),
        ("/v1/jobs?status=done&kind=map&status=failed&status=done", "status", 3),
    ],
)
def test_a_query_parameter_given_twice_is_a_422(
    client: TestClient, url: str, name: str, times: int
) -> None:
    """The last was taken without a word (the hostile-input audit): ?limit=1&limit=2 listed 2."""
    answer = client.get(url)
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert [d["loc"] for d in detail] == [["query", name]]
    assert detail[0]["msg"] == f"{name!r} is given {times} times; give it once"


def test_the_page_its_docs_and_metrics_take_any_query_string(client: TestClient) -> None:
    for url in ("/?from=mail", "/docs?x=1", "/metrics?name[]=dtf_placements_total"):
        assert client.get(url).status_code == 200, url
    assert client.get("/v1/jobs?limit=2").status_code == 200
