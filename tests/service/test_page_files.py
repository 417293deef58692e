"""The page's files are asked for again at each load, so a new release's page is never mixed
with a browser's cached old scripts (the upgrade audit of stop 62, F8): ``no-cache``, and an
unchanged file answers 304 to its ETag."""

from __future__ import annotations

import re
from pathlib import Path

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


STATIC = Path(__file__).resolve().parents[2] / "service" / "web" / "static"


def test_no_function_of_the_pages_scripts_is_declared_twice() -> None:
    """The page's scripts are classic scripts in one global scope: a second ``function name``
    (in the same file or another) silently replaces the first everywhere, and no load error
    says so. A status-line helper named as the box editor's reader of a number once broke every
    box's request (``Cannot read properties of null``), caught only by the browser tests."""
    scripts = re.findall(r'<script src="/ui/([\w.]+)"', (STATIC / "index.html").read_text())
    assert len(scripts) >= 5  # the page's scripts, read from the page itself
    declared: dict[str, str] = {}
    twice = []
    for script in scripts:
        text = (STATIC / script).read_text()
        for name in re.findall(r"^(?:async\s+)?function\s*\*?\s*(\w+)", text, flags=re.MULTILINE):
            if name in declared:
                twice.append(f"{name}: {declared[name]} and {script}")
            declared.setdefault(name, script)
    assert len(declared) > 100
    assert twice == []
