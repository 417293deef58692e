"""The page's files are asked for again at each load, so a new release's page is never mixed
with a browser's cached old scripts (the upgrade audit of stop 62, F8): ``no-cache``, and an
unchanged file answers 304 to its ETag."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient


@pytest.mark.parametrize("path", ["/", "/ui/app.js", "/ui/index.html", "/ui/style.css"])
def test_the_pages_files_are_revalidated(client: TestClient, path: str) -> None:
    answer = client.get(path)
    assert answer.status_code == 200
    assert answer.headers["cache-control"] == "no-cache"
    if path.startswith("/ui/"):  # StaticFiles answers an unchanged file 304 (/ is sent whole)
        again = client.get(path, headers={"If-None-Match": answer.headers["etag"]})
        assert again.status_code == 304


def test_the_api_answers_are_not_given_the_pages_header(client: TestClient) -> None:
    assert "cache-control" not in client.get("/healthz").headers
