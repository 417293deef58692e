"""Every error case of api.md: a 422 (413 for size) whose detail names the field."""

from __future__ import annotations

import asyncio
import copy
import json
import logging
import re
from collections.abc import Callable
from typing import Any

import httpx
import pytest
from fastapi.testclient import TestClient
from starlette.requests import Request
from starlette.types import Message, Receive, Scope, Send

from service.body_limits import BodySizeLimitMiddleware
from service.convert import wants_png
from service.errors import cancelled_handler
from service.work import STOPPING
from solver.core.progress import Cancelled
from tests.cases import EXAMPLES, ROOT

DELETE = object()
RAW = "__raw__"  # stands for a token JSON writers refuse (NaN, Infinity), spliced into the text

Loc = list[str | int]
Changes = dict[tuple[str | int, ...], Any]


def changed(body: dict[str, Any], changes: Changes) -> dict[str, Any]:
    """A copy of ``body`` with the value at each path replaced (or deleted)."""
    new = copy.deepcopy(body)
    for path, value in changes.items():
        parent = new
        for key in path[:-1]:
            parent = parent[key]
        if value is DELETE:
            del parent[path[-1]]
        else:
            parent[path[-1]] = value
    return new


def assert_names(response: httpx.Response, status: int, loc: Loc) -> None:
    """``response`` has ``status`` and FastAPI-shaped detail, one entry at (or under) ``loc``."""
    assert response.status_code == status, response.text
    detail = response.json()["detail"]
    assert all(set(entry) == {"loc", "msg", "type"} for entry in detail), detail
    assert any(entry["loc"][: len(loc)] == loc for entry in detail), detail


@pytest.fixture
def path_body(evaluate_body: dict[str, Any]) -> dict[str, Any]:
    """The evaluate body with the first five waypoints of the example path."""
    example = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    evaluate_body["path"]["waypoints"] = example["path"]["waypoints"][:5]
    return evaluate_body


WAYPOINTS = ("path", "waypoints")

DTF_CASES: list[tuple[str, Changes, Loc]] = [
    ("q not a list", {("q",): "abc"}, ["body", "q"]),
    ("q too short", {("q",): [0.1] * 5}, ["body", "q"]),
    ("q beyond the joint limits", {("q", 1): 7.0}, ["body", "q"]),
    ("number as a string", {("q", 2): "0.1"}, ["body", "q", 2]),
    ("u_T of 2 numbers", {("u_T",): [1.0, 0.0]}, ["body", "u_T"]),
    ("u_T not unit", {("u_T",): [1.0, 1.0, 0.0]}, ["body", "u_T"]),
    ("u_R missing with finite h", {("u_R",): DELETE}, ["body", "u_R"]),
    ("h negative", {("h",): -0.1}, ["body", "h"]),
    ("unknown method", {("method",): "newton"}, ["body", "method"]),
    (
        "closed form at a singular q",
        {("q",): [0.0] * 6, ("method",): "closed_form"},
        ["body", "method"],
    ),
    ("unknown field", {("robot", "colour"): "blue"}, ["body", "robot", "colour"]),
    ("robot without model or urdf", {("robot",): {}}, ["body", "robot"]),
    ("model and urdf", {("robot", "urdf"): "<robot/>"}, ["body", "robot"]),
    ("frame with model", {("robot", "base_frame"): "base"}, ["body", "robot", "base_frame"]),
    ("unknown robot", {("robot", "model"): "ur99"}, ["body", "robot", "model"]),
    (
        "zero limit",
        {("robot", "joint_velocity_limits"): [1.0, 1.0, 0.0, 1.0, 1.0, 1.0]},
        ["body", "robot", "joint_velocity_limits", 2],
    ),
    (
        "negative limit",
        {("robot", "joint_velocity_limits"): [1.0, 1.0, 1.0, -2.0, 1.0, 1.0]},
        ["body", "robot", "joint_velocity_limits", 3],
    ),
    (
        "limits of the wrong length",
        {("robot", "joint_velocity_limits"): [1.0] * 5},
        ["body", "robot", "joint_velocity_limits"],
    ),
    (
        "non-unit tcp quaternion",
        {("robot", "tcp"): {"position": [0.0, 0.0, 0.1], "orientation": [0, 0, 0, 1.002]}},
        ["body", "robot", "tcp", "orientation"],
    ),
]


@pytest.mark.parametrize(
    ("changes", "loc"), [case[1:] for case in DTF_CASES], ids=[case[0] for case in DTF_CASES]
)
def test_dtf_bad_input(
    client: TestClient, dtf_body: dict[str, Any], changes: Changes, loc: Loc
) -> None:
    assert_names(client.post("/v1/dtf", json=changed(dtf_body, changes)), 422, loc)


EVALUATE_CASES: list[tuple[str, Changes, Loc]] = [
    ("placement without yaw", {("placement", "yaw"): DELETE}, ["body", "placement", "yaw"]),
    ("placement x as a string", {("placement", "x"): "0.1"}, ["body", "placement", "x"]),
    ("path not a list", {WAYPOINTS: {"0": {}}}, ["body", "path", "waypoints"]),
    (
        "position of 2 numbers",
        {(*WAYPOINTS, 3, "position"): [0.1, 0.2]},
        ["body", "path", "waypoints", 3, "position"],
    ),
    (
        "non-unit quaternion",
        {(*WAYPOINTS, 3, "orientation"): [1.0, 0.0, 0.0, 0.1]},
        ["body", "path", "waypoints", 3, "orientation"],
    ),
    (
        "zero quaternion",
        {(*WAYPOINTS, 3, "orientation"): [0, 0, 0, 0]},
        ["body", "path", "waypoints", 3, "orientation"],
    ),
    ("one waypoint", {WAYPOINTS: []}, ["body", "path", "waypoints"]),
    ("unknown branch", {("ik", "branch"): "best"}, ["body", "ik", "branch"]),
    (
        "unknown shoulder",
        {("ik", "branch"): {"shoulder": "middle", "elbow": "up", "wrist": "flip"}},
        ["body", "ik", "branch"],
    ),
    (
        "OPW branch name for a UR arm",
        {("ik", "branch"): {"shoulder": "front", "elbow": "up", "wrist": "flip"}},
        ["body", "ik", "branch"],
    ),
    ("zero joint step", {("ik", "max_joint_step"): 0.0}, ["body", "ik", "max_joint_step"]),
    ("unknown field", {("speed",): 1.0}, ["body", "speed"]),
    ("unknown robot", {("robot", "model"): "kuka"}, ["body", "robot", "model"]),
    (
        "zero limit",
        {("robot", "joint_velocity_limits"): [3.0, 3.0, 3.0, 3.0, 3.0, 0.0]},
        ["body", "robot", "joint_velocity_limits", 5],
    ),
    (
        "limits of the wrong length",
        {("robot", "joint_velocity_limits"): [3.0] * 7},
        ["body", "robot", "joint_velocity_limits"],
    ),
    (
        "position near the float limit",
        {(*WAYPOINTS, 2, "position"): [1e308, 0.0, 0.0]},
        ["body", "path", "waypoints", 2],
    ),
    ("placement in millimetres", {("placement", "y"): 4500.0}, ["body", "placement"]),
    (
        "huge speed limits",
        {("robot", "joint_velocity_limits"): [1e30] * 6},
        ["body", "robot", "joint_velocity_limits"],
    ),
]


@pytest.mark.parametrize(
    ("changes", "loc"),
    [case[1:] for case in EVALUATE_CASES],
    ids=[case[0] for case in EVALUATE_CASES],
)
def test_evaluate_bad_input(
    client: TestClient, path_body: dict[str, Any], changes: Changes, loc: Loc
) -> None:
    assert_names(client.post("/v1/evaluate", json=changed(path_body, changes)), 422, loc)


def test_foreign_branch_name_lists_the_valid_ones(
    client: TestClient, path_body: dict[str, Any]
) -> None:
    branch = {"shoulder": "back", "elbow": "down", "wrist": "noflip"}
    response = client.post("/v1/evaluate", json=changed(path_body, {("ik", "branch"): branch}))
    assert_names(response, 422, ["body", "ik", "branch"])
    message = response.json()["detail"][0]["msg"]
    assert "shoulder=back" in message
    assert "{shoulder=left, elbow=up, wrist=noflip}" in message
    assert "{shoulder=right, elbow=down, wrist=flip}" in message


def test_one_waypoint_is_refused(client: TestClient, path_body: dict[str, Any]) -> None:
    body = changed(path_body, {WAYPOINTS: path_body["path"]["waypoints"][:1]})
    assert_names(client.post("/v1/evaluate", json=body), 422, ["body", "path", "waypoints"])


def test_repeated_waypoint_names_its_index(client: TestClient, path_body: dict[str, Any]) -> None:
    body = changed(path_body, {(*WAYPOINTS, 3): path_body["path"]["waypoints"][2]})
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", "path", "waypoints", 3])
    assert response.json()["detail"][0]["type"] == "repeated_waypoint"


NON_FINITE_CASES: list[tuple[str, tuple[str | int, ...], str, Loc]] = [
    ("/v1/dtf", ("q", 1), "NaN", ["body", "q", 1]),
    ("/v1/dtf", ("h",), "Infinity", ["body", "h"]),
    ("/v1/dtf", ("u_T", 0), "-Infinity", ["body", "u_T", 0]),
    ("/v1/dtf", ("robot", "joint_velocity_limits"), "[1e999]", ["body", "robot"]),
    ("/v1/evaluate", (*WAYPOINTS, 1, "position", 2), "NaN", [*WAYPOINTS, 1, "position", 2]),
    ("/v1/evaluate", (*WAYPOINTS, 0, "orientation", 3), "NaN", [*WAYPOINTS, 0, "orientation", 3]),
    ("/v1/evaluate", ("placement", "yaw"), "1e999", ["body", "placement", "yaw"]),
    ("/v1/evaluate", ("ik", "max_joint_step"), "Infinity", ["body", "ik", "max_joint_step"]),
]


@pytest.mark.parametrize(("url", "path", "token", "loc"), NON_FINITE_CASES)
def test_non_finite_numbers_are_refused(
    client: TestClient,
    dtf_body: dict[str, Any],
    evaluate_body: dict[str, Any],
    url: str,
    path: tuple[str | int, ...],
    token: str,
    loc: Loc,
) -> None:
    body = dtf_body if url == "/v1/dtf" else evaluate_body
    text = json.dumps(changed(body, {path: RAW})).replace(f'"{RAW}"', token)
    assert token in text
    response = client.post(url, content=text, headers={"content-type": "application/json"})
    if loc[0] != "body":
        loc = ["body", *loc]
    assert_names(response, 422, loc)


UrdfRobot = Callable[[str], dict[str, Any]]
URDF_CASES: list[tuple[str, UrdfRobot, Loc]] = [
    (
        "malformed URDF",
        lambda urdf: {"urdf": urdf[:200], "base_frame": "panda_link0", "tool_frame": "panda_link8"},
        ["body", "robot", "urdf"],
    ),
    (
        "tool frame not in the URDF",
        lambda urdf: {"urdf": urdf, "base_frame": "panda_link0", "tool_frame": "flange"},
        ["body", "robot", "tool_frame"],
    ),
    (
        "base frame not in the URDF",
        lambda urdf: {"urdf": urdf, "base_frame": "world", "tool_frame": "panda_link8"},
        ["body", "robot", "base_frame"],
    ),
    (
        "base frame that moves",
        lambda urdf: {"urdf": urdf, "base_frame": "panda_link3", "tool_frame": "panda_link8"},
        ["body", "robot", "base_frame"],
    ),
    (
        "base frame missing",
        lambda urdf: {"urdf": urdf, "tool_frame": "panda_link8"},
        ["body", "robot", "base_frame"],
    ),
    (
        "limits of the wrong length",
        lambda urdf: {
            "urdf": urdf,
            "base_frame": "panda_link0",
            "tool_frame": "panda_link8",
            "joint_velocity_limits": [2.0] * 6,
        },
        ["body", "robot", "joint_velocity_limits"],
    ),
]


@pytest.mark.parametrize(
    ("robot", "loc"), [case[1:] for case in URDF_CASES], ids=[case[0] for case in URDF_CASES]
)
def test_bad_urdf_robot(client: TestClient, panda_urdf: str, robot: UrdfRobot, loc: Loc) -> None:
    body = {"robot": robot(panda_urdf), "q": [0.0] * 7, "u_T": [1, 0, 0], "u_R": None, "h": None}
    assert_names(client.post("/v1/dtf", json=body), 422, loc)


@pytest.mark.parametrize("route", ["/v1/evaluate", "/v1/map", "/v1/optimize"])
def test_urdf_chain_of_five_joints_cannot_follow_a_path(
    client: TestClient, evaluate_body: dict[str, Any], panda_urdf: str, route: str
) -> None:
    """Numeric IK solves six-dimensional poses: a chain to panda_link5 has five joints."""
    robot = {"urdf": panda_urdf, "base_frame": "panda_link0", "tool_frame": "panda_link5"}
    body = {**evaluate_body, "robot": robot}
    if route != "/v1/evaluate":
        del body["placement"], body["ik"]
        body |= (
            {
                "grid": {
                    "x": {"min": 0.0, "max": 0.0, "step": 0.1},
                    "y": {"min": 0.4, "max": 0.4, "step": 0.1},
                    "z": 0.1,
                    "yaw": [0.0],
                }
            }
            if route == "/v1/map"
            else {"bounds": {"x": [0.0, 0.1], "y": [0.4, 0.5], "yaw": [0.0, 0.0]}, "z": 0.1}
        )
    response = client.post(route, json=body)
    assert_names(response, 422, ["body", "robot"])
    assert response.json()["detail"][0]["type"] == "no_analytic_ik"
    assert "six joints or more" in response.json()["detail"][0]["msg"]


@pytest.mark.parametrize(
    "content",
    [
        b"",
        b'{"robot": ',
        b"[1, 2]",
        b'{"robot": "\xff"}',  # not UTF-8
        b"[" * 100_000 + b"]" * 100_000,  # nested deeper than the JSON parser goes
    ],
    ids=["empty", "truncated", "array", "not UTF-8", "deep"],
)
def test_body_that_is_not_a_json_object(client: TestClient, content: bytes) -> None:
    response = client.post("/v1/dtf", content=content, headers={"content-type": "application/json"})
    assert_names(response, 422, ["body"])


def test_oversized_body_is_413(client: TestClient, dtf_body: dict[str, Any]) -> None:
    padded = {**dtf_body, "robot": {"model": "ur5e", "urdf": "x" * 2_000_001}}
    assert_names(client.post("/v1/dtf", json=padded), 413, ["body"])


def test_body_limit_is_a_setting(
    client: TestClient, body_limit: int, dtf_body: dict[str, Any], path_body: dict[str, Any]
) -> None:
    assert len(json.dumps(dtf_body)) < body_limit
    assert client.post("/v1/dtf", json=dtf_body).status_code == 200
    assert len(json.dumps(path_body)) > body_limit
    assert_names(client.post("/v1/evaluate", json=path_body), 413, ["body"])


def test_chunked_body_is_counted(client: TestClient, body_limit: int) -> None:
    chunks = [b" " * 400] * 3  # no Content-Length: Transfer-Encoding chunked
    response = client.post(
        "/v1/dtf", content=iter(chunks), headers={"content-type": "application/json"}
    )
    assert "content-length" not in response.request.headers
    assert_names(response, 413, ["body"])


def run_middleware(chunks: list[bytes]) -> tuple[list[Message], list[bytes]]:
    """Stream ``chunks`` through the middleware; return what it sent and what the app read."""
    received: list[bytes] = []
    sent: list[Message] = []
    messages = [
        {"type": "http.request", "body": chunk, "more_body": i < len(chunks) - 1}
        for i, chunk in enumerate(chunks)
    ]

    async def app(scope: Scope, receive: Receive, send: Send) -> None:
        received.append((await receive())["body"])

    async def receive() -> Message:
        return messages.pop(0)

    async def send(message: Message) -> None:
        sent.append(message)

    scope: Scope = {"type": "http", "method": "POST", "path": "/", "headers": []}
    asyncio.run(BodySizeLimitMiddleware(app)(scope, receive, send))
    return sent, received


def test_middleware_counts_streamed_bytes(body_limit: int) -> None:
    sent, received = run_middleware([b"a" * 400] * 3)
    assert received == []  # the app never ran
    assert sent[0]["status"] == 413


def test_middleware_hands_on_the_whole_body(body_limit: int) -> None:
    sent, received = run_middleware([b"a" * 200, b"b" * 200])
    assert sent == []
    assert received == [b"a" * 200 + b"b" * 200]


def test_a_body_its_client_left_is_answered_499_and_logged(
    body_limit: int, caplog: pytest.LogCaptureFixture
) -> None:
    """The middleware returned without an answer, which /metrics counted as a server error
    (5xx), and logged nothing (the soak audit of stop 61): a 499 nobody hears, and a line."""
    messages: list[Message] = [
        {"type": "http.request", "body": b"a" * 100, "more_body": True},
        {"type": "http.disconnect"},
    ]
    sent: list[Message] = []
    ran: list[bool] = []

    async def app(scope: Scope, receive: Receive, send: Send) -> None:
        ran.append(True)

    async def receive() -> Message:
        return messages.pop(0)

    async def send(message: Message) -> None:
        sent.append(message)

    scope: Scope = {"type": "http", "method": "POST", "path": "/v1/map", "headers": []}
    with caplog.at_level(logging.INFO, logger="dtf.requests"):
        asyncio.run(BodySizeLimitMiddleware(app)(scope, receive, send))
    assert ran == [] and sent[0]["status"] == 499
    assert caplog.messages == [
        "POST /v1/map 499: its body stopped after 100 bytes, its client left"
    ]


# Finite but extreme numbers: each is either answered (200) or refused naming its field (422),
# never a 5xx.
EXTREME_DTF_CASES = [
    pytest.param({("h",): 1e-320}, ["body", "h"], id="subnormal h"),
    pytest.param({("h",): 1e-300}, None, id="tiny h"),
    pytest.param({("h",): 1e-200, ("method",): "lp"}, None, id="tiny h, lp"),
    pytest.param(
        {
            ("h",): None,
            ("u_R",): None,
            ("method",): "lp",
            ("robot", "joint_velocity_limits"): [1e30] * 6,
        },
        ["body", "robot", "joint_velocity_limits", 0],
        id="huge limits, lp",
    ),
    pytest.param({("h",): 1e300}, None, id="huge h"),
    pytest.param(
        {("robot", "joint_velocity_limits"): [1e-300] * 6},
        ["body", "robot", "joint_velocity_limits", 0],
        id="tiny limits",
    ),
]


@pytest.mark.parametrize(("changes", "refused_at"), EXTREME_DTF_CASES)
def test_extreme_numbers_are_not_a_server_error(
    client: TestClient, dtf_body: dict[str, Any], changes: Changes, refused_at: list[str] | None
) -> None:
    response = client.post("/v1/dtf", json=changed(dtf_body, changes))
    if refused_at is None:
        assert response.status_code == 200, response.text
        assert response.json()["v_max"] > 0
    else:
        assert response.status_code == 422, response.text
        assert response.json()["detail"][0]["loc"] == refused_at


def test_a_segment_turning_by_a_half_turn_is_refused(client: TestClient) -> None:
    """Issue 9's request: the sign of u_R came from rounding, so map and evaluate disagreed."""
    path = {
        "waypoints": [
            {"position": [0, 0, 0], "orientation": [1, 0, 0, 0]},
            {"position": [0.01, 0, 0], "orientation": [0, 1, 0, 0]},
        ]
    }
    body = {
        "robot": {"model": "ur5"},
        "path": path,
        "placement": {"x": 0.0, "y": 0.4, "z": 0.1, "yaw": 0.15},
        "ik": {"max_joint_step": 3.5},
    }
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", "path", "waypoints", 1])
    assert "half turn" in response.json()["detail"][0]["msg"]
    optimize = {
        "robot": {"model": "ur5"},
        "path": path,
        "bounds": {"x": [0, 0.02], "y": [0.4, 0.45], "yaw": [0.1, 0.2]},
        "z": 0.1,
        "ik": {"max_joint_step": 3.5},
    }
    assert_names(client.post("/v1/optimize", json=optimize), 422, ["body", "path", "waypoints", 1])


def test_h_left_out_is_pure_translation(client: TestClient, dtf_body: dict[str, Any]) -> None:
    """Issue 9: a generated client need not send h = null for pure translation."""
    explicit = client.post("/v1/dtf", json={**dtf_body, "h": None, "u_R": None}).json()
    left_out = changed(dtf_body, {("h",): DELETE, ("u_R",): DELETE})
    answer = client.post("/v1/dtf", json=left_out)
    assert answer.status_code == 200, answer.text
    assert answer.json() == explicit and answer.json()["omega_max"] == 0.0


@pytest.mark.parametrize("content_type", ["text/plain", "application/x-www-form-urlencoded"])
def test_a_body_that_is_not_json_is_415(
    client: TestClient, dtf_body: dict[str, Any], content_type: str
) -> None:
    response = client.post(
        "/v1/dtf", content=json.dumps(dtf_body), headers={"content-type": content_type}
    )
    assert response.status_code == 415, response.text
    assert response.json()["detail"][0]["loc"] == ["header", "content-type"]
    charset = {"content-type": "application/json; charset=utf-8"}
    assert client.post("/v1/dtf", content=json.dumps(dtf_body), headers=charset).status_code == 200


@pytest.mark.parametrize(
    ("accept", "png"),
    [
        ("image/png", True),
        ("*/*", False),
        ("image/png, application/json;q=0.5", True),
        ("image/png;q=0.5, application/json", False),
        ("image/png, */*", True),
        ("image/*", True),
        ("image/png;q=0", False),
        ("text/html", False),
    ],
)
def test_accept_is_parsed_with_q_values(accept: str, png: bool) -> None:
    assert wants_png(accept) is png


def test_messages_say_plain_numbers_and_cut_echoes(
    client: TestClient, dtf_body: dict[str, Any], path_body: dict[str, Any]
) -> None:
    """Issue 9: no np.float64(...) in messages, a 1e-200 vector's norm is 1e-200, a huge
    unknown model name is not echoed whole, a far grid names grid.x."""
    tiny = client.post("/v1/dtf", json={**dtf_body, "u_T": [1e-200, 0.0, 0.0]})
    assert_names(tiny, 422, ["body", "u_T"])
    assert "norm is 1e-200" in tiny.json()["detail"][0]["msg"]
    outside = client.post("/v1/dtf", json={**dtf_body, "q": [9.0, 0, 0, 0, 0, 0]})
    assert "np.float64" not in outside.text and "9 rad" in outside.text
    name = "x" * 100_000
    unknown = client.post("/v1/evaluate", json=changed(path_body, {("robot", "model"): name}))
    assert_names(unknown, 422, ["body", "robot", "model"])
    assert len(unknown.content) < 2_000
    grid = {
        "x": {"min": 1e10, "max": 1e10, "step": 0.1},
        "y": {"min": 0.4, "max": 0.4, "step": 0.1},
        "z": 0.1,
        "yaw": 0.0,
    }
    body = {"robot": path_body["robot"], "path": path_body["path"], "grid": grid}
    assert_names(client.post("/v1/map", json=body), 422, ["body", "grid", "x"])


def test_every_field_name_is_a_word_no_union_tag_is() -> None:
    """request_location leaves out the loc parts of union variants by their form (a colon, a
    bracket, a hyphen, a bare type name): no field of the API has that form."""
    spec = json.loads((ROOT / "openapi" / "openapi.json").read_text())
    names: set[str] = set()

    def walk(node: Any) -> None:
        if isinstance(node, dict):
            names.update(
                node.get("properties", {}) if isinstance(node.get("properties"), dict) else {}
            )
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)

    walk(spec)
    assert len(names) > 100
    assert [n for n in names if not re.fullmatch(r"[a-z][a-z0-9_]*|[a-z]+_[A-Z]", n)] == []
    assert names.isdisjoint({"float", "int", "str", "bool"})


@pytest.mark.parametrize(
    ("yaw", "loc"), [([0.0, 5000.0], ["body", "grid", "yaw", 1]), (5000.0, ["body", "grid", "yaw"])]
)
def test_a_bad_yaw_is_named_once_where_it_is(client: TestClient, yaw: Any, loc: list[Any]) -> None:
    """grid.yaw takes a number or a list: pydantic's loc carried its type names
    ('list[constrained-float]'), and each variant's error was given ('not a valid number' of
    a list, 'not a valid array' of a number)."""
    body = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
    grid: dict[str, Any] = {"x": {"min": 0.0, "max": 0.1, "step": 0.1}}
    grid["y"] = {"min": 0.4, "max": 0.5, "step": 0.1}
    answer = client.post(
        "/v1/map",
        json={
            "robot": body["robot"],
            "path": body["path"],
            "grid": {**grid, "z": 0.1, "yaw": yaw},
        },
    )
    assert answer.status_code == 422
    (detail,) = answer.json()["detail"]
    assert detail["loc"] == loc and detail["msg"] == "Input should be less than or equal to 1000"


def test_work_stopped_says_whether_its_client_left_or_the_service_stops(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """Both were 'the service is shutting down': a proxy or a log read the wrong cause. And a
    client that left was answered 503, which nobody heard and /metrics counted as a server
    error, with no log line (the soak audit of stop 61): 499, and a line naming the request."""
    scope = {"type": "http", "method": "POST", "path": "/v1/map", "headers": []}

    def said(request: Request) -> tuple[int, str | None, str]:
        answer = asyncio.run(cancelled_handler(request, Cancelled()))
        message = str(json.loads(answer.body)["detail"][0]["msg"])
        return answer.status_code, answer.headers.get("Retry-After"), message

    with caplog.at_level(logging.INFO, logger="dtf.requests"):
        left = said(Request(scope))
    assert left == (499, None, "the work was stopped: its client left")
    assert caplog.messages == [
        "POST /v1/map 499: its work was stopped, its client left",
    ]
    STOPPING.set()
    try:
        stopping = said(Request(scope))
    finally:
        STOPPING.clear()
    assert stopping == (503, "5", "the work was stopped: the service is shutting down")
