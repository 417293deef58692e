"""CORS: pages of the origins DTF_CORS_ORIGINS names may call the API from a browser; no others.

The expected headers are the Fetch standard's CORS protocol (a preflight's answer names the
origin, allows the method and headers asked; an answer names the origin and the headers a page
may read), read from the answers as a browser reads them.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient
from pydantic import ValidationError

from service.config import Settings, get_settings
from service.cors import EXPOSED, PREFLIGHT_SECONDS
from service.main import app

CAM = "https://cam.example.com"
PREFLIGHT = {
    "Access-Control-Request-Method": "POST",
    "Access-Control-Request-Headers": "content-type",
}


@pytest.fixture(autouse=True)
def _settings_read_again() -> Iterator[None]:
    """Each test's DTF_CORS_ORIGINS (monkeypatch undoes it) is not kept past the test."""
    yield
    get_settings.cache_clear()


def set_origins(monkeypatch: pytest.MonkeyPatch, value: str) -> None:
    """DTF_CORS_ORIGINS set through the environment, as a deployment would."""
    monkeypatch.setenv("DTF_CORS_ORIGINS", value)
    get_settings.cache_clear()


@pytest.fixture
def origins(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two named origins."""
    set_origins(monkeypatch, f"{CAM}, http://localhost:3000")


@pytest.fixture
def client() -> TestClient:
    return TestClient(app)


def test_without_the_setting_no_page_elsewhere_may_call(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    answer = client.post("/v1/evaluate", json=evaluate_body, headers={"Origin": CAM})
    assert answer.status_code == 200
    assert "access-control-allow-origin" not in answer.headers
    preflight = client.options("/v1/evaluate", headers={"Origin": CAM, **PREFLIGHT})
    assert preflight.status_code == 405  # as any OPTIONS request, the service's JSON error
    assert "access-control-allow-origin" not in preflight.headers
    assert isinstance(preflight.json()["detail"], list)


@pytest.mark.usefixtures("origins")
def test_a_named_origins_preflight_allows_the_method_and_headers_asked(client: TestClient) -> None:
    preflight = client.options("/v1/evaluate", headers={"Origin": CAM, **PREFLIGHT})
    assert preflight.status_code == 200
    assert preflight.headers["access-control-allow-origin"] == CAM
    assert "POST" in preflight.headers["access-control-allow-methods"]
    assert "content-type" in preflight.headers["access-control-allow-headers"].lower()
    assert preflight.headers["access-control-max-age"] == str(PREFLIGHT_SECONDS)
    assert "access-control-allow-credentials" not in preflight.headers


@pytest.mark.usefixtures("origins")
def test_a_named_origin_reads_answers_and_refusals_and_their_headers(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    for origin in (CAM, "http://localhost:3000"):
        answer = client.post("/v1/evaluate", json=evaluate_body, headers={"Origin": origin})
        assert answer.status_code == 200
        assert answer.headers["access-control-allow-origin"] == origin
        assert "origin" in answer.headers["vary"].lower()
        exposed = {
            h.strip().lower() for h in answer.headers["access-control-expose-headers"].split(",")
        }
        assert exposed == {h.lower() for h in EXPOSED}
    refused = client.post("/v1/evaluate", json={}, headers={"Origin": CAM})
    assert refused.status_code == 422 and refused.headers["access-control-allow-origin"] == CAM
    not_json = client.post(
        "/v1/evaluate", content=b"x", headers={"Origin": CAM, "Content-Type": "text/plain"}
    )
    assert not_json.status_code == 415  # refused by the body check, outside the routes
    assert not_json.headers["access-control-allow-origin"] == CAM


@pytest.mark.usefixtures("origins")
def test_an_origin_not_named_gets_no_cors_headers(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    for origin in ("https://evil.example.com", f"{CAM}:8443", "http://cam.example.com"):
        answer = client.post("/v1/evaluate", json=evaluate_body, headers={"Origin": origin})
        assert "access-control-allow-origin" not in answer.headers
        preflight = client.options("/v1/evaluate", headers={"Origin": origin, **PREFLIGHT})
        assert (
            preflight.status_code == 405 and "access-control-allow-origin" not in preflight.headers
        )


def test_any_origin_with_a_star(
    client: TestClient, evaluate_body: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    set_origins(monkeypatch, "*")
    answer = client.post("/v1/evaluate", json=evaluate_body, headers={"Origin": CAM})
    assert answer.headers["access-control-allow-origin"] == "*"


@pytest.mark.parametrize(
    "origin",
    ["http://localhost:3000/", "https://cam.example.com/app", "cam.example.com", "HTTP://CAM"],
)
def test_a_page_url_or_a_host_is_not_an_origin(origin: str) -> None:
    with pytest.raises(ValidationError, match="is not a web origin"):
        Settings(cors_origins=origin)


def test_origins_are_read_as_a_comma_separated_list() -> None:
    listed = Settings(cors_origins=" https://a.example , http://[::1]:8080,,")
    assert listed.cors_origins == ("https://a.example", "http://[::1]:8080")
    assert Settings().cors_origins == ()
