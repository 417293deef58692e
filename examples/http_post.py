"""POST JSON to the service with the standard library alone (the README examples use it)."""

from __future__ import annotations

import json
import urllib.request
from collections.abc import Callable
from typing import Any

Post = Callable[[str, dict[str, Any]], dict[str, Any]]


def http_post(base: str) -> Post:
    """A function that POSTs a JSON body to ``base + route`` and returns the JSON answer."""

    def post(route: str, body: dict[str, Any]) -> dict[str, Any]:
        request = urllib.request.Request(
            base + route,
            data=json.dumps(body).encode(),
            headers={"content-type": "application/json"},
        )
        with urllib.request.urlopen(request) as answer:
            result: dict[str, Any] = json.load(answer)
            return result

    return post
