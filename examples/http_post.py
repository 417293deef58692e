"""POST JSON to the service with the standard library alone (the README examples use it)."""

from __future__ import annotations

import json
import sys
import urllib.error
import urllib.request
from collections.abc import Callable
from typing import Any

Post = Callable[[str, dict[str, Any]], dict[str, Any]]
DEFAULT_URL = "http://127.0.0.1:8000"
"""Where the README's first command serves the service."""


class ServiceError(Exception):
    """The service could not be reached, or answered an error: one line saying which."""


def http_post(base: str) -> Post:
    """A function that POSTs a JSON body to ``base + route`` and returns the JSON answer.

    Raises (from the function):
        ServiceError: no service at ``base``, or an error answer (its status and detail).
    """

    def post(route: str, body: dict[str, Any]) -> dict[str, Any]:
        request = urllib.request.Request(
            base + route,
            data=json.dumps(body).encode(),
            headers={"content-type": "application/json"},
        )
        try:
            with urllib.request.urlopen(request) as answer:
                result: dict[str, Any] = json.load(answer)
                return result
        except urllib.error.HTTPError as error:
            raise ServiceError(f"{base + route} answered {error.code}: {_detail(error)}") from None
        except (urllib.error.URLError, OSError) as error:
            reason = getattr(error, "reason", error)
            raise ServiceError(
                f"no service at {base} ({reason}): start it with the README's first command, "
                f"or give its URL as the argument (python3 {sys.argv[0]} http://host:port)"
            ) from None

    return post


def _detail(error: urllib.error.HTTPError) -> str:
    """An error answer's first detail message, or its text."""
    text = error.read().decode(errors="replace")
    try:
        detail = json.loads(text)["detail"]
        return str(detail[0]["msg"] if isinstance(detail, list) else detail)
    except (ValueError, KeyError, IndexError, TypeError):
        return text[:200]


def run(lines: Callable[[Post], list[str]]) -> None:
    """Print an example's lines, from the service at the URL argument (default DEFAULT_URL).

    A service that cannot be reached or answers an error ends the script with one line on
    stderr and exit status 1, not a traceback.
    """
    url = sys.argv[1] if len(sys.argv) > 1 else DEFAULT_URL
    try:
        printed = lines(http_post(url.rstrip("/")))
    except ServiceError as error:
        sys.exit(f"{sys.argv[0]}: {error}")
    for line in printed:
        print(line)
